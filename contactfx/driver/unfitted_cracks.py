"""The unfitted cracks of :mod:`contactfx.driver.unfitted`: each crack's level sets, cut cells,
side fractions and Gauss points (:class:`Crack`), and the fields of the tip enrichment
(:class:`TipFields`: the branch functions' parts, the enriched strain); the constants of the
discretisation (docs/verification.md section 14)."""

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
from contactfx.contact.cut import (
    SNAP,
    CoarseGrid,
    CrackQuadrature,
    CrackSegment,
    WeightedMeasure,
    cell_sizes,
    cut_cells,
    near_cells,
    snapped_tips,
)
from contactfx.contact.surface import Expr
from contactfx.contact.tip import STAR_POINTS, branch, snapped_point, star_rule, tip_split

__all__ = ["Crack", "TipFields", "accumulate"]

#: the degree of the cell rule that carries the crack's Gauss points (6 points per piece)
QUADRATURE_DEGREE = 4
#: Nitsche's parameter on the cut cells around a tip is TIP_NITSCHE times larger: the branch
#: function's stress on the crack grows as 1 / sqrt(r), which the inverse estimate behind
#: NITSCHE_LENGTH does not bound (with gamma0 = 10 there, the symmetric variant's contact
#: status cycled on a mesh refined to a / 80; gamma0 = 100 or theta = -1 converged:
#: docs/verification.md section 14)
TIP_NITSCHE = 10.0
#: the degree of the cell rule whose points carry the star rule (contactfx.contact.tip): 28
#: points for at most three triangles of STAR_POINTS^2
STAR_DEGREE = 11
assert 3 * STAR_POINTS**2 <= 28
CUT = 1  # the cut cells' tag
#: a crack's frame: its two tips (2, 2), the directions ahead of them (2, 2), its normal
Frame = tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]
#: Nitsche's length h_K = 5 |K| / |Gamma_K| on a cut cell K (area |K|, crack piece |Gamma_K|):
#: gamma = gamma0 E / h_K is then, at the default gamma0 = 10, the stabilisation
#: 2 E |Gamma_K| / |K| of Annavarapu, Hautefeuille & Dolbow 2012 (doi:10.1002/nme.4343) for the
#: area-weighted mean stress
NITSCHE_LENGTH = 5.0
#: al-uzawa's multiplier grid along a crack: its nodes at least GRID_FACTOR cell sizes apart
#: (:class:`contactfx.contact.cut.CoarseGrid`); 0.5, 1 and 2 give the same slip and pressure
#: on crack-inclined, in 36, 23 and 14 outer iterations (docs/verification.md section 14)
GRID_FACTOR = 2.0


def accumulate(
    Q: Any, values: NDArray[Any], dofs: NDArray[np.int32], n_owned: int
) -> NDArray[np.float64]:
    """Sum over every rank's owned cells of ``values`` (per cell, or per cell and vertex) at
    each cell's (block) dofs ``dofs`` of the space Q, on the local dofs (owned and ghosts;
    one value per block)."""
    f = dolfinx.fem.Function(Q)
    blocks = f.x.array.reshape(-1, Q.dofmap.index_map_bs)
    per_vertex = np.broadcast_to(np.asarray(values, float).reshape(len(values), -1), dofs.shape)
    np.add.at(blocks[:, 0], dofs[:n_owned].ravel(), per_vertex[:n_owned].ravel())
    vec = _compat.petsc_vec(f)
    vec.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    vec.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
    return blocks[:, 0].copy()


