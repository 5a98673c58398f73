"""The consistent tangent of the dual mortar in the deformed configuration: the variation of the
mortar integrals D_j, M_jk and of the nodal normals n_j with the displacement (Popp, Gee and
Wall 2009, doi:10.1002/nme.2614, for the finite-deformation dual mortar; Popp et al. 2010,
doi:10.1002/nme.2866, in 3D).

At finite strain the mortar coupling (:mod:`.mortar`) searches and integrates again at every
residual, so its condensed residual F(u) = Phi(gamma(u), u) depends on the displacement both
directly (the bulk's residual R(u), the positions x = X + u: what :meth:`MortarCoupling.jacobian
<contactfx.contact.mortar.MortarCoupling.jacobian>` differentiates, the geometry held) and
through the geometry gamma of each slave node j:

    gamma_j = (D_j, N_j, S_j, Mx_j, Mdu_j),   S_j = sum_k M_jk,
    Mx_j = sum_k M_jk x_k,   Mdu_j = sum_k M_jk du_k,

N_j the sum of the measure-weighted facet normals (n_j = N_j / |N_j|) and du the step's
displacement (friction). This module adds the second part, dPhi/dgamma dgamma/du:

- dgamma/du from the facets: D and N per slave facet, M per (slave facet, master facet) pair,
  each differentiated with respect to its vertices by central differences of the integrals of
  :mod:`.mortar_integrals` (step 1e-6 of the slave facet's diameter: truncation O(1e-12) and
  round-off O(1e-10) relative; the overlap's clipping is piecewise smooth in the vertices,
  and a pair whose overlap starts or ends within the step is differenced across the kink);
- dPhi/dgamma at each contact node by complex steps (Squire and Trapp 1998,
  doi:10.1137/S003614459631241X) of the node's rows (:func:`nodal_rows`: the complementarity
  row, the tangent rows and the node's share phi_j of its master rows,
  R_k + sum_j M_jk phi_j), with the semi-smooth branches (active, stick) of the residual.

The master rows then take sum_j (dM_jk phi_j + M_jk dphi_j). The smoothing's correction of the
gap (:mod:`.smoothing`) and an interference fit's hidden overlap are held (their variations
are of the order of the curvature change of the surfaces over a Newton step).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from contactfx.contact.coupling import blocked_rows
from contactfx.contact.mortar_integrals import (
    nodal_weights,
    segment_pair_integrals,
    triangle_pair_integrals,
)
from contactfx.contact.pair import facet_normals
from contactfx.contact.projection import transport

if TYPE_CHECKING:
    from contactfx.contact.pair import Facets

__all__ = ["frames", "Geometry", "NodeState", "nodal_rows", "geometry_derivatives"]

#: central-difference step of the facet integrals, relative to the slave facet's diameter
STEP = 1e-6
#: complex step of the nodal rows, relative to each input's size (at least 1)
COMPLEX_STEP = 1e-30


def _norm(v: np.ndarray) -> np.ndarray:
    """|v| along the last axis, analytic (complex steps pass through); the same bits as
    np.linalg.norm for real v."""
    return np.sqrt(np.sum(v * v, axis=-1))


def frames(
    n: np.ndarray, free: np.ndarray, comp: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Nodal frames restricted to the free (not Dirichlet) components.

    n: (m, gdim) unit normals, free: (m, gdim) bool. Returns n_F = the normals' free part,
    comp = the free component of largest |n_F| (the row of the complementarity; given, for
    complex n), and tangents (m, gdim, gdim): for every free component c != comp the unit
    vector of the free subspace orthogonal to n_F and to the tangents of the lower components
    (Gram-Schmidt of e_c; e_c and n_F span the free subspace because n_F is largest at comp),
    zero rows elsewhere. Without fixed components these are tangent planes' orthonormal
    bases."""
    m, gdim = n.shape
    n_free = np.where(free, n, 0.0)
    if comp is None:
        comp = np.argmax(np.abs(n_free), axis=1)
    norm = _norm(n_free)
    basis = [n_free / np.where(norm.real > 0, norm, 1.0)[:, None]]
    tangents = np.zeros((m, gdim, gdim), dtype=n.dtype)
    for c in range(gdim):
        use = free[:, c] & (comp != c)
        v = np.zeros((m, gdim), dtype=n.dtype)
        v[:, c] = 1.0
        for b in basis:
            v -= np.sum(v * b, axis=1)[:, None] * b
        length = _norm(v)
        v = np.where(use[:, None], v / np.where(length.real > 0, length, 1.0)[:, None], 0.0)
        tangents[:, c] = v
        basis.append(v)
    return n_free, comp, tangents


