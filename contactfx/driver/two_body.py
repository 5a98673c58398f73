"""The two-body problem kind: separately meshed elastic bodies in one dolfinx mesh (they share
no node), a material per body, and a contact pair (slave surface, master surface) enforced by
a two-body method's coupling (:mod:`contactfx.contact.coupling`).

Materials: small-strain elasticity with a DG0 field of E and nu over the bodies' cells (a
bilinear bulk, assembled once), or finite strain when any body is hyperelastic (a model of
:mod:`contactfx.mechanics.hyperelastic`): under a finite-strain ``--material`` the same model
in every body, each with its own small-strain E and nu from the scene; in a problem file each
body's own model and parameters (``scene.materials()``). The internal work is then
sum_i int_{body i} S_i(u) : grad v dX over the cell tags (a nonlinear bulk, assembled at every
Newton iteration), S_i the body's weak stress (a hyperelastic body's first Piola stress).
Finite strain searches the pair at every Newton iteration (the contact in the deformed
configuration, :mod:`contactfx.contact.point_coupling`) and is offered with penalty and
Nitsche, with or without Coulomb friction (Nitsche: the slave body's first Piola traction in
its consistency term, a neo-Hookean, Saint Venant-Kirchhoff or linear slave body); the contact's
parameters scale with the small-strain E, lambda, mu of each facet's body (a hyperelastic
model's linearisation at F = I).

A linear body among finite-strain ones (a problem file's stiff steel part on a rubber one)
keeps its small-strain stress, S = sigma(u), its term sigma(u) : eps(v): the model the file
names, geometrically linear, as a linearised-elasticity term on one region of a model whose
other regions are finite-strain (GetFEM's linearized and finite-strain elasticity bricks).
It is exact for translations, the motion of a stiff indenter, and for small strains and
rotations, but not objective: a rigid rotation by theta gives the small strain
(cos(theta) - 1) I, about -theta^2 / 2, and its stress (Bonet and Wood 2008,
doi:10.1017/CBO9780511755446, the kinematics chapter). A linear-elastic part of a
geometrically nonlinear analysis in the commercial codes (Abaqus's NLGEOM) is instead
Hooke's law in a rotating frame: for small strains under large rotations that is ``svk``
with the same E and nu (Hooke's law between the Green strain and the second Piola stress,
objective). We keep the named model rather than refuse it (a stiff indenter that translates
is the common case, and refusing would force a finite-strain model where it changes
nothing) or replace it silently, and report the largest |skew grad u| over the linear
bodies' cells at the last step (sin theta of a rigid rotation by theta) as run.json's score
``linear_body_rotation``: its square over two is the spurious strain, to compare with the
body's strains.
"""

from __future__ import annotations

import functools
import operator
from collections.abc import Callable
from pathlib import Path
from typing import Any

import dolfinx
import numpy as np
import ufl
from mpi4py import MPI
from numpy.typing import NDArray

from contactfx import _compat
from contactfx.contact.coupling import NodeLayout
from contactfx.contact.laws import Coulomb, Tresca
from contactfx.contact.pair import ContactPair, Facets, Side, node_held, side_of
from contactfx.contact.point_coupling import nitsche_finite_strain_refusal
from contactfx.contact_edge import ContourMeasure, check_edge_rule, facet_dofs
from contactfx.driver.fields import nodal_contact
from contactfx.driver.interface_post import pyplot
from contactfx.driver.obstacle import closed_form_errors
from contactfx.driver.problem import Method, Numerics, Problem, Scene, Solver, SurfaceSetup
from contactfx.mechanics.elasticity import lame
from contactfx.mechanics.piola import LINEAR, STRESS_MODELS
from contactfx.results import Friction, Quantities

__all__ = ["TwoBodyProblem", "TwoBodyPost", "plot_pressure"]


def _not_offered(
    method: Method, capability: str, what: str, test: Callable[[Any], bool]
) -> ValueError:
    """The one-line refusal: the method, what it lacks, its reason (``why_not``) and the
    methods whose ``supports`` pass ``test``."""
    from contactfx.contact.registry import methods_supporting

    reason = method.supports.why_not.get(capability, "not implemented")
    return ValueError(
        f"method {method.name} {what} ({reason}); use " + ", ".join(methods_supporting(test))
    )


