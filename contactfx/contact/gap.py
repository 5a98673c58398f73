"""Contact kinematics against a rigid obstacle: gap, normal, slip increment and the normal and
tangential stress on a surface."""

from __future__ import annotations

from dataclasses import dataclass

import ufl

from contactfx.contact.laws import Friction
from contactfx.contact.obstacles import Obstacle

__all__ = ["ContactSurface", "tangential"]


def tangential(w, n):
    """Tangential part (I - n n) w of the vector w."""
    return w - ufl.dot(w, n) * n


@dataclass(frozen=True)
class ContactSurface:
    """Everything a method needs to write its terms on one contact boundary.

    u: displacement (a dolfinx Function or a UFL component of a mixed one); v: its test
    function; ds: measure restricted to the candidate contact facets; obstacle and its rigid
    displacement ``offset`` (a dolfinx Constant vector, part of the load program); stress: the
    stress tensor of the state, sigma(u) (or sigma(u, p) = 2 mu eps(u) - p I in the mixed u-p
    formulation), and stress_test the same expression of the test functions, sigma(v) (or
    sigma(v, q)), linear in them; E: Young's modulus of the material at the contact surface,
    used to scale the method parameters; h: local mesh size (UFL).

    Friction (only when ``friction`` is not None): ``u_prev`` and ``offset_prev`` are the
    displacement and the obstacle offset of the last converged load step; the slip increment
    is measured from them. ``ds_nodal`` is the same boundary with the vertex (trapezoidal)
    quadrature rule, for laws collocated at the nodes (semi-smooth Newton multipliers).
    ``multiplier`` (and ``multiplier_test``): the augmented Lagrangian multiplier, when the
    method has one.
    """

    u: object
    v: object
    ds: ufl.Measure
    obstacle: Obstacle
    offset: object
    stress: object
    stress_test: object
    E: float
    h: object
    friction: Friction | None = None
    u_prev: object = None
    offset_prev: object = None
    ds_nodal: ufl.Measure | None = None
    multiplier: object = None
    multiplier_test: object = None

    @property
    def mesh(self):
        return self.ds.ufl_domain()

    def position(self, w=None):
        """Current position in the obstacle's frame, x + u - offset. For the linearised
        (``vertical``) obstacles only the vertical displacement moves the point: their gap is
        the small-deformation Signorini gap height(x_t) - (x_d + u_d) of Hertz and Westergaard."""
        x = ufl.SpatialCoordinate(self.mesh)
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

    @staticmethod
    def sigma_n(stress, n):
        """Normal stress n . stress n (< 0 in compression)."""
        return ufl.dot(n, ufl.dot(stress, n))

    @staticmethod
    def sigma_t(stress, n):
        """Tangential traction (I - n n) stress n."""
        return tangential(ufl.dot(stress, n), n)

    def slip_increment(self, n):
        """Tangential displacement of the body relative to the obstacle since the last
        converged step: (I - n n) ((u - u_prev) - (offset - offset_prev))."""
        if self.u_prev is None:
            raise ValueError("the slip increment needs the previous state (friction only)")
        return tangential((self.u - self.u_prev) - (self.offset - self.offset_prev), n)
