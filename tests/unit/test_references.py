"""Unit tests of :mod:`contactfx.references`: the Westergaard crack field satisfies
equilibrium, compatibility, the face conditions, decay and the tip asymptotics; its strains
integrate to Sneddon's opening and slip; the tables of docs/verification.md sections 6 and 7.

Run at 1 and 2 ranks::

    python3 -m pytest tests/unit/test_references.py
    mpirun -n 2 python3 -m mpi4py -m pytest tests/unit/test_references.py
"""

from __future__ import annotations

import dolfinx.fem
import dolfinx.mesh
import numpy as np
import pytest
import ufl
from mpi4py import MPI

from contactfx._compat import ufl_math
from contactfx.references import (
    bb_closure,
    bb_stiffness,
    bb_stress,
    crack_perturbation_stress,
    crack_plane_tractions,
    driving_shear,
    inclined_crack_KII,
    joint_column,
    opening,
    penny_opening,
    penny_shear_slip,
    penny_stress_intensity,
    propping_pressure,
    rigid_punch_2d,
    stress_intensity,
    width_correction,
)

A = 1.3  # half-length of the crack (not 1, so that a missing factor a shows)
E, NU = 210.0, 0.3
LOADS = [(1.0, 0.0), (0.0, 1.0), (0.7, -1.3)]  # (p, q): mode I, mode II, mixed


def _stress(x, y, p, q):
    return np.array(crack_perturbation_stress(x, y, A, p, q))


def _points(n: int, seed: int):
    """n points with |x| < 3a, 0.05 a < |y| < 2a (the same on every rank), and their distance
    rho to the nearer crack tip: the length scale of the field there."""
    rng = np.random.default_rng(seed)
    x = A * rng.uniform(-3.0, 3.0, n)
    y = A * rng.uniform(0.05, 2.0, n) * rng.choice([-1.0, 1.0], n)
    rho = np.minimum(np.hypot(x - A, y), np.hypot(x + A, y))
    return x, y, rho


def _tip_scale(rho, p, q):
    """Stress scale of the tip field K / sqrt(2 pi rho), K = load sqrt(pi a): its k-th
    derivatives are O(1) multiples of this scale / rho^k."""
    return (abs(p) + abs(q)) * np.sqrt(A / rho)


@pytest.mark.parametrize("p, q", LOADS)
def test_equilibrium(p, q):
    """div sigma = 0 by central differences with the step h = 1e-4 rho. The truncation error
    h^2 / 6 d^3 sigma is C (h / rho)^2 S / rho with the tip scale S and C = O(1) (measured
    C < 3 over 2e4 points; it scales as h^2, so it is truncation); the round-off
    eps S / (h / rho) / rho is 2e-12 S / rho. Tolerance: 10 (h / rho)^2 S / rho."""
    x, y, rho = _points(20, seed=1)
    h = 1e-4 * rho
    d_dx = (_stress(x + h, y, p, q) - _stress(x - h, y, p, q)) / (2.0 * h)
    d_dy = (_stress(x, y + h, p, q) - _stress(x, y - h, p, q)) / (2.0 * h)
    tol = 10.0 * 1e-8 * _tip_scale(rho, p, q) / rho
    assert np.all(np.abs(d_dx[0] + d_dy[2]) < tol)
    assert np.all(np.abs(d_dx[2] + d_dy[1]) < tol)


@pytest.mark.parametrize("p, q", LOADS)
def test_compatibility(p, q):
    """Laplacian(sxx + syy) = 0 (the field derives from an Airy function), 5-point stencil with
    h = 1e-3 rho: truncation h^2 / 12 (d_x^4 + d_y^4) is C (h / rho)^2 S / rho^2 (measured
    C < 4), round-off 8 eps S / (h / rho)^2 / rho^2 = 2e-9 S / rho^2. Tolerance:
    10 (h / rho)^2 S / rho^2."""
    x, y, rho = _points(20, seed=2)
    h = 1e-3 * rho

    def trace(x, y):
        sxx, syy, _ = _stress(x, y, p, q)
        return sxx + syy

    laplacian = (
        trace(x + h, y) + trace(x - h, y) + trace(x, y + h) + trace(x, y - h) - 4.0 * trace(x, y)
    ) / h**2
    assert np.all(np.abs(laplacian) < 10.0 * 1e-6 * _tip_scale(rho, p, q) / rho**2)


