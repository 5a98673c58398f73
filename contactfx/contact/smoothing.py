"""A smooth master surface from the nodal normals: the deviation of a curved surface from its
P1 facets (chords), for the gap on curved non-matching interfaces.

A P1 surface mesh of a curved surface is a polygon (polyhedron) whose facets cut the curve by
up to their sagitta L^2 / (8 R). On a non-matching interface the two sides' polygons differ:
the nodes of the finer side, on the curve, sink into the coarser side's chords by up to that
sagitta at the chords' middles and by nothing at their nodes. Under an approach (or an
interference) delta the contact must then close a gap that oscillates with the coarser side's
element length L, an amplitude w = L^2 / (16 R): the pressure that closes it oscillates by
about pi E* w / L = pi E* L / (16 R) (the half-plane's response to a periodic indentation of
wavelength L), independent of delta, while the mean pressure scales with E* delta / R. When
L / delta is large the needed oscillation exceeds the mean pressure and nodes open. With the
coarser side as the slave its nodes do not resolve the finer master's kinks, and the dual
weights average them out: why mortar's nodal pressure on a curved interface depends on the
side (docs/verification.md, section 10).

The cure is the surface the mesh approximates rather than its chords: per facet a quadratic
deviation along the facet normal n_f,

    d(lambda) = sum over the edges (i, j) of A_ij lambda_i lambda_j,

whose slope at each end of an edge is the one of a surface normal to the nodal normal n_i (the
measure-weighted average of the facet normals at node i): with t the edge's unit direction
and L its length, s_i = -(t . n_i) / (n_f . n_i), and the quadratic's slopes A / L and -A / L
at the ends match the smaller of s_i and -s_j (A = 0 where they bend opposite ways: an
inflection). On a circle the two agree; where a straight part meets a curve (a punch's flat
face and its rounded edge) the averaged normal at the junction is tilted by half the turn
there, and the flat facet, its other end straight, keeps A = 0 (the mean of the slopes would
bulge it into the other body). On a circle of radius R, A = L^2 / (2 R) and the
deviation is the arc's, L^2 / (8 R) at the middle; on a sphere the centroid of an equilateral
triangle gets L^2 / (6 R), the sphere's. This is the edge curve of Nagata's patch (Nagata
2005, doi:10.1016/j.cagd.2004.12.002) projected on the facet normal, the smoothing of the
master surface by its nodal normals of Padmanabhan and Laursen 2001
(doi:10.1016/S0168-874X(01)00054-7). A flat surface has A = 0: the patch tests are untouched.

A node where a facet's normal is more than :data:`FEATURE_ANGLE` from the nodal normal is a
corner (a block's edge, a punch's rim) and keeps its chord's slope: the smoothing rounds the
discretised curve, not the geometry's corners. An open vertex (the end of the surface) has
one facet, the nodal normal is the facet's and its slope 0; on a symmetry plane (a roller)
the mirror image continues the surface, and the normal is the mirrored average, in the plane.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
from petsc4py import PETSc

from contactfx.contact.coupling import blocked_rows

if TYPE_CHECKING:
    from contactfx.contact.coupling import NodeLayout
    from contactfx.contact.pair import Facets, Side

__all__ = [
    "FEATURE_ANGLE",
    "CONFORMING",
    "FLAT",
    "vertex_normals",
    "bulges",
    "deviation",
    "dual_moments",
    "mean_curvature",
    "conforming",
]

#: the angle (degrees) between a facet's normal and a node's normal beyond which the node is a
#: corner of the facet's surface (no smoothing there): 30 degrees, twice the turn of the
#: coarsest curved meshes our scenes make (8 segments per quarter circle: 11.25 degrees)
FEATURE_ANGLE = 30.0


#: ``smoothing = "auto"``: a pair is conforming when its surfaces' mean curvatures (each > 0
#: convex along its own outward normal) cancel to within this fraction of the larger: a fit,
#: a pin in its hole (rings of radii b and b - delta: delta / b); Hertz's convex pairs add up
#: (2), a curved body on a flat one does not reach it (1)
CONFORMING = 0.25

#: a bulge (the smooth surface's deviation from an edge) below this fraction of the edge's
#: length is round-off: the edge is straight (:func:`mean_curvature`)
FLAT = 1e-12


def _edges(d: int) -> list[tuple[int, int]]:
    return [(0, 1)] if d == 2 else [(0, 1), (1, 2), (2, 0)]


def vertex_normals(
    layout: NodeLayout, side: Side, facets: Facets, held: np.ndarray | None = None
) -> np.ndarray:
    """(m, d, gdim) the unit nodal normals at the vertices of this rank's ``facets`` (the
    current configuration of ``side``'s owned facets): the measure-weighted average of the
    facet normals of the whole surface at each node, summed on the nodes' owners and sent
    back to the ranks holding a facet of the node. ``held`` (m, d, gdim): the components a
    Dirichlet condition holds at the vertices (:func:`contactfx.contact.pair.node_held`); a
    node that holds some but not all (a roller on a symmetry plane, where the mirror image
    continues the surface) has the held components of its normal removed where they are
    under sin(:data:`FEATURE_ANGLE`) of it (the surface meets the plane nearly square, as a
    smooth surface meets its plane of symmetry): the mirrored surface's average. Collective."""
    from contactfx.contact.pair import facet_normals

    gdim, d = layout.gdim, facets.x.shape[1]
    if len(facets):
        n = facet_normals(facets.x)
        if d == 2:
            measure = np.linalg.norm(facets.x[:, 1] - facets.x[:, 0], axis=1)
        else:
            e1, e2 = facets.x[:, 1] - facets.x[:, 0], facets.x[:, 2] - facets.x[:, 0]
            measure = 0.5 * np.linalg.norm(np.cross(e1, e2), axis=1)
        contrib = np.repeat((measure[:, None] * n)[:, None, :], d, axis=1)
    else:
        contrib = np.zeros((0, d, gdim))
    vec = layout.vector(gdim)
    rows = blocked_rows(facets.nodes.reshape(-1), gdim).ravel()
    vec.setValues(rows, contrib.reshape(-1), addv=PETSc.InsertMode.ADD_VALUES)
    vec.assemblyBegin()
    vec.assemblyEnd()
    vec.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
    with vec.localForm() as local:
        sums = local.getArray(readonly=True).reshape(-1, gdim)[side.local].copy()
    vec.destroy()
    if held is not None:
        # a roller where the surface meets the plane within FEATURE_ANGLE of square: a
        # symmetry plane (a flat cut driven by a platen, met at a larger angle, is a rim)
        roller = np.any(held, axis=2) & ~np.all(held, axis=2)
        size = np.linalg.norm(sums, axis=2, keepdims=True)
        square = np.abs(sums) <= np.sin(np.radians(FEATURE_ANGLE)) * size
        sums = np.where(roller[:, :, None] & held & square, 0.0, sums)
    norm = np.linalg.norm(sums, axis=2)
    return sums / np.where(norm > 0.0, norm, 1.0)[:, :, None]


