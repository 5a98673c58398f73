"""Problem files: a contact problem described by a TOML file over the user's own gmsh mesh.

The file names a mesh (a ``.msh`` file, a ``.geo`` file meshed at run time with a size factor,
or a geometry of :data:`contactfx.meshes.BUILDERS` with its parameters; 1D, 2D or 3D), the
bodies (a cell group each, with E and nu, optionally a body force), the boundary conditions on
named facet groups (fixed components, prescribed displacement components, tractions, normal
pressures, each scaled by a piecewise-linear load amplitude), and a rigid obstacle touching one
facet group (plane, circle / cylinder, sphere, parabola / paraboloid, sinusoid, punch with
rounded edges, or a signed distance expression; moved by ``motion`` times an amplitude or along
a ``path``), a contact pair between two bodies, or an interface; then an optional initial
displacement (Newton's start), the numerics, PETSc options and outputs (reactions, probes, the
model's symmetry multiplicity)::

    [mesh]
    file = "block.geo"                 # relative to the problem file
    size = 1.0                         # element size factor (.geo only)

    [[bodies]]
    group = "block"
    E = 1000.0
    nu = 0.3

    [[boundary]]
    group = "bottom"
    fix = ["x", "y"]

    [[boundary]]
    group = "right"
    traction = [0.0, -1.0]
    amplitude = [[0.0, 0.0], [1.0, 1.0]]   # (load factor, multiplier) pairs; default t

    [obstacle]
    shape = "plane"                    # plane, circle / cylinder (2D), sphere (3D)
    contact = "top"
    position = [0.0, 0.0]              # the obstacle's lowest point at the start
    motion = [0.0, -0.01]              # its rigid displacement at the end of the program

    [numerics]
    method = "nitsche"
    steps = 2

    [petsc]
    snes_monitor = ""

    [output]
    reactions = ["bottom"]             # reaction per group and step: history.csv

A fitted interface inside one body takes ``[interface]`` (group, fluid_pressure,
proppant_thickness with an optional proppant_zone, joint, h, origin, direction) instead of the
obstacle; a plate held by tractions only takes ``[[pins]]`` (point: a mesh vertex, fix), and a
boundary may carry the traction sigma n of a ``stress`` tensor (numbers or expressions in x, y,
z) integrated with its ``quadrature_degree``.

Groups are the gmsh physical names. Everything is validated before anything is computed: an
unknown key, a value of the wrong type or out of range, a group the mesh does not have (the error
lists those it has) or of the wrong dimension is one error naming the file and the key.

:func:`load_problem` reads and validates a file (``--set key=value`` overrides applied first) and
returns the scene, the numerics and the PETSc options; the scene is an
:class:`contactfx.scenes.base.ObstacleScene` or a
:class:`contactfx.scenes.two_body_base.TwoBodyScene`, solved by the one pipeline like any
built-in scene.
"""

from __future__ import annotations

import ast
import copy
import dataclasses
import functools
import re
import tomllib
from dataclasses import dataclass
from pathlib import Path

import dolfinx
import numpy as np
import ufl
from mpi4py import MPI

from contactfx import _compat
from contactfx.contact.interface import BartonBandis
from contactfx.contact.obstacles import (
    Ball,
    FlatPunch,
    HalfSpace,
    Obstacle,
    Paraboloid,
    Sinusoid,
)
from contactfx.mechanics.elasticity import Elastic
from contactfx.meshes import BUILDERS, build_file, build_grouped, builder_groups
from contactfx.numerics import Numerics
from contactfx.params import Params, param
from contactfx.scenes._common import fix, fix_component, prescribe_component
from contactfx.scenes.base import ObstacleScene
from contactfx.scenes.interface_base import InterfaceScene
from contactfx.scenes.two_body_base import CONTACT_EDGES, TwoBodyScene, contact_edge

__all__ = ["load_problem", "ProblemFile", "FileParams", "apply_sets"]

AXES = ("x", "y", "z")
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
    "numerics",
    "petsc",
    "output",
)
KEYS = {
    "mesh": ("file", "size", "builder", "parameters"),
    "bodies": ("group", "E", "nu", "body_force", "amplitude"),
    "boundary": (
        "group",
        "fix",
        "displacement",
        "traction",
        "pressure",
        "stress",
        "amplitude",
        "quadrature_degree",
    ),
    "pins": ("point", "fix"),
    "obstacle": (
        "shape",
        "contact",
        "radius",
        "distance",
        "position",
        "motion",
        "amplitude",
        "path",
        "height",
        "wavelength",
        "edge_radius",
        "h",
    ),
    "contact": ("slave", "master", "h", "force_on", "edge", "edge_ring"),
    "interface": (
        "group",
        "fluid_pressure",
        "proppant_thickness",
        "proppant_zone",
        "joint",
        "h",
        "origin",
        "direction",
    ),
    "initial": ("displacement",),
    "output": (
        "reactions",
        "probes",
        "symmetry",
        "tangential_symmetry",
        "contact_size",
        "mean_displacement",
    ),
}
SHAPES = (
    "plane",
    "circle",
    "cylinder",
    "sphere",
    "parabola",
    "paraboloid",
    "sinusoid",
    "punch",
    "distance",
)
#: the contact size reported from the measure m of the contact set (times the symmetry)
CONTACT_SIZES = ("half-measure", "measure", "disc-radius")


@dataclass(frozen=True)
class FileParams(Params):
    """What run.json records of a problem-file run: the file and the mesh size factor."""

    problem: str = param("", "the problem file")
    size: float = param(1.0, "element size factor of a .geo mesh", positive=True)


class ProblemError(ValueError):
    pass


# -- reading and validation ---------------------------------------------------------------


def _parse_value(text: str):
    """A --set value: TOML syntax when it parses (numbers, booleans, arrays, quoted strings),
    else the bare text as a string."""
    try:
        return tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        return text


def apply_sets(data: dict, sets: list[str], where: str) -> dict:
    """``data`` with the ``key.sub=value`` overrides applied (arrays of tables by index:
    ``bodies.0.E=2e5``)."""
    data = copy.deepcopy(data)
    for item in sets:
        if "=" not in item:
            raise ProblemError(f"{where}: --set expects key=value, got '{item}'")
        key, text = item.split("=", 1)
        parts = key.strip().split(".")
        node = data
        for i, part in enumerate(parts[:-1]):
            if isinstance(node, list):
                if not part.isdigit() or int(part) >= len(node):
                    raise ProblemError(
                        f"{where}: --set {key}: no entry {part} in '{'.'.join(parts[:i])}'"
                    )
                node = node[int(part)]
            else:
                node = node.setdefault(part, {})
            if not isinstance(node, dict | list):
                raise ProblemError(f"{where}: --set {key}: '{part}' is not a table")
        if isinstance(node, list):
            raise ProblemError(f"{where}: --set {key}: give the entry's index")
        node[parts[-1]] = _parse_value(text.strip())
    return data