def test_face_conditions():
    """syy = -p and sxy = -q on both faces. At |y| = 1e-12 the deviation is about
    |y Z'| <= |y| (p + q) a^2 / (a^2 - x^2)^(3/2) < 1e-9 (p + q) for |x| <= 0.99 a."""
    p, q = 2.0, 3.0
    x = A * np.linspace(-0.99, 0.99, 41)
    for y in (1e-12, -1e-12, 0.0):
        _, syy, sxy = _stress(x, y, p, q)
        np.testing.assert_allclose(syy, -p, rtol=1e-8)
        np.testing.assert_allclose(sxy, -q, rtol=1e-8)


def test_no_cut_ahead_of_the_tips():
    """On the line of the crack outside it the field is finite and continuous across y = 0
    (the branch of sqrt(z^2 - a^2) is cut on the crack only; x < -a is where atan2 jumps).
    The jump over |y| = 1e-12 is O(|y| |grad sigma|) < 1e-9 for |x| - a >= 1e-3 a."""
    x = A * np.concatenate([-1.0 - np.logspace(-3, 1, 9), 1.0 + np.logspace(-3, 1, 9)])
    above = _stress(x, 1e-12, 2.0, 3.0)
    below = _stress(x, -1e-12, 2.0, 3.0)
    assert np.all(np.isfinite(_stress(x, 0.0, 2.0, 3.0)))
    np.testing.assert_allclose(above, below, rtol=1e-8, atol=1e-9)


def test_decay():
    """Stress-free at infinity: Z ~ load a^2 / (2 z^2), so |sigma| ~ 1e-6 load at r = 1e3 a."""
    theta = np.linspace(0.0, 2.0 * np.pi, 73)
    r = 1e3 * A
    stress = _stress(r * np.cos(theta), r * np.sin(theta), 1.0, 1.0)
    assert np.max(np.abs(stress)) < 1e-5


@pytest.mark.parametrize("side", [1.0, -1.0])
def test_near_tip(side):
    """syy (mode I) and sxy (mode II) ahead of either tip times sqrt(2 pi r) tend to
    K = load sqrt(pi a). The next term of the expansion (the -load of Z) makes a relative
    error of sqrt(2 r / a) (1.4e-3 at r = 1e-6 a, too close to 1e-3): r = 1e-8 a gives 1.4e-4."""
    r = 1e-8 * A
    x = side * (A + r)
    p, q = 2.0, 3.0
    _, syy, _ = _stress(x, 0.0, p, 0.0)
    _, _, sxy = _stress(x, 0.0, 0.0, q)
    assert syy * np.sqrt(2.0 * np.pi * r) == pytest.approx(stress_intensity(p, A), rel=1e-3)
    assert sxy * np.sqrt(2.0 * np.pi * r) == pytest.approx(stress_intensity(q, A), rel=1e-3)


def _gauss(n: int, lo, hi):
    t, w = np.polynomial.legendre.leggauss(n)
    return 0.5 * (hi - lo) * t + 0.5 * (hi + lo), 0.5 * (hi - lo) * w


def _plane_strain_strain(sxx, syy):
    """(exx, eyy) in plane strain (ezz = 0)."""
    c = (1.0 + NU) / E
    return c * ((1.0 - NU) * sxx - NU * syy), c * ((1.0 - NU) * syy - NU * sxx)


def test_opening_from_the_strains():
    """u_y(x, 0+) - u_y(x, 0-) = -int eyy dy over y != 0 (u -> 0 at infinity) is Sneddon's
    opening for p and independent of q (eyy is odd in y in mode II); y = a tan(psi) maps the
    O(1/y^2) tail to a smooth integrand: 200 Gauss points give round-off accuracy."""
    p, q = 2.0, 3.0
    psi, w = _gauss(200, 0.0, 0.5 * np.pi)
    y, dy = A * np.tan(psi), A * w / np.cos(psi) ** 2
    for x in A * np.array([-0.8, -0.3, 0.0, 0.5, 0.8]):
        jump = 0.0
        for side in (1.0, -1.0):
            _, eyy = _plane_strain_strain(*_stress(x, side * y, p, q)[:2])
            jump -= np.sum(eyy * dy)
        assert jump == pytest.approx(opening(x, A, p, E, NU), rel=1e-8)


