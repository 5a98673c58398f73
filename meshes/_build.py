"""Build gmsh models on one rank and hand them to dolfinx or to a ``.msh`` file.

A *builder* is a function ``builder(model)`` that receives the ``gmsh.model`` namespace of an open
gmsh session, creates the geometry, the physical groups and the mesh-size field, and calls
``model.mesh.generate(gdim)``. The geometry modules (:mod:`contactfx.meshes.rectangle`,
:mod:`contactfx.meshes.box`, :mod:`contactfx.meshes.crack_plate`,
:mod:`contactfx.meshes.joint_column`) define builders with keyword-only parameters that they
validate before any gmsh call; callers bind the parameters with :func:`functools.partial`::

    data = build(comm, partial(rectangle, x0=-1.0, x1=1.0, ...), gdim=2, name="block")

:func:`build` runs the builder on rank 0 only and distributes the mesh and its physical groups
with ``dolfinx.io.gmshio.model_to_mesh``, as the dolfinx demos do; if the builder fails, every
rank raises the same exception instead of waiting in a collective. :func:`write_msh` runs a
builder with gmsh alone (no dolfinx, no MPI) and writes a gmsh 4.1 ``.msh`` file.

Mesh grading (:func:`set_graded_size`): with d the exact Euclidean distance to the refinement
zone, written as a gmsh MathEval expression (no sampling error), a gmsh Threshold field imposes
the element size

    h(d) = h_min                                        for d <= d_min,
    h(d) = min(h_max, h_min + grading * (d - d_min))    for d >  d_min,

so ``grading`` is the size increase per unit distance and neighbouring elements differ in size
by a factor of about ``1 + grading``. Point, curvature and boundary size sources are disabled:
the field alone decides.

gmsh is imported inside the functions, never at module level: importing gmsh replaces the SIGINT
handler, and importing contactfx must have no side effects.

Reference: C. Geuzaine, J.-F. Remacle, Gmsh: a 3-D finite element mesh generator with built-in
pre- and post-processing facilities, Int. J. Numer. Meth. Eng. 79 (2009) 1309-1331,
doi:10.1002/nme.2579.
"""

from __future__ import annotations

import contextlib
import math
import os
import tempfile
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from enum import IntEnum
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import dolfinx.mesh
    import gmsh
    from mpi4py import MPI

__all__ = [
    "GMSH_RANK",
    "Builder",
    "Group",
    "MeshData",
    "MshInfo",
    "add_physical_groups",
    "build",
    "build_file",
    "build_grouped",
    "builder_groups",
    "file_groups",
    "check_finite",
    "check_less",
    "check_less_equal",
    "check_positive",
    "matheval_number",
    "refine_near",
    "model_to_mesh",
    "set_graded_size",
    "write_msh",
]

GMSH_RANK = 0
"""The rank that runs gmsh in :func:`build`."""

Builder = Callable[["type[gmsh.model]"], None]
"""A function that builds and meshes a geometry in the ``gmsh.model`` namespace it is given."""


@dataclass(frozen=True)
class MeshData:
    """A distributed dolfinx mesh with its physical groups as mesh tags.

    ``cell_tags`` holds the physical groups of the cells (named ``"cells"``), ``facet_tags``
    those of the facets (named ``"facets"``): the boundary facets and, for geometries with
    cracks or joints, interior facets; the tag values are the IntEnum values of the geometry
    module that built the mesh.

    In parallel the mesh has ghost mode ``shared_facet`` (see :func:`build`): a facet on a
    partition boundary is present on both ranks, with both its cells, and carries its tag on
    both; integrals over ``ufl.dS`` count it once (on its owner).
    """

    mesh: dolfinx.mesh.Mesh
    cell_tags: dolfinx.mesh.MeshTags
    facet_tags: dolfinx.mesh.MeshTags


@dataclass(frozen=True)
class MshInfo:
    """What :func:`write_msh` wrote: the file and the size of the mesh in it."""

    path: Path
    num_nodes: int
    num_cells: int


def model_to_mesh(
    model: type[gmsh.model], comm: MPI.Comm, rank: int, gdim: int
) -> tuple[dolfinx.mesh.Mesh, dolfinx.mesh.MeshTags, dolfinx.mesh.MeshTags]:
    """Distribute the gmsh model that lives on ``rank`` as a dolfinx mesh with cell and facet tags.

    The only dolfinx call of :mod:`contactfx.meshes`; ghost mode ``shared_facet``. Collective on
    ``comm``.
    """
    from contactfx import _compat  # dolfinx is imported only when a mesh is built

    return _compat.model_to_mesh(model, comm, rank, gdim)


