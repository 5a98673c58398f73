"""Unit tests of :mod:`contactfx.contact.projection`: closest points on segments and triangles,
the candidate choice of the contact search, 2D segment overlaps, 3D polygon clipping and the
quadrature rules.

Pure numpy, no MPI: at 2 ranks every rank runs the same cases. Every case has an exact answer
(or one built by construction), the coordinates are O(1) and each result costs a few dozen
flops, so the tolerances are round-off only: ROUND = 1e-14 (~50 ulp of 1) where a handful of
operations produce the value, LOOSE = 1e-12 where random geometry (rotations, nearly parallel
edges of random triangles, a 2x2 solve with a condition number up to ~1e2) multiplies it.
"""

from __future__ import annotations

import itertools
from math import factorial

import numpy as np
import pytest

from contactfx.contact.projection import (
    clip_polygon,
    closest_point_facets,
    closest_point_segments,
    closest_point_segments_many,
    closest_point_triangles,
    facet_normal,
    gauss_segment,
    gauss_triangle,
    pick_closest,
    plane_basis,
    polygon_area,
    project_to_plane,
    segment_normal,
    segment_overlap,
    segment_overlaps,
    triangle_normal,
    triangle_overlap,
)

# a few flops on O(1) numbers: ~50 ulp of 1
ROUND = 1e-14
# random geometry: rotations, and 2x2 solves whose round-off grows with their condition number
# (random triangles and segment pairs reach ~1e2 - 1e3): measured errors stay below 2e-13
LOOSE = 1e-12

RNG = np.random.default_rng(20240607)

REF_TRI = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])


def rotation(rng: np.random.Generator) -> np.ndarray:
    """A random proper rotation of R^3 (QR of a Gaussian matrix, signs fixed)."""
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    q = q * np.sign(np.diag(r))
    return q if np.linalg.det(q) > 0 else -q


def tri_area(tri: np.ndarray) -> np.ndarray:
    """Unsigned area of triangles (..., 3, 3)."""
    e = np.cross(tri[..., 1, :] - tri[..., 0, :], tri[..., 2, :] - tri[..., 0, :])
    return 0.5 * np.linalg.norm(e, axis=-1)


# --- normals --------------------------------------------------------------------------------


def test_normals_orientation():
    # (t_y, -t_x): the bottom edge of a counter-clockwise square points down, the top one up
    assert np.array_equal(segment_normal([0, 0], [1, 0]), [0.0, -1.0])  # exact: no round-off
    assert np.array_equal(segment_normal([1, 1], [0, 1]), [0.0, 1.0])
    n = segment_normal(RNG.normal(size=(5, 2)), RNG.normal(size=(5, 2)))
    assert np.allclose(np.linalg.norm(n, axis=1), 1.0, rtol=0, atol=ROUND)  # a sqrt and divide
    assert np.array_equal(triangle_normal(REF_TRI), [0.0, 0.0, 1.0])  # exact integers
    assert np.array_equal(triangle_normal(REF_TRI[::-1]), [0.0, 0.0, -1.0])
    assert np.array_equal(facet_normal(REF_TRI), triangle_normal(REF_TRI))
    with pytest.raises(ValueError):
        facet_normal(np.zeros((2, 3)))


# --- segments -------------------------------------------------------------------------------


@pytest.mark.parametrize("d", [2, 3])
def test_segment_projection_by_construction(d):
    # p = a + xi (b - a) + h m with m orthogonal to the segment: the projection is at xi
    n = 200
    a, b = RNG.normal(size=(n, d)), RNG.normal(size=(n, d))
    xi = RNG.uniform(-0.5, 1.5, n)
    m = RNG.normal(size=(n, d))
    e = b - a
    m -= (np.einsum("ij,ij->i", m, e) / np.einsum("ij,ij->i", e, e))[:, None] * e
    p = a + xi[:, None] * e + m
    r = closest_point_segments(p, a, b)
    # a projection: dot products and a quotient; |e| is not tiny for the bulk of random draws
    assert np.allclose(r.xi, xi, rtol=0, atol=LOOSE)
    assert np.array_equal(r.inside, (xi >= 0) & (xi <= 1))  # no xi within 1e-10 of 0 or 1
    xc = np.clip(xi, 0, 1)[:, None]
    assert np.allclose(r.closest, a + xc * e, rtol=0, atol=LOOSE)
    assert np.allclose(r.distance, np.linalg.norm(p - (a + xc * e), axis=1), rtol=0, atol=LOOSE)


