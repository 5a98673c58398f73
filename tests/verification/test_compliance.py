"""Normal compliance p = kappa0 E ([-g]_+ / h)^m (method ``compliance``, a method added by one
module and one registry line): the 1D bar against a wall in closed form, and m = 1 equal to
the penalty method.

Bar (0, L), E A = E, u(0) = 0, body force f, wall at x = L + g0. With the wall's pressure p at
x = L the bar end moves by u(L) = f L^2 / (2 E) - p L / E, and the law closes the system:
p = k d^m with the penetration d = u(L) - g0 and k = kappa0 E / h^m. On P1 elements the
nodal values of this 1D problem are exact (the discrete Green's function is the exact one), so
the computed penetration and force equal the root of the scalar equation to solver tolerance.
"""

import pytest

from contactfx.scenes.bar import Bar1D, Bar1DParams
from contactfx.scenes.hertz import Hertz2D, Hertz2DParams

BAR = Bar1DParams()  # L = 1, E = 1, f = 1, g0 = 0.3, 8 cells: u(L) = 0.5 without the wall


def _bar_root(kappa0: float, m: float) -> tuple[float, float]:
    """(penetration d, pressure p) of the bar, by bisection on
    d + k d^m L / E - (f L^2 / (2 E) - g0) = 0 (increasing in d)."""
    L, E, f, g0 = BAR.length, BAR.E, BAR.body_force, BAR.gap
    k = kappa0 * E / (L / BAR.cells) ** m
    free = f * L**2 / (2 * E) - g0

    def residual(d):
        return d + k * d**m * L / E - free

    lo, hi = 0.0, free
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if residual(mid) < 0.0 else (lo, mid)
    d = 0.5 * (lo + hi)
    return d, k * d**m


@pytest.mark.parametrize("m", [1.0, 1.5, 2.0])
@pytest.mark.parametrize("kappa0", [1.0, 10.0])
def test_bar_compliance_closed_form(kappa0, m):
    scene = Bar1D(BAR)
    res = scene.run(
        scene.default_numerics(method="compliance", penalty=kappa0, exponent=m), verbose=False
    )
    d, p = _bar_root(kappa0, m)
    # nodally exact discretisation, Newton to rtol 1e-10: the root to 1e-9 (relative)
    assert res.max_penetration == pytest.approx(d, rel=1e-9)
    assert res.force == pytest.approx(p, rel=1e-9)


def test_linear_compliance_is_the_penalty_method():
    scene = Hertz2D(Hertz2DParams(h_contact=0.01, h_far=0.2))
    num = scene.default_numerics
    penalty = scene.run(num(method="penalty", penalty=10.0), verbose=False)
    linear = scene.run(num(method="compliance", penalty=10.0, exponent=1.0), verbose=False)
    # the same residual for m = 1 (p = kappa0 E [-g]_+ / h): the same discrete solution, to
    # the Newton tolerance (rtol 1e-10)
    assert linear.force == pytest.approx(penalty.force, rel=1e-9)
    assert linear.max_penetration == pytest.approx(penalty.max_penetration, rel=1e-8)
