"""A disc dropped on a rigid plane (scene ``disc-drop``; the 2D test of Chouly, Hild and
Renard 2015, doi:10.1051/m2an/2014046; docs/verification.md section 18): radius 20, E = 50,
nu = 0.25, rho = 1, gravity 0.1, released at rest 5 above the plane. A coarse mesh (h 2 at the
bottom, 5 elsewhere) and dt = 0.2 keep the test short; the scene's default is in the docs.

1. The free fall is exact: the impact at t = sqrt(2 H / g) = 10 (the first closed step ends
   within one step after it) with the speed sqrt(2 g H) = 1 (the kinetic energy at t = 10 is
   1/2 m_h of the mesh's mass m_h = int rho dx to 1e-9: Newmark's average acceleration
   integrates a constant acceleration exactly).
2. The energy balance: kinetic + strain + the Nitsche term - the work of gravity stays within
   1 % of the kinetic energy at impact over the contact and the rebound (Nitsche theta = 1
   conserves it but for the contact status changes).
3. One rank against two: the same steps, the contact force at every step to 1e-8 relative to
   its largest value.
"""

from __future__ import annotations

import dolfinx
import numpy as np
import pytest
import ufl
from mpi4py import MPI

from contactfx.scenes.disc_drop import DiscDrop

COMM = MPI.COMM_WORLD
PARAMS = dict(h_contact=2.0, h_far=5.0)


def run(comm, t_end: float = 30.0):
    scene = DiscDrop(DiscDrop.Params(**PARAMS))
    num = scene.default_numerics(dt=0.2, t_end=t_end)
    return scene, scene.run(num, comm=comm, verbose=False)


def test_disc_drop_impact_and_energy():
    scene, res = run(COMM)
    t = np.array([s.load for s in res.steps])
    force = np.array([s.quantities.force for s in res.steps])
    energy = [s.energy for s in res.steps]
    ref = scene.impact()
    assert ref["impact_time"] == pytest.approx(10.0, rel=1e-12)
    assert ref["impact_speed"] == pytest.approx(1.0, rel=1e-12)
    first = t[np.flatnonzero(force > 0.0)[0]]
    assert ref["impact_time"] < first <= ref["impact_time"] + 0.2 + 1e-9
    # the mesh's mass (the discrete disc's area, not pi R^2)
    mesh, _ = DiscDrop(DiscDrop.Params(**PARAMS)).build_mesh(COMM)
    one = dolfinx.fem.Constant(mesh, 1.0)
    mass = COMM.allreduce(dolfinx.fem.assemble_scalar(dolfinx.fem.form(one * ufl.dx(mesh))))
    k10 = next(e["kinetic"] for e in energy if abs(e["time"] - 10.0) < 1e-9)
    assert k10 == pytest.approx(0.5 * mass * ref["impact_speed"] ** 2, rel=1e-9)
    balance = np.array([e["total"] - e["external_work"] for e in energy])
    assert np.max(np.abs(balance - balance[0])) <= 0.01 * k10
    assert np.max(force) > 0.0 and force[-1] == 0.0  # contact, then rebound into flight


@pytest.mark.skipif(COMM.size == 1, reason="compares the run on all ranks with one rank")
def test_disc_drop_one_rank_against_two():
    _, alone = run(MPI.COMM_SELF, t_end=14.0)
    _, together = run(COMM, t_end=14.0)
    f1 = np.array([s.quantities.force for s in alone.steps])
    f2 = np.array([s.quantities.force for s in together.steps])
    assert len(f1) == len(f2) == 70
    assert np.max(np.abs(f1 - f2)) <= 1e-8 * np.max(f1)


def _adaptive(comm, t_end: float = 30.0):
    scene = DiscDrop(DiscDrop.Params(**PARAMS))
    num = scene.default_numerics(dt=0.8, t_end=t_end, time_tolerance=1e-3)
    return scene.run(num, comm=comm, verbose=False)