def test_segment_known_points():
    a, b = np.array([1.0, 2.0]), np.array([3.0, 2.0])
    p = np.array([[1.5, 3.0], [1.0, 2.0], [3.0, 2.0], [0.0, 1.0], [4.0, 2.5], [3.0, 7.0]])
    r = closest_point_segments(p, a, b)
    # exact in binary: quotients of small integers and halves
    assert np.array_equal(r.xi, [0.25, 0.0, 1.0, -0.5, 1.5, 1.0])
    assert np.array_equal(r.inside, [True, True, True, False, False, True])
    assert np.array_equal(r.closest, [[1.5, 2.0], a, b, a, b, b])
    assert np.allclose(r.distance, [1.0, 0.0, 0.0, np.sqrt(2), np.sqrt(1.25), 5.0], atol=ROUND)
    # within the tolerance of the end: still inside, the closest point clamped to b
    r = closest_point_segments([[3.0 + 1e-12, 2.0]], a, b)
    assert r.inside[0] and np.array_equal(r.closest[0], b)
    assert not closest_point_segments([[3.0 + 1e-12, 2.0]], a, b, tol=0.0).inside[0]


# --- triangles ------------------------------------------------------------------------------


def test_triangle_projection_by_construction():
    n = 300
    tri = RNG.normal(size=(n, 3, 3))
    lam = RNG.uniform(-0.6, 1.0, size=(n, 3))
    lam[:, 0] = 1 - lam[:, 1] - lam[:, 2]
    h = RNG.normal(size=n)
    p = np.einsum("ij,ijk->ik", lam, tri) + h[:, None] * triangle_normal(tri)
    r = closest_point_triangles(p, tri)
    # the 2x2 normal equations lose ~cond * eps: below cond 1e4 that is < 1e-12 (measured
    # 2e-13 over 2e4 draws); the rare slivers above are left out of the coordinate comparison
    e = tri[:, 1:] - tri[:, :1]
    keep = np.linalg.cond(np.einsum("nij,nkj->nik", e, e)) < 1e4
    assert np.allclose(r.bary[keep], lam[keep], rtol=0, atol=LOOSE)
    assert np.array_equal(r.inside[keep], np.all(lam[keep] >= 0, axis=1))
    interior = keep & np.all(lam > 0, axis=1)
    assert np.allclose(r.distance[interior], np.abs(h[interior]), rtol=0, atol=LOOSE)

    # the true closest point: the plane when inside, else the best of the three edges
    edges = [closest_point_segments(p, tri[:, i], tri[:, j]) for i, j in [(0, 1), (1, 2), (2, 0)]]
    best = np.min([e.distance for e in edges], axis=0)
    best = np.where(np.all(lam >= 0, axis=1), np.abs(h), best)
    assert np.allclose(r.distance, best, rtol=0, atol=LOOSE)
    assert np.allclose(np.linalg.norm(p - r.closest, axis=1), r.distance, rtol=0, atol=ROUND)


def test_triangle_regions_and_vertices():
    p = np.array(
        [
            [0.25, 0.25, 0.5],  # interior
            [-1.0, -1.0, 0.5],  # vertex A
            [2.0, -0.5, 0.3],  # vertex B
            [-0.5, 2.0, 0.0],  # vertex C
            [0.5, -1.0, 0.2],  # edge AB
            [-1.0, 0.25, 0.0],  # edge AC
            [1.0, 1.0, 0.3],  # edge BC
            [0.0, 0.0, 0.0],  # exactly on A, B, C
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
        ]
    )
    expected = np.array(
        [
            [0.25, 0.25, 0.0],
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.5, 0.0, 0.0],
            [0.0, 0.25, 0.0],
            [0.5, 0.5, 0.0],
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
        ]
    )
    r = closest_point_triangles(p, np.broadcast_to(REF_TRI, (len(p), 3, 3)))
    assert np.allclose(r.closest, expected, rtol=0, atol=ROUND)  # a few flops on halves
    assert np.allclose(r.distance, np.linalg.norm(p - expected, axis=1), rtol=0, atol=ROUND)
    assert np.array_equal(r.inside, [True] + [False] * 6 + [True] * 3)
    assert np.allclose(r.bary[7:], np.eye(3), rtol=0, atol=ROUND)  # vertices: (near) exact
    # a vertex of a general triangle
    tri = RNG.normal(size=(3, 3))
    r = closest_point_triangles(tri, np.broadcast_to(tri, (3, 3, 3)))
    assert r.inside.all()
    assert np.allclose(r.bary, np.eye(3), rtol=0, atol=LOOSE)  # 2x2 solve, random triangle
    assert np.allclose(r.distance, 0.0, rtol=0, atol=LOOSE)


