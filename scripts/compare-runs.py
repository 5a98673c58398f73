#!/usr/bin/env python3
"""Behaviour check for refactors: run a broad set of cases and compare their run.json numbers.

    .venv/bin/python scripts/compare-runs.py run OUT [--np 1,2] [--only SUBSTR]
    .venv/bin/python scripts/compare-runs.py compare BEFORE AFTER [--rtol R --atol A] [--only S]

``run`` solves every case below (each method; the obstacle, fitted interface, unfitted crack,
two-body and problem-file kinds; friction; mixed u-p; nodal quadrature; nested; GAMG; 1D, 2D,
3D) at each rank count into OUT/<case>-np<k>/. ``compare`` reads every run.json present in
both folders and compares each number of it (timings, memory, versions and paths left out):
bit-identical by default, or within ``--rtol`` of the larger magnitude plus ``--atol``. It
prints every number that differs and the counts, and exits 1 if any differs or a case is
missing. (MUMPS's parallel factorisation is not reproducible to the last bit from run to run:
two runs of the same code at 2 ranks differ by round-off, so compare those with a tolerance
and against a second run of the same code.)
"""

from __future__ import annotations

import argparse
import json
import math
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
CONTACTFX = [str(ROOT / ".venv" / "bin" / "contactfx")]