@dataclass
class Geometry:
    """What a search integrated: this rank's slave facets, the near master facets and the
    candidate pairs (slave facet, near master facet)."""

    slave: Facets
    master: Facets
    pairs: tuple[np.ndarray, np.ndarray]


@dataclass
class NodeState:
    """The contact nodes' data that :func:`nodal_rows` holds fixed: R (m, gdim) the bulk's
    residual at the node, x (m, gdim) its position, du (m, gdim) its displacement since the
    last converged step, ``shift`` (m,) the gap's held part (the smoothing's correction minus
    an interference fit's hidden overlap), ``free`` (m, gdim) and ``comp`` (m,) the frame
    (:func:`frames`), ``active`` (m,) the complementarity's branch (``ncp`` min) and, with
    friction (``mu``), ``stick`` and ``bound`` (lambda - c g > 0) and the frame-indifferent
    slip's history (``has``, ``b_old``, ``n_old``: nodes closed at the last step)."""

    R: np.ndarray
    x: np.ndarray
    du: np.ndarray
    shift: np.ndarray
    free: np.ndarray
    comp: np.ndarray
    tmask: np.ndarray
    active: np.ndarray
    c0: float
    ncp: str
    E: float
    mu: float | None = None
    stick: np.ndarray | None = None
    bound: np.ndarray | None = None
    objective: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None


def nodal_rows(gamma: np.ndarray, s: NodeState) -> tuple[np.ndarray, np.ndarray]:
    """The contact nodes' rows (m, gdim) (the complementarity row at ``comp``, the tangent
    rows, 0 at fixed components) and phi (m, gdim), their share of the master rows
    (R_k + sum_j M_jk phi_j), from gamma (m, 2 + 3 gdim) = (D, N, S, Mx, Mdu) and the held
    data ``s``: the residual of :class:`~contactfx.contact.mortar.MortarCoupling` written for
    one node. Analytic in gamma for fixed branches (complex steps pass through)."""
    m, gdim = s.x.shape
    D, N, S = gamma[:, 0], gamma[:, 1 : 1 + gdim], gamma[:, 1 + gdim]
    Mx, Mdu = gamma[:, 2 + gdim : 2 + 2 * gdim], gamma[:, 2 + 2 * gdim :]
    n = N / _norm(N)[:, None]
    n_free, comp, t = frames(n, s.free, s.comp)
    lam = -np.sum(n_free * s.R, axis=1) / (D * np.sum(n_free**2, axis=1))
    gap = np.sum(n * (Mx / S[:, None] - s.x), axis=1) - s.shift
    c = s.c0 / D ** (1.0 / max(gdim - 1, 1))
    cg = c * gap
    if s.ncp == "min":
        C = np.where(s.active, cg, lam)
    else:
        C = lam + cg - np.sqrt(lam**2 + cg**2 + (1e-12 * s.E) ** 2)
    rows = np.zeros((m, gdim), dtype=gamma.dtype)
    tR = np.einsum("jci,ji->jc", t, s.R)
    if s.mu is None:
        rows = np.where(s.tmask, tR, rows)
        phi = -(D * lam / S)[:, None] * n
    else:
        assert s.stick is not None and s.bound is not None
        lt = np.where(s.tmask, -tR / D[:, None], 0.0)
        v = np.einsum("jci,ji->jc", t, s.du - Mdu / S[:, None])
        if s.objective is not None:
            has, b_old, n_old = s.objective
            change = transport(n_old, n[has], b_old) - b_old
            v[has] += np.einsum("jci,ji->jc", t[has], change)
        v = np.where(s.tmask, v, 0.0)
        z = lt + c[:, None] * v
        xi = s.mu * np.where(s.bound, lam - cg, 0.0)
        nz = _norm(z)
        safe = np.where(nz.real > 0.0, nz, 1.0)
        proj = np.where(s.stick[:, None], z, (xi / safe)[:, None] * z)
        rows = np.where(s.tmask, D[:, None] * (lt - proj), rows)
        phi = -(D / S)[:, None] * (lam[:, None] * n + np.einsum("jc,jci->ji", lt, t))
    rows[np.arange(m), comp] = D * C
    return rows, phi


