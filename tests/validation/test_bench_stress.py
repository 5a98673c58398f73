"""contactfx bench and contactfx stress: outputs well formed, every method converging on the
default cases, optimal observed rates on Westergaard full contact, failures as rows.

Run in-process, so also under ``mpirun -n 2`` (rank 0 writes; the folder is rank 0's)."""

from __future__ import annotations

import csv
import math

import pytest
from mpi4py import MPI

from contactfx.cli.bench import cmd_bench
from contactfx.cli.stress import cmd_stress
from contactfx.validation.bench import CASES, observed_rates, run_case

COMM = MPI.COMM_WORLD
PNG = b"\x89PNG\r\n\x1a\n"


@pytest.fixture
def shared_dir(tmp_path):
    return COMM.bcast(tmp_path, root=0)


def _read_csv(path):
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


@pytest.mark.parametrize("case", ["hertz2d", "westergaard-partial", "punch2d", "sliding-block"])
def test_every_method_converges_on_default_case(case):
    """Each method with the scene's default numerics on the coarsest bench mesh: converged,
    or not applicable (friction with vi) - never failed."""
    for method in ("nitsche", "penalty", "al-uzawa", "al-ssn", "vi"):
        row, _, _ = run_case(case, method, {"method": method}, 1, 0, COMM)
        assert row["status"] in ("ok", "n/a"), (case, method, row["reason"])
        if case == "sliding-block" and method == "vi":
            assert row["status"] == "n/a"
        else:
            assert row["status"] == "ok"
            assert row["newton"] > 0 and row["dofs"] > 0


def test_refusals_are_not_applicable():
    """What a problem kind refuses before any solve is n/a, not failed: methods without two-body
    contact, P2 between bodies, mortar against an obstacle."""
    for case, method, degree, words in (
        ("patch-test", "al-ssn", 1, "two meshed bodies"),
        ("patch-test", "vi", 1, "two meshed bodies"),
        ("patch-test", "nitsche", 2, "P1"),
        ("hertz2d", "mortar", 1, "mortar"),
    ):
        row, _, _ = run_case(case, method, {"method": method}, degree, 0, COMM)
        assert row["status"] == "n/a", (case, method, row)
        assert words in row["reason"], row["reason"]


def test_stress_refuses_joint_without_equilibrium(shared_dir):
    """Fluid pressure above the closure stress: the scene refuses it (status refused, not
    counted as a failure); the cases with an equilibrium converge."""
    assert cmd_stress(["--axis", "joint closure", "--out", str(shared_dir)], {}, COMM) == 0
    if COMM.rank == 0:
        rows = {r["case"]: r for r in _read_csv(shared_dir / "stress.csv")}
        refused = rows["joint s_c=3e+07 p=4e+07"]
        assert refused["status"] == "refused"
        assert "exceeds --closure-stress" in refused["reason"]
        assert all(r["status"] == "converged" for r in rows.values() if r is not refused)
        assert ", 0 not converged" in (shared_dir / "stress.md").read_text()


def test_bench_outputs_well_formed(shared_dir):
    argv = [
        "--scene",
        "hertz2d,westergaard-full",
        "--method",
        "nitsche@1,al-ssn",
        "--levels",
        "2",
        "--out",
        str(shared_dir),
    ]
    assert cmd_bench(argv, {}, COMM) == 0
    if COMM.rank == 0:
        rows = _read_csv(shared_dir / "bench.csv")
        assert len(rows) == 2 * 2 * 2  # cases x methods x levels
        for r in rows:
            assert r["status"] == "ok"
            assert int(r["dofs"]) > 0 and int(r["newton"]) > 0
            times = [float(r[k]) for k in ("t_mesh", "t_compile", "t_assembly", "t_solve")]
            assert all(t >= 0.0 for t in times)
            assert 0.0 < float(r["err_p_L2"]) < 1.0
        md = (shared_dir / "bench.md").read_text()
        assert "## hertz2d" in md and "## westergaard-full" in md and "Observed rates" in md
        for name in ("hertz2d_p_L2_time.png", "hertz2d_a_h.png", "westergaard-full_u_H1_h.png"):
            assert (shared_dir / name).read_bytes().startswith(PNG)


