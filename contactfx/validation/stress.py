"""``contactfx stress``: the robustness matrix of stiff and extreme cases.

Every case runs with a wall-time limit and becomes one row: converged or failed with the named
reason, Newton iterations, load cut-backs, the largest penetration (over h), the nodal
complementarity residual max |g p| (over p_max h), the error against the closed form where one
exists (which measure is named), and the wall time. A failure is a row, never a crash of the
command. Axes (see ``cases``): Nitsche gamma0 for theta = 1, 0, -1 (Chouly, Hild & Renard 2015,
doi:10.1051/m2an/2014046: theta = 1 needs gamma0 large enough, theta = -1 is stable for any
gamma0), the penalty parameter, Poisson's ratio up to 0.4999 (P1, P2, mixed u-p where
available), friction mu up to 1 and a stiff stick (1000), contact onset (zero gap, grazing,
clearance, a front crossing many element edges), the flat punch's singular edge, one huge load
step against many small ones, interference (the indenter starts inside the body), finite strain
(indentation to 0.3 R, nu to 0.4999, stiffness contrast 1e3 between two bodies, sliding over 50
elements with mu up to 1), and 1 / 2 / 3 ranks.

Outputs (``--out``): stress.csv, stress.md and gamma0.png (error and Newton iterations against
gamma0, one line per theta).
"""

from __future__ import annotations

import dataclasses
import json
import math
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from contactfx.contact.registry import method_class
from contactfx.io.process import child_env
from contactfx.results import PRIMARY, RunSummary, measure
from contactfx.validation.bench import method_label

__all__ = ["StressCase", "cases", "run_stress"]

#: the coarse Hertz 2D mesh of the matrix (a is about 4 elements wide per side at depth 1.5e-3)
_COARSE = {"h_contact": 6e-3, "h_far": 0.2}
GAMMA0S = (1e-3, 1e-2, 1e-1, 1.0, 10.0, 1e2, 1e3, 1e4)


@dataclasses.dataclass(frozen=True)
class StressCase:
    """One row of the matrix. ``ranks`` > 0 runs the case as ``mpirun -n ranks`` child
    process (the parallel axis); 0 runs it in this process on all ranks. ``refused``: the
    input has no solution, and the expected row is its one-line refusal."""

    id: str
    axis: str
    scene: str
    params: dict
    numerics: dict
    quick: bool = False
    ranks: int = 0
    refused: bool = False