class _Reader:
    """Typed access to the file's tables with errors that name the file and the key."""

    def __init__(self, path: Path) -> None:
        self.path = path

    def fail(self, key: str, message: str):
        raise ProblemError(f"{self.path}: {key}: {message}")

    def table(self, data, key: str, allowed: tuple[str, ...]) -> dict:
        if not isinstance(data, dict):
            self.fail(key, f"expected a table, got {data!r}")
        for k in data:
            if k not in allowed:
                self.fail(f"{key}.{k}", f"unknown key (allowed: {', '.join(allowed)})")
        return data

    def number(self, data: dict, key: str, name: str, default=None, positive=False) -> float:
        value = data.get(name, default)
        if value is None:
            self.fail(f"{key}.{name}", "missing (a number)")
        if isinstance(value, bool) or not isinstance(value, int | float):
            self.fail(f"{key}.{name}", f"expected a number, got {value!r}")
        if not np.isfinite(value):
            self.fail(f"{key}.{name}", f"must be finite, got {value}")
        if positive and not value > 0:
            self.fail(f"{key}.{name}", f"must be > 0, got {value}")
        return float(value)

    def string(self, data: dict, key: str, name: str, choices=None, default=None) -> str:
        value = data.get(name, default)
        if not isinstance(value, str):
            self.fail(
                f"{key}.{name}",
                f"expected a string, got {value!r}" if value is not None else "missing (a string)",
            )
        if choices is not None and value not in choices:
            self.fail(f"{key}.{name}", f"must be one of {', '.join(choices)}, got '{value}'")
        return value

    def vector(self, data: dict, key: str, name: str, gdim: int, default=None) -> np.ndarray:
        value = data.get(name, default)
        ok = (
            isinstance(value, list)
            and len(value) == gdim
            and all(isinstance(v, int | float) and not isinstance(v, bool) for v in value)
        )
        if not ok:
            self.fail(f"{key}.{name}", f"expected {gdim} numbers, got {value!r}")
        return np.asarray(value, dtype=np.float64)

    def amplitude(self, data: dict, key: str) -> list[tuple[float, float]]:
        value = data.get("amplitude", [[0.0, 0.0], [1.0, 1.0]])
        ok = (
            isinstance(value, list)
            and len(value) >= 1
            and all(
                isinstance(r, list)
                and len(r) == 2
                and all(isinstance(v, int | float) and not isinstance(v, bool) for v in r)
                for r in value
            )
        )
        if not ok:
            self.fail(
                f"{key}.amplitude",
                f"expected a table of [load factor, multiplier] pairs, got {value!r}",
            )
        ts = [r[0] for r in value]
        if any(b <= a for a, b in zip(ts, ts[1:], strict=False)):
            self.fail(f"{key}.amplitude", f"load factors must increase, got {ts}")
        return [(float(a), float(b)) for a, b in value]

    def offsets(self, data: dict, key: str) -> list[list[float]]:
        value = data["path"]
        ok = (
            isinstance(value, list)
            and len(value) >= 1
            and all(
                isinstance(r, list)
                and len(r) >= 2
                and all(isinstance(v, int | float) and not isinstance(v, bool) for v in r)
                for r in value
            )
        )
        if not ok or len({len(r) for r in value}) != 1:
            self.fail(
                f"{key}.path",
                f"expected a table of [load factor, offset components] rows, got {value!r}",
            )
        ts = [r[0] for r in value]
        if any(b <= a for a, b in zip(ts, ts[1:], strict=False)):
            self.fail(f"{key}.path", f"load factors must increase, got {ts}")
        return [[float(v) for v in r] for r in value]


def _amplitude(table: list[tuple[float, float]], t: float) -> float:
    ts, vs = zip(*table, strict=True)
    return float(np.interp(t, ts, vs))


def _stress(r: _Reader, value, key: str) -> list[list]:
    """A boundary's stress tensor: d rows of d entries, each a number or an expression in x,
    y, z (:func:`parse_expression`; e.g. a closed-form field around a crack)."""
    ok = (
        isinstance(value, list)
        and len(value) in (1, 2, 3)
        and all(
            isinstance(row, list)
            and len(row) == len(value)
            and all(isinstance(v, int | float | str) and not isinstance(v, bool) for v in row)
            for row in value
        )
    )
    if not ok:
        r.fail(
            key,
            "expected a square table of numbers or expressions in x, y, z (the stress "
            f"tensor's rows), got {value!r}",
        )
    out = []
    for row in value:
        entries = []
        for v in row:
            if isinstance(v, str):
                try:
                    v = parse_expression(v)
                except ValueError as err:
                    r.fail(key, str(err))
            elif not np.isfinite(v):
                r.fail(key, f"must be finite, got {v}")
            else:
                v = float(v)
            entries.append(v)
        out.append(entries)
    return out


@dataclass
class Boundary:
    group: str
    fix: tuple[int, ...] = ()
    displacement: dict[int, float] = dataclasses.field(default_factory=dict)
    traction: np.ndarray | None = None
    pressure: float | None = None
    amplitude: list = dataclasses.field(default_factory=list)
    #: a stress tensor (rows of numbers or expressions in x, y, z) whose traction sigma n
    stress: list | None = None
    quadrature_degree: int | None = None


@dataclass
class ProblemFile:
    """A validated problem file: what the scene needs (groups by name, checked against the
    mesh when it is built)."""

    path: Path
    mesh_file: Path | None
    size: float
    bodies: list[tuple[str, Elastic]]
    boundary: list[Boundary]
    obstacle: dict | None
    contact: tuple[str, str] | None
    interface: dict | None
    reactions: list[str]
    probes: list[list[float]]
    title: str
    body_forces: list = dataclasses.field(default_factory=list)
    initial: list | None = None
    symmetry: float = 1.0
    tangential_symmetry: list[float] | None = None
    contact_size: str | None = None
    #: the contact pair's options: h, force_on, edge, edge_ring (those given)
    pair: dict = dataclasses.field(default_factory=dict)
    pins: list = dataclasses.field(default_factory=list)
    mean_displacement: dict = dataclasses.field(default_factory=dict)
    #: (name, parameters) of a built-in geometry (:data:`contactfx.meshes.BUILDERS`)
    builder: tuple[str, dict] | None = None

    @property
    def mesh_label(self) -> str:
        """The mesh file's name, or the builder's."""
        return self.mesh_file.name if self.builder is None else f"the {self.builder[0]} builder"


