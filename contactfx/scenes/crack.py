"""Crack-face contact in a plate (plane strain): a pressurised crack (Sneddon), an inclined
frictional crack under compression, and a fracture partly held open by a proppant layer.

Geometry: the square [-W/2, W/2]^2 with a straight crack |s| < a through its centre at the angle
beta to the x axis (s along the crack, n_I = (-sin beta, cos beta) its normal), a chain of mesh
edges refined to ``h_crack`` and graded to ``h_far`` (:func:`contactfx.meshes.crack_plate`).
The plate stands for an infinite one: its boundary carries the traction sigma n of

* ``--boundary infinite`` (default): the infinite-plate closed-form stress of the load case
  where one exists (uniform remote stress plus the Westergaard field of the crack faces'
  pressure and driving shear, :mod:`contactfx.references`), so that the finite plate
  has the infinite plate's solution and the only error is the discretisation's;
* ``--boundary remote``: the remote stress only (a finite plate under uniform traction; the
  crack then feels the plate's width, K / K_inf = sqrt(sec(pi a / W)) for a strip).

Three pinned vertices (two corners of the bottom edge) remove the rigid motions; the loads are
in equilibrium, so they carry no force. The load factor t scales every load.

Stress intensity factors are computed from the crack-face jump near the tips (displacement
extrapolation): K(r) = E' / 8 sqrt(2 pi / r) [[u]](r) at the nodes with a / 20 <= r = a - |s|
<= a / 2, fitted by K0 + K1 r (least squares) and extrapolated to r = 0; the mean of both tips
(Chan, Tuba & Wilson 1970, doi:10.1016/0013-7944(70)90026-3). The nodes nearer the tip are
left out: there the linear elements cannot follow the sqrt(r) jump (the first node's jump is
about 20 % low on the default mesh).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
import ufl

from contactfx import references as cf
from contactfx._compat import numpy_math, ufl_math
from contactfx.contact.cut import CrackSegment
from contactfx.driver.interface_post import STATUS, Profile
from contactfx.meshes import CrackPlateFacets, crack_plate, crack_set_plate, structured_plate
from contactfx.params import param
from contactfx.scenes import export
from contactfx.scenes.base import elastic
from contactfx.scenes.interface_base import InterfaceScene

__all__ = [
    "CrackSneddon",
    "CrackInclined",
    "ProppedFracture",
    "stress_intensity_from_jump",
    "extrapolated_K",
    "SlidingCrack",
    "CrackSet",
]

_OUTER = (
    CrackPlateFacets.BOTTOM,
    CrackPlateFacets.RIGHT,
    CrackPlateFacets.TOP,
    CrackPlateFacets.LEFT,
)


def stress_intensity_from_jump(
    s, jump, a: float, E: float, nu: float, window: tuple[float, float] = (0.05, 0.5)
):
    """K from the crack-face displacement jump near both tips (see the module docstring);
    nan when a tip has fewer than 3 nodes at window[0] a <= r <= window[1] a."""
    values = []
    for sign in (1.0, -1.0):
        r = a - sign * np.asarray(s)
        values.append(extrapolated_K(r, jump, E, nu, a, window, sign * np.asarray(s) > 0))
    return float(np.mean(values))


def extrapolated_K(
    r, jump, E: float, nu: float, a: float, window: tuple[float, float] = (0.05, 0.5), near=True
) -> float:
    """K at one tip (or one stretch of a 3D front) from the jump at the distances r to it:
    the near-tip plane-strain field [[u]] = 8 K / E' sqrt(r / (2 pi)) read at the nodes with
    window[0] a <= r <= window[1] a (and ``near``), fitted by K0 + K1 r, K0; nan with fewer
    than 3 such nodes."""
    r = np.asarray(r)
    sel = (r >= window[0] * a) & (r <= window[1] * a) & near
    if sel.sum() < 3:
        return float("nan")
    Ep = E / (1.0 - nu**2)
    K = Ep / 8.0 * np.sqrt(2.0 * np.pi / r[sel]) * np.abs(np.asarray(jump)[sel])
    K1, K0 = np.polyfit(r[sel], K, 1)
    return float(K0)


#: the part of the crack, |s| <= INTERIOR a, where the pressure is measured away from the tips
INTERIOR = 0.8


@dataclass(frozen=True)
class _PlateParams(elastic(10e9, 0.25)):
    crack_half_length: float = param(1.0, "crack half-length a", positive=True)
    plate_width: float = param(20.0, "plate width W (the square [-W/2, W/2]^2)", positive=True)
    h_crack: float = param(0.025, "element size along the crack", positive=True)
    h_tip: float = param(0.0025, "element size at the crack tips (<= h-crack)", positive=True)
    h_far: float = param(0.5, "element size far from the crack", positive=True)
    grading: float = param(0.15, "element size increase per unit distance", positive=True)
    boundary: str = param(
        "infinite",
        "plate boundary traction: infinite (closed-form "
        "infinite-plate field) or remote (uniform remote stress)",
        choices=("infinite", "remote"),
    )
    crack: str = param(
        "fitted",
        "fitted (a chain of mesh edges) or unfitted (level sets on a mesh that ignores the crack)",
        choices=("fitted", "unfitted"),
    )
    crack_offset: float = param(
        0.0, "shift of the crack along its normal (unfitted: its position against the mesh's nodes)"
    )
    background: str = param(
        "graded",
        "the unfitted crack's mesh: graded (the fitted crack's "
        "size field) or structured (a grid of spacing h-crack around it)",
        choices=("graded", "structured"),
    )

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.crack == "fitted" and (self.crack_offset != 0.0 or self.background != "graded"):
            raise ValueError("--crack-offset and --background structured need --crack unfitted")
        if not self.crack_half_length < 0.5 * self.plate_width:
            raise ValueError(
                f"--crack-half-length ({self.crack_half_length}) must be < plate-width / 2 "
                f"({0.5 * self.plate_width})"
            )
        if not self.h_tip <= self.h_crack <= self.h_far:
            raise ValueError(
                f"element sizes must satisfy --h-tip ({self.h_tip}) <= --h-crack "
                f"({self.h_crack}) <= --h-far ({self.h_far})"
            )


class _CrackPlate(InterfaceScene):
    """Shared geometry, supports and boundary tractions of the crack scenes."""

    interface_tag = CrackPlateFacets.CRACK

    # -- load case: remote stress (global frame) and the crack-face loads of the closed form
    def angle(self) -> float:
        return 0.0

    def remote_stress(self) -> np.ndarray:
        return np.zeros((2, 2))

    def face_loads(self) -> tuple[float, float]:
        """(p, q): the pressure and driving shear of the infinite-plate closed form (0, 0 when
        there is none); their Westergaard field is added to the remote stress."""
        return 0.0, 0.0

    def split_points(self) -> tuple[float, ...]:
        return ()

    def crack_segments(self) -> list[CrackSegment]:
        """The crack as a segment (tip to tip), for ``--crack unfitted``."""
        t0, t1 = self.tips()
        return [CrackSegment(t1, t0)]

    # -- geometry -------------------------------------------------------------------------
    def _axes(self):
        beta = np.radians(self.angle())
        d = np.array([np.cos(beta), np.sin(beta)])
        n = np.array([-np.sin(beta), np.cos(beta)])
        return d, n

    def mesh_builder(self):
        p = self.p
        if p.background == "structured":
            d, _ = self._axes()
            reach = p.crack_half_length * np.abs(d).max() + abs(p.crack_offset)
            return functools.partial(
                structured_plate,
                half_width=0.5 * p.plate_width,
                inner_half_width=min(
                    reach + 0.25 * p.crack_half_length, 0.5 * (reach + 0.5 * p.plate_width)
                ),
                h=p.h_crack,
            ), 2
        return functools.partial(
            crack_plate,
            half_width=0.5 * p.plate_width,
            crack_half_length=p.crack_half_length,
            angle=self.angle(),
            h_crack=p.h_crack,
            h_far=p.h_far,
            grading=p.grading,
            h_tip=p.h_tip,
            embed=p.crack == "fitted",
            split_at=self.split_points() if p.crack == "fitted" else (),
        ), 2

    def length_scale(self) -> float:
        return self.p.plate_width

    def h_contact(self) -> float:
        return self.p.h_crack

    def _centre(self) -> np.ndarray:
        _, n = self._axes()
        return self.p.crack_offset * n

    def side(self, x):
        _, n = self._axes()
        return n[0] * x[0] + n[1] * x[1] - self.p.crack_offset

    def tips(self):
        d, _ = self._axes()
        a = self.p.crack_half_length
        return [self._centre() + a * d, self._centre() - a * d]

    def frame(self):
        d, _ = self._axes()
        return self._centre(), d

    def away_from_tips(self, s):
        """|s| <= 0.8 a (docs/verification.md section 6, "Tractions at the tips"): next to a
        tip the discrete traction carries an error of the order of K / sqrt(h) over a few
        elements, which no refinement of standard elements removes in L2; a fixed distance
        away it converges."""
        return ufl.conditional(ufl.le(abs(s), INTERIOR * self.p.crack_half_length), 1.0, 0.0)

    def pinned(self):
        half = 0.5 * self.p.plate_width
        return [
            (np.array([-half, -half]), 0),
            (np.array([-half, -half]), 1),
            (np.array([half, -half]), 1),
        ]

    def _boundary_stress(self, x):
        """UFL stress on the plate boundary at load factor 1."""
        sigma = ufl.as_matrix(self.remote_stress().tolist())
        p, q = self.face_loads()
        if self.p.boundary == "infinite" and (p != 0.0 or q != 0.0):
            d, n = self._axes()
            xl = d[0] * x[0] + d[1] * x[1]
            yl = n[0] * x[0] + n[1] * x[1] - self.p.crack_offset
            sxx, syy, sxy = cf.crack_perturbation_stress(
                xl, yl, self.p.crack_half_length, p, q, ufl_math
            )
            R = ufl.as_matrix([[d[0], n[0]], [d[1], n[1]]])  # local -> global
            local = ufl.as_matrix([[sxx, sxy], [sxy, syy]])
            sigma = sigma + R * local * R.T
        return sigma

    def _boundary_stress_text(self) -> list[list]:
        """:meth:`_boundary_stress` as problem-file entries: numbers, or for the infinite
        plate's field the same closed form written as expressions in x, y
        (:class:`contactfx.scenes.export.Symbol`)."""
        sigma = [[float(v) + 0.0 for v in row] for row in self.remote_stress()]  # no -0.0
        p, q = self.face_loads()
        if self.p.boundary == "infinite" and (p != 0.0 or q != 0.0):
            d, n = self._axes()
            x = (export.Symbol("x"), export.Symbol("y"))  # the variables of the file
            xl = d[0] * x[0] + d[1] * x[1]
            yl = n[0] * x[0] + n[1] * x[1]
            sxx, syy, sxy = cf.crack_perturbation_stress(
                xl, yl, self.p.crack_half_length, p, q, export.SYMBOLIC
            )
            R = [[d[0], n[0]], [d[1], n[1]]]
            local = [[sxx, sxy], [sxy, syy]]
            for i in range(2):
                for j in range(2):
                    for k in range(2):
                        for m in range(2):
                            sigma[i][j] = sigma[i][j] + R[i][k] * local[k][m] * R[j][m]
        return [[export.text(v) for v in row] for row in sigma]

    def interface_data(self) -> dict:
        """The ``[interface]`` keys beyond the group, h and frame."""
        fluid = self.fluid_pressure()
        return {} if fluid is None else {"fluid_pressure": float(fluid)}

    def problem_data(self, numerics) -> dict:
        """The plate with its boundary stress on the four edges (traction sigma n, the same
        degree-8 rule), the pinned corners, and the crack with the scene's frame and h."""
        self._fitted_only()
        stress = self._boundary_stress_text()
        boundary = []
        if any(v != 0.0 for row in stress for v in row):
            boundary = [
                {"group": tag.name.lower(), "stress": stress, "quadrature_degree": 8}
                for tag in _OUTER
            ]
        origin, direction = self.frame()
        interface = {
            "group": "crack",
            "h": self.h_contact(),
            "origin": [float(v) for v in origin],
            "direction": [float(v) for v in direction],
            **self.interface_data(),
        }
        return {
            "bodies": [export.body("domain", self.material())],
            "boundary": boundary,
            "pins": export.pins(self.pinned()),
            "interface": interface,
        }

    def load(self, v, ds, t):
        mesh = ds.ufl_domain()
        x = ufl.SpatialCoordinate(mesh)
        n = ufl.FacetNormal(mesh)
        sigma = self._boundary_stress(x)
        dso = ds(_OUTER, metadata={"quadrature_degree": 8})
        return t * ufl.dot(ufl.dot(sigma, n), v) * dso

    def _ellipse(self, s, load):
        """Sneddon's jump under the face load ``load`` (numpy or UFL in s)."""
        m = numpy_math if isinstance(s, np.ndarray) else ufl_math
        return cf.opening(s, self.p.crack_half_length, load, self.p.E, self.p.nu, m)

    def _K(self, prof: Profile, jump) -> float:
        return stress_intensity_from_jump(
            prof.s, jump, self.p.crack_half_length, self.p.E, self.p.nu
        )


