"""Unfitted cracks: a straight crack on a triangle mesh that does not follow it.

Geometry (level sets, numpy). A crack is the segment from p0 to p1 with unit direction d and
normal n (d turned by +90 degrees). Its level sets are phi(x) = (x - c) . n (signed distance to
the crack's line; > 0 on the +side) and psi(x) = (x - c) . d (c the midpoint; the crack is
phi = 0, |psi| <= a). phi is taken as its P1 interpolant phi_h at the mesh nodes, with
|phi_i| < ``SNAP`` h set to 0 (h the smallest cell size among the cells near the crack, the
same on every rank): a crack passing that near a node is moved onto the node, so that no cell
near the crack is cut into a sliver thinner than 1e-2 of the smallest cell (the conditioning of
the enrichment is bounded) and a crack through a node, along an edge, or at 1e-6 h of a node
is one case. Per cell (:class:`CutCells`):

* a *cut* cell: the zero line of phi_h crosses it along a piece of positive length with both
  ends inside the crack (|psi| <= a); a piece along an edge belongs to the cell on the +side;
* a *tip* cell: its closed triangle contains a tip and its zero line (if any) does not lie
  on the crack, or its piece ends beyond a tip;
* the +side's area fraction f of the cell (exact for the piecewise linear phi_h); 1 or 0 in a
  cell that phi_h does not cross.

Kinematics (Heaviside enrichment; Moes, Dolbow & Belytschko 1999,
doi:10.1002/(SICI)1097-0207(19990910)46:1<131::AID-NME726>3.0.CO;2-J). The displacement is
w = u + H a with H = +1 / -1 on the two sides of phi_h = 0 inside the cells, u and a P1. a is
nonzero only at the *enriched* nodes: those of a cut cell whose support the crack crosses
completely (area on both sides, no tip inside the support). Across the crack [[w]] = 2 a;
elsewhere w is continuous. At the tips: a tip inside a cell is first moved along the crack to
the nearer of the two points where the crack's line crosses that cell's boundary
(:func:`snapped_tips`, by at most half the cell), so that every tip lies on a node or an edge.
The node at the tip, or the two nodes of the tip's edge (``tip_nodes``), carry the branch
function sqrt(r) sin(theta / 2) instead of H (:mod:`contactfx.contact.tip`): the jump vanishes
at the tip and opens as sqrt(r) next to it. With those nodes unenriched (the jump falling
linearly to zero over the last cut cells) K was about 1 % lower (docs/verification.md
section 14).

Integrals. For P1 the strain is constant on each side of a cut cell, so the bulk energy is
f W(eps(u + a)) + (1 - f) W(eps(u - a)) times the cell's area: a DG0 coefficient f keeps it in
UFL and exact. The crack's integrals run along the piece of each cut cell with a Gauss rule of
the cell's quadrature-point count (:class:`CrackQuadrature`): a cell integral over the cut
cells whose integrand, at the cell's k-th quadrature point x_k, is evaluated at the piece's
k-th Gauss point y_k through the Taylor expansion f(y) = f(x) + grad f(x) . (y - x) (exact for
P1 fields), times the weight ratio (the Gauss weight over the cell rule's weight and Jacobian):
the crack integrals are UFL, with exact Jacobians, and the methods write them as for a fitted
interface (:class:`CutSurface`).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import ufl

from contactfx.contact.interface import InterfaceSurface
from contactfx.contact.laws import Expr, tangential

if TYPE_CHECKING:
    from typing import Self

    from contactfx.contact.surface import Form

__all__ = [
    "SNAP",
    "CrackSegment",
    "CutCells",
    "CrackQuadrature",
    "CutSurface",
    "WeightedMeasure",
    "cut_cells",
    "snapped_tips",
    "vertex_distances",
    "cell_sizes",
    "near_cells",
    "CoarseGrid",
]

#: a node within SNAP times its size of the crack's line is moved onto it
SNAP = 1e-2


@dataclass(frozen=True)
class CrackSegment:
    """The straight crack from p0 to p1 (2D points)."""

    p0: np.ndarray
    p1: np.ndarray

    def __post_init__(self) -> None:
        if not np.linalg.norm(np.asarray(self.p1) - np.asarray(self.p0)) > 0.0:
            raise ValueError(f"crack segment of zero length at {self.p0}")

    @property
    def centre(self) -> np.ndarray:
        return 0.5 * (np.asarray(self.p0, float) + np.asarray(self.p1, float))

    @property
    def half_length(self) -> float:
        return 0.5 * float(np.linalg.norm(np.asarray(self.p1) - np.asarray(self.p0)))

    @property
    def direction(self) -> np.ndarray:
        d = np.asarray(self.p1, float) - np.asarray(self.p0, float)
        return d / np.linalg.norm(d)

    @property
    def normal(self) -> np.ndarray:
        d = self.direction
        return np.array([-d[1], d[0]])

    def phi(self, x: np.ndarray) -> np.ndarray:
        """Signed distance to the crack's line of the points x (..., 2)."""
        return (x - self.centre) @ self.normal

    def psi(self, x: np.ndarray) -> np.ndarray:
        """Coordinate along the crack from its midpoint."""
        return (x - self.centre) @ self.direction

    def tips(self) -> list[np.ndarray]:
        return [np.asarray(self.p0, float), np.asarray(self.p1, float)]


