"""Small-strain isotropic linear elasticity: plane strain (2D), 3D, and the uniaxial bar (1D).

sigma(u) = 2 mu eps(u) + lambda tr(eps(u)) I with eps(u) = sym(grad u). In 2D the plane-strain
state is meant: the in-plane Lame formula is exact and sigma_zz = lambda tr(eps) enters only the
von Mises stress. In 1D (a bar of unit cross-section) sigma = E eps.
"""

from __future__ import annotations

from dataclasses import dataclass

import ufl

__all__ = ["Elastic"]


@dataclass(frozen=True)
class Elastic:
    """Isotropic linear-elastic material.

    E: Young's modulus (stress units, > 0); nu: Poisson's ratio in (-1, 0.5).
    """

    E: float
    nu: float

    def __post_init__(self) -> None:
        if not self.E > 0.0:
            raise ValueError(f"Young's modulus E must be > 0, got {self.E}")
        if not -1.0 < self.nu < 0.5:
            raise ValueError(f"Poisson's ratio nu must lie in (-1, 0.5), got {self.nu}")

    @property
    def mu(self) -> float:
        return self.E / (2.0 * (1.0 + self.nu))

    @property
    def lmbda(self) -> float:
        return self.E * self.nu / ((1.0 + self.nu) * (1.0 - 2.0 * self.nu))

    @property
    def E_star(self) -> float:
        """Contact modulus against a rigid body, E / (1 - nu^2) (= plane-strain modulus)."""
        return self.E / (1.0 - self.nu**2)

    @property
    def M(self) -> float:
        """Oedometric (uniaxial-strain) modulus E (1 - nu) / ((1 + nu)(1 - 2 nu))."""
        return self.E * (1.0 - self.nu) / ((1.0 + self.nu) * (1.0 - 2.0 * self.nu))

    def sigma(self, u):
        eps = ufl.sym(ufl.grad(u))
        if ufl.shape(eps) == (1, 1):
            return self.E * eps
        return 2.0 * self.mu * eps + self.lmbda * ufl.tr(eps) * ufl.Identity(ufl.shape(eps)[0])

    def von_mises(self, u):
        s = self.sigma(u)
        d = ufl.shape(s)[0]
        if d == 1:
            return abs(s[0, 0])
        if d == 2:  # plane strain: add sigma_zz = nu (sigma_xx + sigma_yy)
            szz = self.nu * (s[0, 0] + s[1, 1])
            dev = s - (s[0, 0] + s[1, 1] + szz) / 3.0 * ufl.Identity(2)
            j2 = 0.5 * (ufl.inner(dev, dev) + (szz - (s[0, 0] + s[1, 1] + szz) / 3.0) ** 2)
        else:
            dev = ufl.dev(s)
            j2 = 0.5 * ufl.inner(dev, dev)
        return ufl.sqrt(3.0 * j2)
