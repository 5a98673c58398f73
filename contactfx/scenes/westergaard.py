"""Westergaard's wavy surface: a rigid sinusoid pressed on an elastic half-plane.

Half period [0, lambda/2] x [-H, 0], u_x = 0 on both vertical sides (exact symmetry planes),
mean pressure p_m applied as a traction at the bottom (force control), the obstacle fixed.
With p* = pi E* Delta / lambda (Westergaard 1939, doi:10.1115/1.4008969; Johnson 1985, 13.2):

    partial contact (p_m < p*): sin^2(pi a / lambda) = p_m / p*,  p(0) = 2 p* sqrt(p_m / p*)
    full contact  (p_m >= p*): p(x) = p_m + p* cos(2 pi x / lambda)

In full contact the exact displacement is known (Airy function (A + B y) e^{ky} cos kx):

    u_x = p* / (2 mu k) (2 nu - 1 - k y) e^{ky} sin kx
    u_y = Delta - p_m y / M + p* / (2 mu) ((2 nu - 2) / k + y) e^{ky} cos kx,

k = 2 pi / lambda, M the oedometric modulus (the sides are rollers). The truncation at depth
H is of relative size (1 + kH) e^{-kH} (5e-5 at H = 2 lambda): far below the errors measured.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
import ufl

from contactfx.contact.obstacles import Obstacle, Sinusoid
from contactfx.meshes import RectangleFacets, rectangle
from contactfx.params import param
from contactfx.scenes import export
from contactfx.scenes._common import fix_component
from contactfx.scenes.base import ObstacleScene, elastic

__all__ = ["Westergaard"]


@dataclass(frozen=True)
class WestergaardParams(elastic(1000.0, 0.3)):
    wavelength: float = param(1.0, "wavelength lambda of the rigid sinusoid", positive=True)
    amplitude: float = param(0.01, "amplitude Delta of the sinusoid", positive=True)
    mean_pressure_ratio: float = param(
        0.5, "mean pressure p_m / p* (>= 1: full contact)", positive=True
    )
    depth_ratio: float = param(2.0, "strip depth H / lambda", positive=True)
    h_contact: float = param(1.0 / 64, "element size at the surface", positive=True)
    h_far: float = param(1.0 / 8, "element size at depth", positive=True)


class Westergaard(ObstacleScene):
    name = "westergaard"
    summary = "rigid sinusoid on a half-plane under mean pressure; Westergaard a, p0, exact u"
    Params = WestergaardParams
    contact_tag = RectangleFacets.TOP
    numerics_defaults = {"steps": 2}

    @property
    def p_star(self) -> float:
        return np.pi * self.material().E_star * self.p.amplitude / self.p.wavelength

    @property
    def p_mean(self) -> float:
        return self.p.mean_pressure_ratio * self.p_star

    def mesh_builder(self):
        p = self.p
        half = 0.5 * p.wavelength
        return functools.partial(
            rectangle,
            x0=0.0,
            x1=half,
            y0=-p.depth_ratio * p.wavelength,
            y1=0.0,
            refine_x0=0.0,
            refine_x1=half,
            h_contact=p.h_contact,
            h_far=p.h_far,
        ), 2

    def obstacle(self) -> Obstacle:
        return Sinusoid(self.p.amplitude, self.p.wavelength)

    def dirichlet(self, V, facet_tags):
        return [
            fix_component(V, facet_tags, RectangleFacets.LEFT, 0),
            fix_component(V, facet_tags, RectangleFacets.RIGHT, 0),
        ]

    def load(self, v, ds, t):
        return t * self.p_mean * v[1] * ds(RectangleFacets.BOTTOM)

    def initial_guess(self, u, t: float) -> None:
        """Rigid lift that overlaps the obstacle where the exact first-step contact is, plus
        the uniaxial compression of the strip: a state from which Newton sees contact."""
        r = min(t * self.p.mean_pressure_ratio, 1.0)
        lift = 2.0 * self.p.amplitude * r
        strain = t * self.p_mean / self.material().M
        u.interpolate(lambda x: np.vstack([np.zeros(x.shape[1]), lift - strain * x[1]]))

    def contact_size(self, measure: float) -> float:
        return measure

    def problem_data(self, numerics) -> dict:
        p = self.p
        r = min(p.mean_pressure_ratio / numerics.steps, 1.0)
        lift = 2.0 * p.amplitude * r
        strain = self.p_mean / numerics.steps / self.material().M
        return {
            "bodies": [export.body("domain", self.material())],
            "boundary": [
                export.fixed("left", (0,)),
                export.fixed("right", (0,)),
                {"group": "bottom", "traction": [0.0, self.p_mean]},
            ],
            "obstacle": {
                "shape": "sinusoid",
                "contact": "top",
                "height": p.amplitude,
                "wavelength": p.wavelength,
                "h": p.h_contact,
            },
            # Newton's start: a rigid lift into the obstacle plus the strip's compression
            "initial": {"displacement": ["0.0", f"{lift!r} - {strain!r} * y"]},
            "output": {"contact_size": "measure"},
        }

    def reference(self, force: float) -> dict[str, float]:
        r = self.p.mean_pressure_ratio
        lam = self.p.wavelength
        if r >= 1.0:
            force = 0.5 * lam * self.p_mean
            return {"a": 0.5 * lam, "p0": self.p_mean + self.p_star, "force": force}
        a = lam / np.pi * np.arcsin(np.sqrt(r))
        return {"a": a, "p0": 2.0 * self.p_star * np.sqrt(r), "force": 0.5 * lam * self.p_mean}

    def exact_pressure(self, x, ref: dict):
        k = np.pi / self.p.wavelength
        if self.p.mean_pressure_ratio >= 1.0:
            return self.p_mean + self.p_star * ufl.cos(2.0 * k * x[0])
        s2 = ufl.sin(k * ref["a"]) ** 2 - ufl.sin(k * x[0]) ** 2
        return 2.0 * self.p_star * ufl.cos(k * x[0]) * ufl.sqrt(ufl.max_value(s2, 0.0))

    def exact_displacement(self, x):
        if self.p.mean_pressure_ratio < 1.0:
            return None
        mat = self.material()
        k = 2.0 * np.pi / self.p.wavelength
        ps, mu, nu = self.p_star, mat.mu, mat.nu
        e = ufl.exp(k * x[1])
        ux = ps / (2 * mu * k) * (2 * nu - 1 - k * x[1]) * e * ufl.sin(k * x[0])
        uy = (
            self.p.amplitude
            - self.p_mean * x[1] / mat.M
            + ps / (2 * mu) * ((2 * nu - 2) / k + x[1]) * e * ufl.cos(k * x[0])
        )
        return ufl.as_vector([ux, uy])