@dataclass(frozen=True)
class CrackSneddonParams(_PlateParams):
    pressure: float = param(1e6, "fluid pressure p on the crack faces (< 0: suction closes it)")


class CrackSneddon(_CrackPlate):
    name = "crack-sneddon"
    summary = "pressurised crack (Sneddon opening, K_I); negative pressure closes it"
    Params = CrackSneddonParams
    numerics_defaults = {"steps": 1}

    def fluid_pressure(self):
        return self.p.pressure

    def face_loads(self):
        return max(self.p.pressure, 0.0), 0.0

    def exact_opening(self, s):
        return self._ellipse(s, max(self.p.pressure, 0.0))

    def exact_pressure_interface(self, s):
        if self.p.pressure >= 0.0:
            return None  # no contact: the normal force is checked instead
        return -self.p.pressure + 0.0 * s

    def reference_profile(self, s):
        return {"opening": self._ellipse(s, max(self.p.pressure, 0.0))}

    def interface_reference(self, prof, q, friction):
        p = self.p.pressure
        out = {"K_I_exact": cf.stress_intensity(max(p, 0.0), self.p.crack_half_length)}
        if p > 0.0:
            K = self._K(prof, prof.opening)
            out["K_I"] = K
            out["K_rel_error"] = abs(K - out["K_I_exact"]) / out["K_I_exact"]
            # "no false contact": the contact force relative to the fluid force on a face
            out["false_contact"] = abs(q.force) / (2.0 * p * self.p.crack_half_length)
        else:
            out["contact_force_exact"] = -p * 2.0 * self.p.crack_half_length
            out["force_rel_error"] = (
                abs(q.force - out["contact_force_exact"]) / (out["contact_force_exact"])
            )
        return out