def test_disc_drop_adaptive_step():
    """The adaptive step (--time-tolerance 1e-3, the step at most 0.8): the free fall, whose
    acceleration is constant, has no error estimate and goes at the largest step (0.8 to
    t = 9.6); the impact is found within one step after t = 10 and the steps shrink to 0.1 in
    the contact. The balance stays within 1 % of the impact's kinetic energy (measured 0.20 %:
    between the fixed steps' 0.48 % at dt 0.2 and 0.06 % at 0.05) in 213 steps where a fixed
    step of the smallest size taken needs 300."""
    res = _adaptive(COMM)
    t = np.array([s.load for s in res.steps])
    force = np.array([s.quantities.force for s in res.steps])
    sizes = np.diff(np.concatenate([[0.0], t]))
    assert np.allclose(sizes[t <= 9.6 + 1e-9], 0.8, rtol=1e-12)
    first = t[np.flatnonzero(force > 0.0)[0]]
    step = sizes[np.flatnonzero(force > 0.0)[0]]
    assert 10.0 < first <= 10.0 + step + 1e-9
    energy = [s.energy for s in res.steps]
    k10 = max(e["kinetic"] for e in energy if e["time"] <= 10.0 + 1e-9)
    balance = np.array([e["total"] - e["external_work"] for e in energy])
    assert np.max(np.abs(balance - balance[0])) <= 0.01 * k10
    assert len(t) < 30.0 / sizes.min()
    # every step is 0.8 / 2^k (the last: what is left to t_end)
    powers = np.log2(0.8 / sizes[:-1])
    assert np.allclose(powers, np.round(powers), atol=1e-9)


@pytest.mark.ranks_compare
@pytest.mark.skipif(COMM.size == 1, reason="compares the run on all ranks with one rank")
def test_disc_drop_adaptive_one_rank_against_two():
    """The estimate's norms are global: the same steps on 1 and 2 ranks, the force to 1e-8."""
    alone, together = _adaptive(MPI.COMM_SELF, 14.0), _adaptive(COMM, 14.0)
    t1 = np.array([s.load for s in alone.steps])
    t2 = np.array([s.load for s in together.steps])
    assert len(t1) == len(t2) and np.allclose(t1, t2, rtol=1e-12)
    f1 = np.array([s.quantities.force for s in alone.steps])
    f2 = np.array([s.quantities.force for s in together.steps])
    assert np.max(np.abs(f1 - f2)) <= 1e-8 * np.max(f1)


def _multiplier(comm, coupling: str = "auto", t_end: float = 30.0):
    scene = DiscDrop(DiscDrop.Params(**PARAMS))
    num = scene.default_numerics(
        dt=0.2, t_end=t_end, method="al-ssn", mass="redistributed", al_coupling=coupling
    )
    return scene.run(num, comm=comm, verbose=False)


def _balance(res) -> tuple[float, np.ndarray]:
    """The kinetic energy at the impact (t = 10) and the balance E - W_gravity per step."""
    energy = [s.energy for s in res.steps]
    k10 = next(e["kinetic"] for e in energy if abs(e["time"] - 10.0) < 1e-9)
    return k10, np.array([e["total"] - e["external_work"] for e in energy])


def test_disc_drop_multiplier_method():
    """The augmented Lagrangian's multiplier solved with the displacement (al-ssn) and the
    redistributed mass (no inertia at the contact nodes; Khenous, Laborde and Renard 2008,
    doi:10.1016/j.euromechsol.2007.12.001): the Signorini condition holds exactly at the
    nodes, and with the multiplier acting at the nodes (the lumped coupling a dynamic run
    takes) a closed contact does no work. The balance stays within 1 % of the impact's kinetic
    energy (measured 0.24 %; Nitsche theta = 1 with the same mass 0.21 %): its remainder is
    the status changes' alone. With the consistent coupling (the Gauss rule, the P1 multiplier
    paired with the open neighbours' gap rates) the balance takes up 2.5 % during the contact
    and gives most back at the release: ten times the lumped coupling's (asserted: over 4
    times). The contact closes in the step after t = 10 and opens again before t = 30
    (the multiplier vanishes to Newton's tolerance where open: closed above 1e-8 of its
    largest value)."""
    res = _multiplier(COMM)
    k10, balance = _balance(res)
    lumped = np.max(np.abs(balance - balance[0]))
    assert lumped <= 0.01 * k10
    _, consistent = _balance(_multiplier(COMM, coupling="consistent"))
    assert np.max(np.abs(consistent - consistent[0])) > 4.0 * lumped
    t = np.array([s.load for s in res.steps])
    force = np.array([s.quantities.force for s in res.steps])
    closed = t[force > 1e-8 * np.max(force)]
    assert 10.0 < closed[0] <= 10.2 + 1e-9 and closed[-1] < 30.0 - 1e-9


@pytest.mark.skipif(COMM.size == 1, reason="compares the run on all ranks with one rank")
def test_disc_drop_multiplier_method_one_rank_against_two():
    alone = _multiplier(MPI.COMM_SELF, t_end=14.0)
    together = _multiplier(COMM, t_end=14.0)
    f1 = np.array([s.quantities.force for s in alone.steps])
    f2 = np.array([s.quantities.force for s in together.steps])
    assert len(f1) == len(f2) == 70
    assert np.max(np.abs(f1 - f2)) <= 1e-8 * np.max(f1)
