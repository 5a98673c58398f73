"""Hertz line contact (2D, plane strain) and sphere contact (3D, quarter model).

A rigid cylinder / sphere of radius R is pressed by the depth ``depth`` into an elastic block
whose bottom is clamped. The reference is evaluated at the computed force P (the finite block
changes the force-depth relation, not a and p0 at given P; docs/verification.md section 1):

    2D: a = sqrt(4 P R / (pi E*)),  p0 = 2 P / (pi a)
    3D: a = (3 P R / (4 E*))^(1/3), p0 = 3 P / (2 pi a^2)

(Johnson 1985, Contact Mechanics, doi:10.1017/CBO9781139171731, sections 4.2 and 5.2).

The 2D block may carry a bonded top layer -layer_thickness < y < 0 of Young's modulus layer_E
(same Poisson's ratio; the mesh resolves the interface). With layer_E != E the half-space
closed form does not apply (the contact then depends on a / layer_thickness and on the modulus
contrast) and the scene reports no reference.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import dolfinx
import numpy as np
import ufl

from contactfx import _compat
from contactfx.contact.obstacles import Ball, Obstacle, Paraboloid
from contactfx.mechanics.elasticity import Elastic
from contactfx.meshes import BoxFacets, RectangleFacets, box, rectangle
from contactfx.params import param
from contactfx.references import hertz_2d, hertz_3d
from contactfx.scenes import export
from contactfx.scenes._common import fix, fix_component
from contactfx.scenes.base import ObstacleScene, elastic

__all__ = ["Hertz2D", "Hertz3D", "QuarterBlock", "cattaneo_mindlin"]


def _elliptic(p0, s2):
    """Hertz pressure p0 sqrt(1 - s^2), zero outside the contact (s^2 = (x / a)^2)."""
    return p0 * ufl.sqrt(ufl.max_value(1.0 - s2, 0.0))


def _indent_then_shift(t: float, depth: float, shift: float, gdim: int) -> np.ndarray:
    """Indentation over the load factor t (all of it, or its first half when the indenter is
    then shifted tangentially along x over the second half)."""
    offset = np.zeros(gdim)
    if shift > 0.0:
        offset[0] = shift * max(0.0, 2.0 * t - 1.0)
        t = min(2.0 * t, 1.0)
    offset[gdim - 1] = -t * depth
    return offset


def cattaneo_mindlin(f, a: float, exponent: float, exact: bool = False) -> dict[str, float]:
    """Stick size c = a (1 - Q / (mu P))^exponent (2D: 1/2, 3D: 1/3) at the computed normal
    force P and tangential force Q (Johnson 1985, section 7.1; approximate on a rigid-elastic
    pair, Dundurs beta != 0). With Q the x component and the bound mu P of the friction
    quantities ``f`` (:class:`contactfx.results.Friction`). ``exact`` (two bodies of one
    material, Dundurs beta = 0): the computed stick size's relative error is an error measure
    (``c_rel_error``); otherwise c is reported only."""
    if f.bound <= 0.0:
        return {}
    ratio = abs(f.tangential_force[0]) / f.bound
    c = a * max(0.0, 1.0 - ratio) ** exponent
    out = {
        "Q_over_bound": ratio,
        "c": c,
        "c_computed": f.stick_size,
        "c_over_a_computed": f.stick_size / a,
        "c_over_a": c / a,
    }
    if exact and c > 0.0:
        out["c_rel_error"] = abs(f.stick_size - c) / c
    return out


def _indenter(profile: str, radius: float) -> Obstacle:
    return Ball(radius) if profile == "circle" else Paraboloid(radius)


@dataclass(frozen=True)
class Hertz2DParams(elastic(1000.0, 0.3)):
    radius: float = param(1.0, "indenter radius R", positive=True)
    profile: str = param("parabola", "indenter profile", choices=("circle", "parabola"))
    depth: float = param(1.5e-3, "indentation depth (ramped over the load steps)", positive=True)
    half_width: float = param(1.0, "block half-width", positive=True)
    height: float = param(1.0, "block height", positive=True)
    h_contact: float = param(3e-3, "element size in the contact zone", positive=True)
    h_far: float = param(0.1, "element size far from the contact zone", positive=True)
    refine_half_width: float = param(0.06, "half-width of the refined zone", positive=True)
    shift: float = param(
        0.0,
        "tangential displacement of the indenter after the indentation (needs friction)",
        nonnegative=True,
    )
    gap0: float = param(
        0.0,
        "initial clearance of the indenter at load 0 (< 0: interference; "
        "the final position is still -depth)",
    )
    layer_thickness: float = param(
        0.0, "thickness of a bonded top layer -t < y < 0 (0: homogeneous block)", nonnegative=True
    )
    layer_E: float = param(0.0, "Young's modulus of the top layer (0: same as E)", nonnegative=True)

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.gap0 != 0.0 and self.shift > 0.0:
            raise ValueError("--gap0 and --shift cannot be combined")
        if not self.layer_thickness < self.height:
            raise ValueError(
                f"--layer-thickness must be < --height, got {self.layer_thickness} >= {self.height}"
            )
        if self.layer_E > 0.0 and self.layer_thickness == 0.0:
            raise ValueError("--layer-E needs --layer-thickness > 0")


class Hertz2D(ObstacleScene):
    name = "hertz2d"
    summary = "rigid cylinder pressed into a plane-strain block; reference Hertz a and p0"
    Params = Hertz2DParams
    contact_tag = RectangleFacets.TOP

    @property
    def layered(self) -> bool:
        return self.p.layer_thickness > 0.0

    @property
    def layer_E(self) -> float:
        """Young's modulus of the top layer (E without a layer)."""
        return self.p.layer_E if self.layered and self.p.layer_E > 0.0 else self.p.E

    def mesh_builder(self):
        p = self.p
        return functools.partial(
            rectangle,
            x0=-p.half_width,
            x1=p.half_width,
            y0=-p.height,
            y1=0.0,
            refine_x0=-p.refine_half_width,
            refine_x1=p.refine_half_width,
            h_contact=p.h_contact,
            h_far=p.h_far,
            interfaces=(-p.layer_thickness,) if self.layered else (),
        ), 2

    def modulus(self, mesh):
        """Piecewise constant (DG0) modulus: layer_E in the layer, E below. The interface is a
        mesh line, so each cell lies on one side and its midpoint tells which."""
        if not self.layered:
            return None
        field = dolfinx.fem.Function(_compat.function_space(mesh, "DG", 0), name="youngs_modulus")
        top, bottom, t = self.layer_E, self.p.E, self.p.layer_thickness
        field.interpolate(lambda x: np.where(x[1] > -t, top, bottom))
        return field

    def contact_modulus(self) -> float:
        return self.layer_E

    def obstacle(self) -> Obstacle:
        return _indenter(self.p.profile, self.p.radius)

    def obstacle_offset(self, t: float, gdim: int) -> np.ndarray:
        offset = _indent_then_shift(t, self.p.depth, self.p.shift, gdim)
        offset[gdim - 1] += (1.0 - t) * self.p.gap0
        return offset

    def dirichlet(self, V, facet_tags):
        return fix(V, facet_tags, RectangleFacets.BOTTOM)

    def problem_data(self, numerics) -> dict:
        p = self.p
        bodies = [export.body("domain", self.material())]
        if self.layered:  # the top layer: its own cell group, the same nu
            bodies.append(export.body("layer", Elastic(self.layer_E, p.nu)))
        kinks = (0.0, 0.5, 1.0) if p.shift > 0.0 else (0.0, 1.0)
        shape = "circle" if p.profile == "circle" else "parabola"
        return {
            "bodies": bodies,
            "boundary": [export.fixed("bottom", (0, 1))],
            "obstacle": {
                "shape": shape,
                "contact": "top",
                "radius": p.radius,
                "h": p.h_contact,
                **export.motion(self.obstacle_offset, 2, kinks),
            },
        }

    def _hertz(self, force: float) -> dict[str, float]:
        """The half-space closed form, or {} for a layer of another modulus (none applies)."""
        if self.layer_E != self.p.E:
            return {}
        return hertz_2d(force, self.p.radius, self.material().E_star)

    def reference(self, force: float) -> dict[str, float]:
        return self._hertz(force)

    def exact_pressure(self, x, ref: dict):
        if self.p.shift > 0.0 or not ref:  # moving indenter, or no closed form (a layer)
            return None
        return _elliptic(ref["p0"], x[0] ** 2 / ref["a"] ** 2)

    def friction_reference(self, q, friction) -> dict[str, float]:
        ref = self._hertz(q.force)
        return cattaneo_mindlin(q.friction, ref["a"], exponent=0.5) if ref else {}


