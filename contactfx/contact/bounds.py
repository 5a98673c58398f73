"""SNES-VI reference: frictionless contact with a rigid obstacle as bound constraints on the
displacement dofs (PETSc ``vinewtonrsls``, Benson & Munson 2006,
doi:10.1080/10556780500065382).

The linearised (vertical) gap at the contact surface's dofs gives the upper bounds
u_d <= height(x_t + u_t - offset_t) - x_d + offset_d, evaluated at the reference position
(x_t without u_t: small deformation), re-evaluated whenever the load program moves the
obstacle. No contact term enters the residual; the contact pressure is the reaction
-R(u) = f_ext - f_int(u) at the bounded dofs, lumped by the surface's nodal mass.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import dolfinx
import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from contactfx import _compat
from contactfx.contact.method import MethodBase, Supports
from contactfx.solvers.base import SolverWrapper
from contactfx.solvers.snes import owned_size

if TYPE_CHECKING:
    from contactfx.contact.obstacles import Obstacle
    from contactfx.contact.surface import Surface
    from contactfx.solvers.base import Solver
    from contactfx.solvers.snes import ContactSNES

__all__ = ["BoundConstraints"]


@dataclass(frozen=True)
class BoundConstraints(MethodBase):
    """Bound constraints on the displacement (no parameters)."""

    name = "vi"
    supports = Supports(
        finite_strain=False,
        why_not={
            "finite_strain": "its bounds are the obstacle's height above each node's reference "
            "position (small strain)",
            "friction": "bound constraints are frictionless",
            "mixed_up": "it bounds the displacement dofs of a displacement-only space",
            "interfaces": "it bounds dofs, not displacement jumps",
            "nodal_quadrature": "it has no contact integrals",
        },
    )

    def residual(self, s: Surface) -> None:
        return None

    def pressure(self, s: Surface) -> None:
        return None

    def snes_options(self) -> dict[str, object]:
        return {"snes_type": "vinewtonrsls"}

    def attach(self, solver: ContactSNES, problem: Any) -> _Bounded:
        return _Bounded(solver, problem.V, problem.contact_facets, problem.obstacle, problem.offset)

    @staticmethod
    def reaction_pressure(
        solver: Solver, u: dolfinx.fem.Function, mass: np.ndarray, target: dolfinx.fem.Function
    ) -> float:
        """The nodal contact pressure from the reaction -R(u) = f_ext - f_int(u) of the bulk at
        the bounded component (lumped by the surface's nodal ``mass`` of ``target``'s space)
        into ``target``; returns the total contact force. ``u`` is the solver's state."""
        r = solver.bulk_residual()
        gdim = u.function_space.mesh.geometry.dim
        reac = -r.getArray()[gdim - 1 :: gdim]
        vec = _compat.petsc_vec(target)
        pk = vec.getArray()
        pk[:] = 0.0
        on = mass > 0.0
        pk[on] = np.maximum(reac[on], 0.0) / mass[on]
        force = u.function_space.mesh.comm.allreduce(
            float(np.sum(np.maximum(reac[on], 0.0))), op=MPI.SUM
        )
        r.destroy()
        vec.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
        return force


class _Bounded(SolverWrapper):
    """The solver with the bounds of the current obstacle position (updated with the load)."""

    #: the Newton solver itself (its bounds are set here)
    inner: ContactSNES

    def __init__(
        self,
        solver: ContactSNES,
        V: dolfinx.fem.FunctionSpace,
        facets: np.ndarray,
        obstacle: Obstacle,
        offset: dolfinx.fem.Constant,
    ) -> None:
        super().__init__(solver)
        mesh = V.mesh
        gdim = mesh.geometry.dim
        self.obstacle, self.offset, self.gdim = obstacle, offset, gdim
        if V.num_sub_spaces == 0:  # a one-component space (1D on dolfinx 0.9): V itself
            self.dofs = np.asarray(_compat.locate_dofs_topological(V, gdim - 1, facets))
            coords = _compat.dof_coordinates(V)[self.dofs][:, :gdim]
        else:
            Vd, _ = V.sub(gdim - 1).collapse()
            dofs = _compat.locate_dofs_topological((V.sub(gdim - 1), Vd), gdim - 1, facets)
            self.dofs = np.asarray(dofs[0])  # indices into V's local (unrolled) dofs
            coords = _compat.dof_coordinates(Vd)[np.asarray(dofs[1])][:, :gdim]
        self._template = dolfinx.fem.Function(V)  # owns the memory the bounds are copied from
        x = _compat.petsc_vec(self._template)
        self.lower, self.upper = x.copy(), x.copy()
        self.lower.set(PETSc.NINFINITY)
        self.upper.set(PETSc.INFINITY)
        keep = self.dofs < owned_size(V)
        self.dofs, self.coords = self.dofs[keep], coords[keep]

    def assemble_load(self) -> None:
        offset = self.offset.value
        t = self.coords[:, : self.gdim - 1] - offset[: self.gdim - 1]
        bound = self.obstacle.height(t) + offset[self.gdim - 1] - self.coords[:, self.gdim - 1]
        self.upper.getArray()[self.dofs] = np.where(np.isfinite(bound), bound, PETSc.INFINITY)
        self.inner.set_bounds(self.lower, self.upper)
        self.inner.assemble_load()

    def destroy(self) -> None:
        self.lower.destroy()
        self.upper.destroy()
        self.inner.destroy()