@contextlib.contextmanager
def _gmsh_session(name: str) -> Iterator[type[gmsh.model]]:
    """Open a quiet gmsh session (no user configuration files) with one empty model."""
    import gmsh

    gmsh.initialize(readConfigFiles=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add(name)
        yield gmsh.model
    finally:
        gmsh.finalize()


def _check_gdim(gdim: int) -> None:
    if gdim not in (1, 2, 3):
        raise ValueError(f"gdim must be 1, 2 or 3, got {gdim}")


def _check_generated(model: type[gmsh.model], gdim: int) -> None:
    """Raise if the builder left no meshed physical group of dimension ``gdim``."""
    if not model.getPhysicalGroups(gdim):
        raise RuntimeError(f"builder defined no physical group of dimension {gdim}")
    _, element_tags, _ = model.mesh.getElements(gdim)
    if sum(len(tags) for tags in element_tags) == 0:
        raise RuntimeError(f"builder did not generate a {gdim}D mesh")


def build(comm: MPI.Comm, builder: Builder, gdim: int, name: str) -> MeshData:
    """Run ``builder`` with gmsh on rank 0 and distribute the mesh over ``comm``.

    Collective on ``comm``. If the builder raises on rank 0 (invalid parameters raise
    ``ValueError``), every rank raises an exception of the same type and message.

    The mesh is partitioned with ghost mode ``shared_facet`` on every supported dolfinx: each
    rank also holds, as ghosts, the cells across its facets on partition boundaries, so that
    interior-facet integrals (``ufl.dS``: cracks, joints, material interfaces) include the
    facets on partition boundaries, each integrated once (by the rank that owns the facet). With
    ghost mode ``none``, dolfinx's default from 0.8 on, such a facet has one local cell: dolfinx
    0.9 refuses to create a ``dS`` form over it (RuntimeError), dolfinx 0.5 silently skips it.

    ``comm``: the communicator of the mesh; ``builder``: a geometry function with its
    parameters bound, e.g. ``functools.partial(rectangle, x0=-1.0, ...)``; ``gdim``: the
    geometric dimension of the mesh (2 or 3); ``name``: the name of the gmsh model and of the
    dolfinx mesh.
    """
    import gmsh

    _check_gdim(gdim)
    on_gmsh_rank = comm.rank == GMSH_RANK
    session = _gmsh_session(name) if on_gmsh_rank else contextlib.nullcontext(gmsh.model)
    with session as model:
        failure: Exception | None = None
        if on_gmsh_rank:
            try:
                builder(model)
                _check_generated(model, gdim)
            except Exception as exc:
                failure = exc
        # The other ranks receive a copy of the exception; rank 0 re-raises the original one,
        # which keeps the builder's traceback.
        shared_failure = comm.bcast(failure, root=GMSH_RANK)
        if failure is not None:
            raise failure
        if shared_failure is not None:
            raise shared_failure
        mesh, cell_tags, facet_tags = model_to_mesh(model, comm, GMSH_RANK, gdim)
    mesh.name = name
    cell_tags.name = "cells"
    facet_tags.name = "facets"
    return MeshData(mesh, cell_tags, facet_tags)


def write_msh(
    builder: Builder, gdim: int, path: str | os.PathLike[str], name: str, binary: bool = False
) -> MshInfo:
    """Run ``builder`` with gmsh alone and write the mesh to ``path`` (gmsh format 4.1).

    Only the elements of physical groups are written, with their physical tags (gmsh's default
    ``Mesh.SaveAll`` 0). Returns the path and the numbers of nodes and of cells written.
    ``binary`` writes the binary variant: its node coordinates are the doubles themselves,
    while the ASCII file rounds them to 16 significant digits (off by up to an ulp, and a
    contact search can turn an ulp into a different discrete problem).
    """
    _check_gdim(gdim)
    path = Path(path)
    if not path.parent.is_dir():
        raise FileNotFoundError(f"output directory {str(path.parent)!r} does not exist")
    import gmsh

    with _gmsh_session(name) as model:
        builder(model)
        _check_generated(model, gdim)
        gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
        gmsh.option.setNumber("Mesh.Binary", int(binary))
        gmsh.write(str(path))
        node_tags, _, _ = model.mesh.getNodes()
        _, element_tags, _ = model.mesh.getElements(gdim)
        return MshInfo(path, len(node_tags), sum(len(tags) for tags in element_tags))


def check_finite(**values: float) -> None:
    """Raise ``ValueError`` naming the first value that is not a finite number."""
    for name, value in values.items():
        if not math.isfinite(value):
            raise ValueError(f"{name} must be finite, got {value}")


def check_positive(**values: float) -> None:
    """Raise ``ValueError`` naming the first value that is not > 0."""
    for name, value in values.items():
        if not value > 0:
            raise ValueError(f"{name} must be > 0, got {value}")


def check_less(lower_name: str, lower: float, upper_name: str, upper: float) -> None:
    """Raise ``ValueError`` unless ``lower < upper``."""
    if not lower < upper:
        raise ValueError(
            f"{lower_name} must be < {upper_name}, got {lower_name}={lower}, {upper_name}={upper}"
        )


def check_less_equal(lower_name: str, lower: float, upper_name: str, upper: float) -> None:
    """Raise ``ValueError`` unless ``lower <= upper``."""
    if not lower <= upper:
        raise ValueError(
            f"{lower_name} must be <= {upper_name}, got {lower_name}={lower}, {upper_name}={upper}"
        )


def add_physical_groups(
    model: type[gmsh.model],
    domain: IntEnum,
    sides: Mapping[IntEnum, tuple[int, float]],
    interior: Mapping[IntEnum, Sequence[int]] | None = None,
) -> None:
    """Tag all entities of the top dimension as ``domain`` and their boundary by planes.

    ``sides`` maps each facet tag to ``(axis, value)``, the plane ``x[axis] == value`` its
    boundary entities lie in. Every boundary entity must lie in exactly one of the planes, so
    the facet tags cover the boundary exactly once. ``interior`` maps further facet tags to
    entities of dimension ``dim - 1`` inside the domain (cracks, joints: curves embedded in a
    surface or shared by two surfaces), e.g. the children of a line in the map returned by
    ``model.occ.fragment``; none of them may be a boundary entity, and each group must be
    non-empty. Physical names are the lower-case enum names. Call after the geometry is
    synchronised.
    """
    dim = model.getDimension()
    cells = [tag for _, tag in model.getEntities(dim)]
    model.addPhysicalGroup(dim, cells, domain.value)
    model.setPhysicalName(dim, domain.value, domain.name.lower())

    xmin, ymin, zmin, xmax, ymax, zmax = model.getBoundingBox(-1, -1)
    # OCC bounding boxes are enlarged by the geometric tolerance (~1e-7).
    tol = 1e-6 * max(xmax - xmin, ymax - ymin, zmax - zmin)
    members: dict[IntEnum, list[int]] = {side: [] for side in sides}
    for _, tag in model.getBoundary([(dim, cell) for cell in cells], oriented=False):
        box = model.getBoundingBox(dim - 1, tag)
        matches = [
            side
            for side, (axis, value) in sides.items()
            if abs(box[axis] - value) <= tol and abs(box[axis + 3] - value) <= tol
        ]
        if len(matches) != 1:
            raise RuntimeError(f"boundary entity {tag} lies on {len(matches)} sides, expected 1")
        members[matches[0]].append(tag)
    for side, tags in members.items():
        if not tags:
            raise RuntimeError(f"no boundary entity on side {side.name}")
    boundary = {tag for tags in members.values() for tag in tags}
    for group, tags in (interior or {}).items():
        if not tags:
            raise RuntimeError(f"no entity in interior group {group.name}")
        if boundary.intersection(tags):
            raise RuntimeError(f"interior group {group.name} contains boundary entities")
        members[group] = list(tags)
    for group, tags in members.items():
        model.addPhysicalGroup(dim - 1, tags, group.value)
        model.setPhysicalName(dim - 1, group.value, group.name.lower())


def set_graded_size(
    model: type[gmsh.model],
    distance: str,
    *,
    size_min: float,
    size_max: float,
    dist_min: float,
    grading: float,
) -> int:
    """Make the mesh size grow linearly from ``size_min`` to ``size_max`` away from a zone.

    ``distance`` is a gmsh MathEval expression in x, y, z for the distance to the zone; the size
    is ``size_min`` up to ``dist_min`` and grows by ``grading`` per unit distance beyond (see
    the module docstring). Also disables every other source of mesh size. Returns the size
    field's tag (to combine it with others).
    """
    import gmsh

    field = model.mesh.field
    if size_min == size_max:
        # Uniform size. A Threshold field with DistMin == DistMax evaluates to NaN at distance
        # DistMin, and gmsh then leaves a hole in the boundary discretisation.
        size = field.add("MathEval")
        field.setString(size, "F", matheval_number(size_min))
    else:
        distance_field = field.add("MathEval")
        field.setString(distance_field, "F", distance)
        size = field.add("Threshold")
        field.setNumber(size, "InField", distance_field)
        field.setNumber(size, "SizeMin", size_min)
        field.setNumber(size, "SizeMax", size_max)
        field.setNumber(size, "DistMin", dist_min)
        field.setNumber(size, "DistMax", dist_min + (size_max - size_min) / grading)
    field.setAsBackgroundMesh(size)
    gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
    gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
    gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
    return size


def refine_near(
    model: type[gmsh.model],
    size: int,
    distance: str,
    *,
    size_min: float,
    size_max: float,
    grading: float,
) -> int:
    """Combine the size field ``size`` with a finer zone: the size ``size_min`` at distance 0
    of it (``distance``, a MathEval expression) growing by ``grading`` per unit distance up to
    ``size_max``; the smaller of the two holds (a gmsh Min field, the background mesh).
    Returns the Min field's tag."""
    field = model.mesh.field
    zone_distance = field.add("MathEval")
    field.setString(zone_distance, "F", distance)
    zone = field.add("Threshold")
    field.setNumber(zone, "InField", zone_distance)
    field.setNumber(zone, "SizeMin", size_min)
    field.setNumber(zone, "SizeMax", size_max)
    field.setNumber(zone, "DistMin", 0.0)
    field.setNumber(zone, "DistMax", (size_max - size_min) / grading)
    both = field.add("Min")
    field.setNumbers(both, "FieldsList", [size, zone])
    field.setAsBackgroundMesh(both)
    return both


def matheval_number(value: float) -> str:
    """Format ``value`` for a gmsh MathEval expression: full precision, in parentheses."""
    return f"({float(value)!r})"


def distance_along_x(end: float) -> str:
    """A gmsh MathEval expression of the distance along x from the segment [0, ``end``]
    (0 over it, |x| left of it, x - end right of it)."""
    e = matheval_number(end)
    return f"(Fabs(x)+Fabs(x-{e})-{e})/2"


@dataclass(frozen=True)
class Group:
    """A named physical group of a mesh file: its dimension, tag and number of elements."""

    name: str
    dim: int
    tag: int
    elements: int


def _collect_groups(model: type[gmsh.model], groups: list[Group], where: str) -> None:
    """Append the model's named physical groups (with their element counts) to ``groups``."""
    if not model.getPhysicalGroups():
        raise ValueError(
            f"{where}: the mesh has no physical group (name the bodies and "
            "the boundaries with Physical Curve / Surface / Volume)"
        )
    for dim, tag in model.getPhysicalGroups():
        name = model.getPhysicalName(dim, tag) or str(tag)
        count = 0
        for entity in model.getEntitiesForPhysicalGroup(dim, tag):
            _, element_tags, _ = model.mesh.getElements(dim, entity)
            count += sum(len(t) for t in element_tags)
        groups.append(Group(name, dim, tag, count))


def builder_groups(builder: Builder, where: str):
    """``builder`` wrapped to fill, on the rank that runs it, the list it returns with the
    model's named physical groups (:class:`Group`)."""
    groups: list[Group] = []

    def wrapped(model: type[gmsh.model]) -> None:
        builder(model)
        _collect_groups(model, groups, where)

    return wrapped, groups


def file_groups(path: str | os.PathLike[str], size_factor: float = 1.0):
    """A builder that loads a ``.msh`` file or meshes a ``.geo`` file (gmsh's own parser, the
    element sizes scaled by ``size_factor``), and the list it fills, on the rank that runs it,
    with the file's named physical groups (:class:`Group`). The mesh dimension is the highest
    dimension of a physical group. A ``.geo`` is meshed in a child process that writes the
    mesh (binary, every entity) for the builder to load, so that a geometry gmsh cannot mesh
    (a syntax error, an open or self-intersecting curve loop: gmsh can terminate the process)
    raises ValueError "FILE: gmsh failed: MESSAGE" with gmsh's error; so does a ``.msh`` gmsh
    cannot read."""
    path = Path(path)
    groups: list[Group] = []

    def builder(model: type[gmsh.model]) -> None:
        import gmsh

        if path.suffix != ".geo":
            try:
                gmsh.merge(str(path))
            except Exception as exc:  # gmsh's Python API raises Exception(its last error)
                raise ValueError(f"{path}: gmsh failed: {_one_line(str(exc))}") from None
        else:
            with tempfile.TemporaryDirectory(prefix="contactfx-geo-") as tmp:
                msh = Path(tmp) / f"{path.stem}.msh"
                _mesh_geo(path, msh, size_factor)
                gmsh.merge(str(msh))
        _collect_groups(model, groups, str(path))

    return builder, groups


def _one_line(text: str) -> str:
    return " ".join(text.split())


#: how many times gmsh may split intersecting edges and mesh again before a .geo is refused
MAX_RETRIES = 20


def _mesh_geo(geo: Path, msh: Path, size_factor: float) -> None:
    """Mesh ``geo`` into ``msh`` in a child process (``_gmsh_child.py``); raise ValueError
    "GEO: gmsh failed: MESSAGE" with gmsh's last error (and its last note of a problem, e.g.
    the intersections of a self-intersecting loop) when gmsh fails or crashes."""
    import subprocess
    import sys

    script = Path(__file__).with_name("_gmsh_child.py")
    # no MPI state of this process: the child is a plain process, not an MPI singleton
    env = {k: v for k, v in os.environ.items() if not k.startswith(("OMPI_", "PMIX_", "PRTE_"))}
    proc = subprocess.Popen(
        [sys.executable, str(script), str(geo), str(msh), repr(float(size_factor))],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        env=env,
    )
    assert proc.stdout is not None
    lines, retries = [], 0
    for line in proc.stdout:
        lines.append(line.rstrip("\n"))
        # gmsh 4.13 meets a self-intersecting loop by splitting the intersecting edges and
        # meshing again, without end (gmsh 4.8 terminates): a recovery that keeps failing
        if "trying again" in line:
            retries += 1
            if retries > MAX_RETRIES:
                proc.kill()
                break
    proc.wait()
    if proc.returncode == 0 and msh.is_file():
        return
    errors = [ln.split(":", 1)[1].strip() for ln in lines if ln.startswith("Error")]
    notes = [ln.split(":-(", 1)[1].strip() for ln in lines if ":-(" in ln]
    message = "; ".join(dict.fromkeys(notes[-1:] + errors[-1:]))
    if not message:
        message = (
            f"gmsh crashed (signal {-proc.returncode})"
            if proc.returncode < 0
            else f"exit status {proc.returncode}"
        )
    for prefix in (f"'{geo}', ", f"'{geo}': "):  # the file is named once, first
        message = message.removeprefix(prefix)
    raise ValueError(f"{geo}: gmsh failed: {_one_line(message)}")


def build_file(
    comm: MPI.Comm, path: str | os.PathLike[str], size_factor: float, name: str
) -> tuple[MeshData, list[Group]]:
    """:func:`build` for a mesh file (:func:`file_groups`): the distributed mesh and, on every
    rank, the file's physical groups. The dimension is the file's (a 2D mesh in the plane z = 0
    gives a 2D mesh). Collective; a missing file raises FileNotFoundError on every rank."""
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"mesh file {str(path)!r} not found")
    if path.suffix not in (".msh", ".geo"):
        raise ValueError(f"mesh file {str(path)!r}: expected a .msh or .geo file")
    builder, groups = file_groups(path, size_factor)
    return build_grouped(comm, builder, groups, name)