@dataclass(frozen=True)
class Hertz3DParams(elastic(1000.0, 0.3)):
    radius: float = param(1.0, "indenter radius R", positive=True)
    profile: str = param("parabola", "indenter profile", choices=("circle", "parabola"))
    depth: float = param(0.01, "indentation depth (ramped over the load steps)", positive=True)
    size: float = param(1.0, "edge of the quarter block (x, y in [0, size])", positive=True)
    height: float = param(1.0, "block height", positive=True)
    h_contact: float = param(0.02, "element size in the contact zone", positive=True)
    h_far: float = param(0.3, "element size far from the contact zone", positive=True)
    refine_radius: float = param(0.15, "radius of the refined zone", positive=True)
    shift: float = param(
        0.0,
        "tangential displacement (x) of the indenter after the "
        "indentation (needs friction; half model)",
        nonnegative=True,
    )


class QuarterBlock(ObstacleScene):
    """A block [0, size]^2 x [-height, 0] with the symmetry planes x = 0 and y = 0 (quarter
    model of an axisymmetric indentation), clamped at the bottom, contact on the top. With a
    tangential shift along x the plane x = 0 is no symmetry plane: then the half model
    [-size, size] x [0, size] x [-height, 0]."""

    contact_tag = BoxFacets.ZMAX

    def __init__(self, params) -> None:
        super().__init__(params)
        self.shift = getattr(params, "shift", 0.0)
        self.half = self.shift > 0.0
        self.symmetry = 2.0 if self.half else 4.0
        # the mirror images add F_z (and F_x of the half model) and cancel F_y (and F_x of
        # the quarter model)
        self.symmetry_planes = (1,) if self.half else (0, 1)

    def refine_radius(self) -> float:
        raise NotImplementedError

    def mesh_builder(self):
        p = self.p
        return functools.partial(
            box,
            x0=-p.size if self.half else 0.0,
            x1=p.size,
            y0=0.0,
            y1=p.size,
            z0=-p.height,
            z1=0.0,
            refine_center=(0.0, 0.0),
            refine_radius=self.refine_radius(),
            h_contact=p.h_contact,
            h_far=p.h_far,
        ), 3

    def obstacle_offset(self, t: float, gdim: int) -> np.ndarray:
        return _indent_then_shift(t, self.p.depth, self.shift, gdim)

    def obstacle_data(self) -> dict:
        """The ``[obstacle]`` shape keys of the indenter."""
        raise NotImplementedError

    def problem_data(self, numerics) -> dict:
        boundary = [export.fixed("zmin", (0, 1, 2)), export.fixed("ymin", (1,))]
        if not self.half:
            boundary.append(export.fixed("xmin", (0,)))
        kinks = (0.0, 0.5, 1.0) if self.half else (0.0, 1.0)
        return {
            "bodies": [export.body("domain", self.material())],
            "boundary": boundary,
            "obstacle": {
                **self.obstacle_data(),
                "contact": "zmax",
                "h": self.p.h_contact,
                **export.motion(self.obstacle_offset, 3, kinks),
            },
            "output": {
                "symmetry": self.symmetry,
                "symmetry_planes": ["xyz"[k] for k in self.symmetry_planes],
            },
        }

    def dirichlet(self, V, facet_tags):
        bcs = [*fix(V, facet_tags, BoxFacets.ZMIN), fix_component(V, facet_tags, BoxFacets.YMIN, 1)]
        if not self.half:
            bcs.append(fix_component(V, facet_tags, BoxFacets.XMIN, 0))
        return bcs

    def contact_size(self, measure: float) -> float:
        return float(np.sqrt(measure / np.pi))