@dataclass(frozen=True)
class CrackInclinedParams(_PlateParams):
    beta: float = param(
        45.0, "crack angle to the x axis, degrees (the plane normal to the compression)"
    )
    sigma: float = param(10e6, "uniaxial compression along y", positive=True)


class SlidingCrack:
    """Mixin of the closed crack scenes that slide under a remote stress: the run's friction
    law, its bound and the driving shear from the scene's ``_plane()`` = (sigma_n, tau) on
    the crack plane."""

    def __init__(self, params) -> None:
        super().__init__(params)
        self.friction = None  # the friction law of the run (set by configure)

    def configure(self, numerics) -> None:
        self.friction = numerics.friction_law()

    def _bound(self, p):
        """Friction bound of the law at the contact pressure p (numbers)."""
        f = self.friction
        if f is None:
            return 0.0 * p
        if f.name == "coulomb":
            return f.mu * p
        return f.threshold + 0.0 * p

    def _q(self) -> float:
        """Driving shear: tau minus the friction resistance when it is exceeded, else 0."""
        sigma_n, tau = self._plane()
        return float(cf.driving_shear(tau, self._bound(sigma_n), 1.0))


class CrackInclined(SlidingCrack, _CrackPlate):
    name = "crack-inclined"
    summary = "inclined closed crack under uniaxial compression, Coulomb / Tresca friction (K_II)"
    Params = CrackInclinedParams
    numerics_defaults = {"friction": "coulomb", "mu": 0.3, "steps": 1}

    def angle(self):
        return self.p.beta

    def remote_stress(self):
        return np.array([[0.0, 0.0], [0.0, -self.p.sigma]])

    def _plane(self):
        d, n = self._axes()
        S = self.remote_stress()
        sigma_n = -n @ S @ n
        tau = d @ S @ n
        return sigma_n, tau

    def face_loads(self):
        return 0.0, self._q()

    def exact_slip(self, s):
        return self._ellipse(s, self._q())

    def exact_pressure_interface(self, s):
        return self._plane()[0] + 0.0 * s

    def reference_profile(self, s):
        return {"slip": self._ellipse(s, self._q())}

    def interface_reference(self, prof, q, friction):
        sigma_n, tau = self._plane()
        a = self.p.crack_half_length
        exact = abs(self._q()) * np.sqrt(np.pi * a)
        out = {
            "sigma_n": sigma_n,
            "tau": tau,
            "K_II_exact": exact,
            "K_II_normalised_exact": exact / (self.p.sigma * np.sqrt(np.pi * a)),
        }
        K = self._K(prof, prof.slip) if exact > 0.0 else float(np.max(np.abs(prof.slip)))
        out["K_II"] = K
        if exact > 0.0:
            out["K_II_normalised"] = K / (self.p.sigma * np.sqrt(np.pi * a))
            out["K_rel_error"] = abs(K - exact) / exact
            # sliding: the face shear equals the bound at sigma_n at the nodes off the tips
            inner = np.abs(prof.s) < a - 2.0 * self.p.h_crack
            shear = np.abs(prof.t[inner])
            out["face_shear_error"] = float(
                np.max(np.abs(shear - self._bound(sigma_n)), initial=0.0) / sigma_n
            )
            # the friction law itself at the slipping nodes: |t| = bound(p) (computed p)
            out["friction_law_error"] = float(
                np.max(np.abs(shear - self._bound(prof.p[inner])), initial=0.0) / sigma_n
            )
            out["slipping_fraction"] = float(np.mean(prof.status[inner] == STATUS["slip"]))
        else:
            out["max_slip"] = K  # stick: no slip at all
        return out


