"""Unit tests of the mortar integrals and of the search (docs/verification.md section 10):
the partition of unity of D and M that the patch test needs, and known projections."""

from __future__ import annotations

import numpy as np
import pytest

from contactfx.contact.boxes import FacetTree
from contactfx.contact.mortar import mortar_matrices
from contactfx.contact.pair import Facets, facet_normals


def _line(xs, y, nodes0, reverse=False):
    """Segments along y = const through the points xs, left to right (reverse: right to
    left)."""
    a, b = np.asarray(xs[:-1]), np.asarray(xs[1:])
    x = np.stack([np.c_[a, np.full_like(a, y)], np.c_[b, np.full_like(b, y)]], axis=1)
    nodes = np.stack([np.arange(len(a)), np.arange(1, len(a) + 1)], axis=1) + nodes0
    if reverse:
        x, nodes = x[:, ::-1], nodes[:, ::-1]
    return Facets(x, nodes)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_mortar_partition_of_unity(seed):
    rng = np.random.default_rng(seed)
    xs = np.r_[0.0, np.sort(rng.uniform(0, 1, 6)), 1.0]
    xm = np.r_[-0.1, np.sort(rng.uniform(0, 1, 9)), 1.1]
    # slave: the upper body's bottom, left to right: normal (t_y, -t_x) = (0, -1), outward;
    # master: the lower body's top, right to left: normal (0, 1)
    slave = _line(xs, 0.0, 0)
    master = _line(xm, 0.0, 100, reverse=True)
    assert np.allclose(facet_normals(slave.x), [0.0, -1.0])
    assert np.allclose(facet_normals(master.x), [0.0, 1.0])
    pairs = FacetTree(master.x, 0.1).collide(FacetTree(slave.x, 0.0))
    D, normals, (rows, cols, vals), _ = mortar_matrices(slave, master, pairs)
    n_nodes = len(xs)
    D_node = np.zeros(n_nodes)
    np.add.at(D_node, slave.nodes.ravel(), D.ravel())
    M_sum = np.zeros(n_nodes)
    np.add.at(M_sum, rows, vals)
    # exact (2-point Gauss of quadratics): sum_k M_jk = int psi_j = int N_j = D_j, to round-off
    assert np.allclose(M_sum, D_node, rtol=0, atol=1e-14)
    # D_j = half the adjacent segment lengths; the total is the slave length
    assert D_node.sum() == pytest.approx(1.0, abs=1e-14)
    # the master column sums are int N_k over the covered part: their total is the overlap 1
    assert vals.sum() == pytest.approx(1.0, abs=1e-14)
    # the length-weighted normals add up to the slave length times its normal
    assert np.allclose(normals.sum(axis=(0, 1)), [0.0, -1.0], atol=1e-14)


def test_mortar_off_master_is_uncovered():
    # the slave runs from 0 to 2, the master only from 0 to 1: the slave node at x = 2 has
    # no master (M row sum 0), the one at x = 1 half of its support covered
    slave = Facets(
        np.array([[[1.0, 0.0], [0.0, 0.0]], [[2.0, 0.0], [1.0, 0.0]]]), np.array([[1, 0], [2, 1]])
    )
    master = Facets(np.array([[[0.0, 0.0], [1.0, 0.0]]]), np.array([[10, 11]]))
    pairs = FacetTree(master.x, 0.5).collide(FacetTree(slave.x, 0.0))
    D, _, (rows, cols, vals), _ = mortar_matrices(slave, master, pairs)
    M_sum = np.zeros(3)
    np.add.at(M_sum, rows, vals)
    assert M_sum == pytest.approx([0.5, 0.5, 0.0], abs=1e-14)


def test_facet_tree_candidates():
    segments = np.array(
        [[[0.0, 0.0], [1.0, 0.0]], [[1.0, 0.0], [2.0, 0.0]], [[5.0, 0.0], [6.0, 0.0]]]
    )
    tree = FacetTree(segments, 0.1)
    points = np.array([[0.5, 0.05], [1.0, 0.0], [3.0, 0.0]])
    rows, facets = tree.collide_points(points)
    hits = {(int(r), int(f)) for r, f in zip(rows, facets, strict=True)}
    # padded boxes (0.1): the first point meets facet 0 only, the shared vertex both, the
    # point at x = 3 none (farther than the padding from every facet)
    assert hits == {(0, 0), (1, 0), (1, 1)}


