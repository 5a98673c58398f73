"""Nitsche's method for frictionless contact with a rigid obstacle.

With P(u) = [-sigma_n(u) - gamma_N g(u)]_+ the Nitsche contact pressure, the residual is

    R(u; v) = a(u, v) - L(v) - theta / gamma_N int sigma_n(u) sigma_n(v)
              + 1 / gamma_N int P(u) (gamma_N v.n - theta sigma_n(v))

(Chouly, Hild & Renard 2015, doi:10.1090/S0025-5718-2014-02913-X), theta = 1 symmetric,
0 incomplete, -1 skew-symmetric. Here gamma_N = gamma0 E / h with gamma0 dimensionless and
large = strong. The papers write gamma = gamma0' h / E (small = strong): gamma0' = 1 / gamma0.
GetFEM 5.4 uses gamma0_GetFEM / h with gamma0_GetFEM = gamma0 E; asimov-contact gamma_a / h
with gamma_a = gamma0 E.
"""

from __future__ import annotations

from dataclasses import dataclass

import ufl

from contactfx.contact.gap import ContactSurface
from contactfx.contact.laws import positive_part

__all__ = ["Nitsche"]


@dataclass(frozen=True)
class Nitsche:
    """theta in {1, 0, -1}; gamma0 > 0 (gamma_N = gamma0 E / h)."""

    theta: float = 1.0
    gamma0: float = 10.0
    name = "nitsche"

    def __post_init__(self) -> None:
        if self.theta not in (1, 0, -1):
            raise ValueError(f"theta must be one of 1, 0, -1, got {self.theta}")
        if not self.gamma0 > 0.0:
            raise ValueError(f"gamma0 must be > 0, got {self.gamma0}")

    def gamma(self, s: ContactSurface):
        return self.gamma0 * s.E / s.h

    def pressure(self, s: ContactSurface):
        n = s.normal()
        return positive_part(-s.sigma_n(s.u, n) - self.gamma(s) * s.gap())

    def residual(self, s: ContactSurface):
        n = s.normal()
        gamma = self.gamma(s)
        sn_u = s.sigma_n(s.u, n)
        sn_v = s.sigma_n(s.v, n)
        p = self.pressure(s)
        form = p * (ufl.dot(s.v, n) - self.theta / gamma * sn_v) * s.ds
        if self.theta != 0:
            form -= self.theta / gamma * sn_u * sn_v * s.ds
        return form
