"""Normal compliance: a nonlinear penalty p = k [-g]_+^m (Oden & Martins 1985,
doi:10.1016/0045-7825(85)90009-X; Klarbring, Mikelic & Shillor 1988,
doi:10.1016/0020-7225(88)90038-6), frictionless.

The interpenetration is a model of the surface asperities being flattened: m = 1 is the linear
penalty, m > 1 stiffens with the closure. The stiffness is scaled as the penalty's,
k = kappa0 E / h^m, so that p = kappa0 E ([-g]_+ / h)^m and m = 1 gives
:class:`contactfx.contact.penalty.Penalty` exactly (h the same continuous nodal size). The
residual adds int p v.n ds; the derivative m k [-g]_+^(m-1) vanishes at g = 0 for m > 1 (a
smooth law: Newton converges quadratically, unlike the semi-smooth penalty).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import ufl

from contactfx.contact.laws import positive_part
from contactfx.contact.method import MethodBase, Supports
from contactfx.contact.surface import Expr, Form, Surface
from contactfx.params import param, validate

__all__ = ["NormalCompliance"]


@dataclass(frozen=True)
class NormalCompliance(MethodBase):
    """kappa0 > 0 (the ``penalty`` option), exponent m > 0."""

    kappa0: float = param(
        10.0, "stiffness factor, p = penalty E ([-g]_+ / h)^m", positive=True, option="penalty"
    )
    exponent: float = param(
        2.0, "normal compliance exponent m: p = penalty E ([-g]_+ / h)^m", positive=True
    )
    nodal_size: ClassVar[bool] = True
    tip_continued: ClassVar[bool] = True  # as the penalty's
    name = "compliance"
    line_search = "cp"  # the penalised energy's minimum along a step
    sweep = ("exponent", (1.0, 1.5, 2.0))
    supports = Supports(
        mixed_up=True,
        nodal_quadrature=True,
        interfaces=True,
        why_not={"friction": "it is a frictionless law"},
    )

    def __post_init__(self) -> None:
        validate(self)

    def pressure(self, s: Surface) -> Expr:
        s = self.law_surface(s)
        return self.kappa0 * s.E * (positive_part(-s.gap()) / s.h_continuous) ** self.exponent

    def residual(self, s: Surface) -> Form:
        return self.pressure(s) * ufl.dot(s.v, s.normal()) * s.ds
