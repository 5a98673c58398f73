"""``contactfx list`` and ``contactfx run SCENE [options] [-- PETSc options]``."""

from __future__ import annotations

import dataclasses
from pathlib import Path

from contactfx.cli.args import Parser, add_options
from contactfx.contact.registry import method_class
from contactfx.driver.pipeline import WRITERS, write_failed
from contactfx.numerics import Numerics
from contactfx.params import option_help
from contactfx.results import RunSummary
from contactfx.scenes import SCENES, get_scene

__all__ = [
    "cmd_list",
    "cmd_run",
    "table",
    "print_outputs",
    "scene_parser",
    "fields_of",
    "one_line",
    "QUIET_HELP",
    "FORMATS",
    "FORMAT_HELP",
    "add_restart_options",
]


QUIET_HELP = "print one line, the result (no progress, no summary table)"
FORMATS = tuple(WRITERS)
FORMAT_HELP = (
    "ParaView files: xdmf (<scene>.xdmf + .h5, written by every rank in parallel) or vtu "
    "(<scene>.pvd, a VTU file per step gathered on rank 0)"
)


def scene_parser(scene_cls, command: str = "run") -> Parser:
    parser = Parser(
        prog=f"contactfx {command} {scene_cls.name}",
        description=scene_cls.summary,
        epilog="PETSc options go after '--', e.g. -- -snes_monitor -ksp_type gmres",
    )
    add_options(parser.add_argument_group("scene parameters"), scene_cls.Params, {})
    add_options(parser.add_argument_group("numerics"), Numerics, scene_cls.numerics_defaults)
    parser.add_argument("--out", type=Path, default=None, help="output folder (ParaView, run.json)")
    parser.add_argument("--format", choices=FORMATS, default="xdmf", help=FORMAT_HELP)
    add_restart_options(parser)
    parser.add_argument("--quiet", action="store_true", help=QUIET_HELP)
    return parser


def add_restart_options(parser) -> None:
    """--restart DIR and --checkpoint-every N (run and solve)."""
    parser.add_argument(
        "--restart",
        type=Path,
        default=None,
        metavar="DIR",
        help="continue the run whose output folder is DIR from its last checkpoint (same "
        "options, ranks and mesh), appending to its ParaView series and run.json",
    )
    parser.add_argument(
        "--checkpoint-every",
        type=int,
        default=1,
        metavar="N",
        help="with --out: write a checkpoint (DIR/checkpoint) after every N converged steps "
        "and the last (0: none)",
    )


def fields_of(cls, values: dict) -> dict:
    return {f.name: values[f.name] for f in dataclasses.fields(cls)}


#: each friction law's coefficient
COEFFICIENTS = {"mu": "coulomb", "threshold": "tresca"}


def scene_numerics(scene_cls, ns: dict) -> Numerics:
    """The numerics of the parsed options ``ns``: a scene's default friction coefficient gives
    way when its friction law is replaced on the command line (``--friction none`` on a scene
    whose defaults are Coulomb mu = 0.3) without the coefficient given again."""
    values = fields_of(Numerics, ns)
    defaults = scene_cls.numerics_defaults
    law = values["friction"]
    if law != defaults.get("friction", law):
        unset = {f.name: f.default for f in dataclasses.fields(Numerics)}
        for key, owner in COEFFICIENTS.items():
            if law != owner and key in defaults and values[key] == defaults[key]:
                values[key] = unset[key]
    return Numerics(**values)


def cmd_list() -> int:
    def options(cls):
        for f in dataclasses.fields(cls):
            print(f"    --{f.name.replace('_', '-'):22s} {f.default!s:10s} {option_help(f)}")

    for name, cls in SCENES.items():
        print(f"{name:12s} {cls.summary}")
        options(cls.Params)
    print("numerics (every scene):")
    options(Numerics)
    return 0


