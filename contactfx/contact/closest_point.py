"""The closest-point projection of the slave Gauss points of a two-body pair onto the master
surface (:mod:`contactfx.contact.point_coupling`): the candidate facets of each point, the
pick of the closest, whether a point off every facet is beyond the master surface's rim, and
the finite-strain hysteresis that keeps a point's facet.

Points whose projection falls off the master surface are not in contact: no candidate facet
within the search radius, or the closest point of the master surface on its boundary. A
point that projects inside no master facet is decided by the feature of the surface its
closest point lies on: on an edge (3D) it is in contact if two master facets share that edge
(an interior ridge), not on a boundary edge (one facet); at a vertex, if the vertex is
interior to the surface (2D: shared by two segments, a convex kink; the end of the curve is
not). Every vertex of a triangulated surface is shared by several triangles, also on its
boundary, so the vertex alone cannot tell a point at a kink from one beyond the surface's
edge. The boundary edges and vertices are those of the whole master surface, found once by
global node numbers (:func:`contactfx.contact.pair.surface_rim`): the master facets a rank
gathers near its slave points may lack a facet's neighbours, and 1 and 2 ranks pair the
same points. In 3D an edge of one master facet on a symmetry plane is interior, not a
boundary (:func:`contactfx.contact.pair.mirror_edges`: both its nodes hold the displacement
component normal to a plane they lie on, and not every component): the mirror image
continues the surface there, and a point past it, as near a curved master's symmetry plane
where the facets' normals tilt, is in contact (docs/verification.md section 10). No
tolerance beyond the 1e-10 of "inside": slave Gauss points lie inside their facets, so where
flat slave and master surfaces end on the same plane (the edges of equal faces) the points
project inside the master facets; the finite-strain hysteresis below keeps a point's facet
past its edge, boundary or not. A point paired off its facet carries its force to the
facet's vertex of the largest barycentric coordinate.

Finite strain keeps each point's master facet of the last search while the point stays on it
or within 0.1 of its size past its edge (:func:`keep_facets`): the facet
normal jumps at a kink of the master surface, and a point whose equilibrium lies at the kink
would make Newton cycle between the two facets.
"""

from __future__ import annotations

import numpy as np

from contactfx.contact.boxes import FacetTree
from contactfx.contact.pair import Facets, facet_order, facet_rim
from contactfx.contact.projection import TOL, Pick, closest_point_facets, pick_closest

__all__ = ["KEEP_BEYOND", "candidates", "on_rim", "project", "keep_facets"]


#: how far past its edge (a fraction of its size) a point keeps its facet within a Newton
#: solve (:func:`keep_facets`)
KEEP_BEYOND = 0.1


def candidates(xq: np.ndarray, near: Facets, padding: np.ndarray) -> np.ndarray:
    """(n, width) the facets of ``near`` whose bounding box padded by ``padding`` (per facet)
    holds each point of ``xq`` (-1: none)."""
    tree = FacetTree(near.x, padding)
    rows, facets = tree.collide_points(xq)
    counts = np.bincount(rows, minlength=len(xq))
    width = max(int(counts.max(initial=0)), 1)
    cand = -np.ones((len(xq), width), dtype=np.int64)
    order = np.argsort(rows, kind="stable")
    rows, facets = rows[order], facets[order]
    slot = np.arange(len(rows)) - np.repeat(np.cumsum(counts) - counts, counts)
    cand[rows, slot] = facets
    return cand


def on_rim(closest: np.ndarray, index: np.ndarray, near: Facets) -> np.ndarray:
    """(n,) bool: the closest points ``closest`` (n, gdim) on the master facets ``index`` (n,)
    of ``near`` lie on the boundary of the master surface (a point beyond it, not in
    contact): on an open edge of the facet (3D, the edge's barycentric coordinate within TOL
    of 0) or at an open vertex (its coordinate within TOL of 1; 2D: the end of the curve).
    The rim is that of the whole surface (:func:`contactfx.contact.pair.surface_rim`), or,
    for facets built without it, of the ``near`` facets alone."""
    if near.open_vertex is None or near.open_edge is None:
        open_vertex, open_edge = facet_rim(near.nodes)
    else:
        open_vertex, open_edge = near.open_vertex, near.open_edge
    # barycentric coordinates of the closest point (exact 0 and 1 at a vertex)
    lam = closest_point_facets(closest, near.x[index]).bary
    on_edge = (lam <= TOL) & open_edge[index]
    at_vertex = (lam >= 1.0 - TOL) & open_vertex[index]
    return np.any(on_edge | at_vertex, axis=1)


