"""Two-body scenes: the mortar patch test and Hertz contact of two elastic cylinders
(docs/verification.md section 10).

``patch-test``: two stacked blocks with non-matching meshes (element size ratio ``ratio``, the
upper block's contact nodes shifted by ``offset`` of an element), pressure q on the top, the
lower block on rollers at its bottom, both blocks on rollers at x = 0, free to expand
laterally elsewhere. The exact state is the uniform stress sigma_yy = -q (sigma_xx = 0) in both
bodies and the uniform contact pressure q; a mortar method with exact segment-based
integration reproduces it to round-off for any ratio and either slave side (the partition of
unity sum_k M_jk = D_j).

With ``dim = 3`` the blocks are two stacked boxes [0, width]^2 (tetrahedra), the lower one on
rollers at its bottom (u_z = 0), both on rollers at x = 0 (u_x = 0) and y = 0 (u_y = 0); the
exact state is sigma_zz = -q, the contact pressure q and the force q * width^2.

``hertz-cylinders``: two cylinders of radii R1 (upper), R2 (lower), quarter model with the
symmetry plane x = 0, pressed together by the prescribed approach ``depth`` of the upper
body's flat top. At the computed force P per unit length (full model),

    a = sqrt(4 P R / (pi E*)),   p0 = 2 P / (pi a),
    1/R = 1/R1 + 1/R2,   1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2

(Johnson 1985, Contact Mechanics, doi:10.1017/CBO9781139171731, section 4.2).

``hertz-spheres``: two spheres of radii R1 (upper), R2 (lower), quarter model with the
symmetry planes x = 0 and y = 0, pressed together by the approach ``depth`` of the upper
body's flat top, the lower body's flat bottom on rollers (u_z = 0). At the computed force P
(full model)

    a = (3 P R / (4 E*))^(1/3),   p0 = 3 P / (2 pi a^2)

(Johnson 1985, section 4.2), R and E* as for the cylinders.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import dolfinx
import numpy as np

from contactfx import _compat
from contactfx.meshes import (
    CylindersCells,
    CylindersFacets,
    SpheresCells,
    SpheresFacets,
    StackedBlocksCells,
    StackedBlocksFacets,
    StackedBoxesCells,
    StackedBoxesFacets,
    cylinders,
    spheres,
    stacked_blocks,
    stacked_boxes,
)
from contactfx.params import param
from contactfx.references import hertz_2d, hertz_3d
from contactfx.scenes import export
from contactfx.scenes._common import fix_component
from contactfx.scenes.two_body_base import TwoBodyScene, radial_edge, two_elastic

__all__ = ["PatchTest", "HertzCylinders", "HertzSpheres", "radial_edge"]


def _component_value(V, facet_tags, tag: int, component: int, value):
    """u_component = value (a Constant) on the facets tagged ``tag``."""
    sub = V.sub(component)
    facets = facet_tags.indices[facet_tags.values == tag]
    dofs = _compat.locate_dofs_topological(sub, V.mesh.topology.dim - 1, facets)
    return _compat.dirichletbc(value, dofs, sub)


@dataclass(frozen=True)
class PatchTestParams(two_elastic(1000.0, 0.3)):
    width: float = param(1.0, "width of the blocks", positive=True)
    height: float = param(0.5, "height of each block", positive=True)
    h: float = param(0.1, "element size of the lower block", positive=True)
    ratio: float = param(0.7, "element size of the upper block / h", positive=True)
    offset: float = param(
        0.3,
        "shift of the upper block's contact nodes (fraction of its element, in [0, 1))",
        nonnegative=True,
    )
    pressure: float = param(1.0, "pressure q on the top of the upper block", positive=True)
    dim: int = param(2, "dimension: 2 (stacked blocks) or 3 (stacked boxes)", choices=(2, 3))


class PatchTest(TwoBodyScene):
    name = "patch-test"
    summary = (
        "two stacked blocks (--dim 3: boxes) with non-matching meshes under uniform "
        "pressure; exact: uniform stress and contact pressure"
    )
    Params = PatchTestParams
    size_rule = "measure"  # the contact length (2D) or area (3D)
    cells = {"lower": StackedBlocksCells.LOWER, "upper": StackedBlocksCells.UPPER}
    surfaces = {"lower": StackedBlocksFacets.LOWER_TOP, "upper": StackedBlocksFacets.UPPER_BOTTOM}

    def __init__(self, params) -> None:
        super().__init__(params)
        if params.dim == 3:
            self.cells = {"lower": StackedBoxesCells.LOWER, "upper": StackedBoxesCells.UPPER}
            self.surfaces = {
                "lower": StackedBoxesFacets.LOWER_TOP,
                "upper": StackedBoxesFacets.UPPER_BOTTOM,
            }

    def mesh_builder(self):
        p = self.p
        blocks = stacked_boxes if p.dim == 3 else stacked_blocks
        builder = functools.partial(
            blocks,
            width=p.width,
            h_lower=p.height,
            h_upper=p.height,
            h1=p.h,
            ratio=p.ratio,
            offset=p.offset,
        )
        return builder, p.dim

    def h_contact(self) -> float:
        return self.p.h

    def dirichlet(self, V, facet_tags) -> list:
        if self.p.dim == 3:
            f = StackedBoxesFacets
            return [
                fix_component(V, facet_tags, f.LOWER_BOTTOM, 2),
                fix_component(V, facet_tags, f.LOWER_X0, 0),
                fix_component(V, facet_tags, f.UPPER_X0, 0),
                fix_component(V, facet_tags, f.LOWER_Y0, 1),
                fix_component(V, facet_tags, f.UPPER_Y0, 1),
            ]
        f = StackedBlocksFacets
        return [
            fix_component(V, facet_tags, f.LOWER_BOTTOM, 1),
            fix_component(V, facet_tags, f.LOWER_LEFT, 0),
            fix_component(V, facet_tags, f.UPPER_LEFT, 0),
        ]

    def boundary_data(self) -> list[dict]:
        """The rollers of :meth:`dirichlet` and the pressure q on the top (a traction -q along
        the last axis, ramped with the load factor as :meth:`load`)."""
        if self.p.dim == 3:
            rollers = [
                ("lower_bottom", 2),
                ("lower_x0", 0),
                ("upper_x0", 0),
                ("lower_y0", 1),
                ("upper_y0", 1),
            ]
        else:
            rollers = [("lower_bottom", 1), ("lower_left", 0), ("upper_left", 0)]
        traction = [0.0] * self.p.dim
        traction[-1] = -self.p.pressure
        return [
            *(export.fixed(g, (c,)) for g, c in rollers),
            {"group": "upper_top", "traction": traction},
        ]

    def load(self, v, ds, t):
        if self.p.dim == 3:
            return -self.p.pressure * t * v[2] * ds(StackedBoxesFacets.UPPER_TOP)
        return -self.p.pressure * t * v[1] * ds(StackedBlocksFacets.UPPER_TOP)

    def reference(self, force: float) -> dict[str, float]:
        """The exact contact force q * width^(dim - 1) and the uniform pressure q (as p0)."""
        p = self.p
        return {"force": p.pressure * p.width ** (p.dim - 1), "p0": p.pressure}

    def pressure_scores(self, x, p, force):
        """Largest relative deviation of the nodal contact pressure from q."""
        q = self.p.pressure
        return {"pressure_deviation": float(np.max(np.abs(p - q), initial=0.0)) / q}

    def exact_stress(self):
        """The exact stress (uniform): sigma_yy (2D) or sigma_zz (3D) = -q, the rest zero."""
        sigma = np.zeros((self.p.dim, self.p.dim))
        sigma[-1, -1] = -self.p.pressure
        return sigma


@dataclass(frozen=True)
class HertzCylindersParams(two_elastic(1000.0, 0.3)):
    R_upper: float = param(1.0, "radius R1 of the upper cylinder", positive=True)
    R_lower: float = param(1.0, "radius R2 of the lower cylinder", positive=True)
    depth: float = param(
        5e-3, "approach of the upper body's top (ramped over the load steps)", positive=True
    )
    h_contact: float = param(
        2e-3, "element size of the lower body in the contact zone", positive=True
    )
    h_far: float = param(0.1, "element size far from the contact zone", positive=True)
    refine: float = param(
        0.08, "radius of the refined zone around the first contact point", positive=True
    )
    ratio: float = param(0.75, "element size of the upper body / that of the lower", positive=True)
    offset: float = param(
        0.3,
        "shift of the upper body's contact nodes (fraction of an element, in [0, 1))",
        nonnegative=True,
    )


class _TwoHertz(TwoBodyScene):
    """Two curved bodies of radii R_upper, R_lower: Hertz's combined radius and modulus."""

    def E_star(self) -> float:
        m = self.materials()
        return 1.0 / sum((1.0 - b.nu**2) / b.E for b in m.values())

    def R(self) -> float:
        return 1.0 / (1.0 / self.p.R_upper + 1.0 / self.p.R_lower)


