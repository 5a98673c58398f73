"""``contactfx bench``: error against run time over mesh refinement (see
:mod:`contactfx.validation.bench`)."""

from __future__ import annotations

import time
from pathlib import Path

from contactfx.cli.args import Parser, finish_table, int_list
from contactfx.validation.bench import CASES, expand_methods, run_bench
from contactfx.validation.report import write_bench

__all__ = ["cmd_bench"]


def _parser() -> Parser:
    p = Parser(prog="contactfx bench", description="error against run time over refinement")
    p.add_argument("case", nargs="?", default=None, help="one case (same as --scene)")
    p.add_argument(
        "--scene",
        default=None,
        help=f"comma-separated cases, or all (default hertz2d): {', '.join(CASES)}",
    )
    p.add_argument(
        "--method",
        default="nitsche,penalty,al-uzawa,al-ssn,vi",
        help="comma-separated method variants, e.g. nitsche,nitsche@-1,penalty@100",
    )
    p.add_argument("--levels", type=int, default=3, help="refinement levels (h halves)")
    p.add_argument("--degree", default="1", help="comma-separated Lagrange degrees, e.g. 1,2")
    p.add_argument("--solver", default="lu", choices=("lu", "gamg"))
    p.add_argument("--out", type=Path, default=None, help="folder for CSV, Markdown and PNGs")
    p.add_argument(
        "--linear",
        action="store_true",
        help="also time one linear-elastic solve per mesh (contact / linear ratio; "
        "obstacle scenes)",
    )
    p.add_argument(
        "--repeat",
        type=int,
        default=1,
        help="run every case this many times and keep the shortest time (times on a busy "
        "machine vary by tens of %%)",
    )
    p.add_argument(
        "--speedup",
        action="store_true",
        help="under mpirun, also run every case on rank 0 alone (parallel speed-up)",
    )
    return p


def cmd_bench(argv: list[str], petsc_options: dict, comm) -> int:
    ns = _parser().parse_args(argv)
    if ns.case is not None and ns.scene is not None:
        raise ValueError("give the case either positionally or with --scene, not both")
    spec = ns.case or ns.scene or "hertz2d"
    cases = list(CASES) if spec == "all" else [c.strip() for c in spec.split(",") if c.strip()]
    for name in cases:
        if name not in CASES:
            raise ValueError(f"unknown bench case '{name}' (known: {', '.join(CASES)}, all)")
    if ns.levels < 1:
        raise ValueError(f"--levels must be >= 1, got {ns.levels}")
    degrees = int_list(ns.degree)
    if not degrees or any(d not in (1, 2) for d in degrees):
        raise ValueError(f"--degree must list 1 and/or 2, got '{ns.degree}'")
    if ns.repeat < 1:
        raise ValueError(f"--repeat must be >= 1, got {ns.repeat}")
    variants = expand_methods(ns.method)
    started = time.perf_counter()
    rows = run_bench(
        cases,
        variants,
        degrees,
        ns.levels,
        comm,
        petsc_options,
        solver=ns.solver,
        linear=ns.linear,
        speedup=ns.speedup,
        repeat=ns.repeat,
    )
    finish_table(
        rows,
        comm,
        started,
        f"bench: {len(rows)} runs in {{total:.0f}} s on {comm.size} rank(s)",
        ns.out,
        write_bench,
    )
    return 0