class Hertz3D(QuarterBlock):
    name = "hertz3d"
    summary = "rigid sphere pressed into a block (quarter model); reference Hertz a and p0"
    Params = Hertz3DParams

    def refine_radius(self) -> float:
        return self.p.refine_radius

    def obstacle_data(self) -> dict:
        shape = "sphere" if self.p.profile == "circle" else "paraboloid"
        return {"shape": shape, "radius": self.p.radius}

    def obstacle(self) -> Obstacle:
        return _indenter(self.p.profile, self.p.radius)

    def reference(self, force: float) -> dict[str, float]:
        return hertz_3d(force, self.p.radius, self.material().E_star)

    def exact_pressure(self, x, ref: dict):
        if self.half:
            return None
        return _elliptic(ref["p0"], (x[0] ** 2 + x[1] ** 2) / ref["a"] ** 2)

    def friction_reference(self, q, friction) -> dict[str, float]:
        ref = hertz_3d(q.force, self.p.radius, self.material().E_star)
        return cattaneo_mindlin(q.friction, ref["a"], exponent=1.0 / 3.0)


@dataclass(frozen=True)
class HertzAxiParams(elastic(1000.0, 0.3)):
    radius: float = param(1.0, "indenter radius R", positive=True)
    profile: str = param("parabola", "indenter profile", choices=("circle", "parabola"))
    depth: float = param(0.01, "indentation depth (ramped over the load steps)", positive=True)
    block_radius: float = param(1.0, "radius of the cylindrical block", positive=True)
    height: float = param(1.0, "block height", positive=True)
    h_contact: float = param(5e-3, "element size in the contact zone", positive=True)
    h_far: float = param(0.1, "element size far from the contact zone", positive=True)
    refine_radius: float = param(0.15, "radius of the refined zone", positive=True)


