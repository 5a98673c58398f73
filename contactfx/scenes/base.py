"""Scenes: named contact problems. A scene holds parameters, geometry, loads and closed-form
references; the driver (:mod:`contactfx.driver`) solves it with the problem kind the scene
names (``problem``).

:class:`Scene` is what every scene has; :class:`ObstacleScene` adds the hooks of a body against
a rigid obstacle (the interface scenes are in :mod:`contactfx.scenes.interface_base`).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path
from typing import ClassVar

import numpy as np
from mpi4py import MPI

from contactfx.contact.obstacles import Obstacle
from contactfx.driver.obstacle import ObstacleProblem
from contactfx.mechanics.elasticity import Elastic
from contactfx.meshes import build
from contactfx.numerics import Numerics
from contactfx.params import Params, param
from contactfx.results import RunSummary

__all__ = ["SceneParams", "elastic", "resized", "Scene", "ObstacleScene"]

#: base of every scene's parameter dataclass (validated on construction)
SceneParams = Params


def elastic(E0: float, nu0: float) -> type:
    """Base of a scene's parameter dataclass whose body is one isotropic elastic material:
    Young's modulus E and Poisson's ratio nu with the defaults E0 and nu0, checked on
    construction (the material's own rule: E > 0, -1 < nu < 0.5)."""

    @dataclass(frozen=True)
    class ElasticParams(Params):
        E: float = param(E0, "Young's modulus", positive=True)
        nu: float = param(nu0, "Poisson's ratio, in (-1, 0.5)")

        def __post_init__(self) -> None:
            super().__post_init__()
            Elastic(self.E, self.nu)

    return ElasticParams


def resized(params, scale: float):
    """The scene parameters with every mesh size (fields ``h``, ``h_*``) multiplied by
    ``scale``; ValueError when the parameters have none."""
    sizes = {
        f.name: getattr(params, f.name) * scale
        for f in dataclasses.fields(params)
        if f.name == "h" or f.name.startswith("h_")
    }
    if not sizes:
        raise ValueError(f"scene {type(params).__name__} has no mesh size to refine")
    return dataclasses.replace(params, **sizes)


class Scene:
    """Base of the scenes. Subclasses set ``name``, ``summary``, ``Params`` and ``problem`` (the
    problem kind) and implement :meth:`build_mesh`."""

    name: ClassVar[str]
    summary: ClassVar[str]
    Params: ClassVar[type]
    problem: ClassVar[type]
    numerics_defaults: ClassVar[dict] = {}
    #: a body of revolution computed on its (r, z) section (x[0] = r >= 0):
    #: :mod:`contactfx.mechanics.axisymmetric`
    axisymmetric: ClassVar[bool] = False
    #: the axes normal to the model's mirror planes (a quarter model cut by x = 0 and y = 0:
    #: (0, 1)); the full model's forces have no component along them (:meth:`force_symmetry`)
    symmetry_planes: ClassVar[tuple[int, ...]] = ()

    def force_symmetry(self, n: int) -> np.ndarray:
        """The factors (n,) that make a force vector of the modelled part the full model's
        (docs/architecture.md, "Symmetry"): the multiplicity ``symmetry`` for a component that
        every mirror plane contains (the mirror images add), 0 for a component normal to a
        mirror plane (``symmetry_planes``) and for the radial one of a body of revolution (the
        images cancel). A scalar force (the normal contact force, a bound mu P) takes
        ``symmetry`` itself."""
        factors = np.full(n, float(getattr(self, "symmetry", 1.0)))
        cancel = {*self.symmetry_planes, *((0,) if self.axisymmetric else ())}
        factors[[k for k in sorted(cancel) if k < n]] = 0.0
        return factors

    def __init__(self, params) -> None:
        self.p = params

    def configure(self, numerics: Numerics) -> None:
        """Called before a run: a scene whose loads or closed forms depend on the numerics'
        physical choices (the friction law) reads them here."""

    def material(self) -> Elastic:
        return Elastic(self.p.E, self.p.nu)

    def contact_modulus(self) -> float:
        """Young's modulus of the material at the contact surface: it scales the methods'
        parameters (gamma_N = gamma0 E / h, kappa, r)."""
        return self.material().E

    def coarsened(self, factor: float):
        """The same scene with every mesh size (parameters ``h`` and ``h_*``) multiplied by
        ``factor``: the coarser meshes of nested iteration (``--nested``); None when the
        scene's mesh cannot be regenerated at another size (a mesh file)."""
        try:
            return type(self)(resized(self.p, factor))
        except ValueError:
            return None

    def mesh_builder(self):
        """(builder, gdim): the scene's gmsh geometry (:mod:`contactfx.meshes`) with its
        parameters bound; :meth:`build_mesh` meshes it, ``contactfx init`` writes it to a
        ``.msh`` file."""
        raise NotImplementedError(f"scene '{self.name}' has no gmsh builder")

    def build_mesh(self, comm):
        """Return (mesh, facet_tags) (and keep the cell tags as ``cell_tags``)."""
        builder, gdim = self.mesh_builder()
        data = build(comm, builder, gdim, self.name)
        self.cell_tags = data.cell_tags
        return data.mesh, data.facet_tags

    def problem_data(self, numerics: Numerics) -> dict:
        """The scene as the tables of a problem file (all but ``[mesh]``, groups by the
        physical names of :meth:`mesh_builder`) under ``numerics``: what ``contactfx init``
        writes (:mod:`contactfx.scenes.export`); solving that file gives this scene's run."""
        raise NotImplementedError(f"scene '{self.name}' cannot be written as a problem file")

    def load(self, v, ds, t):
        """External load (linear form in v); t is the load-factor Constant. None for none."""
        return None

    def h_contact(self) -> float:
        """The element size at the contact surface."""
        return self.p.h_contact

    def set_load(self, t: float) -> None:
        """Set the load program's constants (prescribed displacements, load amplitudes) for
        load factor t."""

    def on_step(self, problem, solver, load: float, quantities) -> None:
        """Called at every converged load step with its contact quantities
        (:class:`contactfx.results.Quantities`), e.g. to record reactions."""

    @classmethod
    def default_numerics(cls, **overrides) -> Numerics:
        """The scene's default numerics (what the command line starts from), overridden."""
        return Numerics(**{**cls.numerics_defaults, **overrides})

    def run(
        self,
        numerics: Numerics,
        *,
        comm: MPI.Comm = MPI.COMM_WORLD,
        out: Path | None = None,
        petsc_options: dict | None = None,
        verbose: bool = True,
        time_limit: float | None = None,
        output_format: str = "xdmf",
        restart: Path | None = None,
        checkpoint_every: int = 1,
    ) -> RunSummary:
        """Solve with ``numerics`` (see :func:`contactfx.driver.run`)."""
        from contactfx.driver import run

        return run(
            self,
            numerics,
            comm=comm,
            out=out,
            petsc_options=petsc_options,
            verbose=verbose,
            time_limit=time_limit,
            output_format=output_format,
            restart=restart,
            checkpoint_every=checkpoint_every,
        )

    def density_field(self, mesh):
        """The density as a field over ``mesh`` (UFL) for bodies of different densities, or
        None for the homogeneous ``material().density``."""
        return None

    def initial_guess(self, u, t: float) -> None:
        """Set a starting state before the first load step (default: zero); a dynamic run's
        initial displacement."""

    def initial_velocity(self, v) -> None:
        """Set a dynamic run's initial velocity ``v`` (a Function of the unknown's space;
        default: at rest)."""


class ObstacleScene(Scene):
    """A body pressed against a rigid obstacle: geometry and supports, the obstacle and its
    motion, and the closed forms."""

    problem = ObstacleProblem
    contact_tag: ClassVar[int]
    #: multiplicity of the modelled part (4 for a quarter model) for forces and areas
    symmetry: ClassVar[float] = 1.0

    def obstacle(self) -> Obstacle:
        raise NotImplementedError

    def obstacle_offset(self, t: float, gdim: int) -> np.ndarray:
        """Rigid displacement of the obstacle at load factor t."""
        return np.zeros(gdim)

    def dirichlet(self, V, facet_tags) -> list:
        raise NotImplementedError

    def modulus(self, mesh):
        """Young's modulus as a field over ``mesh`` (UFL) for a heterogeneous body, or None for
        the homogeneous ``material().E``."""
        return None

    def contact_size(self, measure: float) -> float:
        """Contact half-width / radius from the measure of the contact set (full model)."""
        return 0.5 * measure

    # -- closed forms ----------------------------------------------------------------------
    def reference(self, force: float) -> dict[str, float]:
        """Closed-form values at the computed ``force``: contact half-width ``a``, peak pressure
        ``p0``, the ``force`` itself where it is known (compared, relative errors added)."""
        return {}

    def exact_pressure(self, x, ref: dict):
        """UFL expression of the closed-form contact pressure on the contact boundary, or None.
        ``ref`` maps the keys of :meth:`reference` (at the computed force) to UFL constants."""
        return None

    def exact_displacement(self, x):
        """UFL expression of the exact displacement, or None."""
        return None

    def friction_reference(self, q, friction) -> dict[str, float]:
        """Closed-form friction quantities at the computed state ``q``
        (:class:`contactfx.results.Quantities`) under the ``friction`` law."""
        return {}

    def pressure_scores(self, x: np.ndarray, p: np.ndarray, force: float) -> dict[str, float]:
        """Scene-specific pointwise scores (local maxima over this rank's surface nodes x with
        nodal pressure p); reduced with MAX over ranks."""
        return {}

    def friction_scores(self, x, p, t, bound, status) -> dict[str, float]:
        """Scene-specific friction scores from the contact nodes' coordinates x, pressure p,
        tangential traction t, friction bound and status (0 open, 1 stick, 2 slip); local
        maxima, reduced with MAX over ranks."""
        return {}
