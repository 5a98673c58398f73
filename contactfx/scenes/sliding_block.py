"""Sliding block: an elastic block pressed on a rigid plane, then dragged along it (plane
strain).

The block [-L/2, L/2] x [-H, 0] touches the rigid half-space y >= 0 with its top face. Load
program: over the first half of the load factor a uniform pressure p on the bottom face presses
it on the plane; over the second half the plane moves tangentially by ``shift`` while the bottom
face is held horizontally (u_x = 0, u_y free). Friction transmits the tangential force Q.

References (exact, any mesh, any method): equilibrium of the vertical forces gives the normal
force P = p L; while the friction bound is not reached everywhere Q < mu P, and once the whole
face slides (gross slip) Q = mu P with the tangential traction |t_T| = mu p at every point
(Coulomb; the Tresca bound gives Q = threshold x contact length). Before gross slip the slip
starts at the two edges, where the free sides meet the stuck face (a corner singularity), and
the stick zone shrinks towards the middle as the shift grows.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
import ufl

from contactfx.contact.obstacles import HalfSpace, Obstacle
from contactfx.meshes import RectangleFacets, rectangle
from contactfx.params import param
from contactfx.scenes import export
from contactfx.scenes._common import fix_component
from contactfx.scenes.base import ObstacleScene, elastic

__all__ = ["SlidingBlock", "SlidingBlockParams"]


@dataclass(frozen=True)
class SlidingBlockParams(elastic(1000.0, 0.3)):
    width: float = param(1.0, "block width L", positive=True)
    height: float = param(0.5, "block height H", positive=True)
    pressure: float = param(
        10.0, "pressure p on the bottom face (first half of the load)", positive=True
    )
    shift: float = param(
        0.02, "tangential displacement of the rigid plane (second half)", nonnegative=True
    )
    h: float = param(0.05, "element size", positive=True)


class SlidingBlock(ObstacleScene):
    name = "sliding-block"
    summary = "block pressed on a rigid plane, then dragged: stick, then gross slip at Q = mu P"
    Params = SlidingBlockParams
    #: the methods' own parameters (a stiff stick: gamma0 = r0 = 10); Newton's reversal guard
    #: (contactfx.contact.laws.reversal) keeps it from cycling between stick and slip
    numerics_defaults = {"friction": "coulomb", "mu": 0.3, "steps": 10}
    contact_tag = RectangleFacets.TOP

    def mesh_builder(self):
        p = self.p
        half = 0.5 * p.width
        return functools.partial(
            rectangle,
            x0=-half,
            x1=half,
            y0=-p.height,
            y1=0.0,
            refine_x0=-half,
            refine_x1=half,
            h_contact=p.h,
            h_far=p.h,
        ), 2

    def h_contact(self) -> float:
        return self.p.h

    def obstacle(self) -> Obstacle:
        return HalfSpace(0.0)

    def obstacle_offset(self, t: float, gdim: int) -> np.ndarray:
        return np.array([self.p.shift * max(0.0, 2.0 * t - 1.0), 0.0])

    def dirichlet(self, V, facet_tags):
        return [fix_component(V, facet_tags, RectangleFacets.BOTTOM, 0)]

    def load(self, v, ds, t):
        ramp = ufl.min_value(2.0 * t, 1.0)
        return ramp * self.p.pressure * v[1] * ds(RectangleFacets.BOTTOM)

    def initial_guess(self, u, t: float) -> None:
        """The uniaxial compression of the first load step plus a slight overlap with the
        plane: the block rests on the plane only through contact, and Newton must see it."""
        strain = min(2.0 * t, 1.0) * self.p.pressure / self.material().M
        overlap = 1e-3 * self.p.h
        u.interpolate(lambda x: np.vstack([np.zeros(x.shape[1]), overlap - strain * x[1]]))

    def problem_data(self, numerics) -> dict:
        p = self.p
        t = 1.0 / numerics.steps
        strain = min(2.0 * t, 1.0) * p.pressure / self.material().M
        overlap = 1e-3 * p.h
        return {
            "bodies": [export.body("domain", self.material())],
            "boundary": [
                {
                    "group": "bottom",
                    "fix": ["x"],
                    "traction": [0.0, p.pressure],
                    "amplitude": [[0.0, 0.0], [0.5, 1.0], [1.0, 1.0]],
                }
            ],
            "obstacle": {
                "shape": "plane",
                "contact": "top",
                "h": p.h,
                **export.motion(self.obstacle_offset, 2, (0.0, 0.5, 1.0)),
            },
            "initial": {"displacement": ["0.0", f"{overlap!r} - {strain!r} * y"]},
        }

    def reference(self, force: float) -> dict[str, float]:
        return {"force": self.p.pressure * self.p.width}

    def friction_reference(self, q, friction) -> dict[str, float]:
        """After the drag the whole face slides (the shift exceeds the stick displacement):
        Coulomb's gross slip Q = mu P."""
        if friction.name != "coulomb" or friction.mu == 0.0 or self.p.shift == 0.0:
            return {}
        q_ref = friction.mu * q.force
        q_h = abs(q.friction.tangential_force[0])
        return {"Q": q_ref, "Q_rel_error": abs(q_h - q_ref) / q_ref}

    def friction_scores(self, x, p, t, bound, status) -> dict[str, float]:
        """Where the face slides, |t_T| = bound exactly: the largest deviation relative to p."""
        slipping = status > 1.5
        dev = np.abs(np.linalg.norm(t[slipping], axis=1) - bound[slipping]) / self.p.pressure
        return {"slip_traction_error": float(np.max(dev, initial=0.0))}