def nodal_partials(gamma: np.ndarray, s: NodeState) -> np.ndarray:
    """(m, 2 gdim, 2 + 3 gdim): d(rows, phi) / d gamma at the contact nodes by complex steps
    (exact to round-off: no difference is taken)."""
    m, q = gamma.shape
    gdim = s.x.shape[1]
    out = np.zeros((m, 2 * gdim, q))
    scale = np.maximum(np.abs(gamma), 1.0)
    for a in range(q):
        h = COMPLEX_STEP * scale[:, a]
        z = gamma.astype(complex)
        z[:, a] += 1j * h
        rows, phi = nodal_rows(z, s)
        out[:, :, a] = np.concatenate([rows.imag, phi.imag], axis=1) / h[:, None]
    return out


def _central(fn: Callable[[np.ndarray], np.ndarray], x: np.ndarray, step: np.ndarray) -> np.ndarray:
    """d fn / d x (n, ..., p, gdim) by central differences of fn (n, ...) at x (n, p, gdim),
    the step (n,) per row."""
    n, p, gdim = x.shape
    out: np.ndarray | None = None
    for a in range(p):
        for c in range(gdim):
            plus, minus = x.copy(), x.copy()
            plus[:, a, c] += step
            minus[:, a, c] -= step
            d = fn(plus) - fn(minus)
            d = d / (2.0 * step).reshape((-1,) + (1,) * (d.ndim - 1))
            if out is None:
                out = np.zeros(d.shape + (p, gdim))
            out[..., a, c] = d
    assert out is not None
    return out


def pair_values(xs: np.ndarray, xm: np.ndarray) -> np.ndarray:
    """(n, d, d) M_jk of n (slave, master) facet pairs, 0 for a pair without overlap."""
    n, d, _ = xs.shape
    out = np.zeros((n, d, d))
    if d == 2:
        valid, points = segment_pair_integrals(xs, xm)
        out[valid] = sum(p[3] for p in points)
    else:
        ov, vals = triangle_pair_integrals(xs, xm)
        out[ov.valid] = vals
    return out


def _facet_values(x: np.ndarray) -> np.ndarray:
    """(m, d, 1 + gdim) per slave facet node: int N_j and int N_j n (:func:`nodal_weights`)."""
    D = nodal_weights(x)
    return np.concatenate([D[:, :, None], D[:, :, None] * facet_normals(x)[:, None, :]], axis=2)


