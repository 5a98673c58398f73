"""Two-body scenes in 2D: an elastic flat punch on an elastic block, a rounded body dragged
along a block, and two identical cylinders pressed and sheared (docs/verification.md
section 10).

``punch-foundation``: a flat punch of half-width b with edges rounded by the radius rho (its
flat face is |x| <= a = b - rho), half model with the symmetry plane x = 0, pressed into a
block clamped at its bottom by the prescribed vertical displacement ``indentation`` of its top
(frictionless). As E_upper / E_lower (punch / block) grows the punch becomes rigid and the
pressure tends to the rigid flat punch of ``punch2d`` (docs/verification.md section 2),

    p(x) = P / (pi sqrt(a^2 - x^2)),

scored, as ``punch2d`` does, by the normalised interior pressure on |x| <= 0.8 a
(:func:`contactfx.scenes.flat_punch.normalised_pressure_error`); it is reported from
E_upper / E_lower >= 1e3 on (``rigid_ratio``). For any moduli the score ``edge_peak`` is the
largest nodal pressure over the mean pressure P / (2 b): for equal materials the edge
singularity is weaker than the rigid punch's (a corner of two elastic wedges, Dundurs 1969),
so it is reported, not compared with the rigid closed form.

``sliding-contact``: the rounded body of :func:`contactfx.meshes.rounded_on_block` (radius R,
cut at ``height``) is pressed into a wide block by the vertical displacement ``press`` of its
top during the first ``press_fraction`` of the load program, then dragged along the block by
``slide`` at that constant vertical displacement (frictionless). The pair's force on the
rounded body has the components Q (tangential, along x) and P (normal, along y), computed
from the nodal pressures and normals of the contact pair. Frictionless and elastic, the state
at each position is the static indentation moved along: in the continuum Q = 0 and P is
constant. Scores: ``P``, ``Q``, ``Q_over_P`` (last step), and over the steady drag (from the
fourth drag step on) ``max_abs_Q_over_P``, ``P_jump`` the largest relative change of P between
consecutive steps and ``P_variation`` (max - min) / mean of P: with mortar integrals the force
does not jump when slave nodes cross master facet boundaries. Q is not zero to round-off: the
pressure centroid of the discrete solution is off the body's axis by a fraction of an element
(the slave mesh is not symmetric about it, see ``offset``), so Q / P is a discretisation error
(2e-5 at the end of the default drag, at most 4e-5 over the steady drag). The frictionless
transmission itself is checked by the kind's score ``tangential_nodal_force`` (the tangential
nodal forces on the slave nodes from the bulk residual: the solver's tolerance).

``cattaneo-cylinders``: two identical cylinders (full half disks, :func:`contactfx.meshes.
cylinders` with ``full``), the lower one clamped at its flat bottom, the upper one's flat top
moved down by ``depth`` during the first ``press_fraction`` of the load program, then along
+x by ``shift`` at that depth, with Coulomb friction. Identical materials (Dundurs' beta = 0)
decouple the normal and the tangential problems: the pressing is frictionless in effect and
the Hertz pressure stays while the tangential force Q grows. Under a monotonically growing
Q < mu P the contact sticks on the central band |x| < c and slips outside it, with

    c / a = sqrt(1 - Q / (mu P))

(Cattaneo 1938, Mindlin 1949; Johnson 1985, section 7.1), a the Hertz half-width at the
normal force P; at Q = mu P the whole contact slips (gross slip). Scores per step: ``Q``,
``P`` and the ratio Q / (mu P) (``Q_over_muP``); the friction references compare the stick
half-width (the measure of the stick nodes / 2) with Cattaneo's at the computed Q / (mu P).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import Any, ClassVar

import dolfinx
import numpy as np

from contactfx.meshes import (
    CylindersFacets,
    PunchFoundationCells,
    PunchFoundationFacets,
    RoundedOnBlockCells,
    RoundedOnBlockFacets,
    cylinders,
    punch_foundation,
    rounded_on_block,
)
from contactfx.params import param
from contactfx.references import rigid_punch_2d
from contactfx.scenes import export
from contactfx.scenes._common import fix, fix_component, prescribe_component
from contactfx.scenes.flat_punch import normalised_pressure_error
from contactfx.scenes.hertz import cattaneo_mindlin
from contactfx.scenes.two_body import HertzCylinders
from contactfx.scenes.two_body_base import TwoBodyScene, two_elastic

__all__ = ["PunchFoundation", "SlidingContact", "CattaneoCylinders"]


def press_then_drag(
    group: str, drag: float, push: float, fraction: float, axis: str = "y"
) -> list[dict]:
    """The ``[[boundary]]`` tables of a face moved by ``push`` along ``axis`` (the vertical,
    y in 2D, z in 3D) during the first ``fraction`` of the load program, then along x by
    ``drag`` at that vertical displacement: one table per component, each with its
    piecewise-linear amplitude."""
    return [
        {
            "group": group,
            "displacement": {"x": float(drag)},
            "amplitude": [[0.0, 0.0], [float(fraction), 0.0], [1.0, 1.0]],
        },
        {
            "group": group,
            "displacement": {axis: float(push)},
            "amplitude": [[0.0, 0.0], [float(fraction), 1.0], [1.0, 1.0]],
        },
    ]


def press_drag_factors(t: float, fraction: float) -> tuple[float, float]:
    """(dragged, pressed) at load factor t: the fractions of the drag and of the pressing done
    when the pressing takes the first ``fraction`` of the load program and the drag the rest."""
    return max(t - fraction, 0.0) / (1.0 - fraction), min(t / fraction, 1.0)


def press_fraction_param(default: float):
    """The parameter ``press_fraction`` of a scene pressed, then dragged (with
    :class:`PressFraction`, which checks it is < 1)."""
    return param(default, "fraction of the load program spent pressing, in (0, 1)", positive=True)


class PressFraction:
    """Mixin of the parameter dataclasses with a ``press_fraction``
    (:func:`press_fraction_param`): after the fields' rules, press_fraction < 1."""

    press_fraction: float

    def __post_init__(self) -> None:
        super().__post_init__()  # type: ignore[misc]
        if not self.press_fraction < 1.0:
            raise ValueError(f"--press-fraction must be < 1, got {self.press_fraction}")


