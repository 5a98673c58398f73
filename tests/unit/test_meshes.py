"""Unit tests of :mod:`contactfx.meshes`: exact measures, graded sizes, validation, command line.

Run at 1 and 2 ranks::

    python3 -m pytest tests/unit/test_meshes.py
    mpirun -n 2 python3 -m mpi4py -m pytest tests/unit/test_meshes.py
"""

from __future__ import annotations

import math
import subprocess
import sys
from functools import partial

import dolfinx.fem
import dolfinx.mesh
import numpy as np
import numpy.typing as npt
import pytest
import ufl
from mpi4py import MPI

from contactfx.meshes import (
    BoxCells,
    BoxFacets,
    Builder,
    CrackPlateCells,
    CrackPlateFacets,
    JointColumnCells,
    JointColumnFacets,
    MeshData,
    RectangleCells,
    RectangleFacets,
    box,
    build,
    crack_plate,
    joint_column,
    rectangle,
)

RECTANGLE = dict(
    x0=-2.0,
    x1=2.0,
    y0=-2.0,
    y1=0.0,
    refine_x0=-0.2,
    refine_x1=0.2,
    h_contact=0.02,
    h_far=0.4,
    grading=0.3,
)
BOX = dict(
    x0=0.0,
    x1=1.0,
    y0=0.0,
    y1=1.0,
    z0=-1.0,
    z1=0.0,
    refine_center=(0.0, 0.0),
    refine_radius=0.15,
    h_contact=0.03,
    h_far=0.25,
    grading=1.0,
)
CRACK_PLATE = dict(
    half_width=1.0,
    crack_half_length=0.4,
    angle=0.0,
    h_crack=0.02,
    h_far=0.2,
    grading=0.5,
    split_at=(0.1, -0.25),
)
JOINT_COLUMN = dict(width=0.5, block_height=0.4, h=0.05)


@pytest.fixture(scope="module")
def rectangle_mesh() -> MeshData:
    return build(MPI.COMM_WORLD, partial(rectangle, **RECTANGLE), gdim=2, name="rectangle")


@pytest.fixture(scope="module")
def box_mesh() -> MeshData:
    return build(MPI.COMM_WORLD, partial(box, **BOX), gdim=3, name="box")


@pytest.fixture(scope="module", params=[0.0, 30.0], ids=lambda angle: f"angle={angle:g}")
def crack_plate_mesh(request) -> tuple[dict, MeshData]:
    p = dict(CRACK_PLATE, angle=request.param)
    return p, build(MPI.COMM_WORLD, partial(crack_plate, **p), gdim=2, name="crack_plate")


@pytest.fixture(scope="module")
def joint_column_mesh() -> MeshData:
    return build(MPI.COMM_WORLD, partial(joint_column, **JOINT_COLUMN), gdim=2, name="joint")


def _measure(data: MeshData, tag: int | None = None, integral: str = "ds") -> float:
    """Global measure of the mesh (``tag`` None) or of the facets tagged ``tag``.

    ``integral`` "ds" for boundary facets, "dS" for interior facets (cracks, joints).
    """
    mesh = data.mesh
    if tag is None:
        measure = ufl.dx(domain=mesh)
    else:
        measure = ufl.Measure(integral, domain=mesh, subdomain_data=data.facet_tags)(tag)
    local = dolfinx.fem.assemble_scalar(dolfinx.fem.form(1.0 * measure))
    return mesh.comm.allreduce(local, op=MPI.SUM)