def test_westergaard_full_contact_rates():
    """Full contact: the exact solution is smooth, P1 must converge at O(h^2) in L2 and O(h)
    in H1. Levels 1/16 .. 1/64 (uniform); the observed rate between the two finest meshes is
    within 0.15 of optimal (the pre-asymptotic deviation measured is below 0.05)."""
    for label, overrides in (
        ("nitsche(1)", {"method": "nitsche", "theta": 1}),
        ("nitsche(-1)", {"method": "nitsche", "theta": -1}),
        ("al-ssn", {"method": "al-ssn"}),
    ):
        rows = [
            run_case("westergaard-full", label, overrides, 1, level, COMM)[0] for level in (1, 2, 3)
        ]
        assert all(r["status"] == "ok" for r in rows), label
        _, l2 = observed_rates(rows, "err_u_L2")
        _, h1 = observed_rates(rows, "err_u_H1")
        assert abs(l2 - 2.0) <= 0.15, (label, l2)
        assert abs(h1 - 1.0) <= 0.15, (label, h1)


def test_stress_quick_rows(shared_dir):
    argv = ["--quick", "--axis", "gamma0,initial penetration,parallel", "--out", str(shared_dir)]
    assert cmd_stress(argv, {}, COMM) == 0
    if COMM.rank == 0:
        rows = _read_csv(shared_dir / "stress.csv")
        assert {r["axis"] for r in rows} == {"gamma0", "initial penetration", "parallel"}
        by_case = {r["case"]: r for r in rows}
        # the standard settings converge; symmetric and skew Nitsche at gamma0 = 10 resolve
        # the penetration to below 1e-3 h (Nitsche's consistency error at this mesh)
        for theta in (1, 0, -1):
            r = by_case[f"gamma0 theta={theta} g0=10"]
            assert r["status"] == "converged"
            assert float(r["penetration_over_h"]) < 1e-3
        for r in rows:
            assert r["status"] in ("converged", "failed", "time limit", "n/a", "refused")
            if r["status"] == "converged":
                assert math.isfinite(float(r["error"])) and int(r["newton"]) >= 0
        if COMM.size == 1:  # the parallel axis launches mpirun children from a serial run
            r = by_case["2 rank(s)"]
            assert r["status"] == "converged"
            assert float(r["error"]) < 1e-8  # force on 2 ranks vs 1: solver tolerance
        assert (shared_dir / "gamma0.png").read_bytes().startswith(PNG)
        assert "## gamma0" in (shared_dir / "stress.md").read_text()


def test_stress_time_limit_is_a_row(shared_dir):
    """A case over its time limit is a row with its reason; the command still completes."""
    argv = ["--axis", "load steps", "--time-limit", "0.01", "--out", str(shared_dir)]
    assert cmd_stress(argv, {}, COMM) == 0
    if COMM.rank == 0:
        rows = _read_csv(shared_dir / "stress.csv")
        assert len(rows) == 6
        assert all(r["status"] == "time limit" for r in rows), [r["reason"] for r in rows]


def test_bench_cases_have_mesh_sizes():
    from contactfx.scenes import SCENES

    for name, case in CASES.items():
        params = SCENES[case.scene].Params(**case.params)
        assert any(f == "h" or f.startswith("h_") for f in vars(params)), name


def test_stress_dynamic_axes(shared_dir):
    """The bar against a wall in time (docs/verification.md section 18): Nitsche theta = 1
    with gamma0 = 0.1 is unstable (the open contact's term -theta / gamma sigma_n^2 makes the
    stiffness indefinite: the energy grows without bound) and stops with that reason, not
    as converged; generalised-alpha's numerical dissipation (the balance's remainder) falls
    as rho_infinity rises to 1 (none at 1 for a linear body but the contact's switching)."""
    argv = ["--axis", "dynamics: gamma0,dynamics: rho_inf", "--out", str(shared_dir)]
    assert cmd_stress(argv, {}, COMM) == 0
    if COMM.rank == 0:
        rows = {r["case"]: r for r in _read_csv(shared_dir / "stress.csv")}
        blown = rows["bar, gamma0=0.1"]
        assert blown["status"] == "failed" and "unstable" in blown["reason"], blown
        for g in (1, 10, 100, 1000):
            assert rows[f"bar, gamma0={g}"]["status"] == "converged"
        removed = [float(rows[f"bar, rho_inf={r}"]["energy_remainder"]) for r in RHOS]
        assert all(a > b for a, b in zip(removed, removed[1:], strict=False)), removed
        # rho_inf = 1 is the midpoint rule: energy-conserving for the linear bar, the rest
        # the contact's switching (measured 4e-5 of the energy at dt = 0.01)
        assert removed[-1] < 1e-3 < removed[0]
        assert "energy balance error" in (shared_dir / "stress.md").read_text()


RHOS = ("0", "0.25", "0.5", "0.75", "1")
