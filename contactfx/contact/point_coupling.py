"""Contact terms between two bodies at the Gauss points of a surface (penalty, Nitsche), the
other body's basis functions evaluated at the projected point.

For every Gauss point x of a slave facet (current configuration), the search
(:meth:`contactfx.contact.pair.ContactPair.search`) finds the closest point y on the master
surface, its facet, barycentric coordinates and outward normal n_m. With n = -n_m,

    g(u) = (x_s + u_s(x) - y - u_m(y)) . n_m     (> 0 apart),
    [v] . n = (v_s(x) - v_m(y)) . n               (the relative test function),

and sigma_n(u) = n . sigma(u_s) n the normal stress of the slave body at x (P1: constant in the
slave cell, from the cell's gradients and its Lame constants). The methods' pointwise laws:

* penalty: p = kappa [-g]_+, residual int p [v].n, kappa = kappa0 E / h;
* Nitsche (biased): P = [-sigma_n(u) - gamma g]_+, residual
  int P ([v].n - theta / gamma sigma_n(v)) - theta / gamma int sigma_n(u) sigma_n(v),
  gamma = gamma0 E / h (E and h of the slave cell): the rigid-obstacle Nitsche of
  :mod:`contactfx.contact.nitsche` with the obstacle replaced by the master body (Chouly,
  Mlika & Renard 2018, doi:10.1007/s00211-018-0959-1, the biased variant);
* Nitsche (unbiased): the same with each body as the slave in turn, half weights each (ibid.).

Jacobian: the derivatives of P and of the stress terms with respect to both bodies' dofs
(the coupling blocks included), exact for the projection of the last search. With
``--search-update newton`` the projection (y, n_m) is recomputed at every residual and its
derivatives are not linearised: for the closest-point projection they vanish in the gap to
first order (n_m is orthogonal to the master tangent and x - y is parallel to n_m), what is
left out is the curvature (geometric) stiffness.

Points whose projection falls off the master surface are not in contact, decided by the
whole surface's rim; a point's master facet is kept while it stays on it or just past its
edge at finite strain (:mod:`contactfx.contact.closest_point`).

Finite strain (``ContactPair.finite_strain``, the two-body kind with a hyperelastic material;
penalty, and Nitsche as below, each with or without friction; always searched at every Newton
iteration):
everything above is already
in the current configuration, x = X + u on both sides: the slave Gauss points, the master facets,
their normal n_m and the closest point y. The weights are the Gauss weights of the REFERENCE
slave facet, so P = kappa [-g]_+ is a nominal pressure (force per unit reference area of the
slave) acting along the current master normal: the large-deformation penalty of Wriggers 2006
(Computational Contact Mechanics, 2nd ed., doi:10.1007/978-3-540-32609-0, chapter 4, the
penalty term int kappa g_N delta g_N dA over the reference slave surface; section 4.2 for
the closest-point projection and its variations). Under finite strain the terms the small-
strain Jacobian leaves out (the variation of the master normal with the rotation of the
master facet, and of the projection's coordinate with the sliding of the point, of relative
size q / E per Newton step) stall Newton at strains of several %; the Jacobian of a point
whose projection falls inside its master facet is then the exact derivative of its residual
w kappa [-g]_+ ([v_s(x)] - [v_m(y(u))]) . n(u) in the dofs of the slave cell and the master
facet, with y the closest point on the master facet's line (2D) or plane (3D) and n its unit
normal, both functions of u: computed by complex-step differentiation of the vectorised
residual (Squire and Trapp 1998, doi:10.1137/S003614459631241X), exact to round-off, which
gives Newton's quadratic convergence without writing Wriggers' geometric terms by hand.
Points at a vertex of the master surface keep the Jacobian above.

Nitsche between finite-strain bodies: sigma_n(u) becomes the slave's first
Piola traction on its reference facet along the current normal, T_n(u) = n . P(F) N (N the
reference facet's outward unit normal, F constant in the P1 slave cell), a nominal pressure as
the penalty's, and sigma_n(v) its derivative with n held, T_n(v) = n . (dP/dF : grad v) N
(the large-deformation Nitsche of Mlika, Renard and Chouly 2017,
doi:10.1016/j.cma.2017.01.003); :func:`first_piola` gives P and dP/dF of neo-Hookean, Saint
Venant-Kirchhoff and linear slave cells in closed form. Residual and Jacobian come from
:meth:`PointCoupling._point_terms` by complex steps, as for penalty friction below.

Nitsche friction between finite-strain bodies (Coulomb; the same paper's large-deformation
Nitsche friction): sigma_T(u) of the small-strain law becomes the tangential part of the same
traction, T_T(u) = (I - n n) P(F) N, and

    t = proj_{B(0, bound)}(T_T(u) - gamma slip),   bound = mu P (Coulomb; Tresca's threshold
    where closed),

with the penalty friction's frame-indifferent slip below (no traction history: the trial is
the stress's); residual, over the reference slave surface,
int P ([v].n - theta / gamma T_n(v)) - theta / gamma int T_n(u) T_n(v)
- int t . ([v] - theta / gamma T_T(v)) - theta / gamma int T_T(u) . T_T(v),
T_T(v) = (I - n n)(dP/dF : grad v) N with n held. Its stick is regularised by the step's slip,
t = T_T(u) - gamma slip: an interface at rest keeps relaxing by (T_T(u) - t) / gamma a step.
At finite strain the slip's offset is carried into the current configuration by the rotation
of the master surface (below), so that a step rotating the contact does not shorten it
(tests/verification/test_large_sliding.py).

Penalty friction (Coulomb |t| <= mu P, or Tresca |t| <= s where closed), small or finite
strain: a return map at every Gauss point, t = proj_{B(0, bound)}(t_trial), with the trial

    t_trial = R(n_old -> n) t_old - kappa P_T ([u] - [u_old] + g_old n_m,old),

the last converged step's traction t_old carried by the rotation of the master surface R (in
2D the rotation from n_old to n; in 3D, at finite strain, the rotation of the point's master
facet over the step, the orthonormal frame of its first edge and normal at the last converged
and the current positions, then the least rotation from R n_old to n for a point that moved
to another facet; in 3D at small strain the least rotation about n_old x n), and the slip
increment made frame-indifferent: the increment of the jump less that of the gap vector
g n_m, whose rotation with the bodies is no slip (Mlika, Renard and Chouly 2017,
doi:10.1016/j.cma.2017.01.003, the correction g (n - n_old) of GetFEM's ``frame_indifferent``
option); at finite strain that vector (the step's slide measured in the last converged
configuration) is carried by R too, so that a step that turns the bodies by dtheta, about
any axis, does not shorten it by 1 - cos(dtheta) nor leave it behind a spin about the
normal. The history (t_old, g_old n_m,old,
n_old; Nitsche reads g_old n_m,old only) is kept per Gauss point of the slave surface (the
same points at every search) and moved on at each converged step (``converged``). Residual
and Jacobian come from one function of the nodal positions (:meth:`PointCoupling._point_terms`),
differentiated by complex steps: with the projection frozen (small strain, and points at a
master vertex) or recomputed (finite strain, inside a facet). A tie (the law's argument, or
the trial against the bound, at round-off) takes the closed and sticking branch on every
partition.

"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, TypeAlias

import numpy as np
from petsc4py import PETSc

from contactfx.contact.closest_point import project
from contactfx.contact.coupling import NodeLayout, blocked_rows
from contactfx.contact.pair import Side, facet_normals
from contactfx.contact.point_readout import PointReadout, State
from contactfx.contact.projection import (
    gauss_segment,
    gauss_triangle,
    transport,
)
from contactfx.contact.reversal import ReversalMemory
from contactfx.mechanics.elasticity import basis_tractions
from contactfx.mechanics.piola import LINEAR, STRESS_MODELS, first_piola

if TYPE_CHECKING:
    from collections.abc import Callable

    from contactfx.contact.pair import ContactPair

__all__ = ["PointCoupling", "Law"]

#: the arrays of one direction's Gauss points (:meth:`PointCoupling._points`), by name
_Points: TypeAlias = dict[str, np.ndarray]


@dataclass(frozen=True)
class Law:
    """The pointwise law: ``kind`` "penalty" (``stiffness`` = kappa0) or "nitsche"
    (``stiffness`` = gamma0, ``theta``)."""

    kind: str
    stiffness: float
    theta: int = 0


def _cell_gradients(X: np.ndarray) -> np.ndarray:
    """(m, d + 1, gdim) gradients of the P1 basis of simplices X (m, d + 1, gdim)."""
    J = np.swapaxes(X[:, 1:] - X[:, :1], 1, 2)  # (m, gdim, d)
    Jinv = np.linalg.inv(J)  # (m, d, gdim): rows are grad lambda_1..d
    return np.concatenate([-Jinv.sum(axis=1, keepdims=True), Jinv], axis=1)


def _outward_normals(facets: np.ndarray, cells: np.ndarray) -> np.ndarray:
    """(m, gdim) unit normals of the facets (m, d, gdim) pointing away from their cells
    (m, d + 1, gdim) (2D: segments, 3D: triangles)."""
    e = facets[:, 1:] - facets[:, :1]
    if facets.shape[2] == 2:
        n = np.stack([e[:, 0, 1], -e[:, 0, 0]], axis=1)
    else:
        n = np.cross(e[:, 0], e[:, 1])
    n /= np.linalg.norm(n, axis=1)[:, None]
    out = np.einsum("mg,mg->m", n, facets[:, 0] - cells.mean(axis=1))
    return np.where(out[:, None] < 0.0, -n, n)


def nitsche_finite_strain_refusal(materials: list[str]) -> str | None:
    """Why finite-strain Nitsche between two bodies refuses the bodies' materials (their
    names), or None: its consistency term evaluates the stress of the STRESS_MODELS only
    (frictionless or with Coulomb friction)."""
    for name in materials:
        if name not in STRESS_MODELS:
            return (
                "nitsche between two finite-strain bodies evaluates the stress of "
                f"{', '.join(STRESS_MODELS)} bodies, not {name}: use --method penalty or mortar"
            )
    return None


class _Directed:
    """One direction of the pair (slave -> master) with its weight and Gauss points."""

    def __init__(
        self,
        slave: Side,
        master: Side,
        weight: float,
        lame: np.ndarray,
        model: np.ndarray | None = None,
    ) -> None:
        self.slave, self.master, self.weight = slave, master, weight
        self.lame = lame  # (m, 3): E, lambda, mu of each slave facet's cell
        #: (m,) the stress model of each slave facet's cell (finite-strain Nitsche,
        #: :func:`first_piola`): LINEAR, NEO_HOOKEAN or SVK
        self.model = np.full(len(lame), LINEAR, dtype=np.int64) if model is None else model
        d = slave.local.shape[1]
        gdim = slave.cell_X.shape[-1] if slave.cell_X.ndim == 3 else d
        # (a rank without facets of this side: empty arrays, the collectives still run)
        self.grads = _cell_gradients(slave.cell_X) if len(slave) else np.zeros((0, d + 1, gdim))
        # position of each facet vertex among its cell's nodes
        self.pos = np.array(
            [
                [np.flatnonzero(c == v)[0] for v in f]
                for f, c in zip(slave.local, slave.cell_local, strict=True)
            ],
            dtype=np.int64,
        ).reshape(-1, d)
        X = slave.cell_X
        edges = [np.linalg.norm(X[:, i] - X[:, j], axis=-1) for i in range(d + 1) for j in range(i)]
        self.h = np.max(edges, axis=0) if len(slave) else np.zeros(0)
        #: (m, gdim) the outward unit normal of each slave facet in the reference configuration
        self.N_ref = _outward_normals(slave.X, X) if len(slave) else np.zeros((0, gdim))
        if d == 2:
            q, w = gauss_segment(2)
            self.qbary = np.stack([1.0 - q, q], axis=1)
        else:
            self.qbary, w = gauss_triangle(2)
        self.qweight = w
        #: penalty friction's history at the last converged step, per Gauss point (the slave
        #: facets' points are the same at every search): the tangential traction t_old, the
        #: normal gap vector g n_m and the master normal n_m
        self._history: dict[str, np.ndarray] = {}
        #: per Gauss point the sorted global nodes of its master facet at the last search
        #: (-1: none)
        self.kept = np.zeros((0, d), dtype=np.int64)
        #: an interference fit: per Gauss point the initial overlap max(-g0, 0) (the gap at
        #: the start, :meth:`PointCoupling.record_start`; empty: none)
        self.overlap = np.zeros(0)

    def history(self, n: int, gdim: int) -> dict[str, np.ndarray]:
        """The history arrays (zero before the first converged step), shared with the
        points' dicts and updated in place at each converged step."""
        if not self._history:
            self._history = {k: np.zeros((n, gdim)) for k in ("t_old", "d_old", "n_old")}
        return self._history


