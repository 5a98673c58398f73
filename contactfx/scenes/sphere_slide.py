"""``sphere-slide``: a neo-Hookean sphere pressed deep into a neo-Hookean block, then slid along
it with Coulomb friction (3D, finite strain, half model).

The upper body is the cap z <= ``height`` (a hemisphere by default) of the sphere of radius R
centred at (0, 0, R), its flat top driven: moved down by ``press`` (0.3 R by default) during
the first ``press_fraction`` of the load program, then along +x by ``slide`` at that depth
(the whole top held as a rigid face: u_y = 0 there too). The lower body is the block
[-left, right] x [0, width] x [-depth, 0], its bottom clamped. Half model: the plane y = 0 is
a symmetry plane of both bodies (u_y = 0). Both bodies neo-Hookean, the sphere 10 times stiffer
than the block by default; penalty method (the contact searched in the deformed configuration
at every Newton iteration), Coulomb friction mu = 0.3 by default
(:mod:`contactfx.contact.point_coupling`). The block's top is the slave surface by default: with
the sphere's as the slave the default run needs 49 load steps (20 asked: Newton's first
iterations of one sliding step in three raise the residual until an element inverts, a NaN
residual, and the step is cut back) and 277 Newton iterations, against 20 and 94 with the
block's (docs/verification.md section 15).

No closed form: the scores are checks of the discrete solution.

- ``P`` and ``Q``: the pair's force on the sphere (full model, ``pair_forces.csv``) at the last
  step: P its z component (the block pushes the sphere up), Q minus its x component (the force
  that drags the sphere along +x); ``Q_over_P`` and, with Coulomb friction, ``Q_over_P_over_mu``
  (not 1 at gross slip: the friction traction lies in the curved, deformed contact surface, the
  pressure acts along its normal); ``curvature_factor`` = sum P sqrt(1 - n_x^2) / sum P |n_z|
  over the slave points, what Q / (mu P) would be at gross slip under a pressure symmetric in
  x; ``tangential_over_bound`` (the kind's) the contact-frame ratio of |t_T| to mu P, 1 at
  gross slip.
- Equilibrium (at every converged step, the largest over the steps): the reactions of the
  supports, from the residual R(u) + F_c(u) summed over the supported rows of a group
  (:func:`contactfx.scenes._common.reaction_forces`), against the pair's force. The driven top
  carries the pair's force on the sphere (the sphere's internal forces sum to zero):
  ``equilibrium_top`` = |F_top + F_pair| / |F_pair| over the x and z components (the y
  components are 0: the full model's forces, whose mirror images cancel along y); the clamped
  bottom carries the pair's force on the block, minus that on the sphere:
  ``equilibrium_bottom`` = |F_bottom - F_pair| / |F_pair|. Both vanish at an exact solution
  of the discrete equations; they are Newton's residual on the free rows (the solver's
  tolerance).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from contactfx.meshes import SphereOnBlockCells, SphereOnBlockFacets, sphere_on_block
from contactfx.params import param
from contactfx.scenes import export
from contactfx.scenes._common import fix, fix_component, prescribe_component, reaction_forces
from contactfx.scenes.two_body_2d import PressThenDrag, press_drag, press_then_drag
from contactfx.scenes.two_body_base import two_elastic

__all__ = ["SphereSlide"]


@dataclass(frozen=True)
class _SphereParams(two_elastic(1000.0, 0.3)):
    # E_lower / nu_lower: the block; E_upper / nu_upper: the sphere
    E_upper: float = param(1e4, "Young's modulus of the upper body (the sphere)", positive=True)
    slave: str = param(
        "lower",
        "the slave surface of the contact pair (the block: with the sphere as the slave, "
        "Newton diverges in one step of three and the load steps are cut back)",
        choices=("upper", "lower"),
    )
    radius: float = param(1.0, "radius R of the sphere", positive=True)
    height: float = param(
        1.0, "height of the sphere cap's flat top above its lowest point, <= R", positive=True
    )


@dataclass(frozen=True)
class SphereSlideParams(
    press_drag(
        _SphereParams,
        press=(0.3, "downward displacement of the sphere's top"),
        slide=(1.0, "displacement of the sphere's top along +x after pressing"),
        press_fraction=0.3,
        slide_may_be_zero=True,
    )
):
    left: float = param(2.5, "extent of the block behind the sphere's lowest point", positive=True)
    right: float = param(
        4.0, "extent of the block ahead of the sphere's lowest point (along +x)", positive=True
    )
    width: float = param(2.5, "extent of the block along y (half model)", positive=True)
    depth: float = param(2.5, "depth of the block", positive=True)
    h_contact: float = param(0.15, "element size of the block along the track", positive=True)
    h_far: float = param(0.6, "element size far from the contact", positive=True)
    refine: float = param(
        0.7,
        "distance from the track (and the sphere's pole) meshed with the contact sizes",
        positive=True,
    )
    ratio: float = param(1.0, "element size of the sphere / that of the block", positive=True)
    grading: float = param(
        0.3, "element size growth per unit distance from the refined zones", positive=True
    )


class SphereSlide(PressThenDrag):
    name = "sphere-slide"
    summary = (
        "neo-Hookean sphere pressed 0.3 R into a neo-Hookean block and slid along it with "
        "Coulomb friction (3D, half model); P, Q / P, equilibrium of reactions and contact force"
    )
    Params = SphereSlideParams
    cells = {"lower": SphereOnBlockCells.BLOCK, "upper": SphereOnBlockCells.SPHERE}
    surfaces = {
        "lower": SphereOnBlockFacets.BLOCK_TOP,
        "upper": SphereOnBlockFacets.SPHERE_CONTACT,
    }
    symmetry = 2.0
    symmetry_planes = (1,)  # y = 0
    # the radius of a disc of the closed nodes' area
    size_rule = "disc-radius"
    numerics_defaults = {
        "method": "penalty",
        "material": "neo-hookean",
        "friction": "coulomb",
        "mu": 0.3,
        "steps": 20,
    }

    #: the block's clamped bottom and the sphere's driven top: (facet tag, group)
    clamped = (SphereOnBlockFacets.BLOCK_BOTTOM, "block_bottom")
    driven = (SphereOnBlockFacets.SPHERE_TOP, "sphere_top")

    builder = staticmethod(sphere_on_block)
    body_params = ("radius", "height")
    block_params = (
        "left",
        "right",
        "width",
        "depth",
        "h_contact",
        "h_far",
        "refine",
        "ratio",
        "grading",
    )
    dim = 3

    def make_constants(self, mesh) -> None:
        super().make_constants(mesh)
        #: per converged step: the load factor, the pair's force on the sphere and the
        #: reactions of the driven top and the clamped bottom (full model)
        self.records: list[dict] = []

    def dirichlet(self, V, facet_tags) -> list:
        f = SphereOnBlockFacets
        top = self.driven[0]
        return [
            *fix(V, facet_tags, self.clamped[0]),
            fix_component(V, facet_tags, f.BLOCK_Y0, 1),
            fix_component(V, facet_tags, f.SPHERE_Y0, 1),
            prescribe_component(V, facet_tags, top, 0, self.drag),
            fix_component(V, facet_tags, top, 1),
            prescribe_component(V, facet_tags, top, 2, self.push),
        ]

    def boundary_data(self) -> list[dict]:
        p = self.p
        return [
            export.fixed(self.clamped[1], (0, 1, 2)),
            export.fixed("block_y0", (1,)),
            export.fixed("sphere_y0", (1,)),
            export.fixed(self.driven[1], (1,)),
            *press_then_drag(self.driven[1], p.slide, -p.press, p.press_fraction, axis="z"),
        ]

    def on_step(self, problem, solver, load, quantities) -> None:
        """The reactions of the top and the bottom and the pair's force on the sphere (full
        model), at the converged state (the residual evaluated again at u, with the step's
        friction history)."""
        r = solver.reactions()
        tags = {"top": self.driven[0], "bottom": self.clamped[0]}
        full = self.force_symmetry(3)  # the full model's: F_y cancels
        reactions = reaction_forces(problem.V, problem.facet_tags, tags, r, full)
        r.destroy()
        sign = 1.0 if self.slave_is_upper else -1.0
        pair = sign * full * problem.coupling().slave_force()
        rec = {"load": load, "pair": pair, "curvature": self.curvature(problem), **reactions}
        if problem.friction is not None:
            comm = problem.mesh.comm
            sums = problem.coupling().friction_state()
            total = {k: comm.allreduce(v) for k, v in sums.items()}
            # the contact-frame ratio of |t_T| to the bound mu P: 1 at gross slip
            rec["tangential_over_bound"] = (
                total["tangential"] / total["bound"] if total["bound"] > 0.0 else 0.0
            )
        self.records.append(rec)

    @staticmethod
    def curvature(problem) -> float:
        """sum w P sqrt(1 - n_x^2) / sum w P |n_z| over the slave points (n the contact
        normal): Q / (mu P) at gross slip for a pressure symmetric about the contact's centre
        in x (the friction traction mu P along the projection of -x on the contact's tangent
        plane, whose x part is sqrt(1 - n_x^2), against the normal force's z part |n_z|); above
        1 on a curved contact. Collective."""
        coupling = problem.coupling()
        w, n, P = coupling.points[0]["w"], coupling.points[0]["n"], coupling.state[0][0]
        num = float(np.sum(w * P * np.sqrt(np.clip(1.0 - n[:, 0] ** 2, 0.0, None))))
        den = float(np.sum(w * P * np.abs(n[:, 2])))
        num, den = (problem.mesh.comm.allreduce(v) for v in (num, den))
        return num / den if den > 0.0 else 1.0

    def equilibrium(self) -> dict[str, float]:
        """The largest relative imbalances over the converged steps (x and z components):
        |F_top + F_pair| / |F_pair| and |F_bottom - F_pair| / |F_pair|."""
        xz = [0, 2]
        top, bottom = 0.0, 0.0
        for rec in self.records:
            pair = rec["pair"][xz]
            scale = np.linalg.norm(pair)
            if scale == 0.0:
                continue
            top = max(top, float(np.linalg.norm(rec["top"][xz] + pair) / scale))
            bottom = max(bottom, float(np.linalg.norm(rec["bottom"][xz] - pair) / scale))
        return {"equilibrium_top": top, "equilibrium_bottom": bottom}

    def force_scores(self, loads, forces):
        """P, Q and Q / P at the last step (with Coulomb friction Q / (mu P)), the largest
        |Q / P| over the slide's steps and the equilibrium of the reactions and the pair's
        force over the steps."""
        P, Q = self.forces_PQ(forces)
        scores = self.last_step(P, Q)
        sliding = self.drag_steps(loads)
        if len(sliding):
            ratio = Q[sliding] / P[sliding]
            scores["min_Q_over_P_sliding"] = float(np.min(ratio))
            scores["max_Q_over_P_sliding"] = float(np.max(ratio))
        if self.coulomb:
            scores["Q_over_P_over_mu"] = float(Q[-1] / P[-1] / self.mu)
            if self.records:
                scores["curvature_factor"] = self.records[-1]["curvature"]
        scores.update(self.equilibrium())
        return scores