def _read(path: Path, sets: list[str]) -> tuple[ProblemFile, dict, dict]:
    """(problem, numerics overrides, PETSc options) of the file, without the mesh."""
    if not path.is_file():
        raise FileNotFoundError(f"problem file {str(path)!r} not found")
    try:
        data = tomllib.loads(path.read_text())
    except tomllib.TOMLDecodeError as err:
        raise ProblemError(f"{path}: not valid TOML: {err}") from None
    data = apply_sets(data, sets, str(path))
    r = _Reader(path)
    for key in data:
        if key not in SECTIONS:
            r.fail(key, f"unknown section (allowed: {', '.join(SECTIONS)})")
    mesh = r.table(data.get("mesh", {}), "mesh", KEYS["mesh"])
    builder = None
    if "builder" in mesh:
        for k in ("file", "size"):
            if k in mesh:
                r.fail(f"mesh.{k}", "give a mesh file or a builder with its parameters, not both")
        name = r.string(mesh, "mesh", "builder", tuple(BUILDERS))
        params = mesh.get("parameters", {})
        if not isinstance(params, dict):
            r.fail(
                "mesh.parameters", f"expected a table of the builder's parameters, got {params!r}"
            )
        params = {k: tuple(v) if isinstance(v, list) else v for k, v in params.items()}
        builder = (name, params)
        mesh_file, size = None, 1.0
    else:
        if "parameters" in mesh:
            r.fail("mesh.parameters", "parameters belong to a builder: give mesh.builder")
        mesh_name = r.string(mesh, "mesh", "file")
        mesh_file = (path.parent / mesh_name).resolve()
        size = r.number(mesh, "mesh", "size", 1.0, positive=True)

    bodies_data = data.get("bodies")
    if not isinstance(bodies_data, list) or not bodies_data:
        r.fail("bodies", "expected at least one [[bodies]] table (group, E, nu)")
    bodies, body_forces = [], []
    for i, b in enumerate(bodies_data):
        key = f"bodies.{i}"
        b = r.table(b, key, KEYS["bodies"])
        group = r.string(b, key, "group")
        E = r.number(b, key, "E", positive=True)
        nu = r.number(b, key, "nu")
        if not -1.0 < nu < 0.5:
            r.fail(f"{key}.nu", f"Poisson's ratio must be in (-1, 0.5), got {nu}")
        bodies.append((group, Elastic(E, nu)))
        if "body_force" in b:
            f = b["body_force"]
            if (
                not isinstance(f, list)
                or not f
                or not all(isinstance(v, int | float) and not isinstance(v, bool) for v in f)
            ):
                r.fail(f"{key}.body_force", f"expected a list of numbers, got {f!r}")
            body_forces.append((group, np.asarray(f, dtype=np.float64), r.amplitude(b, key)))
        elif "amplitude" in b:
            r.fail(f"{key}.amplitude", "an amplitude scales a body_force: give one")

    boundary = []
    for i, b in enumerate(data.get("boundary", [])):
        key = f"boundary.{i}"
        b = r.table(b, key, KEYS["boundary"])
        entry = Boundary(r.string(b, key, "group"), amplitude=r.amplitude(b, key))
        kinds = [k for k in ("fix", "displacement", "traction", "pressure", "stress") if k in b]
        if not kinds:
            r.fail(key, "give one of fix, displacement, traction, pressure, stress")
        if "fix" in b:
            fixv = b["fix"]
            if not isinstance(fixv, list) or not fixv or any(c not in AXES for c in fixv):
                r.fail(f"{key}.fix", f"expected a list of components among x, y, z, got {fixv!r}")
            entry.fix = tuple(sorted({AXES.index(c) for c in fixv}))
        if "displacement" in b:
            disp = b["displacement"]
            if not isinstance(disp, dict) or not disp or any(c not in AXES for c in disp):
                r.fail(
                    f"{key}.displacement",
                    f"expected a table of components, e.g. {{ y = -0.01 }}, got {disp!r}",
                )
            entry.displacement = {
                AXES.index(c): r.number(disp, f"{key}.displacement", c) for c in disp
            }
            both = set(entry.fix) & set(entry.displacement)
            if both:
                r.fail(key, f"component {AXES[min(both)]} is both fixed and prescribed")
        if "traction" in b:
            t = b["traction"]
            if not isinstance(t, list) or not all(isinstance(v, int | float) for v in t):
                r.fail(f"{key}.traction", f"expected a list of numbers, got {t!r}")
            entry.traction = np.asarray(t, dtype=np.float64)
        if "pressure" in b:
            entry.pressure = r.number(b, key, "pressure")
        if "stress" in b:
            entry.stress = _stress(r, b["stress"], f"{key}.stress")
        if "quadrature_degree" in b:
            q = b["quadrature_degree"]
            if isinstance(q, bool) or not isinstance(q, int) or not 1 <= q <= 30:
                r.fail(f"{key}.quadrature_degree", f"expected an integer in 1..30, got {q!r}")
            entry.quadrature_degree = q
        boundary.append(entry)

    pins = []
    pins_data = data.get("pins", [])
    if not isinstance(pins_data, list):
        r.fail("pins", "expected [[pins]] tables (point, fix)")
    for i, q in enumerate(pins_data):
        key = f"pins.{i}"
        q = r.table(q, key, KEYS["pins"])
        point = q.get("point")
        if (
            not isinstance(point, list)
            or len(point) not in (1, 2, 3)
            or not all(isinstance(v, int | float) and not isinstance(v, bool) for v in point)
        ):
            r.fail(f"{key}.point", f"expected the coordinates of a mesh vertex, got {point!r}")
        fixv = q.get("fix")
        if not isinstance(fixv, list) or not fixv or any(c not in AXES for c in fixv):
            r.fail(f"{key}.fix", f"expected a list of components among x, y, z, got {fixv!r}")
        pins.append((np.asarray(point, dtype=np.float64), sorted({AXES.index(c) for c in fixv})))

    obstacle = data.get("obstacle")
    contact_list = data.get("contact")
    interface = data.get("interface")
    given = [k for k in ("obstacle", "contact", "interface") if data.get(k) is not None]
    if not given:
        r.fail("obstacle", "a problem needs an [obstacle], a [[contact]] pair or an [interface]")
    if len(given) > 1:
        r.fail(
            given[1],
            "give one of [obstacle], [[contact]], [interface], not "
            f"{' and '.join(given)} (one contact kind per problem)",
        )
    if interface is not None:
        interface = dict(r.table(interface, "interface", KEYS["interface"]))
        interface["group"] = r.string(interface, "interface", "group")
        if "fluid_pressure" in interface:
            interface["fluid_pressure"] = r.number(interface, "interface", "fluid_pressure")
        if "proppant_thickness" in interface:
            interface["proppant_thickness"] = r.number(
                interface, "interface", "proppant_thickness", positive=True
            )
        if "proppant_zone" in interface:
            zone = interface["proppant_zone"]
            if "proppant_thickness" not in interface:
                r.fail(
                    "interface.proppant_zone",
                    "a zone of the proppant layer: give its proppant_thickness",
                )
            if not (
                isinstance(zone, list)
                and len(zone) == 2
                and all(isinstance(v, int | float) and not isinstance(v, bool) for v in zone)
                and np.all(np.isfinite(zone))
                and zone[0] < zone[1]
            ):
                r.fail(
                    "interface.proppant_zone",
                    "expected [s0, s1] with s0 < s1 (the layer's "
                    f"ends along the interface coordinate s), got {zone!r}",
                )
            interface["proppant_zone"] = (float(zone[0]), float(zone[1]))
        if "h" in interface:
            interface["h"] = r.number(interface, "interface", "h", positive=True)
        for k in ("origin", "direction"):
            if k in interface:
                interface[k] = r.vector(interface, "interface", k, 2)
        if "direction" in interface:
            norm = float(np.linalg.norm(interface["direction"]))
            if not np.isfinite(norm) or norm == 0.0:
                r.fail("interface.direction", "expected a nonzero vector along the interface")
            interface["direction"] = interface["direction"] / norm
        if "joint" in interface:
            j = r.table(interface["joint"], "interface.joint", ("Kni", "Vm", "w0"))
            values = {
                k: r.number(j, "interface.joint", k, positive=True) for k in ("Kni", "Vm", "w0")
            }
            try:
                interface["joint"] = BartonBandis(**values)
            except ValueError as err:
                r.fail("interface.joint", str(err))
        if len(bodies) != 1:
            r.fail("bodies", f"an interface lies inside one body, got {len(bodies)} bodies")
        for i, b in enumerate(boundary):
            if b.displacement:
                r.fail(
                    f"boundary.{i}.displacement",
                    "prescribed displacements are not offered "
                    "with an [interface] yet (fix, traction, pressure are)",
                )
    if pins and interface is None:
        r.fail(
            "pins", "pinned points are offered with an [interface] (use fix on a group otherwise)"
        )
    if obstacle is not None:
        obstacle = dict(r.table(obstacle, "obstacle", KEYS["obstacle"]))
        obstacle["shape"] = r.string(obstacle, "obstacle", "shape", SHAPES)
        obstacle["contact"] = r.string(obstacle, "obstacle", "contact")
        if obstacle["shape"] in ("circle", "cylinder", "sphere", "parabola", "paraboloid", "punch"):
            obstacle["radius"] = r.number(obstacle, "obstacle", "radius", positive=True)
        if obstacle["shape"] == "punch":
            obstacle["edge_radius"] = r.number(obstacle, "obstacle", "edge_radius", positive=True)
        if obstacle["shape"] == "sinusoid":
            for k in ("height", "wavelength"):
                obstacle[k] = r.number(obstacle, "obstacle", k, positive=True)
        if "h" in obstacle:
            obstacle["h"] = r.number(obstacle, "obstacle", "h", positive=True)
        if "path" in obstacle:
            for k in ("motion", "amplitude"):
                if k in obstacle:
                    r.fail(f"obstacle.{k}", "give either path or motion (with its amplitude)")
            obstacle["path"] = r.offsets(obstacle, "obstacle")
        if obstacle["shape"] == "distance":
            text = r.string(obstacle, "obstacle", "distance")
            try:
                obstacle["distance"] = parse_expression(text)
            except ValueError as err:
                r.fail("obstacle.distance", str(err))
        obstacle["amplitude"] = r.amplitude(obstacle, "obstacle")
    contact = None
    if contact_list is not None:
        if not isinstance(contact_list, list) or len(contact_list) != 1:
            r.fail("contact", "expected one [[contact]] pair (slave, master)")
        c = r.table(contact_list[0], "contact.0", KEYS["contact"])
        contact = (r.string(c, "contact.0", "slave"), r.string(c, "contact.0", "master"))
        if contact[0] == contact[1]:
            r.fail("contact.0", "the slave and master surfaces of a pair must differ")
        if len(bodies) != 2:
            r.fail("bodies", f"a contact pair needs two bodies, got {len(bodies)}")
        pair = {}
        if "h" in c:
            pair["h"] = r.number(c, "contact.0", "h", positive=True)
        if "force_on" in c:
            pair["force_on"] = r.string(c, "contact.0", "force_on", [g for g, _ in bodies])
        if "edge" in c:
            pair["edge"] = r.string(c, "contact.0", "edge", CONTACT_EDGES)
        if "edge_ring" in c:
            if pair.get("edge") != "radial":
                r.fail("contact.0.edge_ring", "the ring width of edge = 'radial' only")
            pair["edge_ring"] = r.number(c, "contact.0", "edge_ring", positive=True)
        elif pair.get("edge") == "radial":
            r.fail(
                "contact.0.edge_ring",
                "missing (the ring width of edge = 'radial', about the slave element size)",
            )
    output = r.table(data.get("output", {}), "output", KEYS["output"])
    reactions = output.get("reactions", [])
    if not isinstance(reactions, list) or not all(isinstance(g, str) for g in reactions):
        r.fail("output.reactions", f"expected a list of group names, got {reactions!r}")
    probes = output.get("probes", [])
    if not isinstance(probes, list) or not all(
        isinstance(q, list)
        and len(q) in (2, 3)
        and all(isinstance(v, int | float) and not isinstance(v, bool) for v in q)
        for q in probes
    ):
        r.fail("output.probes", f"expected a list of points [x, y(, z)], got {probes!r}")
    initial = r.table(data.get("initial", {}), "initial", KEYS["initial"])
    displacement = initial.get("displacement")
    if displacement is not None:
        if not isinstance(displacement, list) or not all(
            isinstance(e, str | int | float) for e in displacement
        ):
            r.fail(
                "initial.displacement",
                "expected a list of expressions in x, y, z (one per "
                f"component), got {displacement!r}",
            )
        try:
            displacement = [parse_expression(str(e)) for e in displacement]
        except ValueError as err:
            r.fail("initial.displacement", str(err))
    symmetry = r.number(output, "output", "symmetry", 1.0, positive=True)
    tsym = output.get("tangential_symmetry")
    if tsym is not None and (
        not isinstance(tsym, list)
        or not all(isinstance(v, int | float) and not isinstance(v, bool) for v in tsym)
    ):
        r.fail("output.tangential_symmetry", f"expected a list of numbers, got {tsym!r}")
    mean_displacement = output.get("mean_displacement", {})
    if not isinstance(mean_displacement, dict) or not all(
        isinstance(v, list) and len(v) == 2 and isinstance(v[0], str) and v[1] in AXES
        for v in mean_displacement.values()
    ):
        r.fail(
            "output.mean_displacement",
            "expected a table name = [group, component], e.g. "
            f'{{ top_displacement = ["top", "y"] }}, got {mean_displacement!r}',
        )
    if mean_displacement and interface is None:
        r.fail("output.mean_displacement", "reported with an [interface] only")
    contact_size = None
    if "contact_size" in output:
        contact_size = r.string(output, "output", "contact_size", CONTACT_SIZES)
    title = data.get("title", path.stem)
    if not isinstance(title, str):
        r.fail("title", f"expected a string, got {title!r}")

    numerics = r.table(
        data.get("numerics", {}), "numerics", tuple(f.name for f in dataclasses.fields(Numerics))
    )
    petsc = data.get("petsc", {})
    if not isinstance(petsc, dict):
        r.fail("petsc", f"expected a table of PETSc options, got {petsc!r}")
    petsc = {
        k: (None if v == "" else str(v).lower() if isinstance(v, bool) else str(v))
        for k, v in petsc.items()
    }
    problem = ProblemFile(
        path,
        mesh_file,
        size,
        bodies,
        boundary,
        obstacle,
        contact,
        interface,
        list(reactions),
        probes,
        title,
        body_forces,
        displacement,
        symmetry,
        None if tsym is None else [float(v) for v in tsym],
        contact_size,
        pair if contact is not None else {},
        pins,
        dict(mean_displacement),
        builder,
    )
    return problem, numerics, petsc


