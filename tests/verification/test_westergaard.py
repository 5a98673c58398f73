"""Westergaard's wavy surface (docs/verification.md section 3): partial contact half-width and the
optimal convergence rates of the smooth full-contact solution."""

import numpy as np
import pytest

from contactfx.scenes import Numerics
from contactfx.scenes.westergaard import Westergaard, WestergaardParams


def test_partial_contact_half_width():
    params = WestergaardParams(mean_pressure_ratio=0.5)
    result = Westergaard(params).run(Numerics(steps=2), verbose=False)
    ref = result.reference
    assert ref["a"] == pytest.approx(0.25, rel=1e-12)  # sin^2(pi a / lambda) = 1 / 2
    # within one element of the exact a / lambda = 0.25
    assert abs(result.contact_size - 0.25) <= params.h_contact


@pytest.mark.parametrize("theta", [1, 0, -1])
def test_full_contact_rates(theta):
    errors = {"L2": [], "H1": []}
    sizes = [1 / 8, 1 / 16, 1 / 32]
    for h in sizes:
        params = WestergaardParams(mean_pressure_ratio=1.5, h_contact=h, h_far=h)
        num = Numerics(method="nitsche", theta=theta, steps=1)
        result = Westergaard(params).run(num, verbose=False)
        for key in errors:
            errors[key].append(result.errors[f"displacement_{key}"])
    rates = {k: np.polyfit(np.log(sizes), np.log(v), 1)[0] for k, v in errors.items()}
    # P1 on a smooth solution: H1 error O(h), L2 error O(h^2); 0.15 leaves room for the
    # pre-asymptotic first mesh (8 elements per half wavelength)
    assert rates["H1"] == pytest.approx(1.0, abs=0.15)
    assert rates["L2"] == pytest.approx(2.0, abs=0.15)


def test_full_contact_augmented_lagrangian_p2():
    """al-uzawa with P2 in full contact (the bench case westergaard-full, h = 1/16 and 1/32):
    after the first Uzawa iteration of a step, Newton starts from a residual as small as the
    multiplier's change, and its relative tolerance lay below the residual's round-off floor
    at h = 1/32: it stagnated at 1e-12 until max_it, and the load steps were cut back to a
    failure at load 0.42. The inner solves now also stop at a Newton step below 1e-12 of the
    state (contactfx.solvers.uzawa)."""
    errors = {"L2": [], "H1": []}
    for h in (1 / 16, 1 / 32):
        params = WestergaardParams(mean_pressure_ratio=1.5, h_contact=h, h_far=h)
        num = Numerics(method="al-uzawa", degree=2, steps=2)
        result = Westergaard(params).run(num, verbose=False)
        assert len(result.steps) == 2  # no cut-back
        for key in errors:
            errors[key].append(result.errors[f"displacement_{key}"])
    rates = {k: np.log2(v[0] / v[1]) for k, v in errors.items()}
    # P2 on a smooth solution: H1 error O(h^2), L2 O(h^3); measured 2.06 and 2.72 (the
    # multiplier, P1 at the nodes, and the Uzawa tolerance 1e-8 leave the L2 rate short of 3
    # on these meshes); 0.4 of room
    assert rates["H1"] == pytest.approx(2.0, abs=0.4)
    assert rates["L2"] == pytest.approx(3.0, abs=0.4)
