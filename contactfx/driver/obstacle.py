"""The rigid-obstacle problem kind: an elastic body against an obstacle given by a signed
distance function, moved by the load program (:class:`contactfx.scenes.base.ObstacleScene`).

Unknown: the displacement u (with a P1 multiplier or the u-p pressure as second field).
Surface: :class:`contactfx.contact.gap.ContactSurface` on the scene's contact facets.
Post-processing: contact force, nodal pressure (lumped), contact size, penetration,
complementarity, friction quantities, and the errors against the scene's closed forms.
"""

from __future__ import annotations

import dataclasses
import functools
from pathlib import Path
from typing import Any

import dolfinx
import numpy as np
import ufl
from mpi4py import MPI
from numpy.typing import NDArray
from petsc4py import PETSc

from contactfx import _compat
from contactfx.contact.gap import ContactSurface
from contactfx.contact.laws import active, positive_part
from contactfx.contact.surface import Expr
from contactfx.contact_edge import ContourMeasure, facet_dofs
from contactfx.driver.fields import (
    NodalProjection,
    global_sum,
    nodal_contact,
    surface_mask,
    vertex_rule,
    zero_pattern,
)
from contactfx.driver.problem import (
    Filler,
    Method,
    Numerics,
    Problem,
    Scene,
    Solver,
    SurfaceSetup,
)
from contactfx.mechanics.axisymmetric import measure
from contactfx.results import Friction, Quantities

__all__ = ["ObstacleProblem", "closed_form_errors"]