def load_problem(path, sets: list[str] = ()):
    """(scene, numerics, PETSc options) of the problem file ``path`` with the ``--set``
    overrides; the mesh is read when the scene builds it (its groups are checked then)."""
    path = Path(path)
    problem, overrides, petsc = _read(path, list(sets))
    try:
        numerics = Numerics(**overrides)
    except (TypeError, ValueError) as err:
        msg = str(err).replace("--", "numerics.")
        raise ProblemError(f"{path}: {msg}") from None
    cls = (
        FileTwoBodyScene
        if problem.contact is not None
        else FileInterfaceScene
        if problem.interface is not None
        else FileObstacleScene
    )
    return cls(problem), numerics, petsc


# -- signed distance expressions -------------------------------------------------------------

_FUNCTIONS = {
    "sqrt": ufl.sqrt,
    "sin": ufl.sin,
    "cos": ufl.cos,
    "tan": ufl.tan,
    "exp": ufl.exp,
    "ln": ufl.ln,
    "abs": abs,
    "atan2": _compat.ufl_math.atan2,
    "min": ufl.min_value,
    "max": ufl.max_value,
}
_BINARY = {
    ast.Add: lambda a, b: a + b,
    ast.Sub: lambda a, b: a - b,
    ast.Mult: lambda a, b: a * b,
    ast.Div: lambda a, b: a / b,
    ast.Pow: lambda a, b: a**b,
}


