"""Small-strain isotropic linear elasticity: plane strain (2D), 3D, and the uniaxial bar (1D).

sigma(u) = 2 mu eps(u) + lambda tr(eps(u)) I with eps(u) = sym(grad u). In 2D the plane-strain
state is meant: the in-plane Lame formula is exact and sigma_zz = lambda tr(eps) enters only the
von Mises stress. In 1D (a bar of unit cross-section) sigma = E eps.

Mixed displacement-pressure (u-p) formulation for near-incompressible materials (nu -> 1/2,
lambda -> infinity), where the displacement formulation locks: the pressure p = -lambda div u
is a second unknown, the stress is sigma(u, p) = 2 mu eps(u) - p I (plane strain: sigma_zz =
-p) and the constitutive law of p is imposed weakly,

    int 2 mu eps(u) : eps(v) - p div v dx - int (div u + p / lambda) q dx = L(v),

a symmetric saddle-point problem whose discrete inf-sup constant does not depend on lambda for
Taylor-Hood elements (P2 displacement, P1 pressure): Brezzi & Fortin 1991, Mixed and Hybrid
Finite Element Methods, doi:10.1007/978-1-4612-3172-1; Taylor & Hood 1973,
doi:10.1016/0045-7930(73)90027-3.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import ufl

from contactfx.references import oedometric_modulus

__all__ = ["Elastic", "lame", "hooke", "basis_tractions", "locking_hint", "LOCKING_NU"]

#: a UFL expression (ufl has no type stubs)
Expr = Any


#: Poisson's ratio above which P1 displacements lock (lambda / mu = 2 nu / (1 - 2 nu) > 49)
LOCKING_NU = 0.49


def locking_hint(nu: float | None, degree: int, formulation: str) -> str:
    """The likely cause of a failed solve of a near-incompressible body in P1 displacements
    (volumetric locking: the P1 displacement cannot deform at constant volume, the bulk
    stiffness lambda swamps the shear; Newton stalls, e.g. DIVERGED_MAX_IT) and its fix, or ""
    when that is not the case (nu <= 0.49, P2, or the mixed u-p formulation)."""
    if nu is None or nu <= LOCKING_NU or degree != 1 or formulation != "displacement":
        return ""
    return (
        f"nu = {nu:.10g} with P1 displacements: the near-incompressible body locks; use "
        "--formulation mixed-up --degree 2 (Taylor-Hood u-p), or at least --degree 2 "
        "(numerics.formulation, numerics.degree in a problem file)"
    )


def lame(E: Any, nu: Any) -> tuple[Any, Any]:
    """(lambda, mu) of Young's modulus E and Poisson's ratio nu: numbers, NumPy arrays (a
    modulus per cell) or UFL expressions alike."""
    return E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)), E / (2.0 * (1.0 + nu))


def hooke(eps: Any, lmbda: Any, mu: Any, trace: Callable[[Any], Any], identity: Any) -> Any:
    """Hooke's law sigma = 2 mu eps + lambda tr(eps) I, for UFL (``trace`` = ufl.tr,
    ``identity`` = ufl.Identity(d)) or NumPy arrays of strains (..., d, d) (``trace`` over the
    last two axes, keeping them; ``identity`` = np.eye(d)): the one Hooke's law of the code
    base."""
    return 2.0 * mu * eps + lmbda * trace(eps) * identity


def basis_tractions(
    grads: np.ndarray, n: np.ndarray, lmbda: np.ndarray, mu: np.ndarray
) -> np.ndarray:
    """sigma(N_a e_c) n: the traction on the plane of normal n of the displacement N_a e_c of
    each P1 basis function N_a and direction c, by :func:`hooke` with eps = sym(e_c grad N_a).
    grads (P, A, d): the basis gradients at P points; n (P, d); lmbda, mu (P,). Returns
    (P, A, d, d): [p, a, c, :] the traction vector (NumPy, for the two-body couplings)."""
    d = grads.shape[-1]
    unit = np.eye(d)
    grad_u = unit[None, None, :, :, None] * grads[:, :, None, None, :]  # e_c (x) grad N_a
    eps = 0.5 * (grad_u + np.swapaxes(grad_u, -1, -2))
    sigma = hooke(
        eps,
        lmbda[:, None, None, None, None],
        mu[:, None, None, None, None],
        lambda e: np.trace(e, axis1=-2, axis2=-1)[..., None, None],
        unit,
    )
    return np.einsum("pacij,pj->paci", sigma, n)


@dataclass(frozen=True)
class Elastic:
    """Isotropic linear-elastic material.

    E: Young's modulus (stress units, > 0); nu: Poisson's ratio in (-1, 0.5). modulus: optional
    field of Young's modulus over the mesh (a UFL expression, e.g. a DG0 Function) that replaces
    E in the stress of a heterogeneous (layered) body; E stays the reference modulus of the
    closed forms, and the properties mu, lmbda, E_star, M are its floats. poisson: optional field
    of Poisson's ratio (bodies of different materials in one mesh), likewise. density: mass per
    unit volume (None: a static body).

    A :class:`contactfx.mechanics.material.Material`: small strain, so the weak form's stress is
    the Cauchy stress sigma, linear in (u, p).
    """

    E: float
    nu: float
    modulus: object = None
    poisson: object = None
    density: float | None = None
    #: an axisymmetric body (2D, r-z): its hoop strain, linear in u (u -> u_r / r,
    #: :func:`contactfx.mechanics.axisymmetric.hoop_strain`); None: plane strain, 3D, 1D
    hoop: Callable[[Any], Any] | None = field(default=None, compare=False)

    #: sigma is linear in (u, p): the bulk is assembled once
    linear = True
    #: small strain: the traction is sigma n on the current normal's plane (one configuration)
    finite_strain = False

    def __post_init__(self) -> None:
        if not self.E > 0.0:
            raise ValueError(f"Young's modulus E must be > 0, got {self.E}")
        if not -1.0 < self.nu < 0.5:
            raise ValueError(f"Poisson's ratio nu must lie in (-1, 0.5), got {self.nu}")
        if self.density is not None and not self.density > 0.0:
            raise ValueError(f"density must be > 0, got {self.density}")

    @property
    def mu(self) -> float:
        return lame(self.E, self.nu)[1]

    @property
    def lmbda(self) -> float:
        return lame(self.E, self.nu)[0]

    @property
    def E_star(self) -> float:
        """Contact modulus against a rigid body, E / (1 - nu^2) (= plane-strain modulus)."""
        return self.E / (1.0 - self.nu**2)

    @property
    def M(self) -> float:
        """Oedometric (uniaxial-strain) modulus E (1 - nu) / ((1 + nu)(1 - 2 nu))."""
        return oedometric_modulus(self.E, self.nu)

    def _moduli(self) -> tuple[Any, Any, Any]:
        """(E, mu, lambda) of the stress: floats, or UFL expressions of the modulus field."""
        E = self.E if self.modulus is None else self.modulus
        nu = self.nu if self.poisson is None else self.poisson
        lmbda, mu = lame(E, nu)
        return E, mu, lmbda

    def sigma(self, u: Expr, p: Expr | None = None) -> Expr:
        """Stress of the displacement u, or of the pair (u, p) of the mixed u-p formulation
        (p the pressure -lambda div u): 2 mu eps(u) - p I. Axisymmetric: the in-plane (r, z)
        block, the trace of the strain with the hoop strain."""
        eps = ufl.sym(ufl.grad(u))
        if p is not None:
            return 2.0 * self._moduli()[1] * eps - p * ufl.Identity(ufl.shape(eps)[0])
        if self.hoop is not None:
            _, mu, lmbda = self._moduli()
            return 2.0 * mu * eps + lmbda * self.volumetric_strain(u) * ufl.Identity(2)
        return self.stress(eps)

    def volumetric_strain(self, u: Expr) -> Expr:
        """tr eps: div u, plus the hoop strain of an axisymmetric body."""
        return ufl.div(u) if self.hoop is None else ufl.div(u) + self.hoop(u)

    def hoop_stress(self, u: Expr, p: Expr | None = None) -> Expr:
        """sigma_tt of an axisymmetric body: 2 mu eps_tt + lambda tr eps (mixed: 2 mu eps_tt
        - p)."""
        assert self.hoop is not None
        _, mu, lmbda = self._moduli()
        if p is not None:
            return 2.0 * mu * self.hoop(u) - p
        return 2.0 * mu * self.hoop(u) + lmbda * self.volumetric_strain(u)

    def hoop_work(self, u: Expr, p: Expr | None, v: Expr) -> Expr | None:
        """sigma_tt(u, p) v_r / r: the hoop term of the weak form (None: not axisymmetric)."""
        if self.hoop is None:
            return None
        return self.hoop_stress(u, p) * self.hoop(v)

    # -- the Material protocol -----------------------------------------------------------------
    def weak_stress(self, u: Expr, p: Expr | None = None) -> Expr:
        """sigma(u, p): small strain, the weak form's stress is the Cauchy stress."""
        return self.sigma(u, p)

    def weak_stress_derivative(
        self, u: Expr, p: Expr | None, v: Expr, q: Expr | None = None
    ) -> Expr:
        """sigma(v, q): the stress is linear, its derivative in the direction (v, q) is the
        stress of (v, q)."""
        return self.sigma(v, q)

    def traction(self, u: Expr, p: Expr | None, N: Expr) -> Expr:
        """sigma(u, p) N."""
        return ufl.dot(self.sigma(u, p), N)

    def traction_derivative(
        self, u: Expr, p: Expr | None, v: Expr, q: Expr | None, N: Expr
    ) -> Expr:
        """sigma(v, q) N."""
        return ufl.dot(self.sigma(v, q), N)

    def cauchy(self, u: Expr, p: Expr | None = None) -> Expr:
        return self.sigma(u, p)

    def strain_energy(self, u: Expr) -> Expr:
        """The stored energy density 1/2 sigma(u) : eps(u) (with the hoop term of an
        axisymmetric body): half the weak form's internal work of u on itself."""
        w = 0.5 * ufl.inner(self.sigma(u), ufl.sym(ufl.grad(u)))
        hoop = self.hoop_work(u, None, u)
        return w if hoop is None else w + 0.5 * hoop

    def stress(self, eps: Expr) -> Expr:
        """Stress of the strain eps (a UFL tensor)."""
        E, mu, lmbda = self._moduli()
        if ufl.shape(eps) == (1, 1):
            return E * eps
        return hooke(eps, lmbda, mu, ufl.tr, ufl.Identity(ufl.shape(eps)[0]))

    @property
    def pressure_modulus(self) -> float:
        """The modulus of the mixed formulation's pressure law, lambda."""
        return self.lmbda

    def pressure_law(self, u: Expr, p: Expr, q: Expr) -> Expr:
        """Integrand -(div u + p / lambda) q: the pressure's constitutive law p = -lambda div u
        tested with q (mixed u-p formulation; needs lambda > 0)."""
        return -(self.volumetric_strain(u) + p / self._moduli()[2]) * q

    def von_mises(self, u: Expr, p: Expr | None = None) -> Expr:
        """von Mises stress of u, or of the mixed pair (u, p)."""
        s = self.sigma(u, p)
        d = ufl.shape(s)[0]
        if d == 1:
            return abs(s[0, 0])
        if d == 2:  # plane strain: add sigma_zz = nu (sigma_xx + sigma_yy), = -p when mixed
            nu = self.nu if self.poisson is None else self.poisson
            szz = nu * (s[0, 0] + s[1, 1]) if p is None else -p
            if self.hoop is not None:  # axisymmetric: the hoop stress
                szz = self.hoop_stress(u, p)
            dev = s - (s[0, 0] + s[1, 1] + szz) / 3.0 * ufl.Identity(2)
            j2 = 0.5 * (ufl.inner(dev, dev) + (szz - (s[0, 0] + s[1, 1] + szz) / 3.0) ** 2)
        else:
            dev = ufl.dev(s)
            j2 = 0.5 * ufl.inner(dev, dev)
        return ufl.sqrt(3.0 * j2)