class ObstacleProblem(Problem):
    """A body against a rigid obstacle (see the module docstring)."""

    nested = True
    nonlinear_bulk = True
    axisymmetric = True
    dynamic = True
    dashpot = True

    surface: ContactSurface
    obstacle: Any
    dsc: ufl.Measure
    dsc_fine: ufl.Measure
    offset: dolfinx.fem.Constant
    offset_prev: dolfinx.fem.Constant | None

    @classmethod
    def check(cls, scene: Scene, numerics: Numerics, method: Method) -> None:
        if not method.supports.obstacles:
            raise ValueError(
                f"method {method.name} is not offered against rigid obstacles ("
                f"{method.supports.why_not.get('obstacles', '')})"
            )
        material = numerics.bulk_material(scene.material())
        if numerics.formulation == "mixed-up" and not (material.pressure_modulus or 0.0) > 0.0:
            raise ValueError(
                f"formulation mixed-up needs lambda > 0 (0 < nu < 0.5), got nu = {material.nu}"
            )

    def __init__(
        self,
        scene: Scene,
        numerics: Numerics,
        method: Method,
        mesh: dolfinx.mesh.Mesh,
        facet_tags: Any,
    ) -> None:
        if mesh.topology.dim == 1 and not method.supports.dim1:
            raise ValueError(
                f"method {method.name} needs a 2D or 3D mesh ({method.supports.why_not['dim1']})"
            )
        self.contact_facets = facet_tags.indices[facet_tags.values == scene.contact_tag]
        self.obstacle = scene.obstacle()
        super().__init__(scene, numerics, method, mesh, facet_tags)

    def material_of(self, mesh: dolfinx.mesh.Mesh) -> Any:
        """The scene's material, with its modulus field for a heterogeneous body."""
        material, modulus = self.scene.material(), self.scene.modulus(mesh)
        return material if modulus is None else dataclasses.replace(material, modulus=modulus)

    def boundary_conditions(self) -> list[Any]:
        supports = self.scene.dirichlet(self.V, self.facet_tags)
        return supports + self.confine_multiplier(supports=supports)

    def make_surface(self) -> SurfaceSetup:
        mesh, scene, mat = self.mesh, self.scene, self.material
        self.ds = measure("ds", mesh, scene.axisymmetric, subdomain_data=self.facet_tags)
        self.dsc = self.ds(scene.contact_tag, metadata=self.contact_rule())
        self.dsc_fine = self.ds(scene.contact_tag, metadata={"quadrature_degree": 12})
        self.offset = dolfinx.fem.Constant(mesh, np.zeros(self.gdim))
        self.offset_prev = None
        if self.friction is not None:
            self.offset_prev = dolfinx.fem.Constant(mesh, np.zeros(self.gdim))
        self.v_load = self.V_test
        surface = ContactSurface(
            self.U,
            self.V_test,
            self.dsc,
            self.obstacle,
            self.offset,
            mat.weak_stress(self.U, self.p),
            mat.weak_stress_derivative(self.U, self.p, self.V_test, self.q),
            scene.contact_modulus(),
            self.h,
            friction=self.friction,
            u_prev=None if self.prev is None else self.previous(),
            offset_prev=self.offset_prev,
            traction_prev=self.t_prev,
            ds_nodal=self.nodal_rule()[0] if self.multiplier_field else None,
            multiplier=self.lam,
            multiplier_test=self.lam_test,
            reference_normal=ufl.FacetNormal(mesh) if mat.finite_strain else None,
        )
        return SurfaceSetup(surface, self.ds, self.v_load)

    def nodal_rule(self) -> tuple[ufl.Measure, str | None]:
        return self.ds(self.scene.contact_tag, metadata=vertex_rule(self.fdim)), None

    def bulk_form(self) -> ufl.Form:
        eps_v = ufl.sym(ufl.grad(self.V_test))
        a = ufl.inner(self.material.sigma(self.dU, self.dp), eps_v) * self.dx
        hoop = self.material.hoop_work(self.dU, self.dp, self.V_test)
        if hoop is not None:
            a += hoop * self.dx
        if self.up:
            a += self.material.pressure_law(self.dU, self.dp, self.q) * self.dx
        pattern = self.tangent_pattern()
        return a if pattern is None else a + pattern

    def internal_form(self) -> ufl.Form:
        """int S(u, p) : grad v dx (+ the pressure's law, mixed u-p): the material's weak
        stress."""
        f = ufl.inner(self.material.weak_stress(self.U, self.p), ufl.grad(self.V_test)) * self.dx
        hoop = self.material.hoop_work(self.U, self.p, self.V_test)
        if hoop is not None:
            f += hoop * self.dx
        if self.up:
            f += self.material.pressure_law(self.U, self.p, self.q) * self.dx
        return f

    def tangent_pattern(self) -> ufl.Form | None:
        """A multiplier field's couplings with every cell's dofs (zero)."""
        if not self.multiplier_field:
            return None
        return zero_pattern(self.mesh, self.trial, self.test, [(ufl.dx, lambda f: f)])

    # -- what the methods use ----------------------------------------------------------------
    @functools.cached_property
    def multiplier_mask(self) -> NDArray[np.bool_]:
        assert self.multiplier is not None  # a method with a nodal multiplier
        Q = self.multiplier.function_space
        return surface_mask(Q, self.fdim, self.contact_facets)

    def nodal_update(self, expr: Expr) -> Filler:
        """Interpolation of ``expr`` at the multiplier's nodes."""
        assert self.multiplier is not None
        compiled = _compat.expression(expr, self.multiplier.function_space)
        return lambda target: target.interpolate(compiled)

    # -- load program --------------------------------------------------------------------------
    def apply_load(self, t: float) -> None:
        self.tload.value = t
        self.scene.set_load(t)
        self.offset.value[:] = self.scene.obstacle_offset(t, self.gdim)

    def start(self, solver: Solver) -> None:
        u = self.state.sub(0) if self.split else self.state
        self.scene.initial_guess(u, 1.0 / self.num.steps)

    def converged(self) -> None:
        super().converged()
        if self.offset_prev is not None:
            self.offset_prev.value[:] = self.offset.value

    def post_processor(self) -> ObstaclePost:
        return ObstaclePost(self)


def closed_form_errors(scene: Scene, q: Quantities) -> dict[str, float]:
    """The scene's closed forms at the computed force (``scene.reference``) with the relative
    errors of the computed force, contact size ``a`` and peak pressure ``p0``."""
    ref = scene.reference(q.force)
    reference: dict[str, float] = {}
    if "force" in ref:
        reference["force"] = ref["force"]
        reference["force_rel_error"] = abs(q.force - ref["force"]) / abs(ref["force"])
    for key, computed in (("a", q.contact_size), ("p0", q.peak_pressure)):
        if key in ref:
            reference.update(
                {
                    key: ref[key],
                    f"{key}_computed": computed,
                    f"{key}_rel_error": abs(computed - ref[key]) / abs(ref[key]),
                }
            )
    if "a" in ref:
        reference["a_error_over_h"] = abs(q.contact_size - ref["a"]) / scene.h_contact()
    for key, value in ref.items():
        reference.setdefault(key, value)
    return reference


