"""The unfitted-crack problem kind: a straight crack that the mesh does not follow
(:mod:`contactfx.contact.cut`).

The unknown is U = (u, a) as for a fitted interface (:mod:`contactfx.driver.interface`), the
enrichment a confined to the enriched nodes; the bulk form weighs each cut cell's two sides by
their area fractions, the crack's terms are the methods' residuals on a
:class:`contactfx.contact.cut.CutSurface`. Nitsche's stress on the crack is the sides' mean
weighted by their area fractions and its parameter scales with the piece's length over the
cell's area (Annavarapu, Hautefeuille & Dolbow 2012, doi:10.1002/nme.4343): with the cell
diameter instead the pressure oscillates from cut cell to cut cell, more with a larger gamma0
(docs/verification.md section 14). P1 only (the area-fraction integration is exact for
constant strains); the methods whose law needs the vertex rule or a tip continuation (the
penalties, the augmented Lagrangian ones) are not offered.

Outputs: along the crack, at its Gauss points, the aperture, slip, tractions and status
(``interface.csv``, ``interface.png``); in the ParaView files u, the enrichment a, the side
fraction and the von Mises stress of u + H a (H the side of the larger part of each cell).
"""

from __future__ import annotations

import dolfinx
import numpy as np
import ufl
from mpi4py import MPI
from petsc4py import PETSc

from contactfx import _compat
from contactfx.contact.cut import (
    SNAP,
    CrackQuadrature,
    CrackSegment,
    CutSurface,
    WeightedMeasure,
    cell_sizes,
    cut_cells,
    near_cells,
    snapped_tips,
)
from contactfx.contact.interface import tangent
from contactfx.contact.laws import active
from contactfx.driver.fields import global_sum, nodal_contact
from contactfx.driver.interface import InterfaceProblem
from contactfx.driver.interface_post import STATUS, InterfacePost, Profile
from contactfx.driver.problem import Problem
from contactfx.results import InterfaceQuantities, Quantities

__all__ = ["UnfittedProblem"]

#: the degree of the cell rule that carries the crack's Gauss points (6 points per piece)
QUADRATURE_DEGREE = 4
_CUT = 1  # the cut cells' tag
#: Nitsche's length h_K = 5 |K| / |Gamma_K| on a cut cell K (area |K|, crack piece |Gamma_K|):
#: gamma = gamma0 E / h_K is then, at the default gamma0 = 10, the stabilisation
#: 2 E |Gamma_K| / |K| of Annavarapu, Hautefeuille & Dolbow 2012 (doi:10.1002/nme.4343) for the
#: area-weighted mean stress
NITSCHE_LENGTH = 5.0


def _accumulate(Q, values: np.ndarray, dofs: np.ndarray, n_owned: int) -> np.ndarray:
    """Sum over every rank's owned cells of ``values`` (per cell, or per cell and vertex) at
    each cell's dofs of the scalar P1 space Q, on the local dofs (owned and ghosts)."""
    f = dolfinx.fem.Function(Q)
    per_vertex = np.broadcast_to(np.asarray(values, float).reshape(len(values), -1),
                                 dofs.shape)  # fmt: skip
    np.add.at(f.x.array, dofs[:n_owned].ravel(), per_vertex[:n_owned].ravel())
    vec = _compat.petsc_vec(f)
    vec.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    vec.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
    return f.x.array.copy()


