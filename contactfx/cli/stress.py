"""``contactfx stress``: the robustness matrix (see :mod:`contactfx.validation.stress`)."""

from __future__ import annotations

import time
from pathlib import Path

from contactfx.cli.args import Parser, finish_table
from contactfx.validation.report import STRESS_SETTLED, write_stress
from contactfx.validation.stress import cases, run_stress

__all__ = ["cmd_stress"]


def _parser() -> Parser:
    p = Parser(prog="contactfx stress", description="robustness matrix of extreme cases")
    p.add_argument("--quick", action="store_true", help="the fast subset of the matrix")
    p.add_argument("--axis", default=None, help="comma-separated axes to run (default all)")
    p.add_argument(
        "--time-limit", type=float, default=120.0, help="wall-time limit per case [s] (default 120)"
    )
    p.add_argument("--out", type=Path, default=None, help="folder for CSV, Markdown and PNG")
    return p


def cmd_stress(argv: list[str], petsc_options: dict, comm) -> int:
    ns = _parser().parse_args(argv)
    if not ns.time_limit > 0:
        raise ValueError(f"--time-limit must be > 0, got {ns.time_limit}")
    matrix = cases()
    selected = [c for c in matrix if c.quick or not ns.quick]
    if ns.axis is not None:
        axes = [a.strip() for a in ns.axis.split(",")]
        known = sorted({c.axis for c in matrix})
        for a in axes:
            if a not in known:
                raise ValueError(f"unknown axis '{a}' (known: {', '.join(known)})")
        selected = [c for c in selected if c.axis in axes]
    started = time.perf_counter()
    rows = run_stress(selected, comm, ns.time_limit)
    failed = sum(r["status"] not in STRESS_SETTLED for r in rows)
    finish_table(
        rows,
        comm,
        started,
        f"stress: {len(rows)} cases, {failed} not converged, {{total:.0f}} s",
        ns.out,
        write_stress,
    )
    return 0
