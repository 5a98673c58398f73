"""Unit tests of the contact methods' residuals and Jacobians on tiny meshes.

1D: a P1 bar (0, 2) of two cells (h = 1, E = 3) whose end x = 2 faces HalfSpace(0) moved to
2 + G0. The displacement is set by hand at the nodes (0, U1, uL), so that the gap g = G0 - uL,
the stress of the last cell sigma = E (uL - U1) / h and h are known numbers; the residual of
Nitsche (theta = 1, 0, -1), Penalty, AugmentedLagrangianUzawa and AugmentedLagrangianSSN (min,
fb) tested with every nodal basis function is compared with the method's formula worked out by
hand, in contact (g < 0) and apart (g > 0).
2D: Nitsche with Coulomb friction on the unit square (two triangles) under a uniform strain,
sticking and slipping, tested with linear fields (for which sigma(v) is constant).
Jacobians (ufl.derivative) against central differences of the residual, in every direction.

Run at 1 and 2 ranks: entries are tested as R(phi) = b . phi (PETSc dot, global), never by
local index.
"""

from __future__ import annotations

import dolfinx.fem
import dolfinx.mesh
import numpy as np
import pytest
import ufl
from mpi4py import MPI

from contactfx import _compat
from contactfx.contact.augmented_lagrangian import AugmentedLagrangianSSN, AugmentedLagrangianUzawa
from contactfx.contact.gap import ContactSurface
from contactfx.contact.laws import Coulomb
from contactfx.contact.nitsche import Nitsche
from contactfx.contact.obstacles import HalfSpace
from contactfx.contact.penalty import Penalty
from contactfx.mechanics.elasticity import Elastic

COMM = MPI.COMM_WORLD
L, H, E = 2.0, 1.0, 3.0
NODES = np.array([0.0, 1.0, 2.0])
G0, U1 = 0.1, 0.1
STATES = {"contact": 0.15, "apart": 0.05}  # u(L): g = -0.05 / +0.05
LAM_L = 0.2  # multiplier at x = L (AL methods)
# Round-off: every value below is a few flops on O(1) numbers, assembled from one point.
TOL = 1e-13


def _tagged(mesh, dim, where, tag):
    facets = dolfinx.mesh.locate_entities_boundary(mesh, dim, where)
    return dolfinx.mesh.meshtags(mesh, dim, facets, np.full(len(facets), tag, dtype=np.int32))


def _nodal(values):
    """Piecewise linear function of x with the given values at NODES (exact in P1)."""
    return lambda x: np.interp(x[0], NODES, values)


def _hats():
    return [_nodal(np.eye(3)[i]) for i in range(3)]


def bar(method, uL):
    """(residual form, state Function): the 1D bar with displacement (0, U1, uL)."""
    mesh = _compat.create_interval(COMM, 2, L)
    ds = ufl.Measure(
        "ds", domain=mesh, subdomain_data=_tagged(mesh, 0, lambda x: np.isclose(x[0], L), 2)
    )
    mixed = method.multiplier.field
    extra = {}
    if mixed:  # (u, lambda) in [P1]^1 x P1
        state = dolfinx.fem.Function(_compat.mixed_space(mesh, 1, 1, ()))
        u, lam = ufl.split(state)
        v, mu = ufl.split(ufl.TestFunction(state.function_space))
        state.sub(0).interpolate(lambda x: _nodal([0.0, U1, uL])(x)[None, :])
        state.sub(1).interpolate(_nodal([9.0, 9.0, LAM_L]))  # only the value at x = L enters
        # a vertex facet has one point: ds is already the nodal (vertex) rule
        extra = dict(ds_nodal=ds(2), multiplier=lam, multiplier_test=mu)
    else:
        state = u = dolfinx.fem.Function(_compat.function_space(mesh, "Lagrange", 1, (1,)))
        v = ufl.TestFunction(state.function_space)
        u.interpolate(lambda x: _nodal([0.0, U1, uL])(x)[None, :])
        if isinstance(method, AugmentedLagrangianUzawa):
            lam = dolfinx.fem.Function(_compat.function_space(mesh, "Lagrange", 1))
            lam.interpolate(_nodal([9.0, 9.0, LAM_L]))
            extra = dict(multiplier=lam)
    state.x.scatter_forward()
    offset = dolfinx.fem.Constant(mesh, np.array([L + G0]))
    mat = Elastic(E, 0.0)
    h = _compat.cell_diameter(mesh)
    s = ContactSurface(
        u, v, ds(2), HalfSpace(0.0), offset, mat.sigma(u), mat.sigma(v), E, h, **extra
    )
    return method.residual(s), state


