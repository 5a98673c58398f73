"""Typed results of a run: what the driver measures, what run.json holds, what the command
line, bench, stress and the tests read.

:class:`RunSummary` has named fields; :meth:`RunSummary.to_json` writes them under the run.json
keys documented in the README (the same keys as before the summary was typed, so old readers
keep working). Scene-specific numbers (closed-form comparisons, scores, field errors) are
named floats in the ``reference``, ``scores`` and ``errors`` mappings; the error measures that
bench and stress tabulate are named once, in :data:`MEASURES`.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

__all__ = [
    "StepLog",
    "never_closed",
    "Friction",
    "InterfaceQuantities",
    "Quantities",
    "RunSummary",
    "MEASURES",
    "measure",
]


@dataclass(frozen=True)
class Friction:
    """Friction quantities of a rigid-obstacle contact: tangential force per component (full
    model), the friction bound integrated over the contact (mu P for Coulomb), the stick zone's
    half-width / radius, the slipping fraction of the contact set, and the largest excess of
    |t_T| over the bound (relative to the bound; 0 up to the solver tolerance)."""

    tangential_force: list[float]
    bound: float
    stick_size: float
    slip_fraction: float
    excess: float


@dataclass(frozen=True)
class InterfaceQuantities:
    """Fitted-interface quantities: the tangential force along the interface direction, the
    force the proppant carries and the smallest aperture on the propped part (with a proppant
    floor), and the scene's own integrals (e.g. the joint column's top displacement)."""

    tangential_force: float
    proppant_force: float | None = None
    min_aperture_propped: float | None = None
    extra: dict[str, float] = field(default_factory=dict)


@dataclass(frozen=True)
class Quantities:
    """The contact state after a load step (full model: multiplied by the symmetry).

    force: normal contact force; contact_size: contact half-width / radius (rigid obstacle) or
    closed length (interface); peak_pressure; max_penetration (>= 0); complementarity: max |g p|
    at the surface nodes."""

    force: float
    contact_size: float
    peak_pressure: float
    max_penetration: float
    complementarity: float
    friction: Friction | None = None
    interface: InterfaceQuantities | None = None

    def to_json(self) -> dict[str, Any]:
        """The run.json keys of the final state (interfaces: also under the rigid-obstacle names
        force and peak_pressure, for tools reading any run.json)."""
        if self.interface is None:
            return {**_keys(self, _OBSTACLE), **_keys(self.friction, _FRICTION)}
        i = self.interface
        return {
            **_keys(self, _INTERFACE),
            **_keys(i, _INTERFACE_PARTS),
            **i.extra,
            "force": self.force,
            "peak_pressure": self.peak_pressure,
        }

    def step_json(self) -> dict[str, Any]:
        """The per-step subset written into run.json's ``steps``."""
        if self.interface is None:
            return {**_keys(self, _OBSTACLE, 2), **_keys(self.friction, _FRICTION, 2)}
        return {**_keys(self, _INTERFACE, 1), **_keys(self.interface, _INTERFACE_PARTS, 1)}

    @classmethod
    def from_json(cls, d: dict[str, Any]) -> Quantities:
        """The final state of a run.json (:meth:`RunSummary.to_json`)."""
        if "normal_force" not in d:
            friction = Friction(**_attrs(d, _FRICTION)) if "friction_bound" in d else None
            return cls(**_attrs(d, _OBSTACLE), friction=friction)
        known = (
            {f.name for f in dataclasses.fields(RunSummary)}
            | set(_OBSTACLE)
            | set(_INTERFACE)
            | set(_INTERFACE_PARTS)
            | {"status", "newton_iterations", "ksp_iterations", "outer_iterations", "plot"}
        )
        extra = {k: v for k, v in d.items() if k not in known}
        interface = InterfaceQuantities(**_attrs(d, _INTERFACE_PARTS), extra=extra)
        return cls(**_attrs(d, _INTERFACE), interface=interface)


