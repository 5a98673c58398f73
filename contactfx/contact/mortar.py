"""Mortar contact between two bodies: dual Lagrange multipliers on the slave surface, condensed
out, and the nodal complementarity solved by semi-smooth Newton.

Mortar integrals (P1, 2D), segment-based: for every slave segment and every master segment
whose projection along the slave segment's normal overlaps it (:mod:`.projection`),
Gauss points on the overlap (the map to the master parameter is affine, so the rule is exact)
give

    D_j  = int_{Gamma_s} N_j ds  (diagonal: the dual basis psi_j is biorthogonal to N_j),
    M_jk = int_{Gamma_s} psi_j N_k^m ds,

with psi_0 = 2 N_0 - N_1, psi_1 = 2 N_1 - N_0 on a segment (Wohlmuth 2000,
doi:10.1137/S0036142999350929). The weighted nodal gap along the averaged nodal normal n_j is

    g_j = n_j . (sum_k M_jk x_k - D_j x_j) / D_j

(a length: > 0 apart). Exact integration makes sum_k M_jk = D_j for a slave node whose support
lies on the master surface, so a linear field is transmitted exactly: the patch test. A node
whose support leaves the master surface has its row of M rescaled to that partition of unity
when more than half of the support is covered; with less it is no contact node (its
projection falls off the master surface).

Multiplier and condensation: the contact pressure lambda_j >= 0 enters the equilibrium as
R(u) - G^T lambda = 0 with R = K u - b and G = dg/du (rows: -D_j n_j at the slave node,
M_jk n_j at the master nodes). Because D is diagonal, lambda is a nodal quantity of the slave
node's normal equilibrium, lambda_j = -n_j . R_j / D_j, and the system is condensed onto the
displacement (Popp, Gee & Wall 2009, doi:10.1002/nme.2614; Hueeber & Wohlmuth 2005,
doi:10.1016/j.cma.2004.09.012): with T the row operator

    master row (k, c):   R_kc + sum_j (M_jk / D_j) n_jc (n_j . R_j)
    slave row (j, t):    t_j . R_j                      (each tangent t_j)
    slave row (j, n):    D_j C(lambda_j, c_j g_j),      c_j = r0 E / h_j,

C the complementarity function (``min``: lambda - max(0, lambda - c g), Alart-Curnier;
``fb``: Fischer-Burmeister) and (j, n) the component of the largest |n_j|. The multiplier
thus lives on the slave nodes only; no unknown is added. The Jacobian is exact for the mortar
matrices and normals of the last search: J = diag(s) T K + diag(w) G with s = D_j dC/dlambda
on the normal rows (1 elsewhere) and w = D_j c_j dC/d(cg). With ``--search-update newton`` the
search runs at every residual and the derivatives of D, M and n_j are not linearised.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from petsc4py import PETSc

from contactfx.contact.coupling import NodeLayout, blocked_rows
from contactfx.contact.method import MethodBase, Supports
from contactfx.contact.pair import Facets, facet_normals, owners
from contactfx.contact.projection import gauss_segment, segment_overlaps
from contactfx.params import param, validate

__all__ = ["Mortar", "MortarCoupling", "mortar_matrices"]


@dataclass(frozen=True)
class Mortar(MethodBase):
    """r0 > 0 (c = r0 E / h in the complementarity function), ncp: min or fb."""

    r0: float = param(10.0, "augmented Lagrangian augmentation, r = r0 E / h", positive=True)
    ncp: str = param("min", "complementarity function of al-ssn / mortar: min "
                     "(Alart-Curnier) or fb (Fischer-Burmeister)",
                     choices=("min", "fb"))  # fmt: skip
    name = "mortar"
    sweep = ("ncp", ("min", "fb"))
    supports = Supports(
        obstacles=False, interfaces=False, two_body=True, dim1=False, iterative=False,
        why_not={"obstacles": "a mortar pair joins two meshed surfaces",
                 "interfaces": "a mortar pair joins two meshed surfaces",
                 "friction": "mortar friction is not implemented yet",
                 "iterative": "its condensed Jacobian is not symmetric: use LU"},
    )  # fmt: skip

    def __post_init__(self) -> None:
        validate(self)

    def residual(self, s):
        return None

    def pressure(self, s):
        return None

    def coupling(self, pair) -> MortarCoupling:
        return MortarCoupling(pair, self.r0, self.ncp)


def _dual(xi: np.ndarray) -> np.ndarray:
    """(n, 2) dual shape functions psi_0 = 2 - 3 xi, psi_1 = 3 xi - 1 on a segment."""
    return np.stack([2.0 - 3.0 * xi, 3.0 * xi - 1.0], axis=-1)


def _linear(xi: np.ndarray) -> np.ndarray:
    return np.stack([1.0 - xi, xi], axis=-1)


def mortar_matrices(slave: Facets, master: Facets, pairs, order: int = 2):
    """The local mortar integrals of 2D P1 segments: D contributions (m_s, 2) per slave
    facet node (int N_j), length-weighted normal contributions (m_s, 2, gdim), and the
    triplets (slave node, master node, value) of M over the candidate ``pairs`` (slave facet
    indices, master facet indices) whose normals face each other and whose projections
    overlap."""
    xs, xm = slave.x, master.x
    length = np.linalg.norm(xs[:, 1] - xs[:, 0], axis=1)
    ns = facet_normals(xs)
    D = np.repeat(0.5 * length[:, None], 2, axis=1)
    normals = np.repeat((0.5 * length[:, None] * ns)[:, None], 2, axis=1)
    i, k = pairs
    facing = np.einsum("ij,ij->i", ns[i], facet_normals(xm[k])) < 0.0
    i, k = i[facing], k[facing]
    ov = segment_overlaps(xs[i], xm[k], ns[i])
    i, k = i[ov.valid], k[ov.valid]
    xi, eta = ov.xi[ov.valid], ov.eta[ov.valid]
    g, w = gauss_segment(order)
    rows, cols, vals = [], [], []
    for gq, wq in zip(g, w, strict=True):
        xq = xi[:, 0] + gq * (xi[:, 1] - xi[:, 0])
        eq = eta[:, 0] + gq * (eta[:, 1] - eta[:, 0])
        weight = wq * length[i] * (xi[:, 1] - xi[:, 0])
        contrib = weight[:, None, None] * _dual(xq)[:, :, None] * _linear(eq)[:, None, :]
        rows.append(np.repeat(slave.nodes[i][:, :, None], 2, axis=2))
        cols.append(np.repeat(master.nodes[k][:, None, :], 2, axis=1))
        vals.append(contrib)
    flat = [np.concatenate([a.reshape(-1) for a in arr]) if arr else np.zeros(0)
            for arr in (rows, cols, vals)]  # fmt: skip
    return D, normals, (flat[0].astype(np.int64), flat[1].astype(np.int64), flat[2])


def _to_owners(comm, ranges: np.ndarray, node: np.ndarray, payload: list[np.ndarray]):
    """Send rows (node, *payload) to the owners of ``node``; the received rows."""
    if comm.size == 1:
        return node, payload
    owner = np.searchsorted(ranges, node, side="right") - 1
    order = np.argsort(owner, kind="stable")
    counts = np.bincount(owner, minlength=comm.size)
    splits = np.cumsum(counts)[:-1]
    parts = [np.split(a[order], splits) for a in [node, *payload]]
    received = comm.alltoall([[p[r] for p in parts] for r in range(comm.size)])
    out = [np.concatenate([rec[j] for rec in received]) for j in range(len(parts))]
    return out[0], out[1:]


class MortarCoupling:
    """The condensed dual-mortar contact of one pair (see the module docstring)."""

    def __init__(self, pair, r0: float, ncp: str) -> None:
        self.pair, self.r0, self.ncp = pair, r0, ncp
        self.layout: NodeLayout = pair.layout
        self.comm = self.layout.comm
        self.search_each_newton = pair.search_each_newton
        self.ranges = owners(self.layout.imap, self.comm)
        self.T = self.G = self.TK = self.g0 = None

    # -- search and mortar integrals -------------------------------------------------------
    def update(self, u: np.ndarray) -> None:
        """Search and integrate at x = X + u (``u`` the local array of the displacement)."""
        lay, pair, comm = self.layout, self.pair, self.comm
        gdim = lay.gdim
        ub = u.reshape(-1, lay.bs)[:, :gdim]
        slave, master = pair.slave.current(ub), pair.master.current(ub)
        near, pairs = pair.search(slave, master)
        D, normals, (rows, cols, vals) = mortar_matrices(slave, near, pairs)
        nodes = slave.nodes.reshape(-1)
        # nodal sums on the owners: D_j and sum of weighted normals
        node_data = np.concatenate([D.reshape(-1, 1), normals.reshape(-1, gdim)], axis=1)
        j_nodes, (j_data,) = _to_owners(comm, self.ranges, nodes, [node_data])
        m_rows, (m_cols, m_vals) = _to_owners(comm, self.ranges, rows, [cols, vals])
        self._assemble(j_nodes, j_data, m_rows, m_cols, m_vals)

    def _assemble(self, j_nodes, j_data, m_rows, m_cols, m_vals) -> None:
        lay = self.layout
        gdim, bs = lay.gdim, lay.bs
        uniq, inv = np.unique(j_nodes, return_inverse=True)
        data = np.zeros((len(uniq), 1 + gdim))
        np.add.at(data, inv, j_data)
        Dj = data[:, 0]
        nj = data[:, 1:] / np.linalg.norm(data[:, 1:], axis=1)[:, None]
        # M rows per slave node
        key = np.searchsorted(uniq, m_rows)
        Msum = np.zeros(len(uniq))
        np.add.at(Msum, key, m_vals)
        coverage = Msum / Dj
        contact = coverage > 0.5
        scale = np.where(contact, Dj / np.where(Msum > 0, Msum, 1.0), 0.0)
        m_w = m_vals * scale[key] / Dj[key]  # M_jk / D_j, rescaled to sum to 1
        keep = contact[key]
        # frames: the normal row is the component of largest |n_j|
        comp = np.argmax(np.abs(nj), axis=1)
        self.nodes, self.D = uniq[contact], Dj[contact]
        self.normal, self.comp = nj[contact], comp[contact]
        self.h = self.D ** (1.0 / max(gdim - 1, 1))
        self.c = self.r0 * self.pair.E / self.h
        self.normal_rows = (self.nodes * bs + self.comp - lay.start * bs).astype(np.int32)
        for M in (self.T, self.G, self.TK):
            if M is not None:
                M.destroy()
        T, G = lay.matrix(), lay.matrix()
        slave_local = (uniq[contact] - lay.start).astype(np.int64)
        one = np.ones((lay.n_owned, bs))
        one[slave_local] = 0.0
        ones = T.createVecLeft()
        ones.getArray()[:] = one.ravel()
        T.assemble()
        T.setDiagonal(ones)
        ones.destroy()
        add = PETSc.InsertMode.ADD_VALUES
        tangents = _tangents(self.normal)
        for a, j in enumerate(self.nodes):
            cols_j = blocked_rows(j, bs)
            n = self.normal[a]
            t_rows = [c for c in range(gdim) if c != self.comp[a]]
            for r, t in zip(t_rows, tangents[a], strict=True):
                T.setValues([j * bs + r], cols_j, t, addv=add)
            T.setValues([j * bs + self.comp[a]], cols_j, -n / self.D[a], addv=add)
            G.setValues([j * bs + self.comp[a]], cols_j, -n, addv=add)
        # master couplings
        mk, mj, mw = m_cols[keep], m_rows[keep], m_w[keep]
        pos = np.searchsorted(self.nodes, mj)
        for k, j, w, a in zip(mk, mj, mw, pos, strict=True):
            n = self.normal[a]
            block = w * np.outer(n, n)
            T.setValues(blocked_rows(k, bs), blocked_rows(j, bs), block.ravel(), addv=add)
            G.setValues([j * bs + self.comp[a]], blocked_rows(k, bs), w * n, addv=add)
        for M in (T, G):
            M.assemble()
        self.T, self.G = T, G
        self.g0 = G.createVecLeft()
        G.mult(lay.X, self.g0)
        self.TK = None  # T K, formed at the next Jacobian
        self._y = T.createVecLeft()
        self._g = G.createVecLeft()

    # -- nonlinear residual and Jacobian ---------------------------------------------------
    def _state(self, x: PETSc.Vec, R: PETSc.Vec):
        """(y = T R, lambda, c g, the NCP value and its partial derivatives) at x."""
        self.T.mult(R, self._y)
        self.G.mult(x, self._g)
        self._g.axpy(1.0, self.g0)
        lam = self._y.getArray()[self.normal_rows]
        cg = self.c * self._g.getArray()[self.normal_rows]
        if self.ncp == "min":
            act = lam - cg >= 0.0
            C = np.where(act, cg, lam)
            da, db = np.where(act, 0.0, 1.0), np.where(act, 1.0, 0.0)
        else:
            rho = np.sqrt(lam**2 + cg**2 + (1e-12 * self.pair.E) ** 2)
            C = lam + cg - rho
            da, db = 1.0 - lam / rho, 1.0 - cg / rho
        return lam, cg, C, da, db

    def residual(self, x: PETSc.Vec, F: PETSc.Vec) -> None:
        lam, cg, C, self._da, self._db = self._state(x, F)
        self.lam, self.gap = lam, cg / self.c
        self._y.copy(F)
        F.getArray()[self.normal_rows] = self.D * C

    def jacobian(self, x: PETSc.Vec, K: PETSc.Mat, J: PETSc.Mat) -> None:
        """At the x of the last residual (SNES evaluates F(x) before J(x))."""
        da, db = self._da, self._db
        if self.TK is None:
            self.TK = self.T.matMult(K)
            union = self.TK.copy()
            union.axpy(1.0, self.G, structure=PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
            J.zeroEntries()
            J.axpy(1.0, union, structure=PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
            union.destroy()
        s = self.TK.createVecLeft()
        s.set(1.0)
        s.getArray()[self.normal_rows] = self.D * da
        w = self.G.createVecLeft()
        w.getArray()[self.normal_rows] = self.D * self.c * db
        A = self.TK.copy()
        A.diagonalScale(L=s)
        B = self.G.copy()
        B.diagonalScale(L=w)
        J.zeroEntries()
        J.axpy(1.0, A, structure=PETSc.Mat.Structure.SUBSET_NONZERO_PATTERN)
        J.axpy(1.0, B, structure=PETSc.Mat.Structure.SUBSET_NONZERO_PATTERN)
        for obj in (s, w, A, B):
            obj.destroy()

    # -- what the post-processing reads ----------------------------------------------------
    def force(self) -> float:
        """The normal contact force sum_j D_j lambda_j of the pair."""
        from mpi4py import MPI

        return self.comm.allreduce(float(np.sum(self.D * self.lam)), op=MPI.SUM)

    def nodal(self):
        """Owned contact nodes: (global node, weight D_j, pressure lambda_j, gap g_j)."""
        return self.nodes, self.D, self.lam, self.gap


def _tangents(n: np.ndarray) -> np.ndarray:
    """(m, gdim - 1, gdim) unit tangents orthogonal to the unit normals n (m, gdim)."""
    if n.shape[1] == 2:
        return np.stack([n[:, 1], -n[:, 0]], axis=1)[:, None, :]
    a = np.where(np.abs(n[:, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
    t1 = np.cross(n, a)
    t1 /= np.linalg.norm(t1, axis=1)[:, None]
    return np.stack([t1, np.cross(n, t1)], axis=1)