#: (name, command-line arguments after ``contactfx``): small meshes, a few seconds each
CASES: list[tuple[str, list[str]]] = [
    ("hertz2d-nitsche1", ["run", "hertz2d", "--h-contact", "6e-3"]),
    ("hertz2d-nitsche0", ["run", "hertz2d", "--h-contact", "6e-3", "--theta", "0"]),
    (
        "hertz2d-nitsche-1-p2",
        ["run", "hertz2d", "--h-contact", "6e-3", "--theta", "-1", "--degree", "2"],
    ),
    ("hertz2d-nodal", ["run", "hertz2d", "--h-contact", "6e-3", "--quadrature", "nodal"]),
    ("hertz2d-penalty", ["run", "hertz2d", "--h-contact", "6e-3", "--method", "penalty"]),
    (
        "hertz2d-compliance",
        ["run", "hertz2d", "--h-contact", "6e-3", "--method", "compliance", "--exponent", "1.5"],
    ),
    ("hertz2d-al-uzawa", ["run", "hertz2d", "--h-contact", "6e-3", "--method", "al-uzawa"]),
    ("hertz2d-al-ssn", ["run", "hertz2d", "--h-contact", "6e-3", "--method", "al-ssn"]),
    (
        "hertz2d-al-ssn-fb",
        ["run", "hertz2d", "--h-contact", "6e-3", "--method", "al-ssn", "--ncp", "fb"],
    ),
    ("hertz2d-vi", ["run", "hertz2d", "--h-contact", "6e-3", "--method", "vi"]),
    (
        "hertz2d-mixed-up",
        [
            "run",
            "hertz2d",
            "--h-contact",
            "6e-3",
            "--nu",
            "0.4999",
            "--degree",
            "2",
            "--formulation",
            "mixed-up",
        ],
    ),
    (
        "hertz2d-coulomb-shift",
        [
            "run",
            "hertz2d",
            "--h-contact",
            "6e-3",
            "--friction",
            "coulomb",
            "--mu",
            "0.3",
            "--shift",
            "5e-4",
            "--theta",
            "-1",
            "--gamma0",
            "1",
            "--steps",
            "4",
        ],
    ),
    ("hertz2d-nested", ["run", "hertz2d", "--h-contact", "1.5e-3", "--nested", "2"]),
    (
        "hertz2d-layer",
        ["run", "hertz2d", "--h-contact", "6e-3", "--layer-thickness", "0.02", "--layer-E", "3"],
    ),
    ("sliding-block-coulomb", ["run", "sliding-block", "--friction", "coulomb", "--mu", "0.3"]),
    (
        "sliding-block-penalty",
        ["run", "sliding-block", "--friction", "coulomb", "--mu", "0.3", "--method", "penalty"],
    ),
    (
        "hertz3d-al-ssn-tresca",
        [
            "run",
            "hertz3d",
            "--h-contact",
            "0.04",
            "--method",
            "al-ssn",
            "--friction",
            "tresca",
            "--threshold",
            "0.1",
        ],
    ),
    ("westergaard", ["run", "westergaard", "--mean-pressure-ratio", "0.5"]),
    ("punch2d", ["run", "punch2d", "--h-contact", "1e-2"]),
    ("bar1d", ["run", "bar1d"]),
    ("hertz3d-gamg", ["run", "hertz3d", "--h-contact", "0.04", "--solver", "gamg"]),
    ("hertz3d-penalty", ["run", "hertz3d", "--h-contact", "0.04", "--method", "penalty"]),
    ("crack-sneddon", ["run", "crack-sneddon"]),
    ("crack-inclined-coulomb", ["run", "crack-inclined", "--beta", "45", "--mu", "0.3"]),
    (
        "crack-inclined-al-uzawa",
        ["run", "crack-inclined", "--beta", "45", "--mu", "0.3", "--method", "al-uzawa"],
    ),
    ("propped-fracture", ["run", "propped-fracture"]),
    ("joint-column-al-ssn", ["run", "joint-column", "--method", "al-ssn"]),
    (
        "crack-inclined-unfitted",
        ["run", "crack-inclined", "--crack", "unfitted", "--beta", "30", "--mu", "0.3"],
    ),
    (
        "crack-sneddon-unfitted-penalty",
        ["run", "crack-sneddon", "--crack", "unfitted", "--method", "penalty"],
    ),
    ("joint-column-unfitted", ["run", "joint-column", "--crack", "unfitted"]),
    (
        "crack-inclined-unfitted-al-ssn",
        ["run", "crack-inclined", "--crack", "unfitted", "--beta", "30", "--method", "al-ssn"],
    ),
    (
        "joint-column-unfitted-al-ssn",
        ["run", "joint-column", "--crack", "unfitted", "--method", "al-ssn"],
    ),
    ("patch-test-mortar", ["run", "patch-test", "--method", "mortar"]),
    ("patch-test-nitsche", ["run", "patch-test", "--method", "nitsche"]),
    ("hertz-cylinders-mortar", ["run", "hertz-cylinders", "--method", "mortar"]),
    ("hertz-cylinders-penalty", ["run", "hertz-cylinders", "--method", "penalty"]),
    ("sliding-contact-mortar", ["run", "sliding-contact", "--method", "mortar"]),
    ("cattaneo-nitsche", ["run", "cattaneo-cylinders", "--method", "nitsche"]),
    ("cattaneo-mortar", ["run", "cattaneo-cylinders", "--method", "mortar"]),
    # finite strain between two bodies (dragged bodies, friction)
    (
        "sliding-contact-fs-coulomb",
        ["run", "sliding-contact", "--material", "neo-hookean", "--method", "penalty"]
        + ["--friction", "coulomb", "--mu", "0.3", "--steps", "10"],
    ),
    (
        "sliding-contact-fs-mortar-coulomb",
        ["run", "sliding-contact", "--material", "neo-hookean", "--method", "mortar"]
        + ["--friction", "coulomb", "--mu", "0.3", "--steps", "10"],
    ),
    (
        "shallow-ironing-mortar-coulomb-short",
        ["run", "shallow-ironing", "--slide", "1", "--steps", "10", "--method", "mortar"]
        + ["--friction", "coulomb", "--mu", "0.3"],
    ),
    (
        "shallow-ironing-coulomb-short",
        ["run", "shallow-ironing", "--slide", "1", "--steps", "10"]
        + ["--friction", "coulomb", "--mu", "0.3"],
    ),
    ("sphere-slide-coarse", ["run", "sphere-slide", "--slide", "0.3", "--steps", "6"]),
    ("problem-block-on-plinth", ["solve", str(ROOT / "demos/problems/block-on-plinth.toml")]),
    ("problem-holed-pad", ["solve", str(ROOT / "demos/problems/holed-pad.toml")]),
    ("problem-pressurised-crack", ["solve", str(ROOT / "demos/problems/pressurised-crack.toml")]),
]

#: run.json keys whose values are not results (they may differ between identical runs)
SKIP = {
    "timings",
    "search_time",
    "versions",
    "memory_mib",
    "paraview",
    "paraview_surface",
    "plot",
    "interface_csv",
    "interface_plot",
    "out",
    "mesh",
    "problem_file",
    "path",
}