def geometry_derivatives(
    geo: Geometry, bs: int
) -> tuple[
    tuple[np.ndarray, np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]
]:
    """This rank's facets' contributions to the slave nodes' geometry and its derivatives:

    - records (node j, column, values (2 + 3 gdim)): column -1 for gamma_j's value
      contributions, a global dof (node bs + component) for d gamma_j / d u_col;
    - the M records (node j, master node k, column, dM_jk / du_col).

    The pairs are those whose normals face each other and whose projections overlap (the
    mortar's, :func:`.mortar_integrals.mortar_matrices`)."""
    slave, master = geo.slave, geo.master
    m, d, gdim = slave.x.shape
    q = 2 + 3 * gdim
    step_s = STEP * slave.diameters()
    # D and N per slave facet node, and their derivatives by the facet's vertices
    base = _facet_values(slave.x)  # (m, d, 1 + gdim)
    dfac = _central(_facet_values, slave.x, step_s)  # (m, d, 1 + gdim, d, gdim)
    j_val = [slave.nodes.reshape(-1)]
    c_val = [np.full(m * d, -1, dtype=np.int64)]
    v = np.zeros((m, d, q))
    v[:, :, : 1 + gdim] = base
    v_val = [v.reshape(-1, q)]
    cols = blocked_rows(slave.nodes.reshape(-1), bs)[:, :gdim].reshape(m, d, gdim)
    dv = np.zeros((m, d, d, gdim, q))
    dv[..., : 1 + gdim] = np.moveaxis(dfac, 2, -1)
    j_val.append(np.repeat(slave.nodes, d * gdim, axis=1).reshape(-1))
    c_val.append(np.broadcast_to(cols[:, None], (m, d, d, gdim)).reshape(-1))
    v_val.append(dv.reshape(-1, q))
    # M per facing pair with an overlap, and its derivatives by the pair's 2 d vertices
    i, k = geo.pairs
    if len(i):
        facing = np.einsum("ij,ij->i", facet_normals(slave.x[i]), facet_normals(master.x[k])) < 0
        i, k = i[facing], k[facing]
    xs, xm = slave.x[i], master.x[k]
    M = pair_values(xs, xm)
    hit = np.any(M != 0.0, axis=(1, 2))
    i, k, xs, xm, M = i[hit], k[hit], xs[hit], xm[hit], M[hit]
    npair = len(i)
    both = np.concatenate([xs, xm], axis=1)
    if npair:
        dM = _central(lambda y: pair_values(y[:, :d], y[:, d:]), both, step_s[i])
    else:
        dM = np.zeros((0, d, d, 2 * d, gdim))
    xk = master.x[k]  # (n, d, gdim) the master vertices' positions
    duk = master.shift[k] if master.shift is not None else np.zeros_like(xk)
    S = M.sum(axis=2)  # (n, d)
    pv = np.zeros((npair, d, q))
    pv[:, :, 1 + gdim] = S
    pv[:, :, 2 + gdim : 2 + 2 * gdim] = np.einsum("pab,pbi->pai", M, xk)
    pv[:, :, 2 + 2 * gdim :] = np.einsum("pab,pbi->pai", M, duk)
    sj = slave.nodes[i]  # (n, d)
    j_val.append(sj.reshape(-1))
    c_val.append(np.full(npair * d, -1, dtype=np.int64))
    v_val.append(pv.reshape(-1, q))
    stencil = np.concatenate([slave.nodes[i], master.nodes[k]], axis=1)  # (n, 2 d)
    scol = (stencil[:, :, None] * bs + np.arange(gdim)).astype(np.int64)  # (n, 2 d, gdim)
    dpv = np.zeros((npair, d, 2 * d, gdim, q))
    dpv[..., 1 + gdim] = dM.sum(axis=2)
    dpv[..., 2 + gdim : 2 + 2 * gdim] = np.einsum("pabec,pbi->paeci", dM, xk)
    dpv[..., 2 + 2 * gdim :] = np.einsum("pabec,pbi->paeci", dM, duk)
    j_val.append(np.repeat(sj, 2 * d * gdim, axis=1).reshape(-1))
    c_val.append(np.broadcast_to(scol[:, None], (npair, d, 2 * d, gdim)).reshape(-1))
    v_val.append(dpv.reshape(-1, q))
    records = (
        np.concatenate(j_val).astype(np.int64),
        np.concatenate(c_val).astype(np.int64),
        np.concatenate(v_val),
    )
    shape = (npair, d, d, 2 * d, gdim)
    m_records = (
        np.broadcast_to(sj[:, :, None, None, None], shape).reshape(-1).astype(np.int64),
        np.broadcast_to(master.nodes[k][:, None, :, None, None], shape)
        .reshape(-1)
        .astype(np.int64),
        np.broadcast_to(scol[:, None, None], shape).reshape(-1),
        dM.reshape(-1),
    )
    return records, m_records


