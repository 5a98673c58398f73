"""One reader per section of a problem file, each returning its frozen spec
(:mod:`.specs`); :func:`read` runs them in the file's order and checks what joins sections
(one contact kind, pins and mean displacements with an interface, the bodies a pair or an
interface needs). Every error is one line naming the file and the key."""

from __future__ import annotations

import dataclasses
import tomllib
from pathlib import Path
from typing import Any

import numpy as np

from contactfx.contact.interface import BartonBandis
from contactfx.contact.point_coupling import nitsche_finite_strain_refusal
from contactfx.mechanics.elasticity import Elastic
from contactfx.mechanics.hyperelastic import (
    MODELS,
    Hyperelastic,
    MooneyRivlin,
    NeoHookean,
    SaintVenantKirchhoff,
    parse_spec,
)
from contactfx.meshes import BUILDERS
from contactfx.numerics import Numerics
from contactfx.scenes.problem_file.expressions import parse_expression
from contactfx.scenes.problem_file.reader import ProblemError, Reader, apply_sets, numbers
from contactfx.scenes.problem_file.specs import (
    AXES,
    DYNAMICS_NUMERICS,
    SECTIONS,
    BodySpec,
    BoundarySpec,
    DynamicsSpec,
    InterfaceSpec,
    MeshSpec,
    ObstacleSpec,
    OutputSpec,
    PairSpec,
    PinSpec,
    ProblemFile,
)
from contactfx.scenes.two_body_base import CONTACT_EDGES, INTERFERENCES, SMOOTHINGS
from contactfx.solvers.dynamics import Scheme

__all__ = ["SECTIONS", "KEYS", "SHAPES", "CONTACT_SIZES", "read", "check_materials"]

