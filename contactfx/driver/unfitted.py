"""The unfitted-crack problem kind: straight cracks that the mesh does not follow
(:mod:`contactfx.contact.cut`).

The unknown is U = (u, a_1, ..., a_K) as for a fitted interface
(:mod:`contactfx.driver.interface`) with one enrichment per crack, each confined to its
enriched nodes: Heaviside on the cut cells' nodes, the branch function on the tips' nodes
(:mod:`contactfx.contact.tip`). The bulk form weighs each cut cell's two sides by their area
fractions, except on the cells around the tips' nodes (their *star*), where the star rule
integrates the strain of u + H a_H + F a_T point by point; each crack's terms are the methods'
residuals on its :class:`contactfx.contact.cut.CutSurface`, whose jump 2 (a_H + sqrt(r) a_T)
holds both parts.
Nitsche's stress on the crack is the sides' mean weighted by their area fractions and its
parameter scales with the piece's length over the cell's area (Annavarapu, Hautefeuille &
Dolbow 2012, doi:10.1002/nme.4343): with the cell diameter instead the pressure oscillates
from cut cell to cut cell, more with a larger gamma0 (docs/verification.md section 14). P1
only (the area-fraction integration is exact for constant strains).

The penalty and al-uzawa, which a fitted crack collocates at its nodes, read their laws at
the midpoint of each cut cell's piece (:meth:`contactfx.contact.cut.CutSurface.
tip_extended`). Their values on the crack (the penalty's traction history, al-uzawa's
multiplier) are functions of the cell rule's points (:meth:`UnfittedProblem.surface_space`):
the history is the law's value there; the multiplier is piecewise linear along the crack on a
grid of nodes GRID_FACTOR cell sizes apart (:class:`contactfx.contact.cut.CoarseGrid`), the
lumped L2 projection of the law's values. A multiplier with one value per piece is not
stable: on a piece of vanishing length the multiplier that closes it grows without bound
(Bechet, Moes & Wohlmuth 2009, doi:10.1002/nme.2515; docs/verification.md section 14). The
penalty's length is the cell diameter. al-ssn, whose multiplier is a field of the mixed
space, is not offered: the grid is not a finite element space of the mesh.

Outputs: along the cracks, at their Gauss points, the aperture, slip, tractions and status
(``interface.csv``, ``interface.png``); in the ParaView files u (with one crack u + H a, split
along the cut cells' edges), each enrichment (at a tip's node abs(F) a, its part of the
displacement there), the side fractions and the von Mises stress of u + sum H_k a_k (H_k the
side of the larger part of each cell; on the star cells that reads the tip nodes' F a as a
Heaviside part: the picture's few cells around each tip).
"""

from __future__ import annotations

import functools
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
    CutSurface,
    WeightedMeasure,
    cell_sizes,
    cut_cells,
    near_cells,
    snapped_tips,
)
from contactfx.contact.interface import InterfaceSurface, tangent
from contactfx.contact.laws import active
from contactfx.contact.surface import Expr
from contactfx.contact.tip import STAR_POINTS, branch, snapped_point, star_rule, tip_split
from contactfx.driver.fields import global_sum, nodal_contact, zero_pattern
from contactfx.driver.grid_multiplier import GridMultiplier
from contactfx.driver.interface import InterfaceProblem
from contactfx.driver.interface_post import STATUS, InterfacePost, Profile
from contactfx.driver.problem import (
    Filler,
    Method,
    Numerics,
    Problem,
    Scene,
    Solver,
    SurfaceSetup,
)
from contactfx.io.vtk import Split
from contactfx.results import InterfaceQuantities, Quantities

__all__ = ["UnfittedProblem"]

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
_CUT = 1  # the cut cells' tag
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


