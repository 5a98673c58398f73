"""The contact search's candidate pairs (contactfx.contact.boxes) against a brute-force test of
every box against every point and box: the same pairs, in sorted order."""

import numpy as np
import pytest

from contactfx.contact.boxes import FacetTree


def _facets(rng, m, d, gdim, graded):
    """m random simplices with d vertices; sizes over three decades when ``graded``."""
    centres = rng.uniform(-1.0, 1.0, (m, 1, gdim))
    size = 10.0 ** rng.uniform(-3, 0, (m, 1, 1)) if graded else 0.1
    return centres + size * rng.uniform(-1.0, 1.0, (m, d, gdim))


def _brute_points(lo, hi, points):
    eps = 1e-14 * (hi - lo)
    inside = np.all(
        (points[:, None, :] >= (lo - eps)[None]) & (points[:, None, :] <= (hi + eps)[None]),
        axis=2,
    )
    return np.nonzero(inside)


def _brute_boxes(lo_a, hi_a, lo_b, hi_b):
    eps = 1e-14 * (hi_b - lo_b)
    meet = np.all(
        (hi_a[:, None, :] >= (lo_b - eps)[None]) & (lo_a[:, None, :] <= (hi_b + eps)[None]),
        axis=2,
    )
    return np.nonzero(meet)


@pytest.mark.parametrize("gdim", [2, 3])
@pytest.mark.parametrize("graded", [False, True])
def test_pairs_equal_brute_force(gdim, graded):
    rng = np.random.default_rng(gdim + 10 * graded)
    master = _facets(rng, 400, gdim, gdim, graded)
    slave = _facets(rng, 300, gdim, gdim, graded)
    pad_m = 0.5 * np.linalg.norm(master[:, 0] - master[:, 1], axis=1)
    tree, other = FacetTree(master, pad_m), FacetTree(slave, 0.01)
    lo_m, hi_m = master.min(axis=1) - pad_m[:, None], master.max(axis=1) + pad_m[:, None]
    lo_s, hi_s = slave.min(axis=1) - 0.01, slave.max(axis=1) + 0.01

    # brute force: np.nonzero lists (row, column) in row-major order, the order asked for
    first, second = tree.collide(other)
    expected = _brute_boxes(lo_s, hi_s, lo_m, hi_m)
    assert len(first) > 300  # pairs exist: the comparison below is not of two empty sets
    np.testing.assert_array_equal(first, expected[0])
    np.testing.assert_array_equal(second, expected[1])

    points = rng.uniform(-1.1, 1.1, (500, gdim))
    # points on box faces and corners: the bounds are inclusive (widened by 1e-14 of the
    # extent), so these count as inside
    points[:50] = lo_m[:50]
    points[50:100] = hi_m[50:100]
    rows, facets = tree.collide_points(points)
    expected = _brute_points(lo_m, hi_m, points)
    assert np.all(np.isin(np.arange(100), rows))
    np.testing.assert_array_equal(rows, expected[0])
    np.testing.assert_array_equal(facets, expected[1])


def test_empty_sets():
    tree = FacetTree(np.zeros((0, 2, 2)), 0.1)
    some = FacetTree(np.array([[[0.0, 0.0], [1.0, 0.0]]]), 0.1)
    assert tree.size == 0
    for pairs in (tree.collide(some), some.collide(tree), tree.collide_points(np.ones((3, 2)))):
        assert all(len(p) == 0 for p in pairs)
    assert all(len(p) == 0 for p in some.collide_points(np.zeros((0, 2))))
    # one facet: a far point is not paired (the box test is applied to a single box too)
    rows, facets = some.collide_points(np.array([[0.5, 0.05], [0.5, 0.2]]))
    assert rows.tolist() == [0] and facets.tolist() == [0]