def assemble(F):
    form = dolfinx.fem.form(F)
    return _compat.assemble_vector(_compat.create_vector(form), form)


def entries(b, space, fields):
    """R(phi) = b . phi for each phi: a function of x, or a tuple of them (one per sub-space
    of a mixed space), interpolated in space."""
    out = []
    for f in fields:
        phi = dolfinx.fem.Function(space)
        for i, fi in enumerate(f) if isinstance(f, tuple) else [(None, f)]:
            (phi if i is None else phi.sub(i)).interpolate(fi)
        phi.x.scatter_forward()
        out.append(b.dot(_compat.petsc_vec(phi)))
    return np.array(out)


def hand_1d(method, uL):
    """The residual at the nodes (0, 1, 2) [and the multiplier rows], by hand.

    g = G0 - uL; last cell sigma = E (uL - U1) / h; the test function of node 2 has v(L) = 1,
    v' = 1 / h; node 1: v(L) = 0, v' = -1 / h; node 0 does not touch x = L."""
    g, sig = G0 - uL, E * (uL - U1) / H
    if isinstance(method, Nitsche):
        # gamma = gamma0 E / h; P = [-sigma - gamma g]_+; R(v) = P (v(L) - theta/gamma E v')
        # - theta/gamma sigma E v': theta/gamma E v' = +-theta/gamma0 for node 2 / node 1
        th, g0n = method.theta, method.gamma0
        P = max(-sig - g0n * E / H * g, 0.0)
        return [0.0, th * (P + sig) / g0n, P - th * (P + sig) / g0n]
    if isinstance(method, Penalty):  # kappa [-g]_+ v(L), kappa = kappa0 E / h
        return [0.0, 0.0, method.kappa0 * E / H * max(-g, 0.0)]
    r = method.r0 * E / H
    p = max(LAM_L - r * g, 0.0)
    if isinstance(method, AugmentedLagrangianUzawa):  # [lambda - r g]_+ v(L)
        return [0.0, 0.0, p]
    # SSN: u rows lambda v(L); multiplier rows C_n mu(L): lambda - p or FB(lambda, r g),
    # whose regularisation (1e-12 E)^2 shifts it by ~1e-23 here (sqrt of 0.13)
    c = LAM_L - p if method.ncp == "min" else LAM_L + r * g - np.hypot(LAM_L, r * g)
    return [0.0, 0.0, LAM_L, 0.0, 0.0, c]


METHODS = {
    "nitsche+1": Nitsche(theta=1, gamma0=4.0),
    "nitsche0": Nitsche(theta=0, gamma0=4.0),
    "nitsche-1": Nitsche(theta=-1, gamma0=4.0),
    "penalty": Penalty(kappa0=5.0),
    "al-uzawa": AugmentedLagrangianUzawa(r0=2.0),
    "al-ssn-min": AugmentedLagrangianSSN(r0=2.0, ncp="min"),
    "al-ssn-fb": AugmentedLagrangianSSN(r0=2.0, ncp="fb"),
}


@pytest.mark.parametrize("state", list(STATES))
@pytest.mark.parametrize("name", list(METHODS))
def test_residual_1d(name, state):
    method = METHODS[name]
    F, x = bar(method, STATES[state])
    b = assemble(F)
    vec = [lambda x, h=h: h(x)[None, :] for h in _hats()]  # [P1]^1 fields
    if method.multiplier.field:  # (u, lambda) rows: a hat in one component, zero in the other
        zero = lambda x: np.zeros(x.shape[1])  # noqa: E731
        fields = [(h, zero) for h in vec] + [(lambda x: zero(x)[None, :], h) for h in _hats()]
    else:
        fields = vec
    values = entries(b, x.function_space, fields)
    expected = hand_1d(method, STATES[state])
    np.testing.assert_allclose(values, expected, rtol=0.0, atol=TOL)  # TOL: round-off


