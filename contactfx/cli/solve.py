"""``contactfx solve problem.toml`` and ``contactfx check problem.toml``: a problem file over
the user's own mesh (:mod:`contactfx.scenes.problem_file`)."""

from __future__ import annotations

import csv
import dataclasses
from pathlib import Path

from contactfx.cli.args import Parser
from contactfx.cli.run import (
    FORMAT_HELP,
    FORMATS,
    QUIET_HELP,
    add_restart_options,
    one_line,
    print_outputs,
    table,
)
from contactfx.driver.pipeline import write_failed
from contactfx.scenes.problem_file import load_problem

__all__ = ["cmd_solve", "cmd_check"]


def _parser(command: str, about: str) -> Parser:
    parser = Parser(
        prog=f"contactfx {command}",
        description=about,
        epilog="PETSc options go after '--', e.g. -- -snes_monitor",
    )
    parser.add_argument("problem", type=Path, help="the problem file (TOML)")
    parser.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="override a key of the file, e.g. numerics.method=al-ssn or "
        "bodies.0.E=2e5 (repeatable)",
    )
    return parser


def cmd_solve(argv: list[str], petsc_options: dict, comm) -> int:
    parser = _parser("solve", "solve the contact problem of a problem file")
    parser.add_argument(
        "--out",
        type=Path,
        default=None,
        help="output folder (default: results/<title> beside the file)",
    )
    parser.add_argument("--quiet", action="store_true", help=QUIET_HELP)
    parser.add_argument(
        "--format", choices=FORMATS, default=None, help=FORMAT_HELP + " (default: output.format)"
    )
    add_restart_options(parser)
    ns = parser.parse_args(argv)
    try:
        scene, numerics, file_petsc = load_problem(ns.problem, ns.set)
    except ValueError as error:
        if ns.out is not None:  # else the folder is named by the file's title
            write_failed(ns.out, error, "input", comm, problem=str(ns.problem))
        raise
    out = ns.out if ns.out is not None else ns.restart
    out = out if out is not None else ns.problem.parent / "results" / scene.name
    options = {**file_petsc, **petsc_options}
    if comm.rank == 0 and not ns.quiet:
        print(
            f"contactfx: {ns.problem} ({scene.summary}), method {numerics.method}, "
            f"{comm.size} rank(s)",
            flush=True,
        )
    # a failure from here on writes run.json marked failed (contactfx.driver.pipeline.run)
    res = scene.run(
        numerics,
        comm=comm,
        out=out,
        petsc_options=options,
        verbose=not ns.quiet,
        output_format=ns.format or scene.spec.output.format,
        restart=ns.restart,
        checkpoint_every=ns.checkpoint_every,
    )
    written = _write_reactions(scene, out, comm)
    if comm.rank == 0 and ns.quiet:
        print(one_line(res))
    elif comm.rank == 0:
        print(table(res))
        if res.interface is not None:
            for key, value in res.interface.extra.items():
                print(f"  {key.replace('_', ' '):<42s}  {value:.6g}")
        for g, values in _last_reactions(scene).items():
            print(f"  reaction on {g:<28s}  " + "  ".join(f"{v:.6g}" for v in values))
        if scene.spec.output.symmetry_planes:
            print(f"  {_full_model(scene.spec.output)}")
        if written:
            print(f"  forces per step: {written} (and history.png)")
        print_outputs(res)
    return 0


def _last_reactions(scene) -> dict[str, list[float]]:
    if not scene.reaction_rows:
        return {}
    row = scene.reaction_rows[-1]
    return {g: [row[f"{g}_{c}"] for c in "xyz"[: scene.gdim]] for g in scene.spec.output.reactions}


def _write_reactions(scene, out: Path, comm) -> Path | None:
    """history.csv: per step the load factor, the contact force and each group's reaction
    components; history.png: them against the load factor."""
    rows = scene.reaction_rows
    if not rows:
        return None
    path = out / "history.csv"
    if comm.rank == 0:
        with path.open("w", newline="") as fh:
            writer = csv.DictWriter(fh, fieldnames=list(rows[0]))
            writer.writeheader()
            writer.writerows(rows)
        _plot_history(rows, out / "history.png", scene.name)
    comm.barrier()
    return path


