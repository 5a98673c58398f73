"""The crack-tip enrichment of an unfitted crack (geometry, numpy; :mod:`contactfx.contact.cut`).

The nodes whose support holds a tip inside (after the tip has moved onto a node or an edge:
the tip's node, or the two nodes of its edge) carry the first branch function of the near-tip
field, F(x) = sqrt(r) sin(theta / 2) (r, theta polar about the tip, theta = 0 straight ahead;
Moes, Dolbow & Belytschko 1999,
doi:10.1002/(SICI)1097-0207(19990910)46:1<131::AID-NME726>3.0.CO;2-J), signed so that F > 0 on
the crack's +side: w = u + sum_{i Heaviside} N_i H a_i + sum_{i tip} N_i F a_i. F is the one
branch function that is discontinuous across the crack: its jump 2 sqrt(r) a gives the opening
the sqrt(r) shape near the tip (the other three are continuous and only refine the stress).
On the crack's faces F = +-sqrt(r) and grad F = +-grad sqrt(r): F is H sqrt(r) there.

F is not polynomial, so the cells around the tip's nodes (the *star*) are integrated by a rule
of their own (:func:`star_rule`): each side of a cut cell (or the whole cell) is split into
triangles fanned from the vertex nearest the tip (the tip itself where it lies on the cell's
boundary), each with an n x n Gauss rule in collapsed coordinates whose Jacobian, zero at the
fan's apex, cancels the 1 / r of the energy density at the tip (almost-polar integration,
Laborde, Pommier, Renard & Salaun 2005, doi:10.1002/nme.1370).
"""

from __future__ import annotations

import numpy as np

from contactfx.contact.cut import vertex_distances

__all__ = ["STAR_POINTS", "branch", "snapped_point", "star_rule", "tip_split"]

#: the collapsed Gauss rule's points per direction: n x n points per triangle, three triangles
#: at most per cell (the tip's cut cell: a triangle and a quadrilateral)
STAR_POINTS = 3