#: run.json key -> attribute, for each part of the state (the keys the README documents)
_OBSTACLE = {
    "force": "force",
    "contact_half_width": "contact_size",
    "peak_pressure": "peak_pressure",
    "max_penetration": "max_penetration",
    "complementarity": "complementarity",
}
_FRICTION = {
    "tangential_force": "tangential_force",
    "stick_size": "stick_size",
    "friction_bound": "bound",
    "slip_fraction": "slip_fraction",
    "friction_excess": "excess",
}
_INTERFACE = {
    "normal_force": "force",
    "closed_length": "contact_size",
    "max_pressure": "peak_pressure",
    "max_penetration": "max_penetration",
    "complementarity": "complementarity",
}
_INTERFACE_PARTS = {
    "tangential_force": "tangential_force",
    "proppant_force": "proppant_force",
    "min_aperture_propped": "min_aperture_propped",
}


def _keys(obj, table: dict[str, str], n: int | None = None) -> dict:
    """{key: obj.attribute} over the table's first n entries (None values left out)."""
    if obj is None:
        return {}
    items = list(table.items())[:n]
    return {k: getattr(obj, a) for k, a in items if getattr(obj, a) is not None}


def _attrs(d: dict, table: dict[str, str]) -> dict:
    """{attribute: d[key]} for the table's keys present in d."""
    return {a: d[k] for k, a in table.items() if k in d}


@dataclass(frozen=True)
class StepLog:
    """One converged load step: iterations, cut-backs, SNES reason and the contact state."""

    step: int
    load: float
    newton: int
    ksp: int
    outer: int
    cutbacks: int
    reason: str
    coarse_newton: int  # nested iteration: Newton iterations on the coarser meshes
    halvings: int  # Newton steps halved so that no element inverts (finite strain)
    quantities: Quantities
    #: a dynamic run's energy balance at the step (:class:`contactfx.driver.inertia.
    #: EnergyLedger`), None in a static run
    energy: dict[str, float] | None = None

    def to_json(self) -> dict[str, Any]:
        head = {f.name: getattr(self, f.name) for f in _STEP_COUNTS}
        out = {**head, **self.quantities.step_json()}
        if self.energy is not None:
            out["energy"] = dict(self.energy)
        return out


#: StepLog's fields before its quantities (the step, its time and counts)
_STEP_COUNTS = dataclasses.fields(StepLog)[:-2]