class Crack:
    """One unfitted crack on the mesh: its tips moved onto cell boundaries (``segment``), its
    cut cells, the side fractions and signs (DG0), its Gauss points and weights (quadrature
    functions), Nitsche's length, and the first component of its enrichment in U."""

    #: the crack's measure and its coordinate at the Gauss points (set by the problem's
    #: ``make_surface``)
    ds: WeightedMeasure
    s_coord: Expr

    def __init__(
        self,
        mesh: dolfinx.mesh.Mesh,
        X: NDArray[np.float64],
        crack: CrackSegment,
        first: int,
        rule: tuple[NDArray[np.float64], NDArray[np.float64]],
        n_owned: int,
    ) -> None:
        comm = mesh.comm
        self.true, self.first, self.n_owned = crack, first, n_owned
        near = near_cells(X, crack)
        self.h = h = comm.allreduce(float(cell_sizes(X[near]).min(initial=np.inf)), op=MPI.MIN)
        if not np.isfinite(h):
            raise ValueError(f"the crack from {crack.p0} to {crack.p1} lies outside the mesh")
        #: a tip outside the mesh: the crack runs to the boundary (through the body, or an
        #: edge crack), and the enrichment reaches the boundary's nodes there
        self.exits = any(
            _compat.PointLocator(mesh, np.asarray([tip])).outside[0] for tip in crack.tips()
        )
        # every tip moved onto the boundary of the cell holding it (the same on every rank:
        # from the ranks that hold that cell)
        psi = np.array(comm.allgather(snapped_tips(X, crack, SNAP * h)))
        ends = []
        for k, tip in enumerate(crack.tips()):
            found = psi[:, k][~np.isnan(psi[:, k])]
            ends.append(crack.centre + found[0] * crack.direction if len(found) else tip)
        self.segment = CrackSegment(*ends)
        self.cells = cells = cut_cells(X, self.segment, SNAP * h)
        if comm.allreduce(int(cells.cut[:n_owned].sum()), op=MPI.SUM) == 0:
            raise ValueError("the crack cuts no cell completely (shorter than the cells around it)")
        quad = CrackQuadrature(X, cells, rule)
        self.quad_points = quad.points
        DG0 = _compat.function_space(mesh, "DG", 0)
        c0 = _compat.cell_dofs(DG0)[:, 0]
        self.fraction = dolfinx.fem.Function(DG0, name="side_fraction")
        self.fraction.x.array[c0] = cells.fraction
        self.H = dolfinx.fem.Function(DG0, name="side")
        self.H.x.array[c0] = np.where(cells.fraction >= 0.5, 1.0, -1.0)
        self.is_cut = dolfinx.fem.Function(DG0)
        self.is_cut.x.array[c0] = cells.cut
        Qs = _compat.quadrature_space(mesh, QUADRATURE_DEGREE)
        qd = _compat.cell_dofs(Qs)
        self.Y = [dolfinx.fem.Function(Qs) for _ in range(2)]
        for i, Yi in enumerate(self.Y):
            Yi.x.array[qd] = quad.points[:, :, i]
        # each piece's midpoint at every point of its cell
        self.mid = [dolfinx.fem.Function(Qs) for _ in range(2)]
        for i, Mi in enumerate(self.mid):
            Mi.x.array[qd] = quad.points[:, :, i].mean(axis=1)[:, None]
        self.weight = dolfinx.fem.Function(Qs)
        self.weight.x.array[qd] = quad.ratio
        # Nitsche's length on a cut cell: NITSCHE_LENGTH |K| / |Gamma_K| (module docstring)
        e1, e2 = X[:, 1] - X[:, 0], X[:, 2] - X[:, 0]
        self.area = 0.5 * np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])
        self.h_cut = dolfinx.fem.Function(DG0, name="h_cut")
        length = np.where(
            cells.cut, np.linalg.norm(cells.pieces[:, 1] - cells.pieces[:, 0], axis=1), 1.0
        )
        self.h_cut.x.array[c0] = NITSCHE_LENGTH * self.area / length
        cut = np.flatnonzero(cells.cut).astype(np.int32)
        self.cut, self.cut_owned = cut, cut[cut < n_owned]
        # the Gauss points' psi and weights, and the multiplier's grid along the crack (the
        # same on every rank: from every rank's crossings of its owned cells' edges)
        self.psi_q = self.coordinate(quad.points.reshape(-1, 2).T).reshape(quad.ratio.shape)
        self.weight_q = quad.ratio * rule[1][None, :] * 2.0 * self.area[:, None]
        piece_ends = cells.pieces[self.cut_owned].reshape(-1, 2)
        sizes = np.repeat(cell_sizes(X[self.cut_owned]), 2)
        gathered = comm.allgather((self.coordinate(piece_ends.T), sizes))
        self.grid = CoarseGrid(
            np.concatenate([g[0] for g in gathered]),
            np.concatenate([g[1] for g in gathered]),
            GRID_FACTOR,
        )

    def nodes(self, Q: Any) -> NDArray[np.bool_]:
        """Bool per local (block) dof of the space Q: on one of this crack's cut cells, on any
        rank (a node's cut cell may be neither owned nor a ghost where the node is)."""
        return accumulate(Q, self.cells.cut.astype(float), _compat.cell_dofs(Q), self.n_owned) > 0.0

    def side(self, x: Expr) -> Expr:
        """The side (+1 / -1) of the points x (UFL): the crack's level set's sign in its cut
        cells, elsewhere the cell's side."""
        c, n = self.true.centre, self.true.normal
        phi = (x[0] - c[0]) * n[0] + (x[1] - c[1]) * n[1]
        return ufl.conditional(ufl.gt(self.is_cut, 0.5), ufl.sign(phi), self.H)

    def enrichment(self, X: Expr) -> Expr:
        """Its enrichment field in the unknown (or test function) X."""
        return ufl.as_vector([X[self.first + i] for i in range(2)])

    def coordinate(self, x: Any) -> Any:
        """psi: the true crack's coordinate of the points x (UFL or numpy (2, n))."""
        c, d = self.true.centre, self.true.direction
        return (x[0] - c[0]) * d[0] + (x[1] - c[1]) * d[1]