class HertzAxi(ObstacleScene):
    """The indentation of hertz3d as a body of revolution: a rigid sphere (or paraboloid) of
    radius R pressed into a cylindrical block of radius ``block_radius`` and height
    ``height``, computed on its (r, z) section [0, block_radius] x [-height, 0]
    (:mod:`contactfx.mechanics.axisymmetric`): the axis r = 0 holds u_r = 0, the bottom is
    clamped, the side free. Hertz's 3D closed forms at the computed force (Johnson 1985,
    doi:10.1017/CBO9781139171731, 4.2), with a 2D mesh."""

    name = "hertz-axi"
    summary = (
        "rigid sphere pressed into a cylindrical block, axisymmetric (r-z section); reference "
        "Hertz 3D a and p0"
    )
    Params = HertzAxiParams
    contact_tag = RectangleFacets.TOP
    axisymmetric = True
    #: forces and areas are 2 pi times their integrals over the section (weighted by r); the
    #: radial forces cancel over the revolution (``Scene.force_symmetry``)
    symmetry = 2.0 * np.pi

    def mesh_builder(self):
        p = self.p
        return functools.partial(
            rectangle,
            x0=0.0,
            x1=p.block_radius,
            y0=-p.height,
            y1=0.0,
            refine_x0=0.0,
            refine_x1=p.refine_radius,
            h_contact=p.h_contact,
            h_far=p.h_far,
        ), 2

    def obstacle(self) -> Obstacle:
        return _indenter(self.p.profile, self.p.radius)

    def obstacle_offset(self, t: float, gdim: int) -> np.ndarray:
        return _indent_then_shift(t, self.p.depth, 0.0, gdim)

    def dirichlet(self, V, facet_tags):
        return [
            *fix(V, facet_tags, RectangleFacets.BOTTOM),
            fix_component(V, facet_tags, RectangleFacets.LEFT, 0),
        ]

    def problem_data(self, numerics) -> dict:
        p = self.p
        shape = "circle" if p.profile == "circle" else "parabola"
        return {
            "bodies": [export.body("domain", self.material())],
            "boundary": [export.fixed("bottom", (0, 1)), export.fixed("left", (0,))],
            "obstacle": {
                "shape": shape,
                "contact": "top",
                "radius": p.radius,
                "h": p.h_contact,
                **export.motion(self.obstacle_offset, 2),
            },
        }

    def contact_size(self, measure: float) -> float:
        """The contact radius of the contact area pi a^2 (2 pi times int r dl)."""
        return float(np.sqrt(measure / np.pi))

    def reference(self, force: float) -> dict[str, float]:
        return hertz_3d(force, self.p.radius, self.material().E_star)

    def exact_pressure(self, x, ref: dict):
        return _elliptic(ref["p0"], x[0] ** 2 / ref["a"] ** 2)