def build_grouped(
    comm: MPI.Comm, builder: Builder, groups: list[Group], name: str
) -> tuple[MeshData, list[Group]]:
    """:func:`build` for a builder that fills ``groups`` on the gmsh rank
    (:func:`builder_groups`, :func:`file_groups`): the distributed mesh and, on every rank, the
    named physical groups; the dimension is the highest of a group. Collective; an error of the
    builder is raised on every rank."""
    import gmsh

    on_gmsh_rank = comm.rank == GMSH_RANK
    session = _gmsh_session(name) if on_gmsh_rank else contextlib.nullcontext(gmsh.model)
    with session as model:
        failure: Exception | None = None
        if on_gmsh_rank:
            try:
                builder(model)
            except Exception as exc:
                failure = exc
        shared = comm.bcast((failure, groups), root=GMSH_RANK)
        if failure is not None:
            raise failure
        if shared[0] is not None:
            raise shared[0]
        groups = shared[1]
        gdim = max(g.dim for g in groups)
        _check_gdim(gdim)
        mesh, cell_tags, facet_tags = model_to_mesh(model, comm, GMSH_RANK, gdim)
    mesh.name = name
    cell_tags.name = "cells"
    facet_tags.name = "facets"
    return MeshData(mesh, cell_tags, facet_tags), groups