def cases() -> list[StressCase]:
    """The whole matrix; ``quick`` marks the fast subset."""
    out: list[StressCase] = []
    hz = dict(_COARSE)
    for theta in (1, 0, -1):
        for g in GAMMA0S:
            out.append(
                StressCase(
                    f"gamma0 theta={theta} g0={g:g}",
                    "gamma0",
                    "hertz2d",
                    hz,
                    {"method": "nitsche", "theta": theta, "gamma0": g},
                    quick=g in (1e-3, 10.0, 1e4),
                )
            )
    for g in GAMMA0S:
        out.append(
            StressCase(
                f"gamma0 theta=1 g0={g:g} nodal",
                "gamma0, nodal quadrature",
                "hertz2d",
                hz,
                {"method": "nitsche", "theta": 1, "gamma0": g, "quadrature": "nodal"},
                quick=g == 1e4,
            )
        )
    for k in (1.0, 10.0, 1e2, 1e3, 1e4):
        num = {"method": "penalty", "penalty": k}
        out.append(
            StressCase(f"penalty {k:g}", "penalty", "hertz2d", hz, num, quick=k in (10.0, 1e4))
        )
    for nu in (0.3, 0.49, 0.4999):
        for name, extra in (
            ("P1", {"degree": 1}),
            ("P2", {"degree": 2}),
            ("P2/P1 mixed u-p", {"degree": 2, "formulation": "mixed-up"}),
        ):
            out.append(
                StressCase(
                    f"nu={nu:g} {name}",
                    "Poisson ratio",
                    "hertz2d",
                    {**hz, "nu": nu},
                    {"method": "nitsche", **extra},
                    quick=nu == 0.4999 and name != "P2",
                )
            )
    for ratio in (1.0, 1e3, 1e6, 1e-3, 1e-6):
        layer = {"layer_thickness": 0.02, "layer_E": 1000.0 / ratio}
        kind = "soft layer" if ratio > 1 else "stiff layer" if ratio < 1 else "same"
        out.append(
            StressCase(
                f"E/E_layer={ratio:g} ({kind})",
                "stiffness contrast",
                "hertz2d",
                {**hz, **layer},
                {"method": "nitsche"},
                quick=ratio == 1e6,
            )
        )
    for mu in (0.0, 0.3, 0.6, 1.0):
        for method in ({"method": "nitsche"}, {"method": "penalty"}, {"method": "al-ssn"}):
            out.append(
                StressCase(
                    f"mu={mu:g} {method['method']}",
                    "friction",
                    "sliding-block",
                    {"h": 0.1},
                    {**method, "friction": "coulomb", "mu": mu},
                    quick=mu == 1.0 and method["method"] == "nitsche",
                )
            )
    # a stick 100 times stiffer than the defaults (see test_friction.py)
    stiff = {"nitsche": "gamma0", "penalty": "penalty", "al-uzawa": "r0", "al-ssn": "r0"}
    for method, key in stiff.items():
        out.append(
            StressCase(
                f"mu=0.3 {method} {key}=1000",
                "friction",
                "sliding-block",
                {"h": 0.1},
                {"method": method, key: 1000.0, "friction": "coulomb", "mu": 0.3},
            )
        )
        # partial slip under a curved indenter (the vertex rule where a method has a choice)
        nodal = {"quadrature": "nodal"} if method_class(method).supports.nodal_quadrature else {}
        out.append(
            StressCase(
                f"hertz2d shift mu=0.3 {method} {key}=1000",
                "friction",
                "hertz2d",
                {"shift": 5e-4},
                {
                    "method": method,
                    key: 1000.0,
                    "friction": "coulomb",
                    "mu": 0.3,
                    "steps": 8,
                    **nodal,
                },
            )
        )
    onset = [
        ("zero initial gap, 1 step", {}, {"steps": 1}, True),
        ("grazing (a ~ h/2)", {"depth": 2e-5}, {"steps": 1}, True),
        ("clearance 1e-3, 4 steps", {"gap0": 1e-3}, {"steps": 4}, False),
        ("front crossing edges, 20 steps", {}, {"steps": 20}, False),
    ]
    for name, params, num, quick in onset:
        out.append(
            StressCase(
                name,
                "contact onset",
                "hertz2d",
                {**hz, **params},
                {"method": "nitsche", **num},
                quick=quick,
            )
        )
    for method in ("nitsche", "al-ssn"):
        out.append(
            StressCase(
                f"flat punch edge, {method}",
                "corners",
                "punch2d",
                {},
                {"method": method},
                quick=method == "nitsche",
            )
        )
    for method in (
        {"method": "nitsche"},
        {"method": "penalty", "penalty": 100.0},
        {"method": "al-ssn"},
    ):
        for steps in (1, 20):
            out.append(
                StressCase(
                    f"depth 1.5e-2 in {steps} step(s), {method['method']}",
                    "load steps",
                    "hertz2d",
                    {**hz, "depth": 1.5e-2},
                    {**method, "steps": steps},
                    quick=steps == 1 and method["method"] == "nitsche",
                )
            )
    for method in ("nitsche", "al-ssn"):
        out.append(
            StressCase(
                f"interference gap0=-3e-3, {method}",
                "initial penetration",
                "hertz2d",
                {**hz, "gap0": -3e-3},
                {"method": method, "steps": 4},
                quick=method == "nitsche",
            )
        )
    out += _interface_cases()
    out += _finite_strain_cases()
    out += _dynamic_cases()
    for ranks in (1, 2, 3):
        out.append(
            StressCase(
                f"{ranks} rank(s)",
                "parallel",
                "hertz2d",
                hz,
                {"method": "nitsche"},
                quick=ranks < 3,
                ranks=ranks,
            )
        )
    return out