def _check_boundary_tagged_once(data: MeshData, interior: tuple[int, ...] = ()) -> None:
    """Every boundary facet carries exactly one tag, and only boundary facets are tagged, but for
    the facets tagged ``interior`` (cracks, joints), which must be interior facets.

    Compared on the facets each rank owns: ghost facets differ between the two lists.
    """
    topology = data.mesh.topology
    num_owned = topology.index_map(topology.dim - 1).size_local
    indices = data.facet_tags.indices
    assert np.unique(indices).size == indices.size
    exterior = dolfinx.mesh.exterior_facet_indices(topology)
    owned = indices < num_owned
    on_boundary = ~np.isin(data.facet_tags.values, interior)
    owned_tagged = np.sort(indices[owned & on_boundary])
    assert np.array_equal(owned_tagged, np.sort(exterior[exterior < num_owned]))
    assert not np.isin(indices[owned & ~on_boundary], exterior).any()


def _vertex_coordinates(mesh: dolfinx.mesh.Mesh) -> npt.NDArray[np.float64]:
    """Coordinates of the local (owned and ghost) vertices of a linear simplex mesh.

    For a linear mesh the i-th geometry node of a cell is its i-th topological vertex.
    """
    tdim = mesh.topology.dim
    mesh.topology.create_connectivity(tdim, 0)
    cell_vertices = mesh.topology.connectivity(tdim, 0).array
    dofmap = mesh.geometry.dofmap  # an AdjacencyList in dolfinx 0.5, an array later
    nodes = np.asarray(getattr(dofmap, "array", dofmap)).reshape(-1)
    coordinates = np.empty((cell_vertices.max() + 1, 3))
    coordinates[cell_vertices] = mesh.geometry.x[nodes]
    return coordinates


def _facet_vertices(data: MeshData, tag: int | None = None) -> npt.NDArray[np.float64]:
    """(num_facets, 2, 3) end points of the owned edges of a 2D mesh, or of those tagged ``tag``.

    The owned facets of all ranks are every facet once.
    """
    mesh = data.mesh
    mesh.topology.create_connectivity(1, 0)
    facet_vertices = mesh.topology.connectivity(1, 0).array.reshape(-1, 2)
    num_owned = mesh.topology.index_map(1).size_local
    facets = np.arange(num_owned) if tag is None else data.facet_tags.find(tag)
    return _vertex_coordinates(mesh)[facet_vertices[facets[facets < num_owned]]]


