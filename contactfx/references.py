"""The closed forms the scenes and tests compare with, each written once (docs/verification.md
lists them with their sources): Hertz (section 1), the rigid flat punch (section 2), the exact
discrete Nitsche bar (section 8), the oedometric modulus, and crack-face contact and joints
(plane strain; sections 6, 7).

Hertz (Johnson 1985, Contact Mechanics, doi:10.1017/CBO9781139171731, sections 4.2 and 5.2),
at the load P (per unit length in 2D) with the contact modulus E*:

    2D: a = sqrt(4 P R / (pi E*)),  p0 = 2 P / (pi a)
    3D: a = (3 P R / (4 E*))^(1/3), p0 = 3 P / (2 pi a^2), approach a^2 / R

Bar (0, L), E A = E, u(0) = 0, body force f, wall at x = L + g0, N P1 elements of size h, with
the Chouly-Hild parameter gamma0' = 1 / gamma0: the Nitsche solution penetrates by
pen = gamma0' f h^2 / (2 E (1 - theta gamma0')) and its multiplier differs from
lambda = f L / 2 - E g0 / L by 0 (theta = 1), -E pen / L (0), -2 E pen / L (-1)
(Chouly & Hild 2013, doi:10.1137/12088344X).

Crack faces and joints:

Crack |x| < a on y = 0 in an infinite plate, in the crack's own frame. Signs: tension positive
for stresses; pressures p, normal stresses sigma_n and effective stresses s' are positive in
compression (docs/architecture.md); ``E' = E / (1 - nu^2)``.

Stress field of a crack with loaded faces (Westergaard 1939, J. Appl. Mech. 6, A49-A53,
doi:10.1115/1.4008969; Tada, Paris & Irwin 2000, The Stress Analysis of Cracks Handbook, 3rd
ed., doi:10.1115/1.801535). With z = x + i y and the face load subtracted from the remotely
loaded Griffith crack,

    mode I  (face pressure p):  Z = p (z / sqrt(z^2 - a^2) - 1),
        sxx = Re Z - y Im Z',      syy = Re Z + y Im Z',   sxy = -y Re Z';
    mode II (face shear q):     Z = q (z / sqrt(z^2 - a^2) - 1),
        sxx = 2 Im Z + y Re Z',    syy = -y Re Z',         sxy = Re Z - y Im Z',

Z' = -load a^2 / (z^2 - a^2)^(3/2). Both derive from Airy functions (mode I
phi = Re ZZ + y Im Zb, mode II phi = -y Re Zb with Zb' = Z, ZZ' = Zb); in mode II the real
and imaginary parts are not placed as in mode I (swapping them, sxx = 2 Re Z + y Im Z', ...,
breaks equilibrium). The branch of sqrt(z^2 - a^2) is sqrt(r1 r2) exp(i (t1 + t2) / 2) with
z -+ a = r1,2 exp(i t1,2), t1,2 = atan2(y, x -+ a) in (-pi, pi]: it behaves as z at infinity
and its only cut is the crack. Face conditions (upper face y -> 0+ and lower face y -> 0-, |x| < a):

    syy = -p,  sxy = -q,

i.e. the face y = 0+ (outward normal -e_y) carries the traction (q, p): the pressure p pushes
the faces apart and the shear q pushes the upper face towards +x. The stresses vanish at
infinity, K_I = p sqrt(pi a), K_II = q sqrt(pi a) (syy, sxy ~ K / sqrt(2 pi r) ahead of the
tips), and the face displacement jumps are Sneddon's ellipses (Sneddon 1946,
doi:10.1098/rspa.1946.0077)

    u_y(0+) - u_y(0-) = 4 p / E' sqrt(a^2 - x^2),   u_x(0+) - u_x(0-) = 4 q / E' sqrt(a^2 - x^2).

Closed crack under compression sigma_n > 0 and shear tau with Coulomb friction mu: it sticks
if |tau| <= mu sigma_n, otherwise it slides as a whole under the driving shear
q = sign(tau) (|tau| - mu sigma_n) (docs/verification.md section 6). Under uniaxial compression
sigma with the crack at beta to the plane normal to the compression, sigma_n = sigma cos^2 beta,
tau = sigma sin beta cos beta, so K_II = sigma sqrt(pi a) cos beta (sin beta - mu cos beta)
when tan beta > mu. A strip of full width W with traction data raises K by the factor
sqrt(sec(pi a / W)) (Feddersen 1966, ASTM STP 410, 77-79; Tada et al. 2000).

Joints: Barton-Bandis hyperbolic closure s' = K_ni v / (1 - v / V_m) (Bandis, Lumsden &
Barton 1983, doi:10.1016/0148-9062(83)90595-8). Propped crack: a rigid proppant layer of
thickness h on |x| < b is first touched at x = +-b, where the Sneddon opening under the net
pressure p* = h E' / (4 sqrt(a^2 - b^2)) equals h.

The field functions take a math namespace ``m`` with ``sqrt, atan2, cos, sin``:
:data:`contactfx._compat.numpy_math` (the default) for numpy arrays,
:data:`contactfx._compat.ufl_math` to build UFL expressions (e.g. of ``ufl.SpatialCoordinate``).
Functions without ``m`` use arithmetic only and accept both, except :func:`driving_shear` and
:func:`inclined_crack_KII` (numpy / float: they branch on the data).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from contactfx._compat import numpy_math

__all__ = [
    "hertz_2d",
    "hertz_3d",
    "rigid_punch_2d",
    "bar_nitsche_exact",
    "bar_impact_exact",
    "oedometric_modulus",
    "crack_perturbation_stress",
    "opening",
    "stress_intensity",
    "penny_opening",
    "penny_stress_intensity",
    "penny_shear_slip",
    "crack_plane_tractions",
    "driving_shear",
    "inclined_crack_KII",
    "width_correction",
    "bb_closure",
    "bb_stress",
    "bb_stiffness",
    "joint_column",
    "propping_pressure",
]


def hertz_2d(force: float, radius: float, E_star: float) -> dict[str, float]:
    a = np.sqrt(4.0 * force * radius / (np.pi * E_star))
    return {"a": a, "p0": 2.0 * force / (np.pi * a)}


def hertz_3d(force: float, radius: float, E_star: float) -> dict[str, float]:
    a = (3.0 * force * radius / (4.0 * E_star)) ** (1.0 / 3.0)
    return {"a": a, "p0": 3.0 * force / (2.0 * np.pi * a**2), "delta": a**2 / radius}


def hertz_impact(mass: float, speed: float, radius: float, E_star: float) -> dict[str, float]:
    """The quasi-static impact of an elastic sphere (mass m, radius R) on a rigid plane at the
    speed V (Johnson 1985, Contact Mechanics, doi:10.1017/CBO9781139171731, section 11.4): the
    largest approach delta* = (15 m V^2 / (16 E* sqrt(R)))^(2/5) (the kinetic energy
    1/2 m V^2 stored as Hertz's 8/15 E* sqrt(R) delta^(5/2)), the largest force
    P* = 4/3 E* sqrt(R) delta*^(3/2) and the contact's duration T = 2.9432 delta* / V (twice
    the integral of d delta / sqrt(V^2 - (delta / delta*)^(5/2) V^2) from 0 to delta*)."""
    delta = (15.0 * mass * speed**2 / (16.0 * E_star * np.sqrt(radius))) ** 0.4
    force = 4.0 / 3.0 * E_star * np.sqrt(radius) * delta**1.5
    return {"delta": delta, "force": force, "duration": 2.9432 * delta / speed}


def rigid_punch_2d(x, half_width: float, force: float):
    """Pressure P / (pi sqrt(a^2 - x^2)) under a rigid flat punch of half-width a pressed with
    the force P (per unit length) into an elastic half-plane, frictionless (Johnson 1985,
    section 2.8); nan outside |x| < a."""
    x = np.asarray(x, dtype=float)
    inside = np.abs(x) < half_width
    r = np.sqrt(np.where(inside, half_width**2 - x**2, 1.0))
    return np.where(inside, force / (np.pi * r), np.nan)


def bar_nitsche_exact(*, E, L, f, g0, n, theta, gamma0) -> dict[str, float]:
    """Exact discrete penetration and multiplier of the P1 Nitsche bar."""
    h = L / n
    g_ch = 1.0 / gamma0
    pen = g_ch * f * h**2 / (2.0 * E * (1.0 - theta * g_ch))
    lam = f * L / 2.0 - E * g0 / L
    shift = {1: 0.0, 0: -E * pen / L, -1: -2.0 * E * pen / L}[theta]
    return {"penetration": pen, "multiplier": lam + shift, "multiplier_exact": lam}


def oedometric_modulus(E, nu):
    """Uniaxial-strain modulus M = E (1 - nu) / ((1 + nu)(1 - 2 nu))."""
    return E * (1.0 - nu) / ((1.0 + nu) * (1.0 - 2.0 * nu))


def _griffith(x, y, a, m):
    """Real and imaginary parts of w = z / sqrt(z^2 - a^2) - 1 and of
    w' = -a^2 (z^2 - a^2)^(-3/2), in real arithmetic (z = x + i y)."""
    half_angle = 0.5 * (m.atan2(y, x - a) + m.atan2(y, x + a))
    modulus = m.sqrt(m.sqrt(((x - a) ** 2 + y**2) * ((x + a) ** 2 + y**2)))  # |z^2 - a^2|^(1/2)
    c, s = m.cos(half_angle), m.sin(half_angle)
    re_w = (x * c + y * s) / modulus - 1.0
    im_w = (y * c - x * s) / modulus
    scale = a**2 / modulus**3
    re_dw = -scale * m.cos(3.0 * half_angle)
    im_dw = scale * m.sin(3.0 * half_angle)
    return re_w, im_w, re_dw, im_dw


