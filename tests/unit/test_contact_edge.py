"""The contact size estimate (contactfx.contact_edge) on synthetic nodal fields.

1. The zero contour of phi = p - (E* / h) g: Hertz's pressure p = sqrt(1 - (s / a)^2)
   inside and its gap outside, on a line of segments (2D) and on a structured
   triangulation of a disc's quarter (3D, the radius of the disc of four times its area),
   within h / 4 of a; the segment and triangle cuts exactly (one vertex in, two in).
2. A pressure that leaks to the first open node (a reaction, a multiplier: 10 % of p0 0.7 of an
   element beyond the edge) is outweighed by its gap.
3. The explicit rules are clipped to [last closed node, first open node]; x-band refused on a
   half model in one line, radial in 2D.
"""

from __future__ import annotations

import numpy as np
import pytest

from contactfx.contact_edge import ContourMeasure, check_edge_rule, contact_edge, line_edge


def _hertz(s: np.ndarray, a: float, E: float) -> tuple[np.ndarray, np.ndarray]:
    """Hertz 2D at p0 = 1 (E* a / (2 R) = 1): the pressure inside, the gap outside
    (a / E*) (xi sqrt(xi^2 - 1) - arccosh xi), xi = |s| / a."""
    xi = np.abs(s) / a
    p = np.sqrt(np.clip(1.0 - xi**2, 0.0, None))
    out = np.maximum(xi, 1.0)
    g = a / E * (out * np.sqrt(out**2 - 1.0) - np.arccosh(out))
    return p, g


def test_cuts():
    x = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    tri = ContourMeasure(np.array([[0, 1, 2]]), x)
    zero = np.zeros(3)
    assert tri(np.array([1.0, -1.0, -1.0]), zero, 1.0) == pytest.approx(0.125)
    assert tri(np.array([-1.0, 1.0, 1.0]), zero, 1.0) == pytest.approx(0.375)
    assert tri(np.array([1.0, 1.0, 1.0]), zero, 1.0) == pytest.approx(0.5)
    seg = ContourMeasure(np.array([[0, 1]]), x)
    assert seg(np.array([3.0, -1.0]), zero, 1.0) == pytest.approx(0.75)
    assert seg(np.array([-1.0, 3.0]), zero, 1.0) == pytest.approx(0.75)
    axi = ContourMeasure(np.array([[0, 1]]), x, axisymmetric=True)
    assert axi(np.array([1.0, -1.0]), zero, 1.0) == pytest.approx(0.5 * 0.25)  # int_0^0.5 r


@pytest.mark.parametrize("shift", [0.0, 0.3, 0.7])
def test_contour_2d(shift):
    a, h, E = 0.3, 0.03, 1.0
    s = (np.arange(-20, 21) + shift) * h
    x = np.column_stack([s, np.zeros_like(s), np.zeros_like(s)])
    dofs = np.column_stack([np.arange(len(s) - 1), np.arange(1, len(s))])
    p, g = _hertz(np.abs(s), a, E)
    half = 0.5 * ContourMeasure(dofs, x)(p, g, E)
    assert abs(half - a) < 0.25 * h
    # a reaction's tail on the first open node of each side (the closed nodes' zone grows by
    # an element there): outweighed by its gap 0.7 of an element beyond the edge
    if shift != 0.7:
        return
    leak = p.copy()
    leak[np.flatnonzero((s > 0) & (g > 0))[0]] = 0.1
    leak[np.flatnonzero((s < 0) & (g > 0))[-1]] = 0.1
    assert abs(0.5 * ContourMeasure(dofs, x)(leak, g, E) - a) < 0.25 * h


def test_contour_3d():
    a, h, E = 0.3, 0.02, 1.0
    n = 40
    xs = np.arange(n + 1) * h
    X, Y = np.meshgrid(xs, xs, indexing="ij")
    x = np.column_stack([X.ravel(), Y.ravel(), np.zeros(X.size)])
    idx = np.arange(X.size).reshape(n + 1, n + 1)
    tris = []
    for i in range(n):
        for j in range(n):
            v = idx[i, j], idx[i + 1, j], idx[i + 1, j + 1], idx[i, j + 1]
            tris += [(v[0], v[1], v[2]), (v[0], v[2], v[3])]
    p, g = _hertz(np.hypot(x[:, 0], x[:, 1]), a, E)
    area = 4.0 * ContourMeasure(np.array(tris), x)(p, g, E)  # the quarter model
    assert abs(np.sqrt(area / np.pi) - a) < 0.25 * h


def test_rules_clipped():
    a = 0.3
    s = np.linspace(0.0, 0.6, 31)
    p = np.sqrt(np.clip(1.0 - (s / a) ** 2, 0.0, None))
    closed = p > 0.0
    last, first_open = s[closed].max(), s[~closed].min()
    edge = line_edge(s[closed], p[closed], s[~closed])
    assert last <= edge <= first_open
    # a pressure that hardly falls at the last node extrapolates far beyond the first open
    # node: clipped there
    q = p.copy()
    i = closed.nonzero()[0][-1]
    q[i] = 0.99 * q[i - 1]
    assert line_edge(s[closed], q[closed], s[~closed]) == pytest.approx(first_open)
    assert line_edge(s[closed], q[closed]) > first_open  # unclipped
    pts = np.column_stack([s, np.zeros_like(s)])
    assert contact_edge("x-max", pts, p, closed=closed) == pytest.approx(edge)
    assert contact_edge(None, pts, p, closed=closed) is None


def test_rules_refused():
    half = np.column_stack([np.linspace(0.0, 1.0, 11), np.zeros(11)])
    with pytest.raises(ValueError, match="'x-band' does not apply: the slave surface lies on one"):
        check_edge_rule("x-band", half, 2, "contact.0.edge")
    check_edge_rule("x-band", half - 0.5, 2)  # a full model: both sides of x = 0
    check_edge_rule("x-max", half, 2)
    with pytest.raises(ValueError, match="'radial' applies in 3D only"):
        check_edge_rule("radial", half, 2)