@dataclass(frozen=True)
class ProppedFractureParams(_PlateParams):
    net_pressure: float = param(-1e6, "net pressure p_net = p - s_c (fluid minus closure)")
    closure_stress: float = param(
        20e6, "remote compression s_c normal to the fracture", nonnegative=True
    )
    proppant_half_length: float = param(0.5, "proppant layer on |s| < b", positive=True)
    proppant_thickness: float = param(
        1e-4, "proppant thickness h (aperture >= h there)", positive=True
    )

    def __post_init__(self) -> None:
        super().__post_init__()
        if not self.proppant_half_length < self.crack_half_length:
            raise ValueError(
                f"--proppant-half-length ({self.proppant_half_length}) must be < "
                f"--crack-half-length ({self.crack_half_length})"
            )


class ProppedFracture(_CrackPlate):
    name = "propped-fracture"
    summary = "fracture with a proppant layer under closure stress and fluid pressure"
    Params = ProppedFractureParams
    numerics_defaults = {"steps": 1}

    def p_star(self) -> float:
        p = self.p
        return float(
            cf.propping_pressure(
                p.proppant_thickness, p.crack_half_length, p.proppant_half_length, p.E, p.nu
            )
        )

    def open_branch(self) -> bool:
        return self.p.net_pressure >= self.p_star()

    def split_points(self):
        b = self.p.proppant_half_length
        return (-b, b)

    def remote_stress(self):
        d, n = self._axes()
        return -self.p.closure_stress * np.outer(n, n)

    def fluid_pressure(self):
        return self.p.net_pressure + self.p.closure_stress

    def face_loads(self):
        return (self.p.net_pressure, 0.0) if self.open_branch() else (0.0, 0.0)

    def floor(self, s):
        b = self.p.proppant_half_length * (1.0 - 1e-9)  # the layer's end nodes are unpropped
        return ufl.conditional(ufl.lt(abs(s), b), self.p.proppant_thickness, 0.0)

    def interface_data(self):
        b = self.p.proppant_half_length
        return {
            **super().interface_data(),
            "proppant_thickness": self.p.proppant_thickness,
            "proppant_zone": [-b, b],
        }

    def exact_opening(self, s):
        return self._ellipse(s, self.p.net_pressure) if self.open_branch() else None

    def reference_profile(self, s):
        if self.open_branch():
            return {"opening": self._ellipse(s, self.p.net_pressure)}
        return {}

    def interface_reference(self, prof, q, friction):
        out = {
            "p_star": self.p_star(),
            "open_branch": float(self.open_branch()),
            "proppant_thickness": self.p.proppant_thickness,
        }
        propped = prof.floor > 0.0
        out["min_aperture_propped_over_h"] = float(
            np.min(prof.opening[propped], initial=np.inf) / self.p.proppant_thickness
        )
        out["proppant_force"] = q.interface.proppant_force
        if self.open_branch():
            K = self._K(prof, prof.opening)
            exact = cf.stress_intensity(self.p.net_pressure, self.p.crack_half_length)
            out.update(K_I=K, K_I_exact=exact, K_rel_error=abs(K - exact) / exact)
        return out