def _square(n: int, z: float, nodes0: int, rng, upward: bool) -> Facets:
    """A triangulation of the unit square at height z: an n x n grid, interior nodes moved
    by up to 0.3 of a cell, each cell cut along a random diagonal; normals +z (``upward``) or
    -z."""
    s = np.linspace(0.0, 1.0, n + 1)
    X, Y = np.meshgrid(s, s, indexing="ij")
    inner = (X > 0) & (X < 1) & (Y > 0) & (Y < 1)
    X = X + np.where(inner, rng.uniform(-0.3, 0.3, X.shape) / n, 0.0)
    Y = Y + np.where(inner, rng.uniform(-0.3, 0.3, Y.shape) / n, 0.0)
    pts = np.stack([X.ravel(), Y.ravel(), np.full(X.size, z)], axis=1)
    tris = []
    for a in range(n):
        for b in range(n):
            v00, v10, v01, v11 = (
                a * (n + 1) + b,
                (a + 1) * (n + 1) + b,
                a * (n + 1) + b + 1,
                (a + 1) * (n + 1) + b + 1,
            )
            if rng.random() < 0.5:
                tris += [(v00, v10, v11), (v00, v11, v01)]
            else:
                tris += [(v00, v10, v01), (v10, v11, v01)]
    tris = np.array(tris)  # counter-clockwise seen from +z
    if not upward:
        tris = tris[:, [0, 2, 1]]
    return Facets(pts[tris], tris + nodes0)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_mortar_partition_of_unity_3d(seed):
    rng = np.random.default_rng(seed)
    # slave: the upper body's bottom (normal -z), master: the lower body's top (normal +z),
    # non-matching random triangulations of the same square
    slave = _square(5, 0.0, 0, rng, upward=False)
    master = _square(7, 0.0, 1000, rng, upward=True)
    assert np.allclose(facet_normals(slave.x), [0.0, 0.0, -1.0])
    assert np.allclose(facet_normals(master.x), [0.0, 0.0, 1.0])
    pairs = FacetTree(master.x, 0.3).collide(FacetTree(slave.x, 0.0))
    D, normals, (rows, cols, vals), _ = mortar_matrices(slave, master, pairs)
    n_nodes = 36
    D_node = np.zeros(n_nodes)
    np.add.at(D_node, slave.nodes.ravel(), D.ravel())
    M_sum = np.zeros(n_nodes)
    np.add.at(M_sum, rows, vals)
    # exact integration (the degree-2 rule on the fan triangles, where psi_j N_k is quadratic)
    # and full coverage: sum_k M_jk = int psi_j = int N_j = D_j; the values are O(1 / 25)
    # sums of O(100) terms, so round-off is ~1e-16
    assert np.allclose(M_sum, D_node, rtol=0, atol=1e-14)
    # D_j = a third of the adjacent areas; the total is the slave area 1
    assert D_node.sum() == pytest.approx(1.0, abs=1e-14)
    # the master column sums are int N_k over the overlap: their total is the covered area 1
    assert vals.sum() == pytest.approx(1.0, abs=1e-13)
    # a linear field is transmitted: sum_k M_jk x_k = D_j x_j (the patch test's premise)
    xm = np.zeros((2000, 3))
    xm[master.nodes.ravel()] = master.x.reshape(-1, 3)
    xs = np.zeros((n_nodes, 3))
    xs[slave.nodes.ravel()] = slave.x.reshape(-1, 3)
    Mx = np.zeros((n_nodes, 3))
    np.add.at(Mx, rows, vals[:, None] * xm[cols])
    assert np.allclose(Mx, D_node[:, None] * xs, rtol=0, atol=1e-14)
    # the area-weighted normals add up to the slave area times its normal
    assert np.allclose(normals.sum(axis=(0, 1)), [0.0, 0.0, -1.0], atol=1e-14)


def test_dual_basis_biorthogonal_on_a_triangle():
    from contactfx.contact.mortar import dual_triangle
    from contactfx.contact.projection import gauss_triangle

    # int_T psi_i N_k = delta_ik |T| / 3, by the degree-2 rule (exact for the quadratic
    # integrand) on the unit triangle (|T| = 1/2)
    points, weights = gauss_triangle(2)
    integral = 0.5 * np.einsum("q,qi,qk->ik", weights, dual_triangle(points), points)
    assert np.allclose(integral, np.eye(3) / 6.0, rtol=0, atol=1e-15)


