"""Contact kinematics against a rigid obstacle: gap, normal and normal stress on a surface."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import ufl

from contactfx.contact.obstacles import Obstacle

__all__ = ["ContactSurface"]


@dataclass(frozen=True)
class ContactSurface:
    """Everything a method needs to write its terms on one contact boundary.

    u: displacement (dolfinx Function); v: test function; ds: measure restricted to the
    candidate contact facets; obstacle and its rigid displacement ``offset`` (a dolfinx
    Constant vector, part of the load program); sigma: the stress function w -> sigma(w);
    E: Young's modulus used to scale the method parameters; h: local mesh size (UFL).
    """

    u: object
    v: object
    ds: ufl.Measure
    obstacle: Obstacle
    offset: object
    sigma: Callable
    E: float
    h: object

    def position(self, w=None):
        """Current position in the obstacle's frame, x + u - offset. For the linearised
        (``vertical``) obstacles only the vertical displacement moves the point: their gap is
        the small-deformation Signorini gap height(x_t) - (x_d + u_d) of Hertz and Westergaard."""
        x = ufl.SpatialCoordinate(self.u.function_space.mesh)
        w = self.u if w is None else w
        if self.obstacle.vertical:
            d = ufl.shape(x)[0]
            w = ufl.as_vector([0.0] * (d - 1) + [w[d - 1]])
        return x + w - self.offset

    def gap(self, w=None):
        """g(u) = phi(x + u - offset), > 0 when apart."""
        return self.obstacle.gap(self.position(w))

    def normal(self, w=None):
        """n(u) = -grad phi at x + u - offset: outward normal of the body at contact."""
        return self.obstacle.normal(self.position(w))

    def sigma_n(self, w, n):
        """Normal stress n . sigma(w) n (< 0 in compression)."""
        return ufl.dot(n, ufl.dot(self.sigma(w), n))