def bulges(x: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """(m, edges) the coefficients A_ij of the facets x (m, d, gdim) with the nodal normals
    ``normals`` (m, d, gdim) at their vertices (the module docstring): the deviation along
    the facet normal is sum A_ij lambda_i lambda_j."""
    from contactfx.contact.pair import facet_normals

    m, d, _ = x.shape
    out = np.zeros((m, len(_edges(d))))
    if m == 0:
        return out
    nf = facet_normals(x)
    cos = np.einsum("mdi,mi->md", normals, nf)
    corner = cos < np.cos(np.radians(FEATURE_ANGLE))
    for e, (i, j) in enumerate(_edges(d)):
        edge = x[:, j] - x[:, i]
        length = np.linalg.norm(edge, axis=1)
        t = edge / length[:, None]
        slopes = []
        for v in (i, j):
            s = -np.einsum("mi,mi->m", t, normals[:, v]) / np.where(corner[:, v], 1.0, cos[:, v])
            slopes.append(np.where(corner[:, v], 0.0, s))
        # the smaller of the two ends' curvatures (0 if they bend opposite ways)
        a, b = slopes[0], -slopes[1]
        out[:, e] = length * np.where(a * b > 0.0, np.sign(a) * np.minimum(abs(a), abs(b)), 0.0)
    return out


def deviation(bulge: np.ndarray, lam: np.ndarray) -> np.ndarray:
    """The deviation d = sum A_ij lambda_i lambda_j along the facet normal at barycentric
    coordinates ``lam`` (..., d) of facets with coefficients ``bulge`` (..., edges)
    (broadcast over the leading axes)."""
    d = lam.shape[-1]
    out = np.zeros(lam.shape[:-1])
    for e, (i, j) in enumerate(_edges(d)):
        out = out + bulge[..., e] * lam[..., i] * lam[..., j]
    return out


def dual_moments(x: np.ndarray, bulge: np.ndarray) -> np.ndarray:
    """(m, d) int_F psi_i d over every facet F (vertices x (m, d, gdim)) of its own smooth
    deviation d = sum A_ab lambda_a lambda_b (``bulge`` (m, edges)), psi_i the dual basis of
    the mortar (:mod:`.mortar`). Segments: psi_0 = 2 - 3 xi against xi (1 - xi) gives L / 12
    for either end. Triangles (int lambda_1^a lambda_2^b lambda_3^c = 2 |T| a! b! c! /
    (a + b + c + 2)!): int (4 lambda_i - 1) lambda_a lambda_b is |T| / 20 for i in {a, b} and
    -|T| / 60 otherwise."""
    m, d, _ = x.shape
    if d == 2:
        length = np.linalg.norm(x[:, 1] - x[:, 0], axis=1)
        return np.repeat((length * bulge[:, 0] / 12.0)[:, None], 2, axis=1)
    area = 0.5 * np.linalg.norm(np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]), axis=1)
    out = np.zeros((m, 3))
    for e, (a, b) in enumerate(_edges(3)):
        for i in range(3):
            out[:, i] += bulge[:, e] * area * (1.0 / 20.0 if i in (a, b) else -1.0 / 60.0)
    return out


