"""Geometric primitives of two-body contact: closest-point projection onto facets, the
candidate choice of a contact search, segment-based (mortar) integration domains and their
quadrature. Pure numpy, no dolfinx and no MPI: every function works on the arrays one rank
holds, and the point-wise ones are vectorised over many points / facets at once.

Conventions
-----------
* A *facet* of a d-dimensional body is a (d-1)-simplex given by its d vertices: a segment
  ``(2, 2)`` in 2D, a triangle ``(3, 3)`` in 3D; arrays of them are ``(m, d, d)`` (facet,
  vertex, coordinate).
* Segment [a, b]: parameter xi in [0, 1], x(xi) = (1 - xi) a + xi b. Its unit normal is
  n = (t_y, -t_x) with t = (b - a) / |b - a|, the tangent turned clockwise by 90 degrees: for
  a boundary run counter-clockwise (the body on the left) n is the *outward* normal.
* Triangle [a, b, c]: barycentric coordinates (l0, l1, l2), x = l0 a + l1 b + l2 c, and
  reference coordinates (l1, l2) on the unit triangle {s, t >= 0, s + t <= 1}. Its unit normal
  is (b - a) x (c - a) / |.|: vertices counter-clockwise seen from outside give the outward
  normal.
* "Inside" means inside up to a dimensionless tolerance ``tol`` on xi or on the barycentric
  coordinates (a point projecting onto a shared vertex or edge is inside both facets).
* Signed gap of a point p against a facet: g = (p - x) . n for any point x of the facet's
  line / plane (the vertex, the projection and the clamped closest point give the same value),
  > 0 on the side n points to.
* Degenerate facets (zero length / area) are not supported: their coordinates are NaN or 0
  and their projection is never inside.

Segmentation
------------
2D (Popp, Gee & Wall 2009, "A finite deformation mortar contact formulation using a
primal-dual active set strategy", IJNME 79:1354-1391, doi:10.1002/nme.2614, section 4): the
master segment's end points are projected onto the slave segment's line along a normal; the
overlap is an interval of the slave parameter xi, and the master parameter eta at its ends.
Here the projection direction is one *constant* vector per pair, so x(xi) -> eta is affine
(both the slave parametrisation and the oblique projection onto the master line are affine):
eta is linear between the two ends, and a Gauss rule on [xi0, xi1] maps to the master exactly.
(Popp et al. project along the nodal averaged normals, which vary along the segment and make
the map non-linear; that variant is not implemented here.)

3D (Puso & Laursen 2004, "A mortar segment-to-segment contact method for large deformation
solid mechanics", CMAME 193:601-629, doi:10.1016/j.cma.2003.10.010; Popp, Gitterle, Gee &
Wall 2010, "A dual mortar approach for 3D finite deformation contact with consistent
linearization", IJNME 83:1428-1465, doi:10.1002/nme.2866, section 5): the master triangle is
projected onto the slave triangle's plane along a normal, clipped against the slave triangle
in 2D coordinates of that plane (Sutherland & Hodgman 1974, doi:10.1145/360767.360802), and
the clip polygon is split into a fan of triangles from its vertex centroid, each integrated
with a triangle rule.

Quadrature
----------
Gauss-Legendre on [0, 1] (weights sum to 1) and symmetric triangle rules of Dunavant
("High degree efficient symmetrical Gaussian quadrature rules for the triangle", IJNME
21:1129-1148, 1985, doi:10.1002/nme.1620210612) up to degree 6 in barycentric coordinates
with weights summing to 1 (the fraction of the area: integral over T = |T| sum_q w_q f(x_q)).
Degree 3 uses the positive 6-point degree-4 rule instead of Dunavant's 4-point rule with its
negative weight; degree 5 is Radon's 7-point rule in closed form; the degree-4 and degree-6
abscissae and weights were refined to 25 digits on the moment equations (residual 1e-41).
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike

__all__ = [
    "transport",
    "FacetProjection",
    "Pick",
    "SegmentOverlaps",
    "SegmentProjection",
    "TriangleOverlap",
    "TriangleOverlaps",
    "clip_polygon",
    "closest_point_facets",
    "closest_point_segments",
    "closest_point_segments_many",
    "closest_point_triangles",
    "facet_normal",
    "gauss_segment",
    "gauss_triangle",
    "pick_closest",
    "plane_basis",
    "polygon_area",
    "project_to_plane",
    "segment_normal",
    "segment_overlap",
    "segment_overlaps",
    "triangle_normal",
    "triangle_overlap",
    "triangle_overlaps",
]

#: default tolerance on the facet coordinates (xi, barycentric) for "inside"
TOL = 1e-10


class SegmentProjection(NamedTuple):
    """Projection of n points onto n segments.

    xi: (n,) parameter of the *unclamped* orthogonal projection (may lie outside [0, 1]);
    inside: (n,) bool, xi in [-tol, 1 + tol]; closest: (n, d) closest point of the segment
    (projection clamped to [0, 1]); distance: (n,) |p - closest|."""

    xi: np.ndarray
    inside: np.ndarray
    closest: np.ndarray
    distance: np.ndarray


class FacetProjection(NamedTuple):
    """Projection of n points onto n facets (segments or triangles).

    bary: (n, d) barycentric coordinates of the *unclamped* orthogonal projection onto the
    facet's line / plane (for a segment (1 - xi, xi)); inside: (n,) bool, all of them >= -tol;
    closest: (n, d) the true closest point of the facet; distance: (n,) |p - closest|."""

    bary: np.ndarray
    inside: np.ndarray
    closest: np.ndarray
    distance: np.ndarray


class Pick(NamedTuple):
    """The facet chosen for each of n points among its candidates.

    index: (n,) int facet index, -1 for none; inside: (n,) bool, the chosen facet's projection
    is inside it; bary: (n, d) barycentric coordinates of the unclamped projection onto the
    chosen facet; closest: (n, d) closest point of it; gap: (n,) signed distance (p - x) . n
    along its unit normal; distance: (n,) |p - closest|. Rows with index -1 hold NaN."""

    # the field shadows tuple.index, which typeshed's tuple declares as a method (a field
    # name the checker rejects for a NamedTuple; renaming it would change the public API)
    index: np.ndarray  # type: ignore[assignment]
    inside: np.ndarray
    bary: np.ndarray
    closest: np.ndarray
    gap: np.ndarray
    distance: np.ndarray


class SegmentOverlaps(NamedTuple):
    """Overlaps of n (slave, master) segment pairs.

    valid: (n,) bool, the overlap has positive length; xi: (n, 2) its ends xi0 < xi1 as slave
    parameters in [0, 1]; eta: (n, 2) the master parameters at those ends (decreasing when the
    master runs against the slave). Invalid rows hold NaN."""

    valid: np.ndarray
    xi: np.ndarray
    eta: np.ndarray


class TriangleOverlap(NamedTuple):
    """Overlap of a slave triangle with the projection of a master triangle.

    polygon: (p, 3) vertices of the clip polygon, in the slave plane, counter-clockwise seen
    from the slave normal; area: its area; triangles: (p, 3, 3) the fan (centroid, v_i,
    v_{i+1}), oriented like the polygon; slave_bary, master_bary: (p, 3, 3) barycentric
    coordinates of the fan triangles' vertices in the slave triangle and of their projections
    (along the normal) in the master triangle. Both maps are affine, so a quadrature point with
    barycentric coordinates lam in fan triangle q has lam @ slave_bary[q] and
    lam @ master_bary[q]."""

    polygon: np.ndarray
    area: float
    triangles: np.ndarray
    slave_bary: np.ndarray
    master_bary: np.ndarray


def _dot(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    return np.einsum("...i,...i->...", u, v)


def _cross2(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    return u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]


def _div(num: np.ndarray, den: np.ndarray, fill: float = np.nan) -> np.ndarray:
    """num / den, ``fill`` where den == 0 (no warning)."""
    num, den = np.broadcast_arrays(np.asarray(num, float), np.asarray(den, float))
    out = np.full(num.shape, fill)
    np.divide(num, den, out=out, where=den != 0)
    return out


def _unit(v: np.ndarray) -> np.ndarray:
    return _div(v, np.linalg.norm(v, axis=-1, keepdims=True))


# --- normals -------------------------------------------------------------------------------


def segment_normal(a: ArrayLike, b: ArrayLike) -> np.ndarray:
    """Unit normal (t_y, -t_x) of the oriented 2D segments [a, b], t = (b - a) / |b - a|.

    a, b: (..., 2). Returns (..., 2). The tangent turned clockwise: outward for a boundary run
    counter-clockwise."""
    t = _unit(np.asarray(b, float) - np.asarray(a, float))
    return np.stack([t[..., 1], -t[..., 0]], axis=-1)


def triangle_normal(tri: ArrayLike) -> np.ndarray:
    """Unit normal (b - a) x (c - a) / |.| of the triangles tri = (..., 3, 3) (vertex,
    coordinate). Returns (..., 3)."""
    tri = np.asarray(tri, float)
    return _unit(np.cross(tri[..., 1, :] - tri[..., 0, :], tri[..., 2, :] - tri[..., 0, :]))


def facet_normal(facets: ArrayLike) -> np.ndarray:
    """Unit normal of facets (..., d, d): :func:`segment_normal` for d = 2,
    :func:`triangle_normal` for d = 3. Returns (..., d)."""
    facets = np.asarray(facets, float)
    d = facets.shape[-1]
    if facets.shape[-2:] == (2, 2):
        return segment_normal(facets[..., 0, :], facets[..., 1, :])
    if facets.shape[-2:] == (3, 3):
        return triangle_normal(facets)
    raise ValueError(f"facets must be (..., d, d) with d = 2 or 3, got {facets.shape} (d={d})")


# --- closest points ------------------------------------------------------------------------


def closest_point_segments(
    points: ArrayLike, a: ArrayLike, b: ArrayLike, tol: float = TOL
) -> SegmentProjection:
    """For each i the closest point to points[i] on the segment [a[i], b[i]].

    points, a, b: (n, d), d = 2 or 3 (broadcasting allowed). xi = (p - a) . (b - a) / |b - a|^2
    is the parameter of the orthogonal projection onto the line (0 for a zero-length segment);
    the closest point is at xi clamped to [0, 1]."""
    p, a, b = (np.asarray(x, float) for x in (points, a, b))
    e = b - a
    xi = _div(_dot(p - a, e), _dot(e, e), fill=0.0)
    inside = (xi >= -tol) & (xi <= 1.0 + tol)
    xc = np.clip(xi, 0.0, 1.0)[..., None]
    closest = (1.0 - xc) * a + xc * b
    return SegmentProjection(xi, inside, closest, np.linalg.norm(p - closest, axis=-1))


def _plane_bary(p: np.ndarray, tri: np.ndarray) -> np.ndarray:
    """Barycentric coordinates (n, 3) of the orthogonal projection of p onto tri's plane, from
    the 2x2 normal equations (exact 0 / 1 at the vertices). NaN for degenerate triangles."""
    e1, e2, w = tri[..., 1, :] - tri[..., 0, :], tri[..., 2, :] - tri[..., 0, :], p - tri[..., 0, :]
    g11, g12, g22 = _dot(e1, e1), _dot(e1, e2), _dot(e2, e2)
    r1, r2 = _dot(w, e1), _dot(w, e2)
    det = g11 * g22 - g12 * g12
    s = _div(g22 * r1 - g12 * r2, det)
    t = _div(g11 * r2 - g12 * r1, det)
    return np.stack([1.0 - s - t, s, t], axis=-1)


def closest_point_triangles(points: ArrayLike, tri: ArrayLike, tol: float = TOL) -> FacetProjection:
    """For each i the closest point to points[i] on the triangle tri[i].

    points: (n, 3); tri: (n, 3, 3) (triangle, vertex, coordinate). bary are the barycentric
    coordinates of the orthogonal projection onto the triangle's plane, ``inside`` when all are
    >= -tol. The closest point is the true one also outside (the Voronoi-region method of
    Ericson, Real-Time Collision Detection, 2005, section 5.1.5, doi:10.1201/b14581): a vertex,
    the orthogonal projection onto an edge, or the projection onto the plane."""
    p, tri = np.asarray(points, float), np.asarray(tri, float)
    A, B, C = tri[..., 0, :], tri[..., 1, :], tri[..., 2, :]
    ab, ac = B - A, C - A
    d1, d2 = _dot(ab, p - A), _dot(ac, p - A)
    d3, d4 = _dot(ab, p - B), _dot(ac, p - B)
    d5, d6 = _dot(ab, p - C), _dot(ac, p - C)
    va, vb, vc = d3 * d6 - d5 * d4, d5 * d2 - d1 * d6, d1 * d4 - d3 * d2
    bary = _plane_bary(p, tri)

    # Ericson's early returns in order; np.select takes the first region that holds
    v_ab = _div(d1, d1 - d3, 0.0)
    w_ac = _div(d2, d2 - d6, 0.0)
    w_bc = _div(d4 - d3, (d4 - d3) + (d5 - d6), 0.0)
    one, zero = np.ones_like(d1), np.zeros_like(d1)
    regions = [
        (d1 <= 0) & (d2 <= 0),  # vertex A
        (d3 >= 0) & (d4 <= d3),  # vertex B
        (vc <= 0) & (d1 >= 0) & (d3 <= 0),  # edge AB
        (d6 >= 0) & (d5 <= d6),  # vertex C
        (vb <= 0) & (d2 >= 0) & (d6 <= 0),  # edge AC
        (va <= 0) & (d4 - d3 >= 0) & (d5 - d6 >= 0),  # edge BC
    ]
    choices = [
        (one, zero, zero),
        (zero, one, zero),
        (1.0 - v_ab, v_ab, zero),
        (zero, zero, one),
        (1.0 - w_ac, zero, w_ac),
        (zero, 1.0 - w_bc, w_bc),
    ]
    lam = np.stack(
        [np.select(regions, [c[j] for c in choices], default=bary[..., j]) for j in range(3)],
        axis=-1,
    )
    closest = np.einsum("...j,...jk->...k", lam, tri)
    inside = np.all(bary >= -tol, axis=-1)  # False for NaN (degenerate)
    return FacetProjection(bary, inside, closest, np.linalg.norm(p - closest, axis=-1))


def closest_point_facets(points: ArrayLike, facets: ArrayLike, tol: float = TOL) -> FacetProjection:
    """Closest points of n points on n facets: points (n, d), facets (n, d, d) (segments for
    d = 2, triangles for d = 3). Segments return bary = (1 - xi, xi)."""
    p, facets = np.asarray(points, float), np.asarray(facets, float)
    d = p.shape[-1]
    if facets.shape[-2:] != (d, d) or d not in (2, 3):
        raise ValueError(
            f"points (n, d) and facets (n, d, d), d = 2 or 3: {p.shape}, {facets.shape}"
        )
    if d == 3:
        return closest_point_triangles(p, facets, tol)
    r = closest_point_segments(p, facets[..., 0, :], facets[..., 1, :], tol)
    return FacetProjection(np.stack([1.0 - r.xi, r.xi], axis=-1), r.inside, r.closest, r.distance)


def _candidates(candidates: ArrayLike | None, n: int, m: int) -> np.ndarray:
    if candidates is None:
        return np.broadcast_to(np.arange(m, dtype=np.int64), (n, m))
    cand = np.asarray(candidates, dtype=np.int64).reshape(n, -1)
    if np.any(cand >= m) or np.any(cand < -1):
        raise ValueError(f"candidate indices must be in [-1, {m})")
    return cand


def _pick(
    p: np.ndarray,
    cand: np.ndarray,
    project: Callable[[np.ndarray, np.ndarray], FacetProjection],
    fallback: bool,
    key: np.ndarray | None = None,
) -> Pick:
    """The choice of :func:`pick_closest`; project(points, facet indices) -> FacetProjection.
    gap is left NaN. With ``key`` ((m,) per facet), distances equal to round-off are a tie
    that the lowest key breaks."""
    n, d = p.shape
    k = cand.shape[1]
    rows, cols = np.nonzero(cand >= 0)
    proj = project(p[rows], cand[rows, cols])

    dist = np.full((n, k), np.inf)
    inside = np.zeros((n, k), dtype=bool)
    dist[rows, cols], inside[rows, cols] = proj.distance, proj.inside
    slot = np.full((n, k), -1)
    slot[rows, cols] = np.arange(rows.size)

    def best(d: np.ndarray) -> np.ndarray:
        if key is None or not k:
            return np.argmin(d, axis=1) if k else np.zeros(n, np.int64)
        least = np.min(d, axis=1, keepdims=True)
        finite = np.where(np.isfinite(least), least, 0.0)
        # a tie: within round-off of the least distance (relative to the point's size too)
        scale = np.abs(p).max(axis=1, keepdims=True) + finite
        tied = d <= least + 1e-12 * scale
        keys = np.where(tied & (cand >= 0), key[np.maximum(cand, 0)], np.iinfo(np.int64).max)
        return np.argmin(keys, axis=1)

    col = best(np.where(inside, dist, np.inf))
    found = np.any(inside, axis=1)
    if fallback and k:
        col = np.where(found, col, best(dist))
        found = np.any(cand >= 0, axis=1)

    r = np.nonzero(found)[0]
    s = slot[r, col[r]]
    index = np.full(n, -1, dtype=np.int64)
    index[r] = cand[r, col[r]]
    chosen_inside = np.zeros(n, dtype=bool)
    chosen_inside[r] = proj.inside[s]
    bary = np.full((n, proj.bary.shape[-1]), np.nan)
    closest = np.full((n, d), np.nan)
    distance = np.full(n, np.nan)
    bary[r], closest[r], distance[r] = proj.bary[s], proj.closest[s], proj.distance[s]
    return Pick(index, chosen_inside, bary, closest, np.full(n, np.nan), distance)


def pick_closest(
    points: ArrayLike,
    candidates: ArrayLike | None,
    facets: ArrayLike,
    tol: float = TOL,
    fallback: bool = False,
    key: ArrayLike | None = None,
) -> Pick:
    """Choose for each point the facet it projects onto, among its candidates.

    points: (n, d); facets: (m, d, d), d = 2 (segments) or 3 (triangles); candidates: (n, k)
    int indices into facets, padded with -1 (e.g. the hits of a bounding-box tree), or None
    for all m facets (an (n, m) search). Among the candidates whose orthogonal projection is
    inside (up to ``tol``), the one at the least distance wins (ties: the first in the
    candidate order, or with ``key`` ((m,) int per facet) the lowest key among the distances
    equal to round-off: a choice that does not depend on the order the facets came in, e.g.
    the partition of the mesh). With none inside, index is -1 - or, with ``fallback``, the
    candidate at the least true distance (its ``inside`` False; e.g. a point off a convex
    corner of the master surface, equally far from the facets that share the corner). Rows
    without any candidate are always -1. gap is signed along :func:`facet_normal` of the chosen
    facet."""
    p, f = np.asarray(points, float), np.asarray(facets, float)
    cand = _candidates(candidates, p.shape[0], f.shape[0])
    key = None if key is None else np.asarray(key, dtype=np.int64)
    pick = _pick(p, cand, lambda q, j: closest_point_facets(q, f[j], tol), fallback, key)
    r = np.nonzero(pick.index >= 0)[0]
    pick.gap[r] = _dot(p[r] - pick.closest[r], facet_normal(f[pick.index[r]]))
    return pick


def closest_point_segments_many(
    points: ArrayLike,
    a: ArrayLike,
    b: ArrayLike,
    candidates: ArrayLike | None = None,
    tol: float = TOL,
    fallback: bool = False,
) -> Pick:
    """The best of m segments [a[j], b[j]] ((m, d) each, d = 2 or 3) for each of n points
    ((n, d)), among ``candidates`` ((n, k) int, -1 padded) or all of them: the choice of
    :func:`pick_closest`. xi of the chosen segment is ``bary[:, 1]``; gap is signed along
    :func:`segment_normal` in 2D and NaN in 3D (a segment in space has no normal)."""
    p, a0, b0 = (np.asarray(x, float) for x in (points, a, b))
    cand = _candidates(candidates, p.shape[0], a0.shape[0])

    def project(q: np.ndarray, j: np.ndarray) -> FacetProjection:
        r = closest_point_segments(q, a0[j], b0[j], tol)
        return FacetProjection(np.stack([1 - r.xi, r.xi], axis=-1), r.inside, r.closest, r.distance)

    pick = _pick(p, cand, project, fallback)
    if p.shape[-1] == 2:
        r = np.nonzero(pick.index >= 0)[0]
        normal = segment_normal(a0[pick.index[r]], b0[pick.index[r]])
        pick.gap[r] = _dot(p[r] - pick.closest[r], normal)
    return pick


# --- 2D segmentation -----------------------------------------------------------------------


def segment_overlaps(
    slave: ArrayLike, master: ArrayLike, normal: ArrayLike | None = None, tol: float = 1e-12
) -> SegmentOverlaps:
    """Overlaps of n (slave, master) segment pairs in 2D, master projected along ``normal``.

    slave, master: (n, 2, 2) (pair, end point, coordinate); normal: (n, 2) or (2,), one
    constant projection direction per pair, by default the slave normal
    (:func:`segment_normal`). Master end point m goes to the slave parameter
    xi = cross(m - s0, n) / cross(s1 - s0, n) (the point s0 + xi (s1 - s0) = m + alpha n), the
    overlap is [max(0, min xi), min(1, max xi)] and counts when longer than ``tol`` (in xi): a
    single touching point is no overlap. eta(xi) = cross(x(xi) - m0, n) / cross(m1 - m0, n) is
    affine in xi, as both numerator and denominator are (the latter constant)."""
    slave, master = np.asarray(slave, float), np.asarray(master, float)
    s0, s1, m0, m1 = slave[..., 0, :], slave[..., 1, :], master[..., 0, :], master[..., 1, :]
    n = segment_normal(s0, s1) if normal is None else np.asarray(normal, float)
    n = np.broadcast_to(n, s0.shape)
    den = _cross2(s1 - s0, n)
    xa, xb = _div(_cross2(m0 - s0, n), den), _div(_cross2(m1 - s0, n), den)
    lo = np.maximum(0.0, np.minimum(xa, xb))
    hi = np.minimum(1.0, np.maximum(xa, xb))
    mden = _cross2(m1 - m0, n)
    valid = (hi - lo > tol) & (mden != 0)
    xi = np.where(valid[..., None], np.stack([lo, hi], axis=-1), np.nan)
    x = s0[..., None, :] + xi[..., None] * (s1 - s0)[..., None, :]  # (n, 2 ends, 2)
    eta = _div(_cross2(x - m0[..., None, :], n[..., None, :]), mden[..., None])
    return SegmentOverlaps(valid, xi, eta)


def segment_overlap(
    slave: ArrayLike, master: ArrayLike, normal: ArrayLike | None = None, tol: float = 1e-12
) -> tuple[np.ndarray, np.ndarray] | None:
    """Overlap of one slave segment (2, 2) with the projection of one master segment (2, 2)
    along ``normal`` (2,) (default: the slave normal): (xi (2,), eta (2,)), the slave
    interval [xi0, xi1] within [0, 1] and the master parameters at its ends, or None when the
    overlap is shorter than ``tol`` (disjoint or touching). See :func:`segment_overlaps`."""
    r = segment_overlaps(
        np.asarray(slave, float)[None],
        np.asarray(master, float)[None],
        None if normal is None else np.asarray(normal, float)[None],
        tol,
    )
    return (r.xi[0], r.eta[0]) if r.valid[0] else None


# --- 3D clipping ---------------------------------------------------------------------------


def polygon_area(poly: ArrayLike) -> np.ndarray | float:
    """Signed area (shoelace) of polygons (..., k, 2): > 0 for counter-clockwise vertices;
    0 for k < 3."""
    poly = np.asarray(poly, float)
    x, y = poly[..., 0], poly[..., 1]
    area = 0.5 * np.sum(x * np.roll(y, -1, axis=-1) - np.roll(x, -1, axis=-1) * y, axis=-1)
    return float(area) if np.ndim(area) == 0 else area


def _ccw(poly: np.ndarray) -> np.ndarray:
    return poly[::-1] if polygon_area(poly) < 0 else poly


def clip_polygon(subject: ArrayLike, clip: ArrayLike, tol: float = 1e-12) -> np.ndarray:
    """Sutherland-Hodgman: the part of polygon ``subject`` (k, 2) inside the *convex* polygon
    ``clip`` (m, 2). Both are reoriented counter-clockwise if given clockwise; the result is
    counter-clockwise, (p, 2), or (0, 2) when the overlap has no area.

    Vertices are kept by the exact sign of their distance to each clip edge (>= 0 inside), so
    the edge intersections lie between their end points; afterwards consecutive vertices closer
    than tol * L (L the larger extent of the two polygons) are merged and an area below
    tol * L^2 counts as empty (touching polygons)."""
    subject, clip = np.asarray(subject, float), np.asarray(clip, float)
    empty = np.zeros((0, 2))
    if subject.shape[0] < 3 or clip.shape[0] < 3:
        return empty
    both = np.concatenate([subject, clip])
    scale = float(np.max(np.ptp(both, axis=0))) or 1.0
    out = _ccw(subject)
    clip = _ccw(clip)
    m = clip.shape[0]
    for i in range(m):
        if out.shape[0] == 0:
            return empty
        c0, c1 = clip[i], clip[(i + 1) % m]
        dist = _cross2(c1 - c0, out - c0)  # > 0 left of the edge, i.e. inside
        nxt, dnext = np.roll(out, -1, axis=0), np.roll(dist, -1)
        kept = []
        for j in range(out.shape[0]):
            if dist[j] >= 0:
                kept.append(out[j])
            if (dist[j] >= 0) != (dnext[j] >= 0):
                t = dist[j] / (dist[j] - dnext[j])  # in [0, 1]: the signs differ
                kept.append(out[j] + t * (nxt[j] - out[j]))
        out = np.array(kept).reshape(-1, 2)
    # merge coincident neighbours (a vertex on a clip edge is kept and re-created)
    merged: list[np.ndarray] = []
    for v in out:
        if not merged or np.linalg.norm(v - merged[-1]) > tol * scale:
            merged.append(v)
    while len(merged) > 1 and np.linalg.norm(merged[0] - merged[-1]) <= tol * scale:
        merged.pop()
    out = np.array(merged).reshape(-1, 2)
    if out.shape[0] < 3 or polygon_area(out) <= tol * scale**2:
        return empty
    return out


def plane_basis(normal: ArrayLike) -> np.ndarray:
    """Orthonormal basis (2, 3), rows t1, t2, of the plane orthogonal to ``normal`` (3,), with
    t1 x t2 = normal / |normal|: counter-clockwise seen from the normal's side stays
    counter-clockwise in the 2D coordinates. t1 is the coordinate axis least aligned with the
    normal, made orthogonal to it (deterministic, well conditioned)."""
    n = np.asarray(normal, float)
    n = n / np.linalg.norm(n)
    axis = np.zeros(3)
    axis[np.argmin(np.abs(n))] = 1.0
    t1 = axis - np.dot(axis, n) * n
    t1 /= np.linalg.norm(t1)
    return np.stack([t1, np.cross(n, t1)])


def project_to_plane(points: ArrayLike, origin: ArrayLike, normal: ArrayLike) -> np.ndarray:
    """2D coordinates (k, 2) of the orthogonal projections of ``points`` (k, 3) onto the plane
    through ``origin`` (3,) orthogonal to ``normal`` (3,), in the basis of
    :func:`plane_basis`; back to 3D: origin + xy @ plane_basis(normal)."""
    return (np.asarray(points, float) - np.asarray(origin, float)) @ plane_basis(normal).T


def triangle_overlap(
    slave_tri: ArrayLike,
    master_tri: ArrayLike,
    normal: ArrayLike | None = None,
    tol: float = 1e-12,
) -> TriangleOverlap | None:
    """The overlap of a slave triangle (3, 3) with a master triangle (3, 3) projected onto the
    slave's plane along ``normal`` (3,) (default: the slave normal, :func:`triangle_normal`):
    clip polygon, its fan triangulation and the slave / master coordinates of the fan's
    vertices (:class:`TriangleOverlap`), or None without overlap (area below tol * L^2, see
    :func:`clip_polygon`, or a normal parallel to either plane)."""
    slave, master = np.asarray(slave_tri, float), np.asarray(master_tri, float)
    ns, nm = triangle_normal(slave), triangle_normal(master)
    v = ns if normal is None else np.asarray(normal, float)
    den_s, den_m = float(np.dot(v, ns)), float(np.dot(v, nm))
    if den_s == 0.0 or den_m == 0.0 or not np.isfinite(den_s * den_m):
        return None
    origin = slave[0]
    projected = master - np.outer((master - origin) @ ns / den_s, v)
    basis = plane_basis(ns)
    poly = clip_polygon((projected - origin) @ basis.T, (slave - origin) @ basis.T, tol)
    if poly.shape[0] == 0:
        return None
    centre = poly.mean(axis=0)
    fan2 = np.stack([np.broadcast_to(centre, poly.shape), poly, np.roll(poly, -1, axis=0)], 1)
    polygon = origin + poly @ basis
    triangles = origin + fan2 @ basis  # (p, 3, 3)
    slave_bary = _plane_bary(triangles, slave)
    # the master point x + beta v on the master plane: (x + beta v - m0) . nm = 0
    beta = (master[0] - triangles) @ nm / den_m
    master_bary = _plane_bary(triangles + beta[..., None] * v, master)
    return TriangleOverlap(polygon, float(polygon_area(poly)), triangles, slave_bary, master_bary)


class TriangleOverlaps(NamedTuple):
    """Overlaps of n (slave, master) triangle pairs, vectorised. A clip polygon has at most 6
    vertices (a triangle clipped by three half-planes; more only with repeated vertices on an
    edge, of zero-area fan triangles), its fan as many triangles, padded to f >= 6.

    valid: (n,) bool, the overlap area exceeds the tolerance. The other arrays hold the valid
    pairs only, in order (v = valid.sum() rows, those of ``np.flatnonzero(valid)``): area (v,)
    overlap areas; fan_area (v, f) areas of the fan triangles (centroid, v_i, v_{i+1}), 0 for
    padding; slave_bary, master_bary (v, f, 3, 3) barycentric coordinates of the fan
    triangles' vertices in the slave triangle and of their projections in the master triangle
    (as in :class:`TriangleOverlap`)."""

    valid: np.ndarray
    area: np.ndarray
    fan_area: np.ndarray
    slave_bary: np.ndarray
    master_bary: np.ndarray


def _bary2(p: np.ndarray, tri: np.ndarray) -> np.ndarray:
    """Barycentric coordinates (n, ..., 3) of 2D points p (n, ..., 2) in triangles tri
    (n, 3, 2) of either orientation (NaN for degenerate ones)."""
    e1, e2 = tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
    det = _cross2(e1, e2)
    shape = (-1,) + (1,) * (p.ndim - 2)
    w = p - tri[:, 0].reshape(shape + (2,))
    s = _div(_cross2(w, e2.reshape(shape + (2,))), det.reshape(shape))
    t = _div(_cross2(e1.reshape(shape + (2,)), w), det.reshape(shape))
    return np.stack([1.0 - s - t, s, t], axis=-1)


def _clip_halfplanes(
    poly: np.ndarray, count: np.ndarray, clip: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Sutherland-Hodgman on n convex polygons at once: poly (n, k, 2) padded, count (n,) the
    vertex numbers, clipped by the n counter-clockwise triangles clip (n, 3, 2). Returns the
    clipped (n, k', 2) and the counts (0 for an empty result). A vertex is kept by the exact
    sign of its distance to an edge (>= 0 inside), as in :func:`clip_polygon`."""
    n = poly.shape[0]
    rows = np.arange(n)[:, None]
    for e in range(3):
        c0, c1 = clip[:, e][:, None, :], clip[:, (e + 1) % 3][:, None, :]
        k = poly.shape[1]
        idx = np.arange(k)[None, :]
        live = idx < count[:, None]
        dist = _cross2(c1 - c0, poly - c0)  # (n, k), > 0 inside
        nxt = np.where(idx + 1 < count[:, None], idx + 1, 0)
        pnext, dnext = poly[rows, nxt], dist[rows, nxt]
        keep = live & (dist >= 0)
        cut = live & ((dist >= 0) != (dnext >= 0))
        t = _div(dist, dist - dnext, 0.0)[..., None]
        cross_point = poly + t * (pnext - poly)
        n_out = keep.astype(np.int64) + cut
        start = np.cumsum(n_out, axis=1) - n_out
        count = n_out.sum(axis=1)
        out = np.zeros((n, max(int(count.max(initial=0)), 1), 2))
        r, c = np.nonzero(keep)
        out[r, start[r, c]] = poly[r, c]
        r, c = np.nonzero(cut)
        out[r, start[r, c] + keep[r, c]] = cross_point[r, c]
        poly = out
    return poly, count


