"""An elastic sphere striking a rigid plane (3D, quarter model, implicit dynamics): the Hertz
impact of Johnson 1985 (Contact Mechanics, doi:10.1017/CBO9781139171731, section 11.4). A ball
of radius R, modulus E, Poisson's ratio nu and density rho touches the plane at t = 0 moving
at the speed V towards it. When V is small against the wave speed the contact is quasi-static
(Hertz's force P = 4/3 E* sqrt(R) delta^(3/2) at the approach delta) and the ball's motion that
of a mass m on this spring: the largest approach, force and the contact's duration

    delta* = (15 m V^2 / (16 E* sqrt(R)))^(2/5),  P* = 4/3 E* sqrt(R) delta*^(3/2),
    T = 2.9432 delta* / V,

with E* = E / (1 - nu^2) (a rigid plane). The ball leaves at a speed below V by the energy
left in its vibrations (the coefficient of restitution, reported, not compared). The quarter
model x, y >= 0 (the planes x = 0 and y = 0 mirror planes) of :func:`contactfx.meshes.
quarter_ball`; its mesh's mass m_h (the faceted ball is lighter than 4/3 pi R^3 rho) enters the
reference, so that the comparison measures the contact and the time steps, not the surface's
facets (docs/verification.md section 18).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import dolfinx
import numpy as np
import ufl

from contactfx.contact.obstacles import Floor, Obstacle
from contactfx.mechanics.elasticity import Elastic
from contactfx.meshes import BallFacets, quarter_ball
from contactfx.params import param
from contactfx.references import hertz_impact
from contactfx.scenes import export
from contactfx.scenes._common import OPEN_FORCE, fix_component
from contactfx.scenes.base import ObstacleScene, elastic

__all__ = ["HertzImpact"]


@dataclass(frozen=True)
class HertzImpactParams(elastic(1.0, 0.3)):
    radius: float = param(1.0, "ball radius R", positive=True)
    density: float = param(1.0, "density rho", positive=True)
    speed: float = param(1e-3, "impact speed V (towards the plane)", positive=True)
    h_contact: float = param(0.01, "element size near the lowest point", positive=True)
    h_far: float = param(0.25, "element size far from it", positive=True)
    refine_radius: float = param(0.25, "radius of the zone meshed with h_contact", positive=True)
    cap: float = param(0.3, "height of the contact side of the sphere (its cap)", positive=True)


class HertzImpact(ObstacleScene):
    name = "hertz-impact"
    summary = "elastic sphere striking a rigid plane (quarter model); Hertz's P* and T (dynamic)"
    Params = HertzImpactParams
    contact_tag = BallFacets.LOWER
    symmetry = 4.0
    symmetry_planes = (0, 1)
    numerics_defaults = {"dynamic": True, "dt": 0.5, "t_end": 22.0}

    def material(self) -> Elastic:
        return Elastic(self.p.E, self.p.nu, density=self.p.density)

    def mesh_builder(self):
        p = self.p
        return functools.partial(
            quarter_ball,
            radius=p.radius,
            h_contact=p.h_contact,
            h_far=p.h_far,
            refine_radius=p.refine_radius,
            cap=p.cap,
        ), 3

    def obstacle(self) -> Obstacle:
        return Floor(0.0)

    def obstacle_offset(self, t: float, gdim: int) -> np.ndarray:
        return np.zeros(gdim)

    def dirichlet(self, V, facet_tags):
        # the mirror planes; a free body otherwise (its mass holds it: a dynamic run only)
        return [
            fix_component(V, facet_tags, BallFacets.XMIN, 0),
            fix_component(V, facet_tags, BallFacets.YMIN, 1),
        ]

    def initial_velocity(self, v) -> None:
        speed = self.p.speed
        v.interpolate(lambda x: np.vstack([0.0 * x[0], 0.0 * x[0], np.full(x.shape[1], -speed)]))

    def contact_size(self, measure: float) -> float:
        return float(np.sqrt(measure / np.pi))

    def configure(self, numerics) -> None:
        self.track: list[tuple[float, float, float]] = []  # (t, force, mean v_z)
        self._forms = None

    def on_step(self, problem, solver, load: float, quantities) -> None:
        """Record the contact force (full model) and the ball's mean vertical velocity, its
        momentum over its mass (collective)."""
        comm = problem.mesh.comm
        if self._forms is None:
            one = dolfinx.fem.Constant(problem.mesh, 1.0)
            volume = dolfinx.fem.assemble_scalar(dolfinx.fem.form(one * ufl.dx(problem.mesh)))
            self._volume = comm.allreduce(volume)
            self.mass = self.symmetry * self.p.density * self._volume
            v = problem.inertia.v if problem.inertia is not None else problem.state
            self._forms = dolfinx.fem.form(v[2] * ufl.dx(problem.mesh))
        mean = comm.allreduce(dolfinx.fem.assemble_scalar(self._forms)) / self._volume
        self.track.append((load, quantities.force, mean))

    def reference(self, force: float) -> dict[str, float]:
        """Hertz's delta*, P* and T (module docstring) for the mesh's mass (and the sphere's
        4/3 pi R^3 rho, ``mass_exact``), and the computed: the largest contact force, the
        contact's duration (from t = 0 to the middle of the step in which it opened), the
        ball's speed after it and the coefficient of restitution (that speed over V)."""
        p = self.p
        E_star = self.material().E_star
        exact_mass = 4.0 / 3.0 * np.pi * p.radius**3 * p.density
        track = getattr(self, "track", [])
        mass = getattr(self, "mass", exact_mass)
        ref = hertz_impact(mass, p.speed, p.radius, E_star)
        out = {
            "impact_approach": ref["delta"],
            "impact_peak_force": ref["force"],
            "impact_duration": ref["duration"],
            "mass": mass,
            "mass_exact": exact_mass,
        }
        if not track:
            return out
        t = np.array([r[0] for r in track])
        f = np.array([r[1] for r in track])
        closed = np.flatnonzero(f > OPEN_FORCE * ref["force"])
        out["peak_force_computed"] = float(f.max())
        out["peak_force_rel_error"] = float(f.max() / ref["force"] - 1.0)
        if closed.size and closed[-1] + 1 < len(t):  # the ball has left the plane
            end = 0.5 * (t[closed[-1]] + t[closed[-1] + 1])
            out["duration_computed"] = float(end)
            out["duration_rel_error"] = float(end / ref["duration"] - 1.0)
            out["rebound_speed"] = float(track[-1][2])
            out["restitution"] = float(track[-1][2] / p.speed)
        return out

    def problem_data(self, numerics) -> dict:
        p = self.p
        return {
            "bodies": [export.body("ball", self.material())],
            "boundary": [export.fixed("xmin", (0,)), export.fixed("ymin", (1,))],
            "obstacle": {"shape": "floor", "contact": "lower", "h": self.h_contact()},
            "dynamics": {"initial_velocity": {"ball": [0.0, 0.0, -p.speed]}},
            "output": {"symmetry": self.symmetry, "symmetry_planes": ["x", "y"]},
        }