def _finite_strain_cases() -> list[StressCase]:
    """Neo-Hookean bodies (``--material neo-hookean``): a rigid cylinder pressed ever
    deeper (to 0.3 R, where the elements at the contact's edge reach J of about 0.3), Poisson's
    ratio to 0.4999 (the P2/P1 mixed formulation), two bodies of stiffness contrast 1e3 either
    way, and a rounded body dragged over 50 elements of a block, frictionless and with mu up
    to 1 (penalty, the only method between two finite-strain bodies)."""
    out: list[StressCase] = []
    fs = {"material": "neo-hookean"}
    circle = {"profile": "circle", "h_contact": 0.01, "refine_half_width": 0.6, "h_far": 0.2}
    for depth in (0.01, 0.05, 0.1, 0.2, 0.3):
        out.append(
            StressCase(
                f"depth {depth:g} R, nitsche theta=0",
                "finite strain: indentation",
                "hertz2d",
                {**circle, "depth": depth},
                {**fs, "method": "nitsche", "theta": 0, "steps": 10},
                quick=depth == 0.1,
            )
        )
    for nu, extra in (
        (0.3, {"degree": 1}),
        (0.49, {"degree": 2, "formulation": "mixed-up"}),
        (0.4999, {"degree": 2, "formulation": "mixed-up"}),
        (0.4999, {"degree": 1}),
    ):
        name = "P2/P1 mixed u-p" if extra.get("formulation") else "P1"
        out.append(
            StressCase(
                f"nu={nu:g} {name}, depth 0.05 R",
                "finite strain: Poisson ratio",
                "hertz2d",
                {**circle, "depth": 0.05, "nu": nu},
                {**fs, "method": "nitsche", "theta": 0, "steps": 5, **extra},
            )
        )
    for ratio in (1.0, 1e3, 1e-3):
        out.append(
            StressCase(
                f"E_upper/E_lower={ratio:g}",
                "finite strain: stiffness contrast",
                "hertz-cylinders",
                {"E_upper": 1000.0 * ratio, "depth": 0.02, "h_contact": 0.01},
                {**fs, "method": "penalty", "steps": 4},
                quick=ratio == 1e3,
            )
        )
    # the soft body as the slave (the penalty kappa E / h scales with the slave's E)
    out.append(
        StressCase(
            "E_upper/E_lower=1000, slave lower",
            "finite strain: stiffness contrast",
            "hertz-cylinders",
            {"E_upper": 1e6, "depth": 0.02, "h_contact": 0.01, "slave": "lower"},
            {**fs, "method": "penalty", "steps": 4},
        )
    )
    for mu in (0.0, 0.3, 1.0):
        friction = {"friction": "coulomb", "mu": mu} if mu else {}
        out.append(
            StressCase(
                f"slide 50 elements, mu={mu:g}",
                "finite strain: sliding",
                "sliding-contact",
                {"press": 5e-3},
                {**fs, "method": "penalty", "steps": 25, **friction},
                quick=mu == 0.3,
            )
        )
    return out


def _dynamic_cases() -> list[StressCase]:
    """Implicit dynamics (``--dynamic``): the bar against a wall (contact duration 1) with
    the time step from a tenth of the contact down to a thousandth, the penalty parameter and
    Nitsche's gamma0 (theta = 1) over five decades, rho_infinity of generalised-alpha from 0
    to 1; the disc thrown onto a plane without gravity at impact speeds over three decades
    (0.01 to 10, wave speed 7). The energy balance's largest remainder is a column."""
    out: list[StressCase] = []
    axis = "dynamics: time step"
    for dt in (0.1, 0.03, 0.01, 0.003, 0.001):
        out.append(
            StressCase(f"bar, dt={dt:g}", axis, "bar-impact", {}, {"dt": dt}, quick=dt == 0.01)
        )
    for kappa in (1.0, 10.0, 100.0, 1e3, 1e4):
        out.append(
            StressCase(
                f"bar, penalty={kappa:g}",
                "dynamics: penalty",
                "bar-impact",
                {},
                {"method": "penalty", "penalty": kappa, "dt": 0.01},
                quick=kappa == 100.0,
            )
        )
    for g in (0.1, 1.0, 10.0, 100.0, 1e3):
        out.append(
            StressCase(
                f"bar, gamma0={g:g}",
                "dynamics: gamma0",
                "bar-impact",
                {},
                {"method": "nitsche", "theta": 1, "gamma0": g, "dt": 0.01},
            )
        )
    for rho in (0.0, 0.25, 0.5, 0.75, 1.0):
        out.append(
            StressCase(
                f"bar, rho_inf={rho:g}",
                "dynamics: rho_inf",
                "bar-impact",
                {},
                {"scheme": "generalized-alpha", "rho_inf": rho, "dt": 0.01},
                quick=rho == 0.5,
            )
        )
    disc = {"h_contact": 2.0, "h_far": 6.0, "gravity": 0.0, "drop": 0.1}
    for speed in (0.01, 0.1, 1.0, 10.0):
        out.append(
            StressCase(
                f"disc, speed {speed:g}",
                "dynamics: impact speed",
                "disc-drop",
                {**disc, "speed": speed},
                {"dt": 0.1, "t_end": 40.0},
                quick=speed == 1.0,
            )
        )
    return out


