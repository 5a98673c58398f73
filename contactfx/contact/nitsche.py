"""Nitsche's method for contact with a rigid obstacle, frictionless or with Tresca / Coulomb
friction.

With the Nitsche pressure and tangential traction

    P_n(u) = [-sigma_n(u) - gamma_N g(u)]_+,
    P_T(u) = proj_{B(0, s(P_n))}(sigma_T(u) - gamma_N du_T(u))

(du_T the slip increment since the last load step, s the friction bound: mu P_n for Coulomb,
the threshold for Tresca) and the traction on the body t(u) = -P_n n + P_T, the residual is

    R(u; v) = a(u, v) - L(v) - theta / gamma_N int sigma(u) n . sigma(v) n
              - 1 / gamma_N int t(u) . (gamma_N v - theta sigma(v) n)

(Chouly, Hild & Renard 2015, doi:10.1090/S0025-5718-2014-02913-X, frictionless; Chouly 2014,
doi:10.1016/j.jmaa.2013.10.046, Tresca; Chouly, Hild, Lleras & Renard 2022,
doi:10.1016/j.cam.2022.114557, Coulomb). theta = 1 symmetric, 0 incomplete, -1 skew.
sigma(u) n and sigma(v) n are the tractions of the state and of the test functions
(``Surface.traction`` / ``traction_test``): in the mixed u-p formulation sigma(u, p) =
2 mu eps(u) - p I and sigma(v, q) with the pressure test function q, which keeps the method
consistent (the exact (u, p) satisfies R = 0 for every theta).
Without friction only the normal terms are built. Here gamma_N = gamma0 E / h with gamma0
dimensionless and large = strong. The papers write gamma = gamma0' h / E (small = strong):
gamma0' = 1 / gamma0. GetFEM 5.4 uses gamma0_GetFEM / h with gamma0_GetFEM = gamma0 E;
asimov-contact gamma_a / h with gamma_a = gamma0 E.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import ufl

from contactfx.contact.laws import positive_part
from contactfx.contact.method import MethodBase, Supports, TrialFriction
from contactfx.contact.surface import Expr, Form, Surface
from contactfx.params import param, validate

if TYPE_CHECKING:
    from contactfx.contact.pair import ContactPair
    from contactfx.contact.point_coupling import PointCoupling

__all__ = ["Nitsche"]


@dataclass(frozen=True)
class Nitsche(TrialFriction, MethodBase):
    """theta in {1, 0, -1}; gamma0 > 0 (gamma_N = gamma0 E / h)."""

    theta: int = param(1, "Nitsche variant: 1 symmetric, 0 incomplete, -1 skew", choices=(1, 0, -1))
    gamma0: float = param(10.0, "Nitsche parameter, gamma_N = gamma0 E / h", positive=True)
    sides: str = param(
        "biased",
        "Nitsche between two bodies: biased (the slave's stress) or "
        "unbiased (both sides, half weights)",
        choices=("biased", "unbiased"),
    )
    name = "nitsche"
    sweep = ("theta", (1, 0, -1))
    supports = Supports(
        axisymmetric=True,
        friction=("none", "tresca", "coulomb"),
        mixed_up=True,
        nodal_quadrature=True,
        interfaces=True,
        two_body=True,
        two_body_tresca=True,
    )

    def __post_init__(self) -> None:
        validate(self)

    def gamma(self, s: Surface) -> Expr:
        return self.gamma0 * s.E / s.h

    def pressure(self, s: Surface) -> Expr:
        n = s.normal()
        return positive_part(-s.traction_n(n) - self.gamma(s) * s.gap())

    def contact_energy(self, s: Surface) -> Expr | None:
        """theta / (2 gamma_N) (P_n(u)^2 - sigma_n(u)^2) (frictionless): with theta = 1 the
        residual's contact terms are this energy's derivative, so that the semi-discrete
        energy 1/2 |v|_M^2 + 1/2 a(u, u) + this term is conserved (Chouly, Hild and Renard
        2015, doi:10.1051/m2an/2014041); 0 for theta = 0 (the mechanical energy alone)."""
        if s.friction is not None:
            return None
        sn = s.traction_n(s.normal())
        return self.theta / (2.0 * self.gamma(s)) * (self.pressure(s) ** 2 - sn**2)

    def _trial_t(self, s: Surface) -> Expr:
        """The trial tangential traction sigma_T(u) - gamma_N du_T."""
        n = s.normal()
        return s.traction_t(n) - self.gamma(s) * s.slip_increment(n)

    def residual(self, s: Surface) -> Form:
        n = s.normal()
        gamma = self.gamma(s)
        sn_u = s.traction_n(n)
        sn_v = s.traction_n(n, test=True)
        p = self.pressure(s)
        form = p * (ufl.dot(s.v, n) - self.theta / gamma * sn_v) * s.ds
        if self.theta != 0:
            form -= self.theta / gamma * sn_u * sn_v * s.ds
        if s.friction is not None:
            st_v = s.traction_t(n, test=True)
            t_T = self.tangential_traction(s)
            # t_T is tangential: t_T . v = t_T . (I - n n) v
            form -= ufl.dot(t_T, s.v - self.theta / gamma * st_v) * s.ds
            if self.theta != 0:
                form -= self.theta / gamma * ufl.dot(s.traction_t(n), st_v) * s.ds
        return form

    def coupling(self, pair: ContactPair) -> PointCoupling:
        """Between two bodies (frictionless): biased or unbiased Nitsche at Gauss points
        (:mod:`contactfx.contact.point_coupling`)."""
        from contactfx.contact.point_coupling import Law, PointCoupling

        law = Law("nitsche", self.gamma0, self.theta)
        return PointCoupling(pair, law, unbiased=self.sides == "unbiased")