@dataclass
class CutCells:
    """What a crack does to the local cells (owned and ghosts) of a triangle mesh (module
    docstring): ``phi`` (cells, 3) the snapped level set at each cell's vertices; ``fraction``
    (cells,) the +side's area fraction; ``cut`` (cells,) bool, and ``pieces`` (cells, 2, 2) the
    crack's piece in each cut cell (NaN elsewhere); ``tip`` (cells,) bool; ``tip_nodes``
    (cells, 3) bool: the vertices whose support holds a tip inside (in a cell containing
    the tip, farther than ``snap`` from the vertex's opposite edge)."""

    phi: np.ndarray
    fraction: np.ndarray
    cut: np.ndarray
    pieces: np.ndarray
    tip: np.ndarray
    tip_nodes: np.ndarray


def cell_sizes(X: np.ndarray) -> np.ndarray:
    """(cells,): the longest edge of each triangle X (cells, 3, 2)."""
    e = np.stack([np.linalg.norm(X[:, (i + 1) % 3] - X[:, i], axis=1) for i in range(3)], 1)
    return e.max(axis=1, initial=0.0)


def near_cells(X: np.ndarray, crack: CrackSegment) -> np.ndarray:
    """Bool (cells,): the triangles within their own size of the crack's segment."""
    c = X.mean(axis=1)
    s = np.clip(crack.psi(c), -crack.half_length, crack.half_length)
    foot = crack.centre + s[:, None] * crack.direction
    return np.linalg.norm(c - foot, axis=1) <= cell_sizes(X)


def _zero_line(X: np.ndarray, phi: np.ndarray) -> np.ndarray:
    """(cells, 2, 2): the ends of the zero set of the linear phi in each triangle where it is
    a segment (two distinct points: sign changes along edges, or two zero vertices); NaN where
    it is empty or a point."""
    m = len(X)
    pts = np.full((m, 4, 2), np.nan)
    count = np.zeros(m, dtype=int)
    for i in range(3):  # zero vertices
        z = phi[:, i] == 0.0
        pts[z, count[z]] = X[z, i]
        count[z] += 1
    for i in range(3):  # strict sign changes along the edges
        j = (i + 1) % 3
        c = phi[:, i] * phi[:, j] < 0.0
        t = phi[c, i] / (phi[c, i] - phi[c, j])
        pts[c, count[c]] = X[c, i] + t[:, None] * (X[c, j] - X[c, i])
        count[c] += 1
    out = np.full((m, 2, 2), np.nan)
    two = count == 2
    out[two] = pts[two, :2]
    return out


def _positive_fraction(X: np.ndarray, phi: np.ndarray) -> np.ndarray:
    """Area fraction of {phi > 0} of each triangle, phi linear with vertex values phi."""
    frac = np.where(phi.sum(axis=1) > 0.0, 1.0, 0.0)
    pos, neg = phi > 0.0, phi < 0.0
    for lone, sign in ((pos, 1.0), (neg, -1.0)):
        # one vertex strictly on one side, the other two strictly on the other: the lone
        # vertex's corner triangle has the fraction t1 t2 (the edge fractions to the zero line)
        one = (lone.sum(axis=1) == 1) & ((pos if sign < 0 else neg).sum(axis=1) == 2)
        if not np.any(one):
            continue
        i = np.argmax(lone[one], axis=1)
        p = phi[one]
        r = np.arange(len(p))
        pi, pj, pk = p[r, i], p[r, (i + 1) % 3], p[r, (i + 2) % 3]
        corner = (pi / (pi - pj)) * (pi / (pi - pk))
        frac[one] = corner if sign > 0 else 1.0 - corner
    # one zero vertex with the other two on opposite sides: the zero line halves the triangle
    # through that vertex, in the ratio of the opposite edge's parts
    zero = (phi == 0.0).sum(axis=1) == 1
    split = zero & (pos.sum(axis=1) == 1) & (neg.sum(axis=1) == 1)
    if np.any(split):
        p = phi[split]
        i = np.argmax(p == 0.0, axis=1)
        r = np.arange(len(p))
        pj, pk = p[r, (i + 1) % 3], p[r, (i + 2) % 3]
        t = pj / (pj - pk)  # fraction of the edge j -> k on j's side
        frac[split] = np.where(pj > 0.0, t, 1.0 - t)
    return frac