def _interface_cases() -> list[StressCase]:
    """Crack friction, proppant and joint closure at their extremes."""
    out: list[StressCase] = []
    crack = {"h_crack": 0.05, "h_tip": 0.005, "h_far": 1.0, "grading": 0.3}
    for mu in (0.0, 0.3, 0.6, 1.0):
        for method in ("nitsche", "al-ssn"):
            out.append(
                StressCase(
                    f"crack beta=45 mu={mu:g}, {method}",
                    "crack friction",
                    "crack-inclined",
                    crack,
                    {"method": method, "mu": mu},
                    quick=mu == 0.3 and method == "nitsche",
                )
            )
    for beta in (5.0, 85.0):  # nearly normal and nearly parallel to the compression
        out.append(
            StressCase(
                f"crack beta={beta:g} mu=0.3",
                "crack friction",
                "crack-inclined",
                {**crack, "beta": beta},
                {"method": "nitsche"},
            )
        )
    for p_net in (6e5, 3e5, -1e6, -20e6):  # p* = 3.08e5: open, barely propped, closing
        for method in ("nitsche", "al-ssn"):
            out.append(
                StressCase(
                    f"proppant p_net={p_net:g}, {method}",
                    "proppant",
                    "propped-fracture",
                    {**crack, "net_pressure": p_net},
                    {"method": method},
                    quick=p_net == -1e6 and method == "nitsche",
                )
            )
    # an unfitted crack's position against the nodes of the structured plate (h = a / 20
    # around the crack): along the edges, 1e-6 h off them, between them, through the nodes
    # diagonally; and the unfitted crack on the graded mesh at a shallow angle
    grid = {"crack": "unfitted", "background": "structured", "h_crack": 0.05, "h_tip": 0.05}
    for name, scene, params in (
        ("along edges", "crack-sneddon", {}),
        ("1e-6 h off the nodes", "crack-sneddon", {"crack_offset": 5e-8}),
        ("0.4 h off the nodes", "crack-sneddon", {"crack_offset": 0.02}),
        ("through nodes, beta=-45 mu=0", "crack-inclined", {"beta": -45.0}),
        ("along diagonal edges, beta=45 mu=0", "crack-inclined", {"beta": 45.0}),
    ):
        numerics = {"method": "nitsche", **({"mu": 0.0} if scene == "crack-inclined" else {})}
        out.append(
            StressCase(
                f"unfitted crack {name}",
                "unfitted crack position",
                scene,
                {**grid, **params},
                numerics,
                quick=name == "1e-6 h off the nodes",
            )
        )
    out.append(
        StressCase(
            "unfitted crack beta=10 mu=0.3 (graded)",
            "unfitted crack position",
            "crack-inclined",
            {**crack, "beta": 10.0, "crack": "unfitted"},
            {"method": "nitsche"},
        )
    )
    # the 3D cracks on the coarse penny mesh (h_front = a / 5, P2): closing under suction,
    # sliding without friction, sticking (penny-shear at mu 1.2 > tan 45; the fault at dip 80,
    # where abs(tau) = 2.05 MPa < 0.3 sigma_n = 2.51 MPa), a fault held by 0.5 MPa of
    # effective normal stress (overpressure 10.5 of sigma_n = 11 MPa)
    penny = {"h_front": 0.2, "h_crack": 0.4}
    for name, scene, params, numerics in (
        ("penny-crack suction", "penny-crack", {"pressure": -1e6}, {}),
        ("penny-shear mu=0", "penny-shear", {}, {"friction": "none", "mu": 0.0}),
        ("penny-shear mu=1.2 (stick)", "penny-shear", {}, {"mu": 1.2}),
        ("fault-block dip=80 (stick)", "fault-block", {"dip": 80.0}, {}),
        ("fault-block overpressure=10.5e6", "fault-block", {"overpressure": 10.5e6}, {}),
    ):
        out.append(
            StressCase(
                name, "3D crack", scene, {**penny, **params}, {"method": "nitsche", **numerics}
            )
        )
    for s_c, p in ((30e6, 10e6), (3e9, 0.0), (30e6, 29.9e6), (30e6, 40e6)):
        # the last: fluid pressure above the load, no equilibrium (refused)
        out.append(
            StressCase(
                f"joint s_c={s_c:g} p={p:g}",
                "joint closure",
                "joint-column",
                {"closure_stress": s_c, "fluid_pressure": p},
                {"method": "nitsche"},
                quick=s_c == 3e9,
                refused=p > s_c,
            )
        )
    return out


def _scene(name: str):
    from contactfx.scenes import SCENES

    return SCENES[name]


def _primary_error(res) -> tuple[str, float]:
    """The case's error against the closed form: the first of :data:`contactfx.results.PRIMARY`
    the run has."""
    for name, column in PRIMARY:
        value = measure(res, column)
        if not math.isnan(value):
            return name, value
    return "", float("nan")


