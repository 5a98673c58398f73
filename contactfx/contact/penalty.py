"""Penalty method for frictionless contact with a rigid obstacle.

p = kappa [-g(u)]_+ with kappa = kappa0 E / h; the residual adds int p v.n ds (Kikuchi & Oden
1988, doi:10.1137/1.9781611970845). The penetration is O(p h / (kappa0 E)): the method is not
consistent, the error falls as kappa0 grows (and the conditioning worsens). Friction is not
offered: a penalised stick needs the tangential traction of the last step as history
(t_T = proj(t_T_prev - kappa du_T)), which this module does not store.
"""

from __future__ import annotations

from dataclasses import dataclass

import ufl

from contactfx.contact.laws import positive_part
from contactfx.contact.method import MethodBase, Supports
from contactfx.contact.surface import Surface
from contactfx.params import param, validate

__all__ = ["Penalty"]


@dataclass(frozen=True)
class Penalty(MethodBase):
    """kappa0 > 0 (kappa = kappa0 E / h)."""

    kappa0: float = param(10.0, "penalty parameter, kappa = penalty E / h", positive=True,
                          option="penalty")  # fmt: skip
    name = "penalty"
    sweep = ("penalty", (10.0, 100.0, 1000.0))
    supports = Supports(
        mixed_up=True, nodal_quadrature=True, interfaces=True, two_body=True,
        why_not={"friction": "its stick traction needs the tangential traction history"},
    )  # fmt: skip

    def __post_init__(self) -> None:
        validate(self)

    def kappa(self, s: Surface):
        return self.kappa0 * s.E / s.h

    def pressure(self, s: Surface):
        return self.kappa(s) * positive_part(-s.gap())

    def residual(self, s: Surface):
        return self.pressure(s) * ufl.dot(s.v, s.normal()) * s.ds

    def coupling(self, pair):
        """Between two bodies: p = kappa [-g]_+ at the slave facets' Gauss points."""
        from contactfx.contact.point_coupling import Law, PointCoupling

        return PointCoupling(pair, Law("penalty", self.kappa0))