def table(res: RunSummary) -> str:
    """The summary printed after a run."""
    t, ref, num = res.timings, res.reference, res.numerics
    key = method_class(num["method"]).sweep[0]
    method = num["method"] + (f" {key}={num[key]}" if key else "")
    kind = "P2/P1 mixed u-p" if num["formulation"] == "mixed-up" else f"P{num['degree']}"
    rows = [
        ("scene", res.scene),
        ("method", f"{method}, {kind}"),
        ("dofs / ranks", f"{res.dofs} / {res.ranks}"),
        (
            "load steps / Newton / KSP",
            f"{len(res.steps)} / {res.newton_iterations} / {res.ksp_iterations}",
        ),
        (
            "time mesh / compile / assembly / solve [s]",
            " / ".join(f"{t.get(k, 0.0):.2f}" for k in ("mesh", "compile", "assembly", "solve")),
        ),
    ]
    rows.append(("peak memory, all ranks [MiB]", f"{res.memory_mib:.0f}"))
    if "contact" in t:  # two bodies: the coupling's part of the assembly time
        rows.append(("time of search + contact terms [s]", f"{t['contact']:.2f}"))
    rows += _interface_rows(res) if res.interface is not None else _obstacle_rows(res, ref)
    if res.outer_iterations > len(res.steps):
        rows.append(("Uzawa outer iterations", str(res.outer_iterations)))
    if res.interface is None:
        rows += [(k.replace("_", " "), f"{v:.4g}") for k, v in res.scores.items()]
        rows += [(k.replace("_", " "), f"{v:.4e}") for k, v in res.errors.items()]
    else:
        rows += [(k.replace("_", " "), f"{v:.6g}") for k, v in {**ref, **res.errors}.items()]
    if res.plot:
        rows.append(("line plot", res.plot))
    if res.energy:
        e = res.energy
        rows.append(
            (
                "energy initial / final / work of loads",
                f"{e['initial_total']:.6g} / {e['final_total']:.6g} / {e['external_work']:.6g}",
            )
        )
        lost = {
            k: e[f"{k}_dissipation"] for k in ("friction", "dashpot") if e.get(f"{k}_dissipation")
        }
        if lost:
            rows.append(
                (
                    "energy dissipated by " + " / ".join(lost),
                    " / ".join(f"{v:.6g}" for v in lost.values()),
                )
            )
        rows.append(
            (
                "energy balance: largest remainder",
                f"{e['largest_remainder']:.3g} ({e['largest_remainder_relative']:.2%} of the "
                "largest energy)",
            )
        )
    rows += [("warning", w) for w in res.warnings]
    width = max(len(r[0]) for r in rows)
    return "\n".join(f"  {k:<{width}}  {v}" for k, v in rows)


def _obstacle_rows(res: RunSummary, ref: dict) -> list[tuple[str, str]]:
    rows = [("contact force", f"{res.force:.6g}")]
    if "force_rel_error" in ref:
        rows.append(
            ("reference force", f"{ref['force']:.6g}  (rel. error {ref['force_rel_error']:.2%})")
        )
    if "a" in ref:
        rows.append(
            (
                "contact half-width a (ref)",
                f"{ref['a_computed']:.6g} vs {ref['a']:.6g}  (rel. error "
                f"{ref['a_rel_error']:.2%}, {ref['a_error_over_h']:.2f} h)",
            )
        )
    else:
        rows.append(("contact half-width / radius", f"{res.contact_size:.6g}"))
    if "p0" in ref:
        rows.append(
            (
                "peak pressure p0",
                f"{ref['p0_computed']:.6g} vs {ref['p0']:.6g}  "
                f"(rel. error {ref['p0_rel_error']:.2%})",
            )
        )
    else:
        rows.append(("peak pressure", f"{res.peak_pressure:.6g}"))
    f = res.friction
    if f is not None:
        rows.append(("tangential force Q / bound", f"{f.tangential_force[0]:.6g} / {f.bound:.6g}"))
        stick = f"{f.stick_size:.6g}  (slip fraction {f.slip_fraction:.1%})"
        if "c" in ref:
            stick += f", Cattaneo-Mindlin {ref['c']:.6g}"
        rows.append(("stick zone half-width / radius", stick))
        rows.append(("max friction excess", f"{f.excess:.2e}"))
    return rows


