"""The shallow ironing benchmark (:mod:`contactfx.scenes.ironing`; Yang, Laursen and Meng 2005,
doi:10.1002/nme.1222; Poulios and Renard 2015, doi:10.1016/j.compstruc.2015.02.027) on the
scene's default (coarse) mesh, the die slid 3 instead of 10 to keep the test short: the
plateau window is the slide from 2 to 3, where the published curves are already within 2 % of
their plateau.

Measured (docs/verification.md section 15): the plane-strain model's vertical force on the
plateau is 19 % above the published 3.40e8 frictionless (the published curves come from a 3D
model held out of plane on one face only, and the coarse mesh is stiff), so the test asserts
the sign and a bound of that error (25 %), not the published value within its 3 % reading
error; frictionless Q / P is zero to 1e-3; with Coulomb mu = 0.3, Q / P on the plateau is
within 5 % of mu (the die's curved face tilts the normals: Q / P is not mu pointwise).
"""

from __future__ import annotations

import pytest

from contactfx.scenes.ironing import PUBLISHED_P, ShallowIroning

SHORT = {"slide": 3.0, "plateau_from": 2.0 / 3.0, "plateau_to": 1.0}


@pytest.fixture(scope="module")
def frictionless():
    scene = ShallowIroning(ShallowIroning.Params(**SHORT))
    return scene.run(scene.default_numerics(), verbose=False)


def test_ironing_frictionless_plateau(frictionless):
    s = frictionless.scores
    assert s["plateau_steps"] >= 5
    assert 0.0 < s["P_plateau_error"] < 0.25, s["P_plateau"] / PUBLISHED_P
    assert abs(s["Q_over_P"]) < 1e-3
    assert s["P_jump"] < 0.01


def test_ironing_coulomb_q_over_p():
    scene = ShallowIroning(ShallowIroning.Params(**SHORT))
    res = scene.run(scene.default_numerics(friction="coulomb", mu=0.3), verbose=False)
    s = res.scores
    assert "Q_plateau_error" in s
    assert abs(s["Q_over_P_over_mu"] - 1.0) < 0.05, s["Q_over_P"]
    assert s["Q_jump"] < 0.02
