"""Uzawa's outer loop for the augmented Lagrangian: Newton solves for fixed multipliers, then
the nodal multiplier update, until the update stops changing the multiplier."""

from __future__ import annotations

from collections.abc import Callable

import dolfinx
import numpy as np
from mpi4py import MPI

from contactfx.solvers.base import ConvergenceError, SolverWrapper, SolveStats, TimeLimitExceeded
from contactfx.solvers.snes import ContactSNES

__all__ = ["Uzawa"]


class Uzawa(SolverWrapper):
    """Wraps a :class:`ContactSNES` whose contact residual reads ``multiplier``.

    ``update`` fills the Function it is given with the multiplier's next nodal values;
    ``mask`` (bool per local dof of that space) selects the contact boundary's nodes, elsewhere
    the multiplier is kept at zero. The loop stops when
    max |lambda_{k+1} - lambda_k| <= tol max |lambda_{k+1}| over the contact nodes: the nodal
    constraint violation and complementarity residual are then below tol max |lambda| / r.
    On failure (inner divergence or ``max_it`` outer iterations) the multiplier of the last
    converged load step is restored and ``ConvergenceError`` raised, so load cut-back works.

    The Newton solves also stop at a step below ``STEP_TOL`` of the displacement (unless the
    user sets ``snes_stol``): after the first, each starts from a residual as small as the
    multiplier's last change, and ``rtol`` of that can lie below the residual's round-off
    floor, where Newton would stagnate until ``max_it`` (Westergaard in full contact, P2).
    """

    #: the Newton step, relative to the state, below which an inner solve has converged
    STEP_TOL = 1e-12

    def __init__(
        self,
        inner: ContactSNES,
        multiplier: dolfinx.fem.Function,
        update: Callable[[dolfinx.fem.Function], None],
        mask: np.ndarray,
        *,
        tol: float,
        max_it: int,
    ) -> None:
        super().__init__(inner)
        #: the Newton solver itself (its tolerances are adjusted during the loop)
        self.newton = inner
        self.multiplier = multiplier
        self.update = update
        self.mask = mask
        self.tol = tol
        self.max_it = max_it
        self._next = multiplier.copy()
        self.comm = inner.comm

    def _max(self, values: np.ndarray) -> float:
        local = float(np.max(np.abs(values), initial=0.0))
        return self.comm.allreduce(local, op=MPI.MAX)

    def solve(self) -> SolveStats:
        lam = self.multiplier.x.array
        saved = lam.copy()
        total = SolveStats()
        imap = self.multiplier.function_space.dofmap.index_map
        bs = self.multiplier.function_space.dofmap.index_map_bs
        mask = np.repeat(self.mask, bs) if bs > 1 else self.mask.copy()
        mask[imap.size_local * bs :] = False  # owned dofs decide; ghosts follow
        stol = self.newton.tolerances()["stol"]
        if not self.newton.user_sets("snes_stol"):
            self.newton.set_tolerances(stol=max(stol, self.STEP_TOL))
        try:
            return self._iterate(lam, saved, mask, total)
        finally:
            self.newton.set_tolerances(stol=stol)

    def _iterate(
        self, lam: np.ndarray, saved: np.ndarray, mask: np.ndarray, total: SolveStats
    ) -> SolveStats:
        for k in range(1, self.max_it + 1):
            try:
                stats = self.inner.solve()
            except ConvergenceError as err:
                lam[:] = saved
                if isinstance(err, TimeLimitExceeded):
                    raise
                raise ConvergenceError(f"{err.reason} (Uzawa iteration {k})") from None
            total.newton += stats.newton
            total.ksp += stats.ksp
            total.halvings += stats.halvings
            total.reason = stats.reason
            self.update(self._next)
            new = np.where(mask, self._next.x.array, 0.0)
            change = self._max((new - lam)[mask])
            size = self._max(new[mask])
            lam[:] = new
            self.multiplier.x.scatter_forward()
            if change <= self.tol * size or size == 0.0 and change == 0.0:
                total.outer = k
                return total
        lam[:] = saved
        raise ConvergenceError(
            f"augmented Lagrangian (Uzawa) not converged in {self.max_it} iterations "
            f"(multiplier change {change:.3e}, tolerance {self.tol:.1e} x {size:.3e})"
        )
