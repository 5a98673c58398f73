"""Penalty method for contact, frictionless or with Tresca / Coulomb friction.

p = kappa [-g(u)]_+ with kappa = kappa0 E / h; the residual adds int p v.n ds (Kikuchi & Oden
1988, doi:10.1137/1.9781611970845). The penetration is O(p h / (kappa0 E)): the method is not
consistent, the error falls as kappa0 grows (and the conditioning worsens). h is the surface's
continuous nodal mesh size (``SurfaceData.h_nodal``): with the facet-wise size the traction
carries an error of the order of the cell-size jitter that no refinement removes
(docs/verification.md section 6).

Friction: the stick is a tangential spring of the same stiffness, and the slip its plastic
part (Wriggers 2006, Computational Contact Mechanics, 2nd ed., chapter 5,
doi:10.1007/978-3-540-32609-0). With t_prev the tangential traction of the last converged load
step (the method's history, :attr:`Penalty.traction_history`) and du_T the slip increment since
then,

    t_T = proj_{B(0, s(p))}(t_prev - kappa du_T)

(s = mu p for Coulomb, the threshold for Tresca): a backward-Euler return map. Without the
history the stick traction would restart from zero at every step. The history lives at the
nodes of the contact surface (a P1 field, :meth:`contactfx.driver.problem.Problem.converged`
evaluates t_T there); with the vertex rule (``--quadrature nodal``) the return map is exact at
every quadrature point, with Gauss points the history between nodes is its P1 interpolant.

Contact dashpot (implicit dynamics against a rigid obstacle, ``--dashpot C``): a Kelvin-Voigt
contact, a linear spring and a dashpot in parallel (Goldsmith 1960, Impact: the theory and
physical behaviour of colliding solids, Edward Arnold, London; Hunt and Crossley 1975,
doi:10.1115/1.3423596): while the point penetrates (g < 0) the normal traction is

    p = kappa [-g]_+ + C (-dg/dt),

0 where g >= 0, with dg/dt the gap's rate, the directional derivative of g(u) in the direction
of the velocity (in a time step, the velocity at the force time c_v u - v*,
:mod:`contactfx.solvers.dynamics`; its Jacobian is exact, through g and through the velocity).
C is an absolute coefficient (traction per unit gap rate). The law is not restricted to
compression: as the point recedes at the end of a contact phase (dg/dt > 0) the dashpot pulls
(tension) until the gap reaches 0, where the traction jumps to 0 (the no-tension variant would
end the contact where p reaches 0: Schwager and Poeschel 2007, doi:10.1103/PhysRevE.75.051304).
For this law a rigid mass m on a spring k = int kappa ds and dashpot c = int C ds is a damped
oscillator during the contact, separating when the gap returns to 0, and the coefficient of
restitution has the closed form e = exp(-zeta pi / sqrt(1 - zeta^2)), zeta = c / (2 sqrt(k m))
(zeta < 1; Hunt and Crossley 1975). A time step that the separation falls inside misses the
tension over the rest of that step: e is first order in dt (tests/verification/
test_dashpot.py). The reported contact quantities (force, pressure) are the spring's;
a friction bound reads the spring's pressure; the gap rate is the body's (an obstacle's own
motion is not in it). The dashpot's dissipation is in the energy balance
(:class:`contactfx.driver.inertia.EnergyLedger`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, ClassVar

import ufl

from contactfx.contact.laws import active, positive_part, tangential
from contactfx.contact.method import MethodBase, Supports, TrialFriction
from contactfx.contact.surface import Expr, Form, Surface
from contactfx.params import param, validate

if TYPE_CHECKING:
    from contactfx.contact.pair import ContactPair
    from contactfx.contact.point_coupling import PointCoupling

__all__ = ["Penalty"]


@dataclass(frozen=True)
class Penalty(TrialFriction, MethodBase):
    """kappa0 > 0 (kappa = kappa0 E / h)."""

    kappa0: float = param(
        10.0, "penalty parameter, kappa = penalty E / h", positive=True, option="penalty"
    )
    name = "penalty"
    line_search = "cp"  # the penalised energy's minimum along a step
    sweep = ("penalty", (10.0, 100.0, 1000.0))
    supports = Supports(
        axisymmetric=True,
        friction=("none", "tresca", "coulomb"),
        mixed_up=True,
        nodal_quadrature=True,
        interfaces=True,
        two_body=True,
        two_body_tresca=True,
    )
    #: with friction, the driver keeps the last step's tangential traction (``s.traction_prev``)
    traction_history: ClassVar[bool] = True
    nodal_size: ClassVar[bool] = True
    #: the jump, and so the overlap, vanishes identically at a crack tip: the tip's element
    #: takes its neighbour's traction (``tip_extended``) instead of one falling to zero
    tip_continued: ClassVar[bool] = True

    def __post_init__(self) -> None:
        validate(self)

    def kappa(self, s: Surface) -> Expr:
        return self.kappa0 * s.E / s.h_continuous

    def pressure(self, s: Surface) -> Expr:
        s = self.law_surface(s)
        return self.kappa(s) * positive_part(-s.gap())

    def contact_energy(self, s: Surface) -> Expr | None:
        """kappa / 2 [-g(u)]_+^2, the penalty's elastic energy (frictionless)."""
        if s.friction is not None:
            return None
        s = self.law_surface(s)
        return 0.5 * self.kappa(s) * positive_part(-s.gap()) ** 2

    def _trial_t(self, s: Surface) -> Expr:
        """The trial tangential traction t_prev - kappa du_T."""
        s = self.law_surface(s)
        n = s.normal()
        assert s.traction_prev is not None  # kept by the driver (traction_history)
        return tangential(s.traction_prev, n) - self.kappa(s) * s.slip_increment(n)

    def dashpot_traction(self, s: Surface, C: Expr, velocity: Expr) -> Expr:
        """C (-dg/dt) where g < 0, else 0 (module docstring): dg/dt the derivative of the gap
        g(u) with respect to the state u (``s.u``, a Function) in the direction ``velocity``."""
        s = self.law_surface(s)
        g = s.gap()
        rate = ufl.derivative(g, s.u, velocity)
        return C * -rate * active(-g)

    def dashpot_residual(self, s: Surface, C: Expr, velocity: Expr) -> Form:
        """int C (-dg/dt) H(-g) v . n ds: the dashpot's share of the normal traction (module
        docstring), beside :meth:`residual`'s spring."""
        return self.dashpot_traction(s, C, velocity) * ufl.dot(s.v, s.normal()) * s.ds

    def residual(self, s: Surface) -> Form:
        form = self.pressure(s) * ufl.dot(s.v, s.normal()) * s.ds
        if s.friction is not None:
            form -= ufl.dot(self.tangential_traction(s), s.v) * s.ds
        return form

    def coupling(self, pair: ContactPair) -> PointCoupling:
        """Between two bodies: p = kappa [-g]_+ at the slave facets' Gauss points."""
        from contactfx.contact.point_coupling import Law, PointCoupling

        return PointCoupling(pair, Law("penalty", self.kappa0))
