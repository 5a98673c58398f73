"""Penalty method for contact with a rigid obstacle, frictionless or with friction.

p = kappa [-g(u)]_+ and t_T = proj_{B(0, s(p))}(-kappa du_T) with kappa = kappa0 E / h and
du_T the slip increment; the residual adds int (p v.n - t_T . v) ds (Kikuchi & Oden 1988,
doi:10.1137/1.9781611970845). The penetration and the elastic stick slip are
O(p h / (kappa0 E)): the method is not consistent, the error falls as kappa0 grows (and the
conditioning worsens).
"""

from __future__ import annotations

from dataclasses import dataclass

import ufl

from contactfx.contact.gap import ContactSurface
from contactfx.contact.laws import active, ball_projection, norm, positive_part

__all__ = ["Penalty"]


@dataclass(frozen=True)
class Penalty:
    """kappa0 > 0 (kappa = kappa0 E / h)."""

    kappa0: float = 100.0
    name = "penalty"
    mixed = False

    def __post_init__(self) -> None:
        if not self.kappa0 > 0.0:
            raise ValueError(f"penalty parameter must be > 0, got {self.kappa0}")

    def kappa(self, s: ContactSurface):
        return self.kappa0 * s.E / s.h

    def pressure(self, s: ContactSurface):
        return self.kappa(s) * positive_part(-s.gap())

    def _trial_t(self, s: ContactSurface):
        return -self.kappa(s) * s.slip_increment(s.normal())

    def tangential_traction(self, s: ContactSurface):
        return ball_projection(self._trial_t(s), s.friction.bound(self.pressure(s)), s.E)

    def slip_indicator(self, s: ContactSurface):
        p = self.pressure(s)
        return active(p) * active(norm(self._trial_t(s), s.E) - s.friction.bound(p))

    def residual(self, s: ContactSurface):
        form = self.pressure(s) * ufl.dot(s.v, s.normal()) * s.ds
        if s.friction is not None:
            form -= ufl.dot(self.tangential_traction(s), s.v) * s.ds
        return form
