"""The mortar integrals of P1 facets (segments in 2D, triangles in 3D) over the overlaps of
slave facets with the projections of master facets onto them, with the dual basis of the slave
surface (the formulas are in :mod:`.mortar`'s docstring; Wohlmuth 2000,
doi:10.1137/S0036142999350929; Puso & Laursen 2004, doi:10.1016/j.cma.2003.10.010; Popp et
al. 2010, doi:10.1002/nme.2866). The per-pair kernels (:func:`segment_pair_integrals`,
:func:`triangle_pair_integrals`) are shared with the consistent tangent
(:mod:`.mortar_tangent`), which differentiates them."""

from __future__ import annotations

from typing import TypeAlias

import numpy as np

from contactfx.contact.pair import Facets, facet_normals
from contactfx.contact.projection import (
    TriangleOverlaps,
    gauss_segment,
    gauss_triangle,
    segment_overlaps,
    triangle_overlaps,
)
from contactfx.contact.smoothing import deviation

__all__ = [
    "mortar_matrices",
    "dual_triangle",
    "nodal_weights",
    "segment_pair_integrals",
    "triangle_pair_integrals",
]

#: the local mortar integrals (:func:`mortar_matrices`): D contributions, weighted normals,
#: the triplets (slave node, master node, value) of M and the smooth master's deviation
#: contributions
_Integrals: TypeAlias = tuple[
    np.ndarray, np.ndarray, tuple[np.ndarray, np.ndarray, np.ndarray], np.ndarray
]


def _dual(xi: np.ndarray) -> np.ndarray:
    """(n, 2) dual shape functions psi_0 = 2 - 3 xi, psi_1 = 3 xi - 1 on a segment."""
    return np.stack([2.0 - 3.0 * xi, 3.0 * xi - 1.0], axis=-1)


def _linear(xi: np.ndarray) -> np.ndarray:
    return np.stack([1.0 - xi, xi], axis=-1)


def dual_triangle(lam: np.ndarray) -> np.ndarray:
    """Dual shape functions psi_i = 4 N_i - 1 on a triangle, of barycentric coordinates
    (..., 3): int_T psi_i N_k = 4 |T| (1 + delta_ik) / 12 - |T| / 3 = delta_ik |T| / 3."""
    return 4.0 * lam - 1.0


def nodal_weights(x: np.ndarray) -> np.ndarray:
    """(m, d) int_F N_j over every P1 facet F of the vertices x (m, d, gdim): half its length
    (segments), a third of its area (triangles)."""
    if x.shape[1] == 2:
        return np.repeat(0.5 * np.linalg.norm(x[:, 1] - x[:, 0], axis=1)[:, None], 2, axis=1)
    area = 0.5 * np.linalg.norm(np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]), axis=1)
    return np.repeat(area[:, None] / 3.0, 3, axis=1)


def segment_pair_integrals(
    xs: np.ndarray, xm: np.ndarray, order: int = 2
) -> tuple[np.ndarray, list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]]]:
    """The mortar integrand of n (slave, master) segment pairs ((n, 2, 2) each), the master
    projected along the slave normal: ``valid`` (n,) (the projections overlap) and per Gauss
    point of the overlaps of the valid pairs (weight, slave parameter, master parameter,
    weight psi_j(xi) N_k(eta) (n_valid, 2, 2)): summed over the points, the pairs' M_jk."""
    ns = facet_normals(xs)
    length = np.linalg.norm(xs[:, 1] - xs[:, 0], axis=1)
    ov = segment_overlaps(xs, xm, ns)
    xi, eta = ov.xi[ov.valid], ov.eta[ov.valid]
    length = length[ov.valid]
    points = []
    for gq, wq in zip(*gauss_segment(order), strict=True):
        xq = xi[:, 0] + gq * (xi[:, 1] - xi[:, 0])
        eq = eta[:, 0] + gq * (eta[:, 1] - eta[:, 0])
        weight = wq * length * (xi[:, 1] - xi[:, 0])
        contrib = weight[:, None, None] * _dual(xq)[:, :, None] * _linear(eq)[:, None, :]
        points.append((weight, xq, eq, contrib))
    return ov.valid, points


def triangle_pair_integrals(xs: np.ndarray, xm: np.ndarray) -> tuple[TriangleOverlaps, np.ndarray]:
    """The overlaps of n (slave, master) triangle pairs ((n, 3, 3) each), the master projected
    onto the slave plane along the slave normal, and the valid pairs' M_jk (n_valid, 3, 3):
    int psi_j N_k over the clip polygon's fan triangles with the 3-point degree-2 rule (both
    maps affine there, psi_j N_k quadratic: exact)."""
    ov = triangle_overlaps(xs, xm, facet_normals(xs))
    fan_area, sb, mb = ov.fan_area, ov.slave_bary, ov.master_bary
    points, weights = gauss_triangle(2)
    vals = np.zeros((len(fan_area), 3, 3))
    for lq, wq in zip(points, weights, strict=True):
        # slave and master coordinates of the point in every fan triangle (pair, fan, 3)
        ls = lq[0] * sb[:, :, 0] + lq[1] * sb[:, :, 1] + lq[2] * sb[:, :, 2]
        lm = lq[0] * mb[:, :, 0] + lq[1] * mb[:, :, 1] + lq[2] * mb[:, :, 2]
        psi = (wq * fan_area)[:, :, None] * dual_triangle(ls)
        vals += np.matmul(psi.transpose(0, 2, 1), lm)
    return ov, vals


