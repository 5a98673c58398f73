"""A block sliding to rest on a rigid plane under gravity with Coulomb friction (plane strain,
implicit dynamics): the block [-L/2, L/2] x [0, H] rests on the plane y = 0 in the elastic
state of its own weight and is launched along x with the speed v0. Coulomb friction
decelerates it by mu g: a rigid block stops after the time v0 / (mu g) and the distance
v0^2 / (2 mu g) (exact), and friction dissipates its kinetic energy 1/2 m v0^2. An elastic
block stiff against its weight (E = 1e5, rho g H = 5: strains of 5e-5) follows the rigid one
up to its elastic vibrations (docs/verification.md section 18).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import dolfinx
import numpy as np
import ufl

from contactfx.contact.obstacles import Floor, Obstacle
from contactfx.mechanics.elasticity import Elastic
from contactfx.meshes import RectangleFacets, rectangle
from contactfx.params import param
from contactfx.scenes import export
from contactfx.scenes.base import ObstacleScene, elastic

__all__ = ["SlidingStop"]


@dataclass(frozen=True)
class SlidingStopParams(elastic(1e5, 0.3)):
    width: float = param(1.0, "block width L", positive=True)
    height: float = param(0.5, "block height H", positive=True)
    density: float = param(1.0, "density rho", positive=True)
    gravity: float = param(10.0, "gravity g (downwards)", positive=True)
    speed: float = param(1.0, "initial speed v0 along x", positive=True)
    h: float = param(0.1, "element size", positive=True)


class SlidingStop(ObstacleScene):
    name = "sliding-stop"
    summary = "block launched on a rigid plane, stopped by Coulomb friction: v0^2 / (2 mu g)"
    Params = SlidingStopParams
    contact_tag = RectangleFacets.BOTTOM
    numerics_defaults = {
        "dynamic": True,
        "dt": 0.005,
        "t_end": 0.4,
        "friction": "coulomb",
        "mu": 0.3,
        # Newmark's average acceleration lets the contact's chatter lift the block off the
        # plane while it slides (docs/verification.md section 18): high modes damped
        "scheme": "generalized-alpha",
        "rho_inf": 0.5,
    }

    def material(self) -> Elastic:
        return Elastic(self.p.E, self.p.nu, density=self.p.density)

    def mesh_builder(self):
        p = self.p
        half = 0.5 * p.width
        return functools.partial(
            rectangle,
            x0=-half,
            x1=half,
            y0=0.0,
            y1=p.height,
            refine_x0=-half,
            refine_x1=half,
            h_contact=p.h,
            h_far=p.h,
        ), 2

    def h_contact(self) -> float:
        return self.p.h

    def obstacle(self) -> Obstacle:
        return Floor(0.0)

    def obstacle_offset(self, t: float, gdim: int) -> np.ndarray:
        return np.zeros(gdim)

    def dirichlet(self, V, facet_tags):
        return []  # held by the plane and its own inertia

    def load(self, v, ds, t):
        return -self.p.density * self.p.gravity * v[1] * ufl.dx

    def initial_guess(self, u, t: float) -> None:
        """The vertical settlement of a column under its weight, u_y = -(1 - nu^2) rho g
        (H y - y^2 / 2) / E (plane strain, uniaxial stress sigma_yy = -rho g (H - y)): the
        contact pressure rho g H at the start, the block's own vertical vibration small."""
        p = self.p
        k = (1.0 - p.nu**2) * p.density * p.gravity / p.E
        u.interpolate(
            lambda x: np.vstack([np.zeros(x.shape[1]), -k * (p.height * x[1] - 0.5 * x[1] ** 2)])
        )

    def initial_velocity(self, v) -> None:
        v.interpolate(lambda x: np.vstack([np.full(x.shape[1], self.p.speed), 0.0 * x[0]]))

    def configure(self, numerics) -> None:
        self.mu = numerics.mu
        self.track: list[tuple[float, float, float]] = []  # (t, mean u_x, mean v_x)
        self._forms = None

    def on_step(self, problem, solver, load: float, quantities) -> None:
        """Record the block's mean horizontal displacement and velocity (collective)."""
        if self._forms is None:
            dx = problem.dx
            area = dolfinx.fem.assemble_scalar(
                dolfinx.fem.form(dolfinx.fem.Constant(problem.mesh, 1.0) * dx)
            )
            self._area = problem.mesh.comm.allreduce(area)
            v = problem.inertia.v if problem.inertia is not None else problem.state
            self._forms = [dolfinx.fem.form(f[0] * dx) for f in (problem.state, v)]
        comm = problem.mesh.comm
        means = [comm.allreduce(dolfinx.fem.assemble_scalar(f)) / self._area for f in self._forms]
        self.track.append((load, *means))

    def reference(self, force: float) -> dict[str, float]:
        """The rigid block's stopping time v0 / (mu g) and distance v0^2 / (2 mu g), and the
        computed ones: the mean displacement at the end, the first time the mean velocity
        falls to 1 % of v0 (Coulomb friction) or below."""
        p = self.p
        mu = getattr(self, "mu", 0.0)
        if not mu > 0.0 or not getattr(self, "track", None):
            return {}
        exact_t = p.speed / (mu * p.gravity)
        exact_d = p.speed**2 / (2.0 * mu * p.gravity)
        stopped = [t for t, _, v in self.track if v <= 0.01 * p.speed]
        out = {
            "stop_time": exact_t,
            "stop_distance": exact_d,
            "stop_distance_computed": self.track[-1][1],
            "stop_distance_rel_error": abs(self.track[-1][1] - exact_d) / exact_d,
        }
        if stopped:
            out["stop_time_computed"] = stopped[0]
        return out

    def problem_data(self, numerics) -> dict:
        p = self.p
        k = (1.0 - p.nu**2) * p.density * p.gravity / p.E
        return {
            "bodies": [export.body("domain", self.material())],
            "obstacle": {"shape": "floor", "contact": "bottom", "h": p.h},
            "initial": {"displacement": ["0.0", f"-{k!r} * ({p.height!r} * y - 0.5 * y ** 2)"]},
            "dynamics": {
                "gravity": [0.0, -p.gravity],
                "initial_velocity": {"domain": [p.speed, 0.0]},
            },
        }
