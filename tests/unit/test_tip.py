"""The tip enrichment's geometry (contactfx.contact.tip): the branch function, the star cells'
rule and the tip nodes' share of a P1 field, against closed forms."""

from __future__ import annotations

import numpy as np
import pytest

from contactfx.contact.tip import branch, star_rule, tip_split

TRI = np.array([[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]])


def _frame(angle):
    e1 = np.array([np.cos(angle), np.sin(angle)])
    return e1, np.array([-e1[1], e1[0]])


@pytest.mark.parametrize("angle", [0.0, 0.3, 2.5])
@pytest.mark.parametrize("normal_sign", [1.0, -1.0])
def test_branch_function_values_and_gradient(angle, normal_sign):
    tip = np.array([0.2, 0.1])
    e1, e2 = _frame(angle)
    normal = normal_sign * e2
    rng = np.random.default_rng(1)
    pts = tip + rng.uniform(-1.0, 1.0, (20, 2))
    F, grad = branch(pts, tip, e1, normal)
    d = pts - tip
    r, theta = np.hypot(d @ e1, d @ e2), np.arctan2(d @ e2, d @ e1)
    # sqrt(r) sin(theta / 2), positive on the normal's side
    assert F == pytest.approx(normal_sign * np.sqrt(r) * np.sin(theta / 2.0), abs=1e-14)
    # the gradient against central differences (step 1e-6: error O(1e-12) / r^1.5)
    for i in range(2):
        step = np.zeros(2)
        step[i] = 1e-6
        fd = branch(pts + step, tip, e1, normal)[0] - branch(pts - step, tip, e1, normal)[0]
        assert grad[:, i] == pytest.approx(fd / 2e-6, abs=1e-7)
    # on the crack behind the tip F = +-sqrt(r) and grad F = +-grad sqrt(r) = -+e1 / (2 sqrt r)
    for side in (1.0, -1.0):
        p = tip - 0.3 * e1 + side * 1e-13 * normal
        F, grad = branch(p[None], tip, e1, normal)
        assert F[0] == pytest.approx(side * np.sqrt(0.3), rel=1e-9)
        assert grad[0] == pytest.approx(-side * e1 / (2.0 * np.sqrt(0.3)), rel=1e-6)


def test_star_rule_integrates_each_side():
    """A cut cell: each side's polynomials of degree 2 exactly (the sides' polygons split
    into triangles with a collapsed 3 x 3 Gauss rule, exact to degree 4 in xi and 5 in eta);
    the side of every point from phi."""
    phi = np.array([[-0.3, 0.2, 0.4]])
    tip = np.array([[0.6, 0.0]])  # where the zero line leaves the cell: a vertex of both sides
    pts, w, side, cut_side = star_rule(TRI, phi, np.array([True]), np.array([1.0]), tip, 28)
    assert w.sum() == pytest.approx(0.5, rel=1e-14)
    # the -side is the corner at vertex 0 cut at t = 0.6 and 3 / 7 along its edges
    a, b = 0.6, 0.3 / 0.7
    minus = side[0] < 0
    assert w[0, minus].sum() == pytest.approx(0.5 * a * b, rel=1e-14)
    x, y = pts[0, :, 0], pts[0, :, 1]
    # int x^2 over the corner triangle (0, 0), (a, 0), (0, b): a^3 b / 12
    assert np.sum(w[0, minus] * x[minus] ** 2) == pytest.approx(a**3 * b / 12.0, rel=1e-13)
    assert np.sum(w[0] * x * y) == pytest.approx(1.0 / 24.0, rel=1e-13)
    phi_at = -0.3 + 0.5 * x + 0.7 * y
    assert np.all(np.sign(phi_at[w[0] > 0]) == side[0, w[0] > 0])
    assert np.array_equal(cut_side[0][w[0] > 0], side[0][w[0] > 0])


def test_star_rule_singular_density():
    """An uncut cell with the tip on an edge: the rule is fanned from the tip, whose collapsed
    coordinates' Jacobian (zero at the tip) cancels the energy density's 1 / r."""
    X = np.array([[[0.0, 0.0], [1.0, 0.0], [0.5, 1.0]]])
    tip = np.array([[0.5, 0.0]])
    pts, w, side, cut_side = star_rule(
        X, np.ones((1, 3)), np.array([False]), np.array([1.0]), tip, 28
    )
    assert np.all(np.isnan(cut_side)) and np.all(side == 1.0)
    r = np.linalg.norm(pts[0] - tip[0], axis=1)
    # the two mirror triangles (tip, (1, 0), (0.5, 1)) and (tip, (0.5, 1), (0, 0)): over each,
    # int 1 / r = p (asinh(t1) - asinh(t0)) with p = 1 / sqrt(5) the distance from the tip to
    # the far edge and t0 = -1 / 2, t1 = 2 the edge's ends from the foot of p, over p
    p = 1.0 / np.sqrt(5.0)
    exact = 2.0 * p * (np.arcsinh(2.0) - np.arcsinh(-0.5))
    # the integrand in collapsed coordinates is smooth, 1 / |b - a + eta (c - b)| across the
    # fan: three Gauss points across it measured 0.43 % (a polynomial: exact, above)
    assert np.sum(w[0] / r) == pytest.approx(exact, rel=0.006)
    assert w.sum() == pytest.approx(0.5, rel=1e-14)


def test_tip_split_reproduces_the_nodal_share():
    """L a(x) + grad a (P - L x) is sum over the flagged nodes of lambda_i(y) a_i, and its
    gradient a(x) (x) gL + grad a (gP - x (x) gL) that of the same sum, from any x."""
    rng = np.random.default_rng(2)
    nodal = rng.normal(size=(3, 2))  # a P1 vector field's nodal values
    flags = np.array([[True, False, True]])
    y = np.array([[[0.2, 0.3], [0.1, 0.7]]])
    L, P, gL, gP = tip_split(TRI, flags, y)
    lam = np.column_stack([1.0 - y[0].sum(axis=1), y[0]])
    share = (lam * flags[0]) @ nodal
    grad_a = np.column_stack([nodal[1] - nodal[0], nodal[2] - nodal[0]])  # d a_i / d x_j
    x = np.array([0.25, 0.25])
    a_x = nodal[0] + grad_a @ x
    from_x = L[0][:, None] * a_x + (grad_a @ (P[0] - L[0][:, None] * x).T).T
    assert from_x == pytest.approx(share, abs=1e-14)
    glam = np.array([[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0]])
    exact_grad = sum(np.outer(nodal[i], glam[i]) for i in range(3) if flags[0, i])
    grad = np.outer(a_x, gL[0]) + grad_a @ (gP[0] - np.outer(x, gL[0]))
    assert grad == pytest.approx(exact_grad, abs=1e-14)
