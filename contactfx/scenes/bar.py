"""1D bar against a rigid wall: bar (0, L), E A = E, u(0) = 0, body force f, wall at
x = L + g0 (u(L) <= g0). With Nitsche's method its discrete solution is known exactly
(:func:`contactfx.references.bar_nitsche_exact`, docs/verification.md section 8).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import dolfinx
import numpy as np
import ufl

from contactfx import _compat
from contactfx.contact.obstacles import HalfSpace, Obstacle
from contactfx.mechanics.elasticity import Elastic
from contactfx.meshes import interval
from contactfx.params import param
from contactfx.scenes import export
from contactfx.scenes._common import fix
from contactfx.scenes.base import ObstacleScene, SceneParams

__all__ = ["Bar1D"]

LEFT, RIGHT = 1, 2


@dataclass(frozen=True)
class Bar1DParams(SceneParams):
    length: float = param(1.0, "bar length L", positive=True)
    E: float = param(1.0, "Young's modulus times cross-section", positive=True)
    body_force: float = param(1.0, "body force f per unit length", positive=True)
    gap: float = param(0.3, "initial gap g0 between the bar end and the wall", positive=True)
    cells: int = param(8, "number of elements N", positive=True)


class Bar1D(ObstacleScene):
    name = "bar1d"
    summary = "1D bar pushed by a body force against a rigid wall (exact discrete Nitsche)"
    Params = Bar1DParams
    contact_tag = RIGHT

    def material(self) -> Elastic:
        return Elastic(self.p.E, 0.0)

    def h_contact(self) -> float:
        return self.p.length / self.p.cells

    def build_mesh(self, comm):
        mesh = _compat.create_interval(comm, self.p.cells, self.p.length)
        L = self.p.length
        left = dolfinx.mesh.locate_entities_boundary(mesh, 0, lambda x: np.isclose(x[0], 0.0))
        right = dolfinx.mesh.locate_entities_boundary(mesh, 0, lambda x: np.isclose(x[0], L))
        indices = np.concatenate([left, right]).astype(np.int32)
        values = np.concatenate([np.full(len(left), LEFT), np.full(len(right), RIGHT)])
        order = np.argsort(indices)
        tags = dolfinx.mesh.meshtags(mesh, 0, indices[order], values[order].astype(np.int32))
        return mesh, tags

    def mesh_builder(self):
        return functools.partial(interval, length=self.p.length, cells=self.p.cells), 1

    def problem_data(self, numerics) -> dict:
        p = self.p
        return {
            "bodies": [export.body("bar", self.material(), body_force=[p.body_force])],
            "boundary": [export.fixed("left", (0,))],
            "obstacle": {
                "shape": "plane",
                "contact": "right",
                "h": self.h_contact(),
                **export.motion(self.obstacle_offset, 1),
            },
        }

    def obstacle(self) -> Obstacle:
        return HalfSpace(0.0)

    def obstacle_offset(self, t: float, gdim: int) -> np.ndarray:
        return np.array([self.p.length + self.p.gap])

    def dirichlet(self, V, facet_tags):
        return fix(V, facet_tags, LEFT)

    def load(self, v, ds, t):
        return t * self.p.body_force * v[0] * ufl.dx


@dataclass(frozen=True)
class BarImpactParams(SceneParams):
    cells: int = param(20, "number of elements N", positive=True)


class BarImpact(ObstacleScene):
    """The elastic bar of Dabaghi, Petrov, Pousin and Renard (arXiv:1601.00778; GetFEM's
    ``demo_dynamic_contact_1D.py``): rho = E = L = 1 (wave speed 1), fixed at one end, a rigid
    wall at the other, released at rest. In the paper's frame the bar is (0, 1), fixed at
    x = 1, the wall at x = 0 (u(0) >= 0), u(x, 0) = (1 - x) / 2; here the obstacle lies above
    the body (:mod:`contactfx.contact.obstacles`), so the bar is (-1, 0), fixed at X = -1,
    the wall at X = 0: X = -x and U(X, t) = -u(-X, t). The exact solution
    (:func:`contactfx.references.bar_impact_exact`) has period 3: free flight on [0, 1],
    contact on [1, 2] with the contact stress -1/2, rebound on [2, 3]; its energy
    1/2 int (u_t^2 + u_x^2) dx is 1/8 at all times."""

    name = "bar-impact"
    summary = "1D bar released against a rigid wall: impact, contact and rebound (exact, dynamic)"
    Params = BarImpactParams
    contact_tag = RIGHT
    numerics_defaults = {"dynamic": True, "dt": 0.002, "t_end": 3.0, "gamma0": 5.0}

    def material(self) -> Elastic:
        return Elastic(1.0, 0.0, density=1.0)

    def h_contact(self) -> float:
        return 1.0 / self.p.cells

    def build_mesh(self, comm):
        mesh = dolfinx.mesh.create_interval(comm, self.p.cells, [-1.0, 0.0])
        ends = []
        for tag, x0 in ((LEFT, -1.0), (RIGHT, 0.0)):
            found = dolfinx.mesh.locate_entities_boundary(
                mesh, 0, lambda x, x0=x0: np.isclose(x[0], x0)
            )
            ends.append((found, np.full(len(found), tag, dtype=np.int32)))
        indices = np.concatenate([e[0] for e in ends]).astype(np.int32)
        values = np.concatenate([e[1] for e in ends])
        order = np.argsort(indices)
        return mesh, dolfinx.mesh.meshtags(mesh, 0, indices[order], values[order])

    def obstacle(self) -> Obstacle:
        return HalfSpace(0.0)

    def obstacle_offset(self, t: float, gdim: int) -> np.ndarray:
        return np.zeros(gdim)

    def dirichlet(self, V, facet_tags):
        return fix(V, facet_tags, LEFT)

    def mesh_builder(self):
        """The same bar for ``contactfx init`` (the run meshes it with dolfinx: the same
        vertices, numbered otherwise)."""
        return functools.partial(interval, length=1.0, cells=self.p.cells, x0=-1.0), 1

    def problem_data(self, numerics) -> dict:
        return {
            "bodies": [export.body("bar", self.material())],
            "boundary": [export.fixed("left", (0,))],
            "obstacle": {"shape": "plane", "contact": "right", "h": self.h_contact()},
            "initial": {"displacement": ["-0.5 * (1.0 + x)"]},
        }

    def initial_guess(self, u, t: float) -> None:
        """The initial state U(X, 0) = -(1 + X) / 2 (a dynamic run's, not a guess)."""
        u.interpolate(lambda x: -0.5 * (1.0 + x[:1]))