def test_facets_dispatch():
    r = closest_point_facets([[0.5, 1.0]], [[[0.0, 0.0], [2.0, 0.0]]])
    assert np.array_equal(r.bary, [[0.75, 0.25]])  # exact: 1/4 in binary
    r3 = closest_point_facets([[0.25, 0.25, 1.0]], REF_TRI[None])
    assert np.allclose(r3.bary, [[0.5, 0.25, 0.25]], rtol=0, atol=ROUND)
    with pytest.raises(ValueError):
        closest_point_facets([[0.0, 0.0]], REF_TRI[None])


# --- candidate choice -----------------------------------------------------------------------

SEGMENTS = np.array(
    [
        [[0.0, 0.0], [1.0, 0.0]],
        [[1.0, 0.0], [2.0, 0.5]],
        [[2.0, 0.5], [3.0, 0.5]],
        [[0.0, 3.0], [1.0, 3.0]],  # far away, but the projection of (0.5, y) is inside it too
    ]
)


def test_pick_closest_segments():
    p = np.array([[0.5, 0.25], [0.5, 0.25], [5.0, 0.0], [1.0, 0.0], [2.5, 0.75]])
    cand = np.array([[3, 0, -1], [-1, -1, -1], [0, 1, 2], [1, 0, -1], [2, -1, 1]])
    r = pick_closest(p, cand, SEGMENTS)
    assert np.array_equal(r.index, [0, -1, -1, 1, 2])
    assert np.array_equal(r.inside, [True, False, False, True, True])
    # the chosen rows: exact binary fractions
    assert np.array_equal(r.bary[0], [0.5, 0.5]) and np.array_equal(r.closest[0], [0.5, 0.0])
    assert r.gap[0] == -0.25 and r.distance[0] == 0.25  # normal (0, -1) of seg 0
    assert np.isnan(r.bary[1]).all() and np.isnan(r.gap[1]) and np.isnan(r.closest[2]).all()
    # on the shared vertex of 0 and 1: both inside at distance 0, the first candidate wins
    assert np.array_equal(r.bary[3], [1.0, 0.0]) and r.distance[3] == 0.0
    assert r.gap[4] == pytest.approx(-0.25, abs=ROUND)  # normal (0, -1) of seg 2
    # all outside, with fallback: the nearest end point (vertex (3, 0.5) of seg 2)
    f = pick_closest(p, cand, SEGMENTS, fallback=True)
    assert f.index[2] == 2 and not f.inside[2]
    assert np.array_equal(f.closest[2], [3.0, 0.5]) and f.bary[2, 1] == 3.0  # xi unclamped
    assert f.index[1] == -1  # no candidate at all
    assert np.array_equal(f.index[[0, 3, 4]], r.index[[0, 3, 4]])
    # None: every facet is a candidate
    a = pick_closest(p, None, SEGMENTS)
    assert np.array_equal(a.index, [0, 0, -1, 0, 2])


def test_pick_closest_triangles():
    t0 = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0]])
    t1 = np.array([[0.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]])
    facets = np.stack([t0, t1, t0 + [0.0, 0.0, 1.0]])
    p = np.array([[0.75, 0.25, 0.125], [0.25, 0.75, -0.5], [2.0, 2.0, 0.0], [0.5, 0.25, 0.875]])
    cand = np.array([[2, 1, 0, -1], [0, 2, 1, -1], [0, 1, 2, -1], [0, 2, -1, -1]])
    r = pick_closest(p, cand, facets)
    assert np.array_equal(r.index, [0, 1, -1, 2])
    # quarters and eighths: exact up to the round-off of the 2x2 solve
    assert np.allclose(r.bary[0], [0.25, 0.5, 0.25], rtol=0, atol=ROUND)
    assert np.allclose(r.gap[[0, 1, 3]], [0.125, -0.5, -0.125], rtol=0, atol=ROUND)
    assert np.allclose(r.closest[3], [0.5, 0.25, 1.0], rtol=0, atol=ROUND)


