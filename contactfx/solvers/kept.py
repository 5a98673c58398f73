"""A preconditioner kept across Newton iterations and solves: the kept factorisation of
:meth:`contactfx.solvers.snes.ContactSNES.reuse_factorisation` and the kept AMG hierarchy of
:meth:`contactfx.solvers.snes.ContactSNES.reuse_preconditioner` (when to refresh it:
docs/verification.md section 18, speed)."""

from __future__ import annotations

from petsc4py import PETSc

__all__ = ["KeptPreconditioner", "factorisation_worth"]


class KeptPreconditioner:
    """A preconditioner kept across Newton iterations: its own matrix P, refreshed from the
    Jacobian J only at the first iteration of a solve, after a failed Krylov solve and after
    one that needed ``rebuild_it`` iterations or more (an unchanged P is not set up again:
    PCSetUp compares the matrix state). ``coupled``: J's pattern may grow between refreshes
    (a two-body coupling's search). ``every_solve`` False: not refreshed at a solve's first
    iteration either (a dynamic run's steps, whose Jacobian changes with the contact status
    only); ``stale``: refreshed at the next Jacobian (the bulk was re-assembled). A
    checkpoint holds P's values (a restarted run factorises the same matrix).

    Kept across solves, P is also refreshed once the back-substitutions made with it (the
    Krylov iterations since its factorisation) reach what a factorisation is worth: the
    factor's elimination flops over the flops of one back-substitution, 2 per entry of the
    factors (MUMPS's RINFOG(3) and INFOG(9); read after each factorisation, the same on
    every rank). The kept matrix ages as the contact status drifts from the one it was
    factorised at, and each solve then takes more iterations: in 2D, where a factorisation
    costs 7 (sliding-stop) to 16 (disc-drop) back-substitutions, refreshing at that budget
    halved disc-drop's time per step; in 3D (hertz-impact, 565) the budget is never reached
    and the iteration limit alone refreshes, which is what measured fastest there
    (docs/verification.md section 18, speed)."""

    checkpoint_values = ("P",)

    def __init__(
        self,
        J: PETSc.Mat,
        nullspace: PETSc.NullSpace | None,
        rebuild_it: int,
        coupled: bool,
        every_solve: bool = True,
    ) -> None:
        self.rebuild_it, self.coupled, self.every_solve = rebuild_it, coupled, every_solve
        self.stale = False
        #: Krylov iterations (back-substitutions) made with P since its factorisation, and
        #: what a factorisation is worth in them (across solves only; None: not yet read)
        self.spent = 0
        self.budget: float | None = None
        self._read_budget = False
        self.P = J.duplicate(copy=True)
        if nullspace is not None:  # AMG reads the near-nullspace from its own matrix
            self.P.setNearNullSpace(nullspace)

    def update(self, snes: PETSc.SNES, J: PETSc.Mat) -> None:
        ksp = snes.getKSP()
        its = ksp.getIterationNumber()  # the last Krylov solve's
        if not self.every_solve:  # the back-substitutions made with P, and P's worth
            self.spent += its
            if self._read_budget and its > 0:  # (a solve has factorised P since)
                self.budget = factorisation_worth(ksp)
                self._read_budget = False
        fresh = (
            self.stale
            or (self.every_solve and snes.getIterationNumber() == 0)
            or ksp.getConvergedReason() < 0
            or its >= self.rebuild_it
            or (self.budget is not None and self.spent >= self.budget)
        )
        if fresh:
            self.stale = False
            self.spent = 0
            self._read_budget = not self.every_solve
            S = PETSc.Mat.Structure
            if self.coupled:
                # a coupling adds nonzeros as the search pairs new points: a factorisation
                # from scratch (MUMPS 5.7 under PETSc 3.22 crashed, at 2 ranks, refactorising
                # numerically a matrix whose pattern had grown since its analysis)
                ksp.getPC().reset()
            J.copy(
                self.P,
                structure=S.DIFFERENT_NONZERO_PATTERN if self.coupled else S.SAME_NONZERO_PATTERN,
            )

    def destroy(self) -> None:
        self.P.destroy()


def factorisation_worth(ksp: PETSc.KSP) -> float | None:
    """A MUMPS LU factorisation's elimination flops over one back-substitution's (2 per entry
    of the factors): what refactorising costs in Krylov iterations with the kept factors;
    None before the first factorisation or with another factor package."""
    try:
        F = ksp.getPC().getFactorMatrix()
        flops, entries = F.getMumpsRinfog(3), F.getMumpsInfog(9)
    except PETSc.Error:
        return None
    entries = entries if entries >= 0 else -entries * 1e6  # negative: millions
    return flops / (2.0 * entries) if flops > 0.0 and entries > 0 else None
