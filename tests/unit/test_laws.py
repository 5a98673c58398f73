"""Unit tests of :mod:`contactfx.contact.laws`: the pointwise contact and friction laws.

Each law is built as a UFL expression of dolfinx Constants, integrated over the unit interval
(measure 1, so the integral is the value) and compared with numpy on a table of cases that
includes the kinks: x = 0, |x| = s, s = 0, (a, b) = (0, 0) and negative values. The derivatives
at the kinks (0 for [x]_+ at 0, finite for |x| at 0) follow from ``ufl.diff``. Also the friction
law factory ``friction_law`` and the parameter checks of Tresca / Coulomb.

Run at 1 and 2 ranks (one cell: a rank may own none, the integral is summed over the ranks).
"""

from __future__ import annotations

import dolfinx.fem
import numpy as np
import pytest
import ufl
from mpi4py import MPI
from petsc4py import PETSc

from contactfx import _compat
from contactfx.contact.laws import (
    Coulomb,
    Tresca,
    active,
    ball_projection,
    fischer_burmeister,
    friction_law,
    norm,
    positive_part,
)

COMM = MPI.COMM_WORLD
MESH = _compat.create_interval(COMM, 1, 1.0)
MU, THRESHOLD = 0.3, 0.7

# Round-off: a law costs a few flops on O(1) numbers, and the integral multiplies by the
# quadrature weight and |J| = 1 (a few ulp): 1e-14 relative to max(1, |value|) is ~50 ulp.
ROUND = 1e-14
# norm and fischer_burmeister add (1e-12 scale)^2 under the square root: they differ from
# |x| and a + b - sqrt(a^2 + b^2) by at most 1e-12 scale (sqrt(q + e^2) - sqrt(q) <= e).
REG = 1e-12


def evaluate(law, shapes, cases):
    """law(*constants) evaluated for each row of cases (a tuple of arguments per row)."""
    consts = [
        dolfinx.fem.Constant(MESH, np.zeros(s) if s else PETSc.ScalarType(0.0)) for s in shapes
    ]
    expr = law(*consts)
    n = ufl.shape(expr)[0] if ufl.shape(expr) else 0
    parts = [expr[i] for i in range(n)] if n else [expr]
    forms = [dolfinx.fem.form(p * ufl.dx) for p in parts]
    out = []
    for case in cases:
        for c, value in zip(consts, case, strict=True):
            c.value = value
        out.append([COMM.allreduce(dolfinx.fem.assemble_scalar(f)) for f in forms])
    out = np.array(out)
    return out if n else out[:, 0]


def derivative(law):
    """d law / dx of a law of one argument x (through ufl.variable)."""

    def d(x):
        xv = ufl.variable(x)
        return ufl.diff(law(xv), xv)

    return d


X = [-2.5, -1e-14, 0.0, 1e-14, 0.75, 3.0]
STEP = np.array([0.0, 0.0, 0.0, 1.0, 1.0, 1.0])  # 1 where x > 0: 0 at the kink x = 0
VECTORS = [(0.0, 0.0), (3.0, -4.0), (-1e-3, 0.0), (1e-13, 0.0), (0.6, 0.8)]
# (x, s): inside, on the sphere |x| = s, outside, s = 0 (x != 0 and x = 0), x = 0, tiny s
BALL = [
    ((0.3, -0.4), 1.0),
    ((3.0, 4.0), 5.0),
    ((6.0, -8.0), 5.0),
    ((-6.0, 8.0), 0.0),
    ((0.0, 0.0), 0.0),
    ((0.0, 0.0), 2.0),
    ((-1e-3, 0.0), 1e-4),
]
AB = [(0.0, 0.0), (2.0, 0.0), (0.0, 2.0), (3.0, 4.0), (-1.0, 2.0), (2.0, -1.0), (-3.0, -4.0)]
P_CLOSED = [(-1.0, -1.0), (-1.0, 0.5), (0.0, 0.0), (0.0, 2.0), (1e-14, 1e-14), (2.0, -0.5)]


def _ball(x, s):
    x = np.asarray(x)
    r = np.linalg.norm(x)
    return x if r <= s else s * x / r