def test_pick_closest_ties_do_not_depend_on_the_candidate_order():
    """A point off a convex ridge is equally far from the two triangles that share the ridge
    (its closest point is on the shared edge): with a key, the lowest key wins whatever order
    the candidates come in (the order of the received facets depends on the mesh partition);
    facet_order gives such a key from the reference coordinates alone."""
    from contactfx.contact.pair import facet_order

    ridge = [[0.0, 0.0, 0.0], [0.0, 1.0, 0.0]]
    left = np.array([ridge[0], [-1.0, 0.0, -0.5], ridge[1]])
    right = np.array([ridge[0], ridge[1], [1.0, 0.0, -0.5]])
    facets = np.stack([left, right])
    p = np.array([[0.0, 0.5, 0.25]])  # above the ridge: the same distance to both
    dist = [closest_point_triangles(p, f[None]).distance[0] for f in facets]
    assert dist[0] == pytest.approx(dist[1], rel=1e-15)
    key = facet_order(facets)
    picked = {
        int(pick_closest(p, np.array([order]), facets, fallback=True, key=key).index[0])
        for order in ([0, 1], [1, 0])
    }
    assert picked == {int(np.argmin(key))}
    # the key is the facets' own order: permuting the facets or their vertices keeps it
    assert np.array_equal(facet_order(facets[::-1]), key[::-1])
    assert np.array_equal(facet_order(facets[:, ::-1]), key)


def test_pick_closest_matches_loop():
    # random surfaces and candidate lists against a per-point loop over the candidates
    for d in (2, 3):
        m, n, k = 12, 50, 5
        facets = RNG.normal(size=(m, d, d))
        p = RNG.normal(size=(n, d))
        cand = RNG.integers(-1, m, size=(n, k))
        r = pick_closest(p, cand, facets)
        for i in range(n):
            c = cand[i][cand[i] >= 0]
            proj = closest_point_facets(np.repeat(p[i : i + 1], len(c), 0), facets[c])
            if not proj.inside.any():
                assert r.index[i] == -1
                continue
            j = np.argmin(np.where(proj.inside, proj.distance, np.inf))
            assert r.index[i] == c[j]
            assert np.array_equal(r.closest[i], proj.closest[j])  # the same computation
            gap = np.dot(p[i] - proj.closest[j], facet_normal(facets[c[j]]))
            assert r.gap[i] == pytest.approx(gap, abs=ROUND)
            assert abs(abs(r.gap[i]) - r.distance[i]) < LOOSE  # inside: |gap| = distance


def test_closest_point_segments_many():
    p = np.array([[0.5, 0.25], [5.0, 0.0]])
    r = closest_point_segments_many(p, SEGMENTS[:, 0], SEGMENTS[:, 1])
    assert np.array_equal(r.index, [0, -1])
    q = closest_point_segments_many(p, SEGMENTS[:, 0], SEGMENTS[:, 1], [[3, -1], [1, 2]])
    assert np.array_equal(q.index, [3, -1]) and q.gap[0] == 2.75  # seg 3's normal (0, -1)
    # 3D: a segment in space has no normal, gap NaN
    a3 = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    b3 = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 1.0]])
    r3 = closest_point_segments_many([[0.25, 0.5, 0.5]], a3, b3)
    assert r3.index[0] == 1 and np.isnan(r3.gap[0])
    assert np.array_equal(r3.bary[0], [0.5, 0.5])  # exact halves
    assert r3.distance[0] == pytest.approx(np.sqrt(0.3125), abs=ROUND)  # |(0.25, 0, -0.5)|


# --- 2D segmentation ------------------------------------------------------------------------

SLAVE = np.array([[0.0, 0.0], [1.0, 0.0]])  # normal (0, -1)