def test_slip_from_the_strains():
    """u_x(x, 0+-) = int_{-a}^{x} exx(s, 0+-) ds (exx = 0 on y = 0 beyond the tips, u -> 0 at
    infinity) so the slip is Sneddon's ellipse for q, independent of p; s = -a cos(phi)
    turns the 1 / sqrt(a^2 - s^2) face stress into a polynomial (Gauss is exact).
    The faces are evaluated at |y| = 1e-200 (atan2 then picks the face, y Z' vanishes)."""
    p, q = 2.0, 3.0
    for x in A * np.array([-0.9, -0.3, 0.0, 0.5, 0.95]):
        phi, w = _gauss(20, 0.0, np.arccos(-x / A))
        s, ds = -A * np.cos(phi), A * np.sin(phi) * w
        jump = 0.0
        for side in (1.0, -1.0):
            exx, _ = _plane_strain_strain(*_stress(s, side * 1e-200, p, q)[:2])
            jump += side * np.sum(exx * ds)
        assert jump == pytest.approx(opening(x, A, q, E, NU), rel=1e-10)


def test_inclined_crack_table():
    """docs/verification.md section 6: K_II / (sigma sqrt(pi a)), printed to 5 decimals."""
    table = {0.0: (0.43301, 0.5, 0.43301), 0.3: (0.20801, 0.35, 0.35801), 0.6: (0.0, 0.2, 0.28301)}
    sigma = 7.0
    for mu, row in table.items():
        for beta, expected in zip((30.0, 45.0, 60.0), row, strict=True):
            K = inclined_crack_KII(sigma, A, beta, mu)
            assert K / (sigma * np.sqrt(np.pi * A)) == pytest.approx(expected, abs=5e-5)


def test_crack_plane_and_friction():
    """Tractions on the crack plane (Mohr's circle of a uniaxial compression) and the stick /
    slide / open cases of the driving shear."""
    sigma_n, tau = crack_plane_tractions(10.0, 30.0)
    assert sigma_n == pytest.approx(7.5, rel=1e-14)
    assert tau == pytest.approx(2.5 * np.sqrt(3.0), rel=1e-14)
    assert crack_plane_tractions(10.0, 0.0)[1] == 0.0
    assert crack_plane_tractions(10.0, 90.0)[0] == pytest.approx(0.0, abs=1e-14)
    assert driving_shear(2.0, 10.0, 0.3) == 0.0  # stick: |tau| <= mu sigma_n
    assert driving_shear(3.0, 10.0, 0.3) == 0.0  # at the bound
    assert driving_shear(5.0, 10.0, 0.3) == pytest.approx(2.0)
    assert driving_shear(-5.0, 10.0, 0.3) == pytest.approx(-2.0)
    assert driving_shear(-5.0, -1.0, 0.3) == -5.0  # open crack: no friction
    np.testing.assert_allclose(driving_shear([5.0, -1.0], [10.0, 10.0], 0.3), [2.0, 0.0])


def test_width_correction():
    """Feddersen: sqrt(sec(pi a / W)) = 1.0062 at W / a = 20 (docs/verification.md section 6)."""
    assert width_correction(1.0, 20.0) == pytest.approx(1.0062, abs=1e-4)
    assert width_correction(A, 20.0 * A) == pytest.approx(width_correction(1.0, 20.0), rel=1e-14)