def parse_expression(text: str):
    """A function y -> UFL of the expression ``text`` in x, y, z (the coordinates of the point
    in the obstacle's frame), numbers, + - * / **, pi and the functions sqrt, sin, cos, tan,
    exp, ln, abs, atan2, min, max. Definitions ``name = expression`` may come first, separated
    by ';' or new lines, the last statement being the value: a long closed form names its
    repeated parts once (``r = sqrt(x**2 + y**2); 1 / r``). Anything else is refused (nothing
    is evaluated as Python)."""
    shown = re.sub(r"\s+", " ", text.strip())
    shown = shown if len(shown) <= 80 else shown[:77] + "..."
    try:
        module = ast.parse("\n".join(line.strip() for line in text.strip().splitlines()))
    except SyntaxError:
        raise ValueError(f"not an expression: '{shown}'") from None
    *defs, last = module.body or [None]
    if not isinstance(last, ast.Expr) or not all(
        isinstance(d, ast.Assign) and len(d.targets) == 1 and isinstance(d.targets[0], ast.Name)
        for d in defs
    ):
        raise ValueError(
            f"not an expression: '{shown}' (definitions name = expression, then the value)"
        )
    for d in defs:
        if d.targets[0].id in ("x", "y", "z", "pi", *_FUNCTIONS):
            raise ValueError(f"'{d.targets[0].id}' cannot be redefined in '{shown}'")

    def build(node, y, env):
        if isinstance(node, ast.Constant) and isinstance(node.value, int | float):
            return float(node.value)
        if isinstance(node, ast.Name) and node.id in env:
            return env[node.id]
        if isinstance(node, ast.Name) and node.id in ("x", "y", "z"):
            i = "xyz".index(node.id)
            if i >= ufl.shape(y)[0]:
                raise ValueError(f"'{node.id}' in a {ufl.shape(y)[0]}D problem")
            return y[i]
        if isinstance(node, ast.Name) and node.id == "pi":
            return float(np.pi)
        if isinstance(node, ast.BinOp) and type(node.op) in _BINARY:
            return _BINARY[type(node.op)](build(node.left, y, env), build(node.right, y, env))
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub | ast.UAdd):
            v = build(node.operand, y, env)
            return -v if isinstance(node.op, ast.USub) else v
        if (
            isinstance(node, ast.Call)
            and isinstance(node.func, ast.Name)
            and node.func.id in _FUNCTIONS
            and not node.keywords
        ):
            return _FUNCTIONS[node.func.id](*(build(a, y, env) for a in node.args))
        raise ValueError(
            f"'{ast.unparse(node)}' is not allowed in '{shown}' (numbers, x, y, "
            "z, pi, + - * / **, " + ", ".join(_FUNCTIONS) + ")"
        )

    def evaluate(y):
        env = {}
        for d in defs:
            env[d.targets[0].id] = build(d.value, y, env)
        return build(last.value, y, env)

    # check the names and operators once, in 3D
    evaluate(ufl.as_vector([1.0, 1.0, 1.0]))
    return evaluate


class DistanceObstacle(Obstacle):
    """A rigid obstacle given by a signed distance expression phi(y) (> 0 outside it) in the
    obstacle's frame; the normal is -grad phi / |grad phi|."""

    def __init__(self, phi) -> None:
        self._phi = phi

    def phi(self, y):
        return self._phi(y)

    def height(self, t: np.ndarray) -> np.ndarray:
        raise ValueError(
            "the vi method needs an obstacle with a height function (plane, "
            "circle, cylinder, sphere), not a distance expression"
        )


# -- the scenes -------------------------------------------------------------------------------


