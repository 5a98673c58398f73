"""The volume ratio J = det F of a finite-strain body, sampled in every cell: whether a state
(Newton's trial iterate) has inverted an element, and where the smallest J is.

A finite-strain energy is defined for J > 0 only (the neo-Hookean ln J is NaN at J <= 0), so a
trial iterate that inverts an element makes the residual NaN, and SNES stops with
DIVERGED_FNORM_NAN: its ``bt`` line search does not backtrack from a NaN residual in PETSc
3.18, and the default ``basic`` one takes the full step. :class:`VolumeRatio` is what the
solver's step halving asks (:meth:`contactfx.solvers.snes.ContactSNES.limit_steps`: a damping
of the Newton step as in global Newton methods, Deuflhard 2004, Newton Methods for Nonlinear
Problems, doi:10.1007/978-3-642-23899-4, chapter 3, with J > 0 as the test) and what the
failure diagnosis reports (:meth:`contactfx.driver.problem.Problem.diagnose`).

J is sampled at the points of the reference cell's default quadrature rule of degree 2k (k the
displacement degree: 3 points in a triangle, 4 in a tetrahedron for P1; 6 and 14 for P2),
interior points, where an axisymmetric body's hoop stretch (r + u_r) / r is defined. For P1 in
plane strain or 3D J is constant on a cell and every point sees it; for P2, and with the hoop
stretch, J varies within a cell, and an inversion confined to a cell's corner between the
samples still gives a NaN residual (a failed Newton solve, as without the check). A check does
not change what Newton converges to: it only shortens steps.
"""

from __future__ import annotations

from typing import Any

import dolfinx
import numpy as np
import ufl
from mpi4py import MPI
from numpy.typing import NDArray
from petsc4py import PETSc

from contactfx import _compat

__all__ = ["VolumeRatio"]

#: a UFL expression (ufl has no type stubs)
Expr = Any


class VolumeRatio:
    """J = ``jacobian`` (a UFL expression of ``state``: the material's det F3 of the
    displacement) at the sample points of every owned cell (module docstring), evaluated for
    any vector of ``state``'s layout (copied into a Function of its own: the state is left
    alone). ``degree``: the displacement's Lagrange degree."""

    def __init__(self, jacobian: Expr, state: dolfinx.fem.Function, degree: int) -> None:
        self.mesh = state.function_space.mesh
        self.comm = self.mesh.comm
        self.trial = dolfinx.fem.Function(state.function_space)
        points, _ = _compat.quadrature_rule(self.mesh, 2 * degree)
        self.expr = dolfinx.fem.Expression(
            ufl.replace(jacobian, {state: self.trial}), np.asarray(points)
        )
        tdim = self.mesh.topology.dim
        self.cells = np.arange(self.mesh.topology.index_map(tdim).size_local, dtype=np.int32)

    def values(self, x: PETSc.Vec) -> NDArray[np.float64]:
        """J at the sample points (owned cells, points) of the state x (its owned entries are
        read; NaN entries of an undefined J are kept)."""
        vec = _compat.petsc_vec(self.trial)
        x.copy(vec)
        vec.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
        out = _compat.eval_expression(self.expr, self.mesh, self.cells)
        return np.asarray(out).reshape(len(self.cells), -1)

    def positive(self, x: PETSc.Vec) -> bool:
        """Whether J > 0 at every sample point of every cell (collective: the same answer on
        every rank). NaN counts as not positive."""
        values = self.values(x)
        local = bool(np.all(values > 0.0))
        return bool(self.comm.allreduce(local, op=MPI.LAND))

    def smallest(self, x: PETSc.Vec) -> tuple[float, NDArray[np.float64]]:
        """(the smallest J over the mesh (-inf when J is not a number somewhere), the midpoint
        of its cell in the reference mesh), the same on every rank (collective)."""
        values = np.nan_to_num(self.values(x), nan=-np.inf)
        per_cell = values.min(axis=1) if values.size else np.zeros(0)
        local = float(per_cell.min()) if per_cell.size else np.inf
        j_min, owner = self.comm.allreduce((local, self.comm.rank), op=MPI.MIN)
        where = None
        if self.comm.rank == owner:
            cell = int(per_cell.argmin())
            where = _compat.cell_coordinates(self.mesh)[cell].mean(axis=0)
        return float(j_min), self.comm.bcast(where, root=owner)
