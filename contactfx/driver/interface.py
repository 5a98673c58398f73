"""The fitted-interface problem kind: cracks, fractures and joints inside one body
(:class:`contactfx.scenes.interface_base.InterfaceScene`).

The unknown is the vector field U = (u, a) of 2 d components (d the dimension): the
displacement is w = u + H a, with the enrichment a nonzero only at the interface's dofs and zero
at the crack tips (see :mod:`contactfx.contact.interface`). Contact, friction, proppant floor,
fluid pressure and joint closure are interior-facet integrals; the methods are the ones of the
rigid-obstacle scenes, written against :class:`contactfx.contact.interface.InterfaceSurface`.

Outputs: along the interface the aperture, slip, normal and tangential traction and the status
(0 open, 1 closed / stick, 2 slip, 3 propped) as P1 fields in the ParaView files (zero away from
the interface; also on the interface alone, ``<scene>_surface.pvd``), as a PNG line plot
(``interface.png``) against the interface coordinate s and as CSV (``interface.csv``); the
body with the interface's nodes duplicated, ``displacement`` u + a on the +side's cells and
u - a on the -side's (each face's displacement) and the enrichment a (``enrichment``).
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from typing import Any

import dolfinx
import numpy as np
import ufl
from numpy.typing import NDArray

from contactfx import _compat
from contactfx.contact.interface import BartonBandis, InterfaceSurface, oriented_jump
from contactfx.contact.laws import positive_part, tangential
from contactfx.contact.surface import Expr
from contactfx.driver.fields import (
    NodalProjection,
    at_points,
    surface_mask,
    vertex_rule,
    zero_pattern,
)
from contactfx.driver.interface_post import InterfacePost
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
from contactfx.solvers.snes import owned_size

__all__ = ["InterfaceProblem"]


class InterfaceProblem(Problem):
    """A body with a fitted interface (see the module docstring)."""

    components_per_dim = 2

    surface: InterfaceSurface
    tol: float
    tips: list[tuple[NDArray[np.float64], float]]
    on_front: Callable[[NDArray[np.float64]], NDArray[np.bool_]]
    H: dolfinx.fem.Function
    w: Expr
    dw: Expr
    dS: ufl.Measure
    dSc: ufl.Measure
    dS_fine: ufl.Measure
    dS_nodal: ufl.Measure
    s_coord: Expr
    fluid_value: float | None
    fluid: dolfinx.fem.Constant | None

    @classmethod
    def check(cls, scene: Scene, numerics: Numerics, method: Method) -> None:
        if not method.supports.interfaces:
            from contactfx.contact.registry import methods_supporting

            raise ValueError(
                f"method {method.name} is not offered on fitted interfaces ("
                f"{method.supports.why_not.get('interfaces', 'not supported')}); use "
                + ", ".join(methods_supporting(lambda c: c.interfaces))
            )
        if numerics.formulation != "displacement":
            raise ValueError("fitted interfaces use --formulation displacement")

    def __init__(
        self,
        scene: Scene,
        numerics: Numerics,
        method: Method,
        mesh: dolfinx.mesh.Mesh,
        facet_tags: Any,
    ) -> None:
        self.contact_facets = facet_tags.indices[facet_tags.values == scene.interface_tag]
        self.tol = 1e-9 * scene.length_scale()  # of point location
        self.tips = [(np.asarray(t, dtype=float), self.tol) for t in scene.tips()]
        self.on_front = functools.partial(scene.on_front, tol=self.tol)
        if mesh.geometry.dim == 3:
            # a 3D front is a curve of nodes: no continuation over its elements (the 2D tip's
            # neighbour is one node, a front node's are several). The jump vanishes
            # identically there, so no law fixes a multiplier: it is held at zero, and the
            # traction falls to zero across the front's elements, as the penalty's does
            # (docs/verification.md section 13)
            self.multiplier_excluded = self.on_front
        # the side sign H: +1 / -1 from the cell midpoints
        self.H = dolfinx.fem.Function(_compat.function_space(mesh, "DG", 0), name="side")
        self.H.interpolate(lambda x: np.where(scene.side(x) >= 0.0, 1.0, -1.0))
        super().__init__(scene, numerics, method, mesh, facet_tags)

    def output_split(self) -> Split | None:
        """The ParaView body with the crack faces as separate nodes: ``displacement`` written
        as u + H a, each face's own displacement (Warp By Vector opens the crack)."""
        return Split(self.H, self.contact_facets)

    def total(self, X: Expr) -> Expr:
        """w = u + H a from X = (u, a)."""
        d = self.gdim
        return ufl.as_vector([X[i] + self.H * X[d + i] for i in range(d)])

    def boundary_conditions(self) -> list[Any]:
        V, d, fdim, tags = self.V, self.gdim, self.fdim, self.facet_tags
        bcs: list[Any] = []
        enrichments = self.enrichments()
        for tag, comp in self.scene.supports():  # they hold for the total displacement
            facets = tags.indices[tags.values == tag]
            for c in (comp, *(first + comp for first, _ in enrichments)):
                dofs = _compat.locate_dofs_topological(V.sub(c), fdim, facets)
                bcs.append(_compat.dirichletbc(np.float64(0.0), dofs, V.sub(c)))
        for point, comp in self.scene.pinned():  # removing the rigid motions
            Q, q_to_w = V.sub(comp).collapse()
            dofs = at_points(Q, [(np.asarray(point, dtype=float), self.tol)])
            parent = np.asarray(q_to_w)[dofs].astype(np.int32)
            bcs.append(_compat.dirichletbc(np.float64(0.0), parent, V.sub(comp)))
        for first, mask in enrichments:
            for i in range(d):
                bcs += self.confine(V.sub(first + i), mask)
        return bcs + self.confine_multiplier()  # al-ssn: tied at the tips (_tip_terms)

    def enrichments(self) -> list[tuple[int, Callable[[Any], NDArray[np.bool_]]]]:
        """(first component, mask of the free dofs) of each enrichment field of the unknown:
        the one a, free on the interface."""
        return [(self.gdim, self.free_mask)]

    def free_mask(self, Q: Any) -> NDArray[np.bool_]:
        """On the interface and not on a tip or front."""
        return surface_mask(Q, self.fdim, self.contact_facets, self.on_front)

    def make_surface(self) -> SurfaceSetup:
        mesh, scene, tag = self.mesh, self.scene, self.scene.interface_tag
        self.w, self.dw, self.v_load = (self.total(X) for X in (self.U, self.dU, self.V_test))
        self.dS = ufl.Measure("dS", domain=mesh, subdomain_data=self.facet_tags)
        self.dSc = self.dS(tag, metadata=self.contact_rule())
        self.dS_fine = self.dS(tag, metadata={"quadrature_degree": 12})
        self.dS_nodal = self.dS(tag, metadata=vertex_rule(self.fdim))
        self.ds = ufl.Measure("ds", domain=mesh, subdomain_data=self.facet_tags)
        self.s_coord = scene.coordinate(ufl.SpatialCoordinate(mesh))
        self.fluid_value = scene.fluid_pressure()
        self.fluid = None if self.fluid_value is None else dolfinx.fem.Constant(mesh, 0.0)
        mat = self.material
        surface = InterfaceSurface(
            self.w,
            self.v_load,
            self.H,
            self.dSc,
            mat.weak_stress(self.w),
            mat.weak_stress_derivative(self.w, None, self.v_load),
            scene.contact_modulus(),
            self.h,
            floor=scene.floor(self.s_coord),
            fluid=self.fluid,
            joint=scene.joint(),
            friction=self.friction,
            u_prev=None if self.prev is None else self.total(self.previous()),
            traction_prev=None if self.t_prev is None else self.t_prev("+"),
            ds_nodal=self.dS_nodal if self.multiplier_field else None,
            multiplier=None if self.lam is None else self.lam("+"),
            multiplier_test=None if self.lam_test is None else self.lam_test("+"),
            **self._tip_terms(),
        )
        return SurfaceSetup(surface, self.ds, self.v_load)

    def _tip_terms(self) -> dict[str, Expr]:
        """What the methods need at the crack tips: ``tip_step``, the vector from each tip's
        node to its neighbour's (``InterfaceSurface.tip_extended``), for the methods continued
        over the tips' elements (``tip_continued``) and the multiplier methods; for the latter
        also the multiplier's tie (``SurfaceData.multiplier_tie``, ``at_tips``): lambda(neighbour) -
        lambda(tip) = grad(lambda) . (x_neighbour - x_tip), exact for the P1 multiplier on the
        tip's facet."""
        if not self.tips or self.lam is None and not self.method.tip_continued:
            return {}
        step = self._tip_steps()
        if self.lam is None:
            return {"tip_step": step}
        return {
            "tip_step": step,
            "multiplier_tie": ufl.dot(ufl.grad(self.lam), step)("+"),
            "at_tips": ufl.conditional(ufl.gt(ufl.dot(step, step), 0.0), 1.0, 0.0)("+"),
        }

    def _tip_steps(self) -> dolfinx.fem.Function:
        """P1 vector field: at each tip's node, the vector to the nearest other node of the
        interface (its neighbour along the crack); zero at every other node."""
        V1 = _compat.function_space(self.mesh, "Lagrange", 1, (self.gdim,))
        x = _compat.dof_coordinates(V1)[:, : self.gdim]
        on = surface_mask(V1, self.fdim, self.contact_facets)
        step = dolfinx.fem.Function(V1, name="tip_step")
        values = step.x.array.reshape(-1, self.gdim)
        for point, tol in self.tips:
            d = np.linalg.norm(x - point[: self.gdim], axis=1)
            d[~on | (d < tol)] = np.inf
            i = int(np.argmin(d)) if len(d) else 0
            local = (float(d[i]), x[i]) if len(d) and np.isfinite(d[i]) else (np.inf, None)
            dist, neighbour = min(self.mesh.comm.allgather(local), key=lambda c: c[0])
            if not np.isfinite(dist):
                raise ValueError(f"crack tip {point} has no neighbouring node on the interface")
            values[at_points(V1, [(point, tol)])] = neighbour - point[: self.gdim]
        return step

    def nodal_rule(self) -> tuple[ufl.Measure, str | None]:
        return self.dS_nodal, "+"

    def bulk_form(self) -> ufl.Form:
        a = ufl.inner(self.material.sigma(self.dw), ufl.sym(ufl.grad(self.v_load))) * ufl.dx
        # zero couplings that give the matrix the pattern of the interface terms (dofs of the
        # two cells of an interface facet; every component of a mixed unknown)
        dS = self.dS(self.scene.interface_tag)
        pattern = [(dS, ufl.jump), (dS, ufl.avg)]
        if self.split:
            pattern.append((ufl.dx, lambda f: f))
        return a + zero_pattern(self.mesh, self.trial, self.test, pattern)

    def extra_load(self, L: ufl.Form) -> ufl.Form:
        if self.fluid is None:
            return L
        # the fluid pushes both faces apart
        s = self.surface
        return L + self.fluid * ufl.dot(s.v, s.interface_normal()) * self.dSc

    # -- what the methods use ----------------------------------------------------------------
    @functools.cached_property
    def multiplier_mask(self) -> NDArray[np.bool_]:
        """On the interface, the 2D tips included (al-uzawa's update gives a tip its
        neighbour's value: ``InterfaceSurface.tip_extended``), a 3D front not."""
        assert self.multiplier is not None  # a method with a nodal multiplier
        return surface_mask(
            self.multiplier.function_space, self.fdim, self.contact_facets, self.multiplier_excluded
        )

    @functools.cached_property
    def _multiplier_projection(self) -> NodalProjection:
        assert self.multiplier is not None
        return NodalProjection(self.dS_nodal, self.multiplier.function_space, "+")

    def nodal_update(self, expr: Expr) -> Filler:
        """The nodal values of an interior-facet quantity: a vertex-rule lumped projection."""
        proj = self._multiplier_projection
        form = proj.form(expr)
        return lambda target: proj(form, target)

    # -- load program --------------------------------------------------------------------------
    def apply_load(self, t: float) -> None:
        self.tload.value = t
        self.scene.set_load(t)
        if self.fluid is not None:
            assert self.fluid_value is not None  # (fluid is made with it)
            self.fluid.value = t * self.fluid_value

    def start(self, solver: Solver) -> None:
        """Start from the interface held together under the first load step's loads: a linear
        solve with the jump fixed to zero (the bonded body) or, for a joint, held by its initial
        normal stiffness (tangentially bonded). Where the interface is then in compression the
        contact law is active at the first Newton iterate and the body stays supported (from
        the unloaded, touching state the semi-smooth derivative of [x]_+ at x = 0 would leave a
        part split off by the interface unsupported); where it is in tension the faces open in
        the next iterations. Multipliers start at that state's traction."""
        self.apply_load(1.0 / self.num.steps)
        solver.assemble_load()
        joint = self.scene.joint()
        spring = None
        if joint is not None:
            terms = [self._spring(joint, s, jump, ds) for s, jump, ds in self._trial_jumps()]
            spring = dolfinx.fem.form(sum(terms))
        n_owned = owned_size(self.state.function_space)
        free = np.zeros(n_owned, dtype=bool)
        for i in range(self.gdim * (1 if spring is None else self.components_per_dim)):
            parent = np.asarray(self.V.sub(i).collapse()[1])
            free[parent[parent < n_owned]] = True
        solver.solve_linear(free, spring)
        if self.lam is not None:
            self._start_multiplier()
        self._tolerances(solver)

    def _spring(
        self, joint: BartonBandis, s: InterfaceSurface, jump: Expr, ds: ufl.Measure
    ) -> ufl.Form:
        """The joint held by its initial normal stiffness K_ni and tangentially by E / h:
        the start's bilinear form on the surface s, for the trial function's jump."""
        n_I = s.interface_normal()
        k_t = self.scene.contact_modulus() / s.h
        return (
            joint.Kni * ufl.dot(jump, n_I) * ufl.dot(s.v, n_I)
            + k_t * ufl.dot(tangential(jump, n_I), s.v)
        ) * ds

    def _trial_jumps(self) -> list[tuple[InterfaceSurface, Expr, ufl.Measure]]:
        """(surface, the trial function's jump on it, its measure) of every interface."""
        return [(self.surface, oriented_jump(self.dw, self.H), self.dSc)]

    def _start_traction(self, s: InterfaceSurface) -> Expr:
        """The multipliers' start on the surface s: the traction (with friction) or the
        compressive normal stress of the start's state."""
        if self.mult_shape:
            return s.traction(s.normal())
        return positive_part(s.effective_pressure())

    def _start_multiplier(self) -> None:
        start = self._start_traction
        if self.multiplier is not None:
            self.surface_update(start)(self.multiplier)
            bs = self.multiplier.function_space.dofmap.index_map_bs
            self.multiplier.x.array[~np.repeat(self.multiplier_mask, bs)] = 0.0
            return
        W1 = self.state.function_space.sub(1)
        Q, q_to_w = W1.collapse()
        lam0 = dolfinx.fem.Function(Q)
        proj = NodalProjection(self.dS_nodal, Q, "+")
        proj(proj.form(start(self.surface)), lam0)
        self.state.x.array[np.asarray(q_to_w)] = lam0.x.array
        self.state.x.scatter_forward()

    def _tolerances(self, solver: Solver) -> None:
        if not solver.user_sets("snes_atol"):
            # absolute tolerance a little above the round-off of the loads: the start (bonded,
            # or the load-step predictor) can already be the solution, e.g. of a uniformly
            # compressed joint, and rtol then cannot be met
            solver.set_tolerances(atol=1e-11 * solver.bulk.load.norm())
        if not self.multiplier_field and not solver.user_sets("snes_stol"):
            # and a Newton step below 1e-12 of the displacement is converged too (the
            # residual's round-off floor grows with the conditioning, e.g. P2 on graded tips);
            # not for a multiplier field, whose unknown mixes displacements and multipliers
            solver.set_tolerances(stol=1e-12)

    def post_processor(self) -> InterfacePost:
        return InterfacePost(self)

    def dofs(self) -> int:
        """Free unknowns: the enrichment's fixed dofs away from the interface and the
        supported dofs do not count."""
        return self.dofs_less(self.bcs)
