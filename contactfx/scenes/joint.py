"""Two stacked rock blocks with a joint between them: the Barton-Bandis column (plane strain).

Blocks [0, L] x [0, H] and [0, L] x [H, 2 H], lateral rollers (u_x = 0: uniaxial strain, modulus
M = E (1 - nu) / ((1 + nu)(1 - 2 nu))), the bottom on rollers (u_y = 0), the compression s_c on
the top, and the fluid pressure p on the joint's faces. The joint closes by v under the
effective stress s' = s_c - p by the Barton-Bandis law (Bandis, Lumsden & Barton 1983,
doi:10.1016/0148-9062(83)90595-8): v = s' V_m / (K_ni V_m + s'), aperture w = w0 - v; the top
settles by 2 H s_c / M + v. The solution is uniform in each block, so every mesh and method
reproduces it to the solver tolerance (docs/verification.md section 7).

With ``--crack unfitted`` the joint is a level set y = H + offset on a mesh of the column that
ignores it (:class:`contactfx.driver.unfitted.UnfittedProblem`): a crack through the column,
from one lateral side to the other. The exact solution (uniform stress, a uniform jump) is in
the enriched P1 space for any offset, so the unfitted joint too reproduces it to the solver
tolerance (docs/verification.md section 14).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from contactfx import references as cf
from contactfx.contact.cut import CrackSegment
from contactfx.contact.interface import BartonBandis
from contactfx.meshes import JointColumnFacets, joint_column
from contactfx.params import param
from contactfx.scenes import export
from contactfx.scenes.base import elastic
from contactfx.scenes.interface_base import InterfaceScene

__all__ = ["JointColumn", "JointColumnParams"]


@dataclass(frozen=True)
class JointColumnParams(elastic(10e9, 0.25)):
    block_height: float = param(1.0, "height H of each block", positive=True)
    width: float = param(0.5, "column width L", positive=True)
    closure_stress: float = param(30e6, "compression s_c on the top", nonnegative=True)
    fluid_pressure: float = param(10e6, "fluid pressure p in the joint", nonnegative=True)
    aperture: float = param(1e-3, "initial joint aperture w0", positive=True)
    Kni: float = param(
        50e9, "initial normal stiffness K_ni of the joint (stress / length)", positive=True
    )
    Vm: float = param(3e-4, "maximal closure V_m", positive=True)
    h: float = param(0.25, "element size", positive=True)
    crack: str = param(
        "fitted",
        "the joint: fitted (a chain of mesh edges) or unfitted (a level "
        "set on a mesh of the column that ignores it)",
        choices=("fitted", "unfitted"),
    )
    joint_offset: float = param(
        0.0, "the unfitted joint's height above H (its position against the mesh's nodes)"
    )

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.crack == "fitted" and self.joint_offset != 0.0:
            raise ValueError("--joint-offset needs --crack unfitted")
        if not abs(self.joint_offset) < self.block_height - self.h:
            raise ValueError(
                f"--joint-offset ({self.joint_offset:g}) must leave a cell between "
                f"the joint and the column's ends (|offset| < block-height - h = "
                f"{self.block_height - self.h:g})"
            )
        if self.Vm > self.aperture:
            raise ValueError(f"--Vm ({self.Vm}) must be <= --aperture ({self.aperture})")
        if self.fluid_pressure > self.closure_stress:
            raise ValueError(
                f"--fluid-pressure ({self.fluid_pressure:g}) exceeds --closure-stress "
                f"({self.closure_stress:g}): the joint would open and the upper "
                "block has no equilibrium"
            )


class JointColumn(InterfaceScene):
    name = "joint-column"
    summary = "two blocks with a Barton-Bandis joint under compression and fluid pressure"
    Params = JointColumnParams
    interface_tag = JointColumnFacets.JOINT

    def mesh_builder(self):
        p = self.p
        return functools.partial(
            joint_column,
            width=p.width,
            block_height=p.block_height,
            h=p.h,
            fitted=p.crack == "fitted",
        ), 2

    def crack_segments(self) -> list[CrackSegment]:
        """The unfitted joint: the line y = H + offset, its ends a width beyond the column's
        sides (a crack through the column)."""
        p = self.p
        y = p.block_height + p.joint_offset
        return [CrackSegment((-p.width, y), (2.0 * p.width, y))]

    def problem_data(self, numerics) -> dict:
        """Rollers, the compression on the top as a traction, the joint with the scene's
        frame, h, fluid pressure and Barton-Bandis law; the top's mean settlement."""
        p = self.p
        self._fitted_only()
        origin, direction = self.frame()
        F = JointColumnFacets
        return {
            "bodies": [export.body("domain", self.material())],
            "boundary": [
                *(export.fixed(tag.name.lower(), (c,)) for tag, c in self.supports()),
                {"group": "top", "traction": [0.0, -p.closure_stress]},
            ],
            "interface": {
                "group": F.JOINT.name.lower(),
                "h": p.h,
                "origin": [float(v) for v in origin],
                "direction": [float(v) for v in direction],
                "fluid_pressure": p.fluid_pressure,
                "joint": {"Kni": p.Kni, "Vm": p.Vm, "w0": p.aperture},
            },
            "output": {"mean_displacement": {"top_displacement": ["top", "y"]}},
        }

    def length_scale(self) -> float:
        return self.p.block_height

    def h_contact(self) -> float:
        return self.p.h

    def supports(self):
        F = JointColumnFacets
        return [(F.BOTTOM, 1), (F.LEFT, 0), (F.RIGHT, 0)]

    def side(self, x):
        return x[1] - self.p.block_height

    def frame(self):
        return np.array([0.0, self.p.block_height]), np.array([1.0, 0.0])

    def joint(self):
        return BartonBandis(self.p.Kni, self.p.Vm, self.p.aperture)

    def fluid_pressure(self):
        return self.p.fluid_pressure

    def load(self, v, ds, t):
        return -t * self.p.closure_stress * v[1] * ds(JointColumnFacets.TOP)

    def extra_quantities(self, mesh, w, ds):
        return {"top_displacement": w[1] / self.p.width * ds(JointColumnFacets.TOP)}

    def exact(self) -> dict:
        p = self.p
        return cf.joint_column(
            p.closure_stress, p.fluid_pressure, p.E, p.nu, p.block_height, p.aperture, p.Kni, p.Vm
        )

    def interface_reference(self, prof, q, friction):
        ref = self.exact()
        closure = -float(np.mean(prof.opening))
        aperture = self.p.aperture + float(np.mean(prof.opening))
        settlement = -q.interface.extra["top_displacement"]
        out = {}
        for key, value in (
            ("closure", closure),
            ("aperture", aperture),
            ("settlement", settlement),
        ):
            out[f"{key}_exact"] = float(ref[key])
            out[key] = value
            out[f"{key}_rel_error"] = abs(value - ref[key]) / abs(ref[key])
        # the spread along the joint (uniform in the exact solution)
        out["aperture_spread"] = float(np.ptp(prof.opening)) if len(prof.opening) else 0.0
        return out