def test_triangle_overlaps_match_the_scalar_clip():
    from contactfx.contact.projection import triangle_overlap, triangle_overlaps

    rng = np.random.default_rng(3)
    n = 200
    slave = rng.uniform(0, 1, (n, 3, 3)) * [1.0, 1.0, 0.05]
    master = slave[:, ::-1] + rng.uniform(-0.4, 0.4, (n, 3, 3)) * [1.0, 1.0, 0.05]
    ov = triangle_overlaps(slave, master)
    row = np.cumsum(ov.valid) - 1  # the row of a valid pair in the compact arrays
    for a in range(n):
        one = triangle_overlap(slave[a], master[a])
        assert (one is not None) == ov.valid[a]
        if one is None:
            continue
        # the same polygon (area) and the same integrals: the moments int l_s l_m^T of the
        # slave and master barycentric coordinates over the fan (both maps affine, the
        # degree-2 rule exact), to round-off of O(1) quantities
        b = row[a]
        assert ov.area[b] == pytest.approx(one.area, rel=1e-12)
        assert np.allclose(
            _moments(ov.fan_area[b], ov.slave_bary[b], ov.master_bary[b]),
            _moments(_areas(one.triangles), one.slave_bary, one.master_bary),
            rtol=0,
            atol=1e-14,
        )


def _areas(tri):
    return 0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)


def _moments(area, sb, mb):
    from contactfx.contact.projection import gauss_triangle

    points, weights = gauss_triangle(2)
    ls = np.einsum("qv,fvc->fqc", points, sb)
    lm = np.einsum("qv,fvc->fqc", points, mb)
    return np.einsum("f,q,fqj,fqk->jk", area, weights, ls, lm)


def test_mortar_search_across_ranks_matches_serial():
    """The facets of both surfaces dealt to the ranks by two different cuts (slave facet i on
    rank floor(p x), master on rank floor(p ((x + 1 / 2p) mod 1)), x the facet's midpoint): at
    p >= 2 slave facets face master facets of the same and of other ranks. The search gathers
    the master facets near each rank's slave facets (``gather_near``, one alltoall), and the
    mortar triplets of all ranks together equal those of one rank holding every facet."""
    from mpi4py import MPI

    from contactfx.contact.pair import gather_near

    comm = MPI.COMM_WORLD
    p = comm.size
    rng = np.random.default_rng(3)
    xs = np.r_[0.0, np.sort(rng.uniform(0, 1, 16)), 1.0]
    xm = np.r_[-0.1, np.sort(rng.uniform(0, 1, 23)), 1.1]
    slave = _line(xs, 0.0, 0)
    master = _line(xm, 0.0, 100, reverse=True)

    def rank_of(f: Facets, shift: float) -> np.ndarray:
        mid = np.clip(f.x.mean(axis=1)[:, 0], 0.0, 1.0 - 1e-12)
        return np.floor(p * ((mid + shift) % 1.0)).astype(int)

    s_rank, m_rank = rank_of(slave, 0.0), rank_of(master, 0.5 / p)
    mine_s = Facets(slave.x[s_rank == comm.rank], slave.nodes[s_rank == comm.rank])
    mine_m = Facets(master.x[m_rank == comm.rank], master.nodes[m_rank == comm.rank])
    radius = max(np.ptp(slave.x[:, :, 0], axis=1).max(), np.ptp(master.x[:, :, 0], axis=1).max())
    near = gather_near(comm, mine_m, mine_s, radius)
    pairs = FacetTree(near.x, radius).collide(FacetTree(mine_s.x, 0.0))
    _, _, triplets, _ = mortar_matrices(mine_s, near, pairs)

    def dense(rows, cols, vals) -> np.ndarray:
        M = np.zeros((len(xs), len(xm)))
        np.add.at(M, (rows, cols - 100), vals)
        return M

    parallel = comm.allreduce(dense(*triplets), op=MPI.SUM)
    pairs_all = FacetTree(master.x, radius).collide(FacetTree(slave.x, 0.0))
    serial = dense(*mortar_matrices(slave, master, pairs_all)[2])
    # the same Gauss points summed in another order: equal to round-off
    assert np.allclose(parallel, serial, rtol=0.0, atol=1e-15)
    # and a non-trivial coupling: every slave node has its partition of unity
    assert np.all(serial.sum(axis=1) > 0.0)
    # at 2 ranks and more the overlapping (slave, master) facet pairs are both on one rank
    # and across ranks (by the cuts' construction; counted from the x-intervals)
    lo = np.maximum(slave.x[:, :, 0].min(axis=1)[:, None], master.x[:, :, 0].min(axis=1)[None])
    hi = np.minimum(slave.x[:, :, 0].max(axis=1)[:, None], master.x[:, :, 0].max(axis=1)[None])
    overlap = hi > lo
    across = overlap & (s_rank[:, None] != m_rank[None, :])
    if p > 1:
        assert np.any(across) and np.any(overlap & ~across)