def test_penny_opening_volume_and_front():
    """Sneddon's penny crack (docs/verification.md section 13): the opening integrates to the
    crack opening volume 16 (1 - nu^2) p a^3 / (3 E) (Simpson's rule in t = sqrt(1 - r^2 / a^2),
    where the integrand is a polynomial), and near the front it is the plane-strain field
    8 K_I / E' sqrt(rho / (2 pi)) of K_I = 2 p sqrt(a / pi), to O(rho / a)."""
    a, p, E, nu = 1.7, 3e6, 20e9, 0.3
    # r dr = -a^2 t dt: V = 2 pi a^2 int_0^1 w(r(t)) t dt
    t = np.linspace(0.0, 1.0, 201)
    w = penny_opening(a * np.sqrt(1.0 - t**2), a, p, E, nu)
    f = w * t
    V = (
        2.0
        * np.pi
        * a**2
        * (t[1] - t[0])
        / 3.0
        * (f[0] + 4 * f[1:-1:2].sum() + 2 * f[2:-1:2].sum() + f[-1])
    )
    assert V == pytest.approx(16.0 * (1.0 - nu**2) * p * a**3 / (3.0 * E), rel=1e-12)
    K = penny_stress_intensity(p, a)
    Ep = E / (1.0 - nu**2)
    for rho in (1e-4 * a, 1e-6 * a):
        near = 8.0 * K / Ep * np.sqrt(rho / (2.0 * np.pi))
        # w = near sqrt(1 - rho / (2 a)): relative difference rho / (4 a)
        assert penny_opening(a - rho, a, p, E, nu) == pytest.approx(near, rel=0.3 * rho / a)
    assert penny_opening(1.01 * a, a, p, E, nu) == 0.0


def test_penny_shear_slip_and_front():
    """The circular shear crack (docs/verification.md section 13): near the front its slip is
    the plane-strain mode II jump 8 K_II / E' sqrt(rho / (2 pi)) of the handbook's
    K_II = 4 q sqrt(a / pi) / (2 - nu) where the front's normal is along the slip, and the
    mode III jump 8 (1 + nu) K_III / E sqrt(rho / (2 pi)) of K_III = (1 - nu) K_II where it is
    across: the same slip, two independent formulas, to O(rho / a)."""
    a, q, E, nu = 1.3, -2e6, 30e9, 0.2
    K_II = 4.0 * abs(q) * np.sqrt(a / np.pi) / (2.0 - nu)
    K_III = (1.0 - nu) * K_II
    for rho in (1e-4 * a, 1e-6 * a):
        slip = abs(penny_shear_slip(a - rho, a, q, E, nu))
        mode_II = 8.0 * K_II * (1.0 - nu**2) / E * np.sqrt(rho / (2.0 * np.pi))
        mode_III = 8.0 * K_III * (1.0 + nu) / E * np.sqrt(rho / (2.0 * np.pi))
        assert slip == pytest.approx(mode_II, rel=0.3 * rho / a)
        assert slip == pytest.approx(mode_III, rel=0.3 * rho / a)
    # the sign of the shear, and nothing beyond the front
    assert penny_shear_slip(0.0, a, q, E, nu) < 0.0 < penny_shear_slip(0.0, a, -q, E, nu)
    assert penny_shear_slip(1.01 * a, a, q, E, nu) == 0.0


# docs/verification.md section 7, SI units: E = 10 GPa, nu = 0.25 (M = 12 GPa), H = 1 m, w0 = 1 mm,
# K_ni = 50 GPa/m, V_m = 0.3 mm (K_ni V_m = 15 MPa). The closure v = s' V_m / (K_ni V_m + s') is
# a fraction of a mm (the printed table rounds it: 171.429 um is 2.5e-6 off 6/35 mm).
COLUMN = dict(E=10e9, nu=0.25, H=1.0, w0=1e-3, Kni=50e9, Vm=0.3e-3)
COLUMN_TABLE = [
    # s_c, p, exact closure (mm), printed closure (um), aperture (um), settlement (mm)
    (30e6, 10e6, 6 / 35, (171.429, 828.571, 5.171429)),
    (30e6, 0.0, 0.2, (200.0, 800.0, 5.2)),
    (60e6, 10e6, 3 / 13, (230.769, 769.231, 10.230769)),
]


