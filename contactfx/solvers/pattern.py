"""The nonzero pattern of a two-body Jacobian: every search adds the couplings it finds, and
couplings the contact has left stay as explicit zeros (which the factorisation fills from);
a Jacobian grown past a factor of the bulk's nonzeros is rebuilt on the bulk's pattern
(docs/verification.md, section 15, "The Jacobian's pattern")."""

from __future__ import annotations

from petsc4py import PETSc

__all__ = ["nonzeros", "rebuilt"]


def nonzeros(A: PETSc.Mat) -> float:
    """The nonzeros of A's pattern over all ranks (explicit zeros included). Collective."""
    return float(A.getInfo(PETSc.Mat.InfoType.GLOBAL_SUM)["nz_used"])


def rebuilt(K: PETSc.Mat, nullspace: PETSc.NullSpace | None = None) -> PETSc.Mat:
    """A Jacobian on the bulk matrix K's pattern that accepts new entries (the couplings of
    the next search). Collective."""
    fresh = K.duplicate(copy=True)
    fresh.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, False)
    if nullspace is not None:
        fresh.setNearNullSpace(nullspace)
    return fresh