class HertzCylinders(_TwoHertz):
    name = "hertz-cylinders"
    summary = "two elastic cylinders pressed together (quarter model); reference Hertz a, p0"
    Params = HertzCylindersParams
    cells = {"lower": CylindersCells.LOWER, "upper": CylindersCells.UPPER}
    surfaces = {"lower": CylindersFacets.LOWER_CONTACT, "upper": CylindersFacets.UPPER_CONTACT}
    symmetry = 2.0
    symmetry_planes = (0,)  # x = 0
    # the contact half-width from the zero contour of p - (E / h) g (the default of every
    # pair, :class:`contactfx.contact_edge.ContourMeasure`); edge = "x-max" in a problem file
    # extrapolates p^2 from the two outermost closed nodes instead

    def mesh_builder(self):
        p = self.p
        builder = functools.partial(
            cylinders,
            radius_lower=p.R_lower,
            radius_upper=p.R_upper,
            h_contact=p.h_contact,
            h_far=p.h_far,
            refine=p.refine,
            ratio=p.ratio,
            offset=p.offset,
        )
        return builder, 2

    def make_constants(self, mesh) -> None:
        self.push = dolfinx.fem.Constant(mesh, 0.0)

    def dirichlet(self, V, facet_tags) -> list:
        f = CylindersFacets
        return [
            fix_component(V, facet_tags, f.LOWER_BOTTOM, 1),
            fix_component(V, facet_tags, f.LOWER_SYMMETRY, 0),
            fix_component(V, facet_tags, f.UPPER_SYMMETRY, 0),
            _component_value(V, facet_tags, f.UPPER_TOP, 1, self.push),
        ]

    def boundary_data(self) -> list[dict]:
        return [
            export.fixed("lower_bottom", (1,)),
            export.fixed("lower_symmetry", (0,)),
            export.fixed("upper_symmetry", (0,)),
            {"group": "upper_top", "displacement": {"y": -self.p.depth}},
        ]

    def set_load(self, t: float) -> None:
        self.push.value = -t * self.p.depth

    def pressure_profile(self, s, force):
        """Hertz p0 sqrt(1 - s^2 / a^2) (0 beyond a) at the computed force."""
        ref = self.reference(force)
        return ref["p0"] * np.sqrt(np.clip(1.0 - (s / ref["a"]) ** 2, 0.0, None))

    def reference(self, force: float) -> dict[str, float]:
        return hertz_2d(force, self.R(), self.E_star())


