"""A block sliding to rest on a rigid plane under gravity with Coulomb friction (plane strain,
implicit dynamics): the block [-L/2, L/2] x [0, H] rests on the plane y = 0 in the elastic
state of its own weight and is launched along x with the speed v0. Coulomb friction
decelerates it by mu g: a rigid block stops after the time v0 / (mu g) and the distance
v0^2 / (2 mu g) (exact), and friction dissipates its kinetic energy 1/2 m v0^2. An elastic
block stiff against its weight (E = 1e5, rho g H = 5: strains of 5e-5) follows the rigid one
up to its elastic vibrations (docs/verification.md section 18).

``sliding-stop-plinth``: the same block on a meshed plinth [0, 2 L] x [-H, 0] of the same
material, fixed at its bottom (two bodies): the pair's friction stops it at the same distance
(the plinth's shear under mu rho g H is some 1e-5 of it), and the pair's coupling sums
friction's dissipation into the energy balance.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import dolfinx
import numpy as np
import ufl

from contactfx.contact.obstacles import Floor, Obstacle
from contactfx.mechanics.elasticity import Elastic
from contactfx.meshes import (
    RectangleFacets,
    StackedBlocksCells,
    StackedBlocksFacets,
    rectangle,
    stacked_blocks,
)
from contactfx.params import param
from contactfx.scenes import export
from contactfx.scenes._common import fix
from contactfx.scenes.base import ObstacleScene, elastic
from contactfx.scenes.two_body_base import TwoBodyScene

__all__ = ["SlidingStop", "SlidingStopPlinth"]


@dataclass(frozen=True)
class SlidingStopParams(elastic(1e5, 0.3)):
    width: float = param(1.0, "block width L", positive=True)
    height: float = param(0.5, "block height H", positive=True)
    density: float = param(1.0, "density rho", positive=True)
    gravity: float = param(10.0, "gravity g (downwards)", positive=True)
    speed: float = param(1.0, "initial speed v0 along x", positive=True)
    h: float = param(0.1, "element size", positive=True)


_NUMERICS = {
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


class _Stopping:
    """What both scenes record and score: the block's mean horizontal displacement and
    velocity at every step against the rigid block's stop, and its initial settlement."""

    p: SlidingStopParams

    @property
    def settlement_rate(self) -> float:
        """k = (1 - nu^2) rho g / E of :meth:`settlement`."""
        p = self.p
        return (1.0 - p.nu**2) * p.density * p.gravity / p.E

    def settlement(self, x: np.ndarray) -> np.ndarray:
        """The vertical settlement of a column under its weight, u_y = -k (H y - y^2 / 2),
        k = (1 - nu^2) rho g / E (plane strain, uniaxial stress sigma_yy = -rho g (H - y)), at
        the block's points (y >= 0; zero below): the contact pressure rho g H at the start,
        the block's own vertical vibration small."""
        y = np.maximum(x[1], 0.0)
        k, H = self.settlement_rate, self.p.height
        return np.vstack([np.zeros(x.shape[1]), -k * (H * y - 0.5 * y**2)])

    def settlement_expressions(self) -> list[str]:
        """:meth:`settlement` as a problem file's ``initial.displacement``."""
        k, H = self.settlement_rate, self.p.height
        return ["0.0", f"-{k!r} * ({H!r} * max(y, 0) - 0.5 * max(y, 0) ** 2)"]

    def initial_guess(self, u, t: float) -> None:
        u.interpolate(self.settlement)

    def initial_velocity(self, v) -> None:
        v.interpolate(self.launched)

    def launched(self, x: np.ndarray) -> np.ndarray:
        """The block's initial velocity (v0, 0)."""
        return np.vstack([np.full(x.shape[1], self.p.speed), 0.0 * x[0]])

    def load(self, v, ds, t):
        return -self.p.density * self.p.gravity * v[1] * ufl.dx

    def block_measure(self, problem) -> ufl.Measure:
        """The cells of the block."""
        return problem.dx

    def configure(self, numerics) -> None:
        self.mu = numerics.mu
        self.track: list[tuple[float, float, float]] = []  # (t, mean u_x, mean v_x)
        self._forms = None

    def on_step(self, problem, solver, load: float, quantities) -> None:
        """Record the block's mean horizontal displacement and velocity (collective)."""
        comm = problem.mesh.comm
        if self._forms is None:
            dx = self.block_measure(problem)
            one = dolfinx.fem.Constant(problem.mesh, 1.0)
            self._area = comm.allreduce(dolfinx.fem.assemble_scalar(dolfinx.fem.form(one * dx)))
            v = problem.inertia.v if problem.inertia is not None else problem.state
            self._forms = [dolfinx.fem.form(f[0] * dx) for f in (problem.state, v)]
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


