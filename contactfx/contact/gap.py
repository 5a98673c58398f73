"""Contact kinematics against a rigid obstacle: gap, normal, slip increment and the normal and
tangential stress on a surface."""

from __future__ import annotations

from dataclasses import dataclass

import ufl

from contactfx.contact.laws import tangential
from contactfx.contact.obstacles import Obstacle
from contactfx.contact.surface import Expr, SurfaceData

__all__ = ["ContactSurface"]


@dataclass(frozen=True)
class ContactSurface(SurfaceData):
    """Everything a method needs to write its terms on one contact boundary.

    u: displacement (a dolfinx Function or a UFL component of a mixed one); v: its test
    function; ds: measure restricted to the candidate contact facets; obstacle and its rigid
    displacement ``offset`` (a dolfinx Constant vector, part of the load program); stress: the
    stress tensor of the state, sigma(u) (or sigma(u, p) = 2 mu eps(u) - p I in the mixed u-p
    formulation), and stress_test the same expression of the test functions, sigma(v) (or
    sigma(v, q)), linear in them; E: Young's modulus of the material at the contact surface,
    used to scale the method parameters; h: local mesh size (UFL).

    With friction ``offset_prev`` is the obstacle offset of the last converged load step (the
    slip is measured relative to the obstacle). The other members: :class:`SurfaceData`.
    """

    u: Expr
    v: Expr
    ds: ufl.Measure
    obstacle: Obstacle
    offset: Expr
    stress: Expr
    stress_test: Expr
    E: float
    h: Expr
    offset_prev: Expr | None = None

    def position(self, w: Expr | None = None) -> Expr:
        """Current position in the obstacle's frame, x + u - offset. For the linearised
        (``vertical``) obstacles in small strain only the vertical displacement moves the
        point: their gap is the small-deformation Signorini gap height(x_t) - (x_d + u_d) of
        Hertz and Westergaard; in finite strain (``reference_normal``) every point is where it
        has moved."""
        x = ufl.SpatialCoordinate(self.mesh)
        w = self.u if w is None else w
        if self.obstacle.vertical and self.reference_normal is None:
            d = ufl.shape(x)[0]
            w = ufl.as_vector([0.0] * (d - 1) + [w[d - 1]])
        return x + w - self.offset

    def gap(self, w: Expr | None = None) -> Expr:
        """g(u) = phi(x + u - offset), > 0 when apart."""
        return self.obstacle.gap(self.position(w))

    def normal(self, w: Expr | None = None) -> Expr:
        """n(u) = -grad phi at x + u - offset: outward normal of the body at contact."""
        return self.obstacle.normal(self.position(w))

    def slip_increment(self, n: Expr) -> Expr:
        """Tangential displacement of the body relative to the obstacle since the last
        converged step: (I - n n) ((u - u_prev) - (offset - offset_prev))."""
        if self.u_prev is None:
            raise ValueError("the slip increment needs the previous state (friction only)")
        return tangential((self.u - self.u_prev) - (self.offset - self.offset_prev), n)