def _pyramid(n: int) -> Facets:
    """A triangulation of the unit square (n x n grid, n even, each cell cut along its
    diagonal) lifted to z = 0.5 - |x - 0.5| - 0.3 |y - 0.5|, normals up: a convex roof, flat
    on each triangle, with ridges along x = 0.5 and y = 0.5 and its apex at the centre."""
    s = np.linspace(0.0, 1.0, n + 1)
    X, Y = (a.ravel() for a in np.meshgrid(s, s, indexing="ij"))
    pts = np.stack([X, Y, 0.5 - np.abs(X - 0.5) - 0.3 * np.abs(Y - 0.5)], axis=1)
    tris = []
    for a in range(n):
        for b in range(n):
            v00, v10, v01, v11 = (
                a * (n + 1) + b,
                (a + 1) * (n + 1) + b,
                a * (n + 1) + b + 1,
                (a + 1) * (n + 1) + b + 1,
            )
            tris += [(v00, v10, v11), (v00, v11, v01)]
    tris = np.array(tris)
    return Facets(pts[tris], tris + 1000, pts[tris])


def test_surface_rim():
    """The rim of a surface: the edges of one facet only and their vertices (3D), the ends of
    a curve (2D); over the ranks (each facet on one of them) the same as on one rank."""
    from mpi4py import MPI

    from contactfx.contact.pair import facet_rim, surface_rim

    n = 4
    roof = _pyramid(n)
    open_vertex, open_edge = facet_rim(roof.nodes)
    assert open_edge.sum() == 4 * n  # the square's boundary
    ends = roof.X[np.arange(len(roof))[:, None], (np.arange(3) + 1) % 3]  # edge i from i + 1
    others = roof.X[np.arange(len(roof))[:, None], (np.arange(3) + 2) % 3]
    on_side = np.zeros_like(open_edge)
    for c in (0, 1):
        for value in (0.0, 1.0):
            on_side |= (ends[..., c] == value) & (others[..., c] == value)
    assert np.array_equal(open_edge, on_side)
    xy = roof.X[..., :2]
    assert np.array_equal(open_vertex, np.any((xy == 0.0) | (xy == 1.0), axis=2))
    curve = _line(np.linspace(0.0, 1.0, 6), 0.0, 0)
    v, e = facet_rim(curve.nodes)
    assert v.sum() == 2 and v[0, 0] and v[-1, 1] and not e.any()
    comm = MPI.COMM_WORLD
    for whole in (roof, curve):
        rank = np.random.default_rng(5).integers(0, comm.size, len(whole))
        mine = rank == comm.rank
        parallel = surface_rim(comm, whole.nodes[mine])
        for got, want in zip(parallel, facet_rim(whole.nodes), strict=True):
            assert np.array_equal(got, want[mine])


