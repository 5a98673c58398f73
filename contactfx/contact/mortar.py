"""Mortar contact between two bodies: dual Lagrange multipliers on the slave surface, condensed
out, and the nodal complementarity solved by semi-smooth Newton.

Mortar integrals (P1), segment-based: in 2D for every slave segment and every master segment
whose projection along the slave segment's normal overlaps it (:mod:`.projection`),
Gauss points on the overlap (the map to the master parameter is affine, so the rule is exact);
in 3D for every slave triangle and every facing master triangle, the master projected onto the
slave plane along the slave normal and clipped by the slave triangle
(:func:`.projection.triangle_overlaps`, Puso & Laursen 2004, doi:10.1016/j.cma.2003.10.010;
Popp et al. 2010, doi:10.1002/nme.2866), the degree-2 triangle rule on the clip polygon's fan
triangles (both maps affine there, psi_j N_k quadratic: exact). They give

    D_j  = int_{Gamma_s} N_j ds  (diagonal: the dual basis psi_j is biorthogonal to N_j),
    M_jk = int_{Gamma_s} psi_j N_k^m ds,

with psi_0 = 2 N_0 - N_1, psi_1 = 2 N_1 - N_0 on a segment and psi_i = 4 N_i - 1 on a
triangle (int_T psi_i N_k = delta_ik |T| / 3; Wohlmuth 2000, doi:10.1137/S0036142999350929).
The nodal normals n_j are the length- / area-weighted averages of the facet normals. The
weighted nodal gap along n_j is

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
``fb``: Fischer-Burmeister), h_j = D_j^(1 / (gdim - 1)) (the length of a 2D node's support,
the square root of a 3D node's area) and (j, n) the component of the largest |n_j|. At a slave
node with Dirichlet components (a symmetry plane through the contact) those rows carry the
support's reaction and are replaced by their conditions: the frame is built on the free
components F instead, lambda_j = -n_F . R_j / (D_j |n_F|^2) from R_jc = -D_j lambda_j n_jc
(c in F), the tangents span the free directions orthogonal to n_F, and (j, n) is the free
component of largest |n_F| (without this a tangent row lands on a Dirichlet row, and the
node's tangential equilibrium is lost while the reaction is forced to zero). The multiplier
thus lives on the slave nodes only; no unknown is added. Frictionless, the Jacobian is exact
for the mortar matrices and normals of the last search: J = diag(s) T K + diag(w) G with
s = D_j dC/dlambda on the normal rows (1 elsewhere) and w = D_j c_j dC/d(cg). With
``--search-update newton`` (and at finite strain) the search runs at every residual, and the
Jacobian adds the variation of D, M and n_j with the displacement (:mod:`.mortar_tangent`).

Coulomb friction (``--friction coulomb``): the tangent rows carry the tangential multiplier
lambda_T,jc = -t_jc . R_j / D_j (the master rows receive M_jk / D_j times the whole free part
of R_j), and the weighted slip increment of the load step is

    v_jc = t_jc . (du_j - sum_k (M_jk / D_j) du_k),    du = u - u_prev

(u_prev: the last converged step; M of the search at the start of the step, or of the last
residual with ``--search-update newton``). A translation of both bodies gives no slip (the
rows of M / D sum to 1), and a small rotation omega x gives omega x (D_j x_j - sum_k M_jk x_k)
/ D_j = omega x (g_j n_j): none on a closed node (Gitterle et al. 2010,
doi:10.1002/nme.2907, define the slip objectively at finite rotations; the kinematics here is
small-strain). The rows are D_j C_T with

    C_T = lambda_T - proj_{B(0, xi_j)}(lambda_T + c_j v_j),   xi_j = mu max(0, lambda_j - c_j g_j)

(Hueeber, Stadler & Wohlmuth 2008, doi:10.1137/060671061): stick (|lambda_T + c v| <= xi)
forces v = 0, slip puts lambda_T on the circle (sphere) of radius xi along the slip, an open
node (xi = 0) has lambda_T = 0. Its semi-smooth derivative (the ball projection's, and the
bound's through lambda and g) enters the Jacobian as nodal blocks P, Q: J = P T K + Q G, G
holding the gap rows and the slip rows.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from petsc4py import PETSc

from contactfx.contact.coupling import NodeLayout, blocked_rows
from contactfx.contact.method import MethodBase, Supports
from contactfx.contact.mortar_integrals import dual_triangle, mortar_matrices, nodal_weights
from contactfx.contact.mortar_tangent import (
    Geometry,
    NodeState,
    frames,
    geometry_derivatives,
    tangent_entries,
)
from contactfx.contact.pair import node_held, owners
from contactfx.contact.projection import (
    transport,
)
from contactfx.contact.reversal import ReversalMemory
from contactfx.contact.smoothing import (
    bulges,
    conforming,
    dual_moments,
    mean_curvature,
    vertex_normals,
)
from contactfx.params import param, validate

if TYPE_CHECKING:
    from mpi4py import MPI

    from contactfx.contact.pair import ContactPair
    from contactfx.contact.surface import Surface

__all__ = ["Mortar", "MortarCoupling", "mortar_matrices", "dual_triangle"]


@dataclass(frozen=True)
class Mortar(MethodBase):
    """r0 > 0 (c = r0 E / h in the complementarity function), ncp: min or fb."""

    r0: float = param(10.0, "augmented Lagrangian augmentation, r = r0 E / h", positive=True)
    ncp: str = param(
        "min",
        "complementarity function: min (Alart-Curnier) or fb (Fischer-Burmeister)",
        choices=("min", "fb"),
    )
    name = "mortar"
    sweep = ("ncp", ("min", "fb"))
    supports = Supports(
        friction=("none", "coulomb"),
        obstacles=False,
        interfaces=False,
        two_body=True,
        dim1=False,
        iterative=False,
        why_not={
            "obstacles": "a mortar pair joins two meshed surfaces",
            "interfaces": "a mortar pair joins two meshed surfaces",
            "friction": "mortar has Coulomb friction only",
            "iterative": "its condensed Jacobian is not symmetric: use LU",
        },
    )

    def __post_init__(self) -> None:
        validate(self)

    def residual(self, s: Surface) -> None:
        return None

    def pressure(self, s: Surface) -> None:
        return None

    def coupling(self, pair: ContactPair) -> MortarCoupling:
        return MortarCoupling(pair, self.r0, self.ncp)


def _to_owners(
    comm: MPI.Comm, ranges: np.ndarray, node: np.ndarray, payload: list[np.ndarray]
) -> tuple[np.ndarray, list[np.ndarray]]:
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


class MortarCoupling(ReversalMemory):
    """The condensed dual-mortar contact of one pair (see the module docstring)."""

    #: the nodal complementarity holds exactly at a converged state: the constraint stores no
    #: energy (a dynamic run's balance counts its contact term as 0)
    stores_energy = False

    def __init__(self, pair: ContactPair, r0: float, ncp: str) -> None:
        self.pair, self.r0, self.ncp = pair, r0, ncp
        self.layout: NodeLayout = pair.layout
        self.comm = self.layout.comm
        self.search_each_newton = pair.search_each_newton
        #: searched at every residual: what the last search integrated, for the consistent
        #: tangent (:mod:`.mortar_tangent`); the frame-indifferent slip's history there
        self.geometry: Geometry | None = None
        self._history: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None
        #: the held components of the slave and master facets' vertices (m, d, gdim), for
        #: the smooth surfaces' normals on symmetry planes (:mod:`.smoothing`); made at the
        #: first search
        self._held: tuple[np.ndarray, np.ndarray] | None = None
        #: smoothing "auto": the slave's and the master's mean curvatures it decided on
        self.curvatures: tuple[float, float] | None = None
        self.ranges = owners(self.layout.imap, self.comm)
        # the row operator T, the gap (and slip) rows G, T K and the gaps at the reference
        # configuration: made by the search (update), T K at the next Jacobian
        self.T: PETSc.Mat | None = None
        self.G: PETSc.Mat | None = None
        self.TK: PETSc.Mat | None = None
        self.g0: PETSc.Vec | None = None
        #: the reference weights D0_j (the slave surface at X) of this rank's slave nodes
        #: (sorted global nodes, weights), for the nominal pressure (:meth:`nodal`)
        self._reference: tuple[np.ndarray, np.ndarray] | None = None
        #: Coulomb coefficient (None: frictionless) and the last converged displacement
        self.mu, self.previous = pair.mu, pair.previous
        #: finite strain: the frame-indifferent slip (:meth:`_objective_slip`), with the
        #: weighted gap vectors b_j and nodal normals of the owned slave nodes closed at the
        #: last converged step (sorted global nodes, (m, gdim) vectors, (m, gdim) normals)
        self.objective = pair.finite_strain and self.mu is not None
        #: an interference fit: the owned slave nodes' initial overlaps max(-g0_j, 0) (sorted
        #: global nodes, values; :meth:`record_start`) and, per contact node of the last
        #: search, its own (0 for a node without one)
        self._initial: tuple[np.ndarray, np.ndarray] | None = None
        self.overlap = np.zeros(0)
        empty = np.zeros((0, self.layout.gdim))
        self._b_old: tuple[np.ndarray, np.ndarray, np.ndarray] = (
            np.zeros(0, dtype=np.int64),
            empty,
            empty,
        )
        #: Coulomb: Newton's reversal guard (:mod:`.reversal`) at the slave nodes
        self.init_reversals(self.mu is not None)

    # -- search and mortar integrals -------------------------------------------------------
    def update(self, u: np.ndarray) -> None:
        """Search and integrate at x = X + u (``u`` the local array of the displacement)."""
        lay, pair, comm = self.layout, self.pair, self.comm
        gdim = lay.gdim
        ub = u.reshape(-1, lay.bs)[:, :gdim]
        slave, master = pair.slave.current(ub), pair.master.current(ub)
        if self.search_each_newton and self.mu is not None:
            assert self.previous is not None  # set with mu
            prev = self.previous.x.array.reshape(-1, lay.bs)[:, :gdim]
            master.shift = (ub - prev)[pair.master.local]
        nodes = slave.nodes.reshape(-1)
        if self._reference is None:
            self._reference = self._node_sums(nodes, nodal_weights(pair.slave.X))
        own = np.zeros(slave.nodes.shape)  # int psi_j d_s: the slave's own deviation
        if pair.smooth is not False:
            if self._held is None and pair.fixed is not None:
                held = node_held(lay.V, pair.fixed)
                self._held = (held[pair.slave.local], held[pair.master.local])
            hs, hm = self._held if self._held is not None else (None, None)
            bulge_m = bulges(master.x, vertex_normals(lay, pair.master, master, hm))
            bulge_s = bulges(slave.x, vertex_normals(lay, pair.slave, slave, hs))
            if pair.smooth is None:  # "auto": decided once, at the first search
                self.curvatures = (
                    mean_curvature(comm, slave.x, bulge_s),
                    mean_curvature(comm, master.x, bulge_m),
                )
                pair.smooth = conforming(*self.curvatures)
            if pair.smooth:
                master.bulge = bulge_m
                own = dual_moments(slave.x, bulge_s)
        near, pairs = pair.search(slave, master)
        assert pairs is not None  # searched with pairs
        #: what the consistent tangent differentiates (:mod:`.mortar_tangent`)
        self.geometry = Geometry(slave, near, pairs) if self.search_each_newton else None
        D, normals, (rows, cols, vals), corr = mortar_matrices(slave, near, pairs)
        # nodal sums on the owners: D_j, the sum of weighted normals, int psi_j d_m over
        # the overlaps and int psi_j d_s over the support
        node_data = np.concatenate(
            [D.reshape(-1, 1), normals.reshape(-1, gdim), corr.reshape(-1, 1), own.reshape(-1, 1)],
            axis=1,
        )
        j_nodes, (j_data,) = _to_owners(comm, self.ranges, nodes, [node_data])
        m_rows, (m_cols, m_vals) = _to_owners(comm, self.ranges, rows, [cols, vals])
        self._assemble(j_nodes, j_data, m_rows, m_cols, m_vals)
        if self.objective:
            self._objective_slip(u)

    def _node_sums(self, nodes: np.ndarray, values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(sorted owned nodes, sums): the per-facet-node ``values`` (same shape as the facets'
        nodes) summed on the nodes' owners. Collective."""
        j, (d,) = _to_owners(self.comm, self.ranges, nodes, [values.reshape(-1, 1)])
        uniq, inv = np.unique(j, return_inverse=True)
        return uniq, np.bincount(inv, weights=d[:, 0], minlength=len(uniq))

    def missed(self, u: np.ndarray) -> int:
        """The number of slave nodes (all ranks) that a search at x = X + u makes contact
        nodes (their support more than half over the master surface) and the last search did
        not. Collective; the coupling is not changed."""
        lay, pair, comm = self.layout, self.pair, self.comm
        ub = u.reshape(-1, lay.bs)[:, : lay.gdim]
        slave, master = pair.slave.current(ub), pair.master.current(ub)
        near, pairs = pair.search(slave, master)
        assert pairs is not None  # searched with pairs
        D, _, (rows, _, vals), _ = mortar_matrices(slave, near, pairs)
        uniq, Dj = self._node_sums(slave.nodes.reshape(-1), D)
        m_rows, (m_vals,) = _to_owners(comm, self.ranges, rows, [vals])
        Msum = np.bincount(np.searchsorted(uniq, m_rows), weights=m_vals, minlength=len(uniq))
        covered = uniq[Msum > 0.5 * Dj]
        from mpi4py import MPI

        return comm.allreduce(len(np.setdiff1d(covered, self.covered)), op=MPI.SUM)

    def _assemble(
        self,
        j_nodes: np.ndarray,
        j_data: np.ndarray,
        m_rows: np.ndarray,
        m_cols: np.ndarray,
        m_vals: np.ndarray,
    ) -> None:
        lay = self.layout
        gdim, bs = lay.gdim, lay.bs
        uniq, inv = np.unique(j_nodes, return_inverse=True)
        data = np.zeros((len(uniq), 3 + gdim))
        np.add.at(data, inv, j_data)
        Dj = data[:, 0]
        nj = data[:, 1 : 1 + gdim] / np.linalg.norm(data[:, 1 : 1 + gdim], axis=1)[:, None]
        # M rows per slave node
        key = np.searchsorted(uniq, m_rows)
        Msum = np.zeros(len(uniq))
        np.add.at(Msum, key, m_vals)
        coverage = Msum / Dj
        contact = coverage > 0.5
        self.covered = uniq[contact]  # what the next search is compared with (missed)
        scale = np.where(contact, Dj / np.where(Msum > 0, Msum, 1.0), 0.0)
        m_w = m_vals * scale[key] / Dj[key]  # M_jk / D_j, rescaled to sum to 1
        # the smooth surfaces' deviations d along their normals, the master's weighted as M:
        # the gap between the surfaces rather than their facets is
        # g_j - (int psi_j d_m + int psi_j d_s) / D_j (:mod:`.smoothing`)
        smooth = (data[:, -2] * scale + data[:, -1]) / Dj
        # frames on the free components (a Dirichlet row is overwritten by its condition)
        free = np.ones((len(uniq), gdim), dtype=bool)
        if self.pair.fixed is not None:
            local = (uniq - lay.start).astype(np.int64)
            free = ~self.pair.fixed.reshape(-1, bs)[local, :gdim]
        n_free, comp, tangents = frames(nj, free)
        # a normal nearly along the fixed components: the support carries the contact
        contact &= np.linalg.norm(n_free, axis=1) > 0.5
        keep = contact[key]
        self.nodes, self.D = uniq[contact], Dj[contact]
        assert self._reference is not None  # the first search's (update)
        uniq0, D0 = self._reference
        self.D0 = D0[np.searchsorted(uniq0, self.nodes)]
        self.normal, self.comp = nj[contact], comp[contact]
        n_free, tangents, free = n_free[contact], tangents[contact], free[contact]
        self.free = free
        #: the contact nodes' M entries (slave node, master node, M_jk before the
        #: rescaling): the consistent tangent's (:mod:`.mortar_tangent`)
        self.m_entries = (m_rows[keep], m_cols[keep], m_vals[keep])
        self.h = self.D ** (1.0 / max(gdim - 1, 1))
        self.c = self.r0 * self.pair.E / self.h
        self.overlap = self._overlap_of(self.nodes)
        self.normal_rows = (self.nodes * bs + self.comp - lay.start * bs).astype(np.int32)
        for M in (self.T, self.G, self.TK):
            if M is not None:
                M.destroy()
        m = len(self.nodes)
        # lambda_j = -n_F . R_j / (D_j |n_F|^2) from the free components' equilibrium
        # R_jc = -D_j lambda_j n_jc (the fixed ones carry the support's reaction)
        lam_row = -n_free / (self.D * np.sum(n_free**2, axis=1))[:, None]
        # slave rows (j, c): lambda_j at comp, the tangents at the other free components,
        # the identity at a fixed one (replaced by the Dirichlet condition)
        # tangent rows: t_c . R_j (frictionless: the nodal force has no tangential part), or
        # the tangential multiplier lambda_T,jc = -t_c . R_j / D_j (Coulomb)
        t_rows = tangents if self.mu is None else -tangents / self.D[:, None, None]
        rows_c = np.where(free[:, :, None], t_rows, np.eye(gdim)[None])
        rows_c[np.arange(m), self.comp] = lam_row
        self.tmask = free.copy()
        self.tmask[np.arange(m), self.comp] = False
        self.tangents = tangents
        block = np.zeros((m, bs, bs))
        block[:, :gdim, :gdim] = rows_c
        block[:, gdim:, gdim:] = np.eye(bs - gdim)
        j_rows = blocked_rows(self.nodes, bs)  # (m, bs)
        t_r = [np.repeat(j_rows[:, :, None], bs, axis=2)]
        t_c = [np.repeat(j_rows[:, None, :], bs, axis=1)]
        t_v = [block]
        normal_global = self.nodes * bs + self.comp
        g_r = [np.repeat(normal_global[:, None], gdim, axis=1)]
        g_c = [j_rows[:, :gdim]]
        g_v = [-self.normal]
        # identity on the rows of every other owned node
        others = np.ones(lay.n_owned, dtype=bool)
        others[(self.nodes - lay.start).astype(np.int64)] = False
        diag = blocked_rows(np.flatnonzero(others) + lay.start, bs).ravel()
        t_r.append(diag)
        t_c.append(diag)
        t_v.append(np.ones(len(diag)))
        # master couplings: R_k - sum_j M_jk n_j lambda_j; the gap's master terms
        mk, mj, mw = m_cols[keep], m_rows[keep], m_w[keep]
        pos = np.searchsorted(self.nodes, mj)
        k_rows, jm_rows = blocked_rows(mk, bs), j_rows[pos]
        mblock = np.zeros((len(mk), bs, bs))
        mblock[:, :gdim, :gdim] = -(self.D[pos] * mw)[:, None, None] * (
            self.normal[pos][:, :, None] * lam_row[pos][:, None, :]
        )
        if self.mu is not None:  # and - M_jk t_c lambda_T,jc
            tp = tangents[pos]
            mblock[:, :gdim, :gdim] += mw[:, None, None] * np.einsum("pci,pcj->pij", tp, tp)
        master_r = np.repeat(k_rows[:, :, None], bs, axis=2).ravel()
        master_c = np.repeat(jm_rows[:, None, :], bs, axis=1).ravel()
        g_r.append(np.repeat(normal_global[pos][:, None], gdim, axis=1))
        g_c.append(k_rows[:, :gdim])
        g_v.append(mw[:, None] * self.normal[pos])
        if self.mu is not None:
            # slip rows (j, c): v_jc = t_c . (du_j - sum_k M_jk / D_j du_k), du = u - u_prev
            t_glob = j_rows[:, :gdim]  # the tangent rows of node j are its rows c
            g_r.append(np.repeat(t_glob[:, :, None], gdim, axis=2))
            g_c.append(np.repeat(j_rows[:, None, :gdim], gdim, axis=1))
            g_v.append(tangents)
            g_r.append(np.repeat(t_glob[pos][:, :, None], gdim, axis=2))
            g_c.append(np.repeat(k_rows[:, None, :gdim], gdim, axis=1))
            g_v.append(-mw[:, None, None] * tangents[pos])
        # the master rows go to their owners
        node_k, (master_r, master_c, master_v) = _to_owners(
            self.comm, self.ranges, master_r // bs, [master_r, master_c, mblock.ravel()]
        )
        t_r.append(master_r)
        t_c.append(master_c)
        t_v.append(master_v)
        T = _owned_matrix(
            lay, *(np.concatenate([x.ravel() for x in arr]) for arr in (t_r, t_c, t_v))
        )
        G = _owned_matrix(
            lay, *(np.concatenate([x.ravel() for x in arr]) for arr in (g_r, g_c, g_v))
        )
        self.T, self.G = T, G
        self.g0 = G.createVecLeft()
        G.mult(lay.X, self.g0)
        #: the smoothing's correction of each contact node's gap (0: facets)
        self.smoothed = smooth[contact]
        self.g0.getArray()[self.normal_rows] -= self.smoothed
        if self.mu is not None:  # slip rows: - G u_prev (the increment from the last step)
            n = lay.n_owned * bs
            assert self.previous is not None  # set with mu
            prev = G.createVecRight()
            prev.getArray()[:] = self.previous.x.array[:n]
            slip0 = G.createVecLeft()
            G.mult(prev, slip0)
            rows = self.tangent_rows()[self.tmask]
            self.g0.getArray()[rows] = -slip0.getArray()[rows]
            prev.destroy()
            slip0.destroy()
        self.TK = None  # T K, formed at the next Jacobian
        self._y = T.createVecLeft()
        self._g = G.createVecLeft()

    # -- nonlinear residual and Jacobian ---------------------------------------------------
    def _state(
        self, x: PETSc.Vec, R: PETSc.Vec
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(y = T R, lambda, c g, the NCP value and its partial derivatives) at x."""
        assert self.T is not None and self.G is not None  # made by the search
        self.T.mult(R, self._y)
        self.G.mult(x, self._g)
        self._g.axpy(1.0, self.g0)
        lam = self._y.getArray()[self.normal_rows]
        # an interference fit's hidden overlap: g_j + (1 - t) max(-g0_j, 0)
        g = self._g.getArray()[self.normal_rows] + self.pair.hidden() * self.overlap
        cg = self.c * g
        if self.ncp == "min":
            # a tie (lambda = 0, g at round-off of either sign, as on coinciding flat
            # surfaces at the start) is active: gaps below 1e-12 h_j count as closed in the
            # choice of the branch (C differs by at most r0 E 1e-12 from the other branch)
            act = lam - cg >= -1e-12 * self.c * self.h
            C = np.where(act, cg, lam)
            da, db = np.where(act, 0.0, 1.0), np.where(act, 1.0, 0.0)
        else:
            rho = np.sqrt(lam**2 + cg**2 + (1e-12 * self.pair.E) ** 2)
            C = lam + cg - rho
            da, db = 1.0 - lam / rho, 1.0 - cg / rho
        return lam, cg, C, da, db

    def tangent_rows(self) -> np.ndarray:
        """Local rows (m, gdim) of the contact nodes' components (valid where ``tmask``)."""
        bs = self.layout.bs
        return (
            (self.nodes - self.layout.start)[:, None] * bs + np.arange(self.layout.gdim)
        ).astype(np.int64)

    def _friction(
        self, lam: np.ndarray, cg: np.ndarray, y: np.ndarray, q: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Coulomb at the contact nodes: C_T = lambda_T - proj_{B(xi)}(lambda_T + c v), the
        bound xi = mu max(0, lambda - c g) (Hueeber, Stadler & Wohlmuth 2008,
        doi:10.1137/060671061), in the tangent slots (m, gdim) of ``tmask``; its derivatives
        with respect to lambda_T, v (m, gdim, gdim) and to lambda, g (m, gdim)."""
        assert self.mu is not None
        tm = self.tmask
        lt, v = np.where(tm, y, 0.0), np.where(tm, q, 0.0)
        c = self.c[:, None]
        z = lt + c * v
        arg = lam - cg
        xi = self.mu * np.maximum(arg, 0.0)
        nz = np.linalg.norm(z, axis=1)
        # a tie (both the bound and |lambda_T + c v| at round-off, as on coinciding flat
        # surfaces at the start) sticks, on every partition alike: the normal's tie rule
        # (:meth:`_state`), with the bound's round-off mu c 1e-12 h_j
        tie = 1e-12 * self.c * self.h
        closed = arg >= -tie
        stick = (nz <= xi + self.mu * tie) & closed
        self._record_trial(0, self.nodes, z, ~stick & closed)
        stick |= self._reversed(0, self.nodes, z) & closed
        zhat = z / np.where(nz > 0.0, nz, 1.0)[:, None]
        ratio = np.where(stick, 1.0, xi / np.where(nz > 0.0, nz, 1.0))
        proj = np.where(stick[:, None], z, xi[:, None] * zhat)
        eye = np.eye(tm.shape[1])[None] * tm[:, :, None] * tm[:, None, :]
        slip_d = ratio[:, None, None] * (eye - zhat[:, :, None] * zhat[:, None, :])
        dproj = np.where(stick[:, None, None], eye, slip_d)
        # d proj / d xi = zhat on slip, d xi = mu (d lambda - c d g) where lambda > c g
        dxi = np.where(~stick & (arg > 0.0), self.mu, 0.0)
        d_lam = -zhat * dxi[:, None]
        self.stick, self.xi, self._bound = stick, xi, arg > 0.0
        return (lt - proj, eye - dproj, -dproj * c[:, :, None], d_lam, -d_lam * self.c[:, None])

    def residual(self, x: PETSc.Vec, F: PETSc.Vec) -> None:
        lam, cg, C, self._da, self._db = self._state(x, F)
        if self.geometry is not None:  # the bulk's residual at the contact nodes
            self._R = F.getArray()[self.tangent_rows()]
        self.lam, self.gap = lam, cg / self.c
        self._y.copy(F)
        out = F.getArray()
        out[self.normal_rows] = self.D * C
        if self.mu is not None:
            rows = self.tangent_rows()
            y, q = self._y.getArray()[rows], self._g.getArray()[rows]
            self.lam_t = np.where(self.tmask, y, 0.0)
            self._fric = self._friction(lam, cg, y, q)
            CT = self._fric[0]
            out[rows[self.tmask]] = (self.D[:, None] * CT)[self.tmask]

    def jacobian(
        self, x: PETSc.Vec, K: PETSc.Mat, J: PETSc.Mat, *, bulk_changed: bool = False
    ) -> None:
        """At the x of the last residual (SNES evaluates F(x) before J(x)); T K is formed
        again after a search or when the bulk's Jacobian K changed."""
        assert self.T is not None and self.G is not None  # made by the search
        da, db = self._da, self._db
        if bulk_changed and self.TK is not None:
            self.TK.destroy()
            self.TK = None
        # searched at every residual: the geometry's variation (:mod:`.mortar_tangent`)
        geo = self._geometric(x) if self.geometry is not None else None
        if self.TK is None:
            self.TK = self.T.matMult(K)
            union = self.TK.copy()
            union.axpy(1.0, self.G, structure=PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
            if geo is not None:
                union.axpy(1.0, geo, structure=PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
            J.zeroEntries()
            J.axpy(1.0, union, structure=PETSc.Mat.Structure.DIFFERENT_NONZERO_PATTERN)
            union.destroy()
        if self.mu is not None:
            A, B = self._friction_blocks(da, db)
        else:
            A = self.TK.copy()
            s = self.TK.createVecLeft()
            s.set(1.0)
            s.getArray()[self.normal_rows] = self.D * da
            A.diagonalScale(L=s)
            B = self.G.copy()
            w = self.G.createVecLeft()
            w.getArray()[self.normal_rows] = self.D * self.c * db
            B.diagonalScale(L=w)
            s.destroy()
            w.destroy()
        J.zeroEntries()
        J.axpy(1.0, A, structure=PETSc.Mat.Structure.SUBSET_NONZERO_PATTERN)
        J.axpy(1.0, B, structure=PETSc.Mat.Structure.SUBSET_NONZERO_PATTERN)
        A.destroy()
        B.destroy()
        if geo is not None:
            J.axpy(1.0, geo, structure=PETSc.Mat.Structure.SUBSET_NONZERO_PATTERN)
            geo.destroy()

    def _geometric(self, x: PETSc.Vec) -> PETSc.Mat:
        """The variation of the mortar integrals and the nodal normals with the displacement
        at x (the last residual's), as a matrix of the Jacobian's layout
        (:mod:`.mortar_tangent`). Collective."""
        assert self.geometry is not None
        lay = self.layout
        bs = lay.bs
        records, m_records = geometry_derivatives(self.geometry, bs)
        j, (col, val) = _to_owners(self.comm, self.ranges, records[0], list(records[1:]))
        mj, (mk, mcol, dM) = _to_owners(self.comm, self.ranges, m_records[0], list(m_records[1:]))
        rows = self.tangent_rows()
        u = x.getArray(readonly=True)[rows]
        du = np.zeros_like(u)
        if self.mu is not None:
            assert self.previous is not None  # set with mu
            du = u - self.previous.x.array[rows]
        state = NodeState(
            R=self._R,
            x=lay.X.getArray()[rows] + u,
            du=du,
            shift=self.smoothed - self.pair.hidden() * self.overlap,
            free=self.free,
            comp=self.comp,
            tmask=self.tmask,
            active=self._db > 0.5,
            c0=self.r0 * self.pair.E,
            ncp=self.ncp,
            E=self.pair.E,
            mu=self.mu,
            stick=getattr(self, "stick", None),
            bound=getattr(self, "_bound", None),
            objective=self._history if self.objective else None,
        )
        own, master = tangent_entries(
            self.nodes, state, (j, col, val), (mj, mk, mcol, dM), self.m_entries, bs
        )
        _, (m_r, m_c, m_v) = _to_owners(self.comm, self.ranges, master[0] // bs, list(master))
        return _owned_matrix(
            lay,
            np.concatenate([own[0], m_r]),
            np.concatenate([own[1], m_c]),
            np.concatenate([own[2], m_v]),
        )

    def _friction_blocks(self, da: np.ndarray, db: np.ndarray) -> tuple[PETSc.Mat, PETSc.Mat]:
        """(P T K, Q G): the nodal blocks P, Q (identity and zero away from the contact nodes)
        of the derivative of the rows (normal C, tangential C_T) with respect to y = T R
        (lambda, lambda_T) and q = G u (g, v)."""
        assert self.TK is not None and self.G is not None  # formed by the Jacobian
        lay = self.layout
        gdim, bs, m = lay.gdim, lay.bs, len(self.nodes)
        _, d_lt, d_v, d_lam, d_g = self._fric
        comp, idx = self.comp, np.arange(m)
        P = np.zeros((m, bs, bs))
        P[:, range(bs), range(bs)] = 1.0
        P[:, :gdim, :gdim] = np.where(self.tmask[:, :, None], d_lt, P[:, :gdim, :gdim])
        P[idx, :gdim, comp] = np.where(self.tmask, d_lam, P[idx, :gdim, comp])
        P[idx, comp, :] = 0.0
        P[idx, comp, comp] = da
        Q = np.zeros((m, bs, bs))
        Q[:, :gdim, :gdim] = np.where(self.tmask[:, :, None], d_v, 0.0)
        Q[idx, :gdim, comp] = np.where(self.tmask, d_g, 0.0)
        Q[idx, comp, comp] = self.c * db
        # the normal and tangent rows are D_j C (the fixed components' rows stay R_jc)
        scale = np.where(self.tmask, self.D[:, None], 1.0)
        scale[idx, comp] = self.D
        P[:, :gdim] *= scale[:, :, None]
        Q[:, :gdim] *= scale[:, :, None]
        j_rows = blocked_rows(self.nodes, bs)
        r = np.repeat(j_rows[:, :, None], bs, axis=2).ravel()
        c = np.repeat(j_rows[:, None, :], bs, axis=1).ravel()
        others = np.ones(lay.n_owned, dtype=bool)
        others[(self.nodes - lay.start).astype(np.int64)] = False
        diag = blocked_rows(np.flatnonzero(others) + lay.start, bs).ravel()
        Pm = _owned_matrix(
            lay,
            np.concatenate([r, diag]),
            np.concatenate([c, diag]),
            np.concatenate([P.ravel(), np.ones(len(diag))]),
        )
        Qm = _owned_matrix(lay, r, c, Q.ravel())
        A, B = Pm.matMult(self.TK), Qm.matMult(self.G)
        Pm.destroy()
        Qm.destroy()
        return A, B

    # -- what the post-processing reads ----------------------------------------------------
    def _gap_vectors(self, u: np.ndarray) -> np.ndarray:
        """(m, gdim) the weighted gap vectors b_j = sum_k (M_jk / D_j) x_k - x_j of the
        contact nodes at x = X + u (``u`` the local array) under the last search's weights:
        b_j . n_j = g_j from the gap rows, t_jc . b_j = -(the slip rows' t_jc . (x_j - sum_k
        (M_jk / D_j) x_k)) on the free tangents."""
        assert self.G is not None  # made by the search
        lay = self.layout
        n = lay.n_owned * lay.bs
        x = self.G.createVecRight()
        x.getArray()[:] = lay.X.getArray()[:n] + u[:n]
        y = self.G.createVecLeft()
        self.G.mult(x, y)
        gy = y.getArray()
        g = gy[self.normal_rows]
        t_part = np.where(self.tmask, gy[self.tangent_rows()], 0.0)
        x.destroy()
        y.destroy()
        return g[:, None] * self.normal - np.einsum("jc,jci->ji", t_part, self.tangents)

    def _objective_slip(self, u: np.ndarray) -> None:
        """Make the slip rows frame-indifferent: v_j = t_jc . (du_j - sum_k (M_jk / D_j) du_k)
        + t_jc . (R_j b_j,old - b_j,old), b_j the weighted gap vector at the last converged
        step and R_j the least rotation of the nodal normal since then (the mortar
        counterpart of the correction g (n - n_old) of Mlika, Renard and Chouly 2017,
        doi:10.1016/j.cma.2017.01.003). Under a rigid rotation R of both bodies the weights do
        not change and the jump's increment is t_jc . (b_j,old - R b_j,old): v_j = 0 whatever
        the gap and the tangential part of b (the dual weights' normal is the nodal average,
        so b is not along n_j on a curved or kinked interface). The correction is held at the
        search's normal, as the rest of the rows. A node closed at the last step only."""
        assert self.g0 is not None
        nodes_old, b_kept, n_kept = self._b_old
        self._history = None
        if len(nodes_old) == 0:
            return
        pos = np.minimum(np.searchsorted(nodes_old, self.nodes), len(nodes_old) - 1)
        has = nodes_old[pos] == self.nodes
        b_old, n_old = b_kept[pos[has]], n_kept[pos[has]]
        change = transport(n_old, self.normal[has], b_old) - b_old
        self._history = (has, b_old, n_old)
        correction = np.zeros((len(self.nodes), self.layout.gdim))
        correction[has] = np.einsum("jci,ji->jc", self.tangents[has], change)
        rows = self.tangent_rows()[self.tmask]
        self.g0.getArray()[rows] += correction[self.tmask]

    def converged(self) -> None:
        """A step converged: the number of closed nodes (:meth:`lost`). The slip history is
        the problem's last converged state; with the frame-indifferent slip also the weighted
        gap vectors of the closed nodes (:meth:`_objective_slip`). Collective."""
        from mpi4py import MPI

        closed = self.lam - self.c * self.gap > 0.0
        self.closed_before = self.comm.allreduce(int(np.sum(closed)), op=MPI.SUM)
        if not self.objective:
            return
        assert self.previous is not None  # set with mu
        b = self._gap_vectors(self.previous.x.array)
        self._b_old = (self.nodes[closed], b[closed], self.normal[closed])

    #: the slave nodes closed at the last converged step (all ranks)
    closed_before = 0

    def lost(self) -> str | None:
        """After a converged solve: why it is no solution of the contact problem, or None. A
        solve whose last search found no contact node (no slave node's support over the master
        surface), while nodes were closed at the last converged step, has lost the contact: a
        Newton iterate carried one body through the other, and the solve converged with the
        bodies overlapping and no contact force (seen on shallow-ironing as the die starts to
        slide). Collective."""
        from mpi4py import MPI

        if self.closed_before > 0 and self.comm.allreduce(len(self.nodes), op=MPI.SUM) == 0:
            return (
                f"the contact was lost ({self.closed_before} slave nodes closed at the last "
                "step, no contact node now: a Newton iterate carried one body through the "
                "other)"
            )
        return None

    def force(self) -> float:
        """The normal contact force sum_j D_j lambda_j of the pair."""
        from mpi4py import MPI

        return self.comm.allreduce(float(np.sum(self.D * self.lam)), op=MPI.SUM)

    def slave_force(self) -> np.ndarray:
        """The force vector of the pair on the slave body, -sum_j D_j (lambda_j n_j
        + sum_c lambda_T,jc t_jc). Collective."""
        from mpi4py import MPI

        traction = self.lam[:, None] * self.normal
        if self.mu is not None:
            traction = traction + np.einsum("jc,jci->ji", self.lam_t, self.tangents)
        local = -np.sum(self.D[:, None] * traction, axis=0)
        return self.comm.allreduce(np.asarray(local, dtype=float).reshape(-1), op=MPI.SUM)

    def force_parts(self) -> tuple[np.ndarray, np.ndarray]:
        """The normal and tangential parts of :meth:`slave_force` (whose sum they are to
        round-off): -sum_j D_j lambda_j n_j and -sum_j D_j sum_c lambda_T,jc t_jc (zero
        without friction). Collective."""
        from mpi4py import MPI

        normal = -np.sum(self.D[:, None] * self.lam[:, None] * self.normal, axis=0)
        tangential = np.zeros_like(normal)
        if self.mu is not None:
            traction = np.einsum("jc,jci->ji", self.lam_t, self.tangents)
            tangential = -np.sum(self.D[:, None] * traction, axis=0)
        local = np.stack([normal, tangential]).astype(float)
        total = self.comm.allreduce(local, op=MPI.SUM)
        return total[0], total[1]

    def friction_state(self) -> dict[str, float]:
        """Sums over this rank's contact nodes: the contact measure (the nodes where the
        friction bound is positive) and the stick measure on the reference surface (weights
        D0_j, as :meth:`nodal`), the bound mu lambda, the excess of |lambda_T| over it and the
        sum of |lambda_T| as forces (weights D_j)."""
        assert self.mu is not None  # with friction
        closed = self.xi > 0.0
        bound = self.mu * self.lam
        excess = np.maximum(np.linalg.norm(self.lam_t, axis=1) - bound, 0.0)
        D, D0 = self.D, self.D0
        return {
            "measure": float(np.sum(D0[closed])),
            "stick": float(np.sum(D0[self.stick])),
            "bound": float(np.sum(D * bound)),
            "excess": float(np.sum(D * excess)),
            "tangential": float(np.sum(D * np.linalg.norm(self.lam_t, axis=1))),
        }

    def friction_work(self) -> float:
        """Friction's dissipation on the last step, sum_j D_j lambda_T,j . v_j over the contact
        nodes (v_j the weighted slip increment of the step, at the last residual): the work
        of the tangential forces -D_j lambda_T,jc t_jc on the slave node and M_jk lambda_T,jc
        t_jc on the master nodes, sign reversed. Collective."""
        from mpi4py import MPI

        assert self.mu is not None  # with friction
        slip = np.where(self.tmask, self._g.getArray()[self.tangent_rows()], 0.0)
        local = float(np.sum(self.D * np.einsum("jc,jc->j", self.lam_t, slip)))
        return self.comm.allreduce(local, op=MPI.SUM)

    def nodal_friction(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Per node of :meth:`nodal`: the nominal |lambda_T| (D_j |lambda_T| / D0_j), |weighted
        slip increment of the step| and the stick mask."""
        slip = np.where(self.tmask, self._g.getArray()[self.tangent_rows()], 0.0)
        traction = self.D * np.linalg.norm(self.lam_t, axis=1) / self.D0
        return traction, np.linalg.norm(slip, axis=1), self.stick

    def record_start(self) -> None:
        """An interference fit: the initial overlap max(-g0_j, 0) of every contact node from
        the weighted gaps of the last search (at the start, u = 0), hidden by the
        complementarity in the proportion ``pair.hidden()`` of the load program."""
        gaps = self.search_gaps()
        self._initial = (self.nodes.copy(), np.maximum(-gaps, 0.0))
        self.overlap = self._overlap_of(self.nodes)

    def _overlap_of(self, nodes: np.ndarray) -> np.ndarray:
        """The recorded initial overlaps of the sorted owned ``nodes`` (0 without)."""
        out = np.zeros(len(nodes))
        if self._initial is None or not len(self._initial[0]):
            return out
        known, values = self._initial
        pos = np.minimum(np.searchsorted(known, nodes), len(known) - 1)
        hit = known[pos] == nodes
        out[hit] = values[pos[hit]]
        return out

    def search_gaps(self, facets: bool = False) -> np.ndarray:
        """The weighted nodal gaps g_j of this rank's contact nodes at the last search;
        ``facets``: between the facets (without the smoothing's correction, which at a first
        touch point of two convex surfaces reads -kappa h^2 / 6 from the dual weights: the
        overlap check's)."""
        if self.g0 is None:
            return np.zeros(0)
        gaps = self.g0.getArray()[self.normal_rows] + 0.0
        return gaps + self.smoothed if facets else gaps

    def nodal(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Owned contact nodes: (global node, reference weight D0_j, nominal pressure
        D_j lambda_j / D0_j, gap g_j). The nodal force D_j lambda_j per the node's support
        measured on the reference surface (D0_j = int N_j over it): the bulk is small-strain, its
        tractions sigma n are per reference area, while lambda_j is per current area (the
        surface strain apart: about 1 % under the Hertz contacts' pressures, and lambda_j
        would depend on whether the last search was at the start or the end of a step)."""
        return self.nodes, self.D0, self.D * self.lam / self.D0, self.gap

    def nodal_normals(self) -> np.ndarray:
        """The unit normal n_j of each node of :meth:`nodal` (the weighted mean of the slave
        facets' normals over its support, the one its multiplier acts along)."""
        return self.normal


def _owned_matrix(
    lay: NodeLayout, rows: np.ndarray, cols: np.ndarray, vals: np.ndarray
) -> PETSc.Mat:
    """The AIJ matrix of the node layout with the entries (global row, global column, value)
    of owned rows (duplicates summed), built from local CSR arrays in one call."""
    n_local = lay.n_owned * lay.bs
    n_global = lay.imap.size_global * lay.bs
    start = lay.start * lay.bs
    key = (rows.astype(np.int64) - start) * n_global + cols.astype(np.int64)
    uniq, inv = np.unique(key, return_inverse=True)
    values = np.bincount(inv, weights=vals, minlength=len(uniq))
    local_rows, cols_u = np.divmod(uniq, n_global)
    indptr = np.searchsorted(local_rows, np.arange(n_local + 1))
    M = PETSc.Mat().createAIJ(
        ((n_local, n_global), (n_local, n_global)),
        csr=(indptr.astype(PETSc.IntType), cols_u.astype(PETSc.IntType), values),
        comm=lay.comm,
    )
    M.assemble()
    return M
