"""``shallow-ironing``: a stiff die with a rounded bottom pressed into a soft block and dragged
along it, finite strain (neo-Hookean), frictionless or with Coulomb friction, on the 2D section
(plane-stress-equivalent constants by default, or plane strain).

The two-dimensional ironing benchmark of Yang, Laursen and Meng (B. Yang, T. A. Laursen,
X. Meng, Two dimensional mortar contact methods for large deformation frictional sliding,
Int. J. Numer. Meth. Engng 62 (2005) 1183-1225, doi:10.1002/nme.1222), computed again by
Poulios and Renard (K. Poulios, Y. Renard, An unconstrained integral approximation of large
sliding frictional contact between deformable solids, Computers and Structures 153 (2015)
75-90, doi:10.1016/j.compstruc.2015.02.027). Its set-up and published force curves are those of
the KratosMultiphysics/Examples repository, ``contact_structural_mechanics/validation/
shallow_ironing_3D`` (a 3D model, the 2D section extruded by 1; the numbers below are read
from its ``source/shallow_ironing3D.mdpa``, ``source/StructuralMaterials.json``,
``source/ProjectParameters_literature.json``, ``source/ProjectParameters_frictional.json`` and
the plots ``data/solution_frictionless.png`` and ``data/solution_frictional.png``, whose
Kratos markers lie on the reference curves of Poulios and Renard):

- block 12 x 4 (mdpa: x in [0, 12], y in [0, 4]), its bottom clamped (mdpa group
  ``DISPLACEMENT_Displacement_Auto1``: the 726 nodes at y = 0, all three components); here
  [-0.8, 11.2] x [-4, 0], the die's lowest point at the origin;
- die 1.2 wide and 1.2 high (mdpa: x in [0.2, 1.4], y in [4, 5.2]), its bottom the arc of
  radius 0.75 centred 0.75 above its lowest point (through (0.2, 4.3), (0.8, 4), (1.4, 4.3));
  its top (``DISPLACEMENT_Displacement_Auto2``, the 90 nodes at y = 5.2) moved as a rigid face;
- the thickness: z in [0, 1] (the block 5 hexahedra through it), the displacement along z
  held on the face z = 0 only (``DISPLACEMENT_Displacement_Auto3``: 2646 nodes, all at z = 0,
  block and die) and on the die's top; the face z = 1 is free. The 3D model is half of a slab
  of thickness 2 with free faces, between plane strain and plane stress; its forces are totals
  over the thickness 1, i.e. per unit thickness;
- neo-Hookean ``HyperElastic3DLaw`` (S = lambda ln J C^-1 + mu (I - C^-1), the law of
  :mod:`contactfx.mechanics.hyperelastic`), E = 68.96e8 (die) and 68.96e7 (block), nu = 0.32
  for both (StructuralMaterials.json);
- load program (ProjectParameters_literature.json, start_time 0.2): the die's top moves down
  by t - 0.2 for t in [0.2, 1], i.e. 0.8 from touching (the die's lowest mdpa node is at
  y = 4.00007; the published set-up starts 0.2 above the block and moves 1), then along +x by
  10 (t - 1) at that depth for t in [1, 2];
- contact: the group ``CONTACT_Contact_Auto1`` holds the arc and the block's top only (y <= 4.3;
  not the die's vertical sides), ALM mortar (``ALMContactFrictionlessComponents``, stiffness
  factor 10), ``assume_master_slave`` naming the die's part ``Parts_Parts_Auto1``;
- Coulomb friction mu = 0.3 (ProjectParameters_frictional.json, ``friction_coefficients``;
  that file's load program is the README's custom one, pressed 1 from touching and dragged 11,
  stiffness factor 0.1: the frictional plot, on t in [0, 2] with the force rising from
  t = 0.2 and 2.72e8 at t = 1 as frictionless, is the literature program with mu = 0.3);
- published force on the die while it slides (per unit thickness, read off the plots, about
  3 %; the markers digitised over t in [1.3, 1.7]: 3.385e8 frictionless, 3.381e8 and 1.021e8
  with friction): vertical plateau 3.40e8 (frictionless; the frictional plot shows the same
  level) and horizontal plateau 1.02e8 with mu = 0.3 (frictionless: about 0); at the end of
  the pressing (t = 1) the vertical force is 2.71e8 (digitised, both plots).

The section (``section``): ``plane-stress`` (default) solves the plane-strain equations with
each body's plane-stress-equivalent constants E' = E (1 + 2 nu) / (1 + nu)^2,
nu' = nu / (1 + nu) (exact in linear elasticity; at the compressions of the block, 10-40 %,
true plane stress of this neo-Hookean law is stiffer by 1-5 %); ``plane-strain`` keeps E and
nu. The published 3D slab is near plane stress: from t = 0.6 to 1 its pressing curve is the
plane-stress one to 1.1 % and 12-14 % below the plane-strain one (docs/verification.md,
"Shallow ironing").

Forces: the pair's force on the die (``pair_forces.csv``): P = its y component (the block
pushes the die up), Q = minus its x component (the drag force needed to move the die along +x;
positive with friction). Scores over the plateau (the steps whose slide is within
[plateau_from, plateau_to] of ``slide``: the die far from both ends of the block, where the
published curves are flat): ``P_plateau`` and ``Q_plateau`` (means), their relative errors
against the published plateaus (``P_plateau_error``; ``Q_plateau_error`` with Coulomb mu = 0.3
only), ``Q_over_P`` = Q_plateau / P_plateau (and ``Q_over_P_over_mu`` with friction) and
its two parts, ``Q_pressure_over_P`` (the contact pressure's x component: the ploughing, the
pressure leaning on the die's front) and ``Q_friction_over_P`` (the friction traction's),
``P_jump`` and ``Q_jump``: the largest change of P or Q between consecutive plateau steps over
P_plateau; ``P_pressed``: P at the end of the pressing (interpolated at the load factor
press_fraction), and with the published press depth 0.8 its error against 2.71e8
(``P_pressed_error``). With ``--out`` the scene writes ``history.png``: P and Q against the
slide, with the published plateaus.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
from mpi4py import MPI

from contactfx.mechanics.elasticity import Elastic
from contactfx.meshes import (
    DieOnBlockCells,
    DieOnBlockFacets,
    DieOnSlabCells,
    DieOnSlabFacets,
    die_on_block,
    die_on_slab,
)
from contactfx.params import param
from contactfx.scenes import export
from contactfx.scenes._common import fix, fix_component, prescribe_component
from contactfx.scenes.two_body_2d import PressThenDrag, press_drag, press_then_drag
from contactfx.scenes.two_body_base import two_elastic

__all__ = [
    "ShallowIroning",
    "ShallowIroning3D",
    "PUBLISHED_P",
    "PUBLISHED_Q",
    "PUBLISHED_MU",
    "PUBLISHED_P_PRESSED",
    "plane_stress_equivalent",
]

#: the published vertical force plateau while sliding, per unit thickness (read off the plots
#: of KratosMultiphysics/Examples shallow_ironing_3D, about 3 %)
PUBLISHED_P = 3.40e8
#: the published horizontal force plateau with Coulomb friction mu = PUBLISHED_MU
PUBLISHED_Q = 1.02e8
PUBLISHED_MU = 0.3
#: the published vertical force at the end of the pressing (t = 1, press 0.8), digitised from
#: the Kratos markers of both plots (2.714e8 and 2.719e8)
PUBLISHED_P_PRESSED = 2.71e8
#: the published press depth (from touching)
PUBLISHED_PRESS = 0.8


def plane_stress_equivalent(material: Elastic) -> Elastic:
    """The constants whose plane-strain equations are plane stress with E and nu (linear
    elasticity): E' = E (1 + 2 nu) / (1 + nu)^2, nu' = nu / (1 + nu)."""
    E, nu = material.E, material.nu
    return replace(material, E=E * (1.0 + 2.0 * nu) / (1.0 + nu) ** 2, nu=nu / (1.0 + nu))


@dataclass(frozen=True)
class _DieParams(two_elastic(68.96e7, 0.32)):
    # E_lower / nu_lower: the block; E_upper / nu_upper: the die
    E_upper: float = param(68.96e8, "Young's modulus of the upper body (the die)", positive=True)
    slave: str = param(
        "lower",
        "the slave surface of the contact pair (the block: with the die's arc as the slave, "
        "Newton fails as the die starts to slide)",
        choices=("upper", "lower"),
    )
    radius: float = param(0.75, "radius of the die's rounded bottom", positive=True)
    half_width: float = param(0.6, "half-width of the die", positive=True)
    height: float = param(1.2, "height of the die (its top above its lowest point)", positive=True)


@dataclass(frozen=True)
class _SectionParams(_DieParams):
    section: str = param(
        "plane-stress",
        "the 2D section: plane-stress (each body's plane-stress-equivalent E and nu in the "
        "plane-strain equations; the published 3D slab's free face) or plane-strain",
        choices=("plane-stress", "plane-strain"),
    )


def _ironing_params(base: type, h: tuple[float, float]) -> type:
    """The parameters of an ironing scene on ``base`` (the bodies' and the die's shape): the
    load program (:func:`press_drag`), the block, the mesh sizes (``h``: the defaults of
    h_contact and h_far) and the plateau window (checked: plateau_from < plateau_to <= 1)."""

    @dataclass(frozen=True)
    class IroningParams(
        press_drag(
            base,
            press=(0.8, "downward displacement of the die's top"),
            slide=(10.0, "displacement of the die's top along +x after pressing"),
            press_fraction=0.1,
        )
    ):
        left: float = param(
            0.8, "extent of the block left of the die's lowest point", positive=True
        )
        right: float = param(
            11.2, "extent of the block right of the die's lowest point", positive=True
        )
        depth: float = param(4.0, "depth of the block", positive=True)
        h_contact: float = param(h[0], "element size of the block along the track", positive=True)
        h_far: float = param(h[1], "element size far from the contact", positive=True)
        refine: float = param(
            0.3, "distance from the track meshed with the contact sizes", positive=True
        )
        ratio: float = param(0.6, "element size of the die / that of the block", positive=True)
        plateau_from: float = param(
            0.3, "start of the plateau, a fraction of the slide", nonnegative=True
        )
        plateau_to: float = param(0.7, "end of the plateau, a fraction of the slide", positive=True)

        def __post_init__(self) -> None:
            super().__post_init__()
            if not self.plateau_from < self.plateau_to <= 1.0:
                raise ValueError(
                    "need plateau_from < plateau_to <= 1, got "
                    f"{self.plateau_from} and {self.plateau_to}"
                )

    return IroningParams


@dataclass(frozen=True)
class ShallowIroningParams(_ironing_params(_SectionParams, h=(0.1, 0.2))):
    offset: float = param(
        0.3,
        "shift of the die's contact nodes (fraction of an element, in [0, 1))",
        nonnegative=True,
    )


@dataclass(frozen=True)
class ShallowIroning3DParams(_ironing_params(_DieParams, h=(0.2, 0.4))):
    slave: str = param(
        "upper",
        "the slave surface of the contact pair (the die: with the block's top as the slave, "
        "its points bulge out past the die's free face z = thickness, each drops out of "
        "contact there at once and Newton 2-cycles at the end of the pressing)",
        choices=("upper", "lower"),
    )
    thickness: float = param(
        1.0,
        "extent of both bodies along z (u_z = 0 on z = 0, the face z = thickness free: half of "
        "a free slab twice as thick)",
        positive=True,
    )
    grading: float = param(
        0.3, "element size growth per unit distance from the refined zones", positive=True
    )


class ShallowIroning(PressThenDrag):
    name = "shallow-ironing"
    summary = (
        "neo-Hookean die with a rounded bottom pressed into a block and dragged 10 along it "
        "(Yang et al. 2005); force plateaus against the published curves"
    )
    Params = ShallowIroningParams
    # P: the y component in 2D and on the 3D slab (its thickness along z)
    vertical = 1
    cells = {"lower": DieOnBlockCells.BLOCK, "upper": DieOnBlockCells.DIE}
    surfaces = {"lower": DieOnBlockFacets.BLOCK_TOP, "upper": DieOnBlockFacets.DIE_CONTACT}
    # 120 steps: the die moves 0.93 of a block element a step while sliding (Kratos's
    # reference run moves it 0.1 of its element, 500 steps), 7.7 Newton iterations a step;
    # 40 steps (2.8 elements a step): 9.8 a step, the same plateau to 1e-4. Each step starts
    # from the last converged state, and Newton's steps are shortened to the energy's minimum
    # along them (with the secant predictor and full steps 40 asked took about 230 load
    # steps; docs/verification.md section 15)
    numerics_defaults = {
        "method": "penalty",
        "material": "neo-hookean",
        "steps": 120,
        "predictor": "previous",
        "line_search": "auto",
    }

    def materials(self) -> dict[str, Elastic]:
        """The bodies' constants, plane-stress-equivalent with ``section`` plane-stress."""
        mats = super().materials()
        if self.p.section == "plane-strain":
            return mats
        return {body: plane_stress_equivalent(m) for body, m in mats.items()}

    builder = staticmethod(die_on_block)
    body_params = ("radius", "half_width", "height")

    #: the block's clamped bottom and the die's driven top: (facet tag, group)
    clamped = (DieOnBlockFacets.BLOCK_BOTTOM, "block_bottom")
    driven = (DieOnBlockFacets.DIE_TOP, "die_top")

    def configure(self, numerics) -> None:
        super().configure(numerics)
        #: per converged load factor: the pair's force on the die split into the part of the
        #: contact pressure (along the contact normals) and that of the friction traction
        self.force_split: dict[float, tuple[np.ndarray, np.ndarray]] = {}

    def on_step(self, problem, solver, load, quantities) -> None:
        """Record the force on the die's parts (:attr:`force_split`). Collective."""
        sign = 1.0 if self.slave_is_upper else -1.0
        normal, tangential = problem.coupling().force_parts()
        self.force_split[float(load)] = (sign * normal, sign * tangential)

    def published_Q(self) -> float | None:
        """The published horizontal plateau: with Coulomb mu = 0.3 only."""
        coulomb = self.friction == "coulomb" and abs(self.mu - PUBLISHED_MU) < 1e-12
        return PUBLISHED_Q if coulomb else None

    def reference(self, force: float) -> dict[str, float]:
        ref = {"P_plateau_published": PUBLISHED_P}
        if abs(self.p.press - PUBLISHED_PRESS) < 1e-12:
            ref["P_pressed_published"] = PUBLISHED_P_PRESSED
        Q = self.published_Q()
        if Q is not None:
            ref["Q_plateau_published"] = Q
        return ref

    def plateau(self, loads: np.ndarray) -> np.ndarray:
        """The indices of the steps on the plateau (slide within [plateau_from, plateau_to] of
        ``slide``)."""
        drag = self.drag_steps(loads)
        slide = np.array([self.top_displacement(t)[0] for t in loads[drag]]) / self.p.slide
        on = (slide >= self.p.plateau_from - 1e-9) & (slide <= self.p.plateau_to + 1e-9)
        return drag[on]

    def force_scores(self, loads, forces):
        """P at the end of the pressing and its error against the published value, the plateau
        means of P and Q, their errors against the published plateaus, Q / P, and the largest
        step-to-step jumps of P and Q on the plateau (over P_plateau)."""
        P, Q = self.forces_PQ(forces)
        scores = {"P": float(P[-1]), "Q": float(Q[-1])}
        f = self.p.press_fraction
        if loads[0] <= f <= loads[-1]:
            scores["P_pressed"] = float(np.interp(f, loads, P))
            if abs(self.p.press - PUBLISHED_PRESS) < 1e-12:
                scores["P_pressed_error"] = (
                    scores["P_pressed"] - PUBLISHED_P_PRESSED
                ) / PUBLISHED_P_PRESSED
        on = self.plateau(loads)
        if len(on) < 2:
            return scores
        Pm, Qm = float(np.mean(P[on])), float(np.mean(Q[on]))

        def per(value: float) -> float:  # no force on the plateau (lost): undefined
            return value / Pm if Pm != 0.0 else float("nan")

        scores.update(
            P_plateau=Pm,
            Q_plateau=Qm,
            P_plateau_error=(Pm - PUBLISHED_P) / PUBLISHED_P,
            Q_over_P=per(Qm),
            P_jump=per(float(np.max(np.abs(np.diff(P[on]))))),
            Q_jump=per(float(np.max(np.abs(np.diff(Q[on]))))),
            plateau_steps=float(len(on)),
        )
        split = [self.force_split.get(float(t)) for t in loads[on]]
        if split and all(part is not None for part in split):
            # Q = Q_pressure + Q_friction: the pressure's part is the ploughing (the pressure
            # leaning on the die's front), the friction's is mu P on a flat contact
            scores["Q_pressure_over_P"] = per(float(np.mean([-n[0] for n, _ in split])))
            scores["Q_friction_over_P"] = per(float(np.mean([-t[0] for _, t in split])))
        published = self.published_Q()
        if published is not None:
            scores["Q_plateau_error"] = (Qm - published) / published
        if self.coulomb:
            scores["Q_over_P_over_mu"] = per(Qm) / self.mu
        return scores

    def run(self, numerics, *, comm=MPI.COMM_WORLD, out=None, **kwargs):
        """The run, then ``history.png`` from ``pair_forces.csv`` when ``out`` is given."""
        res = super().run(numerics, comm=comm, out=out, **kwargs)
        if out is not None and comm.rank == 0:
            forces = Path(out) / "pair_forces.csv"
            if forces.exists():
                plot_history(
                    self,
                    np.loadtxt(forces, delimiter=",", skiprows=1, ndmin=2),
                    Path(out) / "history.png",
                )
        return res


