"""Candidate pairs of a contact search: the axis-aligned bounding boxes of surface facets
(segments in 2D, triangles in 3D), and which boxes hold given points or meet other boxes.

Every search of a contact pair (each Newton iteration of a large-sliding run) asks this for
the few master facets near each slave facet or point. The boxes are grouped by size (each
group's largest half-width at most twice its smallest, so a graded mesh's small facets are not
compared with its coarse ones' radius) and each group's box centres go into a k-d tree
(``scipy.spatial.cKDTree``, Maneewongvatana and Mount 1999, "Analysis of approximate nearest
neighbor searching with clustered point sets", arXiv:cs/9901013): two boxes can meet only if
their centres are closer, in the max norm, than the sum of the groups' largest half-widths,
and every such candidate is then tested exactly.

The tests are dolfinx's (``dolfinx.geometry``: a box's bounds widened by 1e-14 of its extent
in each coordinate), so the pairs are the ones a dolfinx bounding-box tree of the facets gives;
they are returned sorted (by point or facet of the other set, then by facet of this one), an
order that does not depend on how the boxes were stored. Building a dolfinx tree needs a
dolfinx mesh of the facets, which cost 1.7 ms a search on one core, a quarter of the shallow
ironing's run time (docs/verification.md, section 15).
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

__all__ = ["FacetTree"]

#: a box's bounds are widened by this fraction of its extent in each coordinate (dolfinx's
#: ``point_in_bbox`` and ``bbox_in_bbox``)
RTOL = 1e-14


class _Group:
    """Boxes of similar size: their indices, a k-d tree of their centres, the largest
    half-width."""

    def __init__(self, index: np.ndarray, centres: np.ndarray, half: float) -> None:
        self.index = index
        self.tree = cKDTree(centres)
        self.half = half


class FacetTree:
    """The bounding boxes of facets given by their vertex coordinates ``(m, d, gdim)``, each
    enlarged by ``padding`` (the search radius): a number, or one per facet (m,).

    ``collide_points(points)`` and ``collide(other)`` give the candidate pairs (point, or
    facet of ``other``; facet of this tree) as two index arrays in the callers' numbering.
    """

    def __init__(self, coords: np.ndarray, padding: float | np.ndarray) -> None:
        coords = np.asarray(coords, dtype=np.float64)
        m = coords.shape[0]
        self.size = m
        pad = np.asarray(padding, dtype=np.float64)
        pad = pad[:, None] if pad.ndim == 1 else pad
        if m == 0:
            gdim = coords.shape[-1] if coords.ndim == 3 else 0
            self.lo = self.hi = np.zeros((0, gdim))
        else:
            self.lo = coords.min(axis=1) - pad
            self.hi = coords.max(axis=1) + pad
        self._groups: list[_Group] | None = None

    def groups(self) -> list[_Group]:
        """The boxes grouped by half-width (built at the first query)."""
        if self._groups is None:
            half = 0.5 * (self.hi - self.lo).max(axis=1, initial=0.0)
            centres = 0.5 * (self.lo + self.hi)
            order = np.argsort(half, kind="stable")
            sorted_half = half[order]
            self._groups = []
            start = 0
            while start < self.size:
                stop = int(np.searchsorted(sorted_half, 2.0 * sorted_half[start], side="right"))
                stop = max(stop, start + 1)
                index = order[start:stop]
                self._groups.append(_Group(index, centres[index], float(sorted_half[stop - 1])))
                start = stop
        return self._groups

    def _slack(self, *others: np.ndarray) -> float:
        """An absolute margin for the rounding of the centres and the max-norm distances."""
        scale = max([float(np.abs(a).max(initial=0.0)) for a in (self.lo, self.hi, *others)])
        return 1e-12 * scale + 1e-300

    def collide_points(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(point, facet) pairs: the facets whose box holds each point of ``points`` (n, gdim),
        sorted by point, then facet."""
        points = np.asarray(points, dtype=np.float64)
        n = len(points)
        if self.size == 0 or n == 0:
            return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
        gdim = self.lo.shape[1]
        points = points[:, :gdim]
        slack = self._slack(points)
        cloud = cKDTree(points)
        rows, facets = [], []
        for group in self.groups():
            near = group.tree.sparse_distance_matrix(
                cloud, group.half * (1.0 + 1e-10) + slack, p=np.inf, output_type="ndarray"
            )
            facet = group.index[near["i"]]
            row = near["j"].astype(np.int64)
            lo, hi = self.lo[facet], self.hi[facet]
            eps = RTOL * (hi - lo)
            x = points[row]
            inside = np.all((x >= lo - eps) & (x <= hi + eps), axis=1)
            rows.append(row[inside])
            facets.append(facet[inside])
        return _sorted(np.concatenate(rows), np.concatenate(facets))

    def collide(self, other: FacetTree) -> tuple[np.ndarray, np.ndarray]:
        """(facet of ``other``, facet of this tree) pairs whose boxes meet, sorted by the
        first, then the second."""
        if self.size == 0 or other.size == 0:
            return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
        slack = self._slack(other.lo, other.hi)
        firsts, seconds = [], []
        for a in other.groups():
            for b in self.groups():
                near = a.tree.sparse_distance_matrix(
                    b.tree,
                    (a.half + b.half) * (1.0 + 1e-10) + slack,
                    p=np.inf,
                    output_type="ndarray",
                )
                first, second = a.index[near["i"]], b.index[near["j"]]
                lo, hi = self.lo[second], self.hi[second]
                eps = RTOL * (hi - lo)
                meet = np.all((other.hi[first] >= lo - eps) & (other.lo[first] <= hi + eps), axis=1)
                firsts.append(first[meet])
                seconds.append(second[meet])
        return _sorted(np.concatenate(firsts), np.concatenate(seconds))


def _sorted(first: np.ndarray, second: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    order = np.lexsort((second, first))
    return first[order].astype(np.int64), second[order].astype(np.int64)
