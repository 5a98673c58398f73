"""Problem kinds: what the pipeline asks of a body against a rigid obstacle, a fitted or
unfitted interface, and two meshed bodies.

:class:`Problem` builds what every kind shares: the unknown (the kind's displacement field,
extended by a multiplier field when the method's :class:`contactfx.contact.method.Multiplier`
asks for one, or by the pressure of the mixed u-p formulation), the friction history (the last
converged state, and the last tangential traction for a method that keeps it), a nodal
multiplier (likewise), and the forms (the bulk, :mod:`contactfx.solvers.bulk`, linear or not
as the material is; the load; the contact residual). A kind adds its unknowns' meaning, its
boundary conditions and measures, its :class:`contactfx.contact.surface.Surface`, its load
program and its post-processing; the hooks are listed in docs/architecture.md ("Adding a
problem kind").
"""

from __future__ import annotations

import dataclasses
import functools
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any, NamedTuple, overload

import dolfinx
import numpy as np
import ufl
from mpi4py import MPI
from numpy.typing import NDArray

from contactfx import _compat
from contactfx.contact.laws import Friction, reversal
from contactfx.contact.surface import Expr
from contactfx.driver.fields import (
    NodalProjection,
    PointPredicate,
    at_nodes,
    confine,
    surface_mask,
    vertex_rule,
)
from contactfx.driver.inertia import Inertia
from contactfx.driver.inversion import VolumeRatio
from contactfx.mechanics.axisymmetric import hoop_strain, measure
from contactfx.mechanics.elasticity import locking_hint
from contactfx.solvers.bulk import Bulk, LinearBulk, NonlinearBulk
from contactfx.solvers.snes import owned_bc_dofs, owned_size

if TYPE_CHECKING:
    from typing import TypeAlias, TypeVar

    from contactfx.contact.gap import ContactSurface
    from contactfx.contact.interface import InterfaceSurface
    from contactfx.io.vtk import Split

    #: the surface a kind's ``make_surface`` builds: a frozen dataclass that presents the
    #: members of :class:`contactfx.contact.surface.Surface` (an unfitted crack's
    #: :class:`contactfx.contact.cut.CutSurface` is an InterfaceSurface)
    KindSurface: TypeAlias = ContactSurface | InterfaceSurface
    _S = TypeVar("_S", bound=KindSurface)

__all__ = ["Forms", "Problem", "SurfaceSetup"]

#: what the driver knows of the objects it is handed (typed as Any): a scene
#: (:class:`contactfx.scenes.base.Scene` and the kind's own scene base, whose hooks differ by
#: kind), the numerics (:class:`contactfx.numerics.Numerics`, a dataclass made at import), a
#: method (:class:`contactfx.contact.method.ContactMethod` with its optional members:
#: ``traction_history``, ``tangential_traction``, ...), a solver (the
#: :class:`contactfx.solvers.snes.ContactSNES` or the wrapper a method attached) and the
#: dolfinx objects whose classes differ between dolfinx versions (compiled forms, meshtags,
#: DirichletBCs)
Scene = Any
Numerics = Any
Method = Any
Solver = Any
#: a filler: writes a law's values into its target Function (``nodal_update`` and friends)
Filler = Callable[[dolfinx.fem.Function], None]


class SurfaceSetup(NamedTuple):
    """What a kind's ``make_surface`` gives: the :class:`contactfx.contact.surface.Surface`
    the methods write against (None for two bodies: their contact is the solver's coupling),
    ``ds`` the boundary measure the scene's loads integrate over, ``v_load`` the test function
    they act on (the total displacement's on an interface)."""

    surface: KindSurface | None
    ds: ufl.Measure
    v_load: Expr


class Forms(NamedTuple):
    """What the solver is built from: the bulk (a callable that builds and assembles it), the
    compiled contact residual and its Jacobian (None without contact terms in UFL)."""

    bulk: Callable[[], Bulk]
    contact_residual: Any = None
    contact_jacobian: Any = None