def branch(
    points: np.ndarray,
    tip: np.ndarray,
    e1: np.ndarray,
    normal: np.ndarray,
    side: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """F and grad F (module docstring) at ``points`` (..., 2) about ``tip``, e1 the unit
    direction ahead of the tip, ``normal`` the crack's normal (F > 0 on its side). ``side``
    (...,): the side (+-1) of points in a cut cell (the sides of the cell's zero line of the
    interpolated level set, which may differ from the true line's within the snap tolerance),
    NaN or None for the true line's side."""
    e2 = np.array([-e1[1], e1[0]])
    s_t = 1.0 if float(e2 @ normal) > 0.0 else -1.0
    d = points - tip
    y1, y2 = d @ e1, d @ e2
    r = np.hypot(y1, y2)
    true_side = np.where(s_t * y2 >= 0.0, 1.0, -1.0)
    if side is not None:
        true_side = np.where(np.isnan(side), true_side, side)
    F = true_side * np.sqrt(np.maximum(r - y1, 0.0) / 2.0)
    G = np.sqrt(np.maximum(r + y1, 0.0) / 2.0)
    safe = np.where(r > 0.0, 2.0 * r, 1.0)
    grad = (-F / safe)[..., None] * e1 + (s_t * G / safe)[..., None] * e2
    return F, grad


def tip_split(
    X: np.ndarray, flags: np.ndarray, points: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The tip nodes' share of a P1 field in the triangles X (cells, 3, 2) with tip-node flags
    (cells, 3), at ``points`` (cells, q, 2): with lambda_i the barycentric coordinates,
    L = sum_i flag_i lambda_i and P = sum_i flag_i lambda_i X_i at the points, and the cells'
    gL = sum_i flag_i grad lambda_i, gP = sum_i flag_i X_i (x) grad lambda_i: the tip part of
    a at y is L a(x) + grad a (P - L x), its gradient a(x) (x) gL + grad a (gP - x (x) gL)
    (exact for P1 a, from its value and gradient at any point x of the cell)."""
    A = np.stack([X[:, 1] - X[:, 0], X[:, 2] - X[:, 0]], axis=2)  # (m, 2, 2)
    Ainv = np.linalg.inv(A)
    mu = np.einsum("mij,mqj->mqi", Ainv, points - X[:, None, 0])  # lambda_1, lambda_2
    lam = np.concatenate([1.0 - mu.sum(axis=2, keepdims=True), mu], axis=2)  # (m, q, 3)
    f = flags.astype(float)
    L = np.einsum("mqi,mi->mq", lam, f)
    P = np.einsum("mqi,mi,mik->mqk", lam, f, X)
    glam = np.concatenate([-Ainv.sum(axis=1, keepdims=True), Ainv], axis=1)  # (m, 3, 2)
    gL = np.einsum("mi,mik->mk", f, glam)
    gP = np.einsum("mi,mij,mik->mjk", f, X, glam)
    return L, P, gL, gP


def snapped_point(X: np.ndarray, point: np.ndarray, snap: float) -> np.ndarray:
    """The point put on the edge or node of the first triangle of X (cells, 3, 2) that holds
    it, when it lies within ``snap`` of them (its barycentric coordinates there set to zero);
    NaN if no triangle holds it."""
    dist = vertex_distances(X, point)
    holds = np.flatnonzero(np.all(dist >= -snap, axis=1))
    if len(holds) == 0:
        return np.full(2, np.nan)
    c = holds[0]
    # the barycentric coordinates are the distances times the opposite edges (over 2 |K|)
    edges = np.linalg.norm(X[c, [2, 0, 1]] - X[c, [1, 2, 0]], axis=1)
    b = np.where(dist[c] < snap, 0.0, dist[c]) * edges
    return b @ X[c] / b.sum()


def _collapsed(n: int) -> tuple[np.ndarray, np.ndarray]:
    """(n * n, 2) collapsed coordinates (xi, eta) in [0, 1]^2 and weights w_i w_j xi_i of the
    triangle apex + xi (b - apex) + xi eta (c - b) (times twice its area)."""
    g, w = np.polynomial.legendre.leggauss(n)
    g, w = 0.5 * (g + 1.0), 0.5 * w
    xi, eta = np.meshgrid(g, g, indexing="ij")
    wx, we = np.meshgrid(w, w, indexing="ij")
    return np.column_stack([xi.ravel(), eta.ravel()]), (wx * we * xi).ravel()


def _side_polygons(tri: np.ndarray, phi: np.ndarray) -> list[tuple[float, np.ndarray]]:
    """The two sides (+1, -1) of a triangle cut by the zero line of the linear phi, as
    polygons (k, 2) of positive area."""
    out: list[tuple[float, np.ndarray]] = []
    for s in (1.0, -1.0):
        vertices: list[np.ndarray] = []
        for i in range(3):
            j = (i + 1) % 3
            if s * phi[i] >= 0.0:
                vertices.append(tri[i])
            if phi[i] * phi[j] < 0.0:
                t = phi[i] / (phi[i] - phi[j])
                vertices.append(tri[i] + t * (tri[j] - tri[i]))
        poly = np.asarray(vertices)
        if len(poly) >= 3:
            e = poly[1:] - poly[0]
            area = 0.5 * abs(np.sum(e[:-1, 0] * e[1:, 1] - e[:-1, 1] * e[1:, 0]))
            if area > 0.0:
                out.append((s, poly))
    return out


def _fan(poly: np.ndarray, tip: np.ndarray, tol: float) -> list[np.ndarray]:
    """Triangles (3, 2) fanned from the polygon's vertex nearest the tip, the tip's foot on an
    edge first made a vertex where the tip lies within ``tol`` of that edge (and not of a
    vertex)."""
    k = len(poly)
    d = np.linalg.norm(poly - tip, axis=1)
    if d.min() > tol:
        for i in range(k):
            a, b = poly[i], poly[(i + 1) % k]
            e = b - a
            t = float((tip - a) @ e / (e @ e))
            if 0.0 < t < 1.0 and np.linalg.norm(a + t * e - tip) <= tol:
                poly = np.insert(poly, i + 1, a + t * e, axis=0)
                break
        d = np.linalg.norm(poly - tip, axis=1)
    poly = np.roll(poly, -int(np.argmin(d)), axis=0)
    return [np.array([poly[0], poly[i], poly[i + 1]]) for i in range(1, len(poly) - 1)]


def star_rule(
    X: np.ndarray,
    phi: np.ndarray,
    cut: np.ndarray,
    cell_side: np.ndarray,
    tips: np.ndarray,
    slots: int,
    snap: float = 0.0,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """A rule for the star cells X (cells, 3, 2) (module docstring): points (cells, slots, 2),
    weights (cells, slots) (zero in the unused slots), and each point's side: the side of the
    cell's zero line of phi (cells, 3) in a cut cell, ``cell_side`` (cells,) elsewhere; and
    ``cut_side`` (cells, slots), that side in the cut cells and NaN elsewhere (for
    :func:`branch`). ``tips`` (cells, 2): the tip each cell is around, on a cell's boundary
    if nearer to it than ``snap`` (as the level set's snap puts nodes on the crack's line)."""
    m = len(X)
    ref, ref_w = _collapsed(STAR_POINTS)
    points = np.repeat(X.mean(axis=1)[:, None, :], slots, axis=1)
    weights = np.zeros((m, slots))
    side = np.repeat(cell_side[:, None], slots, axis=1).astype(float)
    cut_side = np.full((m, slots), np.nan)
    for c in range(m):
        h = np.linalg.norm(X[c, 1:] - X[c, 0], axis=1).max()
        parts = _side_polygons(X[c], phi[c]) if cut[c] else [(cell_side[c], X[c])]
        q = 0
        for s, poly in parts:
            for t in _fan(poly, tips[c], max(snap, 1e-9 * h)):
                area = 0.5 * abs(
                    (t[1, 0] - t[0, 0]) * (t[2, 1] - t[0, 1])
                    - (t[1, 1] - t[0, 1]) * (t[2, 0] - t[0, 0])
                )
                n = len(ref_w)
                if q + n > slots:
                    raise ValueError("a star cell needs more quadrature points than its rule")
                xi, eta = ref[:, :1], ref[:, 1:]
                points[c, q : q + n] = t[0] + xi * (t[1] - t[0]) + xi * eta * (t[2] - t[1])
                weights[c, q : q + n] = ref_w * 2.0 * area
                side[c, q : q + n] = s
                if cut[c]:
                    cut_side[c, q : q + n] = s
                q += n
    return points, weights, side, cut_side