@dataclass
class RunSummary:
    """A completed run (what run.json holds)."""

    scene: str
    parameters: dict[str, Any]
    numerics: dict[str, Any]
    petsc_options: dict[str, str]
    petsc_prefix: str
    versions: dict[str, str]
    ranks: int
    dofs: int
    cells: int
    h_contact: float
    steps: list[StepLog]
    timings: dict[str, float]
    quantities: Quantities
    reference: dict[str, float] = field(default_factory=dict)
    scores: dict[str, float] = field(default_factory=dict)
    errors: dict[str, float] = field(default_factory=dict)
    #: the ParaView files: the body (PVD series, one dataset per load step with every field)
    #: and the contact surface alone
    paraview: str | None = None
    paraview_surface: str | None = None
    plot: str | None = None
    #: peak resident memory of the run's processes during the run (MiB, summed over the
    #: ranks; on Linux, else each process's peak so far)
    memory_mib: float = 0.0
    #: what the run's numbers do not say on their own, one line each (e.g. a contact pair or
    #: obstacle that never closed over the run); run.json's ``warnings``, [] for a run without
    warnings: list[str] = field(default_factory=list)
    #: a run continued from a checkpoint: {"step": its step, "load": its load factor}; the
    #: steps before are the checkpoint's (their timings not in ``timings``)
    restarted: dict[str, Any] | None = None
    #: a dynamic run's energy balance (:meth:`contactfx.driver.inertia.EnergyLedger.summary`)
    energy: dict[str, Any] | None = None

    # -- named views of the final state ---------------------------------------------------
    @property
    def force(self) -> float:
        return self.quantities.force

    @property
    def contact_size(self) -> float:
        return self.quantities.contact_size

    @property
    def peak_pressure(self) -> float:
        return self.quantities.peak_pressure

    @property
    def max_penetration(self) -> float:
        return self.quantities.max_penetration

    @property
    def complementarity(self) -> float:
        return self.quantities.complementarity

    @property
    def friction(self) -> Friction | None:
        return self.quantities.friction

    @property
    def interface(self) -> InterfaceQuantities | None:
        return self.quantities.interface

    @property
    def newton_iterations(self) -> int:
        return sum(s.newton for s in self.steps)

    @property
    def ksp_iterations(self) -> int:
        return sum(s.ksp for s in self.steps)

    @property
    def outer_iterations(self) -> int:
        return sum(s.outer for s in self.steps)

    @property
    def cutbacks(self) -> int:
        return sum(s.cutbacks for s in self.steps)

    @property
    def halvings(self) -> int:
        return sum(s.halvings for s in self.steps)

    @classmethod
    def from_json(cls, d: dict[str, Any]) -> RunSummary:
        """The summary of a run.json written by :meth:`to_json` (a child process's run; the
        steps keep their iterations, their quantities are the final state's)."""
        q = Quantities.from_json(d)
        steps = [
            StepLog(*(s.get(f.name, 0) for f in _STEP_COUNTS), q, s.get("energy"))
            for s in d["steps"]
        ]
        names = [
            f.name
            for f in dataclasses.fields(cls)
            if f.name not in ("steps", "quantities") and f.name in d
        ]
        return cls(steps=steps, quantities=q, **{k: d[k] for k in names})

    def to_json(self) -> dict[str, Any]:
        out: dict[str, Any] = {"status": "completed"}
        for name in (
            "scene",
            "parameters",
            "numerics",
            "petsc_options",
            "petsc_prefix",
            "versions",
            "ranks",
            "dofs",
            "cells",
            "h_contact",
        ):
            out[name] = getattr(self, name)
        out.update(
            newton_iterations=self.newton_iterations,
            ksp_iterations=self.ksp_iterations,
            outer_iterations=self.outer_iterations,
            steps=[s.to_json() for s in self.steps],
            timings=dict(self.timings),
        )
        out.update(self.quantities.to_json())
        out.update(
            paraview=self.paraview,
            paraview_surface=self.paraview_surface,
            reference=self.reference,
            scores=self.scores,
            errors=self.errors,
            warnings=list(self.warnings),
        )
        if self.interface is not None or self.plot is not None:
            out["plot"] = self.plot
        if self.restarted is not None:
            out["restarted"] = dict(self.restarted)
        if self.energy is not None:
            out["energy"] = dict(self.energy)
        return out


def never_closed(steps: list[StepLog], what: str, gap: float | None = None) -> list[str]:
    """The warning of a contact (``what``: "pair", "obstacle") that closed at no step of the
    run (a zero contact force at every converged step), with the smallest gap of the last
    step where known; [] otherwise, and for interfaces (a crack may open by design)."""
    if not steps or any(s.quantities.interface is not None for s in steps):
        return []
    if any(s.quantities.force > 0.0 for s in steps):
        return []
    line = (
        f"the contact {what} never closed: no closed point at any of the {len(steps)} "
        "load steps (contact force 0)"
    )
    if gap is not None and math.isfinite(gap):
        line += f"; smallest gap {gap:.3g} at the last step"
    return [line + ": check the geometry and the load"]


#: the pieces of a closed set (connected over the slave facets) from which its nodal pressure
#: is said to oscillate (:func:`zone_messages`): a contact of one or two zones, each with a
#: node left open at a pressure ripple, stays below; every other node open is far above
PIECES = 5


