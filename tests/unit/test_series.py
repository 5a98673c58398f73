"""The ParaView writers on a unit square, serial and under MPI. XDMF (contactfx.io.xdmf): one
grid per step with every field at the right points, the surface dataset, the split of the
nodes along an interface (each side's cells carry u + H a), and the same values written by
one rank and by every rank (to the last bit, after sorting the nodes and cells by their
coordinates). VTU (contactfx.io.vtk, --format vtu): the same fields, split and surface."""

from pathlib import Path

import dolfinx
import numpy as np
import pytest
from mpi4py import MPI

from contactfx import _compat
from contactfx.io.series import Split
from contactfx.io.vtk import ResultsWriter, read_pvd, read_vtu
from contactfx.io.xdmf import XdmfWriter, read_xdmf

N = 4  # cells per side; the interface y = 1/2 is a row of facets


def _function(space, name, f):
    """f interpolated at the points snapped to multiples of 1 / (12 N): the vertices, edge
    midpoints and centroids exactly, so that the values do not depend on the round-off of
    the interpolation points (which differs between partitions)."""
    u = dolfinx.fem.Function(space, name=name)
    u.interpolate(lambda x: f(np.round(x * 12 * N) / (12 * N)))
    return u


def _write(comm, out: Path, times=(0.5, 1.0), writer=XdmfWriter) -> None:
    """The square's fields at ``times`` (the same functions of x at every step) with
    ``writer`` (the XDMF or the VTU writer)."""
    mesh = dolfinx.mesh.create_unit_square(comm, N, N)
    fdim = mesh.topology.dim - 1
    mesh.topology.create_connectivity(fdim, mesh.topology.dim)
    bottom = dolfinx.mesh.locate_entities_boundary(mesh, fdim, lambda x: np.isclose(x[1], 0.0))
    middle = dolfinx.mesh.locate_entities(mesh, fdim, lambda x: np.isclose(x[1], 0.5))
    Q1 = _compat.function_space(mesh, "Lagrange", 1)
    V1 = _compat.function_space(mesh, "Lagrange", 1, (2,))
    V2 = _compat.function_space(mesh, "Lagrange", 2, (2,))
    DG0 = _compat.function_space(mesh, "DG", 0)
    T0 = _compat.function_space(mesh, "DG", 0, (9,))
    scalar = _function(Q1, "pressure", lambda x: 1.0 + x[0] + 2.0 * x[1])
    u = _function(V1, "displacement", lambda x: np.vstack([x[0] / 3, x[1]]))
    a = _function(V1, "enrichment", lambda x: np.vstack([0 * x[0], np.isclose(x[1], 0.5) * 1.0]))
    quadratic = _function(V2, "quadratic", lambda x: np.vstack([x[0] ** 2, x[1]]))
    side = _function(DG0, "side", lambda x: np.where(x[1] > 0.5, 1.0, -1.0))
    cellwise = _function(DG0, "stress", lambda x: 3.0 + x[0] / 7)
    tensor = _function(T0, "cauchy_stress", lambda x: np.vstack([x[0] + k for k in range(9)]))
    with writer(out, "square", mesh, facets=bottom, split=Split(side, middle)) as w:
        for t in times:
            w.write(t, [u, a, scalar, quadratic, cellwise, tensor])


def _sorted(grid: dict) -> dict:
    """The grid's nodes sorted by (coordinates, displacement: the two faces of the
    interface), its cells by their centroids: independent of the partition."""
    x, pd = grid["points"], grid["point_data"]
    order = np.lexsort((pd["displacement"][:, 1], x[:, 1], x[:, 0]))
    cells = grid["cells"]
    centroid = x[cells].mean(axis=1)
    corder = np.lexsort((centroid[:, 1], centroid[:, 0]))
    return {
        "points": x[order],
        "point_data": {k: v[order] for k, v in pd.items()},
        "cell_data": {k: v[corder] for k, v in grid["cell_data"].items()},
    }


