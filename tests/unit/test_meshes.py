"""Unit tests of :mod:`contactfx.meshes`: exact measures, graded sizes, validation, command line.

Run at 1 and 2 ranks::

    python3 -m pytest tests/unit/test_meshes.py
    mpirun -n 2 python3 -m mpi4py -m pytest tests/unit/test_meshes.py
"""

from __future__ import annotations

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
    MeshData,
    RectangleCells,
    RectangleFacets,
    box,
    build,
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


@pytest.fixture(scope="module")
def rectangle_mesh() -> MeshData:
    return build(MPI.COMM_WORLD, partial(rectangle, **RECTANGLE), gdim=2, name="rectangle")


@pytest.fixture(scope="module")
def box_mesh() -> MeshData:
    return build(MPI.COMM_WORLD, partial(box, **BOX), gdim=3, name="box")


def _measure(data: MeshData, tag: int | None = None) -> float:
    """Global measure of the mesh (``tag`` None) or of the facets tagged ``tag``."""
    mesh = data.mesh
    if tag is None:
        measure = ufl.dx(domain=mesh)
    else:
        measure = ufl.ds(domain=mesh, subdomain_data=data.facet_tags, subdomain_id=tag)
    local = dolfinx.fem.assemble_scalar(dolfinx.fem.form(1.0 * measure))
    return mesh.comm.allreduce(local, op=MPI.SUM)


def _check_boundary_tagged_once(data: MeshData) -> None:
    """Every boundary facet carries exactly one tag, and only boundary facets are tagged.

    Compared on the facets each rank owns: ghost facets differ between the two lists.
    """
    topology = data.mesh.topology
    num_owned = topology.index_map(topology.dim - 1).size_local
    indices = data.facet_tags.indices
    assert np.unique(indices).size == indices.size
    exterior = dolfinx.mesh.exterior_facet_indices(topology)
    owned_tagged = np.sort(indices[indices < num_owned])
    assert np.array_equal(owned_tagged, np.sort(exterior[exterior < num_owned]))


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


@pytest.mark.parametrize(
    ("builder", "gdim", "message"),
    [
        (partial(rectangle, **dict(RECTANGLE, h_contact=-1)), 2, "h_contact must be > 0, got -1"),
        (partial(rectangle, **dict(RECTANGLE, refine_x1=3.0)), 2, "refine_x1 must be <= x1"),
        (partial(rectangle, **dict(RECTANGLE, h_far=0.01)), 2, "h_contact must be <= h_far"),
        (partial(rectangle, **dict(RECTANGLE, interfaces=(0.5,))), 2, "interface must be < y1"),
        (partial(box, **dict(BOX, z1=-2.0)), 3, "z0 must be < z1"),
        (partial(box, **dict(BOX, refine_radius=0.0)), 3, "refine_radius must be > 0"),
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