@pytest.mark.parametrize("s_c, p, closure_mm, printed", COLUMN_TABLE)
def test_joint_column_table(s_c, p, closure_mm, printed):
    out = joint_column(s_c, p, **COLUMN)
    assert out["M"] == pytest.approx(12e9, rel=1e-14)
    v = closure_mm * 1e-3
    exact = (v, 1e-3 - v, 2.0 * s_c / 12e9 + v)  # w0 - v, 2 H s_c / M + v
    shown = (printed[0] * 1e-6, printed[1] * 1e-6, printed[2] * 1e-3)
    for key, value, table in zip(("closure", "aperture", "settlement"), exact, shown, strict=True):
        assert out[key] == pytest.approx(value, rel=1e-6)
        assert out[key] == pytest.approx(table, abs=0.5e-9)  # half a unit of the last digit


def test_barton_bandis_consistency():
    """Closure and stress are inverse; the stiffness is ds'/dv (central difference, relative
    truncation (dv / (V_m - v))^2 ~ 1e-10)."""
    Kni, Vm = COLUMN["Kni"], COLUMN["Vm"]
    s = np.array([0.0, 1e6, 20e6, 300e6])
    v = bb_closure(s, Kni, Vm)
    assert np.all((v >= 0.0) & (v < Vm))
    np.testing.assert_allclose(bb_stress(v, Kni, Vm), s, rtol=1e-12, atol=1e-6)
    dv = 1e-5 * (Vm - v)
    slope = (bb_stress(v + dv, Kni, Vm) - bb_stress(v - dv, Kni, Vm)) / (2.0 * dv)
    np.testing.assert_allclose(bb_stiffness(s, Kni, Vm), slope, rtol=1e-7)
    assert bb_stiffness(0.0, Kni, Vm) == Kni


def test_propping_pressure():
    """At p* the Sneddon opening touches the proppant (thickness h) at x = +-b."""
    h, b = 1e-3, 0.6 * A
    p_star = propping_pressure(h, A, b, E, NU)
    assert opening(b, A, p_star, E, NU) == pytest.approx(h, rel=1e-14)
    assert opening(0.0, A, p_star, E, NU) > h


def test_ufl_expression():
    """The same function builds a UFL expression: its integral over [2a, 3a] x [1, 2]
    (assembled with quadrature degree 8 on 8 x 8 x 2 triangles; the field is smooth there, the
    quadrature error is O(h^9) ~ 1e-12) equals a 40 x 40 Gauss rule of the numpy field."""
    p, q = 2.0, 3.0
    lo, hi = np.array([2.0 * A, 1.0]), np.array([3.0 * A, 2.0])
    mesh = dolfinx.mesh.create_rectangle(
        MPI.COMM_WORLD, [lo, hi], [8, 8], dolfinx.mesh.CellType.triangle
    )
    x = ufl.SpatialCoordinate(mesh)
    fields = crack_perturbation_stress(x[0], x[1], A, p, q, ufl_math)
    dx = ufl.dx(domain=mesh, metadata={"quadrature_degree": 8})
    gx, wx = _gauss(40, lo[0], hi[0])
    gy, wy = _gauss(40, lo[1], hi[1])
    X, Y = np.meshgrid(gx, gy, indexing="ij")
    weights = np.outer(wx, wy)
    for field, reference in zip(fields, _stress(X, Y, p, q), strict=True):
        local = dolfinx.fem.assemble_scalar(dolfinx.fem.form(field * dx))
        integral = mesh.comm.allreduce(local, op=MPI.SUM)
        assert integral == pytest.approx(np.sum(reference * weights), rel=1e-8)


def test_rigid_punch_2d():
    """The rigid flat punch pressure P / (pi sqrt(a^2 - x^2)) carries the force P (with
    x = a sin t the integral is P / pi * pi exactly), has its minimum P / (pi a) at the centre,
    and is nan outside the punch."""
    a, P = 0.05, 2.0
    t = np.linspace(-0.5 * np.pi, 0.5 * np.pi, 2001)[1:-1]
    x = a * np.sin(t)
    integrand = rigid_punch_2d(x, a, P) * a * np.cos(t)  # p(x) dx/dt
    assert np.allclose(integrand, P / np.pi, rtol=1e-12)
    assert rigid_punch_2d(0.0, a, P) == pytest.approx(P / (np.pi * a), rel=1e-14)
    assert np.all(np.isnan(rigid_punch_2d(np.array([-a, a, 2 * a]), a, P)))