def _accumulate(
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


class _Crack:
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
        return (
            _accumulate(Q, self.cells.cut.astype(float), _compat.cell_dofs(Q), self.n_owned) > 0.0
        )

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


class _TipFields:
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
        cracks: Sequence[_Crack],
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
            node = _accumulate(Q1, cells.tip_nodes, dofs, n_owned) > 0.0
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
        self, X: Expr, crack: _Crack, others: Sequence[tuple[Expr, Expr]], side: Expr
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


class UnfittedProblem(InterfaceProblem):
    """A body with unfitted cracks (see the module docstring)."""

    surface: CutSurface
    surfaces: list[CutSurface]
    cracks: list[_Crack]
    tip: _TipFields
    n_owned_cells: int
    rule: tuple[NDArray[np.float64], NDArray[np.float64]]
    area: NDArray[np.float64]
    cut_tags: Any

    @classmethod
    def check(cls, scene: Scene, numerics: Numerics, method: Method) -> None:
        super().check(scene, numerics, method)
        if numerics.degree != 1:
            raise ValueError(
                "unfitted cracks are P1 (--degree 1): the cut cells' area-fraction "
                "integration is exact for constant strains only"
            )
        if method.multiplier.field and numerics.ncp != "min":
            raise ValueError(
                "al-ssn on unfitted cracks projects its multiplier's law (--ncp min); the "
                "Fischer-Burmeister function is not a projection"
            )
        if numerics.quadrature == "nodal":
            raise ValueError("unfitted cracks use Gauss points (--quadrature gauss)")

    def __init__(
        self,
        scene: Scene,
        numerics: Numerics,
        method: Method,
        mesh: dolfinx.mesh.Mesh,
        facet_tags: Any,
    ) -> None:
        tdim = mesh.topology.dim
        if mesh.geometry.dim != 2 or mesh.topology.cell_name() != "triangle":
            raise ValueError("unfitted cracks are implemented on triangle meshes (2D)")
        self.tol = 1e-9 * scene.length_scale()  # of point location (pinned vertices)
        X = _compat.cell_coordinates(mesh)
        self.n_owned_cells = n_owned = mesh.topology.index_map(tdim).size_local
        self.rule = _compat.quadrature_rule(mesh, QUADRATURE_DEGREE)
        segments = scene.crack_segments()
        #: U = (u, a_1, ..., a_K): one enrichment per crack
        self.components_per_dim = 1 + len(segments)
        self.cracks = [
            _Crack(mesh, X, seg, 2 * (k + 1), self.rule, n_owned) for k, seg in enumerate(segments)
        ]
        self.area = self.cracks[0].area
        self.tip = _TipFields(mesh, X, self.area, self.cracks, n_owned)
        c0 = _compat.cell_dofs(self.cracks[0].h_cut.function_space)[:, 0]
        for k, crack in enumerate(self.cracks):  # Nitsche's parameter on the tips' pieces
            near_tip = np.flatnonzero((self.tip.tags == k) & crack.cells.cut)
            crack.h_cut.x.array[c0[near_tip]] /= TIP_NITSCHE
        K = len(self.cracks)
        tags = np.zeros(len(X), dtype=np.int32)
        touched = np.zeros(len(X), dtype=np.int32)  # cut, tip or star cells of a crack
        clash = (0, 0)
        for k, crack in enumerate(self.cracks):
            mine = crack.cells.cut | crack.cells.tip | (self.tip.tags == k)
            if np.any(mine & (touched > 0)) and clash == (0, 0):
                clash = (int(touched[mine & (touched > 0)][0]), k + 1)
            touched[mine] = k + 1
            tags[crack.cells.cut] = k + 1
        clash = mesh.comm.allreduce(clash, op=MPI.MAX)  # every rank raises, or none
        if clash != (0, 0):
            raise ValueError(
                f"cracks {clash[0]} and {clash[1]} cross or share a cell; unfitted "
                "cracks must be a cell apart"
            )
        # every cell tagged: 0, k + 1 (cut by crack k), K + 1 + k (around a tip of crack k)
        star = self.tip.tags >= 0
        tags[star] = K + 1 + self.tip.tags[star]
        self.cut_tags = dolfinx.mesh.meshtags(mesh, tdim, np.arange(len(X), dtype=np.int32), tags)
        Problem.__init__(self, scene, numerics, method, mesh, facet_tags)

    # -- a method's values at the cracks' pieces ----------------------------------------------
    def surface_space(self, shape: tuple[int, ...]) -> Any:
        """Values at the points of the cell rule, which carry the cracks' Gauss points."""
        return _compat.quadrature_space(self.mesh, QUADRATURE_DEGREE, shape)

    @functools.cached_property
    def multiplier_mask(self) -> NDArray[np.bool_]:
        """The points of the cut cells (every crack's)."""
        assert self.multiplier is not None  # a method with a nodal multiplier
        return self._on_cracks(self.multiplier.function_space)

    def _on_cracks(self, Q: Any) -> NDArray[np.bool_]:
        """The dofs of the space Q on the cut cells of every crack."""
        return np.any([c.nodes(Q) for c in self.cracks], axis=0)

    def confine_multiplier(self, supports: Sequence[Any] = ()) -> list[Any]:
        """al-ssn's multiplier lives on the nodes of the cracks' cut cells."""
        if not self.multiplier_field:
            return []
        return self.confine(self.state.function_space.sub(1), self._on_cracks)

    @functools.cache  # noqa: B019 (one problem, one coupling)
    def coupling(self) -> GridMultiplier | None:
        """al-ssn: its multiplier's equations (:class:`contactfx.driver.grid_multiplier.
        GridMultiplier`); no coupling for the other methods."""
        if not self.multiplier_field:
            return None
        return GridMultiplier(self, self.method.projected_law)

    def _start_multiplier(self) -> None:
        """al-ssn: the projection of the start's traction; al-uzawa: as a fitted crack's."""
        if not self.multiplier_field:
            return super()._start_multiplier()
        coupling = self.coupling()
        assert coupling is not None  # (a multiplier field)
        vec = _compat.petsc_vec(self.state)
        vec.getArray()[coupling.rows] = coupling.project(self._start_traction)
        vec.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)

    def surface_update(self, law: Callable[[Any], Expr]) -> Filler:
        """The filler of al-uzawa's multiplier: ``law(s)`` on each crack's surface s projected
        onto the crack's grid (:meth:`_filler`)."""
        return self._filler(law, on_grid=True)

    def history_update(self, law: Callable[[Any], Expr]) -> Filler:
        """The filler of the traction history: ``law(s)`` at each crack's points."""
        return self._filler(law, on_grid=False)

    def _filler(self, law: Callable[[Any], Expr], *, on_grid: bool) -> Filler:
        """The filler of a :meth:`surface_space` Function with ``law(s)`` at the Gauss points
        of each crack's surface s (its owned cut cells; the ghosts by a scatter); ``on_grid``:
        those values projected onto the crack's grid (lumped L2, summed over the ranks) and
        the grid's piecewise linear field taken at the points instead."""
        exprs = [dolfinx.fem.Expression(law(s), self.rule[0]) for s in self.surfaces]
        comm = self.mesh.comm

        def fill(target: dolfinx.fem.Function) -> None:
            bs = target.function_space.dofmap.index_map_bs
            dofs = _compat.cell_dofs(target.function_space)
            values = target.x.array.reshape(-1, bs)
            for crack, e in zip(self.cracks, exprs, strict=True):
                cells = crack.cut_owned
                v = _compat.eval_expression(e, self.mesh, cells).reshape(-1, bs)
                if on_grid:
                    psi = crack.psi_q[cells].ravel()
                    num, den = crack.grid.moments(psi, crack.weight_q[cells].ravel(), v)
                    num, den = comm.allreduce(num, op=MPI.SUM), comm.allreduce(den, op=MPI.SUM)
                    v = crack.grid.evaluate(psi, num / np.where(den > 0.0, den, 1.0)[:, None])
                values[dofs[cells].ravel()] = v
            target.x.scatter_forward()

        return fill

    def _nodal_size(self) -> Expr:
        """The penalty's h (``nodal_size``): the cell diameter, which varies smoothly along the
        crack. With Nitsche's h_K, large where a piece is short, the stiffness jumped from
        cut cell to cut cell and so did the pressure (docs/verification.md section 14)."""
        return self.h

    def output_split(self) -> Split | None:
        """One crack: the ParaView body split along the edges between the cut cells' larger
        sides (u + H a on each cell, H its larger part's side: Warp By Vector opens the crack
        along a zigzag of cell edges); several cracks: not split."""
        if len(self.cracks) != 1:
            return None
        crack, mesh = self.cracks[0], self.mesh
        tdim = mesh.topology.dim
        mesh.topology.create_connectivity(tdim - 1, tdim)
        f2c = mesh.topology.connectivity(tdim - 1, tdim)
        n_facets = (
            mesh.topology.index_map(tdim - 1).size_local
            + mesh.topology.index_map(tdim - 1).num_ghosts
        )
        side = np.where(crack.cells.fraction >= 0.5, 1.0, -1.0)
        facets = []
        for f in range(n_facets):
            cells = f2c.links(f)
            if (
                len(cells) == 2
                and side[cells[0]] != side[cells[1]]
                and np.any(crack.cells.cut[cells])
            ):
                facets.append(f)
        return Split(crack.H, np.asarray(facets, dtype=np.int32), jump="enrichment_1")

    def total(self, X: Expr) -> Expr:
        """w = u + sum_k H_k a_k from X = (u, a_1, ..., a_K)."""
        d = self.gdim
        u = ufl.as_vector([X[i] for i in range(d)])
        return u + sum((c.H * c.enrichment(X) for c in self.cracks), ufl.zero(d))

    def boundary_total(self, X: Expr) -> Expr:
        """w = u + sum_k H_k a_k with each H_k the side of the point (:meth:`_Crack.side`):
        the boundary's test function and quantities, which on a facet of a cut cell see the
        facet's own side (the cell's larger side may be the other one); a loaded facet that a
        crack crosses is refused (:meth:`_refuse_loaded_crossings`)."""
        d, x = self.gdim, ufl.SpatialCoordinate(self.mesh)
        u = ufl.as_vector([X[i] for i in range(d)])
        return u + sum((c.side(x) * c.enrichment(X) for c in self.cracks), ufl.zero(d))

    def enrichments(self) -> list[tuple[int, Callable[[Any], NDArray[np.bool_]]]]:
        return [(c.first, functools.partial(self._enriched, c)) for c in self.cracks]

    def _enriched(self, crack: _Crack, Q: Any) -> NDArray[np.bool_]:
        """The enriched nodes of a crack: of a cut cell, with area on both sides of the crack
        in their support and no tip inside it (summed over every rank's cells)."""
        dofs = _compat.cell_dofs(Q)
        c = crack.cells
        n = self.n_owned_cells
        plus = _accumulate(Q, c.fraction * self.area, dofs, n)
        minus = _accumulate(Q, (1.0 - c.fraction) * self.area, dofs, n)
        cut = _accumulate(Q, c.cut.astype(float), dofs, n)
        tip = _accumulate(Q, c.tip_nodes, dofs, n)
        both = np.minimum(plus, minus) > 1e-12 * (plus + minus)
        # Heaviside on the cut cells' nodes, the branch function on the tips' nodes
        enriched = ((cut > 0.0) & (tip == 0.0) & both) | (tip > 0.0)
        star = _accumulate(Q, np.any(tip[dofs] > 0.0, axis=1).astype(float), dofs, n) > 0.0
        mesh = self.mesh
        fdim = mesh.topology.dim - 1
        mesh.topology.create_connectivity(fdim, mesh.topology.dim)
        outer = _compat.locate_dofs_topological(
            Q, fdim, dolfinx.mesh.exterior_facet_indices(mesh.topology)
        )
        near = enriched[outer] | star[outer]  # (the tips' cells have no boundary rule)
        if not crack.exits and mesh.comm.allreduce(bool(np.any(near)), op=MPI.LOR):
            raise ValueError(
                "the crack is closer to the boundary than a cell (a cut cell's "
                "node lies on the boundary); move it inwards or refine"
            )
        return enriched

    def _mean_stress(self, X: Expr, crack: _Crack) -> Expr:
        """The stress at crack's Gauss points of the cells' sides weighted by their area
        fractions (Hansbo & Hansbo 2002, doi:10.1016/S0045-7825(02)00524-8):
        sigma(u + sum_k (2 f_k - 1) a_k), and the tip part's (F = H sqrt(r) on the crack)."""
        d, t = self.gdim, self.tip
        u = ufl.as_vector([X[i] for i in range(d)])
        m = [2.0 * c.fraction - 1.0 for c in self.cracks]
        mean = self.material.sigma(
            u
            + sum((mk * c.enrichment(X) for mk, c in zip(m, self.cracks, strict=True)), ufl.zero(d))
        )
        a = crack.enrichment(X)
        aT = t.part(a, t.Lc, t.Pc)
        tip = ufl.outer(aT, ufl.as_vector(t.gR)) + (t.R - 1.0) * t.part_grad(a)
        return mean + self.material.stress((2.0 * crack.fraction - 1.0) * ufl.sym(tip))

    def make_surface(self) -> SurfaceSetup:
        """The surface of each crack (``surfaces``); the first is the kind's ``surface``."""
        mesh, scene = self.mesh, self.scene
        self.w, self.dw = self.total(self.U), self.total(self.dU)
        self.v_load = self.boundary_total(self.V_test)
        x = ufl.SpatialCoordinate(mesh)
        rule = {"quadrature_degree": QUADRATURE_DEGREE, "quadrature_rule": "default"}
        dx = ufl.Measure("dx", domain=mesh, subdomain_data=self.cut_tags)
        self.ds = ufl.Measure("ds", domain=mesh, subdomain_data=self.facet_tags)
        self.fluid_value = scene.fluid_pressure()
        self.fluid = None if self.fluid_value is None else dolfinx.fem.Constant(mesh, 0.0)
        self.surfaces = []
        for k, crack in enumerate(self.cracks):
            Y, M = ufl.as_vector(crack.Y), ufl.as_vector(crack.mid)

            def at_crack(f: Expr, Y: Expr = Y) -> Expr:
                return f + ufl.dot(ufl.grad(f), Y - x)

            def at_midpoint(f: Expr, M: Expr = M) -> Expr:
                return f + ufl.dot(ufl.grad(f), M - x)

            t, K = self.tip, len(self.cracks)
            crack.ds = WeightedMeasure(dx((k + 1, K + 1 + k), metadata=rule), crack.weight)
            crack.s_coord = crack.coordinate(Y)
            self.surfaces.append(
                CutSurface(
                    self.U,
                    self.V_test,
                    ufl.as_vector([float(v) for v in crack.true.normal]),
                    crack.ds,
                    self._mean_stress(self.U, crack),
                    self._mean_stress(self.V_test, crack),
                    scene.contact_modulus(),
                    crack.h_cut,
                    floor=scene.floor(crack.s_coord),
                    fluid=self.fluid,
                    friction=self.friction,
                    joint=scene.joint(),
                    u_prev=None if self.prev is None else self.previous(),
                    at_crack=at_crack,
                    at_law=at_midpoint,
                    first=crack.first,
                    traction_prev=self.t_prev,
                    at_jump=functools.partial(t.half_jump, at_crack, R=t.R, L=t.Lc, P=t.Pc),
                    at_jump_law=functools.partial(t.half_jump, at_midpoint, R=t.Rm, L=t.Lm, P=t.Pm),
                    multiplier=self._multiplier_at(at_crack),
                    h_nodal=self._nodal_size(),
                )
            )
        self._refuse_loaded_crossings()
        first = self.cracks[0]
        self.dSc = self.dS_fine = first.ds
        self.s_coord = first.s_coord
        return SurfaceSetup(self.surfaces[0], self.ds, self.v_load)

    def _refuse_loaded_crossings(self) -> None:
        """Raise if a crack crosses a boundary facet that carries a load: the load on that
        facet would have to be split at the crossing between the two sides' enrichment, which
        the facet rule does not do (the supports and a load-free boundary need no split)."""
        mesh, fdim = self.mesh, self.fdim
        tags = self.facet_tags
        crossed = np.zeros(len(tags.indices), dtype=bool)
        if len(tags.indices):
            ends = _compat.entity_coordinates(mesh, fdim, tags.indices)
            for crack in self.cracks:
                phi = crack.true.phi(ends)
                phi = np.where(np.abs(phi) < SNAP * crack.h, 0.0, phi)
                sign_change = phi[:, 0] * phi[:, 1] < 0.0
                # where the crack's line crosses the facet: on the crack itself?
                t = phi[:, 0] / np.where(sign_change, phi[:, 0] - phi[:, 1], 1.0)
                point = ends[:, 0] + t[:, None] * (ends[:, 1] - ends[:, 0])
                on_crack = np.abs(crack.true.psi(point)) <= crack.true.half_length
                crossed |= sign_change & on_crack
        cut = dolfinx.mesh.meshtags(mesh, fdim, tags.indices[crossed], tags.values[crossed])
        ds = ufl.Measure("ds", domain=mesh, subdomain_data=cut)
        load = self.scene.load(self.v_load, ds, dolfinx.fem.Constant(mesh, 1.0))
        if load is None or load.empty() or not load.arguments():  # no load (UFL's zero)
            return
        form = dolfinx.fem.form(load)
        b = _compat.assemble_vector(_compat.create_vector(form), form)
        loaded = b.norm() > 0.0
        b.destroy()
        if loaded:
            raise ValueError(
                "a crack crosses a loaded boundary (the load would have to be split at the "
                "crossing); move the crack or hold that boundary"
            )

    def _trial_jumps(self) -> list[tuple[InterfaceSurface, Expr, ufl.Measure]]:
        return [(s, s.jump(self.dU), s.ds) for s in self.surfaces]

    def _multiplier_at(self, at_crack: Callable[[Expr], Expr]) -> Expr | None:
        """al-uzawa's multiplier (values at the points), al-ssn's P1 field at the crack's
        points, or None."""
        if self.multiplier is not None or self.lam is None:
            return self.multiplier
        return at_crack(self.lam)

    def contact_residual(self) -> ufl.Form:
        return sum(self.method.residual(self.newton_surface(s)) for s in self.surfaces)

    def extra_load(self, L: ufl.Form) -> ufl.Form:
        if self.fluid is None:
            return L
        # the fluid pushes the faces of every crack apart
        for s in self.surfaces:
            L = L + self.fluid * ufl.dot(s.v, s.interface_normal()) * s.ds
        return L

    def bulk_form(self) -> ufl.Form:
        """Each side of a cut cell with its area fraction (exact for P1): with m_k = 2 f_k - 1
        the sides' mean of the sign of crack k's enrichment and 1 - m_k^2 its variance (no
        cell is cut by two cracks),
        sigma(u + sum m_k a_k) : eps(v + sum m_k b_k) + sum (1 - m_k^2) sigma(a_k) : eps(b_k)."""
        d = self.gdim
        sigma = self.material.sigma

        def eps(z: Expr) -> Expr:
            return ufl.sym(ufl.grad(z))

        def mean(X: Expr) -> Expr:
            u = ufl.as_vector([X[i] for i in range(d)])
            return u + sum(
                ((2.0 * c.fraction - 1.0) * c.enrichment(X) for c in self.cracks), ufl.zero(d)
            )

        form = ufl.inner(sigma(mean(self.dU)), eps(mean(self.V_test)))
        for c in self.cracks:
            m = 2.0 * c.fraction - 1.0
            form += (1.0 - m * m) * ufl.inner(
                sigma(c.enrichment(self.dU)), eps(c.enrichment(self.V_test))
            )
        # (one measure for every cell integral: dolfinx 0.9 wants one subdomain data per form)
        K = len(self.cracks)
        dx = ufl.Measure("dx", domain=self.mesh, subdomain_data=self.cut_tags)
        form = form * dx(tuple(range(K + 1))) + self._star_form(dx)
        if not self.split:
            return form
        # a multiplier field: the pattern of its couplings with the cut cells' dofs, and its
        # diagonal everywhere (its dofs off the cracks are held at zero): not the couplings
        # with every cell's dofs, which doubled the LU's memory
        cut = [(dx((k + 1, K + 1 + k)), lambda f: f) for k in range(K)]
        lam, mu = ufl.split(self.trial)[1], ufl.split(self.test)[1]
        zero = dolfinx.fem.Constant(self.mesh, 0.0)
        return (
            form
            + zero_pattern(self.mesh, self.trial, self.test, cut)
            + zero * ufl.inner(lam, mu) * dx
        )

    def _star_form(self, dx: ufl.Measure) -> ufl.Form:
        """The bulk energy on the cells around the tips' nodes, by the star rule
        (:mod:`contactfx.contact.tip`): the tip enrichment is not P1."""
        t, K = self.tip, len(self.cracks)
        rule = {"quadrature_degree": STAR_DEGREE, "quadrature_rule": "default"}
        form = 0
        for k, crack in enumerate(self.cracks):
            if self.mesh.comm.allreduce(int(np.sum(t.tags == k)), op=MPI.SUM) == 0:
                continue
            others = [(2.0 * c.fraction - 1.0, c) for c in self.cracks if c is not crack]
            e_u, e_v = (
                t.strain(X, crack, [(m, c.enrichment(X)) for m, c in others], t.side)
                for X in (self.dU, self.V_test)
            )
            form += (
                ufl.inner(self.material.stress(e_u), e_v) * t.ratio * dx(K + 1 + k, metadata=rule)
            )
        return form

    def post_processor(self) -> CutPost:
        return CutPost(self)