def mortar_matrices(
    slave: Facets, master: Facets, pairs: tuple[np.ndarray, np.ndarray], order: int = 2
) -> _Integrals:
    """The local mortar integrals of P1 facets (segments in 2D, triangles in 3D, from
    ``slave.x.shape[1]``): D contributions (m_s, d) per slave facet node (int N_j),
    measure-weighted normal contributions (m_s, d, gdim), and the triplets (slave node, master
    node, value) of M over the candidate ``pairs`` (slave facet indices, master facet indices)
    whose normals face each other and whose projections overlap, and, per slave facet node
    (m_s, d), int psi_j d_m: the master's smooth surface's deviation d_m from its facets
    (``master.bulge``, :mod:`.smoothing`; zeros without) weighted by the dual basis.
    ``order``: Gauss points per overlap segment in 2D (psi_j d_m is cubic: exact from 2);
    the 3D fan triangles use the degree-2 rule (psi_j N_k is quadratic on a fan triangle,
    where both are affine), degree 3 for psi_j d_m."""
    if slave.x.shape[1] == 3:
        return _mortar_triangles(slave, master, pairs)
    xs, xm = slave.x, master.x
    ns = facet_normals(xs)
    D = nodal_weights(xs)
    normals = D[:, :, None] * ns[:, None, :]
    i, k = pairs
    facing = np.einsum("ij,ij->i", ns[i], facet_normals(xm[k])) < 0.0
    i, k = i[facing], k[facing]
    valid, points = segment_pair_integrals(xs[i], xm[k], order)
    i, k = i[valid], k[valid]
    rows, cols, vals = [], [], []
    corr = np.zeros(D.shape)
    for weight, xq, eq, contrib in points:
        rows.append(np.repeat(slave.nodes[i][:, :, None], 2, axis=2))
        cols.append(np.repeat(master.nodes[k][:, None, :], 2, axis=1))
        vals.append(contrib)
        if master.bulge is not None:
            dm = deviation(master.bulge[k], _linear(eq))
            np.add.at(corr, i, (weight * dm)[:, None] * _dual(xq))
    flat = [
        np.concatenate([a.reshape(-1) for a in arr]) if arr else np.zeros(0)
        for arr in (rows, cols, vals)
    ]
    return D, normals, (flat[0].astype(np.int64), flat[1].astype(np.int64), flat[2]), corr


def _mortar_triangles(
    slave: Facets, master: Facets, pairs: tuple[np.ndarray, np.ndarray]
) -> _Integrals:
    """:func:`mortar_matrices` of P1 triangles: each facing candidate pair's overlap, the
    master projected onto the slave plane along the slave normal
    (:func:`.projection.triangle_overlaps`), integrated over its fan triangles with the
    3-point degree-2 rule (exact for psi_j N_k); D_j = |T| / 3 per vertex, area-weighted
    normals."""
    xs, xm = slave.x, master.x
    ns = facet_normals(xs)
    D = nodal_weights(xs)
    normals = D[:, :, None] * ns[:, None, :]
    i, k = pairs
    nm = facet_normals(xm) if len(xm) else np.zeros((0, 3))
    # per facet once: centroid and radius (largest centroid-vertex distance); a master whose
    # centroid projects onto the slave plane farther than r_s + r_m from the slave's centroid
    # cannot overlap it (the orthogonal projection does not stretch): most candidates of the
    # box search go here, before any per-pair array is built
    cs, cm = xs.mean(axis=1), xm.mean(axis=1)
    rs = np.linalg.norm(xs - cs[:, None], axis=2).max(axis=1)
    rm = np.linalg.norm(xm - cm[:, None], axis=2).max(axis=1) if len(xm) else np.zeros(0)
    d = cm[k] - cs[i]
    nsi = ns[i]
    d_n = np.sum(d * nsi, axis=1)
    lateral2 = np.sum(d * d, axis=1) - d_n**2
    near = (np.sum(nsi * nm[k], axis=1) < 0.0) & (lateral2 < (rs[i] + rm[k]) ** 2)
    i, k = i[near], k[near]
    ov, vals = triangle_pair_integrals(xs[i], xm[k])
    i, k = i[ov.valid], k[ov.valid]
    fan_area, sb, mb = ov.fan_area, ov.slave_bary, ov.master_bary
    corr = np.zeros(D.shape)
    if master.bulge is not None:
        points, weights = gauss_triangle(3)
        for lq, wq in zip(points, weights, strict=True):
            ls = lq[0] * sb[:, :, 0] + lq[1] * sb[:, :, 1] + lq[2] * sb[:, :, 2]
            lm = lq[0] * mb[:, :, 0] + lq[1] * mb[:, :, 1] + lq[2] * mb[:, :, 2]
            dm = deviation(master.bulge[k][:, None, :], lm)
            psi = (wq * fan_area * dm)[:, :, None] * dual_triangle(ls)
            np.add.at(corr, i, psi.sum(axis=1))
    rows = np.repeat(slave.nodes[i][:, :, None], 3, axis=2)
    cols = np.repeat(master.nodes[k][:, None, :], 3, axis=1)
    return (
        D,
        normals,
        (rows.reshape(-1).astype(np.int64), cols.reshape(-1).astype(np.int64), vals.reshape(-1)),
        corr,
    )