class ObstaclePost:
    """Contact force, pressure, contact size, penetration, friction quantities and field
    errors, compiled once."""

    def __init__(self, pb: ObstacleProblem) -> None:
        self.pb, self.scene, self.comm = pb, pb.scene, pb.mesh.comm
        mesh, s, method, gdim = pb.mesh, pb.surface, pb.method, pb.gdim
        self.Q1 = _compat.function_space(mesh, "Lagrange", 1)
        self.nodal = NodalProjection(pb.dsc, self.Q1)
        self.contour = ContourMeasure(
            facet_dofs(self.Q1, pb.contact_facets),
            _compat.dof_coordinates(self.Q1),
            pb.scene.axisymmetric,
        )
        self.pressure = dolfinx.fem.Function(self.Q1, name="contact_pressure")
        self.gap = dolfinx.fem.Function(self.Q1, name="gap")
        self.status = dolfinx.fem.Function(self.Q1, name="contact_status")
        DG0 = _compat.function_space(mesh, "DG", 0)
        self.vm = dolfinx.fem.Function(DG0, name="von_mises")
        self.vm_expr = _compat.expression(pb.material.von_mises(s.u, pb.p), DG0)
        self.gap_expr = _compat.expression(s.gap(), self.Q1)
        self.displacement = pb.state
        if pb.split:
            V_out, self.out_map = pb.V.collapse()
            self.displacement = dolfinx.fem.Function(V_out, name="displacement")
        n = s.normal()
        p = method.pressure(s)
        if p is None:  # bound constraints: the pressure is the reaction
            Qk = _compat.function_space(mesh, "Lagrange", pb.num.degree)
            self.reaction: tuple[NodalProjection, dolfinx.fem.Function] | None = (
                NodalProjection(pb.dsc, Qk),
                dolfinx.fem.Function(Qk),
            )
            self.measure_form = dolfinx.fem.form(self.status * pb.dsc)
        else:
            self.reaction = None
            # the force along e_d the obstacle takes (a floor below the body: along -e_d)
            n_d = -n[gdim - 1] if pb.obstacle.below else n[gdim - 1]
            self.force_form = dolfinx.fem.form(p * n_d * pb.dsc)
            self.p_form = self.nodal.form(p)
            closed = method.contact_indicator(s)
            self.measure_form = dolfinx.fem.form(active(closed) * pb.dsc_fine)
        self.friction = None if pb.friction is None else _FrictionPost(pb, self, p, closed)
        self.errors = _FieldErrors(pb, p, self.pressure)
        self.finite = None if not pb.material.finite_strain else _FiniteStrainPost(pb, self, p)

    def evaluate(self, solver: Solver) -> Quantities:
        on = self.nodal.on
        if self.reaction is None:
            force = global_sum(self.force_form, self.comm)
            self.nodal(self.p_form, self.pressure)
        else:
            proj, pk = self.reaction
            force = self.pb.method.reaction_pressure(solver, self.pb.state, proj.mass, pk)
            self.pressure.interpolate(pk)
        self.gap.interpolate(self.gap_expr)
        peak, closed, penetration, complementarity = nodal_contact(
            self.pressure.x.array, self.gap.x.array, on, self.comm
        )
        self.status.x.array[:] = closed  # 0 open, 1 closed (stick)
        measure = global_sum(self.measure_form, self.comm) * self.scene.symmetry
        friction = None
        if self.friction is not None:
            friction = self.friction.evaluate(measure)
        # the contact size from the zero contour of p - (E / h) g (the closed set's measure
        # above stays the friction's)
        contour = measure
        if self.comm.allreduce(self.contour.supported, op=MPI.LAND):
            p, g = self.pressure.x.array, self.gap.x.array
            nu = self.scene.material().nu  # E* against the rigid obstacle
            local = self.contour(p, g, self.scene.contact_modulus() / (1.0 - nu**2))
            contour = self.comm.allreduce(local, op=MPI.SUM) * self.scene.symmetry
        return Quantities(
            force=force * self.scene.symmetry,
            contact_size=self.scene.contact_size(contour),
            peak_pressure=peak,
            max_penetration=penetration,
            complementarity=complementarity,
            friction=friction,
        )

    def fields(self) -> list[dolfinx.fem.Function]:
        pb = self.pb
        if pb.split:
            self.displacement.x.array[:] = pb.state.x.array[self.out_map]
        self.vm.interpolate(self.vm_expr)
        out = [self.displacement, self.vm, self.pressure, self.gap, self.status]
        if self.friction is not None:
            out += [self.friction.traction, self.friction.slip]
        if self.finite is not None:
            out += self.finite.fields()
        return out

    def finish(self, q: Quantities, out: Path | None) -> dict[str, Any]:
        """Closed-form comparisons, pointwise scores and field errors of the final state."""
        reference = closed_form_errors(self.scene, q)
        if q.friction is not None:
            reference.update(self.scene.friction_reference(q, self.pb.friction))
        return {
            "reference": reference,
            "scores": self.scores(q.force),
            "errors": self.errors.evaluate(self.scene.reference(q.force)),
        }

    def scores(self, force: float) -> dict[str, float]:
        on = self.nodal.on
        n = len(on)
        x = _compat.dof_coordinates(self.Q1)[:n][on]
        p = self.pressure.x.array[:n][on]
        local = self.scene.pressure_scores(x, p, force)
        if self.friction is not None:
            local.update(self.friction.scores(x, p))
        return {k: self.comm.allreduce(v, op=MPI.MAX) for k, v in local.items()}