def _dot3(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Dot product over a last axis of length 3 (faster than einsum on many short rows)."""
    return u[..., 0] * v[..., 0] + u[..., 1] * v[..., 1] + u[..., 2] * v[..., 2]


def _separated(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(n,) bool: the 2D triangles a, b (n, 3, 2) are separated (or only touch) along one of
    their six edge normals (separating axis theorem for convex polygons)."""
    out = np.zeros(a.shape[0], dtype=bool)
    for tri in (a, b):
        for e in range(3):
            edge = tri[:, (e + 1) % 3] - tri[:, e]
            pa = [a[:, v, 1] * edge[:, 0] - a[:, v, 0] * edge[:, 1] for v in range(3)]
            pb = [b[:, v, 1] * edge[:, 0] - b[:, v, 0] * edge[:, 1] for v in range(3)]
            lo_a, hi_a = (
                np.minimum(np.minimum(*pa[:2]), pa[2]),
                np.maximum(np.maximum(*pa[:2]), pa[2]),
            )
            lo_b, hi_b = (
                np.minimum(np.minimum(*pb[:2]), pb[2]),
                np.maximum(np.maximum(*pb[:2]), pb[2]),
            )
            out |= (hi_a <= lo_b) | (hi_b <= lo_a)
    return out


def triangle_overlaps(
    slave: ArrayLike, master: ArrayLike, normal: ArrayLike | None = None, tol: float = 1e-12
) -> TriangleOverlaps:
    """The overlaps of n (slave, master) triangle pairs ((n, 3, 3) each), the master projected
    onto the slave's plane along ``normal`` ((n, 3) or (3,), default: the slave normals): the
    vectorised :func:`triangle_overlap`, with the same clip polygons and the same fan
    (centroid of the clip polygon's vertices; coinciding vertices, which
    :func:`clip_polygon` merges, only add fan triangles of zero area).

    In 2D coordinates of each slave plane (orthonormal, counter-clockwise seen from the slave
    normal) the pairs that an edge normal separates (most candidates of a box search) are
    dropped first; in the others the slave triangle is clipped by the projected master
    triangle (reoriented counter-clockwise). Both maps from the plane to the facets'
    barycentric coordinates are affine, so they are evaluated at the fan's vertices. A pair is
    ``valid`` when its area exceeds tol * L^2 (L the larger extent of the two triangles in the
    plane) and the normal is not parallel to either plane."""
    slave, master = np.asarray(slave, float), np.asarray(master, float)
    ns_all = ns = triangle_normal(slave)
    nm = triangle_normal(master)
    v = ns if normal is None else np.broadcast_to(np.asarray(normal, float), ns.shape)
    den_s, den_m = _dot3(v, ns), _dot3(v, nm)
    ok = (den_s != 0.0) & (den_m != 0.0) & np.isfinite(den_s * den_m)
    # cheap exclusion first: the projection along v onto the slave plane stretches lengths by
    # at most |v| / |v . ns|, so the projected master lies in the disc of radius r_m times
    # that around its projected centroid (r: the largest centroid-vertex distance)
    cs, cm = slave.mean(axis=1), master.mean(axis=1)
    rs = np.sqrt(np.max([_dot3(slave[:, j] - cs, slave[:, j] - cs) for j in range(3)], axis=0))
    rm = np.sqrt(np.max([_dot3(master[:, j] - cm, master[:, j] - cm) for j in range(3)], axis=0))
    stretch = np.sqrt(_dot3(v, v)) / np.abs(np.where(ok, den_s, 1.0))
    pc = cm - _div(_dot3(cm - cs, ns), np.where(ok, den_s, 1.0), 0.0)[:, None] * v
    d = pc - cs
    ok &= _dot3(d, d) < (rs + rm * stretch) ** 2
    keep = np.flatnonzero(ok)
    slave, master, ns, nm, v = slave[keep], master[keep], ns[keep], nm[keep], v[keep]
    den_s, ok = den_s[keep], ok[keep]
    origin = slave[:, None, 0]
    t1 = _unit(slave[:, 1] - slave[:, 0])[:, None]
    t2 = np.cross(ns[:, None], t1)  # t1 x t2 = ns
    alpha = _div(_dot3(master - origin, ns[:, None]), den_s[:, None], 0.0)
    projected = master - alpha[..., None] * v[:, None]
    s2 = np.stack([_dot3(slave - origin, t1), _dot3(slave - origin, t2)], axis=-1)
    m2 = np.stack([_dot3(projected - origin, t1), _dot3(projected - origin, t2)], axis=-1)
    sel = np.flatnonzero(ok & ~_separated(s2, m2))
    s2, m2 = s2[sel], m2[sel]
    n = len(sel)
    # the clip triangle counter-clockwise (facing surfaces project clockwise)
    clip = m2.copy()
    cw = _cross2(m2[:, 1] - m2[:, 0], m2[:, 2] - m2[:, 0]) < 0
    clip[cw, 1], clip[cw, 2] = m2[cw, 2], m2[cw, 1]
    poly, count = _clip_halfplanes(s2, np.full(n, 3), clip)
    k = poly.shape[1]
    idx = np.arange(k)[None, :]
    live = idx < count[:, None]
    centre = np.sum(np.where(live[..., None], poly, 0.0), axis=1) / np.maximum(count, 1)[:, None]
    nxt = np.where(idx + 1 < count[:, None], idx + 1, 0)
    pnext = poly[np.arange(n)[:, None], nxt]
    fan = np.stack([np.broadcast_to(centre[:, None], poly.shape), poly, pnext], axis=2)
    fan_area = np.where(live, 0.5 * _cross2(poly - centre[:, None], pnext - centre[:, None]), 0.0)
    area = fan_area.sum(axis=1)
    both = np.concatenate([s2, m2], axis=1)
    scale = np.max(both.max(axis=1) - both.min(axis=1), axis=1)
    good = (count >= 3) & (area > tol * scale**2)
    valid = np.zeros(len(ns_all), dtype=bool)
    valid[keep[sel[good]]] = True
    fan, fan_area = fan[good], fan_area[good]
    if k < 6:
        fan_area = np.pad(fan_area, ((0, 0), (0, 6 - k)))
        fan = np.pad(fan, ((0, 0), (0, 6 - k), (0, 0), (0, 0)))
    return TriangleOverlaps(
        valid, area[good], fan_area, _bary2(fan, s2[good]), _bary2(fan, m2[good])
    )


# --- quadrature ----------------------------------------------------------------------------


def transport(a: np.ndarray, b: np.ndarray, v: np.ndarray) -> np.ndarray:
    """v (P, gdim) rotated by the rotation about a x b taking the unit vectors a to b (the
    least rotation; analytic, so that complex steps pass through): in 2D by the angle from a to
    b, in 3D R = I + [w]x + [w]x^2 / (1 + a . b), w = a x b. a = 0 (no history): v in 3D, 0 in
    2D (v is 0 there)."""
    c = np.einsum("pg,pg->p", a, b)
    if v.shape[1] == 2:
        w = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
        return c[:, None] * v + w[:, None] * np.stack([-v[:, 1], v[:, 0]], axis=1)
    w = np.cross(a, b)
    wv = np.cross(w, v)
    return v + wv + np.cross(w, wv) / (1.0 + c)[:, None]


def gauss_segment(n: int) -> tuple[np.ndarray, np.ndarray]:
    """n-point Gauss-Legendre rule on [0, 1]: points (n,), weights (n,) summing to 1, exact
    for polynomials of degree 2n - 1. The integral over [x0, x1] is (x1 - x0) sum w f(x)."""
    if n < 1:
        raise ValueError(f"gauss_segment needs n >= 1, got {n}")
    x, w = _leggauss(n)
    return 0.5 * (x + 1.0), 0.5 * w


@functools.lru_cache(maxsize=16)
def _leggauss(n: int) -> tuple[np.ndarray, np.ndarray]:
    """numpy's Gauss-Legendre rule on [-1, 1], computed once per n (the mortar integrals ask
    for it at every search)."""
    x, w = np.polynomial.legendre.leggauss(n)
    x.flags.writeable = False
    w.flags.writeable = False
    return x, w


def _s21(a: float) -> list[tuple[float, float, float]]:
    return [(a, a, 1 - 2 * a), (a, 1 - 2 * a, a), (1 - 2 * a, a, a)]


def _s111(a: float, b: float) -> list[tuple[float, float, float]]:
    c = 1 - a - b
    return [(a, b, c), (a, c, b), (b, a, c), (b, c, a), (c, a, b), (c, b, a)]


_R15 = np.sqrt(15.0)
#: degree -> orbits (barycentric points, weight); Dunavant (1985), weights sum to 1
_TRIANGLE_RULES: dict[int, list[tuple[list[tuple[float, float, float]], float]]] = {
    1: [([(1 / 3, 1 / 3, 1 / 3)], 1.0)],
    2: [(_s21(1 / 6), 1 / 3)],
    4: [
        (_s21(0.4459484909159648863183293), 0.223381589678011465695007),
        (_s21(0.09157621350977074345957146), 0.1099517436553218676383263),
    ],
    5: [  # Radon's 7-point rule in closed form
        ([(1 / 3, 1 / 3, 1 / 3)], 9 / 40),
        (_s21((6 - _R15) / 21), (155 - _R15) / 1200),
        (_s21((6 + _R15) / 21), (155 + _R15) / 1200),
    ],
    6: [
        (_s21(0.2492867451709104212916386), 0.1167862757263793660252896),
        (_s21(0.0630890144915022283403316), 0.05084490637020681692093681),
        (
            _s111(0.05314504984481694735324967, 0.3103524510337844054166077),
            0.08285107561837357519355346,
        ),
    ],
}
_TRIANGLE_RULES[3] = _TRIANGLE_RULES[4]  # positive weights (Dunavant's degree 3 has -27/48)


def gauss_triangle(degree: int) -> tuple[np.ndarray, np.ndarray]:
    """Symmetric rule on a triangle exact for polynomials of ``degree`` (0 to 6): points
    (q, 3) in barycentric coordinates (reference coordinates: points[:, 1:]), weights (q,)
    summing to 1, all positive: the integral over T is |T| sum_q w_q f(points[q] @ T). Point
    counts 1, 1, 3, 6, 6, 7, 12 for degree 0 to 6."""
    if not 0 <= degree <= 6:
        raise ValueError(f"gauss_triangle has degree 0 to 6, got {degree}")
    orbits = _TRIANGLE_RULES[max(degree, 1)]
    points = np.array([p for pts, _ in orbits for p in pts])
    weights = np.array([w for pts, w in orbits for _ in pts])
    return points, weights