class UnfittedProblem(InterfaceProblem):
    """A body with an unfitted crack (see the module docstring)."""

    @classmethod
    def check(cls, scene, numerics, method) -> None:
        super().check(scene, numerics, method)
        if numerics.degree != 1:
            raise ValueError("unfitted cracks are P1 (--degree 1): the cut cells' area-fraction "
                             "integration is exact for constant strains only")  # fmt: skip
        if method.multiplier != "none" or method.tip_continued or method.nodal_size:
            raise ValueError(f"method {method.name} is not implemented on unfitted cracks "
                             "(its law needs the crack's nodes); use nitsche")  # fmt: skip
        if numerics.quadrature == "nodal":
            raise ValueError("unfitted cracks use Gauss points (--quadrature gauss)")
        if scene.joint() is not None:
            raise ValueError("joint closure is not implemented on unfitted cracks")

    def __init__(self, scene, numerics, method, mesh, facet_tags) -> None:
        comm, tdim = mesh.comm, mesh.topology.dim
        if mesh.geometry.dim != 2 or mesh.topology.cell_name() != "triangle":
            raise ValueError("unfitted cracks are implemented on triangle meshes (2D)")
        self.tol = 1e-9 * scene.length_scale()
        self.tips = []  # the jump vanishes on the tip cells by the choice of enriched nodes
        self.on_front = None
        cracks = scene.crack_segments()
        if len(cracks) != 1:
            raise ValueError("one unfitted crack per scene is implemented")
        self.crack = crack = cracks[0]
        X = _compat.cell_coordinates(mesh)
        self.n_owned_cells = mesh.topology.index_map(tdim).size_local
        near = near_cells(X, crack)
        h = comm.allreduce(float(cell_sizes(X[near]).min(initial=np.inf)), op=MPI.MIN)
        if not np.isfinite(h):
            raise ValueError(f"the crack from {crack.p0} to {crack.p1} lies outside the mesh")
        # every tip moved onto the boundary of the cell holding it (the same on every rank:
        # from the ranks that hold that cell)
        psi = np.array(comm.allgather(snapped_tips(X, crack, SNAP * h)))
        d = crack.direction
        ends = []
        for k, tip in enumerate(crack.tips()):
            found = psi[:, k][~np.isnan(psi[:, k])]
            ends.append(crack.centre + found[0] * d if len(found) else tip)
        self.effective = CrackSegment(*ends)
        self.cells = cells = cut_cells(X, self.effective, SNAP * h)
        for tip in crack.tips():
            inside = _compat.PointLocator(mesh, np.asarray([tip]))
            if inside.outside[0]:
                raise ValueError(f"the crack tip {tip} lies outside the mesh")
        if comm.allreduce(int(cells.cut[: self.n_owned_cells].sum()), op=MPI.SUM) == 0:
            raise ValueError("the crack cuts no cell completely (shorter than the cells "
                             "around it)")  # fmt: skip
        e1, e2 = X[:, 1] - X[:, 0], X[:, 2] - X[:, 0]
        self.area = 0.5 * np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])
        self.rule = _compat.quadrature_rule(mesh, QUADRATURE_DEGREE)
        quad = CrackQuadrature(X, cells, self.rule)
        DG0 = _compat.function_space(mesh, "DG", 0)
        c0 = _compat.cell_dofs(DG0)[:, 0]
        self.fraction = dolfinx.fem.Function(DG0, name="side_fraction")
        self.fraction.x.array[c0] = cells.fraction
        self.H = dolfinx.fem.Function(DG0, name="side")
        self.H.x.array[c0] = np.where(cells.fraction >= 0.5, 1.0, -1.0)
        Qs = _compat.quadrature_space(mesh, QUADRATURE_DEGREE)
        qd = _compat.cell_dofs(Qs)
        self.Y = [dolfinx.fem.Function(Qs) for _ in range(2)]
        for i, Yi in enumerate(self.Y):
            Yi.x.array[qd] = quad.points[:, :, i]
        self.weight = dolfinx.fem.Function(Qs)
        self.weight.x.array[qd] = quad.ratio
        # Nitsche's length on a cut cell: NITSCHE_LENGTH |K| / |Gamma_K| (module docstring)
        self.h_cut = dolfinx.fem.Function(DG0, name="h_cut")
        length = np.where(cells.cut, np.linalg.norm(cells.pieces[:, 1] - cells.pieces[:, 0],
                                                    axis=1), 1.0)  # fmt: skip
        self.h_cut.x.array[c0] = NITSCHE_LENGTH * self.area / length
        cut = np.flatnonzero(cells.cut).astype(np.int32)
        self.cut_tags = dolfinx.mesh.meshtags(mesh, tdim, cut, np.full(len(cut), _CUT, np.int32))
        self.cut_owned = cut[cut < self.n_owned_cells]
        Problem.__init__(self, scene, numerics, method, mesh, facet_tags)

    def output_split(self):
        return None

    def free_mask(self, Q) -> np.ndarray:
        """The enriched nodes: of a cut cell, with area on both sides of the crack in their
        support and no tip inside it (summed over every rank's cells)."""
        dofs = _compat.cell_dofs(Q)
        c = self.cells
        n = self.n_owned_cells
        plus = _accumulate(Q, c.fraction * self.area, dofs, n)
        minus = _accumulate(Q, (1.0 - c.fraction) * self.area, dofs, n)
        cut = _accumulate(Q, c.cut.astype(float), dofs, n)
        tip = _accumulate(Q, c.tip_nodes, dofs, n)
        both = np.minimum(plus, minus) > 1e-12 * (plus + minus)
        enriched = (cut > 0.0) & (tip == 0.0) & both
        mesh = self.mesh
        fdim = mesh.topology.dim - 1
        mesh.topology.create_connectivity(fdim, mesh.topology.dim)
        outer = _compat.locate_dofs_topological(
            Q, fdim, dolfinx.mesh.exterior_facet_indices(mesh.topology)
        )
        if mesh.comm.allreduce(bool(np.any(enriched[outer])), op=MPI.LOR):
            raise ValueError(
                "the crack is closer to the boundary than a cell (a cut cell's "
                "node lies on the boundary); move it inwards or refine"
            )
        return enriched

    def make_surface(self) -> CutSurface:
        mesh, scene, d = self.mesh, self.scene, self.gdim
        self.w, self.dw, self.v_load = (self.total(X) for X in (self.U, self.dU, self.V_test))
        x = ufl.SpatialCoordinate(mesh)
        Y = ufl.as_vector(self.Y)

        def at_crack(f):
            return f + ufl.dot(ufl.grad(f), Y - x)

        rule = {"quadrature_degree": QUADRATURE_DEGREE, "quadrature_rule": "default"}
        dx = ufl.Measure("dx", domain=mesh, subdomain_data=self.cut_tags)
        self.dSc = self.dS_fine = WeightedMeasure(dx(_CUT, metadata=rule), self.weight)
        self.ds = ufl.Measure("ds", domain=mesh, subdomain_data=self.facet_tags)
        self.s_coord = scene.coordinate(Y)
        self.fluid_value = scene.fluid_pressure()
        self.fluid = None if self.fluid_value is None else dolfinx.fem.Constant(mesh, 0.0)
        sigma = self.material.sigma

        def body(X):
            return ufl.as_vector([X[i] for i in range(d)])

        def mean_stress(X):
            """The sides' stresses weighted by their area fractions (Hansbo & Hansbo 2002,
            doi:10.1016/S0045-7825(02)00524-8): sigma(u) + (2 f - 1) sigma(a)."""
            a = ufl.as_vector([X[d + i] for i in range(d)])
            return sigma(body(X)) + (2.0 * self.fraction - 1.0) * sigma(a)

        return CutSurface(
            self.U, self.V_test, ufl.as_vector([float(v) for v in self.crack.normal]), self.dSc,
            mean_stress(self.U), mean_stress(self.V_test), scene.contact_modulus(), self.h_cut,
            floor=scene.floor(self.s_coord), fluid=self.fluid, friction=self.friction,
            u_prev=None if self.prev is None else self.previous(), at_crack=at_crack,
        )  # fmt: skip

    def bulk_form(self):
        """Each side of a cut cell with its area fraction (exact for P1)."""
        d, f = self.gdim, self.fraction
        sigma = self.material.sigma

        def sides(X):
            u = ufl.as_vector([X[i] for i in range(d)])
            a = ufl.as_vector([X[d + i] for i in range(d)])
            return u + a, u - a

        (wp, wm), (vp, vm) = sides(self.dU), sides(self.V_test)
        eps = ufl.sym
        return (f * ufl.inner(sigma(wp), eps(ufl.grad(vp)))
                + (1.0 - f) * ufl.inner(sigma(wm), eps(ufl.grad(vm)))) * ufl.dx  # fmt: skip

    def post_processor(self) -> CutPost:
        return CutPost(self)


