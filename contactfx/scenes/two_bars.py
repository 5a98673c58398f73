"""Two identical elastic bars colliding end to end (implicit dynamics, two meshed bodies): the
upper bar, of length L, moves down at v0 onto the lower one, at rest, which it touches at
t = 0. With nu = 0 the strips (width w, free sides) carry the 1D wave exactly: two
compression waves leave the contact at the wave speed c = sqrt(E / rho), reflect at the free
ends as tension waves, and reach the contact again at t = 2 L / c, when the bars separate with
their velocities exchanged: the upper at rest, the lower moving at v0. Momentum is conserved
throughout (no external force, the contact forces equal and opposite), the contact force is
rho c v0 / 2 times the cross-section while the bars touch (the contact stress of two equal
bars meeting at v0). Graff, Wave Motion in Elastic Solids (1975), section 2.4; docs/
verification.md section 18.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import dolfinx
import numpy as np
import ufl

from contactfx.mechanics.elasticity import Elastic
from contactfx.meshes import StackedBlocksCells, StackedBlocksFacets, stacked_blocks
from contactfx.params import Params, param
from contactfx.scenes._common import OPEN_FORCE
from contactfx.scenes.two_body_base import TwoBodyScene

__all__ = ["TwoBars"]


@dataclass(frozen=True)
class TwoBarsParams(Params):
    E: float = param(1.0, "Young's modulus of both bars", positive=True)
    density: float = param(1.0, "density rho of both bars", positive=True)
    length: float = param(1.0, "length L of each bar", positive=True)
    width: float = param(0.1, "width w of the bars", positive=True)
    speed: float = param(0.1, "the upper bar's initial speed v0 (downwards)", positive=True)
    h: float = param(0.05, "element size (both bars: matching surfaces)", positive=True)
    #: the slave surface of the pair (the upper bar's bottom or the lower bar's top)
    slave: str = param("upper", "the slave surface of the contact pair", choices=("upper", "lower"))


class TwoBars(TwoBodyScene):
    name = "two-bars"
    summary = "two bars colliding end to end: velocities exchanged after 2 L / c (dynamic)"
    Params = TwoBarsParams
    size_rule = "measure"
    cells = {"lower": StackedBlocksCells.LOWER, "upper": StackedBlocksCells.UPPER}
    surfaces = {"lower": StackedBlocksFacets.LOWER_TOP, "upper": StackedBlocksFacets.UPPER_BOTTOM}
    numerics_defaults = {
        "dynamic": True,
        "dt": 0.02,
        "t_end": 3.0,
        # Newmark's average acceleration lets the contact status flicker between steps and
        # the energy grow (by 3 to 71 %, docs/verification.md section 18): high modes damped
        "scheme": "generalized-alpha",
        "rho_inf": 0.5,
    }

    def materials(self):
        m = Elastic(self.p.E, 0.0, density=self.p.density)  # nu = 0: the 1D wave
        return {"lower": m, "upper": m}

    def mesh_builder(self):
        p = self.p
        builder = functools.partial(
            stacked_blocks,
            width=p.width,
            h_lower=p.length,
            h_upper=p.length,
            h1=p.h,
            ratio=1.0,
        )
        return builder, 2

    def h_contact(self) -> float:
        return self.p.h

    def dirichlet(self, V, facet_tags) -> list:
        return []  # free bodies: their mass holds them (a dynamic run only)

    def load(self, v, ds, t):
        return None

    def boundary_data(self) -> list[dict]:
        return []

    def problem_data(self, numerics) -> dict:
        data = super().problem_data(numerics)
        del data["boundary"]  # free bodies
        return {**data, "dynamics": {"initial_velocity": {"upper": [0.0, -self.p.speed]}}}

    def initial_velocity(self, v) -> None:
        cells = self.cell_tags.indices[self.cell_tags.values == self.cells["upper"]]
        v.interpolate(lambda x: np.vstack([0.0 * x[0], np.full(x.shape[1], -self.p.speed)]), cells)
        v.x.scatter_forward()

    def configure(self, numerics) -> None:
        self.track: list[tuple[float, float, float, float]] = []  # (t, force, v_up, v_low)
        #: the discrete momentum 1^T M v (vertical) at every step
        self.momentum: list[float] = []
        self._forms = None
        self._momentum = None

    def on_step(self, problem, solver, load: float, quantities) -> None:
        """Record the contact force and each bar's mean vertical velocity (collective)."""
        comm = problem.mesh.comm
        if self._forms is None:
            dx = ufl.Measure("dx", domain=problem.mesh, subdomain_data=self.cell_tags)
            one = dolfinx.fem.Constant(problem.mesh, 1.0)
            v = problem.inertia.v if problem.inertia is not None else problem.state
            self._forms = []
            for body in ("upper", "lower"):
                tag = self.cells[body]
                area = comm.allreduce(dolfinx.fem.assemble_scalar(dolfinx.fem.form(one * dx(tag))))
                self._forms.append((dolfinx.fem.form(v[1] * dx(tag)), area))
            if problem.inertia is not None:  # with the run's mass (lumped, redistributed)
                inertia = problem.inertia
                self._momentum = dolfinx.fem.form(inertia.rho * v[1] * inertia.dx)
        means = [comm.allreduce(dolfinx.fem.assemble_scalar(f)) / a for f, a in self._forms]
        self.track.append((load, quantities.force, *means))
        if self._momentum is not None:
            self.momentum.append(comm.allreduce(dolfinx.fem.assemble_scalar(self._momentum)))

    def reference(self, force: float) -> dict[str, float]:
        """The exact contact duration 2 L / c and force rho c v0 w / 2, the velocities after
        separation (upper 0, lower -v0), and the computed ones: the contact phase (the first
        and last step with a force), the bars' mean velocities at the end, and the largest
        change of the discrete momentum 1^T M v (M the run's mass matrix) relative to the
        exact initial one."""
        p = self.p
        c = np.sqrt(p.E / p.density)
        out = {
            "contact_duration": 2.0 * p.length / c,
            "contact_force": 0.5 * p.density * c * p.speed * p.width,
        }
        track = getattr(self, "track", [])
        if not track:
            return out
        touching = [t for t, f, _, _ in track if f > OPEN_FORCE * out["contact_force"]]
        t, _, v_up, v_low = track[-1]
        start = -p.speed * p.length * p.width * p.density
        momentum = self.momentum or [start]
        out.update(
            contact_end_computed=max(touching) if touching else 0.0,
            upper_velocity_end=v_up,
            lower_velocity_end=v_low,
            momentum_change=max(abs(m - start) for m in momentum) / abs(start),
        )
        return out
