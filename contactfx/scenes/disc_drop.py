"""A disc dropped on a rigid plane (plane strain, implicit dynamics): the 2D test of Chouly,
Hild and Renard 2015 (doi:10.1051/m2an/2014041 and doi:10.1051/m2an/2014046; GetFEM's
``demo_dynamic_contact.m``): radius 20, E = 50, nu = 0.25, rho = 1, gravity 0.1, released at
rest with its lowest point 5 above the plane. Free fall until the impact at t = sqrt(2 H / g)
= 10 with the speed sqrt(2 g H) = 1 (exact), then contact, rebound and flight. The energy
(kinetic + strain + the contact's stored energy) minus the work of gravity is constant for an
energy-conserving discretisation (docs/verification.md section 18).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
import ufl

from contactfx.contact.obstacles import Floor, Obstacle
from contactfx.mechanics.elasticity import Elastic
from contactfx.meshes import DiscFacets, disc
from contactfx.params import param
from contactfx.scenes import export
from contactfx.scenes.base import ObstacleScene, elastic

__all__ = ["DiscDrop"]


@dataclass(frozen=True)
class DiscDropParams(elastic(50.0, 0.25)):
    radius: float = param(20.0, "disc radius R", positive=True)
    density: float = param(1.0, "density rho", positive=True)
    gravity: float = param(0.1, "gravity g (downwards)", nonnegative=True)
    drop: float = param(5.0, "height of the lowest point above the plane at t = 0", positive=True)
    speed: float = param(0.0, "initial downward speed v0", nonnegative=True)
    h_contact: float = param(1.0, "element size near the lowest point", positive=True)
    h_far: float = param(4.0, "element size far from it", positive=True)
    contact_width: float = param(16.0, "width of the refined zone at the bottom", positive=True)


class DiscDrop(ObstacleScene):
    name = "disc-drop"
    summary = "disc dropped on a rigid plane under gravity: impact at t = 10, speed 1 (dynamic)"
    Params = DiscDropParams
    contact_tag = DiscFacets.LOWER
    numerics_defaults = {"dynamic": True, "dt": 0.1, "t_end": 40.0}

    def material(self) -> Elastic:
        return Elastic(self.p.E, self.p.nu, density=self.p.density)

    def mesh_builder(self):
        p = self.p
        builder = functools.partial(
            disc,
            radius=p.radius,
            h_contact=p.h_contact,
            h_far=p.h_far,
            contact_width=p.contact_width,
        )
        return builder, 2

    def obstacle(self) -> Obstacle:
        return Floor(-self.p.drop)

    def obstacle_offset(self, t: float, gdim: int) -> np.ndarray:
        return np.zeros(gdim)

    def dirichlet(self, V, facet_tags):
        return []  # a free body: its mass holds it (a dynamic run only)

    def load(self, v, ds, t):
        if not self.p.gravity:
            return None  # thrown without gravity (--speed): no load
        return -self.p.density * self.p.gravity * v[1] * ufl.dx

    def initial_velocity(self, v) -> None:
        if self.p.speed:
            v.interpolate(lambda x: np.vstack([0.0 * x[0], np.full(x.shape[1], -self.p.speed)]))

    def impact(self) -> dict[str, float]:
        """The free fall's impact speed sqrt(v0^2 + 2 g H) and time (speed - v0) / g (from
        rest: sqrt(2 H / g); without gravity H / v0)."""
        p = self.p
        speed = float(np.sqrt(p.speed**2 + 2.0 * p.gravity * p.drop))
        time = (speed - p.speed) / p.gravity if p.gravity > 0.0 else p.drop / p.speed
        return {"impact_time": float(time), "impact_speed": speed}

    def problem_data(self, numerics) -> dict:
        p = self.p
        return {
            "bodies": [export.body("disc", self.material())],
            "obstacle": {
                "shape": "floor",
                "contact": "lower",
                "h": self.h_contact(),
                "position": [0.0, -p.drop],
            },
            "dynamics": {
                "gravity": [0.0, -p.gravity],
                **({"initial_velocity": {"disc": [0.0, -p.speed]}} if p.speed else {}),
            },
        }
