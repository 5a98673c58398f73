"""A neo-Hookean cylinder thrown onto a rigid floor (``demos/problems/rubber-ball-drop.toml``,
a problem file with a [dynamics] section; docs/verification.md section 18): finite strain in
time. Coarsened here (h 0.1 at the contact, dt 0.005: dt c / h = 0.5)."""

from __future__ import annotations

from pathlib import Path

import pytest
from mpi4py import MPI

from contactfx.scenes.problem_file import load_problem

FILE = Path(__file__).resolve().parents[2] / "demos" / "problems" / "rubber-ball-drop.toml"
COARSE = [
    "mesh.parameters={radius=1.0,h_contact=0.1,h_far=0.4,contact_width=1.2}",
    "dynamics.dt=0.005",
    "dynamics.t_end=0.3",
]


def _run(comm, sets=()):
    scene, num, petsc = load_problem(FILE, [*COARSE, *sets])
    return scene.run(num, comm=comm, petsc_options=petsc, verbose=False)


def test_energy_balance_closes_to_the_scheme():
    res = _run(MPI.COMM_WORLD)
    energy = res.to_json()["energy"]
    steps = [s["energy"] for s in res.to_json()["steps"]]
    largest = max(s["total"] for s in steps)
    # the impact happened (the floor is 0.05 below, the speed 1) and the ball is squeezed
    assert max(s["contact"] + s["strain"] for s in steps) > 0.1 * largest
    # Newmark's average acceleration conserves a linear body's energy exactly; with the
    # neo-Hookean stress (not linear in u) its trapezoidal rule leaves an O(dt^2) remainder:
    # measured 0.19 % of the largest energy on this mesh, 0.10 % at half the step and size
    assert energy["largest_remainder_relative"] < 0.01
    # generalised-alpha dissipates: its remainder (the energy it removed) is positive and
    # larger than Newmark's
    damped = _run(
        MPI.COMM_WORLD, ['dynamics.scheme="generalized-alpha"', "dynamics.rho_inf=0.5"]
    ).to_json()
    last = damped["steps"][-1]["energy"]["remainder"]
    assert last > 0.0
    assert last > abs(res.to_json()["steps"][-1]["energy"]["remainder"])


@pytest.mark.skipif(MPI.COMM_WORLD.size == 1, reason="compares 2 ranks with one")
def test_ranks_agree():
    a = _run(MPI.COMM_WORLD).to_json()
    b = _run(MPI.COMM_SELF).to_json()
    assert len(a["steps"]) == len(b["steps"])
    scale = max(s["energy"]["total"] for s in b["steps"])
    for sa, sb in zip(a["steps"], b["steps"], strict=True):
        # solved to snes_rtol 1e-10 per step: 1e-8 of the force's and the energy's scale
        assert sa["force"] == pytest.approx(sb["force"], rel=1e-8, abs=1e-8 * b["force"])
        for k, v in sb["energy"].items():
            assert sa["energy"][k] == pytest.approx(v, rel=1e-8, abs=1e-8 * scale), k