def _barycentric(X: np.ndarray, point: np.ndarray) -> np.ndarray:
    """(cells, 3): the point's barycentric coordinates in each triangle of X."""
    A = np.stack([X[:, 1] - X[:, 0], X[:, 2] - X[:, 0]], axis=2)  # (m, 2, 2)
    lam = np.linalg.solve(A, (point - X[:, 0])[:, :, None])[:, :, 0]
    return np.column_stack([1.0 - lam.sum(axis=1), lam])


def vertex_distances(X: np.ndarray, point: np.ndarray) -> np.ndarray:
    """(cells, 3): the point's signed distance to each vertex's opposite edge in each triangle
    of X (its barycentric coordinate times the vertex's height; >= 0 inside)."""
    e = [X[:, (i + 2) % 3] - X[:, (i + 1) % 3] for i in range(3)]
    area2 = np.abs(e[0][:, 0] * e[1][:, 1] - e[0][:, 1] * e[1][:, 0])
    height = area2[:, None] / np.stack([np.linalg.norm(ei, axis=1) for ei in e], axis=1)
    return _barycentric(X, point) * height


def _contains(X: np.ndarray, point: np.ndarray, tol: float) -> np.ndarray:
    """Whether each closed triangle of X contains the point (barycentric, within tol)."""
    return np.all(_barycentric(X, point) >= -tol, axis=1)


def cut_cells(X: np.ndarray, crack: CrackSegment, snap: float) -> CutCells:
    """Classify the triangles X (cells, 3, 2) against ``crack`` (module docstring), the level
    set phi set to 0 at the nodes nearer than ``snap`` to the crack's line."""
    phi = crack.phi(X)
    phi = np.where(np.abs(phi) < snap, 0.0, phi)
    line = _zero_line(X, phi)
    a = crack.half_length
    has = ~np.isnan(line[:, 0, 0])
    ends = np.full((len(X), 2), np.nan)
    ends[has] = crack.psi(line[has])
    tol = 1e-12 * a
    inside = np.all(np.abs(ends) <= a + tol, axis=1)
    touches = (
        has
        & (np.min(ends, axis=1, initial=np.inf) < a - tol)
        & (np.max(ends, axis=1, initial=-np.inf) > -a + tol)
    )
    # a piece along an edge (two zero vertices) belongs to the cell on the +side
    on_edge = (phi == 0.0).sum(axis=1) == 2
    plus_side = phi.sum(axis=1) > 0.0
    cut = has & inside & (~on_edge | plus_side)
    tip = touches & ~inside
    tip_nodes = np.zeros((len(X), 3), dtype=bool)
    # a tip within ``snap`` of an edge or a node is on it, as a node within ``snap`` of the
    # crack's line is
    for t in crack.tips():
        dist = vertex_distances(X, np.asarray(t, float))
        holds = np.all(dist >= -max(snap, 1e-10 * a), axis=1)
        # (a cell along the crack, cut or the -side's twin of an edge piece, is not a tip cell)
        tip |= holds & ~(has & inside)
        tip_nodes |= holds[:, None] & (dist > max(snap, 1e-10 * a))
    cut &= ~tip
    pieces = np.where(cut[:, None, None], line, np.nan)
    return CutCells(phi, _positive_fraction(X, phi), cut, pieces, tip, tip_nodes)