class PointCoupling(PointReadout, ReversalMemory):
    """Penalty / Nitsche terms of a contact pair at Gauss points (module docstring)."""

    # set by the search (update) and by the residual
    points: list[_Points]
    state: list[State]
    _local: PETSc.Vec
    _xvec: PETSc.Vec

    def __init__(self, pair: ContactPair, law: Law, unbiased: bool = False) -> None:
        self.pair, self.law = pair, law
        self.layout: NodeLayout = pair.layout
        self.comm = self.layout.comm
        self.search_each_newton = pair.search_each_newton
        assert pair.slave_lame is not None  # set by the problem, as master_lame
        weight = 0.5 if unbiased else 1.0
        dirs = [_Directed(pair.slave, pair.master, weight, pair.slave_lame, pair.slave_model)]
        if unbiased:
            assert pair.master_lame is not None
            dirs.append(
                _Directed(pair.master, pair.slave, 0.5, pair.master_lame, pair.master_model)
            )
        self.dirs = dirs
        self.scatter: PETSc.Scatter | None = None
        #: finite strain: the Jacobian with the variation of the master normal and of the
        #: projection (module docstring)
        self.geometric = pair.finite_strain
        #: Coulomb coefficient (None: frictionless or Tresca), Tresca's threshold (None:
        #: frictionless or Coulomb) and the last converged state (history)
        self.mu, self.threshold = pair.mu, pair.threshold
        self.frictional = self.mu is not None or self.threshold is not None
        self.previous = pair.previous
        #: penalty friction: the tangential traction by a return map with a per-point history
        #: (module docstring), residual and Jacobian from :meth:`_point_terms`
        self.penalty_friction = self.frictional and law.kind == "penalty"
        #: finite-strain Nitsche (frictionless or with friction): the slave's first Piola
        #: traction in the consistency term, from :meth:`_point_terms`
        self.nitsche_finite_strain = pair.finite_strain and law.kind == "nitsche"
        #: residual and Jacobian from :meth:`_point_terms` (penalty friction, finite-strain
        #: Nitsche), else from :meth:`_law`
        self.pointwise = self.penalty_friction or self.nitsche_finite_strain
        #: a per-point history moved on at each converged step (:meth:`converged`): penalty
        #: friction and finite-strain Nitsche friction (small-strain Nitsche friction reads
        #: the last step's displacement only)
        self.keeps_history = self.frictional and self.pointwise
        #: the frame-indifferent slip (False: the jump's increment alone, which reads the
        #: rotation of the penetration vector g n as slip: the objectivity test's contrast)
        self.objective = True
        #: friction: Newton's reversal guard (:mod:`.reversal`), at the Gauss points of each
        #: direction (named by their positions: the slave facets' points are the same at
        #: every search); the pointwise laws' points that it makes stick at the last residual
        self.init_reversals(self.frictional)
        self._forced: dict[int, np.ndarray] = {}

    # -- search ---------------------------------------------------------------------------
    def update(self, u: np.ndarray) -> None:
        lay = self.layout
        gdim, bs = lay.gdim, lay.bs
        ub = u.reshape(-1, bs)[:, :gdim]
        points = [self._points(dr, ub) for dr in self.dirs]
        for dr, p in zip(self.dirs, points, strict=True):
            dr.kept = p["facet_nodes"]
        needed = np.unique(np.concatenate([p["rows"].ravel() for p in points]))
        self._scatter_setup(needed)
        self.points = points
        u_upd = self._gather_u(u)
        u_prev = None
        if self.frictional:
            assert self.previous is not None  # set with the friction law
            u_prev = self._gather_u(self.previous.x.array)
        for p in points:
            p["idx"] = np.searchsorted(needed, p["rows"])
            # reference positions of the involved dofs: current at the search minus u then
            p["X"] = p["x_search"] - u_upd[p["idx"]]
            if u_prev is not None:
                p["u_prev"] = u_prev[p["idx"]]

    def missed(self, u: np.ndarray) -> int:
        """The number of Gauss points (all ranks) that a search at x = X + u pairs with the
        master surface and the last search did not. Collective; the coupling is unchanged."""
        from mpi4py import MPI

        lay = self.layout
        ub = u.reshape(-1, lay.bs)[:, : lay.gdim]
        new = 0
        for dr, old in zip(self.dirs, self.points, strict=True):
            now = self._points(dr, ub)["paired"]
            new += int(np.sum(now & ~old["paired"]))
        return self.comm.allreduce(new, op=MPI.SUM)

    def _points(self, dr: _Directed, ub: np.ndarray) -> _Points:
        lay, pair = self.layout, self.pair
        gdim, bs = lay.gdim, lay.bs
        slave, master = dr.slave.current(ub), dr.master.current(ub)
        near, _ = pair.search(slave, master, pairs=False)
        m, d = len(dr.slave), dr.slave.local.shape[1]
        nq = len(dr.qweight)
        xq = np.einsum("qb,mbg->mqg", dr.qbary, slave.x).reshape(-1, gdim)
        ref = dr.slave.X
        if d == 2:
            measure = np.linalg.norm(ref[:, 1] - ref[:, 0], axis=1)
        else:
            measure = 0.5 * np.linalg.norm(
                np.cross(ref[:, 1] - ref[:, 0], ref[:, 2] - ref[:, 0]), axis=1
            )
        w = (measure[:, None] * dr.qweight[None, :]).reshape(-1) * dr.weight
        facet = np.repeat(np.arange(m), nq)
        # finite strain (searched at every Newton iteration): the facets of the last search
        # kept while their points stay on them (:func:`.closest_point.keep_facets`)
        kept = dr.kept if self.pair.finite_strain and len(dr.kept) == len(xq) else None
        pick = project(xq, near, kept)
        paired = pick.index >= 0
        # slave cell shape functions at the points: the facet's vertices carry qbary
        N = np.zeros((m, nq, d + 1))
        for b in range(d):
            np.put_along_axis(
                N,
                dr.pos[:, None, b : b + 1].repeat(nq, axis=1),
                dr.qbary[None, :, b : b + 1].repeat(m, axis=0),
                axis=2,
            )
        N = N.reshape(-1, d + 1)
        k = np.where(paired, pick.index, 0)
        n_m = np.zeros((len(xq), gdim))
        if len(near):
            n_m[paired] = facet_normals(near.x[k[paired]])
        n = -n_m
        Nm = np.where(paired[:, None], np.nan_to_num(pick.bary), 0.0)
        # dofs of the point: slave cell nodes, then master facet nodes (gdim each)
        cell_nodes = dr.slave.cell_nodes[facet]
        master_nodes = near.nodes[k] if len(near) else np.zeros((len(xq), d), dtype=np.int64)
        rows = np.concatenate(
            [blocked_rows(cell_nodes, bs)[..., :gdim], blocked_rows(master_nodes, bs)[..., :gdim]],
            axis=1,
        ).reshape(len(xq), (d + 1 + d) * gdim)
        Jn = np.concatenate(
            [N[:, :, None] * n[:, None, :], -Nm[:, :, None] * n[:, None, :]], axis=1
        ).reshape(len(xq), (d + 1 + d) * gdim)
        E, lmbda, mu = (dr.lame[facet, i] for i in range(3))
        grads = dr.grads[facet]  # (P, d + 1, gdim)
        # sigma(N_a e_c) n of the slave cell's basis (the material's Hooke's law)
        traction = basis_tractions(grads, n, lmbda, mu)  # (P, d + 1, gdim, gdim)
        S = np.einsum("pacg,pg->pac", traction, n)  # n . sigma(N_a e_c) n
        S = np.concatenate([S, np.zeros((len(xq), d, gdim))], axis=1).reshape(
            len(xq), (d + 1 + d) * gdim
        )
        x_cell = dr.slave.cell_X[facet] + ub[dr.slave.cell_local[facet]]
        x_master = near.x[k] if len(near) else np.zeros((len(xq), d, gdim))
        x_search = np.concatenate([x_cell, x_master], axis=1).reshape(len(xq), (d + 1 + d) * gdim)
        scale = self.law.stiffness * E / dr.h[facet]
        extra: _Points = {}
        if self.frictional:
            P_T = np.eye(gdim)[None] - n[:, :, None] * n[:, None, :]
            Nfull = np.concatenate([N, -Nm], axis=1)  # (P, nodes)
            # [u] = Jvec^T u: rows (node, c) carry N_node e_c
            Jvec = (Nfull[:, :, None, None] * np.eye(gdim)[None, None]).reshape(
                len(xq), (d + 1 + d) * gdim, gdim
            )
            # the tangential part (I - n n) sigma(N_a e_c) n; zero on the master's rows
            ST = np.einsum("pacg,phg->pach", traction, P_T).reshape(len(xq), (d + 1) * gdim, gdim)
            ST = np.concatenate([ST, np.zeros((len(xq), d * gdim, gdim))], axis=1)
            extra = dict(Jvec=Jvec, ST=ST, P_T=P_T, bary=Nm, **dr.history(len(xq), gdim))
        if self.pair.finite_strain and self.law.kind == "nitsche":
            # the slave cell's stress (finite-strain Nitsche, :meth:`_nitsche_stress`)
            extra.update(
                bary=Nm,
                G=grads,
                N_ref=dr.N_ref[facet],
                model=dr.model[facet],
                lmbda=lmbda,
                mu=mu,
            )
        # a tie (the law's argument at round-off, as on coinciding flat surfaces at the start)
        # takes the active branch of the derivative: the branch of a gap within 1e-12 h of 0
        tie = 1e-12 * scale * dr.h[facet]
        return dict(
            **extra,
            rows=rows,
            N=N,
            overlap=dr.overlap if len(dr.overlap) == len(xq) else np.zeros(len(xq)),
            inside=paired & np.asarray(pick.inside, dtype=bool),
            Jn=Jn,
            S=S,
            w=w,
            paired=paired,
            scale=scale,
            n=n,
            tie=tie,
            x_search=x_search,
            N_facet=np.repeat(dr.qbary[None], m, axis=0).reshape(-1, d),
            slave_nodes=dr.slave.nodes[facet],
            # the master facet's global nodes and the point's barycentric coordinates on it
            # (zero off the master): the unbiased variant's second direction lumps its values
            # to the first direction's slave nodes through them (:meth:`_lumped`)
            master_nodes=master_nodes,
            Nm=Nm,
            facet_nodes=np.where(paired[:, None], np.sort(master_nodes, axis=1), -1),
        )

    # -- communication of the involved dofs ----------------------------------------------
    def _scatter_setup(self, needed: np.ndarray) -> None:
        if self.scatter is not None:
            for obj in (self.scatter, self._local):
                obj.destroy()
        else:  # the scatter's source layout: the same at every search
            self._xvec = self.layout.X.duplicate()
        self._local = PETSc.Vec().createSeq(len(needed))
        idx = PETSc.IS().createGeneral(needed.astype(PETSc.IntType), comm=PETSc.COMM_SELF)
        self.scatter = PETSc.Scatter().create(self._xvec, idx, self._local, None)
        idx.destroy()

    def _gather(self, x: PETSc.Vec) -> np.ndarray:
        assert self.scatter is not None  # made by the search (update)
        self.scatter.scatter(
            x, self._local, addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD
        )
        return self._local.getArray().copy()

    def _gather_u(self, u: np.ndarray) -> np.ndarray:
        n = self.layout.n_owned * self.layout.bs
        self._xvec.getArray()[:] = u[:n]
        return self._gather(self._xvec)

    # -- residual and Jacobian ------------------------------------------------------------
    def _law(
        self, p: _Points, vals: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray | None]:
        """(P, dP/du coefficient vector, the stress term's value) at the points of p."""
        u = vals[p["idx"]]
        x = p["X"] + u
        g = np.where(p["paired"], -np.einsum("pi,pi->p", p["Jn"], x), np.inf)
        g = g + self.pair.hidden() * p["overlap"]  # an interference fit's hidden overlap
        law = self.law
        if law.kind == "penalty":
            arg = -p["scale"] * g
            P = np.maximum(arg, 0.0)
            dP = (arg > -p["tie"])[:, None] * p["scale"][:, None] * p["Jn"]
            return P, dP, g, None
        sn = np.einsum("pi,pi->p", p["S"], u)
        arg = -sn - p["scale"] * g
        P = np.maximum(arg, 0.0)
        dP = (arg > -p["tie"])[:, None] * (p["scale"][:, None] * p["Jn"] - p["S"])
        return P, dP, g, sn

    def _friction(
        self, p: _Points, vals: np.ndarray, P: np.ndarray, dP: np.ndarray, k: int
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Nitsche's friction: t = proj_{B(0, s)}(sigma_T(u) - gamma P_T [u - u_prev]), s = mu P
        (Coulomb) or Tresca's threshold where closed (P > 0), and its derivative (P, gdim,
        ndofs); the stick mask (with the reversal guard's points, direction k)."""
        u = vals[p["idx"]]
        gamma = p["scale"]
        Z = p["ST"] - gamma[:, None, None] * np.einsum("pig,pgh->pih", p["Jvec"], p["P_T"])
        z = np.einsum("pig,pi->pg", p["ST"], u) - gamma[:, None] * np.einsum(
            "pgh,pih,pi->pg", p["P_T"], p["Jvec"], u - p["u_prev"]
        )
        if self.mu is not None:
            s = self.mu * P
        else:
            assert self.threshold is not None  # frictional: Coulomb or Tresca
            s = np.where(P > 0.0, self.threshold, 0.0)
        nz = np.linalg.norm(z, axis=1)
        stick = nz <= s
        closed = P > 0.0
        ids = np.arange(len(z))
        self._record_trial(k, ids, z, ~stick & closed)
        stick |= self._reversed(k, ids, z) & closed
        zhat = z / np.where(nz > 0.0, nz, 1.0)[:, None]
        t = np.where(stick[:, None], z, s[:, None] * zhat)
        ratio = np.where(stick, 1.0, s / np.where(nz > 0.0, nz, 1.0))
        gdim = z.shape[1]
        proj = np.where(
            stick[:, None, None],
            np.eye(gdim)[None],
            ratio[:, None, None] * (np.eye(gdim)[None] - zhat[:, :, None] * zhat[:, None, :]),
        )
        dt = np.einsum("pgh,pih->pgi", proj, Z)
        if self.mu is not None:  # the bound's derivative (Tresca's is constant)
            dt += (~stick)[:, None, None] * self.mu * zhat[:, :, None] * dP[:, None, :]
        return t, dt, stick

    @property
    def stores_energy(self) -> bool:
        """Whether :meth:`energy` is the law's stored energy: frictionless at small strain
        (not with friction, nor for the laws of :meth:`_point_terms`)."""
        return not (self.frictional or self.pointwise or self.geometric)

    def energy(self, x: PETSc.Vec) -> float:
        """The energy the pair's law stores at the state ``x`` (where :attr:`stores_energy`),
        summed over the Gauss points (their weights) and the ranks (collective): the
        penalty's kappa / 2 [-g]_+^2 and Nitsche's theta / (2 gamma) (P^2 - sigma_n^2), the
        obstacle forms' densities (:meth:`contactfx.contact.nitsche.Nitsche.contact_energy`;
        with theta = 1 the residual's contact terms are its derivative)."""
        if not self.stores_energy:
            raise ValueError(
                "the pair's law stores no energy in this form (friction, finite strain)"
            )
        if self.scatter is None:  # not searched yet: no point paired
            return 0.0
        vals = self._gather(x)
        total = 0.0
        for p in self.points:
            P, _, _, sn = self._law(p, vals)
            density = P**2 if sn is None else self.law.theta * (P**2 - sn**2)
            total += float(np.sum(p["w"] * density / (2.0 * p["scale"])))
        return float(self.comm.allreduce(total))

    def residual(self, x: PETSc.Vec, F: PETSc.Vec) -> None:
        vals = self._gather(x)
        add = PETSc.InsertMode.ADD_VALUES
        self.state = []
        if self.pointwise:
            self._pointwise_residual(vals, F)
            return
        for k, p in enumerate(self.points):
            P, dP, g, sn = self._law(p, vals)
            r = P[:, None] * p["Jn"]
            if sn is not None and self.law.theta != 0:
                r -= (self.law.theta / p["scale"])[:, None] * (P + sn)[:, None] * p["S"]
            t = stick = slip = None
            if self.frictional:
                t, _, stick = self._friction(p, vals, P, dP, k)
                du = vals[p["idx"]] - p["u_prev"]
                slip = np.einsum("pgh,pih,pi->pg", p["P_T"], p["Jvec"], du)
                tt = (self.law.theta / p["scale"])[:, None]
                r -= np.einsum("pig,pg->pi", p["Jvec"] - tt[:, :, None] * p["ST"], t)
                if self.law.theta != 0:
                    sT = np.einsum("pig,pi->pg", p["ST"], vals[p["idx"]])
                    r -= tt * np.einsum("pig,pg->pi", p["ST"], sT)
            r *= p["w"][:, None]
            F.setValues(p["rows"].ravel(), r.ravel(), addv=add)
            self.state.append((P, g, t, stick, slip))
        F.assemblyBegin()
        F.assemblyEnd()

    def jacobian(
        self, x: PETSc.Vec, K: PETSc.Mat, J: PETSc.Mat, *, bulk_changed: bool = False
    ) -> None:
        vals = self._gather(x)
        J.zeroEntries()
        J.axpy(1.0, K, structure=PETSc.Mat.Structure.SUBSET_NONZERO_PATTERN)
        add = PETSc.InsertMode.ADD_VALUES
        theta = self.law.theta
        for k, p in enumerate(self.points):
            if self.pointwise:  # the whole law by complex steps (module docstring)
                every = np.ones(len(p["w"]), dtype=bool)
                A = self._tangent(p, vals, every, geometric=False, k=k)
            else:
                A = self._law_jacobian(p, vals, theta, k)
            if self.geometric:
                inside = p["inside"]
                A[inside] = self._tangent(p, vals, inside, geometric=True, k=k)
            keep = np.any(A != 0.0, axis=(1, 2))
            for rows, block in zip(p["rows"][keep], A[keep], strict=True):
                J.setValues(rows, rows, block, addv=add)
        J.assemble()

    def _law_jacobian(self, p: _Points, vals: np.ndarray, theta: int, k: int) -> np.ndarray:
        """(P, m, m): the Jacobian blocks of the penalty / Nitsche law (with Nitsche's
        Coulomb friction) at the projection of the last search, weighted (direction k)."""
        P, dP, _, sn = self._law(p, vals)
        A = np.einsum("pi,pj->pij", p["Jn"], dP)
        if sn is not None and theta != 0:
            t = (theta / p["scale"])[:, None]
            A -= np.einsum("pi,pj->pij", p["S"], t * (dP + p["S"]))
        if self.frictional:
            _, dt, _ = self._friction(p, vals, P, dP, k)
            tt = (theta / p["scale"])[:, None, None]
            A -= np.einsum("pig,pgj->pij", p["Jvec"] - tt * p["ST"], dt)
            if theta != 0:
                A -= tt * np.einsum("pig,pjg->pij", p["ST"], p["ST"])
        return A * p["w"][:, None, None]

    def _point_terms(
        self,
        p: _Points,
        x: np.ndarray,
        sel: np.ndarray,
        geometric: bool,
        forced: np.ndarray | None = None,
    ) -> dict[str, np.ndarray]:
        """The penalty terms of the points ``sel`` of p at the current nodal positions x
        (P, 2d + 1, gdim) of their slave cell and master facet, real or complex (what
        :meth:`_tangent` differentiates): ``r`` the residual w [-N tau, bary tau] with the
        traction on the slave tau = -P n + t, P = kappa [-g]_+ and, with friction, t the
        return map of the trial traction (module docstring); also P, g,
        the master normal n_m and with friction t, the stick mask and the slip. With
        ``geometric`` the master facet's unit normal and the closest point y on its line /
        plane are recomputed from x (their variations enter the derivative), else they are the
        search's (frozen). ``forced``: points of ``sel`` that stick whatever the trial (the
        reversal guard's)."""
        d = x.shape[1] // 2
        N = p["N"][sel]
        xs = np.einsum("pa,pag->pg", N, x[:, : d + 1])
        xm = x[:, d + 1 :]
        if geometric:
            e = xm[:, 1:] - xm[:, :1]  # (P, d - 1, gdim) the facet's edge vectors from vertex 0
            rel = xs - xm[:, 0]
            if d == 2:
                tan = e[:, 0]
                nm = np.stack([tan[:, 1], -tan[:, 0]], axis=1)
                xi = np.einsum("pg,pg->p", rel, tan) / np.einsum("pg,pg->p", tan, tan)
                bary = np.stack([1.0 - xi, xi], axis=1)
            else:
                nm = np.cross(e[:, 0], e[:, 1])
                G = np.einsum("pig,pjg->pij", e, e)
                b = np.einsum("pig,pg->pi", e, rel)
                det = G[:, 0, 0] * G[:, 1, 1] - G[:, 0, 1] * G[:, 1, 0]
                a1 = (G[:, 1, 1] * b[:, 0] - G[:, 0, 1] * b[:, 1]) / det
                a2 = (G[:, 0, 0] * b[:, 1] - G[:, 1, 0] * b[:, 0]) / det
                bary = np.stack([1.0 - a1 - a2, a1, a2], axis=1)
            # the unit normal without conjugation (analytic: complex steps pass through)
            nm = nm / np.sqrt(np.einsum("pg,pg->p", nm, nm))[:, None]
        else:
            nm, bary = -p["n"][sel], p["bary"][sel]
        gap = xs - np.einsum("pb,pbg->pg", bary, xm)
        g = np.einsum("pg,pg->p", gap, nm)
        # an interference fit's hidden overlap (a shift of the gap: the friction's gap vector
        # g n_m keeps the geometric gap)
        g_law = g + self.pair.hidden() * p["overlap"][sel]
        scale = p["scale"][sel]
        arg = -scale * g_law
        nitsche = self.law.kind == "nitsche"
        if nitsche:
            # the slave's first Piola traction P(F) N and its derivative (dP/dF : grad v) N;
            # their normal parts along n = -n_m (held in the derivative)
            T, dT = self._nitsche_stress(p, x[:, : d + 1], sel)
            Tn = -np.einsum("pg,pg->p", T, nm)
            S = -np.einsum("pig,pg->pi", dT, nm)
            arg = arg - Tn
        active = p["paired"][sel] & (arg.real > -p["tie"][sel])
        P = np.where(active, arg, 0.0)
        tau = P[:, None] * nm  # -P n with n = -n_m
        out = dict(P=P, g=g, nm=nm, g_law=g_law)
        if self.frictional:
            du = x - (p["X"][sel] + p["u_prev"][sel]).reshape(x.shape)
            jump = np.einsum("pa,pag->pg", N, du[:, : d + 1]) - np.einsum(
                "pb,pbg->pg", bary, du[:, d + 1 :]
            )
            # the frame-indifferent slip: the increment of the jump less that of the gap
            # vector, P_T([u] - [u_old] - (g n_m - g_old n_m_old)) with P_T g n_m = 0
            slip = jump + p["d_old"][sel] if self.objective else jump
            n_old = p["n_old"][sel]
            turn = self._turn(x - du, x, n_old, nm)
            if self.objective and self.geometric:
                # finite strain: that vector, jump + g_old n_m_old - g n_m, is the step's slide
                # in the last converged configuration (the offset of the point's master point
                # then): carried into the current one by the surface's rotation, so that a step
                # that turns the bodies does not shorten it by 1 - cos(dtheta) (a point without
                # history keeps it)
                offset = slip - g[:, None] * nm
                has = (np.einsum("pg,pg->p", n_old, n_old) > 0.0)[:, None]
                slip = np.where(has, turn(offset), offset)
            slip = slip - np.einsum("pg,pg->p", slip, nm)[:, None] * nm
            if nitsche:
                # Nitsche's trial: the slave's tangential traction T_T(u) = (I - n n) P(F) N
                # (a point off the master surface has no tangent plane: 0, as its T_n)
                paired = p["paired"][sel][:, None]
                TT = np.where(paired, T + Tn[:, None] * nm, 0.0)
                trial = TT - scale[:, None] * slip
            else:
                trial = turn(p["t_old"][sel]) - scale[:, None] * slip
            if self.mu is not None:
                bound = self.mu * P
            else:
                assert self.threshold is not None  # frictional: Coulomb or Tresca
                bound = np.where(active, self.threshold, 0.0)
            norm = np.sqrt(np.einsum("pg,pg->p", trial, trial))
            # closed as the normal law's branch is, and a tie (the trial at the round-off
            # of the bound, as with P and the slip both at round-off on coinciding faces at
            # the start) sticks: the same branch on every partition, whatever the round-off
            tie = p["tie"][sel]
            stick = active & (norm.real <= np.maximum(bound.real, 0.0) + tie)
            out.update(trial=trial.real, slipping=active & ~stick)
            if forced is not None:
                stick |= forced & active
            safe = np.where(norm.real > 0.0, norm, 1.0)
            t = np.where(stick[:, None], trial, (bound / safe)[:, None] * trial)
            tau = tau + t
            out.update(t=t, stick=stick, slip=slip)
        r = -np.concatenate([N[:, :, None] * tau[:, None, :], -bary[:, :, None] * tau[:, None]], 1)
        r = r.reshape(len(N), x.shape[1] * x.shape[2])
        if nitsche and self.law.theta != 0:
            # - theta / gamma (P + T_n(u)) T_n(v) on the slave cell's dofs
            cell = S.shape[1]
            r[:, :cell] -= (self.law.theta / scale * (P + Tn))[:, None] * S
            if self.frictional:
                # + theta / gamma (t - T_T(u)) . T_T(v), T_T(v) = (I - n n)(dP/dF : grad v) N
                # (n held): the small-strain residual's friction terms with sigma_T -> T_T
                ST = dT - np.einsum("pig,pg->pi", dT, nm)[:, :, None] * nm[:, None, :]
                ST = np.where(paired[:, :, None], ST, 0.0)
                r[:, :cell] += (self.law.theta / scale)[:, None] * np.einsum(
                    "pig,pg->pi", ST, t - TT
                )
        out["r"] = (p["w"][sel])[:, None] * r
        return out

    def _turn(
        self, x_old: np.ndarray, x: np.ndarray, n_old: np.ndarray, nm: np.ndarray
    ) -> Callable[[np.ndarray], np.ndarray]:
        """The rotation of the master surface over the step, as a map of tangential vectors
        (P, gdim) of the last converged configuration (module docstring): in 2D and at small
        strain the least rotation from n_old to n_m; in 3D at finite strain the rotation of
        the point's master facet (positions x_old, x: (P, 2 d + 1, 3), the facet the last
        d), the orthonormal frame (e_1 / |e_1|, n x e_1 / |e_1|, n) of its first edge and
        unit normal from the last converged to the current positions, exact for a rigid
        motion of any axis (a spin about the normal too), then the least rotation from the
        turned n_old to n_m (a point on another facet than at the last step). Analytic:
        complex steps pass through."""
        if x.shape[2] == 2 or not self.geometric:
            return lambda v: transport(n_old, nm, v)
        d = x.shape[1] // 2

        def frame(xm: np.ndarray) -> np.ndarray:
            e1, e2 = xm[:, 1] - xm[:, 0], xm[:, 2] - xm[:, 0]
            n = np.cross(e1, e2)
            f1 = e1 / np.sqrt(np.einsum("pg,pg->p", e1, e1))[:, None]
            f3 = n / np.sqrt(np.einsum("pg,pg->p", n, n))[:, None]
            return np.stack([f1, np.cross(f3, f1), f3], axis=2)  # columns

        R = np.einsum("pik,pjk->pij", frame(x[:, d + 1 :]), frame(x_old[:, d + 1 :]))

        def turn(v: np.ndarray) -> np.ndarray:
            return transport(np.einsum("pij,pj->pi", R, n_old), nm, np.einsum("pij,pj->pi", R, v))

        return turn

    @staticmethod
    def _nitsche_stress(
        p: _Points, xc: np.ndarray, sel: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """Finite-strain Nitsche: the first Piola traction of the slave on its reference facet
        T(u) = P(F) N (P, gdim) (unit normal N: force per unit reference area, as the
        penalty's P), and its derivative in the slave cell's dofs, T(v) = (dP/dF : grad v) N
        (P, (d + 1) gdim, gdim); F = sum_a x_a grad N_a of the P1 cell's current node positions
        xc (P, d + 1, gdim), the model of the cell's body (:func:`first_piola`). The normal
        part along the current slave normal n = -n_m is T_n(u) = n . T(u), T_n(v) = n . T(v)
        with n held, the tangential part T_T = (I - n n) T."""
        G = p["G"][sel]  # (P, d + 1, gdim) reference gradients of the cell's basis
        F = np.einsum("pag,pah->pgh", xc, G)
        stress, A = first_piola(F, p["model"][sel], p["lmbda"][sel], p["mu"][sel])
        N = p["N_ref"][sel]
        T = np.einsum("piJ,pJ->pi", stress, N)
        dT = np.einsum("piJkL,pJ,paL->paki", A, N, G)
        return T, dT.reshape(len(F), dT.shape[1] * dT.shape[2], dT.shape[3])

    def _tangent(
        self, p: _Points, vals: np.ndarray, sel: np.ndarray, geometric: bool, k: int
    ) -> np.ndarray:
        """(P, m, m): the exact derivative of the residual of :meth:`_point_terms` of the
        points ``sel`` in their m dofs, by complex steps (one per dof, vectorised over the
        points), with the reversal guard's sticking points of the last residual (direction
        k)."""
        forced = self._forced.get(k)
        forced = None if forced is None else forced[sel]
        gdim = self.layout.gdim
        x = (p["X"][sel] + vals[p["idx"][sel]]).astype(complex)
        m = x.shape[1]
        x = x.reshape(len(x), m // gdim, gdim)
        A = np.zeros((len(x), m, m))
        step = 1e-30  # Im r(x + i h e_j) / h = dr / dx_j to round-off (no cancellation)
        for j in range(m):
            xj = x.reshape(len(x), m).copy()
            xj[:, j] += 1j * step
            o = self._point_terms(p, xj.reshape(x.shape), sel, geometric, forced)
            A[:, :, j] = o["r"].imag / step
        return A

    def _pointwise_residual(self, vals: np.ndarray, F: PETSc.Vec) -> None:
        """The residual of :meth:`_point_terms` at the search's projection (penalty friction,
        finite-strain Nitsche), and the state the post-processing and the history read."""
        gdim = self.layout.gdim
        self.state, self._last = [], []
        for k, p in enumerate(self.points):
            every = np.ones(len(p["w"]), dtype=bool)
            m = p["X"].shape[1]
            x = (p["X"] + vals[p["idx"]]).reshape(len(every), m // gdim, gdim)
            o = self._point_terms(p, x, every, geometric=False)
            if self.frictional:  # the reversal guard (:mod:`.reversal`)
                ids = np.arange(len(every))
                self._record_trial(k, ids, o["trial"], o["slipping"])
                self._forced[k] = self._reversed(k, ids, o["trial"])
                if np.any(self._forced[k]):
                    o = self._point_terms(p, x, every, geometric=False, forced=self._forced[k])
            F.setValues(p["rows"].ravel(), o["r"].ravel(), addv=PETSc.InsertMode.ADD_VALUES)
            g = np.where(p["paired"], o["g_law"], np.inf)
            self.state.append((o["P"], g, o.get("t"), o.get("stick"), o.get("slip")))
            # the gap vector's normal part g n_m: with the projection of the step's search
            # (small strain) x_s - y also holds the step's sliding, which is the slip
            gap = np.where(p["paired"], o["g"], 0.0)[:, None] * o["nm"]
            self._last.append((o.get("t"), gap, o["nm"]))
        F.assemblyBegin()
        F.assemblyEnd()

    def converged(self) -> None:
        """A step converged: the number of closed points (:meth:`lost`) and, with penalty
        friction or finite-strain Nitsche friction, the tangential traction, gap vector and
        master normal at every point are the history of the next (Nitsche's trial reads the gap
        vector only: its traction is the stress's). Collective."""
        from mpi4py import MPI

        closed = int(np.sum(self.state[0][0] > 0.0))
        self.closed_before = self.comm.allreduce(closed, op=MPI.SUM)
        if not self.keeps_history:
            return
        for dr, (t, gap, nm) in zip(self.dirs, self._last, strict=True):
            assert t is not None  # with friction
            h = dr.history(len(t), self.layout.gdim)
            h["t_old"][:], h["d_old"][:], h["n_old"][:] = t, gap, nm

    #: the slave points closed at the last converged step (all ranks)
    closed_before = 0

    def lost(self) -> str | None:
        """After a converged solve: why it is no solution of the contact problem, or None. A
        solve whose last search paired no slave point with the master surface, while points
        were closed at the last converged step, has lost the contact: a Newton iterate carried
        one body into the other deeper than the search reaches (a master facet's size), and
        the solve converged with the bodies overlapping and no contact force (seen with the
        critical-point line search, whose step length may exceed 1, on shallow-ironing).
        Collective."""
        from mpi4py import MPI

        paired = self.comm.allreduce(int(np.sum(self.points[0]["paired"])), op=MPI.SUM)
        if self.closed_before > 0 and paired == 0:
            return (
                f"the contact was lost ({self.closed_before} slave points closed at the last "
                "step, none near the master surface now: a Newton iterate carried one body "
                "through the other)"
            )
        return None

    def record_start(self) -> None:
        """An interference fit: the initial overlap max(-g0, 0) of every Gauss point from the
        gaps g0 of the last search (at the start, u = 0), hidden by the law in the proportion
        ``pair.hidden()`` of the load program (:class:`contactfx.contact.pair.ContactPair`)."""
        for dr, p in zip(self.dirs, self.points, strict=True):
            g0 = -np.einsum("pi,pi->p", p["Jn"], p["x_search"])
            dr.overlap = np.where(p["paired"], np.maximum(-g0, 0.0), 0.0)
            p["overlap"] = dr.overlap

    def search_gaps(self, facets: bool = False) -> np.ndarray:
        """The gaps of this rank's paired Gauss points at the last search (between the
        facets: no smoothing here, ``facets`` is ignored)."""
        out = [-np.einsum("pi,pi->p", p["Jn"], p["x_search"])[p["paired"]] for p in self.points]
        return np.concatenate(out) if out else np.zeros(0)