def _lengths(ends: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
    return np.linalg.norm(ends[:, 1] - ends[:, 0], axis=1)


def _check_interior_facets_integrated_once(data: MeshData, boundary_length: float) -> None:
    """``1 * dS`` over the whole mesh is the total length of the interior edges.

    The reference sums the edges each rank owns, so counts every edge once. With ghost mode
    ``none`` the edges on partition boundaries have one local cell: dolfinx 0.5 misses them in
    ``dS``, dolfinx 0.9 raises RuntimeError.
    """
    comm = data.mesh.comm
    dS = ufl.dS(domain=data.mesh)
    interior = comm.allreduce(dolfinx.fem.assemble_scalar(dolfinx.fem.form(1.0 * dS)), MPI.SUM)
    all_edges = comm.allreduce(_lengths(_facet_vertices(data)).sum(), op=MPI.SUM)
    assert interior == pytest.approx(all_edges - boundary_length, rel=1e-12)


def _cell_sizes(data: MeshData) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """Mean edge length and midpoint of every cell of the mesh, gathered on all ranks.

    The mean edge length is what a gmsh size field prescribes.
    """
    mesh = data.mesh
    tdim = mesh.topology.dim
    num_owned = mesh.topology.index_map(tdim).size_local
    # dolfinx 0.5 stores the geometry dofmap as an AdjacencyList, later versions as an array.
    dofmap = mesh.geometry.dofmap
    nodes = np.asarray(getattr(dofmap, "array", dofmap)).reshape(-1, tdim + 1)[:num_owned]
    vertices = mesh.geometry.x[nodes]
    edges = [
        np.linalg.norm(vertices[:, i] - vertices[:, j], axis=1)
        for i in range(tdim + 1)
        for j in range(i + 1, tdim + 1)
    ]
    sizes = np.concatenate(mesh.comm.allgather(np.mean(edges, axis=0)))
    midpoints = np.concatenate(mesh.comm.allgather(vertices.mean(axis=1)))
    return sizes, midpoints


def _check_sizes(
    sizes: npt.NDArray[np.float64],
    distance: npt.NDArray[np.float64],
    near: float,
    far: float,
    h_contact: float,
    h_far: float,
) -> None:
    """Cells closer than ``near`` have size h_contact, cells farther than ``far`` size h_far.

    Factor 1.5: gmsh accepts edges within about [0.7, 1.4] times the prescribed size, and its 3D
    Delaunay refinement stops at mean edge lengths about 1.3 times the prescribed size (median
    measured on uniform boxes). The smallest cells near the zone must not be much smaller than
    h_contact (no over-refinement); the typical (median) cells must match both sizes.
    """
    near_sizes = sizes[distance < near]
    far_sizes = sizes[distance > far]
    assert near_sizes.size > 0 and far_sizes.size > 0
    assert h_contact / 1.5 <= near_sizes.min() <= 1.5 * h_contact
    assert h_contact / 1.5 <= np.median(near_sizes) <= 1.5 * h_contact
    assert h_far / 1.5 <= np.median(far_sizes) <= 1.5 * h_far


def test_rectangle_measures(rectangle_mesh: MeshData) -> None:
    p = RECTANGLE
    width, height = p["x1"] - p["x0"], p["y1"] - p["y0"]
    assert rectangle_mesh.mesh.name == "rectangle"
    assert rectangle_mesh.cell_tags.name == "cells"
    assert rectangle_mesh.facet_tags.name == "facets"
    assert np.all(rectangle_mesh.cell_tags.values == RectangleCells.DOMAIN)
    _check_boundary_tagged_once(rectangle_mesh)
    # Straight-sided triangles tile the rectangle exactly: only round-off remains.
    assert _measure(rectangle_mesh) == pytest.approx(width * height, rel=1e-12)
    lengths = {
        RectangleFacets.BOTTOM: width,
        RectangleFacets.RIGHT: height,
        RectangleFacets.TOP: width,
        RectangleFacets.LEFT: height,
    }
    for tag, length in lengths.items():
        assert _measure(rectangle_mesh, tag) == pytest.approx(length, rel=1e-12), tag.name


def test_rectangle_sizes(rectangle_mesh: MeshData) -> None:
    p = RECTANGLE
    sizes, midpoints = _cell_sizes(rectangle_mesh)
    x, y = midpoints[:, 0], midpoints[:, 1]
    along = np.maximum(np.maximum(p["refine_x0"] - x, x - p["refine_x1"]), 0.0)
    distance = np.hypot(along, p["y1"] - y)
    band = 0.5 * (p["refine_x1"] - p["refine_x0"])
    graded = band + (p["h_far"] - p["h_contact"]) / p["grading"]
    _check_sizes(sizes, distance, band, graded, p["h_contact"], p["h_far"])


def test_rectangle_interfaces() -> None:
    p = dict(RECTANGLE, interfaces=(-0.1, -1.0))
    width, height = p["x1"] - p["x0"], p["y1"] - p["y0"]
    data = build(MPI.COMM_WORLD, partial(rectangle, **p), gdim=2, name="layered")
    _check_boundary_tagged_once(data)
    # Straight-sided triangles tile the layers and the interfaces exactly: only round-off.
    assert _measure(data) == pytest.approx(width * height, rel=1e-12)
    assert _measure(data, RectangleFacets.LEFT) == pytest.approx(height, rel=1e-12)
    mesh = data.mesh
    for y in p["interfaces"]:
        on_line = dolfinx.mesh.locate_entities(mesh, 1, lambda x, y=y: np.isclose(x[1], y))
        tags = dolfinx.mesh.meshtags(mesh, 1, np.sort(on_line), np.ones_like(on_line))
        dS = ufl.dS(domain=mesh, subdomain_data=tags, subdomain_id=1)
        length = dolfinx.fem.assemble_scalar(dolfinx.fem.form(1.0 * dS))
        # the interface is a chain of interior mesh edges covering its full width
        assert mesh.comm.allreduce(length, op=MPI.SUM) == pytest.approx(width, rel=1e-12)


def test_box_measures(box_mesh: MeshData) -> None:
    p = BOX
    dx, dy, dz = p["x1"] - p["x0"], p["y1"] - p["y0"], p["z1"] - p["z0"]
    assert box_mesh.mesh.name == "box"
    assert np.all(box_mesh.cell_tags.values == BoxCells.DOMAIN)
    _check_boundary_tagged_once(box_mesh)
    # Straight-sided tetrahedra tile the box exactly: only round-off remains.
    assert _measure(box_mesh) == pytest.approx(dx * dy * dz, rel=1e-12)
    areas = {
        BoxFacets.XMIN: dy * dz,
        BoxFacets.XMAX: dy * dz,
        BoxFacets.YMIN: dx * dz,
        BoxFacets.YMAX: dx * dz,
        BoxFacets.ZMIN: dx * dy,
        BoxFacets.ZMAX: dx * dy,
    }
    for tag, area in areas.items():
        assert _measure(box_mesh, tag) == pytest.approx(area, rel=1e-12), tag.name


def test_box_sizes(box_mesh: MeshData) -> None:
    p = BOX
    sizes, midpoints = _cell_sizes(box_mesh)
    center = np.array([*p["refine_center"], p["z1"]])
    distance = np.linalg.norm(midpoints - center, axis=1)
    graded = p["refine_radius"] + (p["h_far"] - p["h_contact"]) / p["grading"]
    _check_sizes(sizes, distance, p["refine_radius"], graded, p["h_contact"], p["h_far"])


def test_uniform_rectangle() -> None:
    p = dict(RECTANGLE, x0=-0.5, x1=0.5, y0=-0.5, h_contact=0.1, h_far=0.1)
    data = build(MPI.COMM_WORLD, partial(rectangle, **p), gdim=2, name="uniform")
    sizes, _ = _cell_sizes(data)
    # 2D frontal-Delaunay edges lie within about [0.7, 1.4] times the prescribed size.
    assert 0.1 / 1.5 <= sizes.min() and sizes.max() <= 1.5 * 0.1


def _crack_frame(p: dict, x: npt.NDArray[np.float64]) -> tuple[npt.NDArray, npt.NDArray]:
    """Coordinates (s along the crack, t across it) of the points ``x`` (..., 3)."""
    theta = math.radians(p["angle"])
    c, n = math.cos(theta), math.sin(theta)
    return x[..., 0] * c + x[..., 1] * n, x[..., 1] * c - x[..., 0] * n


def test_crack_plate_measures(crack_plate_mesh: tuple[dict, MeshData]) -> None:
    p, data = crack_plate_mesh
    side = 2 * p["half_width"]
    assert np.all(data.cell_tags.values == CrackPlateCells.DOMAIN)
    _check_boundary_tagged_once(data, interior=(CrackPlateFacets.CRACK,))
    # Straight-sided triangles tile the square exactly and the crack is a chain of mesh edges:
    # only round-off remains.
    assert _measure(data) == pytest.approx(side**2, rel=1e-12)
    assert _measure(data, CrackPlateFacets.CRACK, "dS") == pytest.approx(
        2 * p["crack_half_length"], rel=1e-12
    )
    sides = [CrackPlateFacets.BOTTOM, CrackPlateFacets.RIGHT, CrackPlateFacets.TOP]
    for tag in [*sides, CrackPlateFacets.LEFT]:
        assert _measure(data, tag) == pytest.approx(side, rel=1e-12), tag.name
    # The whole boundary (no crack facet in it).
    boundary = dolfinx.fem.assemble_scalar(dolfinx.fem.form(1.0 * ufl.ds(domain=data.mesh)))
    assert data.mesh.comm.allreduce(boundary, op=MPI.SUM) == pytest.approx(4 * side, rel=1e-12)
    _check_interior_facets_integrated_once(data, 4 * side)


def test_crack_plate_nodes(crack_plate_mesh: tuple[dict, MeshData]) -> None:
    p, data = crack_plate_mesh
    comm = data.mesh.comm
    a = p["crack_half_length"]
    # The crack edges lie on the crack segment, and add up to its length.
    ends = _facet_vertices(data, CrackPlateFacets.CRACK)
    s, t = _crack_frame(p, ends)
    assert np.all(np.abs(t) <= 1e-12) and np.all(np.abs(s) <= a + 1e-12)
    assert comm.allreduce(_lengths(ends).sum(), op=MPI.SUM) == pytest.approx(2 * a, rel=1e-12)
    # The tips and the split points are mesh vertices (on at least one rank).
    theta = math.radians(p["angle"])
    x = data.mesh.geometry.x
    for station in (-a, *p["split_at"], a):
        point = np.array([station * math.cos(theta), station * math.sin(theta), 0.0])
        gap = np.linalg.norm(x - point, axis=1).min(initial=np.inf)
        assert comm.allreduce(gap, op=MPI.MIN) <= 1e-12, station


def test_crack_plate_sizes(crack_plate_mesh: tuple[dict, MeshData]) -> None:
    p, data = crack_plate_mesh
    comm = data.mesh.comm
    h_crack = p["h_crack"]
    crack = _lengths(_facet_vertices(data, CrackPlateFacets.CRACK))
    assert comm.allreduce(crack.max(initial=0.0), op=MPI.MAX) <= 1.5 * h_crack
    assert comm.allreduce(crack.min(initial=np.inf), op=MPI.MIN) >= h_crack / 1.5
    sizes, midpoints = _cell_sizes(data)
    s, t = _crack_frame(p, midpoints)
    distance = np.hypot(np.maximum(np.abs(s) - p["crack_half_length"], 0.0), t)
    # h_crack up to min(a / 2, distance from the crack to the edges), then graded
    theta = math.radians(p["angle"])
    reach = p["crack_half_length"] * max(abs(math.cos(theta)), abs(math.sin(theta)))
    band = min(0.5 * p["crack_half_length"], p["half_width"] - reach)
    graded = band + (p["h_far"] - h_crack) / p["grading"]
    _check_sizes(sizes, distance, band, graded, h_crack, p["h_far"])


def test_joint_column(joint_column_mesh: MeshData) -> None:
    p, data = JOINT_COLUMN, joint_column_mesh
    width, height = p["width"], 2 * p["block_height"]
    assert np.all(data.cell_tags.values == JointColumnCells.DOMAIN)
    _check_boundary_tagged_once(data, interior=(JointColumnFacets.JOINT,))
    assert _measure(data) == pytest.approx(width * height, rel=1e-12)
    lengths = {
        JointColumnFacets.BOTTOM: width,
        JointColumnFacets.RIGHT: height,
        JointColumnFacets.TOP: width,
        JointColumnFacets.LEFT: height,
    }
    for tag, length in lengths.items():
        assert _measure(data, tag) == pytest.approx(length, rel=1e-12), tag.name
    # The joint: edges on y = H, of total length width, and the same through dS.
    ends = _facet_vertices(data, JointColumnFacets.JOINT)
    assert np.all(np.abs(ends[..., 1] - p["block_height"]) <= 1e-12)
    comm = data.mesh.comm
    assert comm.allreduce(_lengths(ends).sum(), op=MPI.SUM) == pytest.approx(width, rel=1e-12)
    assert _measure(data, JointColumnFacets.JOINT, "dS") == pytest.approx(width, rel=1e-12)
    _check_interior_facets_integrated_once(data, 2 * (width + height))
    sizes, _ = _cell_sizes(data)
    assert p["h"] / 1.5 <= sizes.min() and sizes.max() <= 1.5 * p["h"]


@pytest.mark.parametrize(
    ("builder", "gdim", "message"),
    [
        (partial(rectangle, **dict(RECTANGLE, h_contact=-1)), 2, "h_contact must be > 0, got -1"),
        (partial(rectangle, **dict(RECTANGLE, refine_x1=3.0)), 2, "refine_x1 must be <= x1"),
        (partial(rectangle, **dict(RECTANGLE, h_far=0.01)), 2, "h_contact must be <= h_far"),
        (partial(rectangle, **dict(RECTANGLE, interfaces=(0.5,))), 2, "interface must be < y1"),
        (partial(box, **dict(BOX, z1=-2.0)), 3, "z0 must be < z1"),
        (partial(box, **dict(BOX, refine_radius=0.0)), 3, "refine_radius must be > 0"),
        (
            partial(crack_plate, **dict(CRACK_PLATE, crack_half_length=1.0)),
            2,
            "crack_half_length must be < half_width",
        ),
        (
            partial(crack_plate, **dict(CRACK_PLATE, split_at=(0.1, 0.4))),
            2,
            "split_at must be < crack_half_length",
        ),
        (
            partial(crack_plate, **dict(CRACK_PLATE, split_at=(0.1, 0.1))),
            2,
            "split_at must be distinct",
        ),
        (partial(crack_plate, **dict(CRACK_PLATE, h_far=0.01)), 2, "h_crack must be <= h_far"),
        (partial(joint_column, **dict(JOINT_COLUMN, h=0.0)), 2, "h must be > 0, got 0.0"),
    ],
)
def test_invalid_parameter_raises_on_every_rank(builder: Builder, gdim: int, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        build(MPI.COMM_WORLD, builder, gdim=gdim, name="invalid")


@pytest.mark.serial_only
@pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="runs a subprocess; serial only")
def test_command_line(tmp_path) -> None:
    out = tmp_path / "block.msh"
    args = [
        "rectangle", "--x0", "-1", "--x1", "1", "--y0", "-1", "--y1", "0",
        "--refine-x0", "-0.1", "--refine-x1", "0.1", "--h-contact", "0.05", "--h-far", "0.2",
    ]  # fmt: skip
    command = [sys.executable, "-m", "contactfx.meshes", *args]
    done = subprocess.run([*command, "--out", str(out)], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert str(out) in done.stdout and "triangles" in done.stdout
    assert out.read_text().startswith("$MeshFormat\n4.1")

    bad = [*command[:-1], "-0.05", "--out", str(tmp_path / "bad.msh")]
    done = subprocess.run(bad, capture_output=True, text=True)
    assert done.returncode == 2
    assert done.stderr.strip() == (
        "python3 -m contactfx.meshes: error: h_far must be > 0, got -0.05"
    )
    assert not (tmp_path / "bad.msh").exists()


@pytest.mark.serial_only
@pytest.mark.skipif(MPI.COMM_WORLD.size > 1, reason="runs a subprocess; serial only")
@pytest.mark.parametrize(
    "args",
    [
        [
            "crack-plate", "--half-width", "1", "--crack-half-length", "0.4", "--angle", "-30",
            "--h-crack", "0.05", "--h-far", "0.2", "--split-at", "-0.1", "0.2",
        ],
        ["joint-column", "--width", "1", "--block-height", "0.5", "--h", "0.1"],
    ],
    ids=["crack-plate", "joint-column"],
)  # fmt: skip
def test_command_line_interior_facets(tmp_path, args: list[str]) -> None:
    out = tmp_path / "mesh.msh"
    command = [sys.executable, "-m", "contactfx.meshes", *args, "--out", str(out)]
    done = subprocess.run(command, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert str(out) in done.stdout and "triangles" in done.stdout
    text = out.read_text()
    assert text.startswith("$MeshFormat\n4.1")
    name = "crack" if args[0] == "crack-plate" else "joint"
    assert f'1 5 "{name}"' in text  # the interior physical group, tag 5
