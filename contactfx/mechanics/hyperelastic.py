"""Finite-strain hyperelastic materials: compressible neo-Hookean, Mooney-Rivlin and Saint
Venant-Kirchhoff, each a :class:`contactfx.mechanics.material.Material` with ``linear = False``
(the bulk is assembled at every Newton iteration, :class:`contactfx.solvers.bulk.
NonlinearBulk`).

Kinematics. F = I + grad u on the reference configuration. The strain energy is always a
function of the three-dimensional deformation gradient F3: in 3D F3 = F; in 2D (plane strain)
F3 = [[F, 0], [0, 1]]; in an axisymmetric body (r, z) F3 = [[F, 0], [0, 1 + u_r / r]], the hoop
stretch. The first Piola stress is P3 = d psi / d F3 (UFL's ``diff`` of psi in the variable
F3) and the weak form pairs its in-plane block with grad v (plus, axisymmetric, P_thetatheta
with v_r / r). J = det F3, C = F3^T F3, I1 = tr C, I2 = (I1^2 - tr C^2) / 2.

Strain energies (Holzapfel 2000, Nonlinear Solid Mechanics, ISBN 978-0-471-82319-3, 6.4-6.5;
Bonet and Wood 2008, doi:10.1017/CBO9780511755446, chapter 6):

* neo-Hookean: psi = mu/2 (I1 - 3 - 2 ln J) + lambda/2 (ln J)^2, so that P = mu (F - F^-T) +
  lambda ln J F^-T (Bonet and Wood's compressible neo-Hookean);
* Mooney-Rivlin: psi = c10 (J^-2/3 I1 - 3) + c01 (J^-4/3 I2 - 3) + kappa/2 (ln J)^2 (the
  isochoric invariants; a bulk modulus kappa);
* Saint Venant-Kirchhoff: psi = lambda/2 (tr E)^2 + mu E : E with E = (C - I) / 2.

Each reduces to Hooke's law for small strains with the shear modulus mu (Mooney-Rivlin:
mu = 2 (c10 + c01)) and the bulk modulus kappa = lambda + 2 mu / 3: those constants give the
material's E and nu, which scale the contact methods' parameters and enter the closed forms of
the small-load limit.

Mixed displacement-pressure formulation (nu -> 1/2). The neo-Hookean and Mooney-Rivlin
energies split as psi = W(F3) + K/2 (ln J)^2 (K = lambda, or kappa). With the pressure
p = -K ln J as a second unknown (the Kirchhoff pressure; p = -lambda div u for small strains,
the pressure of :class:`contactfx.mechanics.elasticity.Elastic`'s mixed formulation),

    P = dW/dF3 - p F3^-T,    int P : grad v dx - int (ln J + p / K) q dx = L(v),

which tends to the small-strain u-p formulation and does not lock as K -> infinity with
Taylor-Hood elements (Simo and Taylor 1991, doi:10.1016/0045-7825(91)90100-K). Saint
Venant-Kirchhoff has no such split and is offered in the displacement formulation only.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, ClassVar, Self

import ufl

from contactfx.mechanics.elasticity import Elastic, lame
from contactfx.references import oedometric_modulus

__all__ = [
    "Hyperelastic",
    "NeoHookean",
    "MooneyRivlin",
    "SaintVenantKirchhoff",
    "MODELS",
    "material_from_spec",
    "parse_spec",
]

#: a UFL expression (ufl has no type stubs)
Expr = Any


def _positive(model: str, **values: float) -> None:
    for key, value in values.items():
        if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0.0):
            raise ValueError(f"material {model}: {key} must be > 0, got {value}")


def _embed(G: Expr, hoop: Expr | None) -> Expr:
    """The 3 x 3 tensor of an in-plane d x d tensor G (d = 2: the out-of-plane entry ``hoop``,
    0 for a gradient's direction, 1 for F in plane strain; d = 3: G itself)."""
    d = ufl.shape(G)[0]
    if d == 3:
        return G
    if d != 2:
        raise ValueError("finite strain needs a 2D or 3D body")
    zz = 0.0 if hoop is None else hoop
    return ufl.as_matrix([[G[0, 0], G[0, 1], 0.0], [G[1, 0], G[1, 1], 0.0], [0.0, 0.0, zz]])


def _block(T: Expr, d: int) -> Expr:
    """The in-plane d x d block of a 3 x 3 tensor."""
    if d == 3:
        return T
    return ufl.as_matrix([[T[i, j] for j in range(d)] for i in range(d)])


@dataclass(frozen=True)
class Hyperelastic:
    """Base of the hyperelastic materials: subclasses give the strain energy ``W`` (the part
    that stays in the mixed formulation) and the volumetric modulus ``K`` of the (ln J)^2
    term (None: no split, no mixed formulation), and the small-strain constants ``mu`` and
    ``lmbda``. See the module docstring."""

    #: mass per unit reference volume (None: a static body)
    density: float | None = field(default=None, kw_only=True)
    #: the out-of-plane strain of a 2D body, linear in u: F33 = 1 + hoop(u) (None: plane
    #: strain, F33 = 1; an axisymmetric body: hoop(u) = u_r / r)
    hoop: Callable[[Expr], Expr] | None = field(default=None, kw_only=True, compare=False)

    name: ClassVar[str]
    linear: ClassVar[bool] = False
    finite_strain: ClassVar[bool] = True

    # -- what a model defines ----------------------------------------------------------------
    @property
    def mu(self) -> float:
        raise NotImplementedError

    @property
    def lmbda(self) -> float:
        raise NotImplementedError

    def W(self, F: Expr) -> Expr:
        """The strain energy without the volumetric term K/2 (ln J)^2 (all of it when K is
        None), of the 3 x 3 deformation gradient F."""
        raise NotImplementedError

    @property
    def K(self) -> float | None:
        """The modulus of the volumetric term K/2 (ln J)^2 (None: no split)."""
        return None

    # -- the small-strain constants ----------------------------------------------------------
    @property
    def kappa(self) -> float:
        """Small-strain bulk modulus lambda + 2 mu / 3."""
        return self.lmbda + 2.0 * self.mu / 3.0

    @property
    def E(self) -> float:
        """Small-strain Young's modulus mu (3 lambda + 2 mu) / (lambda + mu)."""
        mu, lm = self.mu, self.lmbda
        return mu * (3.0 * lm + 2.0 * mu) / (lm + mu)

    @property
    def nu(self) -> float:
        """Small-strain Poisson's ratio lambda / (2 (lambda + mu))."""
        return self.lmbda / (2.0 * (self.lmbda + self.mu))

    @property
    def E_star(self) -> float:
        """Small-strain contact modulus E / (1 - nu^2)."""
        return self.E / (1.0 - self.nu**2)

    @property
    def M(self) -> float:
        """Small-strain oedometric modulus."""
        return oedometric_modulus(self.E, self.nu)

    def small_strain(self) -> Elastic:
        """The linear-elastic material of the same small-strain constants."""
        return Elastic(self.E, self.nu, density=self.density)

    # -- kinematics ----------------------------------------------------------------------------
    def deformation_gradient(self, u: Expr) -> Expr:
        """F3 of the displacement u (see the module docstring)."""
        d = ufl.shape(u)[0]
        F = ufl.Identity(d) + ufl.grad(u)
        if d == 2:
            return _embed(F, 1.0 if self.hoop is None else 1.0 + self.hoop(u))
        return _embed(F, None)

    def jacobian(self, u: Expr) -> Expr:
        """J = det F3: the volume ratio (<= 0: an inverted element)."""
        return ufl.det(self.deformation_gradient(u))

    def _piola3(self, F: Expr, p: Expr | None) -> Expr:
        """P3 = d psi / d F3 at the variable F (mixed: dW/dF3 - p F3^-T)."""
        if p is None:
            psi = self.W(F)
            if self.K is not None:
                psi = psi + 0.5 * self.K * ufl.ln(ufl.det(F)) ** 2
            return ufl.diff(psi, F)
        if self.K is None:
            raise ValueError(f"material {self.name} has no mixed u-p formulation")
        return ufl.diff(self.W(F), F) - p * ufl.inv(F).T

    def strain_energy(self, u: Expr) -> Expr:
        """The stored energy density psi(F3) per unit reference volume (the volumetric term
        included)."""
        F = self.deformation_gradient(u)
        psi = self.W(F)
        if self.K is not None:
            psi = psi + 0.5 * self.K * ufl.ln(ufl.det(F)) ** 2
        return psi

    def piola(self, u: Expr, p: Expr | None = None) -> Expr:
        """The first Piola stress P3 (3 x 3) of u (and the pressure p, mixed)."""
        F = ufl.variable(self.deformation_gradient(u))
        return self._piola3(F, p)

    # -- the Material protocol ---------------------------------------------------------------
    def weak_stress(self, u: Expr, p: Expr | None = None) -> Expr:
        """The in-plane block of P (paired with grad v; an axisymmetric kind adds P_tt v_r/r)."""
        return _block(self.piola(u, p), ufl.shape(u)[0])

    def weak_stress_derivative(
        self, u: Expr, p: Expr | None, v: Expr, q: Expr | None = None
    ) -> Expr:
        """dP in the direction (v, q): UFL's Gateaux derivative of :meth:`weak_stress` in u
        (and p). u and p are the unknowns themselves: a Function or the components of a mixed
        one (``ufl.split``), v and q the matching test functions. (Differentiating P in the
        variable F instead builds the fourth-order tensor dP/dF: the same values, and 2.5
        times the form compiler's time in 3D.)"""
        P = self.weak_stress(u, p)
        dP = ufl.derivative(P, u, v)
        if p is not None and q is not None:
            dP = dP + ufl.derivative(P, p, q)
        return dP

    def traction(self, u: Expr, p: Expr | None, N: Expr) -> Expr:
        """P N: the first Piola traction on a reference facet of unit normal N (force per unit
        reference area)."""
        return ufl.dot(self.weak_stress(u, p), N)

    def traction_derivative(
        self, u: Expr, p: Expr | None, v: Expr, q: Expr | None, N: Expr
    ) -> Expr:
        return ufl.dot(self.weak_stress_derivative(u, p, v, q), N)

    def cauchy3(self, u: Expr, p: Expr | None = None) -> Expr:
        """The Cauchy stress sigma = P F^T / J (3 x 3)."""
        F = self.deformation_gradient(u)
        return ufl.dot(self.piola(u, p), F.T) / ufl.det(F)

    def cauchy(self, u: Expr, p: Expr | None = None) -> Expr:
        """The in-plane block of the Cauchy stress."""
        return _block(self.cauchy3(u, p), ufl.shape(u)[0])

    def von_mises(self, u: Expr, p: Expr | None = None) -> Expr:
        """von Mises stress of the Cauchy stress (with its out-of-plane entries)."""
        s = ufl.dev(self.cauchy3(u, p))
        return ufl.sqrt(1.5 * ufl.inner(s, s))

    @property
    def pressure_modulus(self) -> float | None:
        """The modulus of the mixed formulation's pressure law (K; None: not offered)."""
        return self.K

    def hoop_work(self, u: Expr, p: Expr | None, v: Expr) -> Expr | None:
        """P_tt(u, p) v_r / r: the hoop term of the weak form of an axisymmetric body (None:
        not axisymmetric)."""
        if self.hoop is None:
            return None
        return self.piola(u, p)[2, 2] * self.hoop(v)

    def pressure_law(self, u: Expr, p: Expr, q: Expr) -> Expr:
        """Integrand -(ln J + p / K) q: the pressure's law p = -K ln J tested with q."""
        if self.K is None:
            raise ValueError(f"material {self.name} has no mixed u-p formulation")
        return -(ufl.ln(self.jacobian(u)) + p / self.K) * q


def _invariants(F: Expr) -> tuple[Expr, Expr, Expr]:
    C = ufl.dot(F.T, F)
    I1 = ufl.tr(C)
    I2 = 0.5 * (I1**2 - ufl.tr(ufl.dot(C, C)))
    return I1, I2, ufl.det(F)


@dataclass(frozen=True)
class _LameModel(Hyperelastic):
    """A model of the two Lame constants (neo-Hookean, Saint Venant-Kirchhoff): mu > 0 and a
    bulk modulus kappa = lambda + 2 mu / 3 > 0, given as (E, nu) or (mu, kappa)."""

    shear: float
    lame_lambda: float

    def __post_init__(self) -> None:
        _positive(self.name, mu=self.shear)
        if not self.lame_lambda + 2.0 * self.shear / 3.0 > 0.0:
            raise ValueError(
                f"material {self.name}: the bulk modulus kappa = lambda + 2 mu / 3 must be > 0, "
                f"got {self.lame_lambda + 2.0 * self.shear / 3.0}"
            )

    @classmethod
    def from_E_nu(cls, E: float, nu: float, **kw: Any) -> Self:
        _positive(cls.name, E=E)
        if not -1.0 < nu < 0.5:
            raise ValueError(f"material {cls.name}: nu must lie in (-1, 0.5), got {nu}")
        lm, mu = lame(E, nu)
        return cls(mu, lm, **kw)

    @classmethod
    def from_mu_kappa(cls, mu: float, kappa: float, **kw: Any) -> Self:
        _positive(cls.name, mu=mu, kappa=kappa)
        return cls(mu, kappa - 2.0 * mu / 3.0, **kw)

    @property
    def mu(self) -> float:
        return self.shear

    @property
    def lmbda(self) -> float:
        return self.lame_lambda


@dataclass(frozen=True)
class NeoHookean(_LameModel):
    """psi = mu/2 (I1 - 3 - 2 ln J) + lambda/2 (ln J)^2 (Bonet and Wood 2008, 6.4.3)."""

    name: ClassVar[str] = "neo-hookean"

    @property
    def K(self) -> float:
        return self.lame_lambda

    def _piola3(self, F: Expr, p: Expr | None) -> Expr:
        if p is not None and not self.lame_lambda > 0.0:
            raise ValueError(f"material {self.name}: the mixed u-p formulation needs lambda > 0")
        return super()._piola3(F, p)

    def W(self, F: Expr) -> Expr:
        I1, _, J = _invariants(F)
        return 0.5 * self.mu * (I1 - 3.0 - 2.0 * ufl.ln(J))


@dataclass(frozen=True)
class MooneyRivlin(Hyperelastic):
    """psi = c10 (J^-2/3 I1 - 3) + c01 (J^-4/3 I2 - 3) + kappa/2 (ln J)^2 (Holzapfel 2000,
    6.5; the small-strain shear modulus mu = 2 (c10 + c01))."""

    c10: float
    c01: float
    bulk: float
    name: ClassVar[str] = "mooney-rivlin"

    def __post_init__(self) -> None:
        if not (math.isfinite(self.c10) and self.c10 >= 0.0):
            raise ValueError(f"material {self.name}: c10 must be >= 0, got {self.c10}")
        if not (math.isfinite(self.c01) and self.c01 >= 0.0):
            raise ValueError(f"material {self.name}: c01 must be >= 0, got {self.c01}")
        _positive(self.name, **{"c10 + c01": self.c10 + self.c01}, kappa=self.bulk)

    @property
    def mu(self) -> float:
        return 2.0 * (self.c10 + self.c01)

    @property
    def lmbda(self) -> float:
        return self.bulk - 2.0 * self.mu / 3.0

    @property
    def K(self) -> float:
        return self.bulk

    def W(self, F: Expr) -> Expr:
        I1, I2, J = _invariants(F)
        return self.c10 * (J ** (-2.0 / 3.0) * I1 - 3.0) + self.c01 * (J ** (-4.0 / 3.0) * I2 - 3.0)


@dataclass(frozen=True)
class SaintVenantKirchhoff(_LameModel):
    """psi = lambda/2 (tr E)^2 + mu E : E, E = (C - I) / 2: Hooke's law between the Green
    strain and the second Piola stress (Holzapfel 2000, 6.5). Not polyconvex: it softens and
    loses stability in strong compression (a stretch below about 0.58 in uniaxial stress)."""

    name: ClassVar[str] = "svk"

    def W(self, F: Expr) -> Expr:
        E = 0.5 * (ufl.dot(F.T, F) - ufl.Identity(3))
        return 0.5 * self.lame_lambda * ufl.tr(E) ** 2 + self.mu * ufl.inner(E, E)


#: the models of ``--material`` and their parameter keys
MODELS: dict[str, tuple[str, ...]] = {
    "linear": ("E", "nu"),
    "neo-hookean": ("E", "nu", "mu", "kappa"),
    "mooney-rivlin": ("c10", "c01", "kappa"),
    "svk": ("E", "nu"),
}


def parse_spec(spec: str) -> tuple[str, dict[str, float]]:
    """``model[:key=value,...]`` (e.g. ``mooney-rivlin:c10=0.4,c01=0.1,kappa=100``) as
    (model, parameters); ValueError in one line naming what is wrong."""
    model, _, rest = spec.strip().partition(":")
    model = model.strip().lower()
    if model not in MODELS:
        raise ValueError(f"material '{model}' is not one of {', '.join(MODELS)}")
    params: dict[str, float] = {}
    for item in filter(None, (s.strip() for s in rest.split(","))):
        key, eq, value = item.partition("=")
        key = key.strip()
        if not eq or key not in MODELS[model]:
            raise ValueError(
                f"material {model}: unknown parameter '{item}' (expected key=value with key "
                f"one of {', '.join(MODELS[model])})"
            )
        try:
            params[key] = float(value)
        except ValueError:
            raise ValueError(f"material {model}: {key} must be a number, got '{value}'") from None
    return model, params


def material_from_spec(
    model: str, params: dict[str, float], base: Elastic
) -> Elastic | Hyperelastic:
    """The material of a model and its parameters; omitted parameters are those of ``base``
    (the scene's elastic material: the same small-strain constants). ``linear`` with E or nu
    overrides them in the elastic material. Mooney-Rivlin: c10 + c01 = mu / 2 of the base,
    c01 = 0 unless given, kappa the base's bulk modulus."""
    if model != "linear" and (base.modulus is not None or base.poisson is not None):
        raise ValueError(
            f"material {model}: this body is heterogeneous (a modulus or Poisson field); the "
            "finite-strain materials are homogeneous"
        )
    kw: dict[str, Any] = {"density": base.density}
    E, nu = params.get("E", base.E), params.get("nu", base.nu)
    if model == "linear":
        return Elastic(E, nu, density=base.density) if params else base
    if model == "svk":
        return SaintVenantKirchhoff.from_E_nu(E, nu, **kw)
    lm, mu = lame(base.E, base.nu)
    kappa0 = lm + 2.0 * mu / 3.0
    if model == "neo-hookean":
        if {"mu", "kappa"} & params.keys():
            if {"E", "nu"} & params.keys():
                raise ValueError(f"material {model}: give E and nu, or mu and kappa, not both")
            return NeoHookean.from_mu_kappa(params.get("mu", mu), params.get("kappa", kappa0), **kw)
        return NeoHookean.from_E_nu(E, nu, **kw)
    c01 = params.get("c01", 0.0)
    c10 = params.get("c10", max(mu / 2.0 - c01, 0.0))
    return MooneyRivlin(c10, c01, params.get("kappa", kappa0), **kw)