class CutPost(InterfacePost):
    """The crack's quantities at its Gauss points, forces, errors against the closed forms."""

    def __init__(self, pb) -> None:
        self.pb, self.scene, self.comm = pb, pb.scene, pb.mesh.comm
        mesh, s, method = pb.mesh, pb.surface, pb.method
        t_I = tangent(s.interface_normal())
        p = method.pressure(s)
        closed = method.contact_indicator(s)
        self.w0 = 0.0
        quantities = {"aperture": s.opening(), "slip": ufl.dot(s.u, t_I),
                      "normal_traction": p, "gap": s.gap(), "x": pb.Y[0], "y": pb.Y[1],
                      "weight": pb.weight}  # fmt: skip
        if s.friction is not None:
            quantities["tangential_traction"] = ufl.dot(method.tangential_traction(s), t_I)
            quantities["slipping"] = method.slip_indicator(s)
        if s.floor is not None:
            quantities["proppant"] = s.floor
        points = pb.rule[0]
        self.exprs = {k: dolfinx.fem.Expression(v, points) for k, v in quantities.items()}
        dS = pb.dS_fine
        self.force_form = dolfinx.fem.form(p * dS)
        self.closed_form = dolfinx.fem.form(active(closed) * dS)
        self.tforce_form = None
        if s.friction is not None:
            self.tforce_form = dolfinx.fem.form(quantities["tangential_traction"] * dS)
        self.propped_form = None
        if s.floor is not None:
            self.propped_form = dolfinx.fem.form(p * active(s.floor) * dS)
        self.err_forms = self._error_forms(s, p, t_I)
        self.extra = {}
        DG0 = _compat.function_space(mesh, "DG", 0)
        self.vm_expr = _compat.expression(pb.material.von_mises(pb.w), DG0)
        self.vm = dolfinx.fem.Function(DG0, name="von_mises")
        V1 = _compat.function_space(mesh, "Lagrange", 1, (pb.gdim,))
        self.u_out = dolfinx.fem.Function(V1, name="displacement")
        self.a_out = dolfinx.fem.Function(V1, name="enrichment")
        U, d = pb.U, pb.gdim
        self.u_expr = _compat.expression(ufl.as_vector([U[i] for i in range(d)]), V1)
        self.a_expr = _compat.expression(ufl.as_vector([U[d + i] for i in range(d)]), V1)
        self.values: dict[str, np.ndarray] = {}

    def _evaluate_points(self) -> dict[str, np.ndarray]:
        """Every quantity at the Gauss points of the owned cut cells (flat arrays)."""
        cells, mesh = self.pb.cut_owned, self.pb.mesh
        return {k: _compat.eval_expression(e, mesh, cells).ravel() for k, e in self.exprs.items()}

    def evaluate(self, solver) -> Quantities:
        v = self.values = self._evaluate_points()
        on = np.ones(len(v["normal_traction"]), dtype=bool)
        peak, closed, penetration, complementarity = nodal_contact(
            v["normal_traction"], v["gap"], on, self.comm)  # fmt: skip
        status = np.where(closed, STATUS["stick"], STATUS["open"]).astype(float)
        if "slipping" in v:
            status[closed & (v["slipping"] > 0.5)] = STATUS["slip"]
        if "proppant" in v:
            status[closed & (v["proppant"] > 0.0)] = STATUS["propped"]
        v["status"] = status
        interface = InterfaceQuantities(
            tangential_force=0.0 if self.tforce_form is None else global_sum(self.tforce_form,
                                                                             self.comm),
        )  # fmt: skip
        if self.propped_form is not None:
            propped = v["proppant"] > 0.0
            interface = InterfaceQuantities(
                tangential_force=interface.tangential_force,
                proppant_force=global_sum(self.propped_form, self.comm),
                min_aperture_propped=self.comm.allreduce(
                    float(np.min(v["aperture"][propped], initial=np.inf)), op=MPI.MIN),
            )  # fmt: skip
        return Quantities(
            force=global_sum(self.force_form, self.comm),
            contact_size=global_sum(self.closed_form, self.comm),
            peak_pressure=peak,
            max_penetration=penetration,
            complementarity=complementarity,
            interface=interface,
        )

    def fields(self) -> list:
        self.u_out.interpolate(self.u_expr)
        self.a_out.interpolate(self.a_expr)
        self.vm.interpolate(self.vm_expr)
        return [self.u_out, self.a_out, self.vm, self.pb.fraction]

    def profile(self) -> Profile:
        """The Gauss points' values gathered on rank 0, sorted by s."""
        v = self.values or self._evaluate_points()
        x = np.column_stack([v["x"], v["y"]])
        s = self.scene.coordinate(x.T)

        def col(name):
            return v[name] if name in v else np.zeros(len(s))

        local = np.column_stack(
            [
                s,
                x,
                col("aperture"),
                col("slip"),
                col("normal_traction"),
                col("tangential_traction"),
                col("status"),
                col("proppant"),
            ]
        )
        parts = self.comm.gather(local, root=0)
        if self.comm.rank != 0:
            return Profile(np.zeros(0), np.zeros((0, 2)), *(np.zeros(0) for _ in range(6)))
        a = np.vstack(parts)
        a = a[np.argsort(a[:, 0], kind="stable")]
        return Profile(a[:, 0], a[:, 1:3], *(a[:, 3 + i] for i in range(6)))