class CutPost(InterfacePost):
    """The cracks' quantities at their Gauss points, forces, errors against the closed forms
    (of the first crack: the scenes with closed forms have one)."""

    pb: UnfittedProblem

    def __init__(self, pb: UnfittedProblem) -> None:
        self.pb, self.scene, self.comm = pb, pb.scene, pb.mesh.comm
        mesh, method = pb.mesh, pb.method
        joint = pb.surface.joint
        self.w0 = 0.0 if joint is None else joint.w0  # the aperture's opening at zero jump
        points = pb.rule[0]
        self.exprs: list[dict[str, dolfinx.fem.Expression]] = []
        forms = {"force": 0, "closed": 0, "tangential": 0, "propped": 0, "slipping": 0}
        for crack, s in zip(pb.cracks, pb.surfaces, strict=True):
            t_I = tangent(s.interface_normal())
            p = method.pressure(s)
            quantities = {
                "aperture": s.opening() + self.w0,
                "slip": ufl.dot(s.u, t_I),
                "normal_traction": p,
                "gap": s.gap(),
                "x": crack.Y[0],
                "y": crack.Y[1],
            }
            forms["force"] += p * s.ds
            forms["closed"] += active(method.contact_indicator(s)) * s.ds
            if s.friction is not None:
                quantities["tangential_traction"] = ufl.dot(method.tangential_traction(s), t_I)
                quantities["slipping"] = method.slip_indicator(s)
                forms["tangential"] += quantities["tangential_traction"] * s.ds
                forms["slipping"] += quantities["slipping"] * s.ds
            if s.floor is not None:
                quantities["proppant"] = s.floor
                forms["propped"] += p * active(s.floor) * s.ds
            self.exprs.append({k: dolfinx.fem.Expression(v, points) for k, v in quantities.items()})
        s = pb.surface
        self.force_form = dolfinx.fem.form(forms["force"])
        self.closed_form = dolfinx.fem.form(forms["closed"])
        self.tforce_form = None
        if s.friction is not None:
            self.tforce_form = dolfinx.fem.form(forms["tangential"])
        self.propped_form = None
        if s.floor is not None:
            self.propped_form = dolfinx.fem.form(forms["propped"])
        self.err_forms = self._error_forms(s, method.pressure(s), tangent(s.interface_normal()))
        self.extra = {
            k: dolfinx.fem.form(v)
            for k, v in self.scene.extra_quantities(mesh, pb.boundary_total(pb.U), pb.ds).items()
        }
        if s.friction is not None:  # the slipping length
            self.extra["slipping_size"] = dolfinx.fem.form(forms["slipping"])
        DG0 = _compat.function_space(mesh, "DG", 0)
        self.vm_expr = _compat.expression(pb.material.von_mises(pb.w), DG0)
        self.vm = dolfinx.fem.Function(DG0, name="von_mises")
        V1 = _compat.function_space(mesh, "Lagrange", 1, (pb.gdim,))
        self.u_out = dolfinx.fem.Function(V1, name="displacement")
        U, d = pb.U, pb.gdim
        self.u_expr = _compat.expression(ufl.as_vector([U[i] for i in range(d)]), V1)
        self.a_outs = [
            dolfinx.fem.Function(V1, name=f"enrichment_{k + 1}") for k in range(len(pb.cracks))
        ]
        self.a_exprs = [_compat.expression(c.enrichment(U), V1) for c in pb.cracks]
        self._tip_scales = [
            self._tip_scale(V1, c, frame) for c, frame in zip(pb.cracks, pb.tip.frames, strict=True)
        ]
        self.values: dict[str, np.ndarray] = {}

    def _tip_scale(
        self,
        V1: Any,
        crack: _Crack,
        frame: Frame,
    ) -> NDArray[np.float64]:
        """Per node of V1: abs(F) at a tip's node (the branch function there, F a_T its
        enriched displacement), 1 elsewhere: the enrichment written for ParaView is then the
        displacement's part at every node."""
        dofs = _compat.cell_dofs(V1)
        node = _accumulate(V1, crack.cells.tip_nodes, dofs, self.pb.n_owned_cells) > 0.0
        scale = np.ones(len(node))
        x = _compat.dof_coordinates(V1)[:, :2]
        ends, ahead, normal = frame
        nearest = np.argmin(np.linalg.norm(x[:, None] - ends[None], axis=2), axis=1)
        for t in range(2):
            on = node & (nearest == t)
            scale[on] = np.abs(branch(x[on], ends[t], ahead[t], normal)[0])
        return scale

    def _evaluate_points(self) -> dict[str, np.ndarray]:
        """Every quantity at the Gauss points of the owned cut cells (flat arrays; ``crack``
        numbers the cracks from 1, ``s`` is each one's own coordinate)."""
        mesh, parts = self.pb.mesh, []
        for k, (crack, exprs) in enumerate(zip(self.pb.cracks, self.exprs, strict=True)):
            v = {
                name: _compat.eval_expression(e, mesh, crack.cut_owned).ravel()
                for name, e in exprs.items()
            }
            v["s"] = crack.coordinate(np.vstack([v["x"], v["y"]]))
            v["crack"] = np.full(len(v["s"]), k + 1.0)
            parts.append(v)
        names = set().union(*parts)
        return {n: np.concatenate([p.get(n, np.zeros(len(p["s"]))) for p in parts]) for n in names}

    def evaluate(self, solver: Solver) -> Quantities:
        v = self.values = self._evaluate_points()
        on = np.ones(len(v["normal_traction"]), dtype=bool)
        peak, closed, penetration, complementarity = nodal_contact(
            v["normal_traction"], v["gap"], on, self.comm
        )
        status = np.where(closed, STATUS["stick"], STATUS["open"]).astype(float)
        if "slipping" in v:
            status[closed & (v["slipping"] > 0.5)] = STATUS["slip"]
        if "proppant" in v:
            status[closed & (v["proppant"] > 0.0)] = STATUS["propped"]
        v["status"] = status
        interface = InterfaceQuantities(
            tangential_force=0.0
            if self.tforce_form is None
            else global_sum(self.tforce_form, self.comm),
            extra={k: global_sum(form, self.comm) for k, form in self.extra.items()},
        )
        if self.propped_form is not None:
            propped = v["proppant"] > 0.0
            interface = InterfaceQuantities(
                tangential_force=interface.tangential_force,
                extra=interface.extra,
                proppant_force=global_sum(self.propped_form, self.comm),
                min_aperture_propped=self.comm.allreduce(
                    float(np.min(v["aperture"][propped], initial=np.inf)), op=MPI.MIN
                ),
            )
        return Quantities(
            force=global_sum(self.force_form, self.comm),
            contact_size=global_sum(self.closed_form, self.comm),
            peak_pressure=peak,
            max_penetration=penetration,
            complementarity=complementarity,
            interface=interface,
        )

    def fields(self) -> list[dolfinx.fem.Function]:
        self.u_out.interpolate(self.u_expr)
        for f, e, scale in zip(self.a_outs, self.a_exprs, self._tip_scales, strict=True):
            f.interpolate(e)
            f.x.array.reshape(-1, self.pb.gdim)[:] *= scale[:, None]
        self.vm.interpolate(self.vm_expr)
        return [self.u_out, *self.a_outs, self.vm, *(c.fraction for c in self.pb.cracks)]

    def profile(self) -> Profile:
        """The Gauss points' values gathered on rank 0, sorted by crack and s."""
        v = self.values or self._evaluate_points()
        x = np.column_stack([v["x"], v["y"]])

        def col(name: str) -> NDArray[np.float64]:
            return v[name] if name in v else np.zeros(len(v["s"]))

        opening = col("aperture") - self.w0
        local = np.column_stack(
            [
                v["s"],
                x,
                opening,
                col("slip"),
                col("normal_traction"),
                col("tangential_traction"),
                col("status"),
                col("proppant"),
                v["crack"],
            ]
        )
        parts = self.comm.gather(local, root=0)
        if self.comm.rank != 0:
            return Profile(np.zeros(0), np.zeros((0, 2)), *(np.zeros(0) for _ in range(6)))
        a = np.vstack(parts)
        a = a[np.lexsort((a[:, 0], a[:, -1]))]
        crack = a[:, -1] if len(self.pb.cracks) > 1 else None
        opening, slip, p, t, status, floor = (a[:, 3 + i] for i in range(6))
        return Profile(a[:, 0], a[:, 1:3], opening, slip, p, t, status, floor, crack=crack)