def crack_perturbation_stress(x, y, a, p, q, m: Any = numpy_math):
    """Stresses (sxx, syy, sxy) at (x, y) of an infinite plane-strain plate with the crack
    |x| < a, y = 0 whose faces carry the pressure p and the shear q, stress-free at infinity.

    Face conditions (both faces, |x| < a): syy = -p, sxy = -q. Exactly on y = 0 the atan2
    branch evaluates the upper face (numpy's arctan2 takes y = -0.0 as the lower face); the
    crack tips (x, y) = (+-a, 0) are singular.
    """
    re_w, im_w, re_dw, im_dw = _griffith(x, y, a, m)
    sxx = p * (re_w - y * im_dw) + q * (2.0 * im_w + y * re_dw)
    syy = p * (re_w + y * im_dw) - q * y * re_dw
    sxy = -p * y * re_dw + q * (re_w - y * im_dw)
    return sxx, syy, sxy


def opening(s, a, load, E, nu, m: Any = numpy_math):
    """Face displacement jump 4 load (1 - nu^2) / E sqrt(a^2 - s^2) at |s| <= a (Sneddon), 0
    beyond: the opening u_y(0+) - u_y(0-) for load = p, the slip u_x(0+) - u_x(0-) for
    load = q."""
    return 4.0 * load * (1.0 - nu**2) / E * m.sqrt(m.maximum(a**2 - s**2, 0.0))


