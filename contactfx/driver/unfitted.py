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
    CutSurface,
    WeightedMeasure,
)
from contactfx.contact.interface import InterfaceSurface, tangent
from contactfx.contact.laws import active
from contactfx.contact.surface import Expr
from contactfx.contact.tip import branch
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
from contactfx.driver.unfitted_cracks import (
    QUADRATURE_DEGREE,
    STAR_DEGREE,
    TIP_NITSCHE,
    Crack,
    Frame,
    TipFields,
    accumulate,
)
from contactfx.io.vtk import Split
from contactfx.results import InterfaceQuantities, Quantities

__all__ = ["UnfittedProblem"]


class UnfittedProblem(InterfaceProblem):
    """A body with unfitted cracks (see the module docstring)."""

    surface: CutSurface
    surfaces: list[CutSurface]
    cracks: list[Crack]
    tip: TipFields
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
            Crack(mesh, X, seg, 2 * (k + 1), self.rule, n_owned) for k, seg in enumerate(segments)
        ]
        self.area = self.cracks[0].area
        self.tip = TipFields(mesh, X, self.area, self.cracks, n_owned)
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
        """w = u + sum_k H_k a_k with each H_k the side of the point
        (:meth:`contactfx.driver.unfitted_cracks.Crack.side`): the boundary's test function and
        quantities, which on a facet of a cut cell see the facet's own side (the cell's larger side
        may be the other one); a loaded facet that a crack crosses is refused
        (:meth:`_refuse_loaded_crossings`)."""
        d, x = self.gdim, ufl.SpatialCoordinate(self.mesh)
        u = ufl.as_vector([X[i] for i in range(d)])
        return u + sum((c.side(x) * c.enrichment(X) for c in self.cracks), ufl.zero(d))

    def enrichments(self) -> list[tuple[int, Callable[[Any], NDArray[np.bool_]]]]:
        return [(c.first, functools.partial(self._enriched, c)) for c in self.cracks]

    def _enriched(self, crack: Crack, Q: Any) -> NDArray[np.bool_]:
        """The enriched nodes of a crack: of a cut cell, with area on both sides of the crack
        in their support and no tip inside it (summed over every rank's cells)."""
        dofs = _compat.cell_dofs(Q)
        c = crack.cells
        n = self.n_owned_cells
        plus = accumulate(Q, c.fraction * self.area, dofs, n)
        minus = accumulate(Q, (1.0 - c.fraction) * self.area, dofs, n)
        cut = accumulate(Q, c.cut.astype(float), dofs, n)
        tip = accumulate(Q, c.tip_nodes, dofs, n)
        both = np.minimum(plus, minus) > 1e-12 * (plus + minus)
        # Heaviside on the cut cells' nodes, the branch function on the tips' nodes
        enriched = ((cut > 0.0) & (tip == 0.0) & both) | (tip > 0.0)
        star = accumulate(Q, np.any(tip[dofs] > 0.0, axis=1).astype(float), dofs, n) > 0.0
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

    def _mean_stress(self, X: Expr, crack: Crack) -> Expr:
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
        crack: Crack,
        frame: Frame,
    ) -> NDArray[np.float64]:
        """Per node of V1: abs(F) at a tip's node (the branch function there, F a_T its
        enriched displacement), 1 elsewhere: the enrichment written for ParaView is then the
        displacement's part at every node."""
        dofs = _compat.cell_dofs(V1)
        node = accumulate(V1, crack.cells.tip_nodes, dofs, self.pb.n_owned_cells) > 0.0
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
