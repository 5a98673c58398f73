"""The frozen, typed specification of a problem file, section by section (what the scenes
read; the groups by name, checked against the mesh when it is built)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from contactfx.contact.interface import BartonBandis
from contactfx.mechanics.elasticity import Elastic

__all__ = [
    "AXES",
    "SECTIONS",
    "DYNAMICS_NUMERICS",
    "MeshSpec",
    "BodySpec",
    "BoundarySpec",
    "PinSpec",
    "ObstacleSpec",
    "PairSpec",
    "InterfaceSpec",
    "OutputSpec",
    "DynamicsSpec",
    "ProblemFile",
]

AXES = ("x", "y", "z")
#: the sections of a problem file, in the order they are read and written
SECTIONS = (
    "title",
    "mesh",
    "bodies",
    "boundary",
    "pins",
    "obstacle",
    "contact",
    "interface",
    "initial",
    "dynamics",
    "numerics",
    "petsc",
    "output",
)

#: the keys of [dynamics] that are numerics (Numerics's fields of the same name)
DYNAMICS_NUMERICS = ("scheme", "rho_inf", "dt", "t_end", "mass", "dashpot", "time_tolerance")

#: a (load factor, multiplier) table
Amplitude = tuple[tuple[float, float], ...]
#: an expression of a problem file: a function of the point (UFL vector) to UFL
Expression = Callable[[Any], Any]


@dataclass(frozen=True)
class MeshSpec:
    """``[mesh]``: a mesh file (``.msh``, or ``.geo`` meshed with the size factor ``size``)
    or a built-in geometry ``builder`` = (name, parameters); ``axisymmetric``: the 2D mesh is
    the (r, z) section of a body of revolution."""

    file: Path | None
    size: float = 1.0
    builder: tuple[str, dict] | None = None
    #: a 2D mesh of the (r, z) section of a body of revolution (x = r >= 0)
    axisymmetric: bool = False

    @property
    def label(self) -> str:
        """The mesh file's name, or the builder's."""
        if self.builder is not None:
            return f"the {self.builder[0]} builder"
        return self.file.name if self.file is not None else "the mesh"


@dataclass(frozen=True)
class BodySpec:
    """``[[bodies]]``: a cell group, its material, an optional body force with its
    amplitude."""

    group: str
    #: :class:`contactfx.mechanics.elasticity.Elastic` or a hyperelastic material
    material: Any
    force: np.ndarray | None = None
    amplitude: Amplitude = ()


@dataclass(frozen=True)
class BoundarySpec:
    """``[[boundary]]``: on a facet group, fixed components, prescribed displacement
    components, a traction, a normal pressure or the traction of a stress tensor (rows of
    numbers or expressions), scaled by the amplitude."""

    group: str
    fix: tuple[int, ...] = ()
    displacement: dict[int, float] = field(default_factory=dict)
    traction: np.ndarray | None = None
    pressure: float | None = None
    amplitude: Amplitude = ()
    stress: tuple[tuple[float | Expression, ...], ...] | None = None
    quadrature_degree: int | None = None


@dataclass(frozen=True)
class PinSpec:
    """``[[pins]]``: components fixed at a mesh vertex."""

    point: np.ndarray
    fix: tuple[int, ...]


@dataclass(frozen=True)
class ObstacleSpec:
    """``[obstacle]``: the shape and its dimensions, the contact facet group, the position
    and motion (checked against the dimension with the mesh) or a path, the element size h."""

    shape: str
    contact: str
    amplitude: Amplitude
    radius: float | None = None
    edge_radius: float | None = None
    height: float | None = None
    wavelength: float | None = None
    distance: Expression | None = None
    h: float | None = None
    position: Any = None
    motion: Any = None
    path: tuple[tuple[float, ...], ...] | None = None


@dataclass(frozen=True)
class PairSpec:
    """``[[contact]]``: the slave and master facet groups and the pair's options."""

    slave: str
    master: str
    h: float | None = None
    force_on: str | None = None
    edge: str | None = None
    edge_ring: float | None = None
    #: an initial overlap of the pair: "ramp" (removed over the load program) or None
    interference: str | None = None
    #: mortar's gap between the facets ("none"), the smoothed surfaces ("normals") or, for
    #: a conforming pair, the smoothed ones ("auto")
    smoothing: str = "auto"


@dataclass(frozen=True)
class InterfaceSpec:
    """``[interface]``: a straight interior facet group and what acts on it."""

    group: str
    fluid_pressure: float | None = None
    proppant_thickness: float | None = None
    proppant_zone: tuple[float, float] | None = None
    joint: BartonBandis | None = None
    h: float | None = None
    origin: np.ndarray | None = None
    direction: np.ndarray | None = None


@dataclass(frozen=True)
class OutputSpec:
    """``[output]``: reactions per group, probe points, the model's symmetry multiplicity and
    its mirror planes (the axes normal to them), the contact size rule, mean displacements
    over facet groups, the ParaView files' format (xdmf or vtu)."""

    reactions: tuple[str, ...] = ()
    probes: tuple[tuple[float, ...], ...] = ()
    symmetry: float = 1.0
    symmetry_planes: tuple[int, ...] = ()
    contact_size: str | None = None
    mean_displacement: dict[str, tuple[str, str]] = field(default_factory=dict)
    format: str = "xdmf"


@dataclass(frozen=True)
class DynamicsSpec:
    """``[dynamics]``: what a dynamic run adds to the bodies (their density is in
    ``[[bodies]]``): a gravity acceleration (constant in time, rho g per body), the initial
    velocity per body (group: its components) or as a field (expressions in x, y, z); the time
    scheme, the step and the end time go to the numerics."""

    gravity: np.ndarray | None = None
    velocity: dict[str, np.ndarray] = field(default_factory=dict)
    velocity_field: tuple[Expression, ...] | None = None


@dataclass(frozen=True)
class ProblemFile:
    """A validated problem file: one spec per section (exactly one of obstacle, pair and
    interface)."""

    path: Path
    title: str
    mesh: MeshSpec
    bodies: tuple[BodySpec, ...]
    boundary: tuple[BoundarySpec, ...] = ()
    pins: tuple[PinSpec, ...] = ()
    obstacle: ObstacleSpec | None = None
    pair: PairSpec | None = None
    interface: InterfaceSpec | None = None
    initial: tuple[Expression, ...] | None = None
    output: OutputSpec = field(default_factory=OutputSpec)
    dynamics: DynamicsSpec | None = None

    @property
    def materials(self) -> dict[str, Elastic]:
        """The bodies' materials by group, in the file's order."""
        return {b.group: b.material for b in self.bodies}