def stress_intensity(load, a):
    """K = load sqrt(pi a): K_I for the face pressure, K_II for the (driving) face shear."""
    return load * (np.pi * a) ** 0.5


def penny_opening(r, a, p, E, nu, m: Any = numpy_math):
    """Opening of a penny-shaped crack of radius a under the face pressure p in an infinite
    body, 8 p (1 - nu^2) / (pi E) sqrt(a^2 - r^2) at r <= a, 0 beyond (Sneddon 1946,
    doi:10.1098/rspa.1946.0077)."""
    return 8.0 * p * (1.0 - nu**2) / (np.pi * E) * m.sqrt(m.maximum(a**2 - r**2, 0.0))


def penny_stress_intensity(p, a):
    """K_I = 2 p sqrt(a / pi) along the front of a penny-shaped crack under the face pressure p
    (Sneddon 1946)."""
    return 2.0 * p * (a / np.pi) ** 0.5


def penny_shear_slip(r, a, tau, E, nu, m: Any = numpy_math):
    """Slip of a penny-shaped crack of radius a under the uniform face shear tau in an infinite
    body, parallel to the shear: 16 (1 - nu^2) tau / (pi (2 - nu) E) sqrt(a^2 - r^2) at r <= a
    (Kassir & Sih 1966, doi:10.1115/1.3625086; Tada, Paris & Irwin 2000, The Stress Analysis of
    Cracks Handbook, doi:10.1115/1.801535). Near the front it is the plane-strain mode II jump
    of K_II = 4 tau sqrt(a / pi) cos(phi) / (2 - nu) where the front normal is along the shear
    (phi = 0), and the mode III jump of K_III = 4 (1 - nu) tau sqrt(a / pi) sin(phi) / (2 - nu)
    where it is across (phi = 90 degrees)."""
    return (
        16.0 * tau * (1.0 - nu**2) / (np.pi * (2.0 - nu) * E) * m.sqrt(m.maximum(a**2 - r**2, 0.0))
    )


def crack_plane_tractions(sigma, beta_deg, m: Any = numpy_math):
    """(sigma_n, tau) = (sigma cos^2 beta, sigma sin beta cos beta) on a crack at beta (degrees)
    to the plane normal to a uniaxial compression sigma > 0 (sigma_n > 0 in compression)."""
    beta = beta_deg * (np.pi / 180.0)
    c, s = m.cos(beta), m.sin(beta)
    return sigma * c**2, sigma * s * c


def driving_shear(tau, sigma_n, mu):
    """Shear that slides the faces: sign(tau) (|tau| - mu sigma_n) if |tau| > mu sigma_n, else 0
    (stick). Friction needs contact: an open crack (sigma_n <= 0) slides under tau itself."""
    tau = np.asarray(tau, dtype=float)
    resistance = mu * np.maximum(np.asarray(sigma_n, dtype=float), 0.0)
    return np.sign(tau) * np.maximum(np.abs(tau) - resistance, 0.0)