def fd_check(F, x, eps=1e-6):
    """max over the unit directions e_j of |J e_j - (F(x + eps e_j) - F(x - eps e_j)) / 2 eps|
    (inf-norm), and |J|_inf (the largest row sum)."""
    a = dolfinx.fem.form(ufl.derivative(F, x, ufl.TrialFunction(x.function_space)))
    J = _compat.assemble_matrix(_compat.create_matrix(a), a)
    xv = _compat.petsc_vec(x)
    lo, hi = xv.getOwnershipRange()
    e, Je = J.createVecRight(), J.createVecLeft()
    worst = 0.0
    for j in range(xv.getSize()):
        e.zeroEntries()
        if lo <= j < hi:
            e.setValue(j, 1.0)
        e.assemble()
        J.mult(e, Je)
        diff = []
        for sign in (1.0, -1.0):
            xv.axpy(sign * eps, e)
            x.x.scatter_forward()
            diff.append(assemble(F).copy())
            xv.axpy(-sign * eps, e)
        x.x.scatter_forward()
        diff[0].axpy(-1.0, diff[1])
        diff[0].scale(1.0 / (2.0 * eps))
        diff[0].axpy(-1.0, Je)
        worst = max(worst, diff[0].norm(3))  # NORM_INFINITY
    return worst, J.norm(3)


@pytest.mark.parametrize("state", list(STATES))
@pytest.mark.parametrize("name", list(METHODS))
def test_jacobian_1d(name, state):
    F, x = bar(METHODS[name], STATES[state])
    worst, scale = fd_check(F, x)
    # The residuals are piecewise affine in the unknowns (fb: smooth) and the states lie
    # >= 0.05 away from every kink, which the 1e-6 steps (moving the kink arguments by <= 2e-5)
    # do not reach: central differences are exact up to the round-off of F (a few ulp of
    # values <= 1, ~1e-15) over 2 eps = 2e-6, i.e. ~1e-9; 1e-8 max(1, |J|) leaves a margin.
    assert worst < 1e-8 * max(1.0, scale)


# 2D: unit square (two triangles, h = CellDiameter = sqrt 2), plane strain E2, NU2; top y = 1
# faces HalfSpace(0) moved to OFFSET = (d, 1 + G2) from (0, 1 + G2) at the last step
# (u_prev = 0). u = (B y, C y): eps_xy = B / 2, eps_yy = C, so sigma_xy = mu B and
# sigma_yy = (2 mu + lambda) C; on the top g = G2 - C and the slip increment is (B - d, 0).
E2, NU2, G2, B2, C2, MU_F, GAMMA0 = 2.0, 0.25, -0.05, 0.01, -0.02, 0.5, 3.0
SLIDES = {"stick": 0.01, "slip": 0.05}  # d
# linear test fields w: (mean of w_x, w_y over the top edge, sigma_xy(w), sigma_yy(w)), e.g.
# (y, 0): eps_xy = 1/2, sigma_xy = mu; (x, 0): eps_xx = 1, sigma_yy = lambda
MU2 = E2 / (2 * (1 + NU2))
LM2 = E2 * NU2 / ((1 + NU2) * (1 - 2 * NU2))
FIELDS = {
    "(1, 0)": (lambda x: np.vstack([np.ones_like(x[0]), 0 * x[0]]), (1.0, 0.0, 0.0, 0.0)),
    "(0, 1)": (lambda x: np.vstack([0 * x[0], np.ones_like(x[0])]), (0.0, 1.0, 0.0, 0.0)),
    "(y, 0)": (lambda x: np.vstack([x[1], 0 * x[0]]), (1.0, 0.0, MU2, 0.0)),
    "(0, y)": (lambda x: np.vstack([0 * x[0], x[1]]), (0.0, 1.0, 0.0, 2 * MU2 + LM2)),
    "(x, 0)": (lambda x: np.vstack([x[0], 0 * x[0]]), (0.5, 0.0, 0.0, LM2)),
    "(0, x)": (lambda x: np.vstack([0 * x[0], x[0]]), (0.0, 0.5, MU2, 0.0)),
}