def snapped_tips(X: np.ndarray, crack: CrackSegment, snap: float) -> list[float]:
    """The coordinate psi of each tip (-a, +a) moved to the nearer end of the crack line's
    piece in the cell that holds the tip strictly inside (where the line enters the cell or
    leaves it): NaN for a tip that no cell of X holds so (outside X, or on an edge or node)."""
    phi = crack.phi(X)
    phi = np.where(np.abs(phi) < snap, 0.0, phi)
    line = _zero_line(X, phi)
    has = ~np.isnan(line[:, 0, 0])
    a = crack.half_length
    out = []
    for sign, t in ((-1.0, crack.p0), (1.0, crack.p1)):
        ends = np.sort(crack.psi(line[has]) * sign, axis=1)  # along the crack, towards the tip
        strict = (ends[:, 0] < a - 1e-12 * a) & (ends[:, 1] > a + 1e-12 * a)
        hold = np.flatnonzero(strict & _contains(X[has], np.asarray(t, float), 1e-10))
        if len(hold) == 0:
            out.append(float("nan"))
            continue
        entry, exit_ = ends[hold[0]]
        out.append(sign * (exit_ if exit_ - a < a - entry else entry))
    return out


class CrackQuadrature:
    """Gauss points on the crack's pieces as the points of a cell rule (module docstring):
    for ``rule`` = (reference points (nq, 2), weights (nq,)) of the cell integrals, the
    piece of each cut cell gets nq Gauss-Legendre points ``points`` (cells, nq, 2) and the
    weight ratios ``ratio`` (cells, nq) = Gauss weight / (cell weight |det J|); zero in the
    other cells."""

    def __init__(self, X: np.ndarray, cells: CutCells, rule: tuple[np.ndarray, np.ndarray]) -> None:
        ref_w = np.asarray(rule[1])
        nq = len(ref_w)
        xi, w = np.polynomial.legendre.leggauss(nq)
        m = len(X)
        self.points = np.repeat(X.mean(axis=1)[:, None, :], nq, axis=1)
        self.ratio = np.zeros((m, nq))
        c = np.flatnonzero(cells.cut)
        p0, p1 = cells.pieces[c, 0], cells.pieces[c, 1]
        t = 0.5 * (1.0 + xi)
        self.points[c] = p0[:, None, :] + t[None, :, None] * (p1 - p0)[:, None, :]
        length = np.linalg.norm(p1 - p0, axis=1)
        e1, e2 = X[c, 1] - X[c, 0], X[c, 2] - X[c, 0]
        det = np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])
        self.ratio[c] = 0.5 * length[:, None] * w[None, :] / (ref_w[None, :] * det[:, None])


