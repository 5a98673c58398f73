"""The ParaView writer (contactfx.io.vtk) on a unit square, serial and under MPI: one VTU per
step with every field, values at the right points, the surface dataset, and the split of the
nodes along an interface (each side's cells carry u + H a)."""

from pathlib import Path

import dolfinx
import numpy as np
import pytest
from mpi4py import MPI

from contactfx import _compat
from contactfx.io.vtk import ResultsWriter, Split, read_pvd, read_vtu

N = 4  # cells per side; the interface y = 1/2 is a row of facets


def _function(space, name, f):
    u = dolfinx.fem.Function(space, name=name)
    u.interpolate(f)
    return u


def test_writer_every_field_surface_and_split(tmp_path):
    comm = MPI.COMM_WORLD
    out = Path(comm.bcast(str(tmp_path), root=0))
    mesh = dolfinx.mesh.create_unit_square(comm, N, N)
    fdim = mesh.topology.dim - 1
    mesh.topology.create_connectivity(fdim, mesh.topology.dim)
    bottom = dolfinx.mesh.locate_entities_boundary(mesh, fdim, lambda x: np.isclose(x[1], 0.0))
    middle = dolfinx.mesh.locate_entities(mesh, fdim, lambda x: np.isclose(x[1], 0.5))
    Q1 = _compat.function_space(mesh, "Lagrange", 1)
    V1 = _compat.function_space(mesh, "Lagrange", 1, (2,))
    V2 = _compat.function_space(mesh, "Lagrange", 2, (2,))
    DG0 = _compat.function_space(mesh, "DG", 0)
    scalar = _function(Q1, "pressure", lambda x: 1.0 + x[0] + 2.0 * x[1])
    u = _function(V1, "displacement", lambda x: np.vstack([x[0], x[1]]))
    a = _function(V1, "enrichment", lambda x: np.vstack([0 * x[0], np.isclose(x[1], 0.5) * 1.0]))
    quadratic = _function(V2, "quadratic", lambda x: np.vstack([x[0] ** 2, x[1]]))
    side = _function(DG0, "side", lambda x: np.where(x[1] > 0.5, 1.0, -1.0))
    cellwise = _function(DG0, "stress", lambda x: 3.0 + 0 * x[0])

    split = Split(side, middle)
    stale = out / "square_0009.vtu"  # a previous run's step: removed
    if comm.rank == 0:
        stale.write_text("")
    comm.barrier()
    with ResultsWriter(out, "square", mesh, facets=bottom, split=split) as writer:
        for t in (0.5, 1.0):
            writer.write(t, [u, a, scalar, quadratic, cellwise])
    comm.barrier()
    if comm.rank != 0:
        return
    assert not stale.exists()
    steps = read_pvd(out / "square.pvd")
    assert [t for t, _ in steps] == [0.5, 1.0]
    grid = read_vtu(steps[-1][1])
    x, pd = grid["points"], grid["point_data"]
    # (N + 1)^2 vertices and the N + 1 of the interface once more; every field on the grid
    assert len(x) == (N + 1) ** 2 + N + 1 and grid["cells"].shape == (2 * N * N, 3)
    assert set(pd) == {"displacement", "enrichment", "pressure", "quadratic"}
    assert grid["cell_data"]["stress"] == pytest.approx(np.full(2 * N * N, 3.0))
    assert pd["pressure"] == pytest.approx(1.0 + x[:, 0] + 2.0 * x[:, 1])
    assert pd["quadratic"][:, :2] == pytest.approx(np.column_stack([x[:, 0] ** 2, x[:, 1]]))
    # each cell's nodes: y +- 1 on the interface (the side of the cell), y elsewhere
    on = np.isclose(x[:, 1], 0.5)
    y = pd["displacement"][:, 1]
    assert y[~on] == pytest.approx(x[~on, 1])
    assert sorted(y[on]) == pytest.approx(sorted([-0.5] * (N + 1) + [1.5] * (N + 1)))
    for cell in grid["cells"]:
        above = x[cell, 1].mean() > 0.5
        for k in cell[on[cell]]:
            assert y[k] == pytest.approx(1.5 if above else -0.5)
    assert pd["displacement"].shape[1] == 3 and not pd["displacement"][:, 2].any()

    surface = read_vtu(read_pvd(out / "square_surface.pvd")[-1][1])
    assert surface["cells"].shape == (N, 2) and len(surface["points"]) == N + 1
    assert surface["points"][:, 1] == pytest.approx(0.0)
    assert surface["point_data"]["pressure"] == pytest.approx(1.0 + surface["points"][:, 0])
    assert surface["cell_data"]["stress"] == pytest.approx(np.full(N, 3.0))