def mean_curvature(comm: Any, x: np.ndarray, bulge: np.ndarray) -> float:
    """The mean curvature of a surface (this rank's facets x (m, d, gdim) and their bulges,
    all ranks): each edge's 2 A / L^2 (a circle's 1 / R, > 0 convex) weighted by its length.
    A bulge under :data:`FLAT` of its edge is round-off (a flat surface's nodal normals
    computed in another order): it counts as 0, so that a flat surface's curvature is 0 on
    every partition, not +-1e-17 (which :func:`conforming` would read either way).
    Collective."""
    from mpi4py import MPI

    total = weight = 0.0
    for e, (i, j) in enumerate(_edges(x.shape[1]) if len(x) else []):
        length = np.linalg.norm(x[:, j] - x[:, i], axis=1)
        curved = np.where(np.abs(bulge[:, e]) > FLAT * length, bulge[:, e], 0.0)
        total += float(np.sum(2.0 * curved / length))
        weight += float(np.sum(length))
    total, weight = comm.allreduce(total, op=MPI.SUM), comm.allreduce(weight, op=MPI.SUM)
    return total / weight if weight > 0.0 else 0.0


def conforming(kappa_s: float, kappa_m: float) -> bool:
    """Whether two surfaces of mean curvatures ``kappa_s``, ``kappa_m`` conform
    (:data:`CONFORMING`): where the facets' chords, of relative size h kappa, are not small
    against the relative curvature kappa_s + kappa_m that shapes the contact."""
    larger = max(abs(kappa_s), abs(kappa_m))
    return larger > 0.0 and abs(kappa_s + kappa_m) < CONFORMING * larger