class _FileMesh:
    """What both file scenes share: the mesh and its named groups, the boundary conditions
    and loads of the file, the reactions per group."""

    symmetry = 1.0
    Params = FileParams

    def coarsened(self, factor: float):
        """None: the file's mesh has one size (nested iteration needs a generated mesh)."""
        return None

    def __init__(self, problem: ProblemFile) -> None:
        self.spec = problem
        self.p = FileParams(problem=str(problem.path), size=problem.size)
        # the name makes the output files and the PETSc options prefix
        self.name = re.sub(r"[^A-Za-z0-9_-]", "_", problem.title)
        self.summary = f"problem file {problem.path.name}"
        self.reaction_rows: list[dict] = []
        self._constants: list[tuple[dolfinx.fem.Constant, list, np.ndarray]] = []
        self.symmetry = problem.symmetry
        if problem.tangential_symmetry is not None:
            self.tangential_symmetry = tuple(problem.tangential_symmetry)

    def _fail(self, key: str, message: str):
        raise ProblemError(f"{self.spec.path}: {key}: {message}")

    def read_mesh(self, comm):
        if self.spec.builder is None:
            data, groups = build_file(comm, self.spec.mesh_file, self.spec.size, self.name)
        else:
            name, params = self.spec.builder
            function, _ = BUILDERS[name]
            builder, groups = builder_groups(functools.partial(function, **params), name)
            try:
                data, groups = build_grouped(comm, builder, groups, self.name)
            except (ValueError, TypeError) as err:  # the builder's own checks, unknown names
                self._fail("mesh.parameters", f"{name}: {err}")
        self.groups = {g.name: g for g in groups}
        self._mesh = data.mesh
        self.gdim = max(g.dim for g in groups)
        self.cell_tags = data.cell_tags
        self._facet_tags = data.facet_tags
        self._check_groups()
        return data.mesh, data.facet_tags

    def group_list(self) -> str:
        return ", ".join(f"{g.name} ({g.dim}D)" for g in self.groups.values())

    def tag(self, key: str, name: str, dim: int) -> int:
        g = self.groups.get(name)
        if g is None:
            self._fail(
                key,
                f"no physical group '{name}' in {self.spec.mesh_label} (it "
                f"has: {self.group_list()})",
            )
        if g.dim != dim:
            what = "cells (a body)" if dim == self.gdim else "facets (a boundary)"
            self._fail(key, f"group '{name}' has dimension {g.dim}, expected {dim}: {what}")
        if g.elements == 0:
            self._fail(key, f"group '{name}' has no element")
        return g.tag

    def _check_groups(self) -> None:
        pb, fdim = self.spec, self.gdim - 1
        self.body_tags = [
            self.tag(f"bodies.{i}.group", g, self.gdim) for i, (g, _) in enumerate(pb.bodies)
        ]
        for i, b in enumerate(pb.boundary):
            self.tag(f"boundary.{i}.group", b.group, fdim)
            comps = [*b.fix, *b.displacement]
            if any(c >= self.gdim for c in comps):
                self._fail(f"boundary.{i}", f"component z in a {self.gdim}D problem")
            if b.traction is not None and len(b.traction) != self.gdim:
                self._fail(f"boundary.{i}.traction", f"expected {self.gdim} numbers")
            if b.stress is not None and len(b.stress) != self.gdim:
                self._fail(f"boundary.{i}.stress", f"expected {self.gdim} rows of {self.gdim}")
        for i, (point, comps) in enumerate(pb.pins):
            if len(point) != self.gdim:
                self._fail(f"pins.{i}.point", f"expected {self.gdim} coordinates")
            if any(c >= self.gdim for c in comps):
                self._fail(f"pins.{i}.fix", f"component z in a {self.gdim}D problem")
        for name, (group, _) in pb.mean_displacement.items():
            self.tag(f"output.mean_displacement.{name}", group, fdim)
        touching = set(pb.contact or ())
        if pb.obstacle is not None:
            touching.add(pb.obstacle["contact"])
        for i, b in enumerate(pb.boundary):
            if b.group in touching:
                self._fail(
                    f"boundary.{i}.group",
                    f"'{b.group}' is a contact surface: the "
                    "contact law there assumes no other condition or load (Nitsche "
                    "would be inconsistent); give it its own physical group",
                )
        if (
            pb.contact is None
            and not pb.pins
            and not any(b.fix or b.displacement for b in pb.boundary)
        ):
            self._fail(
                "boundary",
                "the body has no support (fix or displacement on a group): "
                "frictionless contact alone leaves it free to slide, the solve would be "
                "singular",
            )
        for i, g in enumerate(pb.reactions):
            self.tag(f"output.reactions.{i}", g, fdim)
        for i, q in enumerate(pb.probes):
            if len(q) != self.gdim:
                self._fail(f"output.probes.{i}", f"expected {self.gdim} coordinates, got {q}")

    # -- supports and loads -----------------------------------------------------------------
    def dirichlet(self, V, facet_tags) -> list:
        bcs = []
        for i, b in enumerate(self.spec.boundary):
            tag = self.groups[b.group].tag
            if V.num_sub_spaces == 0:  # one component (1D on dolfinx 0.9): no sub-spaces
                if b.displacement:
                    self._fail(
                        f"boundary.{i}.displacement",
                        "prescribed displacements are not offered in 1D (fix is)",
                    )
                bcs += fix(V, facet_tags, tag) if b.fix else []
                continue
            bcs += [fix_component(V, facet_tags, tag, c) for c in b.fix]
            for c, value in b.displacement.items():
                const = dolfinx.fem.Constant(V.mesh, 0.0)
                self._constants.append((const, b.amplitude, np.array(value)))
                bcs.append(prescribe_component(V, facet_tags, tag, c, const))
        return bcs

    def load(self, v, ds, t):
        L = None
        dx = ufl.Measure("dx", domain=self._mesh, subdomain_data=self.cell_tags)
        for i, (group, force, table) in enumerate(self.spec.body_forces):
            if len(force) != self.gdim:
                self._fail(f"bodies.{i}.body_force", f"expected {self.gdim} numbers")
            amp = dolfinx.fem.Constant(self._mesh, 0.0)
            self._constants.append((amp, table, np.array(1.0)))
            form = amp * ufl.dot(ufl.as_vector(force.tolist()), v) * dx(self.groups[group].tag)
            L = form if L is None else L + form
        for b in self.spec.boundary:
            if b.traction is None and b.pressure is None and b.stress is None:
                continue
            amp = dolfinx.fem.Constant(self._mesh, 0.0)
            self._constants.append((amp, b.amplitude, np.array(1.0)))
            term = 0
            if b.traction is not None:
                term = ufl.dot(ufl.as_vector(b.traction.tolist()), v)
            if b.pressure is not None:  # a pressure pushes into the body: -p n
                term = term - b.pressure * ufl.dot(ufl.FacetNormal(self._mesh), v)
            if b.stress is not None:  # the traction sigma n of a stress field
                x = ufl.SpatialCoordinate(self._mesh)
                y = ufl.as_vector([x[i] for i in range(self.gdim)])
                sigma = ufl.as_matrix(
                    [[e(y) if callable(e) else e for e in row] for row in b.stress]
                )
                term = term + ufl.dot(ufl.dot(sigma, ufl.FacetNormal(self._mesh)), v)
            rule = (
                None if b.quadrature_degree is None else {"quadrature_degree": b.quadrature_degree}
            )
            form = amp * term * ds(self.groups[b.group].tag, metadata=rule)
            L = form if L is None else L + form
        return L

    def set_load(self, t: float) -> None:
        for const, table, value in self._constants:
            const.value = value * _amplitude(table, t)

    def h_contact(self) -> float:
        return self._h

    def contact_size(self, measure: float) -> float:
        """From the measure of the contact set (times the symmetry): by default the contact
        half-width (2D) or the radius of the disc of the same area (3D); ``output.contact_size``
        chooses half-measure, measure or disc-radius."""
        rule = self.spec.contact_size or ("disc-radius" if self.gdim == 3 else "half-measure")
        if rule == "measure":
            return measure
        return 0.5 * measure if rule == "half-measure" else float(np.sqrt(measure / np.pi))

    def initial_guess(self, u, t: float) -> None:
        """The file's ``initial.displacement`` (expressions in x, y, z), else zero."""
        exprs = self.spec.initial
        if exprs is None:
            return
        if len(exprs) != self.gdim:
            self._fail(
                "initial.displacement", f"expected {self.gdim} expressions, got {len(exprs)}"
            )
        x = ufl.SpatialCoordinate(self._mesh)
        y = ufl.as_vector([x[i] for i in range(self.gdim)])
        values = [e(y) for e in exprs]
        values = [
            v if isinstance(v, ufl.core.expr.Expr) else ufl.as_ufl(v) + 0.0 * x[0] for v in values
        ]
        u.interpolate(_compat.expression(ufl.as_vector(values), u.function_space))

    def _facet_points(self, mesh, facets: np.ndarray) -> np.ndarray:
        """(m, vertices per facet, gdim) vertex coordinates of this rank's ``facets``."""
        tdim, fdim = mesh.topology.dim, mesh.topology.dim - 1
        for a, b in ((fdim, 0), (fdim, tdim), (tdim, 0)):
            mesh.topology.create_connectivity(a, b)
        f2v = mesh.topology.connectivity(fdim, 0)
        f2c = mesh.topology.connectivity(fdim, tdim)
        c2v = mesh.topology.connectivity(tdim, 0)
        V = _compat.function_space(mesh, "Lagrange", 1)
        X = _compat.dof_coordinates(V)[:, : self.gdim]
        out = []
        for f in facets:
            c = f2c.links(f)[0]
            dofs, verts = V.dofmap.cell_dofs(c), c2v.links(c)
            out.append(X[[dofs[np.flatnonzero(verts == v)[0]] for v in f2v.links(f)]])
        return np.array(out).reshape(-1, fdim + 1, self.gdim)

    def _facet_size(self, mesh, facet_tags, tags: list[int]) -> float:
        """The longest edge of the facets of the groups ``tags`` (all ranks)."""
        pts = self._facet_points(mesh, facet_tags.indices[np.isin(facet_tags.values, tags)])
        n = pts.shape[1]
        edges = [np.linalg.norm(pts[:, i] - pts[:, j], axis=1) for i in range(n) for j in range(i)]
        h = float(np.max(edges, initial=0.0)) if edges else 0.0
        return mesh.comm.allreduce(h, op=MPI.MAX)

    def _bodies_touching(self, mesh, facet_tags, tag: int) -> list[str]:
        """The bodies (group names, file order) whose cells the facet group ``tag`` bounds,
        on any rank."""
        tdim = mesh.topology.dim
        mesh.topology.create_connectivity(tdim - 1, tdim)
        f2c = mesh.topology.connectivity(tdim - 1, tdim)
        cell_body = dict(zip(self.cell_tags.indices, self.cell_tags.values, strict=True))
        facets = facet_tags.indices[facet_tags.values == tag]
        local = {int(cell_body.get(int(c), -1)) for f in facets for c in f2c.links(f)}
        found = set().union(*mesh.comm.allgather(local))
        return [g for (g, _), t in zip(self.spec.bodies, self.body_tags, strict=True) if t in found]

    # -- reactions -----------------------------------------------------------------------
    def on_step(self, problem, solver, load: float, quantities) -> None:
        """The step's contact force, the probes, and the reaction force of each group of
        ``output.reactions``: the force the supports exert on the body there, per component.
        At a solution K u - b + F_c(u) = R, nonzero on the supported dofs only
        (ContactSNES.reactions); R is summed over the group's owned dofs. (The condensed
        mortar rewrites the rows of the slave nodes: a support sharing nodes with a mortar
        slave surface would not be reported right.)"""
        row = {"load": load, "contact_force": quantities.force}
        self._probe(problem, row)
        if not self.spec.reactions:
            self.reaction_rows.append(row)
            return
        r = solver.reactions()
        values = r.getArray()
        n_owned = len(values)  # the owned dofs come first in the local (unrolled) numbering
        for g in self.spec.reactions:
            facets = self._facet_tags.indices[self._facet_tags.values == self.groups[g].tag]
            for c in range(self.gdim):
                dofs = np.asarray(
                    _compat.locate_dofs_topological(problem.V.sub(c), self.gdim - 1, facets)
                )
                owned = dofs[dofs < n_owned]
                total = float(np.sum(values[owned]))
                row[f"{g}_{AXES[c]}"] = problem.mesh.comm.allreduce(total, op=MPI.SUM)
        r.destroy()
        self.reaction_rows.append(row)

    def _probe(self, problem, row: dict) -> None:
        """The displacement at the probe points (NaN outside the mesh), interpolated into a
        discontinuous space of the displacement's degree, so that near an interface it is
        the total displacement u + H a of the side whose cell holds the point."""
        if not self.spec.probes:
            return
        if not hasattr(self, "_probe_fn"):
            space = _compat.function_space(problem.mesh, "DG", problem.num.degree, (self.gdim,))
            self._probe_fn = dolfinx.fem.Function(space)
            disp = getattr(problem, "w", None)
            if disp is None:
                disp = problem.U
            self._probe_expr = _compat.expression(
                ufl.as_vector([disp[i] for i in range(self.gdim)]), space
            )
        self._probe_fn.interpolate(self._probe_expr)
        values = _compat.point_values(self._probe_fn, np.asarray(self.spec.probes, float))
        for i, v in enumerate(values):
            for c in range(self.gdim):
                row[f"probe{i}_u{AXES[c]}"] = float(v[c])