def tangent_entries(
    nodes: np.ndarray,
    state: NodeState,
    records: tuple[np.ndarray, np.ndarray, np.ndarray],
    m_records: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray],
    m_entries: tuple[np.ndarray, np.ndarray, np.ndarray],
    bs: int,
) -> tuple[tuple[np.ndarray, np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """The geometric part of the Jacobian at this rank's contact ``nodes`` (sorted, owned):
    entries (global row, global column, value) of the nodes' own rows and of the master rows
    (to be sent to their owners), from the received ``records`` and ``m_records``
    (:func:`geometry_derivatives`, on the owners of their slave nodes) and the contact nodes'
    M entries (slave node, master node, M_jk) of the search."""
    m, gdim = state.x.shape
    q = 2 + 3 * gdim
    j, col, val = records
    pos = np.minimum(np.searchsorted(nodes, j), max(m - 1, 0))
    ok = (nodes[pos] == j) if m else np.zeros(len(j), dtype=bool)
    gamma = np.zeros((m, q))
    base = ok & (col < 0)
    np.add.at(gamma, pos[base], val[base])
    deriv = ok & (col >= 0)
    width = int(max(col.max(initial=0), 0)) + 1
    key, inv = np.unique(pos[deriv] * width + col[deriv], return_inverse=True)
    uj, ucol = np.divmod(key, width)
    dgamma = np.zeros((len(key), q))
    np.add.at(dgamma, inv, val[deriv])
    P = nodal_partials(gamma, state) if m else np.zeros((0, 2 * gdim, q))
    _, phi = nodal_rows(gamma, state) if m else (None, np.zeros((0, gdim)))
    # the nodes' own rows: the complementarity row and the free tangent rows
    drows = np.einsum("urq,uq->ur", P[uj, :gdim], dgamma)
    live = state.tmask.copy()
    live[np.arange(m), state.comp] = True
    keep = live[uj]
    r_own = (nodes[uj][:, None] * bs + np.arange(gdim))[keep]
    c_own = np.broadcast_to(ucol[:, None], keep.shape)[keep]
    own = (r_own, c_own, drows[keep])
    # master rows: dM_jk phi_j ...
    mj, mk, mcol, dM = m_records
    mpos = np.minimum(np.searchsorted(nodes, mj), max(m - 1, 0))
    mok = (nodes[mpos] == mj) if m else np.zeros(len(mj), dtype=bool)
    mpos, mk, mcol, dM = mpos[mok], mk[mok], mcol[mok], dM[mok]
    r1 = mk[:, None] * bs + np.arange(gdim)
    v1 = dM[:, None] * phi[mpos]
    c1 = np.repeat(mcol[:, None], gdim, axis=1)
    # ... and M_jk dphi_j: every M entry of node j with every derivative record of j
    dphi = np.einsum("uaq,uq->ua", P[uj, gdim:], dgamma)
    ej, ek, eM = m_entries
    epos = np.searchsorted(nodes, ej)
    counts = np.bincount(uj, minlength=m)
    starts = np.cumsum(counts) - counts
    cnt = counts[epos]
    e_rep = np.repeat(np.arange(len(ej)), cnt)
    offset = np.arange(int(cnt.sum())) - np.repeat(np.cumsum(cnt) - cnt, cnt)
    u_idx = starts[epos][e_rep] + offset
    r2 = ek[e_rep][:, None] * bs + np.arange(gdim)
    v2 = eM[e_rep][:, None] * dphi[u_idx]
    c2 = np.repeat(ucol[u_idx][:, None], gdim, axis=1)
    master = (
        np.concatenate([r1.ravel(), r2.ravel()]).astype(np.int64),
        np.concatenate([c1.ravel(), c2.ravel()]).astype(np.int64),
        np.concatenate([v1.ravel(), v2.ravel()]),
    )
    return own, master