class Problem:
    """Base of the problem kinds. After construction: ``state`` (the unknown Function),
    ``trial`` / ``test``, ``bcs``, ``surface`` and, for the methods, ``multiplier`` and
    ``multiplier_mask`` (nodal multiplier methods)."""

    #: the field count of the kind's displacement-like unknown per space dimension
    components_per_dim = 1
    #: whether nested iteration (``--nested``) can start this kind from a coarser mesh's
    #: solution (:mod:`contactfx.driver.nested`)
    nested = False
    #: whether the kind writes its bulk for a material that is not linear (``internal_form``)
    nonlinear_bulk = False
    #: whether the kind solves axisymmetric bodies (its integrals weighted by r, the hoop term;
    #: :mod:`contactfx.mechanics.axisymmetric`)
    axisymmetric = False
    #: whether the kind integrates in time (``--dynamic``: :mod:`contactfx.driver.inertia`)
    dynamic = False
    #: whether the kind offers the penalty's contact dashpot in time (``--dashpot``: a law in
    #: UFL on its surface, :meth:`contactfx.contact.penalty.Penalty.dashpot_residual`)
    dashpot = False
    #: Newton stops at the residual's round-off level too (:class:`contactfx.solvers.snes.
    #: _RoundOffStop`): finite strain, and an interference fit (the interference's own contact
    #: forces set a floor that a well-predicted step's relative tolerance does not reach)
    roundoff_stop = False

    scene: Scene
    num: Numerics
    method: Method
    mesh: dolfinx.mesh.Mesh
    facet_tags: Any
    gdim: int
    fdim: int
    friction: Friction | None
    #: a :class:`contactfx.mechanics.material.Material` (the kinds use the small-strain
    #: material's ``sigma`` too)
    material: Any
    tload: dolfinx.fem.Constant
    h: Expr
    mult_shape: tuple[int, ...]
    #: the facets of the contact surface (set by the kind before ``Problem.__init__``)
    contact_facets: NDArray[np.int32]
    confined: list[Any]
    bcs: list[Any]
    prev: dolfinx.fem.Function | None
    t_prev: dolfinx.fem.Function | None
    _history: Filler | None
    multiplier: dolfinx.fem.Function | None
    surface: KindSurface | None
    ds: ufl.Measure
    v_load: Expr
    iterate: dolfinx.fem.Function | None
    # the unknowns (``_spaces``)
    multiplier_field: bool
    up: bool
    split: bool
    V: Any
    state: dolfinx.fem.Function
    trial: Expr
    test: Expr
    U: Expr
    dU: Expr
    V_test: Expr
    lam: Expr | None
    lam_test: Expr | None
    p: Expr | None
    dp: Expr | None
    q: Expr | None

    @classmethod
    def check(cls, scene: Scene, numerics: Numerics, method: Method) -> None:
        """Raise ValueError for a request this kind cannot solve (before any collective)."""

    def __init__(
        self,
        scene: Scene,
        numerics: Numerics,
        method: Method,
        mesh: dolfinx.mesh.Mesh,
        facet_tags: Any,
    ) -> None:
        self.scene, self.num, self.method = scene, numerics, method
        self.mesh, self.facet_tags = mesh, facet_tags
        self.gdim = mesh.geometry.dim
        self.fdim = mesh.topology.dim - 1
        self.friction = numerics.friction_law()
        #: the bulk's material: the scene's, under ``--material`` (a finite-strain model)
        self.material = numerics.bulk_material(self.material_of(mesh))
        #: the volume measure: weighted by r for an axisymmetric body, whose material then
        #: carries the hoop strain
        self.dx = measure("dx", mesh, scene.axisymmetric)
        if scene.axisymmetric:
            self.material = dataclasses.replace(self.material, hoop=hoop_strain(mesh))
        self.tload = dolfinx.fem.Constant(mesh, 0.0)
        self.h = _compat.cell_diameter(mesh)
        self.mult_shape = (self.gdim,) if self.friction is not None else ()
        self._spaces()
        #: a dynamic run's inertia (:mod:`contactfx.driver.inertia`), None in a static run
        self.inertia = Inertia(self) if numerics.dynamic else None
        self.confined: list = []  # those of bcs that confine a field to a surface (confine)
        self.bcs = self.boundary_conditions()
        self.prev = None  # the last converged state: the history of friction
        if self.friction is not None:
            self.prev = dolfinx.fem.Function(self.state.function_space)
        #: the tangential traction of the last converged step at the surface's nodes (P1),
        #: for a method whose friction law keeps it (``traction_history``), else None
        self.t_prev = None
        self._history = None
        if self.friction is not None and method.traction_history:
            space = self.surface_space((self.gdim,))
            self.t_prev = dolfinx.fem.Function(space, name="traction_history")
        #: a nodal multiplier (the method's outer loop updates it), or None
        self.multiplier = None
        nodal = method.multiplier.nodal_shape(self.mult_shape)
        if nodal is not None:
            space = self.surface_space(nodal)
            self.multiplier = dolfinx.fem.Function(space, name="multiplier")
            self.lam = self.multiplier
        setup = self.make_surface()
        #: the Surface the methods write against (None: two bodies, a coupling instead), the
        #: boundary measure the scene's loads integrate over, the test function they act on
        self.surface, self.ds, self.v_load = setup.surface, setup.ds, setup.v_load
        if self.surface is not None and method.nodal_size:
            self.surface = dataclasses.replace(self.surface, h_nodal=self._nodal_size())
        #: Newton's previous iterate (the friction law's reversal guard), or None
        self.iterate = None

    def surface_space(self, shape: tuple[int, ...]) -> Any:
        """The space of a method's values on the contact surface (a nodal multiplier, a
        traction history): P1, the law collocated at the surface's nodes."""
        return _compat.function_space(self.mesh, "Lagrange", 1, shape or None)

    def material_of(self, mesh: dolfinx.mesh.Mesh) -> Any:
        """The material of the body (or bodies) on ``mesh``: the scene's."""
        return self.scene.material()

    # -- the hooks every kind provides (docs/architecture.md, "Adding a problem kind") -----
    def boundary_conditions(self) -> list[Any]:
        """The DirichletBCs: the scene's supports, and ``confine_multiplier`` for a
        multiplier field (called before ``make_surface``; ``contact_facets`` is set)."""
        raise NotImplementedError(f"{type(self).__name__} has no boundary conditions")

    def make_surface(self) -> SurfaceSetup:
        """The contact surface and the loads' measure and test function."""
        raise NotImplementedError(f"{type(self).__name__} has no contact surface")

    def apply_load(self, t: float) -> None:
        """Set the load program's constants for time (load factor) t."""
        raise NotImplementedError(f"{type(self).__name__} has no load program")

    def start(self, solver: Solver) -> None:
        """Set the state the first Newton solve starts from (``solver``: the kind's
        ContactSNES, for a linear start)."""
        raise NotImplementedError(f"{type(self).__name__} has no start")

    def post_processor(self) -> Any:
        """An object with ``evaluate(solver) -> Quantities``, ``fields()`` and
        ``finish(quantities, out) -> dict``."""
        raise NotImplementedError(f"{type(self).__name__} has no post-processing")

    @functools.cached_property
    def volume_ratio(self) -> VolumeRatio:
        """J = det F of the displacement at sample points of every cell (a finite-strain
        material): what the solver's step halving and :meth:`diagnose` ask."""
        return VolumeRatio(self.material.jacobian(self.U), self.state, self.num.degree)

    def diagnose(self) -> str:
        """What the state shows after a failed solve (collective): with a finite-strain
        material the smallest volume ratio J = det F over the cells' sample points
        (:attr:`volume_ratio`) and the midpoint of its cell, when an element has inverted
        (J <= 0); with a near-incompressible body in P1 displacements the locking hint
        (:func:`contactfx.mechanics.elasticity.locking_hint`); else ""."""
        hint = locking_hint(self.largest_nu(), self.num.degree, self.num.formulation)
        if not self.material.finite_strain:
            return hint
        j_min, where = self.volume_ratio.smallest(_compat.petsc_vec(self.state))
        if not j_min <= 0.0:
            return hint
        at = ", ".join(f"{x:.4g}" for x in where[: self.gdim])
        value = "not a number" if np.isinf(j_min) else f"= {j_min:.3g} <= 0"
        inverted = f"an element inverted (J {value}) at ({at}) in the reference mesh"
        return inverted + (f"; {hint}" if hint else "")

    def largest_nu(self) -> float | None:
        """The largest Poisson's ratio of the bulk (its field's, bodies of several materials),
        None for a material without one (collective)."""
        nu = getattr(self.material, "nu", None)
        field = getattr(self.material, "poisson", None)
        if isinstance(field, dolfinx.fem.Function):
            local = float(np.max(field.x.array, initial=-1.0))
            nu = max(nu if nu is not None else -1.0, self.mesh.comm.allreduce(local, op=MPI.MAX))
        return nu

    @property
    def multiplier_mask(self) -> NDArray[np.bool_]:
        """A nodal multiplier's dofs on the contact surface (bool per local dof)."""
        raise NotImplementedError(f"{type(self).__name__} has no nodal multiplier")

    def nodal_update(self, expr: Expr) -> Filler:
        """The filler of a nodal multiplier with the values of ``expr`` at its nodes."""
        raise NotImplementedError(f"{type(self).__name__} has no nodal multiplier")

    # -- unknowns ------------------------------------------------------------------------
    def _spaces(self) -> None:
        """The unknown: [P_k]^(c d), or a mixed space with a P1 multiplier (a method whose
        strategy asks for a multiplier field) or the P1 pressure (mixed u-p formulation) as
        second field."""
        num, mesh = self.num, self.mesh
        n = self.components_per_dim * self.gdim
        shape = self.method.multiplier.field_shape(self.mult_shape)
        #: whether the unknown carries a multiplier field (its second field)
        self.multiplier_field = field = shape is not None
        self.up = num.formulation == "mixed-up"
        self.split = field or self.up
        if self.split:
            W = _compat.mixed_space(mesh, num.degree, n, shape if field else ())
            self.V = W.sub(0)
        else:
            W = self.V = _compat.function_space(mesh, "Lagrange", num.degree, (n,))
        self.state = dolfinx.fem.Function(W, name="state" if self.split else "displacement")
        self.trial, self.test = ufl.TrialFunction(W), ufl.TestFunction(W)
        if self.split:
            (self.U, extra), (self.dU, d_extra), (self.V_test, extra_test) = (
                ufl.split(f) for f in (self.state, self.trial, self.test)
            )
        else:
            self.U, self.dU, self.V_test = self.state, self.trial, self.test
            extra = d_extra = extra_test = None
        self.lam, self.lam_test = (extra, extra_test) if field else (None, None)
        self.p, self.dp, self.q = (extra, d_extra, extra_test) if self.up else (None,) * 3

    #: where a multiplier stays zero on the contact surface (a predicate of points, or None)
    multiplier_excluded: PointPredicate | None = None

    def confine_multiplier(self, supports: Sequence[Any] = ()) -> list[Any]:
        """A multiplier field is zero away from the contact surface, and a traction
        multiplier's component i is zero where the displacement's component i is held by one
        of the ``supports`` (a symmetry plane through the contact zone): there that component
        of the contact law has no displacement left to act on, and its row and column of the
        Jacobian would be zero (a singular system). On a symmetry plane the traction component
        normal to the plane vanishes anyway."""
        if not self.multiplier_field:
            return []
        W1 = self.state.function_space.sub(1)

        def on_surface(Q: Any) -> NDArray[np.bool_]:
            return surface_mask(Q, self.fdim, self.contact_facets, self.multiplier_excluded)

        held_dofs = [np.asarray(_compat.bc_dofs(bc)) for bc in supports]
        if not self.mult_shape or not held_dofs:
            return self.confine(W1, on_surface)
        held = np.concatenate(held_dofs)
        bcs: list[Any] = []
        for i in range(self.gdim):
            Vi, to_w = self.V.sub(i).collapse()
            points = _compat.dof_coordinates(Vi)[np.isin(np.asarray(to_w), held)]

            def mask(Q: Any, p: NDArray[np.float64] = points) -> NDArray[np.bool_]:
                return on_surface(Q) & ~at_nodes(Q, p)

            bcs += self.confine(W1.sub(i), mask)
        return bcs

    def confine(self, Wsub: Any, mask_of: Callable[[Any], NDArray[np.bool_]]) -> list[Any]:
        """:func:`contactfx.driver.fields.confine`, the conditions recorded in ``confined``:
        the solver leaves their dofs out of its linear systems."""
        bcs = confine(Wsub, mask_of)
        self.confined += bcs
        return bcs

    def previous(self) -> Expr:
        """The displacement part of the last converged state (friction history)."""
        return ufl.split(self.prev)[0] if self.split else self.prev

    # -- measures --------------------------------------------------------------------------
    def contact_rule(self) -> dict[str, Any]:
        """Gauss (degree 2k + 2) or the vertex rule (``--quadrature nodal``: the contact law at
        the P1 nodes only, so that a curved obstacle does not over-constrain the piecewise
        linear surface when gamma0 / the penalty is large)."""
        if self.num.quadrature == "nodal":
            return vertex_rule(self.fdim)
        return {"quadrature_degree": 2 * self.num.degree + 2}

    # -- forms ---------------------------------------------------------------------------
    def forms(self) -> Forms:
        """The bulk (its compiled forms, assembled when called), the compiled contact residual
        and its consistent Jacobian (None, None for a method without contact terms)."""
        L = self.scene.load(self.v_load, self.ds, self.tload)
        if L is None:
            L = (
                ufl.inner(dolfinx.fem.Constant(self.mesh, np.zeros(self.gdim)), self.v_load)
                * self.dx
            )
        L = self.extra_load(L)
        #: the compiled external load f_ext (a dynamic run's energy balance reads it)
        self.load_form = load = dolfinx.fem.form(L)
        if self.inertia is not None:  # the bulk's load: + M a*
            load = dolfinx.fem.form(L + self.inertia.load_term(self.V_test))
        # two bodies: no UFL surface, the contact terms are the solver's coupling
        F = None if self.surface is None else self.contact_residual()
        bulk = self.bulk(load)
        if F is None:
            return Forms(bulk, None, None)
        J = ufl.derivative(F, self.state, self.trial)
        return Forms(bulk, dolfinx.fem.form(F), dolfinx.fem.form(J))

    def bulk(self, load: Any) -> Callable[[], Bulk]:
        """The kind's bulk for the compiled load form ``load``, built (and assembled) when
        called: for a linear material a :class:`contactfx.solvers.bulk.LinearBulk` of
        :meth:`bulk_form` (bilinear, assembled once), else a
        :class:`contactfx.solvers.bulk.NonlinearBulk` of :meth:`internal_form` and its
        ``ufl.derivative`` (plus :meth:`tangent_pattern`), assembled at every iteration."""
        inertia = self.inertia
        if self.material.linear:
            form = self.bulk_form()
            if inertia is not None:  # K + c M
                form = form + inertia.mass_term(self.dU, self.V_test)
            a = dolfinx.fem.form(form)
            return functools.partial(LinearBulk, stiffness=a, load=load)
        f_int = self.internal_form()
        if inertia is not None:  # + c rho u . v (M a* is in the load)
            f_int = f_int + inertia.internal_term(self.U, self.V_test)
        tangent = ufl.derivative(f_int, self.state, self.trial)
        pattern = self.tangent_pattern()
        if pattern is not None:
            tangent = tangent + pattern
        return functools.partial(
            NonlinearBulk,
            internal=dolfinx.fem.form(f_int),
            tangent=dolfinx.fem.form(tangent),
            load=load,
        )

    def bulk_form(self) -> ufl.Form:
        """The bulk's bilinear form a(du, v) of a linear material (trial ``trial``)."""
        raise NotImplementedError(f"{type(self).__name__} has no bulk form")

    def internal_form(self) -> ufl.Form:
        """The bulk's internal virtual work f_int(u; v), linear in ``test``, of the state (a
        kind with ``nonlinear_bulk``)."""
        raise NotImplementedError(f"{type(self).__name__} has no nonlinear bulk")

    def tangent_pattern(self) -> ufl.Form | None:
        """Zero terms (bilinear in ``trial``, ``test``) that give the bulk's tangent the
        sparsity of the contact terms, or None."""
        return None

    def contact_residual(self) -> ufl.Form:
        """The method's contact residual on the kind's surface (Newton's: ``newton_surface``),
        with ``--dashpot`` the dashpot's at the velocity of the force time (c_v u - v*: the
        step's unknown u, :mod:`contactfx.solvers.dynamics`)."""
        s = self.newton_surface()
        form = self.method.residual(s)
        inertia = self.inertia
        if inertia is not None and inertia.dashpot is not None:
            velocity = inertia.velocity(self.state)
            form = form + self.method.dashpot_residual(s, inertia.dashpot, velocity)
        return form

    @overload
    def newton_surface(self) -> KindSurface: ...

    @overload
    def newton_surface(self, s: _S) -> _S: ...

    def newton_surface(self, s: KindSurface | None = None) -> KindSurface:
        """The surface of Newton's residual (``s``, by default the kind's): with friction, a
        point whose trial tangential traction reversed since Newton's previous iterate
        (``iterate``, kept by the solver) takes the stick branch
        (:func:`contactfx.contact.laws.reversal`); at a converged iterate this is the surface
        itself."""
        s = self.surface if s is None else s
        assert s is not None  # a kind with a UFL surface
        trial = None if s.friction is None else self.method.trial_traction(s)
        if trial is None:
            return s
        if self.iterate is None:
            self.iterate = dolfinx.fem.Function(self.state.function_space, name="iterate")
        x, bound = trial
        x_last = ufl.replace(x, {self.state: self.iterate})
        return dataclasses.replace(s, stick=reversal(x, x_last, bound))

    def extra_load(self, L: ufl.Form) -> ufl.Form:
        return L

    def output_split(self) -> Split | None:
        """How the ParaView output splits the body's nodes (:class:`contactfx.io.vtk.Split`):
        None, one body with continuous fields."""
        return None

    def coupling(self) -> Any:
        """The solver's two-body coupling (:mod:`contactfx.contact.coupling`), or None."""
        return None

    def nodal_rule(self) -> tuple[ufl.Measure, str | None]:
        """(the contact measure with the vertex rule, the restriction of its integrands or
        None): where the traction history and the nodal mesh size are evaluated."""
        raise NotImplementedError(f"{type(self).__name__} has no vertex rule on its surface")

    def _nodal_size(self) -> Expr:
        """The surface's mesh size at its P1 nodes (``SurfaceData.h_nodal``): the lumped
        projection of the facet-wise h with the vertex rule, the length-weighted mean of the
        sizes of a node's facets."""
        assert self.surface is not None
        measure, restrict = self.nodal_rule()
        h = dolfinx.fem.Function(_compat.function_space(self.mesh, "Lagrange", 1), name="h")
        proj = NodalProjection(measure, h.function_space, restrict)
        proj(proj.form(self.surface.h), h)
        return h if restrict is None else h(restrict)

    def converged(self) -> None:
        """A step converged: it is the history of the next (the state and, for a method that
        keeps it, the tangential traction at the surface's nodes: with the vertex rule the
        law's own nodal values, averaged over the facets of a node where they differ)."""
        if self.t_prev is not None:
            if self._history is None:
                self._history = self.history_update(self.method.tangential_traction)
            self._history(self.t_prev)
        if self.prev is not None:
            self.prev.x.array[:] = self.state.x.array

    def surface_update(self, law: Callable[[Any], Expr]) -> Filler:
        """The filler of a nodal multiplier with ``law(surface)`` (a UFL expression on the
        contact surface): its values at the surface's nodes."""
        return self.nodal_update(law(self.surface))

    def history_update(self, law: Callable[[Any], Expr]) -> Filler:
        """The filler of the traction history with ``law(surface)`` at the surface's nodes:
        the vertex rule's lumped projection."""
        assert self.t_prev is not None
        measure, restrict = self.nodal_rule()
        proj = NodalProjection(measure, self.t_prev.function_space, restrict)
        form = proj.form(law(self.surface))
        return lambda target: proj(form, target)

    def nested_fields(self) -> list[dolfinx.fem.Function]:
        """The Functions nested iteration carries from a coarser mesh: the state and the
        nodal multiplier."""
        return [self.state] + ([self.multiplier] if self.multiplier is not None else [])

    def dofs(self) -> int:
        """The unknowns the solver solves for: the state's dofs but the confined ones."""
        return self.dofs_less(self.confined)

    def dofs_less(self, bcs: Sequence[Any]) -> int:
        """The state's dofs less those the DirichletBCs ``bcs`` fix (each once)."""
        W = self.state.function_space
        fixed = len(owned_bc_dofs(bcs, owned_size(W)))
        imap = W.dofmap
        return imap.index_map.size_global * imap.index_map_bs - self.mesh.comm.allreduce(
            fixed, op=MPI.SUM
        )