class FileObstacleScene(_FileMesh, ObstacleScene):
    """A problem file with a rigid obstacle."""

    def build_mesh(self, comm):
        mesh, facet_tags = self.read_mesh(comm)
        ob = self.spec.obstacle
        self.contact_tag = self.tag("obstacle.contact", ob["contact"], self.gdim - 1)
        for shape, dim, other in (
            ("circle", 2, "sphere"),
            ("cylinder", 2, "sphere"),
            ("parabola", 2, "paraboloid"),
            ("sphere", 3, "circle"),
            ("paraboloid", 3, "parabola"),
        ):
            if ob["shape"] == shape and self.gdim != dim:
                self._fail(
                    "obstacle.shape", f"{shape} is a {dim}D obstacle (in {5 - dim}D: {other})"
                )
        if ob["shape"] in ("sinusoid", "punch") and self.gdim == 1:
            self._fail("obstacle.shape", f"{ob['shape']} needs a 2D or 3D problem")
        r = _Reader(self.spec.path)
        zero = [0.0] * self.gdim
        self.position = r.vector(ob, "obstacle", "position", self.gdim, zero)
        self.motion = r.vector(ob, "obstacle", "motion", self.gdim, zero)
        if "path" in ob and len(ob["path"][0]) != self.gdim + 1:
            self._fail(
                "obstacle.path", f"expected rows [load factor, {self.gdim} offset components]"
            )
        self._h = ob.get("h") or self._facet_size(mesh, facet_tags, [self.contact_tag])
        if not self._h > 0.0:
            self._fail(
                "obstacle.h",
                "the contact facets have no size (a 1D problem): give the element size h",
            )
        if len(self.spec.bodies) > 1 and len({m.nu for _, m in self.spec.bodies}) > 1:
            self._fail(
                "bodies",
                "bodies of different nu against an obstacle are not supported (one nu, E per body)",
            )
        # the modulus of the body at the contact surface (the largest, if several touch)
        moduli = dict(self.spec.bodies)
        touching = self._bodies_touching(mesh, facet_tags, self.contact_tag) or list(moduli)
        self._contact_E = max(moduli[g].E for g in touching)
        return mesh, facet_tags

    def material(self) -> Elastic:
        return self.spec.bodies[0][1]

    def modulus(self, mesh):
        if len(self.spec.bodies) == 1:
            return None
        DG0 = _compat.function_space(mesh, "DG", 0)
        E = dolfinx.fem.Function(DG0)
        for tag, (_, mat) in zip(self.body_tags, self.spec.bodies, strict=True):
            cells = self.cell_tags.indices[self.cell_tags.values == tag]
            E.x.array[[DG0.dofmap.cell_dofs(c)[0] for c in cells]] = mat.E
        E.x.scatter_forward()
        return E

    def contact_modulus(self) -> float:
        """The modulus of the body at the contact surface (the largest, if several touch)."""
        return self._contact_E

    def obstacle(self) -> Obstacle:
        ob = self.spec.obstacle
        shape = ob["shape"]
        if shape == "plane":
            return HalfSpace(0.0)
        if shape == "distance":
            return DistanceObstacle(ob["distance"])
        if shape in ("parabola", "paraboloid"):
            return Paraboloid(ob["radius"])
        if shape == "sinusoid":
            return Sinusoid(ob["height"], ob["wavelength"])
        if shape == "punch":
            return FlatPunch(ob["radius"], ob["edge_radius"])
        return Ball(ob["radius"])

    def obstacle_offset(self, t: float, gdim: int) -> np.ndarray:
        ob = self.spec.obstacle
        if "path" in ob:
            rows = np.asarray(ob["path"])
            moved = np.array([np.interp(t, rows[:, 0], rows[:, 1 + i]) for i in range(gdim)])
            return self.position + moved
        return self.position + self.motion * _amplitude(ob["amplitude"], t)


class FileTwoBodyScene(_FileMesh, TwoBodyScene):
    """A problem file with a contact pair between two bodies."""

    def build_mesh(self, comm):
        mesh, facet_tags = self.read_mesh(comm)
        slave, master = self.spec.contact
        fdim = self.gdim - 1
        self._slave = self.tag("contact.0.slave", slave, fdim)
        self._master = self.tag("contact.0.master", master, fdim)
        self.cells = {g: t for (g, _), t in zip(self.spec.bodies, self.body_tags, strict=True)}
        contact = [self._slave, self._master]
        self._h = self.spec.pair.get("h") or self._facet_size(mesh, facet_tags, contact)
        bodies = self._bodies_touching(mesh, facet_tags, self._slave)
        if len(bodies) != 1:
            self._fail(
                "contact.0.slave",
                f"the surface must bound one body, it bounds {sorted(bodies) or 'none'}",
            )
        self._slave_body = bodies[0]
        return mesh, facet_tags

    # (before the mesh is read the tags are unknown; the file's names were checked distinct)
    @property
    def slave_tag(self) -> int:
        return getattr(self, "_slave", -1)

    @property
    def master_tag(self) -> int:
        return getattr(self, "_master", -2)

    @property
    def slave_is_upper(self) -> bool:
        """Whether the pair's force vector (the friction's tangential force, pair_forces.csv)
        is reported on the slave body: ``contact.force_on`` names that body (default the
        slave's)."""
        on = self.spec.pair.get("force_on")
        return on is None or on == getattr(self, "_slave_body", on)

    def materials(self) -> dict[str, Elastic]:
        return dict(self.spec.bodies)

    def material(self) -> Elastic:
        """The slave body's material: it scales the methods' parameters (gamma_N = gamma0 E /
        h, the penalty), as the surface whose traction the method discretises (the stiffest
        body's before the mesh is read)."""
        slave = getattr(self, "_slave_body", None)
        if slave is not None:
            return self.materials()[slave]
        return max((m for _, m in self.spec.bodies), key=lambda m: m.E)

    def contact_edge(self, x: np.ndarray, p: np.ndarray) -> float | None:
        """The contact size by the rule ``contact.edge`` (:func:`contact_edge`), else None
        (the measure rule of ``output.contact_size``)."""
        return contact_edge(self.spec.pair.get("edge"), x, p, self.spec.pair.get("edge_ring"))


