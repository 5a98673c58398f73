"""One retry policy for MUMPS's workspace errors, for every linear solve of a solver.

MUMPS estimates its factorisation workspace during the analysis; in parallel the delayed
pivots (and so the workspace a factorisation needs) differ from run to run, and a
factorisation can fail with INFOG(1) = -9 (or another workspace error) where the same matrix
factorised the run before. MUMPS's advice is a larger relative workspace ICNTL(14) (MUMPS
users' guide, "Error diagnostics": -8, -9, -11, -14, -15, -17, -20). The policy doubles it,
up to :attr:`MumpsWorkspace.RETRIES` times, in the solver's options database, where the next
factorisation reads it (ICNTL set on a failed factor itself is not read again): a new KSP, or
the SNES's preconditioner reset.
"""

from __future__ import annotations

from petsc4py import PETSc

from contactfx.solvers.options import OptionsDB

__all__ = ["MumpsWorkspace", "mumps_error", "ksp_reason_name"]

#: MUMPS's errors of a workspace too small for the factorisation (INFOG(1))
WORKSPACE_ERRORS = (-8, -9, -11, -14, -15, -17, -20)
#: MUMPS's own default of ICNTL(14) (percent of the estimated workspace added)
DEFAULT_ICNTL14 = 20


def mumps_error(ksp: PETSc.KSP) -> int | None:
    """MUMPS's INFOG(1) of the factorisation behind ``ksp``'s preconditioner, None without
    MUMPS."""
    pc = ksp.getPC()
    if pc.getType() not in ("lu", "cholesky") or pc.getFactorSolverType() != "mumps":
        return None
    try:
        return int(pc.getFactorMatrix().getMumpsInfog(1))
    except PETSc.Error:  # no factor (the preconditioner's set-up failed before it)
        return None


def ksp_reason_name(reason: int) -> str:
    names = {v: k for k, v in vars(PETSc.KSP.ConvergedReason).items() if isinstance(v, int)}
    return names.get(reason, str(reason))


class MumpsWorkspace:
    """The retry policy of one solver (module docstring); ``options`` its options database."""

    #: retries of one solve at most
    RETRIES = 3

    def __init__(self, options: OptionsDB) -> None:
        self.options = options

    def enlarge(self, ksp: PETSc.KSP, attempt: int) -> bool:
        """After ``ksp``'s failed solve (``attempt`` from 0): whether to solve again. True if
        MUMPS failed for its workspace and retries are left: then ICNTL(14) is set to twice
        the failed factor's (at least twice MUMPS's default) in the options."""
        if attempt >= self.RETRIES or mumps_error(ksp) not in WORKSPACE_ERRORS:
            return False
        current = int(ksp.getPC().getFactorMatrix().getMumpsIcntl(14))
        self.options.set("mat_mumps_icntl_14", 2 * max(current, DEFAULT_ICNTL14))
        return True

    @staticmethod
    def describe(ksp: PETSc.KSP) -> str:
        """The KSP's reason and MUMPS's INFOG(1), for a failed solve's message."""
        infog = mumps_error(ksp)
        mumps = "" if infog is None else f", MUMPS INFOG(1) = {infog}"
        return f"KSP {ksp_reason_name(ksp.getConvergedReason())}{mumps}"
