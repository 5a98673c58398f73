"""Axisymmetric bodies (docs/verification.md section 16): hertz-axi, the sphere of hertz3d on
a cylindrical block computed on its (r, z) section, against Hertz's 3D closed forms at the
computed force (Johnson 1985, doi:10.1017/CBO9781139171731, 4.2).

Measured (R = 1, depth 0.01, a = 0.103, Nitsche theta = 1, one load step):

    h_contact   dofs    a error          p0 error
    0.01         952    2.7 % (0.28 h)   1.55 %
    0.005       2382    0.82 % (0.17 h)  0.25 %
    0.0025      7372    0.76 % (0.31 h)  0.05 %

against hertz3d's quarter model (2403 dofs: a 4.5 %, p0 2.5 %). The contact radius is the
measure of the closed set (resolved to a fraction of h, as in 2D); the peak converges.
(The homogeneous patch tests of the weighted forms, small and finite strain:
test_finite_strain.py::test_axisymmetric_patch.)
"""

from __future__ import annotations

import dataclasses

import pytest
from mpi4py import MPI

from contactfx.scenes import Numerics
from contactfx.scenes.hertz import HertzAxi


@pytest.mark.parametrize("h, a_over_h, p0", [(0.01, 0.4, 0.025), (0.005, 0.3, 0.005)])
def test_hertz_axisymmetric(h, a_over_h, p0):
    params = dataclasses.replace(HertzAxi.Params(), h_contact=h)
    ref = HertzAxi(params).run(Numerics(), verbose=False).reference
    # the contact edge within a fraction of an element (measured 0.28 h and 0.17 h), the peak
    # pressure converging (measured 1.55 %, 0.25 %): bounds with a margin of about 1.5
    assert ref["a_error_over_h"] < a_over_h
    assert ref["p0_rel_error"] < p0


def test_penalty_and_finite_strain():
    scene = HertzAxi(HertzAxi.Params())
    nitsche = scene.run(Numerics(), verbose=False)
    penalty = scene.run(Numerics(method="penalty", penalty=100.0), verbose=False)
    # penalty 100: its compliance p / (100 E / h) ~ 4e-6 against the 1e-2 depth (measured
    # force -4.5e-4 relative to Nitsche's)
    assert penalty.force == pytest.approx(nitsche.force, rel=2e-3)
    big = dataclasses.replace(HertzAxi.Params(), profile="circle")
    lin = HertzAxi(big).run(Numerics(), verbose=False)
    nh = HertzAxi(big).run(Numerics(material="neo-hookean"), verbose=False)
    # at a / R = 0.1 the nonlinearity softens the response by a fraction of a / R (measured
    # -0.74 % force, -2.1 % peak; the 3D quarter model on its coarser mesh: -0.6 %, -1.5 %)
    assert -0.3 * 0.1 < nh.force / lin.force - 1.0 < 0.0
    assert -0.3 * 0.1 < nh.peak_pressure / lin.peak_pressure - 1.0 < 0.0


@pytest.mark.ranks_compare
def test_serial_and_parallel_agree():
    scene = HertzAxi(HertzAxi.Params())
    serial = scene.run(Numerics(), comm=MPI.COMM_SELF, verbose=False)
    parallel = scene.run(Numerics(), comm=MPI.COMM_WORLD, verbose=False)
    # same mesh, Newton to 1e-10: round-off only
    for key in ("force", "contact_size", "peak_pressure"):
        assert getattr(parallel, key) == pytest.approx(getattr(serial, key), rel=1e-8), key


@pytest.mark.parametrize(
    "numerics, message",
    [
        ({"method": "al-ssn"}, "method al-ssn with --quadrature gauss is not offered"),
        ({"quadrature": "nodal"}, "--quadrature nodal is not offered"),
    ],
)
def test_refused(numerics, message):
    with pytest.raises(ValueError, match=message):
        HertzAxi(HertzAxi.Params()).run(Numerics(**numerics), verbose=False)