def test_symmetry_plane_edges_not_on_the_rim():
    """An edge of one facet on a symmetry plane (both its nodes hold the displacement
    component normal to the plane, and lie on it) is not on the rim: the mirror image
    continues the surface there, and a point past it is in contact. The roof's side x = 0 a
    roller plane (u_x held); its side y = 0 holds u_x too but lies in no plane x = const (the
    plane test: still a boundary), its side y = 1 is clamped (every component held: the
    surface ends there), its side x = 1 free. Over the ranks the same as on one rank."""
    from mpi4py import MPI

    from contactfx.contact.closest_point import project
    from contactfx.contact.pair import facet_rim, mirror_edges, surface_rim

    n = 4
    roof = _pyramid(n)
    X = roof.X
    held = np.zeros(X.shape, dtype=bool)
    held[..., 0] = (X[..., 0] == 0.0) | (X[..., 1] == 0.0)
    held[X[..., 1] == 1.0] = True
    ends = X[np.arange(len(roof))[:, None], (np.arange(3) + 1) % 3]  # edge i from i + 1
    others = X[np.arange(len(roof))[:, None], (np.arange(3) + 2) % 3]

    def side(c: int, value: float) -> np.ndarray:
        return (ends[..., c] == value) & (others[..., c] == value)

    assert np.array_equal(mirror_edges(X, held, 1e-12), side(0, 0.0))
    # a node of the plane moved off it by more than round-off: its two edges are not on it
    shifted = X.copy()
    shifted[..., 0] += np.where(X[..., 1] == 0.5, 1e-9, 0.0)
    assert mirror_edges(shifted, held, 1e-12).sum() == side(0, 0.0).sum() - 2
    open_vertex, open_edge = facet_rim(roof.nodes, X, held)
    assert open_edge.sum() == 3 * n
    assert np.array_equal(open_edge, side(0, 1.0) | side(1, 0.0) | side(1, 1.0))
    x, y = X[..., 0], X[..., 1]
    assert np.array_equal(open_vertex, (x == 1.0) | (y == 0.0) | (y == 1.0))
    # without the flags every side is on the rim
    assert facet_rim(roof.nodes)[1].sum() == 4 * n
    comm = MPI.COMM_WORLD
    rank = np.random.default_rng(7).integers(0, comm.size, len(roof))
    mine = rank == comm.rank
    parallel = surface_rim(comm, roof.nodes[mine], X[mine], held[mine])
    for got, want in zip(parallel, (open_vertex, open_edge), strict=True):
        assert np.array_equal(got, want[mine])
    # past the roller plane: paired; past the other sides: not
    roof.open_vertex, roof.open_edge = open_vertex, open_edge
    points = np.array(
        [
            [-0.1, 0.3, -0.06],  # beyond the roller plane x = 0
            [-0.1, 0.5, 0.0],  # beyond the end of the ridge y = 0.5 on the roller plane
            [1.1, 0.3, -0.06],  # beyond the free side x = 1
            [0.3, -0.1, 0.0],  # beyond y = 0 (u_x held, not its plane)
            [0.3, 1.1, 0.0],  # beyond the clamped side y = 1
            [-0.1, -0.1, -0.15],  # beyond the corner of the roller plane and y = 0
        ]
    )
    pick = project(points, roof)
    assert not pick.inside.any()
    assert list(pick.index >= 0) == [True, True, False, False, False, False]


def test_points_beyond_the_master_rim_unpaired():
    """The point coupling's pairing off a master facet: a point whose closest point on the
    master surface is on an interior ridge or at an interior vertex (a convex kink) is in
    contact, one whose closest point is on the surface's boundary (edge or vertex; 2D: the end
    of the curve) is beyond the surface and is not."""
    from contactfx.contact.closest_point import project
    from contactfx.contact.pair import facet_rim

    roof = _pyramid(4)
    roof.open_vertex, roof.open_edge = facet_rim(roof.nodes)
    points = np.array(
        [
            [0.5, 0.5, 0.8],  # above the apex: the closest point is the apex
            [0.3, 0.5, 0.45],  # above the ridge y = 0.5: on the ridge
            [1.1, 0.3, -0.06],  # beyond the boundary edge x = 1
            [1.1, 0.5, 0.0],  # beyond the end of the ridge: a boundary vertex
            [1.1, 1.1, -0.15],  # beyond a corner of the square
            [0.6, 0.3, 0.5],  # above a facet (inside it)
        ]
    )
    pick = project(points, roof)
    assert list(pick.inside) == [False] * 5 + [True]
    assert list(pick.index >= 0) == [True, True, False, False, False, True]
    # 2D: a convex kink (0, 0) -> (1, 0.5) -> (2, 0), normals up (right to left)
    x = np.array([[[2.0, 0.0], [1.0, 0.5]], [[1.0, 0.5], [0.0, 0.0]]])
    curve = Facets(x, np.array([[2, 1], [1, 0]]), x)
    pick = project(np.array([[1.0, 0.8], [-0.2, -0.05], [2.1, 0.1]]), curve)
    assert not pick.inside.any()
    assert list(pick.index >= 0) == [True, False, False]