class _FiniteStrainPost:
    """The fields of a finite-strain body (on the reference mesh; ParaView's Warp By Vector
    with the displacement shows the deformed body): the volume ratio J = det F and the
    Cauchy stress sigma = P F^T / J (DG0 cell fields; the 3 x 3 tensor, out-of-plane entries
    included in 2D), and the contact pressure as a Cauchy traction on the deformed surface,
    p da / dA with the area ratio da / dA = J |F^-T N| (Nanson's formula), beside the
    ``contact_pressure`` per unit reference area whose integral is the contact force."""

    def __init__(self, pb: ObstacleProblem, post: ObstaclePost, p: Expr | None) -> None:
        mesh, mat, u = pb.mesh, pb.material, pb.surface.u
        DG0 = _compat.function_space(mesh, "DG", 0)
        T0 = _compat.function_space(mesh, "DG", 0, (9,))
        self.J = dolfinx.fem.Function(DG0, name="volume_ratio")
        self.sigma = dolfinx.fem.Function(T0, name="cauchy_stress")
        F = mat.deformation_gradient(u)
        sigma = mat.cauchy3(u, pb.p)
        self.J_expr = _compat.expression(ufl.det(F), DG0)
        self.sigma_expr = _compat.expression(
            ufl.as_vector([sigma[i, j] for i in range(3) for j in range(3)]), T0
        )
        d = pb.gdim
        Finv_T = ufl.inv(ufl.as_matrix([[F[i, j] for j in range(d)] for i in range(d)])).T
        N = ufl.FacetNormal(mesh)
        area_ratio = ufl.det(F) * ufl.sqrt(ufl.dot(ufl.dot(Finv_T, N), ufl.dot(Finv_T, N)))
        self.post = post
        self.current = dolfinx.fem.Function(post.Q1, name="contact_pressure_current")
        self.current_form = None if p is None else post.nodal.form(p / area_ratio)

    def fields(self) -> list:
        self.J.interpolate(self.J_expr)
        self.sigma.interpolate(self.sigma_expr)
        out = [self.J, self.sigma]
        if self.current_form is not None:
            self.post.nodal(self.current_form, self.current)
            out.append(self.current)
        return out


