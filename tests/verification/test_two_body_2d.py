"""Two-body scenes in 2D (docs/verification.md section 10): the elastic flat punch on an
elastic block against the rigid flat punch, frictionless sliding of a rounded body along a
block (no tangential force, no jumps of the normal force), the pressure plot, and serial
against parallel.

Run at 1 and 2 ranks (``make test``); the serial / parallel comparison solves the same mesh on
COMM_SELF and COMM_WORLD.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from mpi4py import MPI

from contactfx.io.xdmf import read_xdmf
from contactfx.scenes import Numerics
from contactfx.scenes.two_body import HertzCylinders
from contactfx.scenes.two_body_2d import CattaneoCylinders, PunchFoundation, SlidingContact

MORTAR = Numerics(method="mortar")


@pytest.fixture(scope="module")
def stiff_punch():
    scene = PunchFoundation(PunchFoundation.Params())
    assert scene.p.E_upper >= 1e3 * scene.p.E_lower  # the default is the stiff punch
    return scene.run(MORTAR, verbose=False)


@pytest.fixture(scope="module")
def sliding():
    scene = SlidingContact(SlidingContact.Params())
    return scene, scene.run(scene.default_numerics(method="mortar"), verbose=False)


def test_punch_foundation_stiff_punch_is_the_rigid_punch(stiff_punch):
    # E_punch / E_block = 1e3: the punch is rigid to 0.1 % (its compliance is 1e-3 of the
    # block's; 1e4 changes the score by < 1e-3). The shared punch2d score (normalised pressure
    # on |x| <= 0.8 a) measures 1.3 % on the default mesh (block h = 5e-4 = a / 100 under the
    # punch, punch 6e-4): the rest of the 3 % bound is the discretisation of the edge
    # singularity near x = 0.8 a (2.4 % at h = 7e-4, 3.6 % at 1.25e-3) and the finite,
    # clamped block (punch2d itself scores 2.3 %).
    assert stiff_punch.scores["normalised_pressure_error"] < 0.03
    # frictionless: the slave nodes receive no tangential force (the solver's tolerance)
    assert stiff_punch.scores["tangential_nodal_force"] < 1e-8
    assert stiff_punch.newton_iterations <= 5


def test_punch_foundation_equal_moduli_edge_peak(stiff_punch):
    scene = PunchFoundation(PunchFoundation.Params(E_upper=1000.0))
    res = scene.run(MORTAR, verbose=False)
    # equal materials: no rigid-punch comparison; the edge peak is reported and is lower than
    # the stiff punch's (a corner of two elastic wedges is a weaker singularity than the rigid
    # corner; measured 6.2 against 9.6 mean pressures), and above the mean pressure
    assert "normalised_pressure_error" not in res.scores
    assert 1.5 < res.scores["edge_peak"] < stiff_punch.scores["edge_peak"]
    assert res.scores["tangential_nodal_force"] < 1e-8


def test_sliding_contact_frictionless(sliding):
    scene, res = sliding
    s = res.scores
    # the pair transmits no tangential nodal force: the tangential nodal forces on the slave
    # nodes, from the bulk residual, are the Newton tolerance (measured 3e-12) at every step
    assert s["tangential_nodal_force"] < 1e-8
    # Q / P of the whole pair is not round-off: the discrete pressure centroid sits off the
    # body's axis by a fraction of a slave element (the slave mesh is not symmetric about it),
    # Q / P = x_c / R. Bound: half a slave element, h_slave / (2 R) = 1.6e-3; measured 2e-5 at
    # the last step, 4e-5 at most over the steady drag (from the fourth drag step on; the
    # first three are the load program's transient, up to 1.8e-3).
    h_slave = scene.p.ratio * scene.p.h_contact
    bound = 0.5 * h_slave / scene.p.radius
    assert abs(s["Q_over_P"]) < bound
    assert s["max_abs_Q_over_P"] < bound
    assert s["P"] > 0.0
    # every step moves the body by 0.2 / 45 = 1.1 block elements, so every slave node crosses
    # a master facet boundary at every step; a coupling that jumped there would change P by a
    # node's share of the force, h / (2 a) ~ 5 %. The mortar integrals are continuous in the
    # positions: P changes only with the discretisation error along the track (measured over
    # the steady drag: largest step change 1.8e-4, spread 1.1e-3). Bounds: 5 times the
    # measured values, 50 times below a node's share.
    assert s["P_jump"] < 1e-3
    assert s["P_variation"] < 5e-3
    # many steps, each a few Newton iterations (search once per step at the prediction)
    assert len(res.steps) == 50
    assert max(step.newton for step in res.steps) <= 8


def _shared_tmp(tmp_path: Path) -> Path:
    """rank 0's tmp_path on every rank (the output folder of a parallel run)."""
    return Path(MPI.COMM_WORLD.bcast(str(tmp_path), root=0))


def test_pressure_plot_written(tmp_path):
    out = _shared_tmp(tmp_path) / "hertz"
    res = HertzCylinders(HertzCylinders.Params()).run(MORTAR, out=out, verbose=False)
    MPI.COMM_WORLD.barrier()
    plot = out / "pressure.png"
    assert res.plot == str(plot)
    assert plot.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert json.loads((out / "run.json").read_text())["plot"] == str(plot)
    forces = np.loadtxt(out / "pair_forces.csv", delimiter=",", skiprows=1, ndmin=2)
    # one step; the quarter model's vertical force is the run's force (flat contact, the
    # nodal normals are within a / R = 0.034 of vertical: cos >= 0.9994)
    assert forces.shape == (1, 3)
    assert forces[0, 2] == pytest.approx(res.force, rel=1e-3)