def press_drag(
    base: type,
    press: tuple[float, str],
    slide: tuple[float, str],
    press_fraction: float,
    *,
    slide_may_be_zero: bool = False,
) -> type:
    """Base of the parameters of a :class:`PressThenDrag` scene: the fields of ``base`` (the
    bodies'), then ``press`` and ``slide`` (each (default, help); press > 0, slide > 0 or,
    with ``slide_may_be_zero``, >= 0) and ``press_fraction`` (default ``press_fraction``,
    checked in (0, 1)). The scene's own fields (the block, the mesh sizes) follow."""
    fields = {
        "press": param(*press, positive=True),
        "slide": param(*slide, positive=not slide_may_be_zero, nonnegative=slide_may_be_zero),
        "press_fraction": press_fraction_param(press_fraction),
    }

    @dataclass(frozen=True)
    class PressDragParams(PressFraction, base):  # type: ignore[valid-type, misc]
        press: float = fields["press"]
        slide: float = fields["slide"]
        press_fraction: float = fields["press_fraction"]

    return PressDragParams


@dataclass(frozen=True)
class PunchFoundationParams(two_elastic(1000.0, 0.3)):
    # E_lower / nu_lower: the block; E_upper / nu_upper: the punch (stiff by default)
    E_upper: float = param(1e6, "Young's modulus of the upper body (the punch)", positive=True)
    b: float = param(
        0.052, "half-width of the punch (flat face b - rho, then the rounded edge)", positive=True
    )
    rho: float = param(0.002, "edge radius of the punch", positive=True)
    punch_height: float = param(0.05, "height of the punch", positive=True)
    indentation: float = param(
        1e-4, "prescribed downward displacement of the punch's top", positive=True
    )
    width: float = param(1.0, "half-width of the block", positive=True)
    depth: float = param(1.0, "depth of the block", positive=True)
    h_contact: float = param(5e-4, "element size of the block under the punch", positive=True)
    h_far: float = param(0.1, "element size far from the punch", positive=True)
    refine: float = param(
        0.01, "distance from the punch face meshed with the contact sizes", positive=True
    )
    ratio: float = param(1.2, "element size of the punch / that of the block", positive=True)
    offset: float = param(
        0.3,
        "shift of the punch's contact nodes (fraction of an element, in [0, 1))",
        nonnegative=True,
    )
    rigid_ratio: float = param(
        1e3,
        "E_upper / E_lower from which the punch is compared with the rigid flat punch",
        positive=True,
    )


