"""Newton's guards beside the SNES solve (:class:`contactfx.solvers.snes.ContactSNES`): the
friction law's reversal guard against stick/slip cycling, and the convergence test that stops
at the residual's round-off level (finite strain)."""

from __future__ import annotations

from typing import Any

import dolfinx
import numpy as np
from petsc4py import PETSc


class ReversalGuard:
    """Newton's previous iterate for the friction law's reversal guard
    (:func:`contactfx.contact.laws.reversal`, and a ``guarded`` coupling's own, as the
    mortar's): at every
    Jacobian ``iterate`` (a Function of u's space that the contact forms read) becomes u and
    the coupling remembers its iterate (``remember_iterate``); ``active`` False makes the
    residual the law's own (the iterate follows u at every residual too; the coupling's
    ``guard_active`` follows it); ``initial_norm`` the residual norm at the start of the last
    SNES solve (its relative tolerance's reference)."""

    def __init__(
        self,
        iterate: dolfinx.fem.Function | None,
        u: dolfinx.fem.Function,
        snes: PETSc.SNES,
        coupling: Any = None,
    ) -> None:
        self.iterate, self.u = iterate, u
        #: a coupling with its own guard (``remember_iterate``, ``guard_active``), or None
        self.coupling = coupling if getattr(coupling, "guarded", False) else None
        self._active = True
        self.initial_norm = 0.0
        snes.setMonitor(self._monitor)

    @property
    def active(self) -> bool:
        return self._active

    @active.setter
    def active(self, value: bool) -> None:
        self._active = value
        if self.coupling is not None:
            self.coupling.guard_active = value

    def remember(self) -> None:
        if self.iterate is not None:
            self.iterate.x.array[:] = self.u.x.array
        if self.coupling is not None:
            self.coupling.remember_iterate()

    def start(self) -> None:
        """A new load step: the coupling's iterate is forgotten (the first residual of the
        step is the law's own, as the forms' with the iterate at the step's start)."""
        if self.coupling is not None:
            self.coupling.forget_iterate()

    def _monitor(self, snes: PETSc.SNES, its: int, norm: float) -> None:
        if its == 0:
            self.initial_norm = norm


class RoundOffStop:
    """Newton's convergence test for finite-strain bodies: PETSc's default one (the residual
    below ``atol`` or below ``rtol`` times the first, ``stol`` on the update, the divergence
    tolerance), and a stop at the residual's round-off level: an iterate whose residual
    is no longer falling (above 0.1 of the last) once the last is 1e-8 of the first is
    converged. Newton falls quadratically to that level; below it the residual is the
    round-off of terms far larger than it (the gap of the contact in the deformed
    configuration is the difference of current positions, x_s - y, of size |x| where the
    penalty kappa multiplies it: a floor of kappa eps |x| w, 2e-11 on a block pressed to
    1e-10 of a small load increment's residual), which the relative tolerance of a step
    whose predictor was already close does not reach. The depth is measured against the
    largest first residual of the run's solves too: a step that changes nothing (a hold in
    the load program) starts at the round-off level, where the residual cannot fall."""

    #: how far below the first residual the last must be before a stall counts as round-off
    DEPTH = 1e-8

    def __init__(self, snes: PETSc.SNES, divergence: float) -> None:
        self.first = self.last = 0.0
        self.peak = 0.0  # the largest first residual of the solves so far
        #: the size of the residual's terms when known (a dynamic step's inertia load M a*:
        #: its round-off floor, 1e-16 of that, can lie above 1e-8 of a well-predicted step's
        #: first residual), else 0
        self.scale = 0.0
        self.divergence = divergence
        self.stalled = 0  # solves stopped at the round-off level (a statistic)
        snes.setConvergenceTest(self)

    def __call__(self, snes: PETSc.SNES, it: int, norms: tuple[float, float, float]) -> int:
        xnorm, ynorm, fnorm = norms
        rtol, atol, stol, _ = snes.getTolerances()
        R = PETSc.SNES.ConvergedReason
        last, self.last = self.last, fnorm
        if it == 0:
            self.first = fnorm
            if np.isfinite(fnorm):
                self.peak = max(self.peak, fnorm)
        if not np.isfinite(fnorm):
            return R.DIVERGED_FNORM_NAN
        if fnorm < atol:
            return R.CONVERGED_FNORM_ABS
        if it == 0:
            return R.CONVERGED_ITERATING
        if fnorm <= rtol * self.first:
            return R.CONVERGED_FNORM_RELATIVE
        if ynorm < stol * xnorm:
            return R.CONVERGED_SNORM_RELATIVE
        if self.divergence > 0 and fnorm > self.divergence * self.first:
            return R.DIVERGED_DTOL
        depth = self.DEPTH * max(self.first, self.peak, self.scale)
        if it >= 2 and last <= depth and fnorm > 0.1 * last:
            self.stalled += 1
            return R.CONVERGED_FNORM_RELATIVE
        return R.CONVERGED_ITERATING