def project(xq: np.ndarray, near: Facets, kept: np.ndarray | None = None) -> Pick:
    """The master facet of each point (index -1: not in contact). ``kept``: (n, d)
    the sorted global nodes of each point's facet at the last search (-1: none), kept
    while the point projects inside it (:func:`keep_facets`)."""

    n, d = xq.shape
    if n == 0 or len(near) == 0:  # nothing to project, or nothing near: no contact
        nan = np.full((n, d), np.nan)
        return Pick(
            -np.ones(n, dtype=np.int64),
            np.zeros(n, dtype=bool),
            nan,
            nan,
            np.full(n, np.nan),
            np.full(n, np.nan),
        )
    cand = candidates(xq, near, near.diameters())
    # ties (a point equally far from facets sharing an edge or a vertex, to round-off) go
    # to the facet first in the order of the reference coordinates: the same choice on
    # every partition (the candidates' order and the global numbers depend on it)
    key = None if near.X is None else facet_order(near.X)
    pick = pick_closest(xq, cand, near.x, fallback=True, key=key)
    off = (pick.index >= 0) & ~pick.inside
    if np.any(off):
        # a point whose closest candidate is off its facet: its candidates are the facets
        # within their own size, so the closest facet (a small one on the surface's rim)
        # can be missing; the facets within the largest size decide (the same pick
        # wherever the closest facet was a candidate)
        wide = candidates(xq[off], near, np.full(len(near), near.diameters().max()))
        again = pick_closest(xq[off], wide, near.x, fallback=True, key=key)
        for field, value in zip(pick, again, strict=True):
            field[off] = value
    if kept is not None:
        keep_facets(xq, near, pick, kept)
    off = (pick.index >= 0) & ~pick.inside
    if np.any(off):
        # the closest point on an edge or at a vertex of the master surface: in contact
        # unless that is on the surface's boundary (:func:`on_rim`)
        beyond = on_rim(pick.closest[off], pick.index[off], near)
        vertex = np.argmax(np.nan_to_num(pick.bary[off], nan=-1.0), axis=1)
        bary = np.zeros_like(pick.bary[off])
        bary[np.arange(len(vertex)), vertex] = 1.0
        pick.bary[off] = bary
        pick.index[np.flatnonzero(off)[beyond]] = -1
    return pick


def keep_facets(xq: np.ndarray, near: Facets, pick: Pick, kept: np.ndarray) -> None:
    """Keep each point's facet of the last search (``kept``, its sorted global nodes)
    while the point's projection stays on it or beyond its edge by at most KEEP_BEYOND
    of it, and it is no farther than the closest facet plus 1e-2 of its size: a
    hysteresis of the node-to-segment projection. The facet normal jumps at a kink of
    the master surface (Wriggers 2006, doi:10.1007/978-3-540-32609-0, section 9.1, on
    this non-smoothness), and a point whose equilibrium lies at the kink makes Newton
    cycle between the two facets with a residual that does not fall below the jump
    (seen at the leading edge of a block dragged with friction over a foundation: a 2-cycle
    at 0.16 with the point moving 0.008 h). Keeping the facet, the residual is smooth
    and the point converges on the extended facet, at most KEEP_BEYOND h past the
    vertex (a gap error of that times the kink's angle). Edits pick."""
    has = np.flatnonzero(kept[:, 0] >= 0)
    if len(has) == 0:
        return
    facets = np.sort(near.nodes, axis=1)
    both = np.concatenate([facets, kept[has]])
    _, inverse = np.unique(both, axis=0, return_inverse=True)
    inverse = inverse.reshape(-1)
    first = np.full(inverse.max() + 1, -1, dtype=np.int64)
    first[inverse[: len(facets)][::-1]] = np.arange(len(facets))[::-1]
    j = first[inverse[len(facets) :]]
    has, j = has[j >= 0], j[j >= 0]  # the last facet among the near ones
    if len(has) == 0:
        return
    old = pick_closest(xq[has], j[:, None], near.x, fallback=True)
    size = near.diameters()[j]
    best = np.where(pick.index[has] >= 0, pick.distance[has], np.inf)
    within = np.min(np.nan_to_num(old.bary, nan=-np.inf), axis=1) >= -KEEP_BEYOND
    keep = (old.index >= 0) & within & (old.distance <= best + 1e-2 * size)
    rows = has[keep]
    for field, value in zip(pick, old, strict=True):
        field[rows] = value[keep]
    # on the facet's line / plane (extended by at most KEEP_BEYOND of it): the law and
    # its Jacobian take the unclamped projection
    pick.inside[rows] = True
