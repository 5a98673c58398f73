"""Newton's reversal guard of a friction law evaluated at a set of points (a coupling's slave
nodes or Gauss points), shared by the two-body couplings (:mod:`.mortar`,
:mod:`.point_coupling`).

Semi-smooth Newton can 2-cycle on a point whose trial traction flips direction between
iterates while it slips at both (an edge node of a contact pressed and dragged: a trial
traction of 1e8 flipping sign against a bound of 7e6; a block stopped by friction on a plinth
with its slave nodes' mass redistributed: two residuals 0.49 and 0.53 alternating until
max_it). A reversal went through stick, so the next iterate takes the point as sticking
(linear in u there), as the penalty's guard on the obstacle's forms
(:func:`contactfx.contact.laws.reversal`). At a converged iterate nothing reverses: the
solution is the law's own. :class:`contactfx.solvers.guards.ReversalGuard` drives the
coupling: ``remember_iterate`` at every Jacobian, ``forget_iterate`` at a new step,
``guard_active`` False for the law's own residual.
"""

from __future__ import annotations

import numpy as np

__all__ = ["ReversalMemory"]


class ReversalMemory:
    """The trial tractions of the last residual and of the iterate remembered at the last
    Jacobian, per group of points (``key``: a direction of the pair), each point named by an
    id (global node numbers, or positions in a fixed set of Gauss points). A coupling calls
    :meth:`init_reversals` in its constructor."""

    #: whether the coupling has the guard (friction), read by ContactSNES
    guarded: bool
    #: False: the law's own residual (set by ReversalGuard)
    guard_active: bool
    _trials: dict[int, tuple[np.ndarray, np.ndarray, np.ndarray]]
    _remembered: dict[int, tuple[np.ndarray, np.ndarray, np.ndarray]] | None

    def init_reversals(self, guarded: bool) -> None:
        self.guarded = guarded
        self.guard_active = True
        self._trials = {}
        self._remembered = None

    def _record_trial(self, key: int, ids: np.ndarray, z: np.ndarray, slipping: np.ndarray) -> None:
        """The trial tractions z (n, gdim) of the points ``ids`` at this residual, and which
        of them slip by the law's own test."""
        self._trials[key] = (np.array(ids), np.array(z), np.array(slipping))

    def _reversed(self, key: int, ids: np.ndarray, z: np.ndarray) -> np.ndarray:
        """True at a point that slipped at the remembered iterate and whose trial traction z
        now points against the one there (module docstring)."""
        out = np.zeros(len(z), dtype=bool)
        last = self._remembered
        if not self.guard_active or last is None or key not in last:
            return out
        ids_last, z_last, slipped = last[key]
        _, here, there = np.intersect1d(ids, ids_last, return_indices=True)
        out[here] = slipped[there] & (np.einsum("ij,ij->i", z[here], z_last[there]) < 0.0)
        return out

    def remember_iterate(self) -> None:
        """The last residual's trial tractions become the guard's previous iterate."""
        self._remembered = dict(self._trials)

    def forget_iterate(self) -> None:
        self._remembered = None
