"""Command line: ``contactfx list | run SCENE [options] [-- PETSc options] | bench | stress``.

PETSc options after ``--`` reach PETSc: they initialise petsc4py before dolfinx is imported and
are copied under the solver's options prefix, so ``-- -snes_monitor -ksp_type gmres`` works.
Errors are one line on rank 0 and a non-zero exit status on every rank.
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
from pathlib import Path

__all__ = ["main"]


def _split_petsc(argv: list[str]) -> tuple[list[str], list[str]]:
    if "--" in argv:
        i = argv.index("--")
        return argv[:i], argv[i + 1 :]
    return argv, []


def _petsc_dict(args: list[str]) -> dict[str, str | None]:
    """['-snes_monitor', '-ksp_type', 'gmres'] -> {'snes_monitor': None, 'ksp_type': 'gmres'}."""
    out: dict[str, str | None] = {}
    i = 0
    while i < len(args):
        key = args[i]
        if not key.startswith("-") or _is_number(key):
            raise ValueError(f"PETSc option expected after '--', got '{key}'")
        value = None
        if i + 1 < len(args) and (not args[i + 1].startswith("-") or _is_number(args[i + 1])):
            value = args[i + 1]
            i += 1
        out[key.lstrip("-")] = value
        i += 1
    return out


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


class _Parser(argparse.ArgumentParser):
    """argparse that raises ValueError (reported once, on rank 0) instead of exiting."""

    def error(self, message: str):
        raise ValueError(message)


def _add_dataclass_options(parser: argparse.ArgumentParser, cls, defaults: dict) -> None:
    for f in dataclasses.fields(cls):
        default = defaults.get(f.name, f.default)
        kind = type(f.default)
        help_text = f.metadata.get("help", "")
        parser.add_argument(
            "--" + f.name.replace("_", "-"),
            dest=f.name,
            type=kind,
            default=default,
            metavar=kind.__name__.upper(),
            help=f"{help_text} (default: {default})",
        )


def _scene_parser(scene_cls) -> argparse.ArgumentParser:
    from contactfx.scenes import Numerics

    parser = _Parser(
        prog=f"contactfx run {scene_cls.name}",
        description=scene_cls.summary,
        epilog="PETSc options go after '--', e.g. -- -snes_monitor -ksp_type gmres",
    )
    group = parser.add_argument_group("scene parameters")
    _add_dataclass_options(group, scene_cls.Params, {})
    group = parser.add_argument_group("numerics")
    _add_dataclass_options(group, Numerics, scene_cls.numerics_defaults)
    parser.add_argument("--out", type=Path, default=None, help="output folder (XDMF, run.json)")
    parser.add_argument("--quiet", action="store_true", help="no progress output")
    return parser


def _build(scene_cls, ns: argparse.Namespace):
    from contactfx.scenes import Numerics

    values = vars(ns)
    fields = dataclasses.fields(scene_cls.Params)
    params = scene_cls.Params(**{f.name: values[f.name] for f in fields})
    numerics = Numerics(**{f.name: values[f.name] for f in dataclasses.fields(Numerics)})
    return scene_cls(params), numerics


def _cmd_list() -> int:
    from contactfx.scenes import SCENES, Numerics

    for name, cls in SCENES.items():
        print(f"{name:12s} {cls.summary}")
        for f in dataclasses.fields(cls.Params):
            print(f"    --{f.name.replace('_', '-'):22s} {f.default!s:10s} {f.metadata['help']}")
    print("numerics (every scene):")
    for f in dataclasses.fields(Numerics):
        print(f"    --{f.name.replace('_', '-'):22s} {f.default!s:10s} {f.metadata['help']}")
    return 0


def _table(data: dict) -> str:
    t = data["timings"]
    ref = data.get("reference", {})
    num = data["numerics"]
    method = num["method"] + (f" theta={num['theta']}" if num["method"] == "nitsche" else "")
    rows = [
        ("scene", data["scene"]),
        ("method", f"{method}, " + (
            "P2/P1 mixed u-p" if num["formulation"] == "mixed-up" else f"P{num['degree']}")),
        ("dofs / ranks", f"{data['dofs']} / {data['ranks']}"),
        ("load steps / Newton / KSP", f"{len(data['steps'])} / {data['newton_iterations']} / "
         f"{data['ksp_iterations']}"),
        ("time mesh / compile / assembly / solve [s]",
         " / ".join(f"{t.get(k, 0.0):.2f}" for k in ("mesh", "compile", "assembly", "solve"))),
    ]  # fmt: skip
    if "normal_force" in data:  # a fitted interface (crack, fracture, joint)
        return _rows(rows + _interface_rows(data))
    rows.append(("contact force", f"{data['force']:.6g}"))
    if "force_rel_error" in ref:
        rows.append(("reference force", f"{ref['force']:.6g}  (rel. error "
                     f"{ref['force_rel_error']:.2%})"))  # fmt: skip
    if "a" in ref:
        rows.append(
            ("contact half-width a (ref)",
             f"{ref['a_computed']:.6g} vs {ref['a']:.6g}  (rel. error {ref['a_rel_error']:.2%},"
             f" {ref['a_error_over_h']:.2f} h)")
        )  # fmt: skip
    else:
        rows.append(("contact half-width / radius", f"{data['contact_half_width']:.6g}"))
    if "p0" in ref:
        rows.append(
            ("peak pressure p0", f"{ref['p0_computed']:.6g} vs {ref['p0']:.6g}  "
             f"(rel. error {ref['p0_rel_error']:.2%})")
        )  # fmt: skip
    else:
        rows.append(("peak pressure", f"{data['peak_pressure']:.6g}"))
    if "tangential_force" in data:
        q = data["tangential_force"][0]
        rows.append(("tangential force Q / bound", f"{q:.6g} / {data['friction_bound']:.6g}"))
        stick = f"{data['stick_size']:.6g}  (slip fraction {data['slip_fraction']:.1%})"
        if "c" in ref:
            stick += f", Cattaneo-Mindlin {ref['c']:.6g}"
        rows.append(("stick zone half-width / radius", stick))
        rows.append(("max friction excess", f"{data['friction_excess']:.2e}"))
    if data.get("outer_iterations", 0) > len(data["steps"]):
        rows.append(("Uzawa outer iterations", str(data["outer_iterations"])))
    for key, value in data.get("scores", {}).items():
        rows.append((key.replace("_", " "), f"{value:.4g}"))
    for key, value in data.get("errors", {}).items():
        rows.append((key.replace("_", " "), f"{value:.4e}"))
    return _rows(rows)


def _interface_rows(data: dict) -> list[tuple[str, str]]:
    rows = [
        ("interface normal / tangential force",
         f"{data['normal_force']:.6g} / {data['tangential_force']:.6g}"),
        ("closed length / max penetration",
         f"{data['closed_length']:.6g} / {data['max_penetration']:.3e}"),
    ]  # fmt: skip
    if "proppant_force" in data:
        rows.append(
            (
                "proppant force / min aperture (propped)",
                f"{data['proppant_force']:.6g} / {data['min_aperture_propped']:.6g}",
            )
        )
    for key, value in {**data.get("reference", {}), **data.get("errors", {})}.items():
        rows.append((key.replace("_", " "), f"{value:.6g}"))
    if data.get("plot"):
        rows.append(("line plot", data["plot"]))
    return rows


def _rows(rows: list[tuple[str, str]]) -> str:
    width = max(len(r[0]) for r in rows)
    return "\n".join(f"  {k:<{width}}  {v}" for k, v in rows)


def _cmd_run(argv: list[str], petsc_options: dict, comm) -> int:
    from contactfx.scenes import get_scene
    from contactfx.solvers.snes import ConvergenceError

    if not argv or argv[0].startswith("-"):
        if argv and argv[0] in ("-h", "--help"):
            print("usage: contactfx run SCENE [options] [-- PETSc options]; see `contactfx list`")
            return 0
        raise ValueError("missing scene name: contactfx run SCENE (see `contactfx list`)")
    scene_cls = get_scene(argv[0])
    if comm.rank != 0 and ("-h" in argv or "--help" in argv):
        return 0
    ns = _scene_parser(scene_cls).parse_args(argv[1:])
    scene, numerics = _build(scene_cls, ns)
    if comm.rank == 0 and not ns.quiet:
        print(f"contactfx: {scene.name}, method {numerics.method}, {comm.size} rank(s)", flush=True)
    try:
        result = scene.run(
            numerics, comm=comm, out=ns.out, petsc_options=petsc_options, verbose=not ns.quiet
        )
    except ConvergenceError:
        if ns.out is not None:
            _write_failed(ns.out, scene, numerics, sys.exc_info()[1], comm)
        raise
    if comm.rank == 0:
        print(_table(result.data))
        if result.data["xdmf"]:
            print(f"  ParaView: {result.data['xdmf']}")
            print(f"  summary:  {Path(result.data['xdmf']).parent / 'run.json'}")
    return 0


def _write_failed(out: Path, scene, numerics, error: Exception, comm) -> None:
    from contactfx.io.provenance import versions, write_json

    data = {
        "status": "failed",
        "error": str(error),
        "scene": scene.name,
        "parameters": dataclasses.asdict(scene.p),
        "numerics": dataclasses.asdict(numerics),
        "versions": versions(),
        "ranks": comm.size,
    }
    try:
        write_json(Path(out) / "run.json", data, comm)
    except OSError:
        pass


def _usage() -> str:
    return (
        "usage: contactfx {list | run SCENE [options] [-- PETSc options] | "
        "bench [--scene CASES] [--method M,...] [--levels N] [--degree 1,2] [--out DIR] | "
        "stress [--quick] [--axis AXES] [--out DIR]}"
    )


def main(argv: list[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    argv, petsc_args = _split_petsc(argv)

    import petsc4py

    petsc4py.init([sys.argv[0], *petsc_args])
    from mpi4py import MPI

    comm = MPI.COMM_WORLD
    try:
        petsc_options = _petsc_dict(petsc_args)
        if not argv or argv[0] in ("-h", "--help"):
            if comm.rank == 0:
                print(_usage())
            return 0 if argv else 2
        command, rest = argv[0], argv[1:]
        if command == "list":
            return _cmd_list() if comm.rank == 0 else 0
        if command == "run":
            return _cmd_run(rest, petsc_options, comm)
        if command == "bench":
            from contactfx.validation.bench import bench_main

            return bench_main(rest, petsc_options, comm)
        if command == "stress":
            from contactfx.validation.stress import stress_main

            return stress_main(rest, petsc_options, comm)
        raise ValueError(f"unknown command '{command}' ({_usage()})")
    except SystemExit as exc:  # argparse: --help (0) or a bad option (2, message printed)
        return int(exc.code or 0)
    except Exception as exc:  # noqa: BLE001 - every error becomes one line and a status
        from contactfx.solvers.snes import ConvergenceError

        expected = isinstance(exc, ValueError | OSError | ConvergenceError)
        if expected:
            if comm.rank == 0:
                print(f"contactfx: error: {exc}", file=sys.stderr, flush=True)
            return 1
        import traceback

        traceback.print_exc()
        comm.Abort(1)  # an unexpected error may be on one rank only: never hang the others
        return 1


if __name__ == "__main__":
    sys.exit(main())