class ShallowIroning3D(ShallowIroning):
    """The published 3D slab: the section of :class:`ShallowIroning` extruded through z in
    [0, ``thickness``], u_z = 0 on the face z = 0 of both bodies and on the die's top, the
    face z = thickness free (Kratos's ``shallow_ironing3D.mdpa``: half of a free slab of
    thickness 2); the same load program, published forces and scores, the forces the totals
    over the thickness (per unit thickness for thickness 1, as published)."""

    name = "shallow-ironing-3d"
    summary = (
        "the shallow ironing on the published 3D slab (its face z = 1 free): force plateaus "
        "against the published curves without a 2D section's assumption"
    )
    Params = ShallowIroning3DParams
    cells = {"lower": DieOnSlabCells.BLOCK, "upper": DieOnSlabCells.DIE}
    surfaces = {"lower": DieOnSlabFacets.BLOCK_TOP, "upper": DieOnSlabFacets.DIE_CONTACT}
    # 60 steps: the die moves 1.9 block elements (h_contact 0.2) a step while sliding
    numerics_defaults = {**ShallowIroning.numerics_defaults, "steps": 60}
    builder = staticmethod(die_on_slab)
    block_params = (
        "left",
        "right",
        "depth",
        "thickness",
        "h_contact",
        "h_far",
        "refine",
        "ratio",
        "grading",
    )
    dim = 3
    clamped = (DieOnSlabFacets.BLOCK_BOTTOM, "block_bottom")
    driven = (DieOnSlabFacets.DIE_TOP, "die_top")

    def materials(self) -> dict[str, Elastic]:
        """The bodies' constants as given: no section in 3D."""
        return PressThenDrag.materials(self)

    def dirichlet(self, V, facet_tags) -> list:
        f = DieOnSlabFacets
        top = self.driven[0]
        return [
            *fix(V, facet_tags, self.clamped[0]),
            fix_component(V, facet_tags, f.BLOCK_Z0, 2),
            fix_component(V, facet_tags, f.DIE_Z0, 2),
            prescribe_component(V, facet_tags, top, 0, self.drag),
            prescribe_component(V, facet_tags, top, 1, self.push),
            fix_component(V, facet_tags, top, 2),
        ]

    def boundary_data(self) -> list[dict]:
        p = self.p
        return [
            export.fixed(self.clamped[1], (0, 1, 2)),
            export.fixed("block_z0", (2,)),
            export.fixed("die_z0", (2,)),
            export.fixed(self.driven[1], (2,)),
            *press_then_drag(self.driven[1], p.slide, -p.press, p.press_fraction),
        ]


