"""The unfitted crack's geometry (contactfx.contact.cut): cut cells, area fractions, enriched
nodes and the crack's Gauss points, on a structured mesh where the crack passes through nodes,
along edges, at 1e-6 of a node, and in general position (docs/verification.md section 14)."""

from __future__ import annotations

import dolfinx
import numpy as np
import pytest
import ufl
from mpi4py import MPI

from contactfx import _compat
from contactfx.contact.cut import (
    SNAP,
    CoarseGrid,
    CrackQuadrature,
    CrackSegment,
    WeightedMeasure,
    cut_cells,
)

N = 16  # cells per side of the unit square, h = 1 / 16 along the edges


def _mesh():
    return dolfinx.mesh.create_unit_square(MPI.COMM_WORLD, N, N, dolfinx.mesh.CellType.triangle)


#: (name, p0, p1): horizontal cracks through the nodes (y = 8 h: along the edges of the
#: structured triangles), at 1e-6 h above them (snapped onto them), between them, and an
#: inclined one in general position
CASES = [
    ("along-edges", (0.2, 0.5), (0.8, 0.5)),
    ("1e-6-of-nodes", (0.2, 0.5 + 1e-6 / N), (0.8, 0.5 + 1e-6 / N)),
    ("between-nodes", (0.2, 0.53), (0.8, 0.53)),
    ("inclined", (0.23, 0.31), (0.71, 0.77)),
    ("through-nodes-diagonal", (0.25, 0.25), (0.75, 0.75)),
]


@pytest.mark.parametrize("name, p0, p1", CASES, ids=[c[0] for c in CASES])
def test_cut_geometry_and_crack_quadrature(name, p0, p1):
    mesh = _mesh()
    crack = CrackSegment(np.array(p0), np.array(p1))
    X = _compat.cell_coordinates(mesh)
    h = 1.0 / N
    cells = cut_cells(X, crack, SNAP * h)
    n_owned = mesh.topology.index_map(2).size_local
    owned = np.zeros(len(X), dtype=bool)
    owned[:n_owned] = True
    # the pieces of the cut cells, away from the tip cells, tile the crack: their summed length
    # is the crack's length less the stretch in the tip cells, less than two cells' diameters
    length = np.linalg.norm(cells.pieces[:, 1] - cells.pieces[:, 0], axis=1)
    total = MPI.COMM_WORLD.allreduce(float(length[cells.cut & owned].sum()), op=MPI.SUM)
    crack_length = 2.0 * crack.half_length
    assert crack_length - 2.0 * np.sqrt(2.0) * h - 1e-12 <= total <= crack_length + 1e-12
    # every piece lies on the crack (phi = 0 within the snapping distance) and inside it
    ends = cells.pieces[cells.cut].reshape(-1, 2)
    assert np.all(np.abs(crack.phi(ends)) <= SNAP * h + 1e-12)
    assert np.all(np.abs(crack.psi(ends)) <= crack.half_length + 1e-12)
    # the +side's area fractions are exact for the piecewise linear level set: the area above
    # the crack's line in the cut cells, computed independently by sampling each cell
    rng = np.random.default_rng(0)
    for c in np.flatnonzero(cells.cut)[:20]:
        lam = rng.dirichlet(np.ones(3), size=20000)
        pts = lam @ X[c]
        phi_h = lam @ cells.phi[c]
        # Monte Carlo with 20000 samples: standard error below 0.5 / sqrt(20000) = 0.0035
        assert cells.fraction[c] == pytest.approx(np.mean(phi_h > 0.0), abs=0.015), (c, pts[0])
    # the crack's Gauss points through the cell rule: the integral of 1 over the crack is the
    # pieces' length, and of psi^2 (a polynomial of degree 2 along each piece, integrated
    # exactly by the 6-point Gauss rule) is the exact integral over the pieces
    rule = _compat.quadrature_rule(mesh, 4)
    quad = CrackQuadrature(X, cells, rule)
    Qs = _compat.quadrature_space(mesh, 4)
    qd = _compat.cell_dofs(Qs)
    Y = [dolfinx.fem.Function(Qs) for _ in range(2)]
    for i in range(2):
        Y[i].x.array[qd] = quad.points[:, :, i]
    weight = dolfinx.fem.Function(Qs)
    weight.x.array[qd] = quad.ratio
    cut = np.flatnonzero(cells.cut).astype(np.int32)
    tags = dolfinx.mesh.meshtags(mesh, 2, cut, np.ones(len(cut), dtype=np.int32))
    dx = ufl.Measure("dx", domain=mesh, subdomain_data=tags)
    ds = WeightedMeasure(
        dx(1, metadata={"quadrature_degree": 4, "quadrature_rule": "default"}), weight
    )
    d, c0 = crack.direction, crack.centre
    psi = (Y[0] - c0[0]) * d[0] + (Y[1] - c0[1]) * d[1]

    def integral(expr):
        form = dolfinx.fem.form(expr * ds)
        return MPI.COMM_WORLD.allreduce(dolfinx.fem.assemble_scalar(form), op=MPI.SUM)

    assert integral(1.0) == pytest.approx(total, rel=1e-12)
    s0, s1 = (
        crack.psi(cells.pieces[cells.cut & owned, 0]),
        crack.psi(cells.pieces[cells.cut & owned, 1]),
    )
    exact = MPI.COMM_WORLD.allreduce(float(np.sum(np.abs(s1**3 - s0**3)) / 3.0), op=MPI.SUM)
    assert integral(psi**2) == pytest.approx(exact, rel=1e-12)


