"""A block launched on a rigid plane and stopped by Coulomb friction (scene ``sliding-stop``;
docs/verification.md section 18): E = 1e5, nu = 0.3, rho = 1, 1 x 0.5, g = 10, mu = 0.3,
v0 = 1, generalised-alpha with rho_inf = 0.5, dt = 0.005, Nitsche theta = 1.

1. The rigid block's closed form: it stops after v0^2 / (2 mu g) = 1/6 (the mean horizontal
   displacement at the end within 1 %: measured 0.55 %; the elastic block's vertical vibration
   modulates the normal force by some 7 % about m g) at t = v0 / (mu g) = 1/3 (the mean
   velocity below 1 % of v0 within two steps of it).
2. The energy: friction's dissipation (the sum of -int t_T . du_T ds over the steps) equals
   the kinetic energy lost, 1/2 m v0^2, within 1 % (measured 0.4 %: the scheme's own
   dissipation of the high modes is the rest of the balance), and the block never leaves the
   plane.
3. One rank against two: the mean displacement at every step to 1e-8 relative.

The same block on a meshed plinth (``sliding-stop-plinth``: two bodies, the plinth 2 x 0.5 of
the same material, fixed at its bottom): Nitsche (theta = 1) with the consistent and with the
redistributed mass, dual mortar and the penalty (10) with the redistributed mass:

4. The rigid block's stop as in 1 (measured 0.53 %, 0.57 %, 0.58 % and 0.57 % from
   v0^2 / (2 mu g), at t = 0.335 all four; the plinth's shear under mu rho g H displaces its
   top by some 1e-5 of the stop distance), and the pair's friction dissipation, summed by its
   coupling, equal to the kinetic energy lost within 1 % (measured 0.40 % to 0.44 %, as on
   the rigid plane). Nitsche and the penalty with the redistributed mass are the reversal
   guard's cases (the Gauss-point law and the pointwise one): without it Newton 2-cycled at
   the stop (t = 0.335) until the step could not be cut further.
5. One rank against two: the mean displacement at every step and the dissipation to 1e-8.
6. The initial state of two bodies (the scene's settlement of the block under its weight,
   u_y = -k (H y - y^2 / 2), k = (1 - nu^2) rho g / E, u_x = 0, the plinth at rest): the
   energy at t = 0 is the block's kinetic energy 1/2 m v0^2 (the consistent mass of a uniform
   velocity: exact) plus the strain energy of that field, 1/2 (lambda + 2 mu) k^2 H^3 L / 3
   = 2.3225e-5; its P1 interpolant on h = 0.1 stores 0.7 % less (measured 2.3057e-5), so 2 %.
"""

from __future__ import annotations

import numpy as np
import pytest
from mpi4py import MPI

from contactfx.scenes.sliding_stop import SlidingStop, SlidingStopPlinth

COMM = MPI.COMM_WORLD


def run(comm, t_end: float = 0.4):
    scene = SlidingStop(SlidingStop.Params())
    res = scene.run(scene.default_numerics(t_end=t_end), comm=comm, verbose=False)
    return scene, res


def test_sliding_block_stops_at_the_rigid_distance():
    scene, res = run(COMM)
    ref = res.reference
    assert ref["stop_distance"] == pytest.approx(1.0 / 6.0, rel=1e-12)
    assert ref["stop_distance_rel_error"] <= 0.01
    assert abs(ref["stop_time_computed"] - ref["stop_time"]) <= 2 * 0.005 + 1e-9
    e = res.energy
    kinetic_lost = 0.5 * 0.5 * 1.0**2 - res.steps[-1].energy["kinetic"]
    assert e["friction_dissipation"] == pytest.approx(kinetic_lost, rel=0.01)
    assert min(s.quantities.force for s in res.steps) > 0.0


@pytest.mark.skipif(COMM.size == 1, reason="compares the run on all ranks with one rank")
def test_sliding_stop_one_rank_against_two():
    alone, _ = run(MPI.COMM_SELF, t_end=0.2)
    together, _ = run(COMM, t_end=0.2)
    x1 = np.array([m for _, m, _ in alone.track])
    x2 = np.array([m for _, m, _ in together.track])
    assert len(x1) == len(x2) == 40
    assert np.max(np.abs(x1 - x2)) <= 1e-8 * np.max(np.abs(x1))


def run_plinth(comm, method: str, mass: str = "consistent", t_end: float = 0.4):
    scene = SlidingStopPlinth(SlidingStopPlinth.Params())
    numerics = scene.default_numerics(t_end=t_end, method=method, mass=mass)
    res = scene.run(numerics, comm=comm, verbose=False)
    return scene, res


@pytest.mark.parametrize(
    "method, mass",
    [
        ("nitsche", "consistent"),
        ("nitsche", "redistributed"),
        ("mortar", "redistributed"),
        ("penalty", "redistributed"),
    ],
)
def test_block_on_a_plinth_stops_and_its_pair_dissipates_the_kinetic_energy(method, mass):
    scene, res = run_plinth(COMM, method, mass)
    if mass == "consistent":
        p = scene.p
        k = (1.0 - p.nu**2) * p.density * p.gravity / p.E
        lame = p.E * (1.0 - p.nu) / ((1.0 + p.nu) * (1.0 - 2.0 * p.nu))  # lambda + 2 mu
        strain = 0.5 * lame * k**2 * p.height**3 / 3.0 * p.width
        kinetic = 0.5 * p.density * p.width * p.height * p.speed**2
        assert res.energy["initial_total"] - kinetic == pytest.approx(strain, rel=0.02)
    ref = res.reference
    assert ref["stop_distance_rel_error"] <= 0.01
    assert abs(ref["stop_time_computed"] - ref["stop_time"]) <= 2 * 0.005 + 1e-9
    kinetic_lost = 0.5 * 0.5 * 1.0**2 - res.steps[-1].energy["kinetic"]
    assert res.energy["friction_dissipation"] == pytest.approx(kinetic_lost, rel=0.01)


@pytest.mark.skipif(COMM.size == 1, reason="compares the run on all ranks with one rank")
def test_block_on_a_plinth_one_rank_against_two():
    alone, a = run_plinth(MPI.COMM_SELF, "nitsche", t_end=0.1)
    together, b = run_plinth(COMM, "nitsche", t_end=0.1)
    x1 = np.array([m for _, m, _ in alone.track])
    x2 = np.array([m for _, m, _ in together.track])
    assert len(x1) == len(x2) == 20
    assert np.max(np.abs(x1 - x2)) <= 1e-8 * np.max(np.abs(x1))
    d1, d2 = a.energy["friction_dissipation"], b.energy["friction_dissipation"]
    assert d1 == pytest.approx(d2, rel=1e-8)
