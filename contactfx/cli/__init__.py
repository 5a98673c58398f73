"""Command line: ``contactfx list | run SCENE [options] [-- PETSc options] | bench | stress |
solve PROBLEM.toml | check PROBLEM.toml | init SCENE --out DIR | plot RUN``.

PETSc options after ``--`` reach PETSc: they initialise petsc4py before dolfinx is imported and
are copied under the solver's options prefix, so ``-- -snes_monitor -ksp_type gmres`` works.
Errors are one line on rank 0 and a non-zero exit status on every rank.
"""

from __future__ import annotations

import logging
import os
import signal
import sys

from contactfx.cli.args import petsc_dict, split_petsc
from contactfx.solvers.interrupt import Interrupted

__all__ = ["main"]

USAGE = (
    "usage: contactfx {list | run SCENE [options] [-- PETSc options] | "
    "bench [--scene CASES] [--method M,...] [--levels N] [--degree 1,2] [--out DIR] | "
    "stress [--quick] [--axis AXES] [--out DIR] | "
    "solve PROBLEM.toml [--set KEY=VALUE] [--out DIR] [-- PETSc options] | "
    "check PROBLEM.toml | init SCENE [options] --out DIR | "
    "plot RUN [--field NAME] [--step N] [--scale S] [--out PNG]}"
)


def _dispatch(command: str, rest: list[str], petsc_options: dict, comm) -> int:
    # the command modules import dolfinx: only after petsc4py.init
    if command == "list":
        from contactfx.cli.run import cmd_list

        return cmd_list() if comm.rank == 0 else 0
    if command == "run":
        from contactfx.cli.run import cmd_run

        return cmd_run(rest, petsc_options, comm)
    if command == "bench":
        from contactfx.cli.bench import cmd_bench

        return cmd_bench(rest, petsc_options, comm)
    if command == "stress":
        from contactfx.cli.stress import cmd_stress

        return cmd_stress(rest, petsc_options, comm)
    if command in ("solve", "check"):
        from contactfx.cli.solve import cmd_check, cmd_solve

        return (cmd_solve if command == "solve" else cmd_check)(rest, petsc_options, comm)
    if command == "init":
        from contactfx.cli.init import cmd_init

        return cmd_init(rest, comm)
    if command == "plot":
        from contactfx.cli.plot import cmd_plot

        return cmd_plot(rest, comm)
    raise ValueError(f"unknown command '{command}' ({USAGE})")


def _below_warning_on_root(record: logging.LogRecord) -> bool:
    return record.levelno >= logging.WARNING


def _quiet_compiler() -> None:
    """No compiler chatter on a first run (empty form cache). FFCx builds each form through
    cffi, which runs setuptools' distutils with verbose=True: cffi lowers the root logger to
    INFO for the build, and distutils logs every step ("running build_ext", the gcc command
    lines) to the root logger, which FFCx's import gave a stderr handler (logging.basicConfig).
    A level set on the root logger does not hold (cffi sets it for each build); a filter on it
    does: it sees only the records logged on the root logger itself, so the named loggers
    (ffcx, UFL, py.warnings) keep their levels, and the form cache is untouched."""
    root = logging.getLogger()
    if _below_warning_on_root not in root.filters:
        root.addFilter(_below_warning_on_root)


def _python_sigpipe() -> None:
    """A closed pipe (``contactfx check FILE | head``) raises BrokenPipeError in Python, as
    without PETSc. PETSc's initialisation installs its signal handler for every signal, also
    SIGPIPE (which Python ignores, so that a write to a closed pipe raises): that handler prints
    a "Caught signal number 13 Broken Pipe" banner and aborts MPI. SIGPIPE alone goes back to
    Python's setting; PETSc keeps its handler for the others (SIGSEGV, SIGFPE, ...)."""
    from petsc4py import PETSc  # noqa: F401  (initialises PETSc: its handlers are installed)

    if hasattr(signal, "SIGPIPE"):
        signal.signal(signal.SIGPIPE, signal.SIG_IGN)


def _closed_stdout() -> int:
    """The reader of our output went away (``| head``): end quietly. Python would report the
    failed flush of the rest at exit; stdout goes to /dev/null instead."""
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, sys.stdout.fileno())
    os.close(devnull)
    return 0


def main(argv: list[str] | None = None) -> int:
    try:
        status = _main(argv)
        sys.stdout.flush()  # a closed pipe is found here, not at the interpreter's exit
        return status
    except BrokenPipeError:
        return _closed_stdout()


def _main(argv: list[str] | None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    _quiet_compiler()
    argv, petsc_args = split_petsc(argv)

    import petsc4py

    petsc4py.init([sys.argv[0], *petsc_args])
    _python_sigpipe()
    from mpi4py import MPI

    comm = MPI.COMM_WORLD
    try:
        petsc_options = petsc_dict(petsc_args)
        if not argv or argv[0] in ("-h", "--help"):
            if comm.rank == 0:
                print(USAGE)
            return 0 if argv else 2
        return _dispatch(argv[0], argv[1:], petsc_options, comm)
    except BrokenPipeError:
        raise
    except SystemExit as exc:  # argparse: --help (0) or a bad option (2, message printed)
        return int(exc.code or 0)
    except Interrupted as stopped:  # SIGTERM / SIGINT: the complete steps are kept
        if comm.rank == 0:
            print(
                f"contactfx: {stopped}: the output holds the complete steps, run.json says "
                '"interrupted"',
                file=sys.stderr,
                flush=True,
            )
        return 128 + stopped.signum
    except Exception as exc:  # every error becomes one line and a status
        from contactfx.solvers.snes import ConvergenceError

        if isinstance(exc, ValueError | OSError | ConvergenceError):
            if comm.rank == 0:
                print(f"contactfx: error: {exc}", file=sys.stderr, flush=True)
            return 1
        import traceback

        traceback.print_exc()
        comm.Abort(1)  # an unexpected error may be on one rank only: never hang the others
        return 1
