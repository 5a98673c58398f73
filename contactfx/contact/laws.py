"""Pointwise contact and friction laws as UFL expressions.

Conventions (docs/architecture.md): gap g >= 0 when apart, pressure p >= 0 in compression, g p = 0;
the tangential traction t_T on the body satisfies |t_T| <= s (s = mu p for Coulomb, a given
threshold for Tresca), and it opposes the slip where |t_T| = s.

The Signorini conditions are equivalent, for any r > 0, to p = [p - r g]_+, and the friction
conditions to t_T = proj_{B(0, s)}(t_T - r du_T) with du_T the slip increment (Alart & Curnier
1991, doi:10.1016/0045-7825(91)90022-X): the forms every method here discretises.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TypeAlias

import ufl

__all__ = [
    "Expr",
    "tangential",
    "positive_part",
    "active",
    "ball_projection",
    "reversal",
    "norm",
    "fischer_burmeister",
    "Friction",
    "Tresca",
    "Coulomb",
    "friction_law",
]

#: a UFL expression (a Function, a component of a mixed one, a test function, a Constant;
#: re-exported as :data:`contactfx.contact.surface.Expr`)
Expr: TypeAlias = ufl.core.expr.Expr


def tangential(w: Expr, n: Expr) -> Expr:
    """Tangential part (I - n n) w of the vector w."""
    return w - ufl.dot(w, n) * n


def positive_part(x: Expr) -> Expr:
    """[x]_+ = max(x, 0), with the derivative 0 at x = 0 (semi-smooth Newton)."""
    return ufl.conditional(ufl.gt(x, 0.0), x, 0.0)


def active(x: Expr) -> Expr:
    """Indicator 1 where x > 0, else 0."""
    return ufl.conditional(ufl.gt(x, 0.0), 1.0, 0.0)


def norm(x: Expr, scale: float) -> Expr:
    """|x|, regularised by 1e-12 ``scale`` so that it and its derivative stay finite at 0."""
    return ufl.sqrt(ufl.dot(x, x) + (1e-12 * scale) ** 2)


def ball_projection(x: Expr, s: Expr, scale: float, stick: Expr | None = None) -> Expr:
    """Projection of the vector x onto the ball of radius s >= 0: x where |x| <= s, else
    s x / |x|. ``scale`` is a typical magnitude of x (regularises |x| at 0). ``stick``
    (optional): where it is > 0 and s > 0, x itself whatever |x| (the stick branch; see
    :func:`reversal`)."""
    nx = norm(x, scale)
    inside = ufl.le(nx, s)
    if stick is not None:
        inside = ufl.Or(inside, ufl.And(ufl.gt(stick, 0.0), ufl.gt(s, 0.0)))
    return ufl.conditional(inside, x, s / nx * x)


def reversal(x: Expr, x_last: Expr, s: Expr) -> Expr:
    """1 where the point slipped at Newton's previous iterate (its trial tangential traction
    there, x_last, outside the ball of radius s) and the trial x now points against x_last,
    else 0.

    Newton's guard against stick/slip cycling: with a stiff stick (r = gamma0 E / h large) a
    point sticks only while |du_T| < s / r, a window far narrower than a Newton update, so an
    iterate that crosses it leaves a point slipping the other way, and the next crosses back
    (the traction jumps between +s and -s with a zero tangential derivative in between). A
    point whose slip direction reversed between two iterates went through stick: the next
    Newton step takes it as sticking (t_T = x, linear in u). At a converged iterate nothing
    reverses, so the solution is the law's own."""
    slipped = ufl.gt(ufl.dot(x_last, x_last), s**2)  # not a trial at round-off level
    return ufl.conditional(ufl.And(slipped, ufl.lt(ufl.dot(x, x_last), 0.0)), 1.0, 0.0)


def fischer_burmeister(a: Expr, b: Expr, scale: float) -> Expr:
    """phi(a, b) = a + b - sqrt(a^2 + b^2): zero exactly when a >= 0, b >= 0 and a b = 0
    (Fischer 1992, doi:10.1080/02331939208843795). Regularised at (0, 0) by 1e-12 scale."""
    return a + b - ufl.sqrt(a**2 + b**2 + (1e-12 * scale) ** 2)


@dataclass(frozen=True)
class Friction:
    """A friction law: ``bound(p)`` is the radius of the admissible tangential tractions."""

    name = "none"

    def bound(self, p: Expr) -> Expr:
        raise NotImplementedError

    def bound_where(self, p: Expr, closed: Expr) -> Expr:
        """The bound for the pressure p where ``closed`` > 0 marks the contact set (they
        differ only for multiplier methods, whose pressure is not exactly 0 where open)."""
        return self.bound(p)


@dataclass(frozen=True)
class Tresca(Friction):
    """Tresca friction with a given threshold (stress units), acting where the surfaces are in
    contact (p > 0): |t_T| <= threshold there."""

    threshold: float
    name = "tresca"

    def __post_init__(self) -> None:
        if not self.threshold >= 0.0:
            raise ValueError(f"Tresca threshold must be >= 0, got {self.threshold}")

    def bound(self, p: Expr) -> Expr:
        return self.threshold * active(p)

    def bound_where(self, p: Expr, closed: Expr) -> Expr:
        return self.threshold * active(closed)


@dataclass(frozen=True)
class Coulomb(Friction):
    """Coulomb friction |t_T| <= mu p."""

    mu: float
    name = "coulomb"

    def __post_init__(self) -> None:
        if not self.mu >= 0.0:
            raise ValueError(f"friction coefficient mu must be >= 0, got {self.mu}")

    def bound(self, p: Expr) -> Expr:
        return self.mu * positive_part(p)


def friction_law(name: str, mu: float = 0.0, threshold: float = 0.0) -> Friction | None:
    """'none' -> None (no friction terms are built), 'tresca', 'coulomb'."""
    if name == "none":
        return None
    if name == "tresca":
        return Tresca(threshold)
    if name == "coulomb":
        return Coulomb(mu)
    raise ValueError(f"unknown friction law '{name}' (known: none, tresca, coulomb)")