@pytest.mark.ranks_compare
def test_punch_foundation_serial_and_parallel_agree():
    scene = PunchFoundation(PunchFoundation.Params())
    serial = scene.run(MORTAR, comm=MPI.COMM_SELF, verbose=False)
    parallel = scene.run(MORTAR, comm=MPI.COMM_WORLD, verbose=False)
    # the same discrete problem (the search gathers the master facets of every rank), solved
    # to a relative residual of 1e-10: forces, sizes and scores agree to the solver tolerance
    for key in ("force", "contact_size", "peak_pressure"):
        assert getattr(parallel, key) == pytest.approx(getattr(serial, key), rel=1e-8), key
    assert parallel.scores["edge_peak"] == pytest.approx(serial.scores["edge_peak"], rel=1e-8)
    # the normalised pressure error is a difference of normalised pressures (about 1e-2): it
    # moves by the pressures' relative differences, so it agrees in absolute terms (measured
    # 5.6e-10 on dolfinx 0.9 at 2 ranks, a relative 4e-8 of the score)
    key = "normalised_pressure_error"
    assert parallel.scores[key] == pytest.approx(serial.scores[key], abs=1e-8)


def test_cattaneo_cylinders_stick_zone():
    """Identical cylinders pressed, then sheared at Q < mu P (mortar, Coulomb mu = 0.3): the
    stick half-width against Cattaneo-Mindlin c = a sqrt(1 - Q / (mu P))."""
    scene = CattaneoCylinders(CattaneoCylinders.Params())
    res = scene.run(scene.default_numerics(method="mortar"), verbose=False)
    ref = res.reference
    assert 0.4 < ref["Q_over_bound"] < 0.8  # partial slip, well inside (0, 1)
    f = res.friction
    assert 0.2 < f.slip_fraction < 0.8
    # the stick half-width is the measure of the stick nodes / 2: each edge is resolved to
    # about half a slave element (h_s / 2 = 1.7 % of c on the default mesh) on top of the
    # discretisation error of the tractions and of the load path (measured c / a 1.5 % below
    # Cattaneo's in 8 steps, 0.26 % in 15); 5 % as the issue asks
    assert ref["c_over_a_computed"] == pytest.approx(ref["c_over_a"], rel=0.05)
    # the normal problem is Hertz's (identical materials: no coupling with the shear)
    assert ref["a_rel_error"] < 0.02


def test_cattaneo_cylinders_gross_slip(tmp_path):
    """Sheared beyond the stick limit the whole contact slides: |q| = mu p everywhere."""
    scene = CattaneoCylinders(CattaneoCylinders.Params(shift=4e-3))
    out = _shared_tmp(tmp_path) / "cattaneo"
    res = scene.run(scene.default_numerics(method="mortar"), out=out, verbose=False)
    MPI.COMM_WORLD.barrier()
    # with friction the ParaView file has the tangential traction and the slip increment,
    # and the status distinguishes stick from slip
    body = out / "cattaneo-cylinders.xdmf"
    surface = out / "cattaneo-cylinders_surface.xdmf"
    for grid in (read_xdmf(body), read_xdmf(surface)):
        for name in ("contact_pressure", "contact_status", "tangential_traction", "slip"):
            assert name in grid["point_data"], name
    assert res.friction.slip_fraction == pytest.approx(1.0, abs=1e-12)
    # in the contact's frame: the sum of |lambda_T| is mu times the sum of lambda, to the
    # solver's tolerance (measured 2e-13)
    assert res.scores["tangential_over_bound"] == pytest.approx(1.0, abs=1e-8)
    # the x component of the force against mu P: the contact normals are tilted by the
    # shear (the bodies rotate a little), 1.1 % measured
    assert res.reference["Q_over_bound"] == pytest.approx(1.0, abs=0.02)


def _tresca_slide(method):
    scene = SlidingContact(SlidingContact.Params(h_contact=0.02, h_far=0.3, refine=0.1, slide=0.1))
    num = scene.default_numerics(method=method, friction="tresca", threshold=5.0, steps=6)
    return scene.run(num, verbose=False)


def test_sliding_contact_tresca_nitsche_against_penalty():
    """Tresca friction between two bodies with Nitsche (t = proj_{B(0, s)}(sigma_T(u) -
    gamma slip), s the threshold where closed): the rounded body dragged 0.1 over the block
    slides at the threshold everywhere it touches. Nitsche's |t_T| integral over the bound's is
    1 in the contact frame (the solver's tolerance), every closed point slips, and the
    tangential force is the penalty's (the same Tresca law, another enforcement of the
    contact: measured 6e-5 apart, the normal forces 0.8 %)."""
    nitsche, penalty = _tresca_slide("nitsche"), _tresca_slide("penalty")
    f = nitsche.quantities.friction
    assert nitsche.scores["tangential_over_bound"] == pytest.approx(1.0, rel=1e-8)
    assert f.slip_fraction == pytest.approx(1.0)
    # the global x force against s times the closed length: the contact's tangents tilt
    # off x on the rounded body (measured |Q| / bound = 1.0044)
    assert abs(f.tangential_force[0]) / f.bound == pytest.approx(1.0, abs=0.01)
    assert f.tangential_force[0] == pytest.approx(
        penalty.quantities.friction.tangential_force[0], rel=1e-3
    )