class SlidingStop(_Stopping, ObstacleScene):
    name = "sliding-stop"
    summary = "block launched on a rigid plane, stopped by Coulomb friction: v0^2 / (2 mu g)"
    Params = SlidingStopParams
    contact_tag = RectangleFacets.BOTTOM
    numerics_defaults = _NUMERICS

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

    def problem_data(self, numerics) -> dict:
        p = self.p
        return {
            "bodies": [export.body("domain", self.material())],
            "obstacle": {"shape": "floor", "contact": "bottom", "h": p.h},
            "initial": {"displacement": self.settlement_expressions()},
            "dynamics": {
                "gravity": [0.0, -p.gravity],
                "initial_velocity": {"domain": [p.speed, 0.0]},
            },
        }


@dataclass(frozen=True)
class SlidingStopPlinthParams(SlidingStopParams):
    plinth_width: float = param(2.0, "plinth width (the block at its left end)", positive=True)
    plinth_height: float = param(0.5, "plinth height", positive=True)
    #: the slave surface of the pair (the block's bottom or the plinth's top)
    slave: str = param("upper", "the slave surface of the contact pair", choices=("upper", "lower"))


class SlidingStopPlinth(_Stopping, TwoBodyScene):
    name = "sliding-stop-plinth"
    summary = "block launched on a meshed plinth, stopped by Coulomb friction (two bodies)"
    Params = SlidingStopPlinthParams
    size_rule = "measure"
    cells = {"lower": StackedBlocksCells.LOWER, "upper": StackedBlocksCells.UPPER}
    surfaces = {"lower": StackedBlocksFacets.LOWER_TOP, "upper": StackedBlocksFacets.UPPER_BOTTOM}
    numerics_defaults = _NUMERICS

    def materials(self):
        m = Elastic(self.p.E, self.p.nu, density=self.p.density)
        return {"lower": m, "upper": m}

    def mesh_builder(self):
        p = self.p
        builder = functools.partial(
            stacked_blocks,
            width=p.plinth_width,
            h_lower=p.plinth_height,
            h_upper=p.height,
            h1=p.h,
            ratio=1.0,
            upper_width=p.width,
        )
        return builder, 2

    def h_contact(self) -> float:
        return self.p.h

    def dirichlet(self, V, facet_tags) -> list:
        return [*fix(V, facet_tags, StackedBlocksFacets.LOWER_BOTTOM)]

    def boundary_data(self) -> list[dict]:
        return [export.fixed("lower_bottom", (0, 1))]

    def initial_velocity(self, v) -> None:
        """The block's nodes only (the plinth's top nodes share its bottom's positions)."""
        cells = self.cell_tags.indices[self.cell_tags.values == self.cells["upper"]]
        v.interpolate(self.launched, cells)
        v.x.scatter_forward()

    def block_measure(self, problem) -> ufl.Measure:
        dx = ufl.Measure("dx", domain=problem.mesh, subdomain_data=self.cell_tags)
        return dx(int(self.cells["upper"]))

    def problem_data(self, numerics) -> dict:
        data = super().problem_data(numerics)
        return {
            **data,
            "initial": {"displacement": self.settlement_expressions()},
            "dynamics": {
                "gravity": [0.0, -self.p.gravity],
                "initial_velocity": {"upper": [self.p.speed, 0.0]},
            },
        }