def _row(case: StressCase, res: RunSummary | None, error: str, wall: float) -> dict:
    row = {"axis": case.axis, "case": case.id, "method": method_label(case.numerics)}
    if res is None:
        status = "time limit" if "time limit" in error else "failed"
        return {**row, "status": status, "reason": error, "time": wall}
    name, value = _primary_error(res)
    h = res.h_contact
    p0 = max(res.peak_pressure, 1e-300)
    row.update(
        status="converged",
        reason="",
        newton=res.newton_iterations,
        cutbacks=res.cutbacks,
        penetration_over_h=abs(res.max_penetration) / h,
        complementarity=res.complementarity / (p0 * h),
        error_measure=name,
        error=value,
        p0_error=measure(res, "err_p0"),
        force=res.force,
        # a dynamic run's energy balance: its largest remainder over the largest energy
        energy_remainder=(res.energy or {}).get("largest_remainder_relative", math.nan),
        time=wall,
    )
    return row


def run_in_process(case: StressCase, comm, limit: float) -> dict:
    from contactfx.solvers.snes import ConvergenceError

    scene_cls = _scene(case.scene)
    t0 = time.perf_counter()
    try:
        scene = scene_cls(scene_cls.Params(**case.params))
        num = scene_cls.default_numerics(**case.numerics)
        res = scene.run(num, comm=comm, verbose=False, time_limit=limit)
    except ValueError as err:
        row = _row(case, None, str(err), time.perf_counter() - t0)
        return {**row, "status": "refused"} if case.refused else row
    except ConvergenceError as err:
        return _row(case, None, str(err), time.perf_counter() - t0)
    if case.refused:
        return _row(case, None, "solved an input that has no solution", time.perf_counter() - t0)
    return _row(case, res, "", time.perf_counter() - t0)


def run_child(case: StressCase, limit: float) -> dict:
    """``mpirun -n ranks contactfx run ...`` with a timeout; the row from its run.json."""
    args = [f"--{k.replace('_', '-')}={v}" for k, v in {**case.params, **case.numerics}.items()]
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="contactfx-stress-") as tmp:
        cmd = [
            "mpirun",
            "-n",
            str(case.ranks),
            sys.executable,
            "-m",
            "contactfx",
            "run",
            case.scene,
            *args,
            "--quiet",
            "--out",
            tmp,
        ]
        try:
            proc = subprocess.run(
                cmd, capture_output=True, text=True, timeout=limit, env=child_env()
            )
        except subprocess.TimeoutExpired:
            return _row(case, None, "time limit exceeded", time.perf_counter() - t0)
        except OSError as err:
            return _row(case, None, f"cannot launch mpirun: {err}", time.perf_counter() - t0)
        wall = time.perf_counter() - t0
        lines = (proc.stderr.strip() or proc.stdout.strip() or "no output").splitlines()
        if proc.returncode != 0:
            return _row(case, None, lines[-1], wall)
        res = RunSummary.from_json(json.loads((Path(tmp) / "run.json").read_text()))
    return _row(case, res, "", wall)


def run_stress(selected: list[StressCase], comm, limit: float) -> list[dict]:
    """Run the cases (printing each row on rank 0); the parallel axis compares its forces
    with its 1-rank run."""
    rows: list[dict] = []
    reference_force = None
    for case in selected:
        if case.ranks == 0:
            row = run_in_process(case, comm, limit)
        elif comm.size > 1:
            row = _row(case, None, "", 0.0)
            row.update(status="n/a", reason="child mpirun runs only from a serial stress run")
        else:
            row = run_child(case, limit)
        if case.axis == "parallel" and row["status"] == "converged":
            if case.ranks == 1:
                reference_force = row["force"]
            if reference_force is not None:
                row["error_measure"] = "force vs 1 rank"
                row["error"] = abs(row["force"] - reference_force) / reference_force
        rows.append(row)
        if comm.rank == 0:
            print(_format(row), flush=True)
    return rows


def _format(row: dict) -> str:
    head = f"{row['axis']:>19s} | {row['case']:<38s}"
    if row["status"] != "converged":
        return f"{head} {row['status'].upper()}: {row['reason']}"
    err = f"{row['error_measure']} {row['error']:.2e}" if np.isfinite(row["error"]) else ""
    if np.isfinite(row.get("energy_remainder", np.nan)):
        err += f" energy {row['energy_remainder']:.1e}"
    return (
        f"{head} newton {row['newton']:3d} cutbacks {row['cutbacks']} pen/h "
        f"{row['penetration_over_h']:.1e} |gp|/(p0 h) {row['complementarity']:.1e} {err} "
        f"{row['time']:.1f} s"
    )