class TwoBodyProblem(Problem):
    """Bodies in contact through a pair of non-matching surfaces (see the module docstring)."""

    #: a hyperelastic material is written as an internal work (``internal_form``)
    nonlinear_bulk = True

    #: no UFL surface: the contact is the solver's coupling of the pair
    surface: None
    #: whether the bodies are finite-strain (a hyperelastic ``--material``)
    finite_strain: bool
    #: finite strain: each body's material by its cell tag (empty for small strain)
    body_materials: dict[int, Any]
    layout: NodeLayout
    pair: ContactPair
    _coupling: Any
    #: an interference fit's largest overlap at the start (0: none recorded)
    initial_overlap: float = 0.0
    #: bodies in time (``--dynamic``): the contact's stored energy is the coupling's sum
    #: over its Gauss points (``PointCoupling.energy``; frictionless, small strain: else it
    #: is in the balance's remainder while the bodies touch)
    dynamic = True

    @classmethod
    def check(cls, scene: Scene, numerics: Numerics, method: Method) -> None:
        if not method.supports.two_body:
            raise _not_offered(
                method, "two_body", "is not offered between two meshed bodies", lambda c: c.two_body
            )
        if numerics.degree != 1:
            raise ValueError("two-body contact is implemented for P1 (--degree 1) only")
        if numerics.formulation != "displacement":
            raise ValueError("two-body contact uses --formulation displacement")
        if numerics.quadrature != "gauss":
            # the vertex rule was measured to make it worse: node-to-segment gaps see the
            # master polygon's kinks (docs/verification.md, two bodies)
            raise ValueError(
                f"--quadrature {numerics.quadrature} is not offered between two meshed bodies "
                "(at the slave vertices the pressure follows the master polygon's kinks and "
                "oscillates more than at Gauss points); use --quadrature gauss"
            )
        if numerics.friction != "none" and not method.supports.two_body_friction:
            raise _not_offered(
                method,
                "two_body_friction",
                "has no friction between two meshed bodies",
                lambda c: c.two_body and c.two_body_friction and "coulomb" in c.friction,
            )
        if numerics.friction == "tresca" and not method.supports.two_body_tresca:
            raise _not_offered(
                method,
                "two_body_tresca",
                "has no Tresca friction between two meshed bodies",
                lambda c: c.two_body and c.two_body_tresca,
            )
        if scene.slave_tag == scene.master_tag:
            raise ValueError("the slave and master surfaces of a contact pair must differ")
        if scene.smoothing() == "normals" and method.name != "mortar":
            raise ValueError(
                f'contact.0.smoothing = "{scene.smoothing()}" is mortar\'s (its weighted nodal '
                f"gaps); {method.name} measures the gap between the facets at Gauss points: "
                "remove the key or use --method mortar"
            )

    def __init__(
        self,
        scene: Scene,
        numerics: Numerics,
        method: Method,
        mesh: dolfinx.mesh.Mesh,
        facet_tags: Any,
    ) -> None:
        self.contact_facets = facet_tags.indices[facet_tags.values == scene.slave_tag]
        # each body's material: the scene's (a problem file's own model, or the small-strain
        # E and nu of a built-in scene) under --material
        materials = {
            int(scene.cells[body]): numerics.bulk_material(m)
            for body, m in scene.materials().items()
        }
        self.finite_strain = any(m.finite_strain for m in materials.values())
        self.body_materials = materials if self.finite_strain else {}
        if self.finite_strain and method.name == "nitsche":
            names = [m.name if m.finite_strain else "linear" for m in materials.values()]
            refusal = nitsche_finite_strain_refusal(names)
            if refusal is not None:
                raise ValueError(refusal)
        super().__init__(scene, numerics, method, mesh, facet_tags)
        # penalty friction's history is the coupling's (per Gauss point of the slave surface)
        self.t_prev = None

    def converged(self) -> None:
        super().converged()
        self.coupling().converged()

    def material_of(self, mesh: dolfinx.mesh.Mesh) -> Any:
        """Small strain: the bodies' material with DG0 fields of E and nu. Finite strain: a
        finite-strain body's material before ``--material`` (the slave's if it is one), which
        makes the bulk nonlinear and answers the volume ratio of ``diagnose``; the bulk is
        written per body with ``body_materials``."""
        if not self.finite_strain:
            return self.scene.body_material(mesh)
        slave = self.scene.material()
        if self.num.bulk_material(slave).finite_strain:
            return slave
        return next(
            m for m in self.scene.materials().values() if self.num.bulk_material(m).finite_strain
        )

    def boundary_conditions(self) -> list[Any]:
        return self.scene.dirichlet(self.V, self.facet_tags)

    def make_surface(self) -> SurfaceSetup:
        """No UFL surface: the contact is the solver's coupling of the pair (``pair``, its
        ``layout``)."""
        mesh, scene, comm = self.mesh, self.scene, self.mesh.comm
        self.ds = ufl.Measure("ds", domain=mesh, subdomain_data=self.facet_tags)
        self.v_load = self.V_test
        for tag, what in ((scene.slave_tag, "slave"), (scene.master_tag, "master")):
            count = comm.allreduce(int(np.sum(self.facet_tags.values == tag)), op=MPI.SUM)
            if count == 0:
                raise ValueError(f"the {what} surface (facet tag {tag}) has no facet")
        self.check_edge_rule()
        self.layout = NodeLayout(self.V)
        n_dofs = self.layout.n_owned * self.layout.bs
        fixed = np.zeros(n_dofs, dtype=bool)  # owned Dirichlet dofs (symmetry planes, rollers)
        for bc in self.bcs:
            dofs = np.asarray(_compat.bc_dofs(bc))
            fixed[dofs[dofs < n_dofs]] = True
        self.pair = ContactPair(
            self.layout,
            # the rims of the surfaces without their edges on symmetry planes
            side_of(self.V, self.facet_tags, scene.slave_tag, fixed),
            side_of(self.V, self.facet_tags, scene.master_tag, fixed),
            scene.contact_modulus(),
            # finite strain: the contact in the deformed configuration, searched at every
            # Newton iteration (large sliding moves a point across master facets in a step)
            search_each_newton=self.num.search_update == "newton" or self.finite_strain,
            fixed=fixed,
            finite_strain=self.finite_strain,
            smooth={"normals": True, "none": False}.get(scene.smoothing()),
        )
        if isinstance(self.friction, Coulomb):
            self.pair.mu = self.friction.mu
        elif isinstance(self.friction, Tresca):
            self.pair.threshold = self.friction.threshold
        self.pair.previous = self.prev
        self.pair.slave_lame = self._lame(self.pair.slave)
        self.pair.master_lame = self._lame(self.pair.master)
        if self.finite_strain:
            self.pair.slave_model = self._model(self.pair.slave)
            self.pair.master_model = self._model(self.pair.master)
        return SurfaceSetup(None, self.ds, self.v_load)

    def _lame(self, side: Side) -> NDArray[np.float64]:
        """(m, 3): E, lambda, mu of the cell of each facet of ``side``, which scale the
        contact's parameters (the penalty kappa E / h) and its small-strain traction (finite
        strain: the small-strain constants of the cell's body's own material, a hyperelastic
        model's E, lambda, mu of its linearisation at F = I)."""
        if self.finite_strain:
            tags = self._cell_body(side.cell)
            out = np.zeros((len(side.cell), 3))
            for tag, m in self.body_materials.items():
                out[tags == tag] = (m.E, m.lmbda, m.mu)
            return out
        mat = self.material
        fields = [mat.modulus, mat.poisson]
        dofs = np.array(
            [fields[0].function_space.dofmap.cell_dofs(c)[0] for c in side.cell], dtype=np.int64
        )
        E, nu = (f.x.array[dofs] for f in fields)
        return np.stack([E, *lame(E, nu)], axis=1)

    def _model(self, side: Side) -> NDArray[np.int64]:
        """(m,) the stress model of the cell of each facet of ``side`` (finite-strain Nitsche's
        consistency term, :func:`contactfx.mechanics.piola.first_piola`)."""
        tags = self._cell_body(side.cell)
        out = np.full(len(side.cell), LINEAR, dtype=np.int64)
        for tag, m in self.body_materials.items():
            # (a model Nitsche does not evaluate is refused before; penalty reads none)
            out[tags == tag] = STRESS_MODELS.get(m.name, LINEAR) if m.finite_strain else LINEAR
        return out

    def coupling(self) -> Any:
        if not hasattr(self, "_coupling"):
            self._coupling = self.method.coupling(self.pair)
        return self._coupling

    def _cell_body(self, cells: NDArray[np.int64]) -> NDArray[np.int64]:
        """The body (cell tag) of each local cell of ``cells``; -1 for an untagged cell."""
        cell_tags = self.scene.cell_tags
        imap = self.mesh.topology.index_map(self.mesh.topology.dim)
        tag = np.full(imap.size_local + imap.num_ghosts, -1, dtype=np.int64)
        tag[cell_tags.indices] = cell_tags.values
        return tag[np.asarray(cells, dtype=np.int64)]

    def bulk_form(self) -> ufl.Form:
        eps = ufl.sym(ufl.grad(self.V_test))
        return ufl.inner(self.material.sigma(self.dU), eps) * ufl.dx

    def internal_form(self) -> ufl.Form:
        """sum over the bodies of int_{body i} S_i(u) : grad v dX over each body's cells (the
        cell tags), in the reference configuration, with S_i the weak stress of the body's own
        material (``body_materials``): a hyperelastic body's first Piola stress P_i(F); a
        linear body's small-strain stress sigma(u), so that its term is sigma(u) : eps(v), as
        in a small-strain run (see the module docstring: geometrically linear)."""
        dx = ufl.Measure("dx", domain=self.mesh, subdomain_data=self.scene.cell_tags)
        grad_v = ufl.grad(self.V_test)
        forms = [
            ufl.inner(m.weak_stress(self.U), grad_v) * dx(tag)
            for tag, m in self.body_materials.items()
        ]
        return functools.reduce(operator.add, forms)

    def von_mises(self) -> Any:
        """The von Mises stress of the state: of the Cauchy stress of each body's material
        (finite strain: a DG0 indicator of each body's cells times its material's; a linear
        body's small-strain stress)."""
        if not self.finite_strain:
            return self.material.von_mises(self.state)
        terms = [
            self._indicator([tag]) * m.von_mises(self.state)
            for tag, m in self.body_materials.items()
        ]
        return functools.reduce(operator.add, terms)

    @property
    def small_strain_tags(self) -> list[int]:
        """The cell tags of the linear (small-strain) bodies of a finite-strain problem."""
        return [tag for tag, m in self.body_materials.items() if not m.finite_strain]

    def small_strain_rotation(self) -> Any:
        """|skew grad u| = sqrt(W : W / 2), W = skew(grad u), on the cells of the linear bodies
        (0 elsewhere): sin(theta) of a rigid rotation by theta, whose small-strain strain is
        the spurious (cos(theta) - 1) I, about -|W|^2 / 2 (the module docstring)."""
        W = ufl.skew(ufl.grad(self.U))
        return self._indicator(self.small_strain_tags) * ufl.sqrt(0.5 * ufl.inner(W, W))

    def _indicator(self, tags: list[int]) -> dolfinx.fem.Function:
        """The DG0 indicator of the cells of the bodies ``tags``."""
        DG0 = _compat.function_space(self.mesh, "DG", 0)
        dofs = _compat.cell_dofs(DG0)[:, 0]  # every local cell's dof, in cell order
        body = self._cell_body(np.arange(len(dofs), dtype=np.int64))
        chi = dolfinx.fem.Function(DG0)
        chi.x.array[dofs] = np.isin(body, tags).astype(float)
        return chi

    # -- load program ------------------------------------------------------------------------
    def apply_load(self, t: float) -> None:
        self.tload.value = t
        self.scene.set_load(t)
        # an interference fit: the hidden part of the initial overlap, (1 - t)
        self.pair.load = t

    @property
    def roundoff_stop(self) -> bool:  # type: ignore[override]
        """An interference fit: Newton stops at the residual's round-off level too (the
        predicted step starts near the solution, the interference's contact forces set the
        floor)."""
        return self.scene.interference() is not None

    def initial_gap(self) -> tuple[float, float]:
        """(the least gap of the pair at the start over all ranks, the overlap tolerated
        without ``contact.interference``: 1 % of the contact element size, since two
        polygonal approximations of touching curved surfaces cross by O(h^2 / R)): the
        coupling searched at u = 0 (its gaps between the facets: the Gauss points' or the
        weighted nodal gaps). Collective."""
        coupling = self.coupling()
        coupling.update(np.zeros_like(self.state.x.array))
        gaps = coupling.search_gaps(facets=True)
        least = self.mesh.comm.allreduce(float(np.min(gaps, initial=np.inf)), op=MPI.MIN)
        return least, 1e-2 * self.scene.h_contact()

    def overlap_refusal(self, least: float, tol: float) -> str | None:
        """Why the start is refused: an overlap of more than ``tol`` without
        ``contact.interference``, or None."""
        if least >= -tol or self.scene.interference() is not None:
            return None
        return (
            f"the bodies overlap by {-least:.3g} at the start (more than {tol:.3g}): for a "
            'press or shrink fit set interference = "ramp" on the [[contact]] pair (the '
            "overlap removed over the load program), else move them apart or correct the "
            "geometry"
        )

    def start(self, solver: Solver) -> None:
        """From the undeformed state (the Dirichlet values are set by the solve), after two
        checks of the geometry at the start (collective, so that every rank raises alike):
        the bodies must not overlap by more than 1 % of the contact element size
        (:meth:`initial_gap`) unless the pair is an interference fit, and a body without any
        support must touch the other one (else the first solve is singular; in time its mass
        holds it). An interference
        fit (``contact.interference = "ramp"``) records the initial gaps g0 in the coupling,
        whose law then takes g + (1 - t) max(-g0, 0) at the load factor t: at t = 0 the
        overlap is hidden, at t = 1 the whole interference acts."""
        comm, scene = self.mesh.comm, self.scene
        coupling = self.coupling()
        least, tol = self.initial_gap()
        refusal = self.overlap_refusal(least, tol)
        if refusal is not None:
            raise ValueError(refusal)
        if scene.interference() == "ramp":
            coupling.record_start()
            self.pair.interference = True
            #: the largest overlap at the start (run.json's score ``initial_overlap``)
            self.initial_overlap = max(-least, 0.0)
        fixed = np.zeros(len(self.state.x.array) // self.gdim, dtype=bool)
        for bc in self.bcs:
            fixed[np.asarray(_compat.bc_dofs(bc)) // self.gdim] = True
        cell_tags = scene.cell_tags
        for body, tag in scene.cells.items():
            cells = cell_tags.indices[cell_tags.values == tag]
            dofs = np.unique([self.V.dofmap.cell_dofs(c) for c in cells]) if len(cells) else []
            supported = comm.allreduce(
                bool(np.any(fixed[np.asarray(dofs, dtype=np.int64)])), op=MPI.LOR
            )
            if not supported and not least <= tol and not self.num.dynamic:
                raise ValueError(
                    f"the {body} body has no support and does not touch the other "
                    f"one at the start (closest gap {least:.3g}): the solve would "
                    "be singular"
                )
        # the scene's initial state (a problem file's ``initial.displacement``; in time the
        # initial displacement)
        scene.initial_guess(self.state, 0.0)

    def check_edge_rule(self) -> None:
        """Refuse a contact edge rule that does not apply to the slave surface (x-band on a
        half or quarter model) in one line, before the solve. Collective."""
        rule = self.scene.contact_edge_rule()
        if rule is None:
            return
        fdim = self.mesh.topology.dim - 1
        facets = self.facet_tags.indices[self.facet_tags.values == self.scene.slave_tag]
        x = _compat.entity_coordinates(self.mesh, fdim, facets).reshape(-1, self.mesh.geometry.dim)
        x_all = np.concatenate(self.mesh.comm.allgather(x))
        check_edge_rule(rule, x_all, self.mesh.geometry.dim, "contact.0.edge")

    def post_processor(self) -> TwoBodyPost:
        return TwoBodyPost(self)


class TwoBodyPost:
    """The contact state of the pair on the slave nodes, and the fields for ParaView."""

    def __init__(self, pb: TwoBodyProblem) -> None:
        self.pb, self.scene, self.comm = pb, pb.scene, pb.mesh.comm
        mesh = pb.mesh
        self.Q1 = _compat.function_space(mesh, "Lagrange", 1)
        self.pressure = dolfinx.fem.Function(self.Q1, name="contact_pressure")
        self.gap = dolfinx.fem.Function(self.Q1, name="gap")
        self.status = dolfinx.fem.Function(self.Q1, name="contact_status")
        #: with friction: |tangential traction| and |slip increment of the step| on the slave
        #: nodes; the status is then 0 open, 1 stick, 2 slip
        self.friction_fields: list[dolfinx.fem.Function] = []
        if pb.friction is not None:
            self.friction_fields = [
                dolfinx.fem.Function(self.Q1, name=name) for name in ("tangential_traction", "slip")
            ]
        DG0 = _compat.function_space(mesh, "DG", 0)
        self.vm = dolfinx.fem.Function(DG0, name="von_mises")
        self.vm_expr = _compat.expression(pb.von_mises(), DG0)
        #: finite strain with linear bodies: their rotation (the run.json score
        #: linear_body_rotation, the largest over their cells)
        self.rotation = None
        if pb.small_strain_tags:
            self.rotation = dolfinx.fem.Function(DG0)
            self.rotation_expr = _compat.expression(pb.small_strain_rotation(), DG0)
        self.start = pb.layout.start
        self.x = _compat.dof_coordinates(self.Q1)
        self.gdim = mesh.geometry.dim
        #: per converged step: (load factor, force vector on the upper body)
        self.history: list[tuple[float, np.ndarray]] = []
        #: per converged step: sum over the slave nodes of |tangential part of the nodal force|
        #: / sum of |normal part| (0 up to the solver tolerance for frictionless contact)
        self.tangential: list[float] = []
        n = pb.layout.n_owned * pb.layout.bs
        bc_rows = [_compat.bc_dofs(bc) for bc in pb.bcs]
        rows = np.unique(np.concatenate(bc_rows)) if bc_rows else np.zeros(0, dtype=np.int64)
        self.bc_rows = rows[rows < n]
        # the owned slave facets' P1 nodes and their longest edges (the contact zone's size)
        self.contour = ContourMeasure(facet_dofs(self.Q1, pb.contact_facets), self.x)
        self.contour.supported = self.comm.allreduce(self.contour.supported, op=MPI.LAND)
        self.facet_dofs, self.facet_size = self.contour.dofs, self.contour.size
        #: the contact zone's element size at the last evaluated step
        self.zone_size = 0.0

    def evaluate(self, solver: Solver) -> Quantities:
        nodes, D, lam, gap = self.pb.coupling().nodal()
        local = (nodes - self.start).astype(np.int64)
        on = np.zeros(self.pb.layout.n_owned, dtype=bool)
        on[local] = True
        for f, values in ((self.pressure, lam), (self.gap, gap)):
            f.x.array[:] = 0.0
            f.x.array[local] = values
            f.x.scatter_forward()
        peak, closed, penetration, complementarity = nodal_contact(
            self.pressure.x.array, self.gap.x.array, on, self.comm
        )
        self.status.x.array[:] = closed
        if self.friction_fields:
            t_mag, slip, stick = self.pb.coupling().nodal_friction()
            for f, values in zip(self.friction_fields, (t_mag, slip), strict=True):
                f.x.array[:] = 0.0
                f.x.array[local] = values
                f.x.scatter_forward()
            status = self.status.x.array
            status[local] = np.where(closed[local], np.where(stick, 1.0, 2.0), 0.0)
            self.status.x.scatter_forward()
        sym = self.scene.symmetry
        force = self.pb.coupling().force() * sym
        measure = self.comm.allreduce(float(np.sum(D[closed[local]])), op=MPI.SUM) * sym
        if self.contour.supported:  # the zero contour of p - (E / h) g (else the closed nodes')
            E = self.scene.pair_modulus()
            contour = self.contour(self.pressure.x.array, self.gap.x.array, E)
            measure = self.comm.allreduce(contour, op=MPI.SUM) * sym
        size = self.scene.contact_size(measure)
        edge = None
        if self.scene.contact_edge_rule() is not None:  # every slave node, closed and open
            x_all = np.concatenate(self.comm.allgather(self.x[local]))
            p_all = np.concatenate(self.comm.allgather(lam))
            c_all = np.concatenate(self.comm.allgather(closed[local]))
            edge = self.scene.contact_edge(x_all, p_all, c_all)
        self.zone_size = self.contact_zone_size(closed)
        self.closed = closed
        self.history.append((float(self.pb.tload.value), self.pair_force()))
        self.tangential.append(self.tangential_nodal_force(solver, local))
        return Quantities(
            force=force,
            contact_size=size if edge is None else edge,
            peak_pressure=peak,
            max_penetration=penetration,
            complementarity=complementarity,
            friction=self.friction(),
        )

    def contact_zone_size(self, closed: np.ndarray) -> float:
        """The element size in the contact zone: the mean longest edge of the slave facets
        with a closed node (0 with none closed). Collective."""
        touching = np.any(closed[self.facet_dofs], axis=1) if len(self.facet_dofs) else []
        total = self.comm.allreduce(float(np.sum(self.facet_size[touching])), op=MPI.SUM)
        count = self.comm.allreduce(int(np.count_nonzero(touching)), op=MPI.SUM)
        return total / count if count else 0.0

    def auto_smoothing(self) -> list[str]:
        """The note of mortar's ``smoothing = "auto"`` choosing the smoothed surfaces (a
        conforming pair), with the mean curvatures it read; [] otherwise."""
        curvatures = getattr(self.pb.coupling(), "curvatures", None)
        if curvatures is None or not self.pb.pair.smooth:
            return []
        ks, km = curvatures
        return [
            f"mortar's gap is the one between the smoothed surfaces (smoothing = auto: a "
            f'conforming pair, mean curvatures {ks:.3g} and {km:.3g}); smoothing = "none" '
            "on the pair for the facets'"
        ]

    def zone_warnings(self) -> list[str]:
        """The warnings of the last step's closed set on the slave surface
        (:func:`zone_warnings`): its rim here is the surface's end, not a symmetry plane (a
        rim node holding some but not all components). Collective."""
        side = self.pb.pair.slave
        closed = self.closed[side.local]
        rim = side.open_vertex if side.open_vertex is not None else np.zeros_like(closed)
        if self.pb.pair.fixed is not None:
            held = node_held(self.pb.V, self.pb.pair.fixed)[side.local]
            rim = rim & ~(np.any(held, axis=2) & ~np.all(held, axis=2))
        size = Facets(side.X, side.nodes).diameters()
        return zone_warnings(self.comm, side.nodes, closed, rim, size)

    def friction(self) -> Friction | None:
        """Coulomb friction of the pair: the tangential force on the upper body (the last
        component of the pair force is the normal one), the bound mu P, the stick size and the
        slip fraction of the contact set, and the relative excess of |t_T| over mu P."""
        if self.pb.friction is None:
            return None
        sums = self.pb.coupling().friction_state()
        total = {k: self.comm.allreduce(v, op=MPI.SUM) for k, v in sums.items()}
        #: the tangential traction's integral of |t_T| over the friction bound's (1 at gross
        #: slip, in the contact's own frame)
        self.slip_ratio = total["tangential"] / total["bound"] if total["bound"] > 0 else 0.0
        sym = self.scene.symmetry
        force = self.history[-1][1]
        return Friction(
            tangential_force=[float(c) for c in force[:-1]],
            bound=total["bound"] * sym,
            stick_size=self.scene.contact_size(total["stick"] * sym),
            slip_fraction=1.0 - total["stick"] / total["measure"] if total["measure"] else 0.0,
            excess=total["excess"] / total["bound"] if total["bound"] > 0.0 else total["excess"],
        )

    def pair_force(self) -> np.ndarray:
        """The force of the pair on the upper body (the coupling's force on the slave body,
        with the sign of the slave side), the full model's (``Scene.force_symmetry``: the
        components normal to a mirror plane are 0). Collective."""
        sign = 1.0 if self.scene.slave_is_upper else -1.0
        force = self.pb.coupling().slave_force()
        return sign * self.scene.force_symmetry(len(force)) * force + 0.0  # no -0.0

    def tangential_nodal_force(self, solver: Solver, local: np.ndarray) -> float:
        """sum_j |f_j - (n_j . f_j) n_j| / sum_j |n_j . f_j| over the slave contact nodes j
        (nodes with a support left out: they carry its reaction too), with f_j = -R(u)_j the
        force the contact exerts on node j, from the bulk residual R(u) = f_int(u) - f_ext,
        independent of the multiplier, and n_j the coupling's nodal normal (mortar: its
        multiplier's; Nitsche and penalty: their Gauss points' contact normal lumped to the
        node). Frictionless contact transmits no tangential nodal force: on a flat interface
        this is the solver's tolerance for mortar, penalty and Nitsche theta = 0 (patch-test:
        1e-15); Nitsche theta = 1 / -1 adds its consistency term theta / gamma (sigma_n(u) -
        P) sigma_n(v), whose gradient of v has tangential nodal parts (1.5e-3 / 1.3e-3 on
        patch-test, the discretisation's sigma_n(u) - P); on a curved interface the Gauss-point
        couplings add the normal's turn over a node's support. nan without a solver."""
        if solver is None:
            return float("nan")
        normals = self.pb.coupling().nodal_normals()
        R = solver.bulk_residual()
        bs = self.pb.layout.bs
        f = -R.getArray().reshape(-1, bs)[local, : self.gdim]
        R.destroy()
        # nodes with a support (a symmetry plane) also carry its reaction: left out
        free = ~np.isin(local, self.bc_rows // bs)
        fn = np.einsum("ij,ij->i", f, normals)[free]
        ft = np.linalg.norm(f[free] - fn[:, None] * normals[free], axis=1)
        tangential = self.comm.allreduce(float(np.sum(ft)), op=MPI.SUM)
        normal = self.comm.allreduce(float(np.sum(np.abs(fn))), op=MPI.SUM)
        return tangential / normal if normal > 0.0 else 0.0

    def fields(self) -> list[dolfinx.fem.Function]:
        self.vm.interpolate(self.vm_expr)
        return [self.pb.state, self.vm, self.pressure, self.gap, self.status, *self.friction_fields]

    def finish(self, q: Quantities, out: Path | None) -> dict[str, Any]:
        reference = closed_form_errors(self.scene, q)
        if q.friction is not None:
            reference.update(self.scene.friction_reference(q, self.pb.friction))
        x = _compat.dof_coordinates(self.Q1)
        nodes, _, lam, _ = self.pb.coupling().nodal()
        local = (nodes - self.start).astype(np.int64)
        scores = self.scene.pressure_scores(x[local], lam, q.force)
        scores = {k: self.comm.allreduce(v, op=MPI.MAX) for k, v in scores.items()}
        loads = np.array([t for t, _ in self.history])
        forces = np.array([f for _, f in self.history]).reshape(len(loads), self.gdim)
        if np.all(np.isfinite(forces)):  # every step converged to a finite force
            scores.update(self.scene.force_scores(loads, forces))
            measured = [t for t in self.tangential if np.isfinite(t)]
            if measured:
                scores["tangential_nodal_force"] = float(np.max(measured))
        if q.friction is not None:
            scores["tangential_over_bound"] = self.slip_ratio
        pair = self.pb.pair
        if self.rotation is not None:
            self.rotation.interpolate(self.rotation_expr)
            owned = self.rotation.function_space.dofmap.index_map.size_local
            largest = float(np.max(self.rotation.x.array[:owned], initial=0.0))
            scores["linear_body_rotation"] = self.comm.allreduce(largest, op=MPI.MAX)
        if pair.interference:  # the interference fit's largest overlap at the start
            scores["initial_overlap"] = self.pb.initial_overlap
        scores["searches"] = pair.searches
        scores["search_time"] = self.comm.allreduce(pair.search_time, op=MPI.MAX)
        plot = None
        x_all = np.concatenate(self.comm.gather(x[local], root=0) or [np.zeros((0, 3))])
        p_all = np.concatenate(self.comm.gather(lam, root=0) or [np.zeros(0)])
        if out is not None:
            plot = Path(out) / "pressure.png"
            if self.comm.rank == 0:
                plot_pressure(x_all[:, : self.gdim], p_all, self.scene, q.force, plot)
                header = "load," + ",".join(f"force_{c}" for c in "xyz"[: self.gdim])
                np.savetxt(
                    Path(out) / "pair_forces.csv",
                    np.column_stack([loads, forces]),
                    delimiter=",",
                    comments="",
                    header=header,
                )
        extra: dict[str, Any] = {"warnings": self.auto_smoothing() + self.zone_warnings()}
        if self.scene.h_contact_in_zone and self.zone_size > 0.0:
            extra["h_contact"] = self.zone_size
        return {
            **extra,
            "reference": reference,
            "scores": scores,
            "errors": {},
            "plot": None if plot is None else str(plot),
        }


def zone_warnings(
    comm: MPI.Comm, nodes: np.ndarray, closed: np.ndarray, rim: np.ndarray, size: np.ndarray
) -> list[str]:
    """run.json's warnings on a contact zone, from the slave surface's facets of every rank
    (``nodes`` (m, d) global node numbers, ``closed`` (m, d) their contact status, ``rim``
    (m, d) the surface's end, ``size`` (m,) the facets' longest edges), the same on every
    rank:

    - the zone reaches the end of the slave surface (a closed rim node): the contact may go
      on beyond the surface the pair declares;
    - the zone's edge (the facets with a closed and an open node) lies on facets more than
      twice the size of the finest facet it covers: the contact has grown out of the refined
      region;
    - the closed set breaks into many pieces along the surface (connected over the facets;
      :data:`contactfx.results.PIECES`): the nodal pressure oscillates between closed and
      open nodes (on a curved non-matching interface, mortar's slave nodes on the master's
      chords: ``smoothing = "normals"``; Gauss-point spikes: a finer mesh). Collective."""
    from contactfx.results import zone_messages

    parts = comm.gather((nodes, closed, rim, size), root=0)
    found: list[str] = []
    if comm.rank == 0:
        assert parts is not None
        d = nodes.shape[1] if nodes.ndim == 2 else 2
        n_all = np.concatenate([np.reshape(p[0], (-1, d)) for p in parts]).astype(np.int64)
        c_all = np.concatenate([np.reshape(p[1], (-1, d)) for p in parts]).astype(bool)
        r_all = np.concatenate([np.reshape(p[2], (-1, d)) for p in parts]).astype(bool)
        s_all = np.concatenate([np.reshape(p[3], -1) for p in parts])
        found = zone_messages(n_all, c_all, r_all, s_all)
    return comm.bcast(found, root=0)


def plot_pressure(
    x: NDArray[np.float64], p: NDArray[np.float64], scene: Scene, force: float, path: Path
) -> None:
    """The nodal contact pressure p at the slave nodes x (n, gdim) against s = x (2D) or the
    distance s from the axis x = y = 0 (3D), with the scene's closed form
    (``pressure_profile``) at the computed force on a fine grid of s where it has one."""
    plt = pyplot()
    s = x[:, 0] if x.shape[1] == 2 else np.hypot(x[:, 0], x[:, 1])
    order = np.argsort(s)
    fig, ax = plt.subplots(figsize=(7.0, 4.0))
    ax.plot(s[order], p[order], "o-", ms=2, lw=0.8, label="contact pressure (computed)")
    lo, hi = (s.min(), s.max()) if len(s) else (0.0, 1.0)
    closed = s[p > 1e-6 * np.max(p, initial=0.0)] if np.any(p > 0.0) else s[:0]
    if len(closed):  # the contact zone and half its width either side
        margin = 0.5 * (closed.max() - closed.min())
        lo, hi = max(lo, closed.min() - margin), min(hi, closed.max() + margin)
    ax.set_xlim(lo, hi)
    fine = np.linspace(lo, hi, 1001)
    exact = scene.pressure_profile(fine, force)
    if exact is not None:
        ax.plot(fine, exact, "-", lw=1.2, label="closed form at the computed force")
    if len(p) and np.max(p) > 0.0:  # the rigid punch's closed form is singular at its edge
        ax.set_ylim(0.0, 1.3 * np.max(p))
    ax.set_xlabel("x" if x.shape[1] == 2 else "r = sqrt(x^2 + y^2)")
    ax.set_ylabel("pressure")
    ax.set_title(f"{scene.name}: pressure along the slave surface")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
