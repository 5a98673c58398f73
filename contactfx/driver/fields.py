"""Surface-field helpers shared by every problem kind: quadrature rules, masks of surface dofs,
conditions that confine a field to a surface, lumped nodal projections and global sums."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import dolfinx
import numpy as np
import ufl
from mpi4py import MPI
from numpy.typing import NDArray
from petsc4py import PETSc

from contactfx import _compat
from contactfx.contact.surface import Expr
from contactfx.mechanics.axisymmetric import unweighted

__all__ = [
    "vertex_rule",
    "surface_mask",
    "near_points",
    "at_points",
    "at_nodes",
    "confine",
    "assemble_array",
    "NodalProjection",
    "nodal_contact",
    "global_sum",
    "zero_pattern",
]


#: a predicate of points x (3, n): bool per point
PointPredicate = Callable[[NDArray[np.float64]], NDArray[np.bool_]]
#: (point, tolerance) pairs
TolerancePoints = Sequence[tuple[NDArray[np.float64], float]]


def vertex_rule(fdim: int) -> dict[str, Any]:
    """Quadrature at the vertices of a simplex of dimension ``fdim`` (a facet's: the
    trapezoidal rule, nodal collocation of the multiplier equations, exact nodal
    complementarity; a cell's: the lumped mass of P1)."""
    points: tuple[tuple[float, ...], ...]
    weights: tuple[float, ...]
    if fdim == 0:
        points, weights = ((),), (1.0,)
    elif fdim == 1:
        points, weights = ((0.0,), (1.0,)), (0.5, 0.5)
    elif fdim == 2:
        points, weights = ((0.0, 0.0), (1.0, 0.0), (0.0, 1.0)), (1.0 / 6.0,) * 3
    else:
        points = ((0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
        weights = (1.0 / 24.0,) * 4
    return {
        "quadrature_rule": "custom",
        "quadrature_degree": 1,
        "quadrature_points": points,
        "quadrature_weights": weights,
    }


def surface_mask(
    Q: Any, fdim: int, facets: NDArray[np.int32], excluded: PointPredicate | None = None
) -> NDArray[np.bool_]:
    """Bool per local (owned + ghost) dof block of the collapsed space Q: on one of the facets
    on any rank, and not where ``excluded`` (a predicate of the points (3, n), e.g. on a crack
    tip or front) holds."""
    marker = dolfinx.fem.Function(Q)
    dofs = _compat.locate_dofs_topological(Q, fdim, facets)
    bs = Q.dofmap.index_map_bs
    marker.x.array.reshape(-1, bs)[dofs] = 1.0
    vec = _compat.petsc_vec(marker)
    vec.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    vec.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
    on = marker.x.array.reshape(-1, bs)[:, 0] > 0.0
    if excluded is not None:
        on[dolfinx.fem.locate_dofs_geometrical(Q, excluded)] = False
    return on


def near_points(points: TolerancePoints) -> PointPredicate:
    """The predicate of points x (3, n): within the tolerance of one of the (point, tolerance)
    pairs."""

    def at(x: NDArray[np.float64]) -> NDArray[np.bool_]:
        hit = np.zeros(x.shape[1], dtype=bool)
        for point, tol in points:
            hit |= np.linalg.norm(x[: len(point)].T - point, axis=1) < tol
        return hit

    return at


def at_points(Q: Any, points: TolerancePoints) -> NDArray[np.int32]:
    """Local dof blocks of the collapsed space Q within the tolerance of one of the
    (point, tolerance) pairs."""
    return dolfinx.fem.locate_dofs_geometrical(Q, near_points(points))


def at_nodes(Q: Any, points: NDArray[np.float64]) -> NDArray[np.bool_]:
    """Bool per local dof (block) of the collapsed space Q: at one of ``points`` (dof
    coordinates of another space on the same mesh; the same vertex gives the same coordinates
    to round-off)."""
    x = _compat.dof_coordinates(Q)
    if len(points) == 0:
        return np.zeros(len(x), dtype=bool)
    scale = 1e-9 * max(float(np.abs(x).max(initial=0.0)), float(np.abs(points).max()), 1e-300)
    keys = {tuple(k) for k in np.round(points / scale).astype(np.int64)}
    return np.array([tuple(k) in keys for k in np.round(x / scale).astype(np.int64)], dtype=bool)


def confine(Wsub: Any, mask_of: Callable[[Any], NDArray[np.bool_]]) -> list[Any]:
    """Dirichlet conditions that fix the sub-space ``Wsub`` to zero outside the dofs that
    ``mask_of(Q)`` marks (Q the collapsed sub-space): a field that lives on a surface only
    (a contact multiplier, an interface enrichment)."""
    Q, q_to_w = Wsub.collapse()
    keep = mask_of(Q)
    bs = Q.dofmap.index_map_bs
    q_to_w = np.asarray(q_to_w).reshape(-1, bs)
    if bs == 1:
        return [_compat.dirichletbc(np.float64(0.0), q_to_w[~keep, 0].astype(np.int32), Wsub)]
    return [
        _compat.dirichletbc(np.float64(0.0), q_to_w[~keep, i].astype(np.int32), Wsub.sub(i))
        for i in range(bs)
    ]


def assemble_array(form: Any) -> NDArray[np.float64]:
    """The assembled linear form's owned entries (ghost contributions accumulated)."""
    b = _compat.assemble_vector(_compat.create_vector(form), form)
    arr = b.getArray().copy()
    b.destroy()
    return arr


class NodalProjection:
    """Lumped L2 projection onto the nodes of a surface: target = (int f q dS) / (int q dS)
    where the mass is > 0, 0 elsewhere. With the vertex rule it gives f's exact nodal values;
    it serves interior-facet quantities, which cannot be interpolated cellwise. An average:
    the measure's weight (an axisymmetric body's r) is left out."""

    def __init__(self, measure: ufl.Measure, space: Any, restrict: str | None = None) -> None:
        q = ufl.TestFunction(space)
        self.q = q if restrict is None else q(restrict)
        self.measure = measure = unweighted(measure)
        shape = q.ufl_shape
        ones = ufl.as_vector([1.0] * shape[0]) if shape else 1.0
        self.mass = assemble_array(dolfinx.fem.form(ufl.inner(ones, self.q) * measure))
        self.on = self.mass > 0.0

    def form(self, expr: Expr) -> Any:
        """The compiled right-hand side of ``expr`` (compile once, project every step)."""
        return dolfinx.fem.form(ufl.inner(expr, self.q) * self.measure)

    def __call__(self, form: Any, target: dolfinx.fem.Function) -> None:
        b = assemble_array(form)
        vec = _compat.petsc_vec(target)
        arr = vec.getArray()
        arr[:] = 0.0
        arr[self.on] = b[self.on] / self.mass[self.on]
        vec.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)


def nodal_contact(
    p: NDArray[np.float64], gap: NDArray[np.float64], on: NDArray[np.bool_], comm: MPI.Comm
) -> tuple[float, NDArray[np.bool_], float, float]:
    """(peak pressure, closed, max penetration, max |g p|) from the nodal pressure and gap
    (local arrays of a P1 field) at the surface nodes ``on``; closed marks the local nodes
    where p > 1e-10 of the peak."""
    n = len(on)
    p_s, g_s = p[:n][on], gap[:n][on]
    peak = comm.allreduce(float(np.max(p_s, initial=0.0)), op=MPI.MAX)
    penetration = comm.allreduce(max(0.0, -float(g_s.min(initial=0.0))), op=MPI.MAX)
    complementarity = comm.allreduce(float(np.max(np.abs(g_s * p_s), initial=0.0)), op=MPI.MAX)
    return peak, p > 1e-10 * max(peak, 1e-300), penetration, complementarity


def global_sum(form: Any, comm: MPI.Comm) -> float:
    """A compiled functional summed over the ranks."""
    return comm.allreduce(dolfinx.fem.assemble_scalar(form), op=MPI.SUM)


def zero_pattern(
    mesh: dolfinx.mesh.Mesh,
    trial: Expr,
    test: Expr,
    measures: Sequence[tuple[ufl.Measure, Callable[[Expr], Expr]]],
) -> ufl.Form:
    """A zero coupling of every component of ``trial`` with every component of ``test`` on
    each (measure, restriction) pair: gives the bulk matrix the sparsity of the contact terms,
    so that the contact Jacobian can be added to it."""
    zero = dolfinx.fem.Constant(mesh, 0.0)
    n = ufl.shape(trial)[0]
    s_trial = sum(trial[i] for i in range(n))
    s_test = sum(test[i] for i in range(n))
    terms = [zero * couple(s_trial) * couple(s_test) * measure for measure, couple in measures]
    return sum(terms[1:], terms[0])
