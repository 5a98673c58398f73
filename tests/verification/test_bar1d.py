"""1D bar with Nitsche contact: the exact discrete solution (docs/verification.md section 8)."""

import pytest

from contactfx.references import bar_nitsche_exact
from contactfx.scenes import Numerics
from contactfx.scenes.bar import Bar1D, Bar1DParams


@pytest.mark.parametrize("theta", [1, 0, -1])
def test_bar_penetration_and_multiplier_exact(theta):
    # gamma0 = 2 is the Chouly-Hild gamma0' = 0.5 of the benchmark table
    params = Bar1DParams(length=1.0, E=1.0, body_force=1.0, gap=0.3, cells=8)
    result = Bar1D(params).run(Numerics(theta=theta, gamma0=2.0), verbose=False)
    exact = bar_nitsche_exact(E=1.0, L=1.0, f=1.0, g0=0.3, n=8, theta=theta, gamma0=2.0)
    # P1 reproduces the piecewise-quadratic problem's discrete solution exactly: only
    # round-off and the Newton tolerance (1e-10 relative residual) remain.
    assert abs(result.max_penetration - exact["penetration"]) < 1e-10
    assert abs(result.force - exact["multiplier"]) < 1e-10


def test_bar_table_values():
    # the closed form itself against the numbers printed in docs/verification.md
    e1 = bar_nitsche_exact(E=1, L=1, f=1, g0=0.3, n=8, theta=1, gamma0=2.0)
    e0 = bar_nitsche_exact(E=1, L=1, f=1, g0=0.3, n=8, theta=0, gamma0=2.0)
    assert e1["penetration"] == pytest.approx(7.8125e-3, rel=1e-14)
    assert e1["multiplier"] == pytest.approx(0.2, rel=1e-14)
    assert e0["penetration"] == pytest.approx(3.90625e-3, rel=1e-14)
    assert e0["multiplier"] == pytest.approx(0.19609375, rel=1e-14)