class FileInterfaceScene(_FileMesh, InterfaceScene):
    """A problem file with a straight fitted interface (a crack, a fracture with fluid
    pressure) on an interior facet group of one body, in 2D. The interface's line, its sides
    and its tips (the group's end points that are not on the body's boundary) are read from
    the mesh; ``crack_volume`` reports the integral of the opening along it.

    The frame of the interface coordinate s = (x - origin) . direction (the proppant zone, the
    profiles) and the side sign (the + side is the one the normal (-d_y, d_x) points to) are
    ``interface.origin`` and ``interface.direction`` when given, else the centre of the group's
    points and their principal direction (of arbitrary sign). ``interface.h``, when given, is
    the element size that scales the methods' parameters, else the longest interface edge.
    ``[[pins]]`` fix components at mesh vertices (removing the rigid motions of a plate held
    by tractions only)."""

    def build_mesh(self, comm):
        mesh, facet_tags = self.read_mesh(comm)
        if self.gdim != 2:
            self._fail("interface", "interfaces in problem files are 2D (plane strain) for now")
        self.interface_tag = self.tag("interface.group", self.spec.interface["group"], 1)
        segments = self._segments(mesh, facet_tags, [self.interface_tag])
        pts = segments.reshape(-1, 2)
        lo, hi = mesh.geometry.x[:, :2].min(axis=0), mesh.geometry.x[:, :2].max(axis=0)
        lo = np.min(comm.allgather(lo), axis=0)
        hi = np.max(comm.allgather(hi), axis=0)
        self._length = float(np.linalg.norm(hi - lo))
        centre = pts.mean(axis=0)
        _, _, vt = np.linalg.svd(pts - centre)
        spec = self.spec.interface
        self._origin = spec.get("origin", centre)
        self._dir = spec.get("direction", vt[0])
        self._normal = np.array([-self._dir[1], self._dir[0]])
        off = np.abs((pts - centre) @ np.array([-vt[0][1], vt[0][0]])).max()
        if off > 1e-8 * self._length:
            self._fail(
                "interface.group",
                f"the group '{self.spec.interface['group']}' is not "
                f"straight ({off:.3g} off its line): curved interfaces are not offered "
                "yet",
            )
        given = [k for k in ("origin", "direction") if k in spec]
        off = np.abs((pts - self._origin) @ self._normal).max()
        if given and off > 1e-8 * self._length:
            self._fail(
                f"interface.{given[-1]}",
                f"the group '{spec['group']}' is {off:.3g} "
                "off the line through interface.origin along interface.direction",
            )
        tol = 1e-9 * self._length
        keys = np.round(pts / tol).astype(np.int64)
        uniq, count = np.unique(keys, axis=0, return_counts=True)
        ends = uniq[count == 1] * tol
        fdim = mesh.topology.dim - 1
        mesh.topology.create_connectivity(fdim, mesh.topology.dim)
        exterior = _compat_exterior(mesh)
        outer = self._segments(mesh, None, exterior).reshape(-1, 2)
        self._tips = [e for e in ends if not np.any(np.linalg.norm(outer - e, axis=1) < 1e3 * tol)]
        self._h = spec.get("h") or self._facet_size(mesh, facet_tags, [self.interface_tag])
        self._check_pins(mesh, tol)
        return mesh, facet_tags

    def _check_pins(self, mesh, tol: float) -> None:
        """Every pin is a mesh vertex (of some rank)."""
        x = mesh.geometry.x[:, : self.gdim]
        for i, (point, _) in enumerate(self.spec.pins):
            found = bool(len(x)) and float(np.min(np.linalg.norm(x - point, axis=1))) < tol
            if not mesh.comm.allreduce(found, op=MPI.LOR):
                self._fail(
                    f"pins.{i}.point",
                    f"{point.tolist()} is not a vertex of the mesh {self.spec.mesh_label}",
                )

    def _segments(self, mesh, facet_tags, selection) -> np.ndarray:
        """(m, 2, gdim) vertex coordinates of the facets (of the groups ``selection``, or the
        facet indices ``selection`` when facet_tags is None) of every rank."""
        facets = (
            selection
            if facet_tags is None
            else facet_tags.indices[np.isin(facet_tags.values, selection)]
        )
        local = self._facet_points(mesh, facets)
        # ghost facets appear on two ranks: keep each facet once
        every = np.concatenate(mesh.comm.allgather(local))
        keys = np.round(np.sort(every.reshape(len(every), -1), axis=1) * 1e9).astype(np.int64)
        _, first = np.unique(keys, axis=0, return_index=True)
        return every[np.sort(first)]

    def length_scale(self) -> float:
        return self._length

    def supports(self):
        return [(self.groups[b.group].tag, c) for b in self.spec.boundary for c in b.fix]

    def pinned(self):
        return [(point, c) for point, comps in self.spec.pins for c in comps]

    def side(self, x):
        return self._normal[0] * (x[0] - self._origin[0]) + self._normal[1] * (
            x[1] - self._origin[1]
        )

    def tips(self):
        return list(self._tips)

    def frame(self):
        return self._origin, self._dir

    def material(self) -> Elastic:
        return self.spec.bodies[0][1]

    def fluid_pressure(self):
        return self.spec.interface.get("fluid_pressure")

    def floor(self, s):
        """A proppant layer of uniform thickness along the whole interface, or on the zone
        s0 < s < s1 of ``interface.proppant_zone`` only: its end points are unpropped (the
        zone shrunk by 1e-9 of its half-length, so that nodes placed at the ends are out)."""
        t = self.spec.interface.get("proppant_thickness")
        if t is None:
            return None
        zone = self.spec.interface.get("proppant_zone")
        if zone is None:
            return t + 0.0 * s
        centre, half = 0.5 * (zone[0] + zone[1]), 0.5 * (zone[1] - zone[0])
        return ufl.conditional(ufl.lt(abs(s - centre), half * (1.0 - 1e-9)), t, 0.0)

    def joint(self):
        return self.spec.interface.get("joint")

    def extra_quantities(self, mesh, w, ds):
        """crack_volume: the integral of the opening -[w] . n+ along the interface (the + cell's
        outward normal points to the other face, so the opening is independent of which cell
        is +)."""
        dS = ufl.Measure("dS", domain=mesh, subdomain_data=self._facet_tags)
        n = ufl.FacetNormal(mesh)
        out = {"crack_volume": -ufl.dot(ufl.jump(w), n("+")) * dS(self.interface_tag)}
        # output.mean_displacement: the mean of a displacement component over a facet group
        for name, (group, comp) in self.spec.mean_displacement.items():
            tag = self.groups[group].tag
            one = dolfinx.fem.Constant(mesh, 1.0)
            local = dolfinx.fem.assemble_scalar(dolfinx.fem.form(one * ds(tag)))
            measure = mesh.comm.allreduce(local, op=MPI.SUM)
            out[name] = w[AXES.index(comp)] / measure * ds(tag)
        return out


def _compat_exterior(mesh) -> np.ndarray:
    """The exterior facets of this rank (local indices)."""
    return np.asarray(dolfinx.mesh.exterior_facet_indices(mesh.topology), dtype=np.int32)