@pytest.mark.parametrize(
    "master, xi, eta",
    [
        ([[0.5, -0.1], [1.5, -0.1]], [0.5, 1.0], [0.0, 0.5]),  # partial
        ([[1.5, -0.1], [0.5, -0.1]], [0.5, 1.0], [1.0, 0.5]),  # partial, reversed master
        ([[0.75, -0.2], [0.25, -0.1]], [0.25, 0.75], [1.0, 0.0]),  # master within slave
        ([[2.0, -0.1], [-2.0, -0.1]], [0.0, 1.0], [0.5, 0.25]),  # slave within master
        ([[1.5, -0.1], [2.5, -0.1]], None, None),  # disjoint
        ([[1.0, -0.1], [2.0, -0.1]], None, None),  # touching at xi = 1
        ([[0.5, -0.1], [0.5, -0.3]], None, None),  # master along the normal: a point
    ],
)
def test_segment_overlap_known(master, xi, eta):
    r = segment_overlap(SLAVE, master)
    if xi is None:
        assert r is None
        return
    # quotients of binary fractions (the 0.1s cancel in the cross products): round-off only
    assert np.allclose(r[0], xi, rtol=0, atol=ROUND)
    assert np.allclose(r[1], eta, rtol=0, atol=ROUND)


def test_segment_overlap_oblique_normal():
    # projected along (1, -1), the master [0.5, 1.5] at y = -0.25 lands on [0.25, 1.25]
    r = segment_overlap(SLAVE, [[0.5, -0.25], [1.5, -0.25]], normal=[1.0, -1.0])
    assert np.allclose(r[0], [0.25, 1.0], rtol=0, atol=ROUND)
    assert np.allclose(r[1], [0.0, 0.75], rtol=0, atol=ROUND)


def test_segment_overlap_affine_map():
    # random pairs and normals: eta at interior xi, found by projecting x(xi) along the
    # normal onto the master line (a 2x2 solve), is the linear interpolation of the ends
    n = 200
    slave = RNG.normal(size=(n, 2, 2))
    master = slave[:, ::-1] + 0.3 * RNG.normal(size=(n, 2, 2))
    normal = segment_normal(slave[:, 0], slave[:, 1]) + 0.3 * RNG.normal(size=(n, 2))
    r = segment_overlaps(slave, master, normal)
    assert r.valid.sum() > n // 2  # most pairs overlap
    for i in np.nonzero(r.valid)[0]:
        s0, s1 = slave[i]
        m0, m1 = master[i]
        for t in (0.0, 0.3, 1.0):
            x = s0 + ((1 - t) * r.xi[i, 0] + t * r.xi[i, 1]) * (s1 - s0)
            # x + alpha n = m0 + eta (m1 - m0)
            alpha_eta = np.linalg.solve(np.column_stack([normal[i], m0 - m1]), m0 - x)
            eta = (1 - t) * r.eta[i, 0] + t * r.eta[i, 1]
            # relative to 1 + |eta|: measured 1e-14 over 5000 pairs (conditions up to ~3e2)
            assert abs(alpha_eta[1] - eta) < LOOSE * (1 + abs(eta))
        single = segment_overlap(slave[i], master[i], normal[i])
        assert np.array_equal(single[0], r.xi[i]) and np.array_equal(single[1], r.eta[i])
    assert np.isnan(r.xi[~r.valid]).all()
    assert np.all((r.xi[r.valid] >= 0) & (r.xi[r.valid] <= 1))


# --- clipping -------------------------------------------------------------------------------

SQUARE = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])


def test_clip_shifted_squares():
    poly = clip_polygon(SQUARE + [0.5, 0.25], SQUARE)
    assert polygon_area(poly) == pytest.approx(0.375, abs=ROUND)  # 0.5 x 0.75, exact corners
    assert poly.shape == (4, 2)
    # clockwise input: reoriented, the same counter-clockwise result
    cw = clip_polygon((SQUARE + [0.5, 0.25])[::-1], SQUARE[::-1])
    assert polygon_area(cw) == pytest.approx(0.375, abs=ROUND)


