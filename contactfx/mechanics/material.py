"""The material protocol: what the bulk, the contact surfaces and the output ask of a material.

A material answers in UFL, for the state u (and the pressure p of a mixed u-p formulation):

* ``weak_stress(u, p)``: the stress the weak form pairs with grad v, int S(u) : grad v dx (small
  strain: the Cauchy stress sigma(u); finite strain: the first Piola stress P(F), F = I + grad u),
  and ``weak_stress_derivative(u, p, v, q)``, its directional derivative in the direction
  (v, q) (small strain: sigma(v, q), linear; finite strain: dP/dF : grad v);
* ``traction(u, p, N)`` = S(u) N on a facet of reference unit normal N and
  ``traction_derivative(u, p, v, q, N)``: what a contact method's consistency terms read
  (Nitsche's n . sigma(u) n, its tangential part);
* ``hoop_work(u, p, v)``: an axisymmetric body's hoop term S_tt v_r / r of the weak form (None
  for other bodies; :mod:`contactfx.mechanics.axisymmetric`);
* ``cauchy(u, p)`` and ``von_mises(u, p)`` for the output, ``strain_energy(u)`` (the stored
  energy density per unit reference volume) for a dynamic run's energy balance;
* ``E`` (the reference modulus of the closed forms; the scenes' contact modulus scales the
  methods' parameters, gamma_N = gamma0 E / h) and ``density`` (None in a static run);
* ``linear``: whether S is linear in (u, p), so that the bulk is assembled once
  (:class:`contactfx.solvers.bulk.LinearBulk`) instead of at every Newton iteration;
* ``finite_strain``: whether S is the first Piola stress of F = I + grad u, so that a contact
  surface reads its traction on the reference facet (P N) and its geometry at x + u.

:class:`contactfx.mechanics.elasticity.Elastic` (small strain; plane strain, 3D, 1D, mixed u-p)
is the small-strain implementation, :mod:`contactfx.mechanics.hyperelastic` the finite-strain
ones (neo-Hookean, Mooney-Rivlin, Saint Venant-Kirchhoff). In finite strain the reference
normal N (where the integral lives) and the current normal n (where the gap and the traction's
normal part live) differ; a method passes the normal it means.
"""

from __future__ import annotations

from typing import Any, Protocol, runtime_checkable

__all__ = ["Material"]


@runtime_checkable
class Material(Protocol):
    """See the module docstring."""

    E: float
    density: float | None
    linear: bool
    finite_strain: bool

    @property
    def pressure_modulus(self) -> float | None: ...

    def weak_stress(self, u: Any, p: Any = None) -> Any: ...

    def weak_stress_derivative(self, u: Any, p: Any, v: Any, q: Any = None) -> Any: ...

    def traction(self, u: Any, p: Any, N: Any) -> Any: ...

    def traction_derivative(self, u: Any, p: Any, v: Any, q: Any, N: Any) -> Any: ...

    def hoop_work(self, u: Any, p: Any, v: Any) -> Any: ...

    def cauchy(self, u: Any, p: Any = None) -> Any: ...

    def von_mises(self, u: Any, p: Any = None) -> Any: ...

    def strain_energy(self, u: Any) -> Any: ...