def _run(args) -> int:
    out = Path(args.out)
    env = dict(
        os.environ,
        OMPI_ALLOW_RUN_AS_ROOT="1",
        OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
        OMPI_MCA_rmaps_base_oversubscribe="1",
        OPENBLAS_NUM_THREADS="1",
        OMP_NUM_THREADS="1",
    )
    failed = 0
    for np_ in (int(k) for k in args.np.split(",")):
        for name, cmd in CASES:
            if args.only and args.only not in name:
                continue
            folder = out / f"{name}-np{np_}"
            full = ([] if np_ == 1 else ["mpirun", "-n", str(np_)]) + CONTACTFX + cmd
            full += ["--out", str(folder), "--quiet"]
            res = subprocess.run(full, env=env, capture_output=True, text=True)
            status = "ok" if res.returncode == 0 else f"exit {res.returncode}"
            print(f"{folder.name:45s} {status}", flush=True)
            if res.returncode != 0:
                failed += 1
                print((res.stderr or res.stdout).strip().splitlines()[-1:], flush=True)
    return 1 if failed else 0


def _numbers(value, path: str = ""):
    """(path, number) for every number in a run.json value, skipped keys left out."""
    if isinstance(value, dict):
        for k, v in value.items():
            if k not in SKIP:
                yield from _numbers(v, f"{path}.{k}" if path else k)
    elif isinstance(value, list):
        for i, v in enumerate(value):
            yield from _numbers(v, f"{path}[{i}]")
    elif isinstance(value, bool) or value is None:
        return
    elif isinstance(value, (int, float)):
        yield path, float(value)


def _compare(args) -> int:
    before, after = Path(args.before), Path(args.after)
    compared = differ = missing = identical = unpaired = status = 0
    runs = [a for a in sorted(before.glob("*/run.json")) if args.only in a.parent.name]
    for a in runs:
        b = after / a.parent.name / "run.json"
        if not b.exists():
            print(f"{a.parent.name}: missing in {after}")
            missing += 1
            continue
        ja, jb = json.loads(a.read_text()), json.loads(b.read_text())
        na, nb = dict(_numbers(ja)), dict(_numbers(jb))
        for key in sorted(set(na) | set(nb)):
            if key not in na or key not in nb:
                print(f"{a.parent.name}: {key} only in {'before' if key in na else 'after'}")
                unpaired += 1
                continue
            x, y = na[key], nb[key]
            compared += 1
            same = x == y or (math.isnan(x) and math.isnan(y))
            identical += same
            if not same:
                same = abs(x - y) <= args.rtol * max(abs(x), abs(y)) + args.atol
            if not same:
                rel = abs(x - y) / max(abs(x), abs(y), 1e-300)
                print(f"{a.parent.name}: {key}: {x!r} -> {y!r} (rel {rel:.2e})")
                differ += 1
        for key in ("status",):
            if ja.get(key) != jb.get(key):
                print(f"{a.parent.name}: {key}: {ja.get(key)} -> {jb.get(key)}")
                status += 1
    print(
        f"{len(runs)} runs, {compared} numbers compared: {identical} bit-identical, "
        f"{compared - identical - differ} within rtol {args.rtol:g} + atol {args.atol:g}, "
        f"{differ} differ; {unpaired} keys in one run only; {status} statuses changed; "
        f"{missing} runs missing"
    )
    return 1 if differ or missing or unpaired or status else 0


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)
    r = sub.add_parser("run", help="run the cases")
    r.add_argument("out")
    r.add_argument("--np", default="1,2", help="rank counts (default 1,2)")
    r.add_argument("--only", default="", help="only the cases whose name contains this")
    c = sub.add_parser("compare", help="compare two folders of runs")
    c.add_argument("before")
    c.add_argument("after")
    c.add_argument("--rtol", type=float, default=0.0)
    c.add_argument("--atol", type=float, default=0.0)
    c.add_argument("--only", default="", help="only the runs whose folder contains this")
    args = parser.parse_args()
    return _run(args) if args.command == "run" else _compare(args)


if __name__ == "__main__":
    sys.exit(main())