def test_clip_known_cases():
    tri = np.array([[0.25, 0.25], [0.75, 0.25], [0.25, 0.75]])  # inside the square
    assert polygon_area(clip_polygon(tri, SQUARE)) == pytest.approx(0.125, abs=ROUND)
    assert polygon_area(clip_polygon(SQUARE, tri)) == pytest.approx(0.125, abs=ROUND)
    assert clip_polygon(tri + 5.0, SQUARE).shape == (0, 2)  # disjoint
    assert clip_polygon(SQUARE + [1.0, 0.0], SQUARE).shape == (0, 2)  # a shared edge only
    assert clip_polygon(SQUARE + [1.0, 1.0], SQUARE).shape == (0, 2)  # a shared corner only
    same = clip_polygon(tri, tri)
    assert same.shape == (3, 2) and polygon_area(same) == pytest.approx(0.125, abs=ROUND)
    # a triangle with a vertex through an edge: the square [0,1]^2 cut by x + y <= 1.5
    big = np.array([[0.0, 0.0], [1.5, 0.0], [0.0, 1.5]])
    assert polygon_area(clip_polygon(SQUARE, big)) == pytest.approx(1 - 0.125, abs=ROUND)


def test_clip_rotation_invariance():
    # rotations and translations in the plane: same area (round-off of the rotation)
    for _ in range(20):
        a = RNG.normal(size=(3, 2))
        b = a + 0.4 * RNG.normal(size=(3, 2))
        area = polygon_area(clip_polygon(a, b))
        phi = RNG.uniform(0, 2 * np.pi)
        rot = np.array([[np.cos(phi), -np.sin(phi)], [np.sin(phi), np.cos(phi)]])
        shift = RNG.normal(size=2)
        rotated = polygon_area(clip_polygon(a @ rot.T + shift, b @ rot.T + shift))
        assert rotated == pytest.approx(area, abs=LOOSE)


def test_plane_projection():
    for _ in range(5):
        n = RNG.normal(size=3)
        basis = plane_basis(n)
        # orthonormal and right-handed with the normal: a few flops each
        assert np.allclose(basis @ basis.T, np.eye(2), rtol=0, atol=ROUND)
        assert np.allclose(np.cross(*basis), n / np.linalg.norm(n), rtol=0, atol=ROUND)
        origin = RNG.normal(size=3)
        xy = RNG.normal(size=(4, 2))
        pts = origin + xy @ basis + RNG.normal(size=(4, 1)) * n  # lift, then move off-plane
        assert np.allclose(project_to_plane(pts, origin, n), xy, rtol=0, atol=LOOSE)


# --- 3D overlap -----------------------------------------------------------------------------


def _check_overlap(ov, slave, master, normal):
    """The fan covers the polygon, its coordinates map onto the slave / along the normal."""
    assert tri_area(ov.triangles).sum() == pytest.approx(ov.area, abs=LOOSE)
    assert np.allclose(
        np.einsum("qij,jk->qik", ov.slave_bary, slave), ov.triangles, rtol=0, atol=LOOSE
    )
    on_master = np.einsum("qij,jk->qik", ov.master_bary, master)
    # the master point minus the slave-plane point is parallel to the normal
    assert np.allclose(np.cross(on_master - ov.triangles, normal), 0.0, rtol=0, atol=LOOSE)
    n = triangle_normal(slave)
    assert np.allclose((ov.polygon - slave[0]) @ n, 0.0, rtol=0, atol=LOOSE)  # in the plane
    assert np.all(
        np.cross(*(ov.triangles[:, 1:] - ov.triangles[:, :1]).transpose(1, 0, 2)) @ n > 0
    )  # fan oriented like the slave