def plot_history(scene: ShallowIroning, rows: np.ndarray, path: Path) -> None:
    """P and Q (the force on the die) against the die's top displacement along x (the pressing
    at slide 0, drawn against its depth on a second axis would hide nothing more), with the
    published plateaus over the plateau window."""
    from contactfx.driver.interface_post import pyplot

    plt = pyplot()
    loads = rows[:, 0]
    P, Q = rows[:, 2], -rows[:, 1]
    # the x axis: the published load program's time (0.2 -> 1 pressing, 1 -> 2 sliding)
    f = scene.p.press_fraction
    time = np.where(loads <= f, 0.2 + 0.8 * loads / f, 1.0 + (loads - f) / (1.0 - f))
    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    ax.plot(time, P, "o-", ms=3, label="P (vertical)")
    ax.plot(time, Q, "s-", ms=3, label="Q (horizontal)")
    window = [1.0 + scene.p.plateau_from, 1.0 + scene.p.plateau_to]
    ax.plot(window, [PUBLISHED_P] * 2, "k--", label=f"published P plateau {PUBLISHED_P:.3g}")
    published = scene.published_Q()
    if published is not None:
        ax.plot(window, [published] * 2, "k:", label=f"published Q plateau {published:.3g}")
    ax.set_xlabel("time of the published load program (0.2-1 pressing, 1-2 sliding)")
    ax.set_ylabel("force on the die per unit thickness")
    friction = f"Coulomb mu = {scene.mu:g}" if scene.friction == "coulomb" else scene.friction
    ax.set_title(f"shallow ironing ({friction})")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
