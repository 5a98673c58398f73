"""The system on the kept dofs: Newton's unknowns without the confined ones.

A field that lives on a surface (a multiplier field, an interface enrichment) is carried by a
space on the whole mesh and fixed to zero away from the surface (dolfinx 0.5.2 has no
mixed-dimensional assembly to give it a boundary space). A confined dof is fixed to zero and
its column is zero in every Jacobian (Dirichlet rows and columns), so the kept rows of F(x) and
J(x) at x with the confined entries zero are exactly the system of the kept unknowns: SNES
works on those, and a surface field costs its surface dofs in every factorisation, not a copy
of the mesh.
"""

from __future__ import annotations

import numpy as np
from petsc4py import PETSc

__all__ = ["ReducedSystem"]


class ReducedSystem:
    """``K``: a matrix of the full layout (the bulk's Jacobian; its kept block is ``self.K``);
    ``keep``: the owned kept dofs (local indices); ``bc_rows``: the owned Dirichlet rows (local
    indices, confined ones included)."""

    def __init__(self, K: PETSc.Mat, keep: np.ndarray, bc_rows: np.ndarray) -> None:
        rstart = K.getOwnershipRange()[0]
        self.rows = PETSc.IS().createGeneral(
            (rstart + keep).astype(PETSc.IntType), comm=K.getComm()
        )
        self.K = K.createSubMatrix(self.rows, self.rows)
        kept_bc = np.flatnonzero(np.isin(keep, bc_rows))  # positions among the kept dofs
        self.bc_rows = (self.K.getOwnershipRange()[0] + kept_bc).astype(PETSc.IntType)
        self.x = self.K.createVecRight()
        self.F = K.createVecLeft()  # a residual on all dofs
        self.scatter = PETSc.Scatter().create(self.F, self.rows, self.x, None)
        self.Jc: PETSc.Mat | None = None

    def restrict(self, full: PETSc.Vec, out: PETSc.Vec | None = None) -> PETSc.Vec:
        """The kept entries of ``full`` (into ``out``, a new vector if None)."""
        out = self.x.duplicate() if out is None else out
        self.scatter.scatter(
            full, out, addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD
        )
        return out

    def extend(self, kept: PETSc.Vec, full: PETSc.Vec) -> None:
        """Set the owned kept entries of ``full`` (its confined entries stay zero)."""
        self.scatter.scatter(
            kept, full, addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.REVERSE
        )

    def bulk_block(self, K: PETSc.Mat) -> PETSc.Mat:
        """The kept rows and columns of a bulk Jacobian that changed (into ``self.K``)."""
        self.K = K.createSubMatrix(self.rows, self.rows, submat=self.K)
        return self.K

    def kept_block(self, A: PETSc.Mat) -> PETSc.Mat:
        """The kept rows and columns of A (a matrix of A's pattern, reused from call to
        call)."""
        self.Jc = A.createSubMatrix(self.rows, self.rows, submat=self.Jc)
        return self.Jc

    def destroy(self) -> None:
        for obj in (self.rows, self.K, self.x, self.F, self.scatter, self.Jc):
            if obj is not None:
                obj.destroy()
