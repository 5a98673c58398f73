"""Problem files: a contact problem described by a TOML file over the user's own gmsh mesh.

The file names a mesh (a ``.msh`` file, a ``.geo`` file meshed at run time with a size factor,
or a geometry of :data:`contactfx.meshes.BUILDERS` with its parameters; 1D, 2D or 3D), the
bodies (a cell group each, with its material: linear E and nu, or a hyperelastic model and its
parameters; optionally a body force), the boundary conditions on
named facet groups (fixed components, prescribed displacement components, tractions, normal
pressures, each scaled by a piecewise-linear load amplitude), and a rigid obstacle touching one
facet group (plane, circle / cylinder, sphere, parabola / paraboloid, sinusoid, punch with
rounded edges, or a signed distance expression; moved by ``motion`` times an amplitude or along
a ``path``), a contact pair between two bodies, or an interface; then an optional initial
displacement (Newton's start), the numerics, PETSc options and outputs (reactions, probes, the
mirror planes of a symmetric part, ``symmetry_planes = ["x", "y"]`` for a quarter model: every
force is then the full model's, 2^n times the model's along the planes, 0 normal to them)::

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
    shape = "plane"                    # plane, circle / cylinder (2D), sphere (3D); floor:
                                       # a plane below its body (a body dropped on it)
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

A ``[dynamics]`` section makes the run dynamic (against an obstacle): ``dt``, ``t_end``,
``scheme``, ``rho_inf``, ``mass`` and ``dashpot`` as the numerics of the same names,
``gravity`` (an acceleration: rho g on each body, constant in time) and ``initial_velocity``
(per body, ``{ ball = [0.0, -1.0] }``, or a field of expressions in x, y, z); each body then
needs its ``density`` in ``[[bodies]]``, and ``[initial] displacement`` is the initial state.
The obstacle shape ``floor`` is the plane below its body, through ``position``.

Groups are the gmsh physical names. Everything is validated before anything is computed: an
unknown key, a value of the wrong type or out of range, a group the mesh does not have (the error
lists those it has) or of the wrong dimension is one error naming the file and the key.

:func:`load_problem` reads and validates a file (``--set key=value`` overrides applied first) and
returns the scene, the numerics and the PETSc options; the scene is an
:class:`contactfx.scenes.base.ObstacleScene`, a
:class:`contactfx.scenes.two_body_base.TwoBodyScene` or an
:class:`contactfx.scenes.interface_base.InterfaceScene`, solved by the one pipeline like any
built-in scene.

The package: :mod:`.reader` (typed access, one-line errors, ``--set``), :mod:`.specs` (the
frozen spec of each section), :mod:`.sections` (one reader per section), :mod:`.expressions`
(closed forms in x, y, z), :mod:`.scenes` (the three scenes of a file).
"""

from __future__ import annotations

from pathlib import Path

from contactfx.numerics import Numerics
from contactfx.scenes.problem_file.expressions import DistanceObstacle, parse_expression
from contactfx.scenes.problem_file.reader import ProblemError, apply_sets
from contactfx.scenes.problem_file.scenes import (
    FileInterfaceScene,
    FileObstacleScene,
    FileParams,
    FileTwoBodyScene,
)
from contactfx.scenes.problem_file.sections import check_materials, read
from contactfx.scenes.problem_file.specs import ProblemFile

__all__ = [
    "load_problem",
    "ProblemFile",
    "ProblemError",
    "FileParams",
    "apply_sets",
    "parse_expression",
    "DistanceObstacle",
    "FileObstacleScene",
    "FileTwoBodyScene",
    "FileInterfaceScene",
]


def load_problem(path, sets: list[str] = ()):
    """(scene, numerics, PETSc options) of the problem file ``path`` with the ``--set``
    overrides; the mesh is read when the scene builds it (its groups are checked then)."""
    path = Path(path)
    problem, overrides, petsc = read(path, list(sets))
    try:
        numerics = Numerics(**overrides)
    except (TypeError, ValueError) as err:
        msg = str(err).replace("--", "numerics.")
        raise ProblemError(f"{path}: {msg}") from None
    check_materials(problem, numerics)
    if problem.pair is not None:
        return FileTwoBodyScene(problem), numerics, petsc
    if problem.interface is not None:
        return FileInterfaceScene(problem), numerics, petsc
    return FileObstacleScene(problem), numerics, petsc