KEYS = {
    "mesh": ("file", "size", "builder", "parameters", "axisymmetric"),
    "bodies": (
        "group",
        "material",
        "E",
        "nu",
        "mu",
        "kappa",
        "c10",
        "c01",
        "body_force",
        "amplitude",
        "density",
    ),
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
    "contact": (
        "slave",
        "master",
        "h",
        "force_on",
        "edge",
        "edge_ring",
        "interference",
        "smoothing",
    ),
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
    "dynamics": (
        "scheme",
        "rho_inf",
        "dt",
        "t_end",
        "mass",
        "dashpot",
        "time_tolerance",
        "gravity",
        "initial_velocity",
    ),
    "output": (
        "reactions",
        "probes",
        "symmetry",
        "symmetry_planes",
        "contact_size",
        "mean_displacement",
        "format",
    ),
}
#: output.format: XDMF3 + HDF5 (written in parallel) or a PVD series of VTU files
OUTPUT_FORMATS = ("xdmf", "vtu")
SHAPES = (
    "plane",
    "floor",
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
#: the shapes with a radius
_ROUND = ("circle", "cylinder", "sphere", "parabola", "paraboloid", "punch")


def read_mesh(r: Reader, data: dict) -> MeshSpec:
    mesh = r.table(data.get("mesh", {}), "mesh", KEYS["mesh"])
    axisymmetric = r.flag(mesh, "mesh", "axisymmetric")
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
        return MeshSpec(None, 1.0, (name, params), axisymmetric)
    if "parameters" in mesh:
        r.fail("mesh.parameters", "parameters belong to a builder: give mesh.builder")
    mesh_file = (r.path.parent / r.string(mesh, "mesh", "file")).resolve()
    size = r.number(mesh, "mesh", "size", 1.0, positive=True)
    return MeshSpec(mesh_file, size, None, axisymmetric)


def read_bodies(r: Reader, data: dict) -> tuple[BodySpec, ...]:
    bodies_data = data.get("bodies")
    if not isinstance(bodies_data, list) or not bodies_data:
        r.fail("bodies", "expected at least one [[bodies]] table (group, E, nu)")
    bodies = []
    for i, b in enumerate(bodies_data):
        key = f"bodies.{i}"
        b = r.table(b, key, KEYS["bodies"])
        group = r.string(b, key, "group")
        material = _material(r, b, key)
        force, amplitude = None, ()
        if "body_force" in b:
            if not numbers(b["body_force"], minimum=1):
                r.fail(f"{key}.body_force", f"expected a list of numbers, got {b['body_force']!r}")
            force, amplitude = np.asarray(b["body_force"], dtype=np.float64), r.amplitude(b, key)
        elif "amplitude" in b:
            r.fail(f"{key}.amplitude", "an amplitude scales a body_force: give one")
        bodies.append(BodySpec(group, material, force, amplitude))
    return tuple(bodies)


def _check_finite_strain(r: Reader, bodies: tuple[BodySpec, ...], kind: str) -> None:
    """Finite strain is offered for one body against an obstacle, and for each of the two
    bodies of a [[contact]] pair (a material per body: :func:`_material`)."""
    finite = [i for i, b in enumerate(bodies) if b.material.finite_strain]
    if finite and len(bodies) > 1 and kind != "contact":
        r.fail(
            f"bodies.{finite[0]}.material",
            "a finite-strain material is offered for one body against a rigid obstacle or for "
            "the bodies of a [[contact]] pair (give the other bodies' groups to the same "
            "[[bodies]] table, or use linear materials)",
        )


def _material(r: Reader, b: dict, key: str) -> Elastic | Hyperelastic:
    """A body's material: ``material`` (linear, the default; neo-hookean, mooney-rivlin,
    svk) with its parameters (linear and svk: E, nu; neo-hookean: E, nu or mu, kappa;
    mooney-rivlin: c10, c01 (default 0), kappa) and its ``density`` (a dynamic run's mass
    per unit volume). Each body has its own: a problem with a
    hyperelastic body is finite strain, and a linear body in a finite-strain pair keeps its
    small-strain stress (:mod:`contactfx.driver.two_body`)."""
    model = r.string(b, key, "material", tuple(MODELS), default="linear")
    allowed = MODELS[model]
    kw = {"density": r.optional_number(b, key, "density", positive=True)}
    for k in ("E", "nu", "mu", "kappa", "c10", "c01"):
        if k in b and k not in allowed:
            r.fail(
                f"{key}.{k}",
                f"not a parameter of material {model} (its parameters: {', '.join(allowed)})",
            )
    if model == "mooney-rivlin":
        c10 = r.number(b, key, "c10")
        c01 = r.number(b, key, "c01", 0.0)
        for name, value in (("c10", c10), ("c01", c01)):
            if value < 0.0:
                r.fail(f"{key}.{name}", f"must be >= 0, got {value}")
        if not c10 + c01 > 0.0:
            r.fail(f"{key}.c10", "c10 + c01 (half the shear modulus) must be > 0")
        return MooneyRivlin(c10, c01, r.number(b, key, "kappa", positive=True), **kw)
    if model == "neo-hookean" and ("mu" in b or "kappa" in b):
        for k in ("E", "nu"):
            if k in b:
                r.fail(f"{key}.{k}", "give E and nu, or mu and kappa, not both")
        mu = r.number(b, key, "mu", positive=True)
        return NeoHookean.from_mu_kappa(mu, r.number(b, key, "kappa", positive=True), **kw)
    E = r.number(b, key, "E", positive=True)
    nu = r.number(b, key, "nu")
    if not -1.0 < nu < 0.5:
        r.fail(f"{key}.nu", f"Poisson's ratio must be in (-1, 0.5), got {nu}")
    if model == "neo-hookean":
        return NeoHookean.from_E_nu(E, nu, **kw)
    if model == "svk":
        return SaintVenantKirchhoff.from_E_nu(E, nu, **kw)
    return Elastic(E, nu, **kw)


def _boundary(r: Reader, b: Any, key: str) -> BoundarySpec:
    b = r.table(b, key, KEYS["boundary"])
    group, amplitude = r.string(b, key, "group"), r.amplitude(b, key)
    if not any(k in b for k in ("fix", "displacement", "traction", "pressure", "stress")):
        r.fail(key, "give one of fix, displacement, traction, pressure, stress")
    fix = r.components(b["fix"], f"{key}.fix", AXES) if "fix" in b else ()
    displacement = {}
    if "displacement" in b:
        disp = b["displacement"]
        if not isinstance(disp, dict) or not disp or any(c not in AXES for c in disp):
            r.fail(
                f"{key}.displacement",
                f"expected a table of components, e.g. {{ y = -0.01 }}, got {disp!r}",
            )
        displacement = {AXES.index(c): r.number(disp, f"{key}.displacement", c) for c in disp}
        both = set(fix) & set(displacement)
        if both:
            r.fail(key, f"component {AXES[min(both)]} is both fixed and prescribed")
    traction = None
    if "traction" in b:
        if not numbers(b["traction"]):
            r.fail(f"{key}.traction", f"expected a list of numbers, got {b['traction']!r}")
        traction = np.asarray(b["traction"], dtype=np.float64)
    pressure = r.optional_number(b, key, "pressure")
    stress = _stress(r, b["stress"], f"{key}.stress") if "stress" in b else None
    degree = None
    if "quadrature_degree" in b:
        degree = b["quadrature_degree"]
        if isinstance(degree, bool) or not isinstance(degree, int) or not 1 <= degree <= 30:
            r.fail(f"{key}.quadrature_degree", f"expected an integer in 1..30, got {degree!r}")
    return BoundarySpec(group, fix, displacement, traction, pressure, amplitude, stress, degree)


def read_boundary(r: Reader, data: dict) -> tuple[BoundarySpec, ...]:
    return tuple(_boundary(r, b, f"boundary.{i}") for i, b in enumerate(data.get("boundary", [])))


def _stress(r: Reader, value: Any, key: str) -> tuple[tuple[Any, ...], ...]:
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
        entries: list[Any] = []
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
        out.append(tuple(entries))
    return tuple(out)


def read_pins(r: Reader, data: dict) -> tuple[PinSpec, ...]:
    pins_data = data.get("pins", [])
    if not isinstance(pins_data, list):
        r.fail("pins", "expected [[pins]] tables (point, fix)")
    pins = []
    for i, q in enumerate(pins_data):
        key = f"pins.{i}"
        q = r.table(q, key, KEYS["pins"])
        point = q.get("point")
        if not numbers(point, (1, 2, 3)):
            r.fail(f"{key}.point", f"expected the coordinates of a mesh vertex, got {point!r}")
        fix = r.components(q.get("fix"), f"{key}.fix", AXES)
        pins.append(PinSpec(np.asarray(point, dtype=np.float64), fix))
    return tuple(pins)


def read_interface(r: Reader, data: dict) -> InterfaceSpec:
    d = r.table(data["interface"], "interface", KEYS["interface"])
    group = r.string(d, "interface", "group")
    fluid = r.optional_number(d, "interface", "fluid_pressure")
    thickness = r.optional_number(d, "interface", "proppant_thickness", positive=True)
    zone = None
    if "proppant_zone" in d:
        zone = d["proppant_zone"]
        if thickness is None:
            r.fail(
                "interface.proppant_zone",
                "a zone of the proppant layer: give its proppant_thickness",
            )
        if not (numbers(zone, 2) and np.all(np.isfinite(zone)) and zone[0] < zone[1]):
            r.fail(
                "interface.proppant_zone",
                "expected [s0, s1] with s0 < s1 (the layer's "
                f"ends along the interface coordinate s), got {zone!r}",
            )
        zone = (float(zone[0]), float(zone[1]))
    h = r.optional_number(d, "interface", "h", positive=True)
    origin = r.vector(d["origin"], "interface.origin", 2) if "origin" in d else None
    direction = None
    if "direction" in d:
        direction = r.vector(d["direction"], "interface.direction", 2)
        norm = float(np.linalg.norm(direction))
        if not np.isfinite(norm) or norm == 0.0:
            r.fail("interface.direction", "expected a nonzero vector along the interface")
        direction = direction / norm
    joint = None
    if "joint" in d:
        j = r.table(d["joint"], "interface.joint", ("Kni", "Vm", "w0"))
        values = {k: r.number(j, "interface.joint", k, positive=True) for k in ("Kni", "Vm", "w0")}
        try:
            joint = BartonBandis(**values)
        except ValueError as err:
            r.fail("interface.joint", str(err))
    return InterfaceSpec(group, fluid, thickness, zone, joint, h, origin, direction)


def read_obstacle(r: Reader, data: dict) -> ObstacleSpec:
    d = r.table(data["obstacle"], "obstacle", KEYS["obstacle"])
    shape = r.string(d, "obstacle", "shape", SHAPES)
    contact = r.string(d, "obstacle", "contact")
    radius = r.number(d, "obstacle", "radius", positive=True) if shape in _ROUND else None
    edge_radius = None
    if shape == "punch":
        edge_radius = r.number(d, "obstacle", "edge_radius", positive=True)
    height = wavelength = None
    if shape == "sinusoid":
        height = r.number(d, "obstacle", "height", positive=True)
        wavelength = r.number(d, "obstacle", "wavelength", positive=True)
    h = r.optional_number(d, "obstacle", "h", positive=True)
    path = None
    if "path" in d:
        for k in ("motion", "amplitude"):
            if k in d:
                r.fail(f"obstacle.{k}", "give either path or motion (with its amplitude)")
        path = r.offsets(d, "obstacle")
    distance = None
    if shape == "distance":
        text = r.string(d, "obstacle", "distance")
        try:
            distance = parse_expression(text)
        except ValueError as err:
            r.fail("obstacle.distance", str(err))
    return ObstacleSpec(
        shape,
        contact,
        r.amplitude(d, "obstacle"),
        radius=radius,
        edge_radius=edge_radius,
        height=height,
        wavelength=wavelength,
        distance=distance,
        h=h,
        position=d.get("position"),
        motion=d.get("motion"),
        path=path,
    )


def read_pair(r: Reader, data: dict, bodies: tuple[BodySpec, ...]) -> PairSpec:
    contact_list = data["contact"]
    if not isinstance(contact_list, list) or len(contact_list) != 1:
        r.fail("contact", "expected one [[contact]] pair (slave, master)")
    c = r.table(contact_list[0], "contact.0", KEYS["contact"])
    slave, master = r.string(c, "contact.0", "slave"), r.string(c, "contact.0", "master")
    if slave == master:
        r.fail("contact.0", "the slave and master surfaces of a pair must differ")
    if len(bodies) != 2:
        r.fail("bodies", f"a contact pair needs two bodies, got {len(bodies)}")
    h = r.optional_number(c, "contact.0", "h", positive=True)
    force_on = None
    if "force_on" in c:
        force_on = r.string(c, "contact.0", "force_on", [b.group for b in bodies])
    edge = r.string(c, "contact.0", "edge", CONTACT_EDGES) if "edge" in c else None
    ring = None
    if "edge_ring" in c:
        if edge != "radial":
            r.fail("contact.0.edge_ring", "the ring width of edge = 'radial' only")
        ring = r.number(c, "contact.0", "edge_ring", positive=True)
    elif edge == "radial":
        r.fail(
            "contact.0.edge_ring",
            "missing (the ring width of edge = 'radial', about the slave element size)",
        )
    interference = None
    if "interference" in c:
        interference = r.string(c, "contact.0", "interference", INTERFERENCES)
    smoothing = "auto"
    if "smoothing" in c:
        smoothing = r.string(c, "contact.0", "smoothing", SMOOTHINGS)
    return PairSpec(slave, master, h, force_on, edge, ring, interference, smoothing)


def read_output(r: Reader, data: dict) -> OutputSpec:
    raw = data.get("output", {})
    if isinstance(raw, dict) and "tangential_symmetry" in raw:
        r.fail(
            "output.tangential_symmetry",
            "replaced by symmetry_planes, the axes normal to the mirror planes (e.g. "
            '["x", "y"] for a quarter model): every force is the full model\'s, its components '
            "along them 0",
        )
    output = r.table(raw, "output", KEYS["output"])
    reactions = output.get("reactions", [])
    if not isinstance(reactions, list) or not all(isinstance(g, str) for g in reactions):
        r.fail("output.reactions", f"expected a list of group names, got {reactions!r}")
    probes = output.get("probes", [])
    if not isinstance(probes, list) or not all(numbers(q, (2, 3)) for q in probes):
        r.fail("output.probes", f"expected a list of points [x, y(, z)], got {probes!r}")
    planes = output.get("symmetry_planes", [])
    if (
        not isinstance(planes, list)
        or not all(isinstance(a, str) and a in AXES for a in planes)
        or len(set(planes)) != len(planes)
    ):
        r.fail(
            "output.symmetry_planes",
            "expected a list of distinct axes normal to the mirror planes, e.g. "
            f'["x", "y"] for a quarter model cut by x = 0 and y = 0, got {planes!r}',
        )
    # each mirror plane doubles the model
    full = 2.0 ** len(planes)
    symmetry = r.number(output, "output", "symmetry", full, positive=True)
    if planes and symmetry != full:
        r.fail(
            "output.symmetry",
            f"{symmetry:g} with {len(planes)} mirror plane(s) in symmetry_planes: each "
            f"doubles the model, so {full:g} (or leave symmetry out)",
        )
    if symmetry != 1.0 and not planes:
        r.fail(
            "output.symmetry",
            f"{symmetry:g} needs the mirror planes: symmetry_planes = [...], the axes normal "
            'to them (["x", "y"] for a quarter model cut by x = 0 and y = 0; the full '
            "model's force components along them are 0)",
        )
    mean = output.get("mean_displacement", {})
    if not isinstance(mean, dict) or not all(
        isinstance(v, list) and len(v) == 2 and isinstance(v[0], str) and v[1] in AXES
        for v in mean.values()
    ):
        r.fail(
            "output.mean_displacement",
            "expected a table name = [group, component], e.g. "
            f'{{ top_displacement = ["top", "y"] }}, got {mean!r}',
        )
    size = None
    if "contact_size" in output:
        size = r.string(output, "output", "contact_size", CONTACT_SIZES)
    fmt = r.string(output, "output", "format", OUTPUT_FORMATS, default="xdmf")
    return OutputSpec(
        tuple(reactions),
        tuple(tuple(float(v) for v in q) for q in probes),
        symmetry,
        tuple(AXES.index(a) for a in planes),
        size,
        {name: (v[0], v[1]) for name, v in mean.items()},
        fmt,
    )


def read_initial(r: Reader, data: dict) -> tuple | None:
    initial = r.table(data.get("initial", {}), "initial", KEYS["initial"])
    displacement = initial.get("displacement")
    if displacement is None:
        return None
    if not isinstance(displacement, list) or not all(
        isinstance(e, str | int | float) for e in displacement
    ):
        r.fail(
            "initial.displacement",
            f"expected a list of expressions in x, y, z (one per component), got {displacement!r}",
        )
    try:
        return tuple(parse_expression(str(e)) for e in displacement)
    except ValueError as err:
        r.fail("initial.displacement", str(err))


_CHOICES = {f.name: f.metadata["choices"] for f in dataclasses.fields(Numerics)}


def read_dynamics(
    r: Reader, data: dict, bodies: tuple[BodySpec, ...], kind: str
) -> tuple[DynamicsSpec | None, dict]:
    """``[dynamics]`` (the file's run is then dynamic): its spec and its numerics (the time
    scheme, rho_inf, dt, t_end, the mass matrix, the contact dashpot, the adaptive step's
    time_tolerance); each body needs its density. Offered against an obstacle and between two
    bodies (interfaces in time are not yet)."""
    if "dynamics" not in data:
        return None, {}
    d = r.table(data["dynamics"], "dynamics", KEYS["dynamics"])
    if kind == "interface":
        r.fail(
            "dynamics",
            "a dynamic run is offered against an [obstacle] or between the bodies of a "
            "[[contact]] pair; a problem with an [interface] is static",
        )
    for i, b in enumerate(bodies):
        if b.material.density is None:
            r.fail(
                f"bodies.{i}.density",
                "missing: a dynamic run ([dynamics]) needs each body's density (mass per unit "
                "volume)",
            )
    numerics: dict[str, Any] = {"dynamic": True}
    for k in DYNAMICS_NUMERICS:
        if k not in d:
            continue
        if k in data.get("numerics", {}):
            r.fail(f"numerics.{k}", f"given in [dynamics] too: give dynamics.{k} only")
        if k in ("scheme", "mass"):
            numerics[k] = r.string(d, "dynamics", k, _CHOICES[k])
        else:
            zero = ("rho_inf", "dashpot", "time_tolerance")  # 0 allowed (off)
            numerics[k] = r.number(d, "dynamics", k, positive=k not in zero)
        if k in ("dashpot", "time_tolerance") and not numerics[k] >= 0.0:
            r.fail(f"dynamics.{k}", f"must be >= 0, got {numerics[k]}")
    try:  # rho_inf's range for the scheme, one line naming the key
        Scheme.named(numerics.get("scheme", "newmark"), numerics.get("rho_inf", 1.0))
    except ValueError as err:
        r.fail("dynamics.rho_inf", str(err).replace("--rho-inf", "rho_inf").replace("--", ""))
    if "dt" in numerics and numerics.get("t_end", np.inf) < numerics["dt"] * (1.0 - 1e-12):
        r.fail("dynamics.t_end", f"must be at least one time step (dt = {numerics['dt']})")
    gravity = None
    if "gravity" in d:
        if not numbers(d["gravity"], (1, 2, 3)):
            r.fail(
                "dynamics.gravity", f"expected the acceleration's components, got {d['gravity']!r}"
            )
        gravity = np.asarray(d["gravity"], dtype=np.float64)
    velocity, field = {}, None
    given = d.get("initial_velocity")
    if isinstance(given, dict):
        groups = [b.group for b in bodies]
        for group, value in given.items():
            if group not in groups:
                r.fail(
                    f"dynamics.initial_velocity.{group}",
                    f"not a body (the bodies: {', '.join(groups)})",
                )
            if not numbers(value, (1, 2, 3)):
                r.fail(
                    f"dynamics.initial_velocity.{group}",
                    f"expected the velocity's components, got {value!r}",
                )
            velocity[group] = np.asarray(value, dtype=np.float64)
    elif isinstance(given, list) and all(isinstance(e, str | int | float) for e in given):
        try:
            field = tuple(parse_expression(str(e)) for e in given)
        except ValueError as err:
            r.fail("dynamics.initial_velocity", str(err))
    elif given is not None:
        r.fail(
            "dynamics.initial_velocity",
            "expected a table body = [components] (e.g. { ball = [0.0, -1.0] }) or a list of "
            f"expressions in x, y, z (one per component), got {given!r}",
        )
    return DynamicsSpec(gravity, velocity, field), numerics


def read_numerics(r: Reader, data: dict) -> dict:
    """The ``[numerics]`` overrides (checked by Numerics itself in :func:`load_problem`)."""
    allowed = tuple(f.name for f in dataclasses.fields(Numerics))
    return dict(r.table(data.get("numerics", {}), "numerics", allowed))


def read_petsc(r: Reader, data: dict) -> dict:
    petsc = data.get("petsc", {})
    if not isinstance(petsc, dict):
        r.fail("petsc", f"expected a table of PETSc options, got {petsc!r}")
    return {
        k: (None if v == "" else str(v).lower() if isinstance(v, bool) else str(v))
        for k, v in petsc.items()
    }


def _contact_kind(r: Reader, data: dict) -> str:
    """The one contact kind of the file: obstacle, contact (a pair) or interface."""
    given = [k for k in ("obstacle", "contact", "interface") if data.get(k) is not None]
    if not given:
        r.fail("obstacle", "a problem needs an [obstacle], a [[contact]] pair or an [interface]")
    if len(given) > 1:
        r.fail(
            given[1],
            "give one of [obstacle], [[contact]], [interface], not "
            f"{' and '.join(given)} (one contact kind per problem)",
        )
    return given[0]


def _check_interface(
    r: Reader, bodies: tuple[BodySpec, ...], boundary: tuple[BoundarySpec, ...]
) -> None:
    if len(bodies) != 1:
        r.fail("bodies", f"an interface lies inside one body, got {len(bodies)} bodies")
    for i, b in enumerate(boundary):
        if b.displacement:
            r.fail(
                f"boundary.{i}.displacement",
                "prescribed displacements are not offered "
                "with an [interface] yet (fix, traction, pressure are)",
            )


def check_materials(problem: ProblemFile, numerics: Numerics) -> None:
    """The bodies' materials against the numerics: ``numerics.material`` (``--set
    numerics.material=...``) turns every linear body into one model with the body's E and nu,
    as ``--material`` does for a built-in scene, so it cannot be combined with a body that
    names its own finite-strain model; a pair with a finite-strain body needs a method that
    offers finite strain between two bodies (the problem kind's check sees the slave body's
    material only)."""
    r = Reader(problem.path)
    finite = [(i, b) for i, b in enumerate(problem.bodies) if b.material.finite_strain]
    if not finite:
        return
    i, body = finite[0]
    if parse_spec(numerics.material) != ("linear", {}):
        r.fail(
            "numerics.material",
            f"{numerics.material!r} conflicts with bodies.{i}.material = "
            f"{body.material.name!r}: numerics.material makes every linear body one model (with "
            "its E and nu); give each body's model in its [[bodies]] table instead",
        )
    if problem.pair is not None and numerics.method == "nitsche":
        names = [b.material.name if b.material.finite_strain else "linear" for b in problem.bodies]
        refusal = nitsche_finite_strain_refusal(names)
        if refusal is not None:
            r.fail("numerics.method", refusal)


def read(path: Path, sets: list[str]) -> tuple[ProblemFile, dict, dict]:
    """(problem, numerics overrides, PETSc options) of the file, without the mesh."""
    if not path.is_file():
        raise FileNotFoundError(f"problem file {str(path)!r} not found")
    try:
        data = tomllib.loads(path.read_text())
    except tomllib.TOMLDecodeError as err:
        raise ProblemError(f"{path}: not valid TOML: {err}") from None
    data = apply_sets(data, sets, str(path))
    r = Reader(path)
    for key in data:
        if key not in SECTIONS:
            r.fail(key, f"unknown section (allowed: {', '.join(SECTIONS)})")
    mesh = read_mesh(r, data)
    bodies = read_bodies(r, data)
    boundary = read_boundary(r, data)
    pins = read_pins(r, data)
    kind = _contact_kind(r, data)
    _check_finite_strain(r, bodies, kind)
    obstacle = pair = interface = None
    if kind == "interface":
        interface = read_interface(r, data)
        _check_interface(r, bodies, boundary)
    if pins and interface is None:
        r.fail(
            "pins", "pinned points are offered with an [interface] (use fix on a group otherwise)"
        )
    if kind == "obstacle":
        obstacle = read_obstacle(r, data)
    if kind == "contact":
        pair = read_pair(r, data, bodies)
    output = read_output(r, data)
    initial = read_initial(r, data)
    dynamics, dynamic_numerics = read_dynamics(r, data, bodies, kind)
    if output.mean_displacement and interface is None:
        r.fail("output.mean_displacement", "reported with an [interface] only")
    title = data.get("title", path.stem)
    if not isinstance(title, str):
        r.fail("title", f"expected a string, got {title!r}")
    problem = ProblemFile(
        path=path,
        title=title,
        mesh=mesh,
        bodies=bodies,
        boundary=boundary,
        pins=pins,
        obstacle=obstacle,
        pair=pair,
        interface=interface,
        initial=initial,
        output=output,
        dynamics=dynamics,
    )
    return problem, {**read_numerics(r, data), **dynamic_numerics}, read_petsc(r, data)