class PunchFoundation(TwoBodyScene):
    name = "punch-foundation"
    summary = (
        "elastic flat punch with rounded edges on an elastic block (half model); stiff "
        "punch: rigid flat punch pressure, equal moduli: edge peak"
    )
    Params = PunchFoundationParams
    cells = {"lower": PunchFoundationCells.BLOCK, "upper": PunchFoundationCells.PUNCH}
    surfaces = {
        "lower": PunchFoundationFacets.BLOCK_TOP,
        "upper": PunchFoundationFacets.PUNCH_CONTACT,
    }
    symmetry = 2.0
    symmetry_planes = (0,)  # x = 0

    def mesh_builder(self):
        p = self.p
        builder = functools.partial(
            punch_foundation,
            width=p.width,
            depth=p.depth,
            b=p.b,
            rho=p.rho,
            h_punch=p.punch_height,
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
        f = PunchFoundationFacets
        return [
            *fix(V, facet_tags, f.BLOCK_BOTTOM),
            fix_component(V, facet_tags, f.BLOCK_SYMMETRY, 0),
            fix_component(V, facet_tags, f.PUNCH_SYMMETRY, 0),
            prescribe_component(V, facet_tags, f.PUNCH_TOP, 1, self.push),
        ]

    def boundary_data(self) -> list[dict]:
        return [
            export.fixed("block_bottom", (0, 1)),
            export.fixed("block_symmetry", (0,)),
            export.fixed("punch_symmetry", (0,)),
            {"group": "punch_top", "displacement": {"y": -self.p.indentation}},
        ]

    def set_load(self, t: float) -> None:
        self.push.value = -t * self.p.indentation

    @property
    def flat_half_width(self) -> float:
        """a = b - rho, the half-width of the flat face (``punch2d``'s punch_half_width)."""
        return self.p.b - self.p.rho

    def rigid(self) -> bool:
        return self.p.E_upper >= self.p.rigid_ratio * self.p.E_lower

    def pressure_scores(self, x, p, force):
        """The rigid-punch score of ``punch2d`` (stiff punch only) and the edge peak: the
        largest nodal pressure over the mean pressure P / (2 b)."""
        scores = {"edge_peak": float(np.max(p, initial=0.0)) * 2.0 * self.p.b / force}
        if self.rigid():
            scores["normalised_pressure_error"] = normalised_pressure_error(
                x, p, force, self.flat_half_width
            )
        return scores

    def pressure_profile(self, s, force):
        """The rigid flat punch (stiff punch only)."""
        return rigid_punch_2d(s, self.flat_half_width, force) if self.rigid() else None


@dataclass(frozen=True)
class _RoundedBodyParams(two_elastic(1000.0, 0.3)):
    radius: float = param(1.0, "radius R of the rounded body", positive=True)
    height: float = param(
        0.15, "height of the rounded body (the disk cut at y = height <= R)", positive=True
    )


@dataclass(frozen=True)
class SlidingContactParams(
    press_drag(
        _RoundedBodyParams,
        press=(2e-3, "prescribed downward displacement of the rounded body's top"),
        slide=(0.2, "tangential displacement of the top (along +x) after pressing"),
        press_fraction=0.1,
    )
):
    left: float = param(0.8, "extent of the block left of the first contact point", positive=True)
    right: float = param(
        1.2, "extent of the block right of the first contact point (> slide)", positive=True
    )
    depth: float = param(0.5, "depth of the block", positive=True)
    h_contact: float = param(4e-3, "element size of the block along the track", positive=True)
    h_far: float = param(0.1, "element size far from the contact", positive=True)
    refine: float = param(
        0.06, "distance from the track meshed with the contact sizes", positive=True
    )
    ratio: float = param(0.8, "element size of the rounded body / that of the block", positive=True)
    offset: float = param(
        0.3,
        "shift of the rounded body's contact nodes (fraction of an element, in [0, 1))",
        nonnegative=True,
    )


class PressThenDrag(TwoBodyScene):
    """A body's top pressed down by ``press`` on [0, press_fraction] of the load program, then
    dragged along +x by ``slide`` at that depth, the other body's bottom clamped: ``clamped``
    and ``driven`` are (facet tag, problem-file group) of the two; the scene's parameters
    (:func:`press_drag`) ``press``, ``slide`` and ``press_fraction``. The run's friction law
    and coefficient are kept (``friction``, ``mu``) for the scores."""

    clamped: ClassVar[tuple[int, str]]
    driven: ClassVar[tuple[int, str]]
    #: the gmsh builder of the body on the block (the track's length is its keyword
    #: ``track``), the names of the body's own parameters it takes and of the block's and the
    #: mesh sizes' (the keywords of rounded_on_block by default), and the dimension
    builder: ClassVar[Any]
    body_params: ClassVar[tuple[str, ...]]
    block_params: ClassVar[tuple[str, ...]] = (
        "left",
        "right",
        "depth",
        "h_contact",
        "h_far",
        "refine",
        "ratio",
        "offset",
    )
    dim: ClassVar[int] = 2
    #: Q = q_sign times the x component of the pair's force on the driven body: -1 the force
    #: that drags the body along +x, +1 the force along +x
    q_sign: ClassVar[float] = -1.0
    #: the vertical axis (P's component, the pressing's direction): None for the last one
    #: (y in 2D, z in 3D)
    vertical: ClassVar[int | None] = None

    friction = "none"
    mu = 0.0

    def configure(self, numerics) -> None:
        super().configure(numerics)
        self.friction, self.mu = numerics.friction, float(numerics.mu)

    @property
    def coulomb(self) -> bool:
        """Coulomb friction with mu > 0."""
        return self.friction == "coulomb" and self.mu > 0.0

    def mesh_builder(self):
        p = self.p
        builder = functools.partial(
            type(self).builder,
            **{name: getattr(p, name) for name in self.body_params + self.block_params},
            track=p.slide,
        )
        return builder, self.dim

    def make_constants(self, mesh) -> None:
        self.push = dolfinx.fem.Constant(mesh, 0.0)
        self.drag = dolfinx.fem.Constant(mesh, 0.0)

    def dirichlet(self, V, facet_tags) -> list:
        top = self.driven[0]
        return [
            *fix(V, facet_tags, self.clamped[0]),
            prescribe_component(V, facet_tags, top, 0, self.drag),
            prescribe_component(V, facet_tags, top, 1, self.push),
        ]

    def boundary_data(self) -> list[dict]:
        p = self.p
        return [
            export.fixed(self.clamped[1], (0, 1)),
            *press_then_drag(self.driven[1], p.slide, -p.press, p.press_fraction),
        ]

    def top_displacement(self, t: float) -> tuple[float, float]:
        """(tangential, vertical) displacement of the top at load factor t: pressing on
        [0, press_fraction], then dragging at the constant vertical displacement."""
        dragged, pressed = press_drag_factors(t, self.p.press_fraction)
        return dragged * self.p.slide, -pressed * self.p.press

    def set_load(self, t: float) -> None:
        self.drag.value, self.push.value = self.top_displacement(t)

    def drag_steps(self, loads: np.ndarray) -> np.ndarray:
        """The indices of the steps after the pressing."""
        return np.flatnonzero(loads > self.p.press_fraction * (1.0 + 1e-9))

    def forces_PQ(self, forces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(P, Q) per step from the pair's force on the driven body (``forces``, a row a
        step): P its vertical component (the block pushes the body up), Q ``q_sign`` times its
        x component."""
        axis = self.dim - 1 if self.vertical is None else self.vertical
        return forces[:, axis], self.q_sign * forces[:, 0]

    @staticmethod
    def last_step(P: np.ndarray, Q: np.ndarray) -> dict[str, float]:
        """P, Q and Q / P at the last step."""
        return {"P": float(P[-1]), "Q": float(Q[-1]), "Q_over_P": float(Q[-1] / P[-1])}


class SlidingContact(PressThenDrag):
    name = "sliding-contact"
    summary = (
        "rounded body pressed into a block and dragged along it (frictionless); "
        "Q / P = 0, P without jumps"
    )
    Params = SlidingContactParams
    cells = {"lower": RoundedOnBlockCells.BLOCK, "upper": RoundedOnBlockCells.ROUNDED}
    surfaces = {
        "lower": RoundedOnBlockFacets.BLOCK_TOP,
        "upper": RoundedOnBlockFacets.ROUNDED_CONTACT,
    }
    numerics_defaults = {"steps": 50}

    builder = staticmethod(rounded_on_block)
    body_params = ("radius", "height")
    # Q: the force along +x
    q_sign = 1.0

    #: the block's clamped bottom and the rounded body's driven top: (facet tag, group)
    clamped = (RoundedOnBlockFacets.BLOCK_BOTTOM, "block_bottom")
    driven = (RoundedOnBlockFacets.ROUNDED_TOP, "rounded_top")

    def force_scores(self, loads, forces):
        """P, Q, Q / P at the last step; over the steady drag (the drag steps from the fourth
        on) the largest |Q / P|, the largest relative change of P between consecutive steps
        and the spread (max - min) / mean of P. The first three drag steps are the load
        program's transient: the secant predictor extrapolates the pressing into the first
        drag step, and the search of a step runs at its prediction (|Q / P| up to 2e-3 and P
        changes of 3e-3 there with the defaults)."""
        P, Q = self.forces_PQ(forces)
        scores = self.last_step(P, Q)
        steady = self.drag_steps(loads)[3:]
        if len(steady) >= 2:
            Pd, Qd = P[steady], Q[steady]
            scores["max_abs_Q_over_P"] = float(np.max(np.abs(Qd / Pd)))
            scores["P_jump"] = float(np.max(np.abs(np.diff(Pd)) / Pd[:-1]))
            scores["P_variation"] = float((Pd.max() - Pd.min()) / Pd.mean())
        return scores


@dataclass(frozen=True)
class CattaneoCylindersParams(PressFraction, two_elastic(1000.0, 0.3)):
    R_upper: float = param(1.0, "radius R1 of the upper cylinder", positive=True)
    R_lower: float = param(1.0, "radius R2 of the lower cylinder", positive=True)
    depth: float = param(
        5e-3, "downward displacement of the upper body's top (pressing)", positive=True
    )
    shift: float = param(
        1.5e-3, "displacement of the top along +x after pressing", nonnegative=True
    )
    press_fraction: float = press_fraction_param(0.5)
    h_contact: float = param(
        1e-3, "element size of the lower body in the contact zone", positive=True
    )
    h_far: float = param(0.1, "element size far from the contact zone", positive=True)
    refine: float = param(
        0.045, "radius of the refined zone around the first contact point", positive=True
    )
    ratio: float = param(0.75, "element size of the upper body / that of the lower", positive=True)
    offset: float = param(
        0.3,
        "shift of the upper body's contact nodes (fraction of an element, in [0, 1))",
        nonnegative=True,
    )


class CattaneoCylinders(HertzCylinders):
    name = "cattaneo-cylinders"
    summary = (
        "two identical cylinders pressed, then sheared with Coulomb friction; "
        "stick half-width c / a = sqrt(1 - Q / (mu P))"
    )
    Params = CattaneoCylindersParams
    symmetry = 1.0  # the whole pair: the shear breaks the mirror symmetry about x = 0
    symmetry_planes = ()
    numerics_defaults = {"friction": "coulomb", "mu": 0.3, "steps": 8}

    # half the length of the contact band inside the zero contour of p - (E / h) g

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
            full=True,
        )
        return builder, 2

    def make_constants(self, mesh) -> None:
        self.push = dolfinx.fem.Constant(mesh, 0.0)
        self.drag = dolfinx.fem.Constant(mesh, 0.0)

    def dirichlet(self, V, facet_tags) -> list:
        f = CylindersFacets
        return [
            *fix(V, facet_tags, f.LOWER_BOTTOM),
            prescribe_component(V, facet_tags, f.UPPER_TOP, 0, self.drag),
            prescribe_component(V, facet_tags, f.UPPER_TOP, 1, self.push),
        ]

    def boundary_data(self) -> list[dict]:
        p = self.p
        return [
            export.fixed("lower_bottom", (0, 1)),
            *press_then_drag("upper_top", p.shift, -p.depth, p.press_fraction),
        ]

    def set_load(self, t: float) -> None:
        dragged, pressed = press_drag_factors(t, self.p.press_fraction)
        self.push.value = -pressed * self.p.depth
        self.drag.value = dragged * self.p.shift

    def force_scores(self, loads, forces):
        """Q, P at the last step and Q / (mu P) is in the friction references."""
        return {"P": float(forces[-1, 1]), "Q": float(forces[-1, 0])}

    def friction_reference(self, q, friction) -> dict[str, float]:
        ref = self.reference(q.force)
        return cattaneo_mindlin(q.friction, ref["a"], exponent=0.5, exact=True)
