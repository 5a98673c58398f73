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
from contactfx.driver.two_body import TwoBodyProblem
from contactfx.mechanics.elasticity import Elastic
from contactfx.meshes import build
from contactfx.params import Params, param
from contactfx.scenes.base import Scene

__all__ = ["two_elastic", "TwoBodyScene"]


def two_elastic(E0: float, nu0: float) -> type:
    """Base of the parameters of two bodies (lower, upper) of materials with the defaults E0,
    nu0, checked on construction, and the choice of the slave side."""

    @dataclass(frozen=True)
    class TwoElasticParams(Params):
        E_lower: float = param(E0, "Young's modulus of the lower body", positive=True)
        nu_lower: float = param(nu0, "Poisson's ratio of the lower body, in (-1, 0.5)")
        E_upper: float = param(E0, "Young's modulus of the upper body", positive=True)
        nu_upper: float = param(nu0, "Poisson's ratio of the upper body, in (-1, 0.5)")
        slave: str = param("upper", "the slave surface of the contact pair (mortar "
                           "multiplier, biased Nitsche)", choices=("upper", "lower"))  # fmt: skip

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
    #: multiplicity of the modelled part for forces and contact measures
    symmetry: ClassVar[float] = 1.0

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

    def mesh_of(self, comm, builder, gdim: int):
        data = build(comm, builder, gdim, self.name)
        self.cell_tags = data.cell_tags
        return data.mesh, data.facet_tags

    def body_material(self, mesh) -> Elastic:
        """The material with DG0 fields of E and nu over the bodies' cells."""
        DG0 = _compat.function_space(mesh, "DG", 0)
        E, nu = dolfinx.fem.Function(DG0), dolfinx.fem.Function(DG0)
        for body, mat in self.materials().items():
            cells = self.cell_tags.indices[self.cell_tags.values == self.cells[body]]
            dofs = np.array([DG0.dofmap.cell_dofs(c)[0] for c in cells], dtype=np.int64)
            E.x.array[dofs] = mat.E
            nu.x.array[dofs] = mat.nu
        for f in (E, nu):
            f.x.scatter_forward()
        return Elastic(self.material().E, self.material().nu, modulus=E, poisson=nu)

    def dirichlet(self, V, facet_tags) -> list:
        raise NotImplementedError

    def contact_size(self, measure: float) -> float:
        """Contact half-width / radius from the measure of the contact set (full model)."""
        return 0.5 * measure

    def contact_edge(self, x: np.ndarray, p: np.ndarray) -> float | None:
        """The contact half-width / radius from the closed slave nodes of every rank
        (coordinates x, pressures p), or None for the measure of the closed nodes."""
        return None

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
        (the sum over the slave nodes of D_j lambda_j n_j, times ``symmetry``)."""
        return {}