def test_triangle_overlap_known():
    master = REF_TRI[[0, 2, 1]] + [0.0, 0.0, -0.1]  # opposite orientation, below
    ov = triangle_overlap(REF_TRI, master)
    assert ov.area == pytest.approx(0.5, abs=ROUND)  # identical in projection
    _check_overlap(ov, REF_TRI, master, triangle_normal(REF_TRI))
    # tilted master, orthogonal projection: the same reference triangle
    tilted = np.array([[0.0, 0.0, -0.1], [0.0, 1.0, -0.5], [1.0, 0.0, -0.3]])
    ov = triangle_overlap(REF_TRI, tilted)
    assert ov.area == pytest.approx(0.5, abs=ROUND)
    _check_overlap(ov, REF_TRI, tilted, triangle_normal(REF_TRI))
    # shifted by (0.5, 0.25): the overlap triangle with legs 0.25 -> area 1/32
    shifted = master + [0.5, 0.25, 0.0]
    ov = triangle_overlap(REF_TRI, shifted)
    assert ov.area == pytest.approx(1 / 32, abs=ROUND)
    _check_overlap(ov, REF_TRI, shifted, triangle_normal(REF_TRI))
    assert triangle_overlap(REF_TRI, master + [2.0, 0.0, 0.0]) is None  # disjoint
    assert triangle_overlap(REF_TRI, master + [1.0, 0.0, 0.0]) is None  # a shared vertex
    # a master containing the normal direction projects to a segment: no overlap
    assert triangle_overlap(REF_TRI, [[0, 0, 0], [1, 0, 0], [0, 0, -1]]) is None


def test_triangle_overlap_rotation_invariance():
    for _ in range(20):
        slave = RNG.normal(size=(3, 3))
        master = slave[[0, 2, 1]] + 0.3 * RNG.normal(size=(3, 3))
        normal = triangle_normal(slave) + 0.2 * RNG.normal(size=3)
        ov = triangle_overlap(slave, master, normal)
        if ov is None:
            continue
        _check_overlap(ov, slave, master, normal)
        rot, shift = rotation(RNG), RNG.normal(size=3)
        moved = triangle_overlap(slave @ rot.T + shift, master @ rot.T + shift, normal @ rot.T)
        assert moved.area == pytest.approx(ov.area, abs=LOOSE)
        # the polygons agree as sets of points (the start vertex may differ)
        back = (moved.polygon - shift) @ rot
        dist = np.linalg.norm(back[:, None] - ov.polygon[None], axis=-1)
        assert np.all(dist.min(axis=1) < LOOSE)


def test_overlap_quadrature():
    # integrate x over the overlap of two reference triangles shifted by (0.25, 0.25): the
    # fan and a degree-1 rule are exact for a linear integrand; closed form: the overlap is
    # the triangle (0.25,0.25), (0.75,0.25), (0.25,0.75) with area 1/8 and centroid x = 5/12
    master = REF_TRI[[0, 2, 1]] + [0.25, 0.25, -0.5]
    ov = triangle_overlap(REF_TRI, master)
    pts, w = gauss_triangle(2)
    x = np.einsum("qj,tjk->tqk", pts, ov.triangles)
    integral = np.sum(tri_area(ov.triangles)[:, None] * w * x[..., 0])
    assert integral == pytest.approx(5 / 12 / 8, abs=ROUND)


# --- quadrature -----------------------------------------------------------------------------


@pytest.mark.parametrize("n", range(1, 8))
def test_gauss_segment(n):
    x, w = gauss_segment(n)
    assert np.all((x > 0) & (x < 1)) and np.all(w > 0)
    for k in range(2 * n):
        # int_0^1 x^k = 1 / (k + 1); sums of n terms <= 1: a few ulp each
        assert np.dot(w, x**k) == pytest.approx(1 / (k + 1), abs=ROUND)


@pytest.mark.parametrize("degree", range(0, 7))
def test_gauss_triangle(degree):
    pts, w = gauss_triangle(degree)
    assert pts.shape[1] == 3 and len(pts) == [1, 1, 3, 6, 6, 7, 12][degree]
    assert np.all(w > 0) and np.all(pts > 0)
    assert np.allclose(pts.sum(axis=1), 1.0, rtol=0, atol=ROUND)
    s, t = pts[:, 1], pts[:, 2]
    for i, j in itertools.product(range(degree + 1), repeat=2):
        if i + j > degree:
            continue
        # int over the reference triangle of s^i t^j = i! j! / (i + j + 2)!, area 1/2
        exact = 2 * factorial(i) * factorial(j) / factorial(i + j + 2)
        assert np.dot(w, s**i * t**j) == pytest.approx(exact, abs=ROUND)  # <= 12 terms <= 1


def test_quadrature_arguments():
    with pytest.raises(ValueError):
        gauss_segment(0)
    with pytest.raises(ValueError):
        gauss_triangle(7)