def _interface_rows(res: RunSummary) -> list[tuple[str, str]]:
    i = res.interface
    rows = [
        ("interface normal / tangential force", f"{res.force:.6g} / {i.tangential_force:.6g}"),
        (
            "closed length (area in 3D) / max penetration",
            f"{res.contact_size:.6g} / {res.max_penetration:.3e}",
        ),
    ]
    if i.proppant_force is not None:
        rows.append(
            (
                "proppant force / min aperture (propped)",
                f"{i.proppant_force:.6g} / {i.min_aperture_propped:.6g}",
            )
        )
    return rows


def cmd_run(argv: list[str], petsc_options: dict, comm) -> int:
    if not argv or argv[0].startswith("-"):
        if argv and argv[0] in ("-h", "--help"):
            print("usage: contactfx run SCENE [options] [-- PETSc options]; see `contactfx list`")
            return 0
        raise ValueError("missing scene name: contactfx run SCENE (see `contactfx list`)")
    scene_cls = get_scene(argv[0])
    if comm.rank != 0 and ("-h" in argv or "--help" in argv):
        return 0
    ns = vars(scene_parser(scene_cls).parse_args(argv[1:]))
    try:
        scene = scene_cls(scene_cls.Params(**fields_of(scene_cls.Params, ns)))
        numerics = scene_numerics(scene_cls, ns)
    except ValueError as error:
        if ns["out"] is not None:
            write_failed(ns["out"], error, "input", comm, scene=scene_cls.name)
        raise
    if comm.rank == 0 and not ns["quiet"]:
        print(f"contactfx: {scene.name}, method {numerics.method}, {comm.size} rank(s)", flush=True)
    # a failure from here on writes run.json marked failed (contactfx.driver.pipeline.run)
    res = scene.run(
        numerics,
        comm=comm,
        out=ns["out"],
        petsc_options=petsc_options,
        verbose=not ns["quiet"],
        output_format=ns["format"],
        restart=ns["restart"],
        checkpoint_every=ns["checkpoint_every"],
    )
    if comm.rank == 0:
        if ns["quiet"]:
            print(one_line(res))
        else:
            print(table(res))
            print_outputs(res)
    return 0


def one_line(res: RunSummary) -> str:
    """The result in one line (``--quiet``): the scene, the method, the force, the contact size
    and peak pressure (with their closed forms where known), the steps and where run.json is."""
    num, ref = res.numerics, res.reference
    kind = "P2/P1 mixed u-p" if num["formulation"] == "mixed-up" else f"P{num['degree']}"
    parts = [f"{res.scene}, {num['method']} {kind}: force {res.force:.6g}"]
    if res.interface is not None:
        parts.append(f"tangential force {res.interface.tangential_force:.6g}")
        parts.append(f"closed size {res.contact_size:.6g}")
    else:
        if "a" in ref:
            parts.append(f"a {ref['a_computed']:.6g} (ref {ref['a']:.6g})")
        else:
            parts.append(f"contact size {res.contact_size:.6g}")
        if "p0" in ref:
            parts.append(f"p0 {ref['p0_computed']:.6g} (ref {ref['p0']:.6g})")
        else:
            parts.append(f"peak pressure {res.peak_pressure:.6g}")
    parts.append(f"{len(res.steps)} steps, {res.newton_iterations} Newton")
    if res.paraview:
        parts.append(f"run.json in {Path(res.paraview).parent}")
    return ", ".join(parts)


def print_outputs(res: RunSummary) -> None:
    """The files a run wrote (rank 0)."""
    if res.paraview:
        print(f"  ParaView: {res.paraview}")
        if res.paraview_surface:
            print(f"  surface:  {res.paraview_surface}")
        print(f"  summary:  {Path(res.paraview).parent / 'run.json'}")