# name: (law, argument shapes, cases, numpy reference, tolerance)
TABLES = {
    "positive_part": (positive_part, [()], [(x,) for x in X], np.maximum(X, 0.0), ROUND),
    "d_positive_part": (derivative(positive_part), [()], [(x,) for x in X], STEP, ROUND),
    "active": (active, [()], [(x,) for x in X], STEP, ROUND),
    # |x| up to the regularisation 1e-12 scale (scale 1 and 2.5)
    **{
        f"norm_scale{scale}": (
            lambda x, scale=scale: norm(x, scale),
            [(2,)],
            [(x,) for x in VECTORS],
            np.linalg.norm(VECTORS, axis=1),
            REG * scale + ROUND,
        )
        for scale in (1.0, 2.5)
    },
    # d|x|/dx = x / |x|, finite (= 0) at x = 0 thanks to the regularisation; the regularised
    # derivative x / sqrt(|x|^2 + e^2) differs from x / |x| by <= e^2 / (2 |x|^2) (1e-24 here)
    "d_norm": (
        derivative(lambda x: norm(x, 1.0)),
        [(2,)],
        [(x,) for x in VECTORS if x != (1e-13, 0.0)],
        np.array([(0.0, 0.0), (0.6, -0.8), (-1.0, 0.0), (0.6, 0.8)]),
        ROUND,
    ),
    # x or s x / |x|; the regularised |x| changes s x / |x| by a relative e^2 / |x|^2 < 1e-17
    "ball_projection": (
        lambda x, s: ball_projection(x, s, 1.0),
        [(2,), ()],
        BALL,
        np.array([_ball(x, s) for x, s in BALL]),
        ROUND,
    ),
    # phi(a, b) = a + b - sqrt(a^2 + b^2) up to the regularisation 1e-12 scale
    **{
        f"fischer_burmeister_scale{scale}": (
            lambda a, b, scale=scale: fischer_burmeister(a, b, scale),
            [(), ()],
            AB,
            np.array([a + b - np.hypot(a, b) for a, b in AB]),
            REG * scale + ROUND,
        )
        for scale in (1.0, 3.0)
    },
    # Tresca: the threshold where p > 0 (bound) or where closed > 0 (bound_where), else 0
    "tresca_bound": (
        lambda p: friction_law("tresca", threshold=THRESHOLD).bound(p),
        [()],
        [(x,) for x in X],
        THRESHOLD * STEP,
        ROUND,
    ),
    "tresca_bound_where": (
        lambda p, c: friction_law("tresca", threshold=THRESHOLD).bound_where(p, c),
        [(), ()],
        P_CLOSED,
        np.array([THRESHOLD * (c > 0) for _, c in P_CLOSED]),
        ROUND,
    ),
    # Coulomb: mu [p]_+, whatever the contact indicator
    "coulomb_bound": (
        lambda p: friction_law("coulomb", mu=MU).bound(p),
        [()],
        [(x,) for x in X],
        MU * np.maximum(X, 0.0),
        ROUND,
    ),
    "coulomb_bound_where": (
        lambda p, c: friction_law("coulomb", mu=MU).bound_where(p, c),
        [(), ()],
        P_CLOSED,
        np.array([MU * max(p, 0.0) for p, _ in P_CLOSED]),
        ROUND,
    ),
}


@pytest.mark.parametrize("name", list(TABLES))
def test_law_table(name):
    law, shapes, cases, reference, tol = TABLES[name]
    values = evaluate(law, shapes, cases)
    reference = np.asarray(reference, dtype=float)
    assert values.shape == reference.shape
    # tol: see ROUND / REG above (absolute, scaled by max(1, |reference|))
    np.testing.assert_allclose(
        values, reference, rtol=0.0, atol=tol * max(1.0, abs(reference).max())
    )


@pytest.mark.parametrize("scale", [1.0, 2.5])
def test_regularisation_at_zero(scale):
    # the regularised values at the kink itself: |0| = 1e-12 scale and phi(0, 0) = -1e-12 scale
    # exactly (sqrt of (1e-12 scale)^2: a relative round-off of 1e-15)
    zero = [((0.0, 0.0),)]
    assert evaluate(lambda x: norm(x, scale), [(2,)], zero)[0] == pytest.approx(
        1e-12 * scale, rel=1e-14
    )
    fb = evaluate(lambda a, b: fischer_burmeister(a, b, scale), [(), ()], [(0.0, 0.0)])[0]
    assert fb == pytest.approx(-1e-12 * scale, rel=1e-14)


def test_friction_law_factory():
    assert friction_law("none") is None
    tresca = friction_law("tresca", mu=MU, threshold=THRESHOLD)
    assert isinstance(tresca, Tresca) and tresca.threshold == THRESHOLD and tresca.name == "tresca"
    coulomb = friction_law("coulomb", mu=MU, threshold=THRESHOLD)
    assert isinstance(coulomb, Coulomb) and coulomb.mu == MU and coulomb.name == "coulomb"
    with pytest.raises(ValueError, match="unknown friction law 'bad'"):
        friction_law("bad")


@pytest.mark.parametrize(
    "make", [lambda: Tresca(-0.1), lambda: Coulomb(-1e-3), lambda: Coulomb(float("nan"))]
)
def test_friction_parameters_checked(make):
    with pytest.raises(ValueError, match="must be >= 0"):
        make()
