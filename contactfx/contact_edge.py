"""The contact size from the nodal contact pressure and gap.

The default (:class:`ContourMeasure`, every obstacle and two-body scene and problem file): the
measure of the region of the contact surface where the P1 interpolant of phi = p - (E* / h) g
is positive, converted to a half-width (2D) or the radius of the disc of the same area (3D) by
the scene's rule. The edge of a contact lies between the last closed node (p > 0, g = 0) and
the first open one (p = 0, g > 0): phi changes sign there and its linear interpolant puts the
edge at its zero, on a triangle the zero contour. One rule for every method, geometry and
symmetry (no axis, band or symmetry plane to name), for the nodal pressure of Nitsche,
penalty, the augmented Lagrangian and bound-constrained methods and the mortar multiplier. The
measure of the closed set (the nodes or Gauss points with p > 0) is biased outwards by up to
h / 2, more where the pressure leaks to the first open node (a reaction, a multiplier).

The explicit rules of a problem file's ``contact.0.edge`` (:func:`contact_edge`) extrapolate
p^2 (near the edge of a smooth contact p ~ sqrt(a - s), p^2 linear in the distance to the
edge) from the two outermost closed nodes, clipped to the interval between the last closed
node and the first open one:

- ``x-max``: the edge on the side of growing x (a symmetric contact modelled on x >= 0);
- ``x-band``: half the distance between the edges on both sides in x (a full 2D model; the
  band may move); refused when the slave surface lies on one side of x = 0 (a half or quarter
  model, whose x = 0 is a symmetry plane: ``x-max``);
- ``radial``: the radius about the axis x = y = 0 from rings of the slave element size (3D).
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "ContourMeasure",
    "facet_dofs",
    "CONTACT_EDGES",
    "line_edge",
    "radial_edge",
    "contact_edge",
    "check_edge_rule",
]

#: the rules of :func:`contact_edge`
CONTACT_EDGES = ("x-max", "x-band", "radial")


def _clip(edge: float, last: float, first_open: float | None) -> float:
    """The edge within [last closed, first open] (no upper bound without an open node)."""
    edge = max(edge, last)
    return edge if first_open is None else min(edge, first_open)


def line_edge(s: np.ndarray, p: np.ndarray, s_open: np.ndarray | None = None) -> float | None:
    """The edge of a smooth contact on the side of growing s from the closed nodes at s with
    the pressures p > 0: the zero of the straight line through (s, p^2) at the two outermost
    closed nodes, clipped to the interval from the outermost closed node to the first open
    node beyond it (s_open: the open nodes' s; None: no clipping above). None with fewer than
    two closed nodes."""
    if len(s) < 2:
        return None
    order = np.argsort(s)
    (x1, x2), (p1, p2) = s[order][-2:], p[order][-2:]
    beyond = None if s_open is None else s_open[s_open > x2]
    first_open = None if beyond is None or len(beyond) == 0 else float(beyond.min())
    if not p1 > p2:
        return float(x2)
    return _clip(float(x2 + p2**2 * (x2 - x1) / (p1**2 - p2**2)), float(x2), first_open)


def radial_edge(
    r: np.ndarray, p: np.ndarray, width: float, r_open: np.ndarray | None = None
) -> float | None:
    """The radius of a round contact area from its closed nodes at the radii r with the
    pressures p > 0: the closed nodes are binned in rings of ``width`` (the slave element
    size), each ring gives its mean radius and mean p^2, and the straight line of p^2 through
    the two outermost rings is extrapolated to zero (for Hertz p^2 = p0^2 (1 - r^2 / a^2)
    exactly linear in r^2, and the line in r errs by O((width / a)^2)), clipped to the interval
    from the outermost ring's mean radius to the mean radius of the open nodes (r_open) of
    that ring and the next (where the zero contour lies). Averaging over a ring of nodes
    smooths the scatter of single nodes of an unstructured surface mesh. None with fewer than
    two rings."""
    if len(r) == 0:
        return None
    ring = np.floor(r / width).astype(np.int64)
    rings, inv = np.unique(ring, return_inverse=True)
    if len(rings) < 2:
        return None
    count = np.bincount(inv)
    r_mean = np.bincount(inv, weights=r) / count
    p2_mean = np.bincount(inv, weights=p**2) / count
    (r1, r2), (q1, q2) = r_mean[-2:], p2_mean[-2:]
    if not q1 > q2:
        return float(r2)
    first_open = None
    if r_open is not None:
        near = r_open[(r_open > r2) & (r_open < (rings[-1] + 2) * width)]
        first_open = float(near.mean()) if len(near) else None
    return _clip(float(r2 + q2 * (r2 - r1) / (q1 - q2)), float(r2), first_open)


def contact_edge(
    rule: str | None,
    x: np.ndarray,
    p: np.ndarray,
    ring: float | None = None,
    closed: np.ndarray | None = None,
) -> float | None:
    """The contact half-width / radius from the slave surface nodes x (all ranks) with the
    nodal pressures p by the rule (see the module); ``closed`` marks the closed nodes (None:
    p > 0, with no open node to clip by). None (no rule, or too few closed nodes) for the
    measure of the closed nodes."""
    if rule is None:
        return None
    closed = p > 0.0 if closed is None else closed
    xc, pc, xo = x[closed], p[closed], x[~closed]
    if rule == "x-max":
        return line_edge(xc[:, 0], pc, xo[:, 0])
    if rule == "x-band":
        right, left = line_edge(xc[:, 0], pc, xo[:, 0]), line_edge(-xc[:, 0], pc, -xo[:, 0])
        return None if right is None or left is None else 0.5 * (right + left)
    if rule == "radial":
        return radial_edge(np.hypot(xc[:, 0], xc[:, 1]), pc, ring, np.hypot(xo[:, 0], xo[:, 1]))
    raise ValueError(f"unknown contact edge rule {rule!r}")


def check_edge_rule(rule: str | None, x: np.ndarray, gdim: int, where: str = "edge") -> None:
    """Refuse, in one line (ValueError), a rule that does not apply to the slave surface
    nodes x (all ranks): ``x-band`` on a surface on one side of x = 0 (a half or quarter model:
    the band's other edge is the mirror image, use ``x-max``), ``radial`` in 2D."""
    if rule is None or len(x) == 0:
        return
    span = float(np.ptp(x[:, 0])) or 1.0
    if rule == "x-band" and (x[:, 0].min() >= -1e-9 * span or x[:, 0].max() <= 1e-9 * span):
        raise ValueError(
            f"{where} = 'x-band' does not apply: the slave surface lies on one side of x = 0 "
            "(a symmetry plane of a half or quarter model); use 'x-max'"
        )
    if rule == "radial" and gdim != 3:
        raise ValueError(f"{where} = 'radial' applies in 3D only; use 'x-max' or 'x-band'")


class ContourMeasure:
    """The measure of the contact set as the region where the P1 interpolant, on the contact
    surface's facets, of phi = p - (E* / h_f) g is positive: p the nodal contact pressure, g
    the nodal gap, E* the contact modulus (Hertz's: E / (1 - nu^2) against a rigid obstacle, 1
    / sum (1 - nu^2) / E over the two bodies of a pair) and h_f the facet's longest edge (phi
    is the active-set function of Nitsche's method and the augmented Lagrangian with gamma =
    E* / h: a pressure over an element's compliance). On a segment the positive part is cut at
    phi's zero, on a triangle the region enclosed by the zero contour is taken. A pressure that
    leaks to the first open node (a reaction, an augmented Lagrangian's multiplier) is
    outweighed there by the gap. With ``axisymmetric`` the measure of a segment is its
    integral of r = x[:, 0] (times the scene's 2 pi symmetry, the area).

    ``dofs``: (facets, nodes) the owned contact facets' P1 dofs (local, ghosts included), ``x``
    the P1 dof coordinates.
    """

    def __init__(self, dofs: np.ndarray, x: np.ndarray, axisymmetric: bool = False) -> None:
        self.dofs = np.asarray(dofs, dtype=np.int64)
        self.pts = x[self.dofs]
        nv = self.dofs.shape[1]
        #: segments and triangles (the contour of quadrilateral facets is not implemented)
        self.supported = nv in (2, 3)
        self.axisymmetric = axisymmetric
        edges = [
            np.linalg.norm(self.pts[:, i] - self.pts[:, j], axis=1)
            for i in range(nv)
            for j in range(i)
        ]
        #: the facets' longest edges
        self.size = np.max(edges, axis=0) if edges else np.zeros(len(self.dofs))

    def __call__(self, p: np.ndarray, g: np.ndarray, modulus: float) -> float:
        """This rank's measure of {phi_h > 0} for the local nodal arrays p and g."""
        if len(self.dofs) == 0 or not self.supported:
            return 0.0
        phi = p[self.dofs] - (modulus / self.size)[:, None] * g[self.dofs]
        if self.dofs.shape[1] == 2:
            return float(np.sum(self._segments(phi)))
        return float(np.sum(self._triangles(phi)))

    def _segments(self, phi: np.ndarray) -> np.ndarray:
        a, b = self.pts[:, 0], self.pts[:, 1]
        pa, pb = phi[:, 0], phi[:, 1]
        # the positive part [t0, t1] of the parameter t in [0, 1] along a -> b
        with np.errstate(divide="ignore", invalid="ignore"):
            t = np.where(pa != pb, pa / (pa - pb), 0.0)
        t0 = np.where(pa > 0, 0.0, np.where(pb > 0, t, 1.0))
        t1 = np.where(pb > 0, 1.0, np.where(pa > 0, t, 0.0))
        length = np.linalg.norm(b - a, axis=1) * np.clip(t1 - t0, 0.0, 1.0)
        if not self.axisymmetric:
            return length
        r = a[:, 0] + 0.5 * (t0 + t1) * (b[:, 0] - a[:, 0])
        return length * r

    def _triangles(self, phi: np.ndarray) -> np.ndarray:
        a, b, c = self.pts[:, 0], self.pts[:, 1], self.pts[:, 2]
        area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
        positive = phi > 0.0
        count = positive.sum(axis=1)
        out = np.where(count == 3, area, 0.0)
        for k, sign in ((1, 1.0), (2, -1.0)):
            sel = count == k
            if not np.any(sel):
                continue
            f = sign * phi[sel]  # the lone vertex (positive for k = 1, negative for k = 2)
            lone = np.argmax(f, axis=1)
            rows = np.arange(len(f))
            others = np.stack([(lone + 1) % 3, (lone + 2) % 3], axis=1)
            f0 = f[rows, lone]
            t = f0[:, None] / (f0[:, None] - f[rows[:, None], others])
            corner = area[sel] * t[:, 0] * t[:, 1]
            out[sel] = corner if k == 1 else area[sel] - corner
        return out


def facet_dofs(Q1, facets: np.ndarray) -> np.ndarray:
    """(owned facets, nodes): the P1 space Q1's dofs of the vertices of the owned ones among
    the local ``facets`` (each facet once over the ranks), through a cell of each (a P1 cell's
    dofs follow its vertices)."""
    mesh = Q1.mesh
    tdim = mesh.topology.dim
    fdim = tdim - 1
    owned = mesh.topology.index_map(fdim).size_local
    facets = np.asarray(facets)[np.asarray(facets) < owned]
    for d0, d1 in ((fdim, tdim), (fdim, 0), (tdim, 0)):
        mesh.topology.create_connectivity(d0, d1)
    f2c, f2v = mesh.topology.connectivity(fdim, tdim), mesh.topology.connectivity(fdim, 0)
    c2v = mesh.topology.connectivity(tdim, 0)
    rows = []
    for f in facets:
        cell = f2c.links(f)[0]
        dof_of = dict(zip(c2v.links(cell), Q1.dofmap.cell_dofs(cell), strict=True))
        rows.append([dof_of[v] for v in f2v.links(f)])
    if not rows:  # no owned contact facet on this rank
        return np.zeros((0, fdim + 1), dtype=np.int64)
    return np.array(rows, dtype=np.int64)