def test_xdmf_every_field_surface_and_split(tmp_path):
    comm = MPI.COMM_WORLD
    out = Path(comm.bcast(str(tmp_path), root=0))
    stale = out / "square.xdmf"  # a previous run's series: replaced, not appended to
    if comm.rank == 0:
        out.mkdir(parents=True, exist_ok=True)
        stale.write_text("<Xdmf/>")
    comm.barrier()
    _write(comm, out)
    comm.barrier()
    if comm.rank != 0:
        return
    grid = read_xdmf(out / "square.xdmf")
    assert grid["times"] == [0.5, 1.0] and grid["type"] == "Triangle"
    x, pd = grid["points"], grid["point_data"]
    # (N + 1)^2 vertices and the N + 1 of the interface once more; every field on the grid
    assert len(x) == (N + 1) ** 2 + N + 1 and grid["cells"].shape == (2 * N * N, 3)
    assert set(pd) == {"displacement", "enrichment", "pressure", "quadratic"}
    assert set(grid["cell_data"]) == {"stress", "cauchy_stress"}
    centroid = x[grid["cells"]].mean(axis=1)
    # DG0 interpolation evaluates at the cell's midpoint (its centroid on triangles)
    assert grid["cell_data"]["stress"] == pytest.approx(3.0 + centroid[:, 0] / 7, abs=1e-14)
    assert grid["cell_data"]["cauchy_stress"].shape == (2 * N * N, 9)
    assert pd["pressure"] == pytest.approx(1.0 + x[:, 0] + 2.0 * x[:, 1], abs=1e-14)
    assert pd["quadratic"][:, :2] == pytest.approx(np.column_stack([x[:, 0] ** 2, x[:, 1]]))
    # each cell's nodes: y +- 1 on the interface (the side of the cell), y elsewhere
    on = np.isclose(x[:, 1], 0.5)
    y = pd["displacement"][:, 1]
    assert y[~on] == pytest.approx(x[~on, 1], abs=1e-14)
    assert sorted(y[on]) == pytest.approx(sorted([-0.5] * (N + 1) + [1.5] * (N + 1)))
    for cell in grid["cells"]:
        above = x[cell, 1].mean() > 0.5
        for k in cell[on[cell]]:
            assert y[k] == pytest.approx(1.5 if above else -0.5)
    assert pd["displacement"].shape[1] == 3 and not pd["displacement"][:, 2].any()
    assert pd["displacement"][:, 0] == pytest.approx(x[:, 0] / 3, abs=1e-14)

    surface = read_xdmf(out / "square_surface.xdmf")
    assert surface["type"] == "Polyline" and surface["times"] == [0.5, 1.0]
    assert surface["cells"].shape == (N, 2) and len(surface["points"]) == N + 1
    assert surface["points"][:, 1] == pytest.approx(0.0)
    sx = surface["points"][:, 0]
    assert surface["point_data"]["pressure"] == pytest.approx(1.0 + sx, abs=1e-14)
    assert surface["cell_data"]["stress"] == pytest.approx(
        3.0 + surface["points"][surface["cells"]].mean(axis=1)[:, 0] / 7 + 0 * N, abs=0.2 / N
    )  # a facet's cell's centroid: within a cell of the facet's midpoint

    # the first step is still there, readable, with the same mesh
    first = read_xdmf(out / "square.xdmf", step=0)
    assert first["time"] == 0.5 and np.array_equal(first["points"], x)


def test_xdmf_one_rank_and_every_rank_write_the_same_bits(tmp_path):
    """Rank 0 writes the square alone (COMM_SELF) beside the run on every rank (partitioned
    in the MPI session): after sorting, the same coordinates, node values and cell values,
    bit for bit."""
    comm = MPI.COMM_WORLD
    out = Path(comm.bcast(str(tmp_path), root=0))
    _write(comm, out / "parallel", times=(1.0,))
    if comm.rank == 0:
        _write(MPI.COMM_SELF, out / "serial", times=(1.0,))
    comm.barrier()
    if comm.rank != 0:
        return
    for name in ("square.xdmf", "square_surface.xdmf"):
        one = _sorted(read_xdmf(out / "serial" / name))
        every = _sorted(read_xdmf(out / "parallel" / name))
        assert np.array_equal(one["points"], every["points"])
        for key in ("point_data", "cell_data"):
            assert one[key].keys() == every[key].keys()
            for k in one[key]:
                assert np.array_equal(one[key][k], every[key][k]), (name, k)


def test_vtu_every_field_surface_and_split(tmp_path):
    """The same square through the VTU writer (--format vtu): one VTU per step, gathered on
    rank 0, with the same fields, split and surface."""
    comm = MPI.COMM_WORLD
    out = Path(comm.bcast(str(tmp_path), root=0))
    stale = out / "square_0009.vtu"  # a previous run's step: removed
    if comm.rank == 0:
        out.mkdir(parents=True, exist_ok=True)
        stale.write_text("")
    comm.barrier()
    _write(comm, out, writer=ResultsWriter)
    comm.barrier()
    if comm.rank != 0:
        return
    assert not stale.exists()
    steps = read_pvd(out / "square.pvd")
    assert [t for t, _ in steps] == [0.5, 1.0]
    grid = read_vtu(steps[-1][1])
    x, pd = grid["points"], grid["point_data"]
    assert len(x) == (N + 1) ** 2 + N + 1 and grid["cells"].shape == (2 * N * N, 3)
    assert set(pd) == {"displacement", "enrichment", "pressure", "quadratic"}
    centroid = x[grid["cells"]].mean(axis=1)
    assert grid["cell_data"]["stress"] == pytest.approx(3.0 + centroid[:, 0] / 7, abs=1e-14)
    assert pd["pressure"] == pytest.approx(1.0 + x[:, 0] + 2.0 * x[:, 1])
    assert pd["quadratic"][:, :2] == pytest.approx(np.column_stack([x[:, 0] ** 2, x[:, 1]]))
    on = np.isclose(x[:, 1], 0.5)
    y = pd["displacement"][:, 1]
    assert y[~on] == pytest.approx(x[~on, 1])
    for cell in grid["cells"]:
        above = x[cell, 1].mean() > 0.5
        for k in cell[on[cell]]:
            assert y[k] == pytest.approx(1.5 if above else -0.5)
    assert pd["displacement"].shape[1] == 3 and not pd["displacement"][:, 2].any()
    surface = read_vtu(read_pvd(out / "square_surface.pvd")[-1][1])
    assert surface["cells"].shape == (N, 2) and len(surface["points"]) == N + 1
    assert surface["points"][:, 1] == pytest.approx(0.0)
    assert surface["point_data"]["pressure"] == pytest.approx(1.0 + surface["points"][:, 0])