def inclined_crack_KII(sigma, a, beta_deg, mu):
    """K_II = sigma sqrt(pi a) cos beta (sin beta - mu cos beta) if tan beta > mu, else 0:
    a closed crack at beta (degrees, 0 <= beta <= 90) to the plane normal to a uniaxial
    compression sigma > 0."""
    sigma_n, tau = crack_plane_tractions(sigma, beta_deg)
    return stress_intensity(driving_shear(tau, sigma_n, mu), a)


def width_correction(a, W, m: Any = numpy_math):
    """K / K_inf = sqrt(sec(pi a / W)) for a central crack of length 2a in a strip of width W."""
    return (1.0 / m.cos(np.pi * a / W)) ** 0.5


def bb_closure(s_eff, Kni, Vm):
    """Barton-Bandis closure v = s' V_m / (K_ni V_m + s') at the effective stress s' >= 0."""
    return s_eff * Vm / (Kni * Vm + s_eff)


def bb_stress(v, Kni, Vm):
    """Barton-Bandis effective stress s' = K_ni v / (1 - v / V_m) at the closure 0 <= v < V_m."""
    return Kni * v / (1.0 - v / Vm)


def bb_stiffness(s_eff, Kni, Vm):
    """Barton-Bandis tangent stiffness ds'/dv = K_ni [1 - s' / (K_ni V_m + s')]^(-2)."""
    return Kni * (1.0 - s_eff / (Kni * Vm + s_eff)) ** -2


def joint_column(s_c, p, E, nu, H, w0, Kni, Vm) -> dict[str, Any]:
    """Two blocks of height H with lateral rollers around a Barton-Bandis joint (initial
    aperture w0), top compression s_c, fluid pressure p on the faces: the closure v at
    s' = s_c - p, the aperture w0 - v, the oedometric modulus M = E (1 - nu) / ((1 + nu)
    (1 - 2 nu)) and the top settlement 2 H s_c / M + v."""
    M = oedometric_modulus(E, nu)
    closure = bb_closure(s_c - p, Kni, Vm)
    return {
        "closure": closure,
        "aperture": w0 - closure,
        "settlement": 2.0 * H * s_c / M + closure,
        "M": M,
    }


def propping_pressure(h, a, b, E, nu):
    """Net pressure p* = h E' / (4 sqrt(a^2 - b^2)) at which the Sneddon opening equals the
    proppant thickness h at the proppant edges x = +-b (b < a): above it the proppant carries
    nothing."""
    return h * E / (1.0 - nu**2) / (4.0 * (a**2 - b**2) ** 0.5)


def bar_impact_exact(x, t):
    """The elastic bar against a rigid wall (Dabaghi, Petrov, Pousin and Renard,
    arXiv:1601.00778, the benchmark of GetFEM's ``demo_dynamic_contact_1D.py``): rho = E = 1,
    the bar (0, 1) fixed at x = 1, Signorini at x = 0, u(x, 0) = (1 - x) / 2, v(x, 0) = 0.
    With s = t mod 1 and k = floor(t mod 3): k = 0 (flight) u = (1 - max(x, s)) / 2; k = 1
    (contact) u = -min(s, 1 - s, x, 1 - x) / 2; k = 2 (rebound) u = min(s, 1 - x) / 2.
    Returns (u, u_x, u_t) at the points x (arrays) and time t; the contact stress is
    u_x(0, t) (-1/2 on t in [1, 2] + 3 n), the energy 1/2 int (u_t^2 + u_x^2) dx = 1/8."""
    x = np.asarray(x, dtype=float)
    tp = t % 3.0
    k = int(np.floor(tp))
    s = tp - k
    if k == 0:
        u = 0.5 * (1.0 - np.maximum(x, s))
        ux = np.where(x > s, -0.5, 0.0)
        ut = np.where(x > s, 0.0, -0.5)
    elif k == 1:
        parts = np.stack(np.broadcast_arrays(s, 1.0 - s, x, 1.0 - x))
        which = np.argmin(parts, axis=0)
        u = -0.5 * np.min(parts, axis=0)
        ux = np.choose(which, [0.0, 0.0, -0.5, 0.5])
        ut = np.choose(which, [-0.5, 0.5, 0.0, 0.0])
    else:
        first = s < 1.0 - x
        u = 0.5 * np.where(first, s, 1.0 - x)
        ux = np.where(first, 0.0, -0.5)
        ut = np.where(first, 0.5, 0.0)
    return u, ux, ut