def closed_pieces(nodes: np.ndarray, closed: np.ndarray) -> int:
    """The connected pieces of the closed nodes over the facets ``nodes`` (m, d)."""
    ids = np.unique(nodes[closed])
    if len(ids) == 0:
        return 0
    label = np.arange(len(ids))
    # the facets' edges between two closed nodes
    d = nodes.shape[1]
    a, b = [], []
    for i in range(d):
        for j in range(i + 1, d):
            both = closed[:, i] & closed[:, j]
            a.append(nodes[both, i])
            b.append(nodes[both, j])
    ea = np.searchsorted(ids, np.concatenate(a))
    eb = np.searchsorted(ids, np.concatenate(b))
    while True:  # label propagation to the smallest label of each piece
        low = np.minimum(label[ea], label[eb])
        new = label.copy()
        np.minimum.at(new, ea, low)
        np.minimum.at(new, eb, low)
        new = new[new]  # jump to the label's label
        if np.array_equal(new, label):
            return len(np.unique(label))
        label = new


def zone_messages(
    nodes: np.ndarray, closed: np.ndarray, rim: np.ndarray, size: np.ndarray
) -> list[str]:
    """The warnings on a contact zone of the whole slave surface (the arguments of
    :func:`contactfx.driver.two_body.zone_warnings`, all ranks' facets)."""
    out = []
    if np.any(closed & rim):
        out.append(
            "the contact zone reaches the end of the slave surface (its rim): where the "
            "body's surface goes on beyond it, the contact may too (extend the slave group)"
        )
    touched = np.any(closed, axis=1)
    edge = touched & ~np.all(closed, axis=1)
    if np.any(edge) and np.any(touched):
        ratio = float(np.max(size[edge]) / np.min(size[touched]))
        if ratio > 2.0:
            out.append(
                f"the contact zone's edge lies on facets {ratio:.2g} times the finest it "
                "covers: the contact has grown out of the refined region (refine further out)"
            )
    pieces = closed_pieces(nodes, closed)
    if pieces >= PIECES:
        out.append(
            f"the closed set breaks into {pieces} pieces along the slave surface: the nodal "
            "pressure oscillates between closed and open nodes (mortar on a curved "
            'interface: smoothing = "normals" on the pair; Gauss-point methods: a finer mesh)'
        )
    return out


#: error measures against the closed forms: column -> (label, section, key). Bench tabulates
#: all of them; stress reports the first one a run has in the order of PRIMARY.
MEASURES: dict[str, tuple[str, str, str]] = {
    "err_force": ("force", "reference", "force_rel_error"),
    "err_a": ("half-width a", "reference", "a_rel_error"),
    "err_p0": ("peak pressure p0", "reference", "p0_rel_error"),
    "err_p_L2": ("pressure, L2 on contact", "errors", "pressure_L2_rel"),
    "err_p_in": ("crack pressure, L2 on |s| <= 0.8 a", "errors", "pressure_interior_L2_rel"),
    "err_u_L2": ("displacement, L2", "errors", "displacement_L2_rel"),
    "err_u_H1": ("displacement, H1 semi-norm", "errors", "displacement_H1_rel"),
    "err_punch": ("punch pressure on |x| <= 0.8 a", "scores", "normalised_pressure_error"),
    "err_Q": ("gross-slip force Q = mu P", "reference", "Q_rel_error"),
    "err_c": ("stick half-width c (Cattaneo-Mindlin)", "reference", "c_rel_error"),
    "err_opening": ("crack opening, L2 on the crack", "errors", "opening_L2_rel"),
    "err_slip": ("crack slip, L2 on the crack", "errors", "slip_L2_rel"),
    "err_K": ("stress intensity factor", "reference", "K_rel_error"),
    "err_settlement": ("joint column settlement", "reference", "settlement_rel_error"),
}

#: stress's primary error, most specific first, with the short name it prints
PRIMARY = (
    ("K", "err_K"),
    ("settlement", "err_settlement"),
    ("opening L2", "err_opening"),
    ("stick c", "err_c"),
    ("p L2", "err_p_L2"),
    ("punch p", "err_punch"),
    ("Q = mu P", "err_Q"),
    ("force", "err_force"),
)


def measure(summary: RunSummary, column: str) -> float:
    """The error measure ``column`` of :data:`MEASURES` (nan when the run has none)."""
    _, section, key = MEASURES[column]
    value = getattr(summary, section).get(key)
    return math.nan if value is None else float(value)
