"""A penny-shaped (circular) crack in a 3D block: the fitted interface in 3D (``penny-crack``,
pressurised; ``penny-shear``, closed and sliding under remote compression with friction).

Geometry: the crack is the disk r = sqrt(x^2 + y^2) <= a in the plane z = 0 (interface normal
n_I = e_z) at the centre of the cube [-W/2, W/2]^3; the planes x = 0 and y = 0 are planes of
symmetry, so the quarter block [0, W/2]^2 x [-W/2, W/2] is meshed
(:func:`contactfx.meshes.penny_block`) with u_x = 0 on x = 0 and u_y = 0 on y = 0, and one
vertex, the corner (W/2, W/2, -W/2), holds u_z = 0 (the loads are in equilibrium, so it carries
no force). The crack front is the quarter circle r = a, z = 0, where the jump vanishes.

``penny-crack``: the fluid pressure p on the faces of a crack in an unloaded block. Sneddon's
infinite-body solution (Sneddon 1946, doi:10.1098/rspa.1946.0077):

    opening w(r) = 8 (1 - nu^2) p a / (pi E) sqrt(1 - r^2 / a^2),    K_I = 2 p sqrt(a / pi).

The block's faces are traction free; the crack's field decays as (a / r)^3, so the block of
width W = 16 a stands for the infinite body within about 1e-3 (the finite block's opening is a
little larger: the crack feels the free faces). With p < 0 (suction) the faces close and carry
the uniform pressure -p over the whole crack.

Stress intensity along the front (``front.png`` / ``front.csv``): the crack's nodes are binned
by the front angle phi = atan2(y, x) (``--front-bins`` bins of the quarter), and each bin's K is
the displacement extrapolation of the 2D crack scenes
(:func:`contactfx.scenes.crack.extrapolated_K`) at the distance a - r from the front: the
near-front field is the plane-strain one.

``penny-shear``: the crack under the remote uniaxial compression sigma along the direction
(sin beta, 0, cos beta), at beta to the crack's normal: on the crack plane the normal stress
sigma_n = sigma cos^2 beta and the shear tau = -sigma sin beta cos beta along x, so y = 0 is the
one plane of symmetry and the half block y >= 0 is meshed (``half``), u_y = 0 on y = 0, three
conditions at two bottom corners removing the other rigid motions. The block's faces carry the
remote traction (the crack's perturbation decays as (a / r)^3). The crack stays closed under
sigma_n; with Coulomb friction (or Tresca) it slides where |tau| exceeds the bound, and then
under the uniform driving shear q = sign(tau) (|tau| - mu sigma_n) the slip is parallel to x
and elliptical, 16 (1 - nu^2) q / (pi (2 - nu) E) sqrt(a^2 - r^2) (Kassir & Sih 1966,
doi:10.1115/1.3625086), with K_II = 4 q sqrt(a / pi) cos(phi) / (2 - nu) and K_III =
4 (1 - nu) q sqrt(a / pi) sin(phi) / (2 - nu) along the front (Tada, Paris & Irwin 2000,
doi:10.1115/1.801535); the faces carry sigma_n and the shear mu sigma_n.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
import ufl

from contactfx import references as cf
from contactfx._compat import numpy_math, ufl_math
from contactfx.driver.interface_post import STATUS
from contactfx.meshes import PennyBlockFacets, penny_block
from contactfx.params import param
from contactfx.scenes.base import elastic
from contactfx.scenes.crack import SlidingCrack, extrapolated_K
from contactfx.scenes.interface_base import InterfaceScene

__all__ = ["PennyCrack", "PennyShear", "FaultBlock"]


@dataclass(frozen=True)
class _PennyParams(elastic(10e9, 0.25)):
    crack_radius: float = param(1.0, "crack radius a", positive=True)
    block_width: float = param(16.0, "block width W (the cube [-W/2, W/2]^3)", positive=True)
    h_front: float = param(0.05, "element size at the crack front (<= h-crack)", positive=True)
    h_crack: float = param(0.1, "element size on the crack", positive=True)
    h_far: float = param(2.0, "element size far from the crack", positive=True)
    grading: float = param(0.3, "element size increase per unit distance", positive=True)
    front_bins: int = param(6, "bins of the front angle for K along the front", positive=True)

    def __post_init__(self) -> None:
        super().__post_init__()
        if not self.crack_radius < 0.5 * self.block_width:
            raise ValueError(
                f"--crack-radius ({self.crack_radius}) must be < block-width / 2 "
                f"({0.5 * self.block_width})"
            )
        if not self.h_front <= self.h_crack <= self.h_far:
            raise ValueError(
                f"element sizes must satisfy --h-front ({self.h_front}) <= --h-crack "
                f"({self.h_crack}) <= --h-far ({self.h_far})"
            )


class _PennyBlock(InterfaceScene):
    """Shared geometry of the penny-crack scenes: the quarter (or ``half``) block."""

    interface_tag = PennyBlockFacets.CRACK
    #: P2: P1 tetrahedra on the default mesh give K 24 % and the opening 10 % low
    #: (docs/verification.md section 13)
    numerics_defaults: ClassVar[dict] = {"steps": 1, "degree": 2}
    half: ClassVar[bool] = False

    def mesh_builder(self):
        p = self.p
        return functools.partial(
            penny_block,
            half_width=0.5 * p.block_width,
            crack_radius=p.crack_radius,
            h_front=p.h_front,
            h_crack=p.h_crack,
            h_far=p.h_far,
            grading=p.grading,
            half=self.half,
        ), 3

    def dimension(self) -> int:
        return 3

    def length_scale(self) -> float:
        return self.p.block_width

    def h_contact(self) -> float:
        return self.p.h_crack

    def problem_data(self, numerics):
        raise ValueError(
            f"scene '{self.name}' cannot be written as a problem file: problem files carry 2D "
            "interfaces only"
        )

    def side(self, x):
        return x[2]

    def on_front(self, x, tol):
        r = np.sqrt(x[0] ** 2 + x[1] ** 2)
        return (np.abs(r - self.p.crack_radius) < tol) & (np.abs(x[2]) < tol)

    def coordinate(self, x):
        """The radius r = sqrt(x^2 + y^2)."""
        m = ufl_math if isinstance(x, ufl.core.expr.Expr) else numpy_math
        return m.sqrt(x[0] ** 2 + x[1] ** 2)

    def slip_axis(self):
        return np.array([1.0, 0.0, 0.0])

    def _front_K(self, prof, jump, E: float, nu: float) -> tuple[np.ndarray, np.ndarray]:
        """(bin centres, K per bin) of the front angle phi = atan2(y, x) over the model's part
        of the front, from the ``jump`` at the crack's vertices (:func:`extrapolated_K` with
        the modulus E / (1 - nu^2) of the mode)."""
        p = self.p
        a, n = p.crack_radius, p.front_bins
        # the model is y >= 0 (and x >= 0 for the quarter): the nodes on its symmetry planes
        # carry coordinates of +-1e-18 from the cell they are tabulated from, which depends on
        # the partition, and a sign would put them outside [0, 90] / [0, 180]
        x, y = prof.x[:, 0], np.abs(prof.x[:, 1])
        phi = np.degrees(np.arctan2(y, x if self.half else np.abs(x)))
        edges = np.linspace(0.0, 180.0 if self.half else 90.0, n + 1)
        K = np.array(
            [
                extrapolated_K(a - prof.s, jump, E, nu, a, near=(phi >= lo) & (phi <= hi))
                for lo, hi in zip(edges[:-1], edges[1:], strict=True)
            ]
        )
        return 0.5 * (edges[:-1] + edges[1:]), K


@dataclass(frozen=True)
class PennyCrackParams(_PennyParams):
    pressure: float = param(1e6, "fluid pressure p on the crack faces (< 0: suction closes it)")


class PennyCrack(_PennyBlock):
    name = "penny-crack"
    summary = "pressurised penny-shaped crack in 3D (Sneddon opening, K_I along the front)"
    Params = PennyCrackParams

    def supports(self):
        return [(PennyBlockFacets.XSYM, 0), (PennyBlockFacets.YSYM, 1)]

    def pinned(self):
        half = 0.5 * self.p.block_width
        return [(np.array([half, half, -half]), 2)]

    def fluid_pressure(self):
        return self.p.pressure

    # -- closed forms -----------------------------------------------------------------------
    def _opening(self, r):
        m = numpy_math if isinstance(r, np.ndarray) else ufl_math
        p = self.p
        return cf.penny_opening(r, p.crack_radius, max(p.pressure, 0.0), p.E, p.nu, m)

    def exact_opening(self, s):
        return self._opening(s)

    def exact_pressure_interface(self, s):
        if self.p.pressure >= 0.0:
            return None  # no contact: the normal force is checked instead
        return -self.p.pressure + 0.0 * s

    def reference_profile(self, s):
        return {"opening": self._opening(np.asarray(s))}

    def front_profile(self, prof):
        p = self.p
        angle, K = self._front_K(prof, prof.opening, p.E, p.nu)
        K_exact = cf.penny_stress_intensity(max(p.pressure, 0.0), p.crack_radius)
        return {"angle": angle, "K": K, "K_exact": np.full(len(K), K_exact)}

    def interface_reference(self, prof, q, friction):
        p, a = self.p.pressure, self.p.crack_radius
        out = {"K_I_exact": cf.penny_stress_intensity(max(p, 0.0), a)}
        area = 0.25 * np.pi * a**2  # of the quarter crack
        if p > 0.0:
            front = self.front_profile(prof)
            err = np.abs(front["K"] - front["K_exact"]) / front["K_exact"]
            out["K_I"] = float(np.mean(front["K"]))
            out["K_rel_error"] = abs(out["K_I"] - out["K_I_exact"]) / out["K_I_exact"]
            out["K_rel_error_max"] = float(np.max(err))
            # "no false contact": the contact force relative to the fluid force on a face
            out["false_contact"] = abs(q.force) / (p * area)
        else:
            out["contact_force_exact"] = -p * area
            out["force_rel_error"] = (
                abs(q.force - out["contact_force_exact"]) / out["contact_force_exact"]
            )
        return out


@dataclass(frozen=True)
class PennyShearParams(_PennyParams):
    sigma: float = param(10e6, "remote uniaxial compression", positive=True)
    beta: float = param(45.0, "angle of the compression to the crack's normal, degrees")


class PennyShear(SlidingCrack, _PennyBlock):
    name = "penny-shear"
    summary = "closed penny-shaped crack sliding under inclined compression, Coulomb (3D)"
    Params = PennyShearParams
    numerics_defaults: ClassVar[dict] = {"steps": 1, "degree": 2, "friction": "coulomb", "mu": 0.3}
    half = True

    def supports(self):
        return [(PennyBlockFacets.YSYM, 1)]

    def pinned(self):
        w = 0.5 * self.p.block_width
        return [
            (np.array([-w, 0.0, -w]), 0),
            (np.array([-w, 0.0, -w]), 2),
            (np.array([w, 0.0, -w]), 2),
        ]

    def remote_stress(self) -> np.ndarray:
        b = np.radians(self.p.beta)
        d = np.array([np.sin(b), 0.0, np.cos(b)])
        return -self.p.sigma * np.outer(d, d)

    def load(self, v, ds, t):
        n = ufl.FacetNormal(ds.ufl_domain())
        sigma = ufl.as_matrix(self.remote_stress().tolist())
        outer = (
            PennyBlockFacets.XMIN,
            PennyBlockFacets.XMAX,
            PennyBlockFacets.YMAX,
            PennyBlockFacets.BOTTOM,
            PennyBlockFacets.TOP,
        )
        return t * ufl.dot(ufl.dot(sigma, n), v) * ds(outer)

    # -- closed forms -----------------------------------------------------------------------
    def _plane(self) -> tuple[float, float]:
        """(sigma_n, tau): the compression across the crack and the shear along x on it."""
        S = self.remote_stress()
        return float(-S[2, 2]), float(S[0, 2])

    def _slip(self, r):
        m = numpy_math if isinstance(r, np.ndarray) else ufl_math
        p = self.p
        return cf.penny_shear_slip(r, p.crack_radius, self._q(), p.E, p.nu, m)

    def exact_slip(self, s):
        return self._slip(s)

    def exact_pressure_interface(self, s):
        return self._plane()[0] + 0.0 * s

    def reference_profile(self, s):
        return {"slip": self._slip(np.asarray(s))}

    def _K0(self) -> float:
        """K_II at phi = 0: 4 |q| sqrt(a / pi) / (2 - nu)."""
        return 4.0 * abs(self._q()) * np.sqrt(self.p.crack_radius / np.pi) / (2.0 - self.p.nu)

    def front_profile(self, prof):
        """The amplitude K_II0 = K_II / cos(phi) = K_III / ((1 - nu) sin(phi)) per bin: the
        slip is parallel to x, so near the front its normal part slip cos(phi) is the mode II
        jump and its part along the front slip sin(phi) the mode III one, both of the
        plane-strain fit of the slip itself."""
        p = self.p
        angle, K = self._front_K(prof, prof.slip, p.E, p.nu)
        return {"angle": angle, "K_II0": K, "K_II0_exact": np.full(len(K), self._K0())}

    def interface_reference(self, prof, q, friction):
        sigma_n, tau = self._plane()
        a, q_d, K0 = self.p.crack_radius, self._q(), self._K0()
        out = {"sigma_n": sigma_n, "tau": tau, "driving_shear": q_d, "K_II0_exact": K0}
        if q_d == 0.0:
            out["max_slip"] = float(np.max(np.abs(prof.slip), initial=0.0))  # stick
            return out
        front = self.front_profile(prof)
        err = np.abs(front["K_II0"] - K0) / K0
        out["K_II0"] = float(np.mean(front["K_II0"]))
        out["K_rel_error"] = abs(out["K_II0"] - K0) / K0
        out["K_rel_error_max"] = float(np.max(err))
        # sliding: the face shear equals the bound at sigma_n away from the front
        inner = prof.s < a - 2.0 * self.p.h_crack
        shear = np.abs(prof.t[inner])
        out["face_shear_error"] = float(
            np.max(np.abs(shear - self._bound(sigma_n)), initial=0.0) / sigma_n
        )
        out["slipping_fraction"] = float(np.mean(prof.status[inner] == STATUS["slip"]))
        return out


@dataclass(frozen=True)
class FaultBlockParams(_PennyParams):
    sigma_v: float = param(20e6, "vertical remote compression sigma_v", positive=True)
    sigma_h: float = param(
        8e6, "horizontal remote compression sigma_h (in the dip plane)", nonnegative=True
    )
    dip: float = param(60.0, "the fault's dip: its normal's angle to the vertical, degrees")
    overpressure: float = param(
        0.0,
        "fluid overpressure p on the fault's faces (it lowers the effective normal stress)",
        nonnegative=True,
    )

    def __post_init__(self) -> None:
        super().__post_init__()
        if not 0.0 <= self.dip <= 90.0:
            raise ValueError(f"--dip ({self.dip}) must be within [0, 90] degrees")


class FaultBlock(PennyShear):
    """A circular fault patch of radius a in a block (the penny crack's geometry, its plane
    z = 0 in the fault's frame) under the remote principal stresses sigma_v (vertical) and
    sigma_h (horizontal, in the dip plane), the fault's normal at ``dip`` to the vertical, with
    Coulomb friction and a fluid overpressure p on its faces. In the fault's frame the vertical
    is (sin dip, 0, cos dip): on the fault sigma_n = sigma_v cos^2 + sigma_h sin^2 and
    tau = -(sigma_v - sigma_h) sin cos along x. The fluid carries p of sigma_n, the contact
    the effective sigma_n - p; where abs(tau) > mu (sigma_n - p) the whole fault slips under the
    uniform driving shear q (penny-shear's closed forms with q), and the stress drop, the shear
    released on the fault, is abs(q). Reported: the slip distribution (interface.csv, the
    profile plot), the slipping area, the stress drop against abs(q)."""

    name = "fault-block"
    summary = "circular fault patch under remote stress, Coulomb, fluid overpressure (3D)"
    Params = FaultBlockParams

    def remote_stress(self) -> np.ndarray:
        b = np.radians(self.p.dip)
        v = np.array([np.sin(b), 0.0, np.cos(b)])  # the vertical in the fault's frame
        h = np.array([np.cos(b), 0.0, -np.sin(b)])  # the horizontal in the dip plane
        return -self.p.sigma_v * np.outer(v, v) - self.p.sigma_h * np.outer(h, h)

    def fluid_pressure(self):
        return self.p.overpressure if self.p.overpressure > 0.0 else None

    def _plane(self) -> tuple[float, float]:
        """(effective sigma_n, tau): the compression the contact carries and the shear."""
        sigma_n, tau = super()._plane()
        return sigma_n - self.p.overpressure, tau

    def interface_reference(self, prof, q, friction):
        out = super().interface_reference(prof, q, friction)
        sigma_n, tau = self._plane()
        q_d = self._q()
        area = 0.5 * np.pi * self.p.crack_radius**2  # the half model's fault
        out["slipping_area_fraction"] = q.interface.extra.get("slipping_size", 0.0) / area
        out["stress_drop_exact"] = abs(q_d)
        if q_d != 0.0:
            # the shear released on the fault: tau before slip minus the face shear after,
            # averaged away from the front
            inner = prof.s < self.p.crack_radius - 2.0 * self.p.h_crack
            drop = abs(tau) - float(np.mean(np.abs(prof.t[inner])))
            out["stress_drop"] = drop
            out["stress_drop_rel_error"] = abs(drop - abs(q_d)) / abs(q_d)
        return out
