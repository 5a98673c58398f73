"""Rigid obstacles given by signed distance functions, never meshed.

Each obstacle is described in its own frame, with its lowest point touching the plane
``y_d = 0`` (d the last axis) and the body below it. A point y of the body (current position
x + u minus the obstacle's rigid displacement) has the gap ``g = phi(y)`` (> 0 outside) and the
contact normal ``n = -grad phi(y)``, the outward normal of the body where it touches.

Two profiles follow Hertz's and Westergaard's own linearised model instead of the true distance:
``Paraboloid`` and ``Sinusoid`` (and ``HalfSpace``) are ``vertical``: the gap is measured
vertically above the reference point, moved by the vertical displacement only, and the pressure
acts vertically (n = e_d): the small-deformation Signorini problem. The
true circle/sphere is ``Ball``; at a/R = 0.1 its pressure peak is about 1 % below Hertz.

``height(t)`` is the obstacle's lower surface above the tangential coordinates t (+inf where
there is none): the vertical gap used for the SNES-VI bound constraints.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import ufl

from contactfx.contact.laws import Expr

__all__ = ["Obstacle", "HalfSpace", "Floor", "Ball", "Paraboloid", "FlatPunch", "Sinusoid"]


def _tangential_sq(y: Expr) -> Expr:
    d = ufl.shape(y)[0]
    return sum(y[i] ** 2 for i in range(d - 1)) if d > 1 else 0.0


def _e_last(d: int) -> Expr:
    return ufl.as_vector([0.0] * (d - 1) + [1.0])


def _check_positive(**values: float) -> None:
    for name, value in values.items():
        if not value > 0.0:
            raise ValueError(f"{name} must be > 0, got {value}")


class Obstacle:
    """Base class: subclasses define ``phi`` (UFL) and ``height`` (NumPy)."""

    vertical: bool = False  # gap measured along e_d, pressure along e_d
    below: bool = False  # below its body (a floor): the reported force is along -e_d

    def phi(self, y: Expr) -> Expr:
        raise NotImplementedError

    def height(self, t: np.ndarray) -> np.ndarray:
        raise NotImplementedError

    def gap(self, y: Expr) -> Expr:
        return self.phi(y)

    def normal(self, y: Expr) -> Expr:
        d = ufl.shape(y)[0]
        if self.vertical:
            return _e_last(d)
        yv = ufl.variable(y)
        grad_phi = ufl.diff(self.phi(yv), yv)
        return -grad_phi / ufl.sqrt(ufl.dot(grad_phi, grad_phi))


@dataclass(frozen=True)
class HalfSpace(Obstacle):
    """The half-space y_d >= level."""

    level: float = 0.0
    vertical = True

    def phi(self, y: Expr) -> Expr:
        return self.level - y[ufl.shape(y)[0] - 1]

    def height(self, t: np.ndarray) -> np.ndarray:
        return np.full(t.shape[0], self.level)


@dataclass(frozen=True)
class Floor(Obstacle):
    """The half-space y_d <= level, the body above it (a floor a body falls onto): the
    gap y_d - level, the contact normal -e_d. The one obstacle below its body (the others
    lie above theirs, module docstring); offered to the methods that read the gap and the
    normal (not the VI's vertical bounds: ``height`` is the floor's upper surface, -inf
    nowhere)."""

    level: float = 0.0
    below = True

    def phi(self, y: Expr) -> Expr:
        return y[ufl.shape(y)[0] - 1] - self.level

    def normal(self, y: Expr) -> Expr:
        return -_e_last(ufl.shape(y)[0])

    def height(self, t: np.ndarray) -> np.ndarray:
        raise ValueError("a floor below the body has no upper bound (method vi)")


@dataclass(frozen=True)
class Ball(Obstacle):
    """Cylinder (2D) / sphere (3D) of radius R centred at (0, ..., 0, R)."""

    radius: float

    def __post_init__(self) -> None:
        _check_positive(radius=self.radius)

    def phi(self, y: Expr) -> Expr:
        d = ufl.shape(y)[0]
        r = y - ufl.as_vector([0.0] * (d - 1) + [self.radius])
        return ufl.sqrt(ufl.dot(r, r)) - self.radius

    def normal(self, y: Expr) -> Expr:
        d = ufl.shape(y)[0]
        r = y - ufl.as_vector([0.0] * (d - 1) + [self.radius])
        return -r / ufl.sqrt(ufl.dot(r, r))

    def height(self, t: np.ndarray) -> np.ndarray:
        rho2 = np.sum(t**2, axis=1)
        out = np.full(t.shape[0], np.inf)
        inside = rho2 < self.radius**2
        out[inside] = self.radius - np.sqrt(self.radius**2 - rho2[inside])
        return out


@dataclass(frozen=True)
class Paraboloid(Obstacle):
    """Hertz's profile y_d = |t|^2 / (2 R), vertical gap and vertical pressure."""

    radius: float
    vertical = True

    def __post_init__(self) -> None:
        _check_positive(radius=self.radius)

    def phi(self, y: Expr) -> Expr:
        return _tangential_sq(y) / (2.0 * self.radius) - y[ufl.shape(y)[0] - 1]

    def height(self, t: np.ndarray) -> np.ndarray:
        return np.sum(t**2, axis=1) / (2.0 * self.radius)


@dataclass(frozen=True)
class FlatPunch(Obstacle):
    """Flat punch of half-width (2D) / radius (3D) w whose edges are rounded with radius r_e.

    The punch is the set of points within r_e of the flat strip / disk {|t| <= w, y_d = r_e}:
    flat face at y_d = 0 for |t| <= w, quarter-circle edges up to |t| = w + r_e.
    """

    half_width: float
    edge_radius: float

    def __post_init__(self) -> None:
        _check_positive(half_width=self.half_width, edge_radius=self.edge_radius)

    def phi(self, y: Expr) -> Expr:
        d = ufl.shape(y)[0]
        rho = ufl.sqrt(_tangential_sq(y) + (1e-12 * self.half_width) ** 2)
        q = ufl.max_value(rho - self.half_width, 0.0)
        dz = y[d - 1] - self.edge_radius
        return ufl.sqrt(q**2 + dz**2) - self.edge_radius

    def height(self, t: np.ndarray) -> np.ndarray:
        rho = np.sqrt(np.sum(t**2, axis=1))
        q = rho - self.half_width
        out = np.full(t.shape[0], np.inf)
        out[q <= 0.0] = 0.0
        edge = (q > 0.0) & (q < self.edge_radius)
        out[edge] = self.edge_radius - np.sqrt(self.edge_radius**2 - q[edge] ** 2)
        return out


@dataclass(frozen=True)
class Sinusoid(Obstacle):
    """Westergaard's wavy surface y_d = Delta (1 - cos(2 pi t_0 / wavelength)), vertical gap."""

    amplitude: float
    wavelength: float
    vertical = True

    def __post_init__(self) -> None:
        _check_positive(amplitude=self.amplitude, wavelength=self.wavelength)

    def phi(self, y: Expr) -> Expr:
        k = 2.0 * np.pi / self.wavelength
        return self.amplitude * (1.0 - ufl.cos(k * y[0])) - y[ufl.shape(y)[0] - 1]

    def height(self, t: np.ndarray) -> np.ndarray:
        k = 2.0 * np.pi / self.wavelength
        return self.amplitude * (1.0 - np.cos(k * t[:, 0]))
