"""Scenes of two separately meshed elastic bodies in contact (problem kind
:class:`contactfx.driver.two_body.TwoBodyProblem`): a material per body (Young's modulus and
Poisson's ratio of the lower and the upper body), the contact pair (which side is the slave),
supports and loads that the load program scales, and the closed forms."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import dolfinx
import numpy as np

from contactfx import _compat
from contactfx.contact_edge import CONTACT_EDGES, contact_edge, line_edge, radial_edge
from contactfx.driver.two_body import TwoBodyProblem
from contactfx.mechanics.elasticity import Elastic
from contactfx.meshes import build
from contactfx.params import Params, param
from contactfx.scenes import export
from contactfx.scenes.base import Scene

__all__ = [
    "two_elastic",
    "TwoBodyScene",
    "line_edge",
    "radial_edge",
    "contact_edge",
    "CONTACT_EDGES",
    "INTERFERENCES",
    "SMOOTHINGS",
]

#: what ``contact.interference`` may name: ``ramp`` removes an initial overlap of the pair
#: progressively over the load program (:class:`contactfx.driver.two_body.TwoBodyProblem`)
INTERFERENCES = ("ramp",)

#: what ``contact.smoothing`` may name (mortar's, :mod:`contactfx.contact.smoothing`): the gap
#: between the curved surfaces the facets approximate, from the nodal normals (``normals``:
#: conforming curved interfaces, fits, bearings, where the facets' chords make the nodal
#: pressure oscillate), between the facets (``none``), or ``auto`` (the default): ``normals``
#: for a conforming pair (its mean curvatures cancel), else ``none``
SMOOTHINGS = ("auto", "none", "normals")


def two_elastic(E0: float, nu0: float) -> type:
    """Base of the parameters of two bodies (lower, upper) of materials with the defaults E0,
    nu0, checked on construction, and the choice of the slave side."""

    @dataclass(frozen=True)
    class TwoElasticParams(Params):
        E_lower: float = param(E0, "Young's modulus of the lower body", positive=True)
        nu_lower: float = param(nu0, "Poisson's ratio of the lower body, in (-1, 0.5)")
        E_upper: float = param(E0, "Young's modulus of the upper body", positive=True)
        nu_upper: float = param(nu0, "Poisson's ratio of the upper body, in (-1, 0.5)")
        slave: str = param(
            "upper",
            "the slave surface of the contact pair (mortar multiplier, biased Nitsche)",
            choices=("upper", "lower"),
        )

        def __post_init__(self) -> None:
            super().__post_init__()
            Elastic(self.E_lower, self.nu_lower)
            Elastic(self.E_upper, self.nu_upper)

    return TwoElasticParams


class TwoBodyScene(Scene):
    """Two bodies: ``cells`` maps "lower" / "upper" to their cell tags, ``surfaces`` to their
    contact facet tags; subclasses build the mesh with :meth:`mesh_of` and give supports,
    loads (:meth:`set_load` updates the load program's constants) and closed forms."""

    problem = TwoBodyProblem
    cells: ClassVar[dict[str, int]]
    surfaces: ClassVar[dict[str, int]]
    #: multiplicity of the modelled part for forces and contact measures (2 to the number of
    #: ``symmetry_planes``)
    symmetry: ClassVar[float] = 1.0
    #: the contact size from the measure m of the closed set (full model): ``half-measure``
    #: m / 2 (a half-width), ``measure`` m, ``disc-radius`` sqrt(m / pi)
    size_rule: ClassVar[str] = "half-measure"
    #: the rule of :func:`contact_edge` (None: the contact size from the measure)
    edge_rule: ClassVar[str | None] = None
    #: run.json's h_contact is the element size in the contact zone measured at the last step
    #: (the mean longest edge of the slave facets with a closed node), not :meth:`h_contact`
    #: (which scales the methods' parameters and the closed forms' a_error_over_h)
    h_contact_in_zone: ClassVar[bool] = True

    @property
    def slave_tag(self) -> int:
        return int(self.surfaces[self.p.slave])

    @property
    def master_tag(self) -> int:
        other = "lower" if self.p.slave == "upper" else "upper"
        return int(self.surfaces[other])

    @property
    def slave_is_upper(self) -> bool:
        """Whether the slave surface is the upper body's (the pair's force is reported on the
        upper body)."""
        return self.p.slave == "upper"

    def materials(self) -> dict[str, Elastic]:
        p = self.p
        return {"lower": Elastic(p.E_lower, p.nu_lower), "upper": Elastic(p.E_upper, p.nu_upper)}

    def material(self) -> Elastic:
        """The slave body's material (it scales the methods' parameters)."""
        return self.materials()[self.p.slave]

    def pair_modulus(self) -> float:
        """The pair's contact modulus E* = 1 / sum (1 - nu^2) / E over its two bodies (it
        scales the gap in the contour of the contact size)."""
        return 1.0 / sum((1.0 - m.nu**2) / m.E for m in self.materials().values())

    def mesh_of(self, comm, builder, gdim: int):
        data = build(comm, builder, gdim, self.name)
        self.cell_tags = data.cell_tags
        return data.mesh, data.facet_tags

    def body_material(self, mesh) -> Elastic:
        """The material with DG0 fields of E and nu over the bodies' cells."""
        mats = self.materials()
        E = self._body_field(mesh, {body: m.E for body, m in mats.items()})
        nu = self._body_field(mesh, {body: m.nu for body, m in mats.items()})
        ref = self.material()
        return Elastic(ref.E, ref.nu, modulus=E, poisson=nu, density=ref.density)

    def density_field(self, mesh):
        """Each body's density as a DG0 field when they differ (None: one density)."""
        densities = {body: m.density for body, m in self.materials().items()}
        if len(set(densities.values())) < 2:
            return None
        return self._body_field(mesh, densities)

    def _body_field(self, mesh, values: dict[str, float]) -> dolfinx.fem.Function:
        """A DG0 field with each body's value on its cells."""
        DG0 = _compat.function_space(mesh, "DG", 0)
        f = dolfinx.fem.Function(DG0)
        for body, value in values.items():
            cells = self.cell_tags.indices[self.cell_tags.values == self.cells[body]]
            f.x.array[np.array([DG0.dofmap.cell_dofs(c)[0] for c in cells], dtype=np.int64)] = value
        f.x.scatter_forward()
        return f

    def dirichlet(self, V, facet_tags) -> list:
        raise NotImplementedError

    def contact_size(self, measure: float) -> float:
        """Contact half-width / radius from the measure of the contact set (full model), by
        :attr:`size_rule`."""
        if self.size_rule == "measure":
            return measure
        if self.size_rule == "disc-radius":
            return float(np.sqrt(measure / np.pi))
        return 0.5 * measure

    def interference(self) -> str | None:
        """How an initial overlap of the pair is taken (``ramp``: removed over the load
        program), or None: an overlap is refused."""
        return None

    def smoothing(self) -> str:
        """How mortar's gap sees curved surfaces (:data:`SMOOTHINGS`): ``none``, the facets;
        ``normals``, the surfaces the facets approximate, smoothed by the nodal normals;
        ``auto``, normals for a conforming pair."""
        return "auto"

    def edge_ring(self) -> float | None:
        """The ring width of the ``radial`` edge rule (the slave element size)."""
        return None

    def contact_edge_rule(self) -> str | None:
        """The rule of :func:`contact_edge` (None: the contact size from the measure)."""
        return self.edge_rule

    def contact_edge(self, x: np.ndarray, p: np.ndarray, closed: np.ndarray) -> float | None:
        """The contact half-width / radius from the slave nodes of every rank (coordinates x,
        nodal pressures p, the closed ones marked) by :meth:`contact_edge_rule`, or None for
        the measure of the closed nodes."""
        return contact_edge(self.contact_edge_rule(), x, p, self.edge_ring(), closed)

    # -- the scene as a problem file ----------------------------------------------------------
    def build_mesh(self, comm):
        """The mesh of :meth:`mesh_builder`, then :meth:`make_constants` on it."""
        mesh, facet_tags = super().build_mesh(comm)
        self.make_constants(mesh)
        return mesh, facet_tags

    def make_constants(self, mesh) -> None:
        """Create the load program's constants (prescribed displacements) on ``mesh``."""

    def boundary_data(self) -> list[dict]:
        """The supports and loads as the ``[[boundary]]`` tables of a problem file."""
        raise NotImplementedError(f"scene '{self.name}' cannot be written as a problem file")

    def problem_data(self, numerics) -> dict:
        """Bodies (the cell groups with their materials), the scene's supports and loads, the
        contact pair (slave and master surfaces, h, the body the pair force is reported on,
        the contact edge rule, an interference fit) and the symmetry and contact size
        outputs."""
        other = "lower" if self.p.slave == "upper" else "upper"
        mats = self.materials()
        pair = {
            "slave": self.surfaces[self.p.slave].name.lower(),
            "master": self.surfaces[other].name.lower(),
            "h": float(self.h_contact()),
            "force_on": self.cells["upper"].name.lower(),
        }
        if self.edge_rule is not None:
            pair["edge"] = self.edge_rule
            if self.edge_ring() is not None:
                pair["edge_ring"] = float(self.edge_ring())
        if self.interference() is not None:
            pair["interference"] = self.interference()
        if self.smoothing() != "auto":
            pair["smoothing"] = self.smoothing()
        output: dict = {"symmetry": float(self.symmetry)}
        if self.symmetry_planes:
            output["symmetry_planes"] = ["xyz"[k] for k in self.symmetry_planes]
        return {
            "bodies": [
                export.body(self.cells[b].name.lower(), mats[b]) for b in ("lower", "upper")
            ],
            "boundary": self.boundary_data(),
            "contact": [pair],
            "output": {**output, "contact_size": self.size_rule},
        }

    def reference(self, force: float) -> dict[str, float]:
        return {}

    def friction_reference(self, q, friction) -> dict[str, float]:
        """Closed-form friction quantities at the computed state ``q``
        (:class:`contactfx.results.Quantities`) under the ``friction`` law."""
        return {}

    def pressure_scores(self, x: np.ndarray, p: np.ndarray, force: float) -> dict[str, float]:
        """Scene-specific scores from this rank's slave contact nodes x and pressures p (local
        maxima, reduced with MAX over ranks)."""
        return {}

    def pressure_profile(self, s: np.ndarray, force: float) -> np.ndarray | None:
        """The closed-form contact pressure at the points s along the slave surface (x in 2D,
        the distance from the axis x = y = 0 in 3D; reference coordinates) at the computed
        force (full model), for the pressure plot; None for no closed form."""
        return None

    def force_scores(self, loads: np.ndarray, forces: np.ndarray) -> dict[str, float]:
        """Scores from the history of the pair's force on the upper body: ``loads`` (steps,)
        the load factors of the converged steps, ``forces`` (steps, gdim) the force vectors
        (the sum over the slave nodes of D_j lambda_j n_j, the full model's:
        ``Scene.force_symmetry``)."""
        return {}