class _FrictionPost:
    """Tangential traction and slip at the nodes, stick zone, forces, the friction excess."""

    def __init__(self, pb: ObstacleProblem, post: ObstaclePost, p: Expr, closed: Expr) -> None:
        self.pb, self.post, self.comm = pb, post, pb.mesh.comm
        s, method, mesh, gdim = pb.surface, pb.method, pb.mesh, pb.gdim
        assert pb.friction is not None  # (only with friction)
        V1 = _compat.function_space(mesh, "Lagrange", 1, (gdim,))
        self.vector = NodalProjection(pb.dsc, V1)
        t_T = method.tangential_traction(s)
        # the bound plus a zero that keeps the forms' arguments when mu = 0 or the threshold is
        # 0 (UFL would simplify the bound away)
        bound = pb.friction.bound_where(p, closed) + dolfinx.fem.Constant(mesh, 0.0)
        slipping = method.slip_indicator(s)
        self.traction = dolfinx.fem.Function(V1, name="tangential_traction")
        self.slip = dolfinx.fem.Function(V1, name="slip")
        self._increment = dolfinx.fem.Function(V1)
        self._slipping = dolfinx.fem.Function(post.Q1)
        self._bound = dolfinx.fem.Function(post.Q1)
        self.increment_expr = _compat.expression(s.slip_increment(s.normal()), V1)
        self.t_form = self.vector.form(t_T)
        self.slip_form = post.nodal.form(slipping)
        self.bound_nodal_form = post.nodal.form(bound)
        self.tforce_forms = [dolfinx.fem.form(t_T[i] * pb.dsc) for i in range(gdim)]
        t_abs = ufl.sqrt(ufl.dot(t_T, t_T))
        self.excess_form = dolfinx.fem.form(positive_part(t_abs - bound) * pb.dsc)
        self.bound_form = dolfinx.fem.form(bound * pb.dsc)
        self.stick_form = dolfinx.fem.form(active(closed) * (1.0 - slipping) * pb.dsc_fine)

    def evaluate(self, measure: float) -> Friction:
        scene, comm = self.pb.scene, self.comm
        self.vector(self.t_form, self.traction)
        self.post.nodal(self.slip_form, self._slipping)
        st = self.post.status.x.array
        st[:] += (st > 0.0) & (self._slipping.x.array > 0.5)  # 2 where slipping
        bound = global_sum(self.bound_form, comm)
        excess = global_sum(self.excess_form, comm)
        stick = global_sum(self.stick_form, comm) * scene.symmetry
        self.accumulate_slip()
        # the full model's force: the components normal to a mirror plane cancel
        factors = scene.force_symmetry(len(self.tforce_forms))
        return Friction(
            tangential_force=[
                global_sum(f, comm) * factors[i] + 0.0 for i, f in enumerate(self.tforce_forms)
            ],
            bound=bound * scene.symmetry,
            stick_size=scene.contact_size(stick),
            slip_fraction=1.0 - stick / measure if measure > 0.0 else 0.0,
            excess=excess / bound if bound > 0.0 else excess,
        )

    def accumulate_slip(self) -> None:
        """slip += tangential slip increment of this step, on the contact boundary's nodes."""
        self._increment.interpolate(self.increment_expr)
        on = self.post.nodal.on
        gdim = self.pb.gdim
        vec = _compat.petsc_vec(self.slip)
        arr = vec.getArray().reshape(-1, gdim)
        inc = self._increment.x.array[: arr.size].reshape(-1, gdim)
        arr[on] += inc[on]
        vec.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)

    def scores(self, x: NDArray[np.float64], p: NDArray[np.float64]) -> dict[str, float]:
        on = self.post.nodal.on
        n, gdim = len(on), self.pb.gdim
        t = self.traction.x.array[: n * gdim].reshape(-1, gdim)[on]
        status = self.post.status.x.array[:n][on]
        self.post.nodal(self.bound_nodal_form, self._bound)
        bound = self._bound.x.array[:n][on]
        return self.pb.scene.friction_scores(x, p, t, bound, status)


class _FieldErrors:
    """Relative L2 error of the pressure on the contact boundary against the closed form at the
    computed force (the method's pressure at quadrature points; the lumped nodal pressure for
    bound constraints and nodal quadrature), integrated with a degree-12 rule; L2 and H1
    errors of the displacement where the scene has an exact field."""

    def __init__(
        self, pb: ObstacleProblem, p: Expr | None, nodal_pressure: dolfinx.fem.Function
    ) -> None:
        self.pb, self.comm = pb, pb.mesh.comm
        # the nodal pressure (bound constraints, nodal quadrature): piecewise linear
        self.p_h = p if p is not None and pb.num.quadrature == "gauss" else nodal_pressure
        x = ufl.SpatialCoordinate(pb.mesh)
        exact = pb.scene.exact_displacement(x)
        self.forms: dict[str, tuple[Any, ...]] = {}
        if exact is not None:
            e = pb.surface.u - exact
            dxq = pb.dx(metadata={"quadrature_degree": 2 * pb.num.degree + 4})
            for key, op in (("L2", lambda f: f), ("H1", ufl.grad)):
                self.forms[key] = tuple(
                    dolfinx.fem.form(ufl.inner(op(f), op(f)) * dxq) for f in (e, exact)
                )

    def evaluate(self, ref: dict[str, float]) -> dict[str, float]:
        out: dict[str, float] = {}
        pb = self.pb
        consts = {k: dolfinx.fem.Constant(pb.mesh, float(v)) for k, v in ref.items()}
        exact = pb.scene.exact_pressure(ufl.SpatialCoordinate(pb.mesh), consts)
        if exact is not None:
            dsf = pb.dsc_fine
            err = np.sqrt(global_sum(dolfinx.fem.form((self.p_h - exact) ** 2 * dsf), self.comm))
            norm = np.sqrt(global_sum(dolfinx.fem.form(exact**2 * dsf), self.comm))
            out.update(pressure_L2=err, pressure_L2_rel=err / norm)
        for key, (err_form, norm_form) in self.forms.items():
            err = np.sqrt(global_sum(err_form, self.comm))
            norm = np.sqrt(global_sum(norm_form, self.comm))
            out[f"displacement_{key}"] = err
            out[f"displacement_{key}_rel"] = err / norm
        return out