class TipFields:
    """The tip enrichment (:mod:`contactfx.contact.tip`) of every crack, as functions of the
    cells and of the points of their rules: on the star cells (the cells around a tip's
    nodes) the star rule's points, weights, sides, F and grad F, and the tip part's L and P;
    at the cracks' Gauss points and the pieces' midpoints sqrt(r), grad sqrt(r) and L, P; per
    cell gL and gP (:func:`contactfx.contact.tip.tip_split`). Zero off the stars: there the
    enrichment is Heaviside only. ``tags`` (cells,): crack k's star cells get k."""

    def __init__(
        self,
        mesh: dolfinx.mesh.Mesh,
        X: NDArray[np.float64],
        area: NDArray[np.float64],
        cracks: Sequence[Crack],
        n_owned: int,
    ) -> None:
        ref_w = _compat.quadrature_rule(mesh, STAR_DEGREE)[1]
        self.slots = len(ref_w)
        Qb = _compat.quadrature_space(mesh, STAR_DEGREE)
        Qs = _compat.quadrature_space(mesh, QUADRATURE_DEGREE)
        DG0 = _compat.function_space(mesh, "DG", 0)
        qb, qs, c0 = (_compat.cell_dofs(S) for S in (Qb, Qs, DG0))
        c0 = c0[:, 0]

        def functions(space: Any, n: int) -> list[dolfinx.fem.Function]:
            return [dolfinx.fem.Function(space) for _ in range(n)]

        # the star rule: weight ratio, side, F, grad F (2), L, P (2)
        self.ratio, self.side = functions(Qb, 2)
        self.F, self.gF = dolfinx.fem.Function(Qb), functions(Qb, 2)
        self.L, self.P = dolfinx.fem.Function(Qb), functions(Qb, 2)
        # the Gauss points (crack) and the midpoints (law): sqrt(r), grad sqrt(r), L, P
        self.R, self.gR, self.Lc, self.Pc = (
            dolfinx.fem.Function(Qs),
            functions(Qs, 2),
            dolfinx.fem.Function(Qs),
            functions(Qs, 2),
        )
        self.Rm, self.Lm, self.Pm = (
            dolfinx.fem.Function(Qs),
            dolfinx.fem.Function(Qs),
            functions(Qs, 2),
        )
        self.gL, self.gP = functions(DG0, 2), functions(DG0, 4)
        Q1 = _compat.function_space(mesh, "Lagrange", 1)
        dofs = _compat.cell_dofs(Q1)
        self.tags = np.full(len(X), -1, dtype=np.int32)
        #: per crack: its tips (on their edges or nodes), the directions ahead, its normal
        self.frames: list[Frame] = []
        for k, crack in enumerate(cracks):
            cells = crack.cells
            node = accumulate(Q1, cells.tip_nodes, dofs, n_owned) > 0.0
            flags = node[dofs]
            star = np.flatnonzero(np.any(flags, axis=1))
            seg = crack.segment
            ahead = np.array([-seg.direction, seg.direction])
            # the tips on the edges or nodes that they are within the snap of (the same on
            # every rank: from the ranks that hold them)
            snap = SNAP * crack.h
            held = mesh.comm.allgather(
                [snapped_point(X[star], np.asarray(p, float), snap) for p in (seg.p0, seg.p1)]
            )
            ends = np.array(
                [
                    next((h[t] for h in held if not np.isnan(h[t][0])), p)
                    for t, p in enumerate((seg.p0, seg.p1))
                ],
                float,
            )
            self.frames.append((ends, ahead, seg.normal))
            if len(star) == 0:
                continue
            self.tags[star] = k
            centre = X[star].mean(axis=1)
            which = np.argmin(np.linalg.norm(centre[:, None] - ends[None], axis=2), axis=1)
            tips = ends[which]
            side = np.where(cells.fraction[star] >= 0.5, 1.0, -1.0)
            pts, w, sides, cut_side = star_rule(
                X[star], cells.phi[star], cells.cut[star], side, tips, self.slots, snap
            )
            F, gF = np.zeros(w.shape), np.zeros(w.shape + (2,))
            crack_pts = crack.quad_points[star]
            mids = crack_pts.mean(axis=1, keepdims=True)
            R, gR, Rm = (
                np.zeros(crack_pts.shape[:2]),
                np.zeros(crack_pts.shape),
                np.zeros((len(star), 1)),
            )
            for t in range(2):
                on = which == t
                F[on], gF[on] = branch(pts[on], ends[t], ahead[t], seg.normal, cut_side[on])
                d = crack_pts[on] - ends[t]
                r = np.linalg.norm(d, axis=2)
                R[on] = np.sqrt(r)
                gR[on] = d / (2.0 * np.maximum(r, 1e-300) ** 1.5)[..., None]
                Rm[on] = np.sqrt(np.linalg.norm(mids[on] - ends[t], axis=2))
            cut = cells.cut[star]
            L, P, gL, gP = tip_split(X[star], flags[star], pts)
            Lc, Pc = tip_split(X[star], flags[star], crack_pts)[:2]
            Lm, Pm = tip_split(X[star], flags[star], mids)[:2]
            # the crack's points only in the cut cells (elsewhere they are the cell's centre)
            Lc, Pc = Lc * cut[:, None], Pc * cut[:, None, None]
            Lm, Pm = Lm * cut[:, None], Pm * cut[:, None, None]
            ratio = w / (ref_w[None, :] * 2.0 * area[star, None])
            for f, v in (
                (self.ratio, ratio),
                (self.side, sides),
                (self.F, F),
                (self.L, L),
                *zip(self.gF, np.moveaxis(gF, 2, 0), strict=True),
                *zip(self.P, np.moveaxis(P, 2, 0), strict=True),
            ):
                f.x.array[qb[star]] = v
            for f, v in (
                (self.R, R),
                (self.Lc, Lc),
                (self.Rm, np.repeat(Rm, R.shape[1], 1)),
                (self.Lm, np.repeat(Lm, R.shape[1], 1)),
                *zip(self.gR, np.moveaxis(gR, 2, 0), strict=True),
                *zip(self.Pc, np.moveaxis(Pc, 2, 0), strict=True),
                *zip(self.Pm, np.moveaxis(np.repeat(Pm, R.shape[1], 1), 2, 0), strict=True),
            ):
                f.x.array[qs[star]] = v
            for f, v in zip([*self.gL, *self.gP], [*gL.T, *gP.reshape(-1, 4).T], strict=True):
                f.x.array[c0[star]] = v

        self.x = ufl.SpatialCoordinate(mesh)

    def part(self, f: Expr, L: Expr, P: Sequence[Expr]) -> Expr:
        """The tip nodes' share of the P1 field f at the points of L and P (lists)."""
        return L * f + ufl.dot(ufl.grad(f), ufl.as_vector(P) - L * self.x)

    def part_grad(self, f: Expr) -> Expr:
        """The gradient of the tip nodes' share of the P1 field f."""
        gL = ufl.as_vector(self.gL)
        gP = ufl.as_matrix([self.gP[:2], self.gP[2:]])
        return ufl.outer(f, gL) + ufl.dot(ufl.grad(f), gP - ufl.outer(self.x, gL))

    def half_jump(
        self, at: Callable[[Expr], Expr], f: Expr, R: Expr, L: Expr, P: Sequence[Expr]
    ) -> Expr:
        """The half jump of the enrichment f at the points: f's value there (``at``) with its
        tip nodes' share weighted by sqrt(r) (F = H sqrt(r) on the crack)."""
        return at(f) + (R - 1.0) * self.part(f, L, P)

    def strain(
        self, X: Expr, crack: Crack, others: Sequence[tuple[Expr, Expr]], side: Expr
    ) -> Expr:
        """The strain of w at the star rule's points, crack's enrichment split into its
        Heaviside part (with ``side``) and its tip part (with F); ``others``: the other
        cracks' (sign, enrichment) (constant sides here)."""
        u = ufl.as_vector([X[i] for i in range(2)])
        a = crack.enrichment(X)
        gT = self.part_grad(a)
        aT = self.part(a, self.L, self.P)
        grad = ufl.grad(u) + side * (ufl.grad(a) - gT) + ufl.outer(aT, ufl.as_vector(self.gF))
        grad = grad + self.F * gT
        for m, b in others:
            grad = grad + m * ufl.grad(b)
        return ufl.sym(grad)