def _plot_history(rows: list[dict], path: Path, title: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 4))
    loads = [0.0] + [r["load"] for r in rows]
    for key in rows[0]:
        if key != "load":
            ax.plot(loads, [0.0] + [r[key] for r in rows], "o-", label=key)
    ax.set_xlabel("load factor")
    ax.set_ylabel("force")
    ax.set_title(title)
    ax.grid(True, alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def _describe(material, finite: bool) -> str:
    """A body's material for ``check``: linear E, nu (small strain among finite-strain bodies
    when ``finite``), or the hyperelastic model, its parameters and small-strain E, nu."""
    if not material.finite_strain:
        note = " (small strain among finite-strain bodies)" if finite else ""
        return f"E = {material.E:g}, nu = {material.nu:g}{note}"
    if material.name == "mooney-rivlin":
        given = f"c10 = {material.c10:g}, c01 = {material.c01:g}, kappa = {material.K:g}"
    elif material.name == "neo-hookean":
        given = f"mu = {material.mu:g}, kappa = {material.kappa:g}"
    else:
        given = f"E = {material.E:g}, nu = {material.nu:g}"
    small = "" if material.name == "svk" else f" (E = {material.E:g}, nu = {material.nu:g})"
    return f"{material.name}, {given}{small}"


def cmd_check(argv: list[str], petsc_options: dict, comm) -> int:
    """Validate the file and its mesh and print a summary, without solving."""
    import numpy as np

    ns = _parser("check", "validate a problem file and summarise it without solving").parse_args(
        argv
    )
    scene, numerics, file_petsc = load_problem(ns.problem, ns.set)
    from contactfx.driver.pipeline import setup

    problem = setup(scene, numerics, comm=comm)
    # a pair's overlap at the start (collective), refused without contact.interference
    overlap = None
    if scene.spec.pair is not None and hasattr(problem, "initial_gap"):
        least, tol = problem.initial_gap()
        refusal = problem.overlap_refusal(least, tol)
        if refusal is not None:
            raise ValueError(f"{ns.problem}: {refusal}")
        overlap = max(-least, 0.0), tol
    dofs = problem.dofs()  # collective (a sum over the ranks): before rank 0 alone prints
    if comm.rank != 0:
        return 0
    pb = scene.spec
    print(f"{ns.problem}: valid")
    where = (
        f"{pb.mesh.file} (size factor {pb.mesh.size})" if pb.mesh.builder is None else pb.mesh.label
    )
    print(f"  mesh       {where}, {scene.gdim}D, {dofs} dofs")
    print("  groups     " + scene.group_list())
    # each body's material as the run takes it: its own, or a linear one under numerics.material
    materials = [numerics.bulk_material(body.material) for body in pb.bodies]
    finite = any(m.finite_strain for m in materials)
    for body, material in zip(pb.bodies, materials, strict=True):
        print(f"  body       {body.group}: {_describe(material, finite)}")
    for b in pb.boundary:
        what = []
        if b.fix:
            what.append("fixed " + ",".join("xyz"[c] for c in b.fix))
        if b.displacement:
            what.append(
                "displacement "
                + ", ".join(f"{'xyz'[c]} = {v:g}" for c, v in b.displacement.items())
            )
        if b.traction is not None:
            what.append(f"traction {np.array2string(b.traction, separator=', ')}")
        if b.pressure is not None:
            what.append(f"pressure {b.pressure:g}")
        if b.stress is not None:
            exact = all(isinstance(v, int | float) for row in b.stress for v in row)
            what.append(f"stress {b.stress}" if exact else "stress (expressions in x, y)")
        ramp = ((0.0, 0.0), (1.0, 1.0))
        amp = "" if b.amplitude == ramp else f" x amplitude {[list(r) for r in b.amplitude]}"
        print(f"  boundary   {b.group}: {'; '.join(what)}{amp}")
    if pb.obstacle is not None:
        ob = pb.obstacle
        size = ", ".join(
            f"{k} {getattr(ob, k):g}"
            for k in ("radius", "edge_radius", "height", "wavelength", "h")
            if getattr(ob, k) is not None
        )
        moves = (
            f"along the path {[list(r) for r in ob.path]}"
            if ob.path is not None
            else f"moving by {scene.motion.tolist()}"
        )
        print(
            f"  obstacle   {ob.shape}{' (' + size + ')' if size else ''} touching "
            f"{ob.contact}, from {scene.position.tolist()} {moves}"
        )
    for body in pb.bodies:
        if body.force is not None:
            print(f"  body force {body.group}: {body.force.tolist()}")
    if pb.initial is not None:
        print("  initial    displacement given (Newton's start)")
    if pb.pair is not None:
        print(f"  contact    slave {pb.pair.slave}, master {pb.pair.master}")
    # (an overlap at round-off, flat faces meshed touching, is no overlap)
    if overlap is not None and (overlap[0] > 1e-6 * overlap[1] or pb.pair.interference):
        how = (
            f"interference = {pb.pair.interference}: removed over the load program"
            if pb.pair.interference is not None
            else f"within the tolerance {overlap[1]:.3g}"
        )
        print(f"  overlap    largest {overlap[0]:.6g} at the start ({how})")
    for pin in pb.pins:
        print(f"  pin        {pin.point.tolist()}: fixed {','.join('xyz'[c] for c in pin.fix)}")
    if pb.interface is not None:
        spec = pb.interface
        keys = [
            f.name
            for f in dataclasses.fields(spec)
            if f.name != "group" and getattr(spec, f.name) is not None
        ]
        print(f"  interface  {spec.group}" + (f" ({', '.join(keys)})" if keys else ""))
    print(
        f"  numerics   method {numerics.method}, friction {numerics.friction}, "
        f"{numerics.steps} step(s), solver {numerics.solver}"
    )
    if file_petsc:
        print(f"  petsc      {file_petsc}")
    if pb.output.reactions:
        print(f"  output     reactions of {', '.join(pb.output.reactions)}")
    if pb.output.symmetry_planes:
        print(f"  symmetry   {_full_model(pb.output)}")
    return 0


def _full_model(output) -> str:
    """How the forces of a model with mirror planes are reported (the full model's)."""
    axes = ", ".join("xyz"[k] for k in output.symmetry_planes)
    return (
        f"forces of the full model: {output.symmetry:g} times the model's, 0 along {axes} "
        "(normal to the mirror planes)"
    )