@dataclass(frozen=True)
class CrackSetParams(_PlateParams):
    crack: str = param(
        "unfitted", "unfitted (several cracks are implemented unfitted only)", choices=("unfitted",)
    )
    angles: str = param(
        "30,75,-40",
        "the cracks' angles to the x axis, degrees, comma-"
        "separated: centred on y = 0, spacing apart along x",
    )
    spacing: float = param(5.0, "distance between neighbouring cracks' centres", positive=True)
    sigma_x: float = param(5e6, "remote compression along x", nonnegative=True)
    sigma_y: float = param(10e6, "remote compression along y", nonnegative=True)
    tau: float = param(3e6, "remote shear stress sigma_xy")

    def __post_init__(self) -> None:
        super().__post_init__()
        angles = self.angle_list()
        if not angles:
            raise ValueError("--angles needs at least one angle")
        if not self.spacing > 2.0 * self.crack_half_length:
            raise ValueError(
                f"--spacing ({self.spacing}) must exceed the crack length "
                f"({2.0 * self.crack_half_length}): the cracks must not touch"
            )
        reach = 0.5 * (len(angles) - 1) * self.spacing + self.crack_half_length
        if not reach < 0.5 * self.plate_width:
            raise ValueError(
                f"the cracks reach x = {reach}, beyond the plate (half-width "
                f"{0.5 * self.plate_width})"
            )

    def angle_list(self) -> list[float]:
        try:
            return [float(v) for v in self.angles.split(",") if v.strip()]
        except ValueError:
            raise ValueError(
                f"--angles must be numbers separated by commas, got {self.angles!r}"
            ) from None