@dataclass(frozen=True)
class HertzSpheresParams(two_elastic(1000.0, 0.3)):
    R_upper: float = param(1.0, "radius R1 of the upper sphere", positive=True)
    R_lower: float = param(1.0, "radius R2 of the lower sphere", positive=True)
    depth: float = param(
        0.02, "approach of the upper body's top (ramped over the load steps)", positive=True
    )
    h_contact: float = param(
        0.0065, "element size of the lower body in the contact zone", positive=True
    )
    h_far: float = param(0.25, "element size far from the contact zone", positive=True)
    refine: float = param(
        0.13, "radius of the refined zone around the first contact point", positive=True
    )
    # the slave (upper) surface coarser than the master: with a finer slave the nodal
    # pressures scatter by several % (docs/verification.md section 10)
    ratio: float = param(1.3, "element size of the upper body / that of the lower", positive=True)
    offset: float = param(
        0.3,
        "shift of the upper body's contact nodes (fraction of an element, in [0, 1))",
        nonnegative=True,
    )
    grading: float = param(
        0.3, "element size growth per unit distance from the refined zone", positive=True
    )


class HertzSpheres(_TwoHertz):
    name = "hertz-spheres"
    summary = "two elastic spheres pressed together (quarter model); reference Hertz a, p0"
    Params = HertzSpheresParams
    cells = {"lower": SpheresCells.LOWER, "upper": SpheresCells.UPPER}
    surfaces = {"lower": SpheresFacets.LOWER_CONTACT, "upper": SpheresFacets.UPPER_CONTACT}
    symmetry = 4.0
    symmetry_planes = (0, 1)  # x = 0 and y = 0
    # the radius of the disc of the area enclosed by the zero contour of p - (E / h) g
    size_rule = "disc-radius"

    def mesh_builder(self):
        p = self.p
        builder = functools.partial(
            spheres,
            radius_lower=p.R_lower,
            radius_upper=p.R_upper,
            h_contact=p.h_contact,
            h_far=p.h_far,
            refine=p.refine,
            ratio=p.ratio,
            offset=p.offset,
            grading=p.grading,
        )
        return builder, 3

    def make_constants(self, mesh) -> None:
        self.push = dolfinx.fem.Constant(mesh, 0.0)

    def dirichlet(self, V, facet_tags) -> list:
        f = SpheresFacets
        return [
            fix_component(V, facet_tags, f.LOWER_BOTTOM, 2),
            fix_component(V, facet_tags, f.LOWER_X0, 0),
            fix_component(V, facet_tags, f.UPPER_X0, 0),
            fix_component(V, facet_tags, f.LOWER_Y0, 1),
            fix_component(V, facet_tags, f.UPPER_Y0, 1),
            _component_value(V, facet_tags, f.UPPER_TOP, 2, self.push),
        ]

    def boundary_data(self) -> list[dict]:
        return [
            export.fixed("lower_bottom", (2,)),
            export.fixed("lower_x0", (0,)),
            export.fixed("upper_x0", (0,)),
            export.fixed("lower_y0", (1,)),
            export.fixed("upper_y0", (1,)),
            {"group": "upper_top", "displacement": {"z": -self.p.depth}},
        ]

    def set_load(self, t: float) -> None:
        self.push.value = -t * self.p.depth

    def h_slave(self) -> float:
        """The element size of the slave surface in the contact zone."""
        p = self.p
        return p.h_contact * (p.ratio if p.slave == "upper" else 1.0)

    def edge_ring(self) -> float:
        return self.h_slave()

    def reference(self, force: float) -> dict[str, float]:
        return hertz_3d(force, self.R(), self.E_star())