def test_crack_along_edges_belongs_to_one_side():
    """A crack along mesh edges: each edge's piece is integrated once, by the +side's cell;
    the -side's cell has fraction 0, the +side's 1."""
    mesh = _mesh()
    crack = CrackSegment(np.array([0.2, 0.5]), np.array([0.8, 0.5]))
    X = _compat.cell_coordinates(mesh)
    cells = cut_cells(X, crack, SNAP / N)
    assert np.all(cells.fraction[cells.cut] == 1.0)
    centres = X.mean(axis=1)
    below = (np.abs(centres[:, 1] - 0.5) < 0.5 / N) & (centres[:, 1] < 0.5)
    assert not np.any(cells.cut & below)


def test_segment_of_zero_length_is_refused():
    with pytest.raises(ValueError, match="zero length"):
        CrackSegment(np.array([0.5, 0.5]), np.array([0.5, 0.5]))


def test_coarse_grid_nodes_and_projection():
    """al-uzawa's multiplier grid along a crack (CoarseGrid): crossings at psi with the cell
    sizes there, graded like a mesh towards one end, given twice and shuffled (as gathered
    from the ranks)."""
    rng = np.random.default_rng(7)
    psi = np.concatenate([[-1.0], -1.0 + np.cumsum(np.geomspace(1e-3, 0.2, 25)), [1.0]])
    psi = psi[psi <= 1.0]
    size = np.full(len(psi), 0.05)
    size[:8] = 2e-3  # small cells at the psi = -1 end
    both = np.concatenate([psi, psi])
    order = rng.permutation(len(both))
    grid = CoarseGrid(both[order], np.concatenate([size, size])[order], 2.0)
    assert np.array_equal(grid.nodes, CoarseGrid(psi, size, 2.0).nodes)  # order-free
    nodes = grid.nodes
    assert nodes[0] == -1.0 and nodes[-1] == 1.0
    assert np.all(np.isin(nodes, psi))  # every node a crossing
    # each node but the last at least twice the size of its cell beyond the one before
    kept = np.searchsorted(psi, nodes[1:-1])
    assert np.all(np.diff(nodes)[:-1] >= 2.0 * size[kept] - 1e-15)
    assert len(nodes) < len(psi)  # the short pieces are merged
    # the lumped L2 projection keeps constants, the grid's field interpolates its nodes
    x = np.linspace(-1.0, 1.0, 401)
    w = np.full(len(x), 2.0 / 400)
    num, den = grid.moments(x, w, np.column_stack([np.full(len(x), 3.0), -np.ones(len(x))]))
    assert np.allclose(num / den[:, None], [3.0, -1.0], rtol=0, atol=1e-13)
    field = rng.normal(size=(len(nodes), 1))
    assert np.allclose(grid.evaluate(nodes, field), field, rtol=0, atol=1e-14)
    mid = 0.5 * (nodes[:-1] + nodes[1:])
    assert np.allclose(grid.evaluate(mid, field)[:, 0], 0.5 * (field[:-1, 0] + field[1:, 0]))