def square(method, d):
    mesh = dolfinx.mesh.create_unit_square(COMM, 1, 1)
    top = _tagged(mesh, 1, lambda x: np.isclose(x[1], 1.0), 3)
    ds = ufl.Measure("ds", domain=mesh, subdomain_data=top)
    V = _compat.function_space(mesh, "Lagrange", 1, (2,))
    u, u_prev = dolfinx.fem.Function(V), dolfinx.fem.Function(V)
    u.interpolate(lambda x: np.vstack([B2 * x[1], C2 * x[1]]))
    u.x.scatter_forward()
    offset = dolfinx.fem.Constant(mesh, np.array([d, 1.0 + G2]))
    offset_prev = dolfinx.fem.Constant(mesh, np.array([0.0, 1.0 + G2]))
    mat, v = Elastic(E2, NU2), ufl.TestFunction(V)
    h, prev = _compat.cell_diameter(mesh), dict(u_prev=u_prev, offset_prev=offset_prev)
    stress = (mat.sigma(u), mat.sigma(v))
    s = ContactSurface(
        u, v, ds(3), HalfSpace(0.0), offset, *stress, E2, h, friction=Coulomb(MU_F), **prev
    )
    return method.residual(s), u


@pytest.mark.parametrize("slide", list(SLIDES))
@pytest.mark.parametrize("theta", [1, 0, -1])
def test_nitsche_coulomb_2d(theta, slide):
    F, u = square(Nitsche(theta=theta, gamma0=GAMMA0), SLIDES[slide])
    b = assemble(F)
    values = entries(b, u.function_space, [f for f, _ in FIELDS.values()])
    # by hand: gamma = gamma0 E / h, P = [-sigma_yy - gamma g]_+, trial T = sigma_xy - gamma
    # (B - d), t = T if |T| <= mu P else mu P sign(T); constant along the top edge, so
    # R(w) = P (w_y - th/gamma s_yy(w)) - th/gamma s_yy s_yy(w) - t (w_x - th/gamma s_xy(w))
    #        - th/gamma s_xy s_xy(w)   (w_x, w_y their means over the edge of length 1)
    gamma = GAMMA0 * E2 / np.sqrt(2.0)
    s_xy, s_yy = MU2 * B2, (2 * MU2 + LM2) * C2
    P = max(-s_yy - gamma * (G2 - C2), 0.0)
    T = s_xy - gamma * (B2 - SLIDES[slide])
    t = T if abs(T) <= MU_F * P else MU_F * P * np.sign(T)
    assert (abs(T) <= MU_F * P) == (slide == "stick") and P > 0.1  # the intended regimes
    k = theta / gamma
    expected = [
        P * (wy - k * syy) - k * s_yy * syy - t * (wx - k * sxy) - k * s_xy * sxy
        for wx, wy, sxy, syy in (h for _, h in FIELDS.values())
    ]
    np.testing.assert_allclose(values, expected, rtol=0.0, atol=TOL)  # TOL: round-off


@pytest.mark.parametrize("slide", list(SLIDES))
def test_nitsche_coulomb_jacobian_2d(slide):
    # theta = -1: every term present, a nonsymmetric Jacobian
    F, u = square(Nitsche(theta=-1, gamma0=GAMMA0), SLIDES[slide])
    worst, scale = fd_check(F, u)
    # piecewise affine again (t = mu P sign(T) when slipping; the regularised |T| adds a
    # relative 1e-24 / T^2) with P, |T| - mu P >= 0.08 away from the kinks: as in 1D
    assert worst < 1e-8 * max(1.0, scale)


def testshared_option_method_options_mean_one_thing():
    """An option several methods declare (r0: al-uzawa, al-ssn, mortar; ncp: al-ssn, mortar;
    penalty: penalty, compliance) has one type, default and rule, and its help names every
    method that reads it; two methods declaring one option differently is refused."""
    import dataclasses

    from contactfx.numerics import Numerics, method_parameters, shared_option
    from contactfx.params import param

    shared = {k: [m for m, _ in v] for k, v in method_parameters().items() if len(v) > 1}
    assert shared["r0"] == ["al-uzawa", "al-ssn", "mortar"]
    assert shared["ncp"] == ["al-ssn", "mortar"]
    helps = {f.name: f.metadata["help"] for f in dataclasses.fields(Numerics)}
    for key, methods in shared.items():
        assert all(m in helps[key] for m in methods), helps[key]

    @dataclasses.dataclass(frozen=True)
    class A:
        r0: float = param(10.0, "augmentation", positive=True)

    @dataclasses.dataclass(frozen=True)
    class B:
        r0: float = param(1.0, "augmentation", positive=True)

    declared = [("a", dataclasses.fields(A)[0]), ("b", dataclasses.fields(B)[0])]
    with pytest.raises(TypeError, match="--r0: methods a and b"):
        shared_option("r0", declared)
