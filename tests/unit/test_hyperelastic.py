"""The finite-strain materials (contactfx.mechanics.hyperelastic) against closed forms.

A unit square (two P1 triangles) carries the homogeneous uniaxial strain u = (l - 1) x e_1,
F = diag(l, 1, 1) (plane strain): the integral of P_11 over the unit square is P_11 itself.
Closed forms at the stretch l (J = l, I1 = l^2 + 2, I2 = 2 l^2 + 1):

    neo-Hookean    P11 = mu (l - 1/l) + lambda ln(l) / l
    Mooney-Rivlin  P11 = 4/3 c10 (l^(1/3) - l^(-5/3)) + 4/3 c01 (l^(-1/3) - l^(-7/3))
                         + kappa ln(l) / l
    SVK            P11 = l (lambda + 2 mu) (l^2 - 1) / 2

The directional derivative dP[grad v] is checked against a central difference of P in the
direction v; the mixed u-p stress at p = -K ln J against the displacement one; the small-strain
constants (E, nu) against the moduli they come from; the command-line spec parser's refusals.
"""

from __future__ import annotations

import dolfinx.fem
import dolfinx.mesh
import numpy as np
import pytest
import ufl
from mpi4py import MPI

from contactfx import _compat
from contactfx.mechanics.elasticity import Elastic
from contactfx.mechanics.hyperelastic import (
    MooneyRivlin,
    NeoHookean,
    SaintVenantKirchhoff,
    material_from_spec,
    parse_spec,
)

L = 1.3
MATERIALS = {
    "neo-hookean": NeoHookean.from_E_nu(1.0, 0.3),
    "mooney-rivlin": MooneyRivlin(0.3, 0.1, 5.0),
    "svk": SaintVenantKirchhoff.from_E_nu(1.0, 0.3),
}


def p11(name: str, m) -> float:
    if name == "neo-hookean":
        return m.mu * (L - 1 / L) + m.lmbda * np.log(L) / L
    if name == "mooney-rivlin":
        return (
            4 / 3 * m.c10 * (L ** (1 / 3) - L ** (-5 / 3))
            + 4 / 3 * m.c01 * (L ** (-1 / 3) - L ** (-7 / 3))
            + m.bulk * np.log(L) / L
        )
    return L * (m.lmbda + 2 * m.mu) * (L * L - 1) / 2


@pytest.fixture(scope="module")
def square():
    mesh = dolfinx.mesh.create_unit_square(MPI.COMM_WORLD, 1, 1)
    V = _compat.function_space(mesh, "Lagrange", 1, (2,))
    u, v = dolfinx.fem.Function(V), dolfinx.fem.Function(V)
    u.interpolate(lambda x: np.vstack([(L - 1) * x[0], 0 * x[1]]))
    v.interpolate(lambda x: np.vstack([0.1 * x[1] + 0.2 * x[0], 0.3 * x[0]]))
    return mesh, u, v


def integral(mesh, expr) -> float:
    value = dolfinx.fem.assemble_scalar(dolfinx.fem.form(expr * ufl.dx))
    return mesh.comm.allreduce(value, op=MPI.SUM)


@pytest.mark.parametrize("name", sorted(MATERIALS))
def test_uniaxial_strain_stress(square, name):
    mesh, u, _ = square
    m = MATERIALS[name]
    P = m.weak_stress(u)
    # a homogeneous F, exact in P1, integrated over the unit area: round-off only
    assert integral(mesh, P[0, 0]) == pytest.approx(p11(name, m), rel=1e-13)
    assert abs(integral(mesh, P[0, 1])) < 1e-14
    if m.K is not None:
        # the mixed stress at the pressure p = -K ln J is the displacement one
        p = dolfinx.fem.Constant(mesh, -m.K * np.log(L))
        assert integral(mesh, m.weak_stress(u, p)[0, 0]) == pytest.approx(p11(name, m), rel=1e-13)


@pytest.mark.parametrize("name", sorted(MATERIALS))
def test_stress_derivative_is_the_directional_derivative(square, name):
    mesh, u, v = square
    m = MATERIALS[name]
    exact = integral(mesh, ufl.inner(m.weak_stress_derivative(u, None, v), ufl.grad(v)))
    eps, x0 = 1e-5, u.x.array.copy()
    values = []
    for sign in (1.0, -1.0):
        u.x.array[:] = x0 + sign * eps * v.x.array
        values.append(integral(mesh, ufl.inner(m.weak_stress(u), ufl.grad(v))))
    u.x.array[:] = x0
    # central difference: error O(eps^2 |P'''|) ~ 1e-10 relative, plus round-off 1e-16 / eps
    assert exact == pytest.approx((values[0] - values[1]) / (2 * eps), rel=1e-8)


def test_small_strain_constants():
    nh = NeoHookean.from_E_nu(1000.0, 0.3)
    assert (nh.E, nh.nu) == pytest.approx((1000.0, 0.3), rel=1e-14)
    nk = NeoHookean.from_mu_kappa(2.0, 10.0)
    assert (nk.mu, nk.kappa) == pytest.approx((2.0, 10.0), rel=1e-14)
    mr = MooneyRivlin(0.3, 0.2, 5.0)
    # the small-strain shear modulus of Mooney-Rivlin is 2 (c10 + c01)
    assert mr.mu == pytest.approx(1.0, rel=1e-14)
    assert mr.kappa == pytest.approx(5.0, rel=1e-14)


def test_spec_defaults_keep_the_scene_moduli():
    base = Elastic(1000.0, 0.3)
    for spec in ("neo-hookean", "svk", "mooney-rivlin", "mooney-rivlin:c01=50"):
        m = material_from_spec(*parse_spec(spec), base)
        assert (m.E, m.nu) == pytest.approx((1000.0, 0.3), rel=1e-12), spec
    assert material_from_spec(*parse_spec("linear"), base) is base
    assert material_from_spec(*parse_spec("neo-hookean:E=5,nu=0.2"), base).E == pytest.approx(5)


@pytest.mark.parametrize(
    "spec, message",
    [
        ("rubber", "'rubber' is not one of"),
        ("neo-hookean:mu=-1", "mu must be > 0"),
        ("neo-hookean:kappa=0", "kappa must be > 0"),
        ("neo-hookean:nu=0.5", "nu must lie in"),
        ("neo-hookean:E=1,mu=1", "not both"),
        ("mooney-rivlin:c10=-1", "c10 must be >= 0"),
        ("mooney-rivlin:kappa=0", "kappa must be > 0"),
        ("svk:c10=1", "unknown parameter 'c10=1'"),
        ("svk:E=abc", "E must be a number"),
    ],
)
def test_bad_parameters_are_refused_naming_the_key(spec, message):
    with pytest.raises(ValueError, match=message):
        material_from_spec(*parse_spec(spec), Elastic(1000.0, 0.3))
