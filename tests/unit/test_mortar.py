"""Unit tests of the mortar integrals and of the search (docs/verification.md section 10):
the partition of unity of D and M that the patch test needs, and known projections."""

from __future__ import annotations

import numpy as np
import pytest

from contactfx._compat import FacetTree
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
    D, normals, (rows, cols, vals) = mortar_matrices(slave, master, pairs)
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
    slave = Facets(np.array([[[1.0, 0.0], [0.0, 0.0]], [[2.0, 0.0], [1.0, 0.0]]]),
                   np.array([[1, 0], [2, 1]]))  # fmt: skip
    master = Facets(np.array([[[0.0, 0.0], [1.0, 0.0]]]), np.array([[10, 11]]))
    pairs = FacetTree(master.x, 0.5).collide(FacetTree(slave.x, 0.0))
    D, _, (rows, cols, vals) = mortar_matrices(slave, master, pairs)
    M_sum = np.zeros(3)
    np.add.at(M_sum, rows, vals)
    assert M_sum == pytest.approx([0.5, 0.5, 0.0], abs=1e-14)


def test_facet_tree_candidates():
    segments = np.array([[[0.0, 0.0], [1.0, 0.0]], [[1.0, 0.0], [2.0, 0.0]],
                         [[5.0, 0.0], [6.0, 0.0]]])  # fmt: skip
    tree = FacetTree(segments, 0.1)
    points = np.array([[0.5, 0.05], [1.0, 0.0], [3.0, 0.0]])
    rows, facets = tree.collide_points(points)
    hits = {(int(r), int(f)) for r, f in zip(rows, facets, strict=True)}
    # padded boxes (0.1): the first point meets facet 0 only, the shared vertex both, the
    # point at x = 3 none (farther than the padding from every facet)
    assert hits == {(0, 0), (1, 0), (1, 1)}