class CrackSet(SlidingCrack, _CrackPlate):
    """Several straight unfitted cracks of half-length a at different angles, centred on
    y = 0 at ``spacing`` from each other, in a plate under the remote stress
    [[-sigma_x, tau], [tau, -sigma_y]], with friction.

    Reference: each crack alone in the infinite plate (section 6's closed form with its own
    plane's normal stress and driving shear). ``--boundary infinite`` loads the plate's edges
    with the remote stress plus the sum of every crack's Westergaard field, so that only the
    cracks' interaction separates the computed K_II from the isolated cracks' (it decays as
    (a / spacing)^2: docs/verification.md section 14)."""

    name = "crack-set"
    summary = "several unfitted cracks at different angles under compression and shear (K_II)"
    Params = CrackSetParams
    numerics_defaults = {"friction": "coulomb", "mu": 0.3, "steps": 1}

    def _layout(self) -> list[tuple[np.ndarray, float]]:
        """(centre, angle in degrees) of every crack."""
        angles = self.p.angle_list()
        shift = 0.5 * (len(angles) - 1)
        return [
            (np.array([(k - shift) * self.p.spacing, 0.0]), beta) for k, beta in enumerate(angles)
        ]

    @staticmethod
    def _frame(beta: float) -> tuple[np.ndarray, np.ndarray]:
        t = np.radians(beta)
        return np.array([np.cos(t), np.sin(t)]), np.array([-np.sin(t), np.cos(t)])

    def angle(self):
        return self._layout()[0][1]

    def crack_segments(self):
        a = self.p.crack_half_length
        out = []
        for centre, beta in self._layout():
            d, _ = self._frame(beta)
            out.append(CrackSegment(centre - a * d, centre + a * d))
        return out

    def tips(self):
        return [t for seg in self.crack_segments() for t in seg.tips()]

    def frame(self):
        centre, beta = self._layout()[0]
        return centre, self._frame(beta)[0]

    def remote_stress(self):
        p = self.p
        return np.array([[-p.sigma_x, p.tau], [p.tau, -p.sigma_y]])

    def _plane_of(self, beta: float) -> tuple[float, float]:
        """(sigma_n, tau): the compression and the shear on a crack's plane."""
        d, n = self._frame(beta)
        S = self.remote_stress()
        return float(-n @ S @ n), float(d @ S @ n)

    def _q_of(self, beta: float) -> float:
        sigma_n, tau = self._plane_of(beta)
        return float(cf.driving_shear(tau, self._bound(sigma_n), 1.0))

    def mesh_builder(self):
        p = self.p
        cracks = tuple((float(c[0]), float(c[1]), float(beta)) for c, beta in self._layout())
        return functools.partial(
            crack_set_plate,
            half_width=0.5 * p.plate_width,
            cracks=cracks,
            crack_half_length=p.crack_half_length,
            h_crack=p.h_crack,
            h_tip=p.h_tip,
            h_far=p.h_far,
            grading=p.grading,
        ), 2

    def _boundary_stress(self, x):
        sigma = ufl.as_matrix(self.remote_stress().tolist())
        if self.p.boundary != "infinite":
            return sigma
        for centre, beta in self._layout():
            q = self._q_of(beta)
            if q == 0.0:
                continue
            d, n = self._frame(beta)
            xl = d[0] * (x[0] - centre[0]) + d[1] * (x[1] - centre[1])
            yl = n[0] * (x[0] - centre[0]) + n[1] * (x[1] - centre[1])
            sxx, syy, sxy = cf.crack_perturbation_stress(
                xl, yl, self.p.crack_half_length, 0.0, q, ufl_math
            )
            R = ufl.as_matrix([[d[0], n[0]], [d[1], n[1]]])
            sigma = sigma + R * ufl.as_matrix([[sxx, sxy], [sxy, syy]]) * R.T
        return sigma

    def problem_data(self, numerics):
        raise ValueError(
            f"scene '{self.name}' cannot be written as a problem file: problem "
            "files carry fitted interfaces only"
        )

    def interface_reference(self, prof, q, friction):
        a, out = self.p.crack_half_length, {}
        K_errors, slip_errors = [], []
        for k, (_, beta) in enumerate(self._layout()):
            sel = np.ones(len(prof.s), dtype=bool) if prof.crack is None else prof.crack == k + 1
            s, slip = prof.s[sel], np.abs(prof.slip[sel])
            sigma_n, tau = self._plane_of(beta)
            qk = self._q_of(beta)
            exact = abs(qk) * np.sqrt(np.pi * a)
            name = f"crack_{k + 1}"
            out.update(
                {f"{name}_sigma_n": sigma_n, f"{name}_tau": tau, f"{name}_K_II_exact": exact}
            )
            if exact == 0.0:
                out[f"{name}_max_slip"] = float(np.max(slip, initial=0.0))
                continue
            K = stress_intensity_from_jump(s, slip, a, self.p.E, self.p.nu)
            ref = np.abs(self._ellipse(s, qk))
            err = float(np.sqrt(np.mean((slip - ref) ** 2) / np.mean(ref**2)))
            out.update(
                {
                    f"{name}_K_II": K,
                    f"{name}_K_rel_error": abs(K - exact) / exact,
                    f"{name}_slip_rms_rel": err,
                }
            )
            K_errors.append(abs(K - exact) / exact)
            slip_errors.append(err)
        if K_errors:
            out["K_rel_error"] = max(K_errors)
            out["slip_rms_rel"] = max(slip_errors)
        return out
