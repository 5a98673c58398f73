"""Axisymmetric bodies in the (r, z) half-plane: the measures weighted by r and the hoop strain.

A body of revolution loaded symmetrically about the z axis is computed on its meridian section
(x[0] = r >= 0, x[1] = z), as Abaqus's CAX and MOOSE's RZ elements do. Per radian of the
revolution, every volume and surface integral carries the weight r (dV = r dr dz dtheta,
dA = r dl dtheta), and the strain has a fourth, hoop component:

    eps_tt = u_r / r (small strain),    F_tt = 1 + u_r / r (finite strain),

paired in the weak form with its virtual hoop strain v_r / r:

    int (S : grad v + S_tt v_r / r) r dr dz = int t . v r dl + ...

(Zienkiewicz and Taylor 2000, The Finite Element Method, vol. 1, ISBN 978-0-7506-5049-6,
chapter 5; Bonet and Wood 2008, doi:10.1017/CBO9780511755446, for F_tt.) A quantity over the
whole body (a force, a contact area) is 2 pi times its integral: the scene's ``symmetry``.
The axis r = 0 is held by u_r = 0; the weight makes the integrands finite there (the
quadrature points lie inside the cells, where r > 0).

:class:`WeightedMeasure` is a UFL measure that multiplies every integrand by the weight, so
that the contact methods, the loads and the post-processing, written with the kind's measures,
are weighted without knowing it.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import ufl

__all__ = ["WeightedMeasure", "measure", "unweighted", "hoop_strain"]

#: a UFL expression (ufl has no type stubs)
Expr = Any


class WeightedMeasure(ufl.Measure):
    """A UFL measure whose integrals carry a weight: ``f * m`` is ``(weight f) * m``; a
    restriction (``m(tag)``, ``m(metadata=...)``) keeps the weight."""

    def __init__(self, *args: Any, weight: Expr, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.weight = weight

    def reconstruct(self, **kwargs: Any) -> WeightedMeasure:
        m = super().reconstruct(**kwargs)
        return WeightedMeasure(m.integral_type(), **_where(m), weight=self.weight)

    def __rmul__(self, integrand: Expr) -> Any:
        return super().__rmul__(self.weight * integrand)


def measure(kind: str, mesh: Any, axisymmetric: bool, **kwargs: Any) -> ufl.Measure:
    """The measure ``kind`` ("dx", "ds") on ``mesh``: weighted by r = x[0] when
    ``axisymmetric``."""
    if not axisymmetric:
        return ufl.Measure(kind, domain=mesh, **kwargs)
    r = ufl.SpatialCoordinate(mesh)[0]
    return WeightedMeasure(kind, domain=mesh, weight=r, **kwargs)


def unweighted(m: ufl.Measure) -> ufl.Measure:
    """The measure without its weight (itself if it has none): for averages, whose weights
    cancel, and which the weight r would leave undefined at the axis (a vertex rule puts
    zero weight on a node at r = 0)."""
    if not isinstance(m, WeightedMeasure):
        return m
    return ufl.Measure(m.integral_type(), **_where(m))


def _where(m: ufl.Measure) -> dict[str, Any]:
    """A measure's domain, subdomain, metadata and subdomain data (to build another)."""
    return {
        "domain": m.ufl_domain(),
        "subdomain_id": m.subdomain_id(),
        "metadata": m.metadata(),
        "subdomain_data": m.subdomain_data(),
    }


def hoop_strain(mesh: Any) -> Callable[[Expr], Expr]:
    """u -> u_r / r: the hoop strain of the displacement (or test function) u."""
    r = ufl.SpatialCoordinate(mesh)[0]
    return lambda u: u[0] / r