class CoarseGrid:
    """A multiplier along the crack, piecewise linear in psi on a grid coarser than the cut
    cells (the coarse-grained multiplier of Akula, Vignollet & Yastrebov 2019, MorteX,
    arXiv:1902.04000). The multiplier whose values are the law's at every piece (or its
    nodal trace) is not stable: a piece that clips a cell's corner moves the enrichment of a
    far node with a small lever, and the multiplier that closes it grows without bound (Bechet,
    Moes & Wohlmuth 2009, doi:10.1002/nme.2515; docs/verification.md section 14). The grid's
    nodes are the crack's crossings of the cells' edges ``psi`` (in any order, repeated) with
    the sizes ``size`` of the cells there: the first and the last, and each crossing at least
    ``factor`` times its size beyond the last node kept (the last node moves to the crack's
    end if that is nearer)."""

    def __init__(self, psi: np.ndarray, size: np.ndarray, factor: float) -> None:
        psi, size = np.asarray(psi, float), np.asarray(size, float)
        order = np.lexsort((size, psi))  # the same grid whatever the order (ranks) given
        psi, size = psi[order], size[order]
        nodes = [psi[0]]
        for p, h in zip(psi[1:], size[1:], strict=True):
            if p - nodes[-1] >= factor * h:
                nodes.append(p)
        if psi[-1] > nodes[-1]:
            if len(nodes) > 1 and psi[-1] - nodes[-1] < factor * size[-1]:
                nodes[-1] = psi[-1]
            else:
                nodes.append(psi[-1])
        self.nodes = np.asarray(nodes)

    def hats(self, psi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(left node, weight of the right node) of the points psi (clipped to the grid)."""
        x = np.clip(psi, self.nodes[0], self.nodes[-1])
        i = np.clip(np.searchsorted(self.nodes, x, side="right") - 1, 0, len(self.nodes) - 2)
        return i, (x - self.nodes[i]) / (self.nodes[i + 1] - self.nodes[i])

    def moments(
        self, psi: np.ndarray, weights: np.ndarray, values: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """(int phi_j v, int phi_j) of the grid's hat functions phi_j against the values
        (points, components) at the points psi with the quadrature weights: one rank's part
        of the lumped L2 projection (sum them over the ranks, then divide)."""
        i, t = self.hats(psi)
        n = len(self.nodes)
        num = np.zeros((n, values.shape[1]))
        den = np.zeros(n)
        for j, phi in ((i, 1.0 - t), (i + 1, t)):
            np.add.at(num, j, (weights * phi)[:, None] * values)
            np.add.at(den, j, weights * phi)
        return num, den

    def evaluate(self, psi: np.ndarray, nodal: np.ndarray) -> np.ndarray:
        """The piecewise linear field of ``nodal`` (nodes, components) at the points psi."""
        i, t = self.hats(psi)
        return (1.0 - t)[:, None] * nodal[i] + t[:, None] * nodal[i + 1]


class WeightedMeasure(ufl.Measure):
    """A measure that multiplies every integrand by ``weight`` (``integrand * measure``)."""

    def __init__(self, measure: ufl.Measure, weight: Expr) -> None:
        super().__init__(
            measure.integral_type(),
            domain=measure.ufl_domain(),
            subdomain_id=measure.subdomain_id(),
            metadata=measure.metadata(),
            subdomain_data=measure.subdomain_data(),
        )
        self.weight = weight

    def __rmul__(self, integrand: Expr | float) -> Form:
        if isinstance(integrand, (int, float)):
            integrand = ufl.as_ufl(integrand)
        return super().__rmul__(self.weight * integrand)


@dataclass(frozen=True)
class CutSurface(InterfaceSurface):
    """:class:`contactfx.contact.interface.InterfaceSurface` on an unfitted crack (module
    docstring): ``w`` / ``v_total`` are the unknown U = (u, a_1, ...) and its test function
    (the crack's enrichment from component ``first``); ``ds``
    a :class:`WeightedMeasure` on the cut cells; ``stress_cell`` / ``stress_test_cell`` the
    sides' stress weighted by their area fractions; ``H`` the crack's normal n_I; ``at_crack``
    maps a P1 field to its value at the crack's Gauss points, ``at_law`` to its value at the
    midpoint of each cell's piece (:meth:`tip_extended`)."""

    at_crack: Callable[[Expr], Expr] | None = None
    at_law: Callable[[Expr], Expr] | None = None
    #: the enrichment's half jump at the Gauss points and at the pieces' midpoints (the tip
    #: enrichment's part included: contactfx.contact.tip); None: ``at_crack`` / ``at_law``
    at_jump: Callable[[Expr], Expr] | None = None
    at_jump_law: Callable[[Expr], Expr] | None = None
    #: the first component of this crack's enrichment in U = (u, a_1, ..., a_K)
    first: int = 2

    def jump(self, X: Expr) -> Expr:
        """[[w]] = 2 a at the crack's Gauss points (2 (a_H + sqrt(r) a_T) with the tip
        enrichment), for X = (u, a_1, ...) (the unknown, its test or trial function)."""
        half = self.at_crack if self.at_jump is None else self.at_jump
        assert half is not None  # the driver gives at_crack
        return 2.0 * half(ufl.as_vector([X[self.first + i] for i in range(2)]))

    @property
    def u(self) -> Expr:
        return self.jump(self.w)

    @property
    def v(self) -> Expr:
        return self.jump(self.v_total)

    @property
    def h(self) -> Expr:
        return self.h_cell

    @property
    def stress(self) -> Expr:
        s = self.stress_cell
        if self.fluid is not None:
            s = s + self.fluid * self._identity()
        return s

    @property
    def stress_test(self) -> Expr:
        return self.stress_test_cell

    def _identity(self) -> Expr:
        return ufl.Identity(ufl.shape(self.H)[0])

    def interface_normal(self) -> Expr:
        return self.H

    def opening(self, w: Expr | None = None) -> Expr:
        jump = self.u if w is None else self.jump(w)
        return ufl.dot(jump, self.interface_normal())

    def tip_extended(self) -> Self:
        """The surface that the law of a method collocated at a fitted crack's nodes (the
        penalty: ``tip_continued``) reads: its motion at the midpoint of each cut cell's
        piece, where the linear jump takes its mean, so that the law is one value per piece.
        At the piece's six Gauss points instead the penalty's pressure oscillated from cut
        cell to cut cell, the more the stiffer the penalty (docs/verification.md section 14).
        No midpoint lies at a tip: no tip needs a continuation."""
        if self.at_law is None:
            return self
        return dataclasses.replace(self, at_crack=self.at_law, at_jump=self.at_jump_law)

    def slip_increment(self, n: Expr) -> Expr:
        if self.u_prev is None:
            raise ValueError("the slip increment needs the previous state (friction only)")
        return tangential(self.u - self.jump(self.u_prev), n)
