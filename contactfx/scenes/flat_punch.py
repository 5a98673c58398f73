"""Flat rigid punch with rounded edges pressed into an elastic block (frictionless).

2D (plane strain, half-width a): p(x) = P / (pi sqrt(a^2 - x^2)); the pressure is singular at
the edge, so the score is the normalised interior pressure pi sqrt(a^2 - x^2) p_h / P on
|x| <= 0.8 a. 3D (circular punch of radius a, quarter model): stiffness P = 2 a E* delta
(Johnson 1985, doi:10.1017/CBO9781139171731, sections 2.8 and 3.8; docs/verification.md section 2).
The edge radius regularises the corner; the contact extends beyond a by O(edge radius).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from contactfx.contact.obstacles import FlatPunch, Obstacle
from contactfx.meshes import RectangleFacets, rectangle
from contactfx.params import param
from contactfx.references import rigid_punch_2d
from contactfx.scenes import export
from contactfx.scenes._common import fix
from contactfx.scenes.base import ObstacleScene, elastic
from contactfx.scenes.hertz import QuarterBlock

__all__ = ["FlatPunch2D", "FlatPunch3D", "normalised_pressure_error"]


def normalised_pressure_error(x: np.ndarray, p: np.ndarray, force: float, a: float) -> float:
    """max |p_h / p_rigid - 1| = max |pi sqrt(a^2 - x^2) p_h / P - 1| over the nodes x (n, gdim)
    with |x| <= 0.8 a: the pressure p_h against the rigid flat punch of half-width a at the
    force P (full model). The edge (singular) is left out; 0 for no such node."""
    inner = np.abs(x[:, 0]) <= 0.8 * a
    ratio = p[inner] / rigid_punch_2d(x[inner, 0], a, force)
    return float(np.max(np.abs(ratio - 1.0), initial=0.0))


@dataclass(frozen=True)
class FlatPunch2DParams(elastic(1000.0, 0.3)):
    punch_half_width: float = param(0.05, "punch half-width a", positive=True)
    edge_radius: float = param(0.002, "radius of the rounded punch edges", positive=True)
    depth: float = param(1e-4, "indentation depth", positive=True)
    half_width: float = param(1.0, "block half-width", positive=True)
    height: float = param(1.0, "block height", positive=True)
    h_contact: float = param(2.5e-3, "element size under the punch", positive=True)
    h_far: float = param(0.1, "element size far from the punch", positive=True)


class FlatPunch2D(ObstacleScene):
    name = "punch2d"
    summary = "flat punch with rounded edges on a plane-strain block; normalised pressure"
    Params = FlatPunch2DParams
    contact_tag = RectangleFacets.TOP

    def mesh_builder(self):
        p = self.p
        w = 1.2 * p.punch_half_width
        return functools.partial(
            rectangle,
            x0=-p.half_width,
            x1=p.half_width,
            y0=-p.height,
            y1=0.0,
            refine_x0=-w,
            refine_x1=w,
            h_contact=p.h_contact,
            h_far=p.h_far,
        ), 2

    def obstacle(self) -> Obstacle:
        return FlatPunch(self.p.punch_half_width, self.p.edge_radius)

    def obstacle_offset(self, t: float, gdim: int) -> np.ndarray:
        return np.array([0.0, -t * self.p.depth])

    def dirichlet(self, V, facet_tags):
        return fix(V, facet_tags, RectangleFacets.BOTTOM)

    def problem_data(self, numerics) -> dict:
        p = self.p
        return {
            "bodies": [export.body("domain", self.material())],
            "boundary": [export.fixed("bottom", (0, 1))],
            "obstacle": {
                "shape": "punch",
                "contact": "top",
                "radius": p.punch_half_width,
                "edge_radius": p.edge_radius,
                "h": p.h_contact,
                **export.motion(self.obstacle_offset, 2),
            },
        }

    def pressure_scores(self, x: np.ndarray, p: np.ndarray, force: float) -> dict[str, float]:
        """max |pi sqrt(a^2 - x^2) p_h / P - 1| over surface nodes with |x| <= 0.8 a."""
        error = normalised_pressure_error(x, p, force, self.p.punch_half_width)
        return {"normalised_pressure_error": error}


@dataclass(frozen=True)
class FlatPunch3DParams(elastic(1000.0, 0.3)):
    punch_radius: float = param(0.05, "punch radius a", positive=True)
    edge_radius: float = param(0.002, "radius of the rounded punch edge", positive=True)
    depth: float = param(1e-4, "indentation depth delta", positive=True)
    size: float = param(1.0, "edge of the quarter block", positive=True)
    height: float = param(1.0, "block height", positive=True)
    h_contact: float = param(0.006, "element size under the punch", positive=True)
    h_far: float = param(0.3, "element size far from the punch", positive=True)


class FlatPunch3D(QuarterBlock):
    name = "punch3d"
    summary = "circular flat punch on a block (quarter model); stiffness P = 2 a E* delta"
    Params = FlatPunch3DParams

    def refine_radius(self) -> float:
        return 1.2 * self.p.punch_radius

    def obstacle_data(self) -> dict:
        return {"shape": "punch", "radius": self.p.punch_radius, "edge_radius": self.p.edge_radius}

    def obstacle(self) -> Obstacle:
        return FlatPunch(self.p.punch_radius, self.p.edge_radius)

    def reference(self, force: float) -> dict[str, float]:
        p = self.p
        return {"force": 2.0 * p.punch_radius * self.material().E_star * p.depth}
