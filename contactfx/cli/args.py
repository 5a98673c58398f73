"""The argument layer shared by the commands: an argparse parser that raises instead of
exiting, options generated from parameter dataclasses, and PETSc options after ``--``."""

from __future__ import annotations

import argparse
import dataclasses
import sys
import time

from contactfx.params import option_help, option_name

__all__ = [
    "Parser",
    "attach_negative_numbers",
    "split_petsc",
    "petsc_dict",
    "add_options",
    "int_list",
    "finish_table",
]


class Parser(argparse.ArgumentParser):
    """argparse that raises ValueError (reported once, on rank 0) instead of exiting, and
    takes negative numbers in any float notation as option values (``--gap0 -3e-3``)."""

    def error(self, message: str):
        raise ValueError(message)

    def parse_known_args(self, args=None, namespace=None):
        # Python 3.11 (Debian 12) takes '-3e-3' or '-1E+6' for an option: its negative-number
        # pattern (private, _negative_number_matcher) knows '-1' and '-.5' only; 3.13 (Debian
        # 13) accepts them. Rather than patch argparse's private attributes, which differ
        # between versions, the value is attached to its option ('--gap0=-3e-3', argparse's
        # documented form), so the parsing is the same on every Python. parse_args calls
        # parse_known_args on 3.11 and 3.13 alike.
        args = sys.argv[1:] if args is None else list(args)
        return super().parse_known_args(attach_negative_numbers(args), namespace)


def attach_negative_numbers(args: list[str]) -> list[str]:
    """['--gap0', '-3e-3'] -> ['--gap0=-3e-3']: a negative number right after an option
    (no '=' in it) becomes that option's value; everything else is left to argparse (an
    unknown '-x' is still an error, a flag followed by a number too)."""
    out: list[str] = []
    for arg in args:
        prev = out[-1] if out else ""
        if (
            arg.startswith("-")
            and _is_number(arg)
            and prev.startswith("-")
            and "=" not in prev
            and not _is_number(prev)
        ):
            out[-1] = f"{prev}={arg}"
        else:
            out.append(arg)
    return out


def split_petsc(argv: list[str]) -> tuple[list[str], list[str]]:
    """(our arguments, PETSc arguments after '--')."""
    if "--" in argv:
        i = argv.index("--")
        return argv[:i], argv[i + 1 :]
    return argv, []


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def petsc_dict(args: list[str]) -> dict[str, str | None]:
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


def add_options(parser, cls, defaults: dict) -> None:
    """One ``--option`` per field of the parameter dataclass ``cls`` (its help and type)."""
    for f in dataclasses.fields(cls):
        name = option_name(f)
        default = defaults.get(name, f.default)
        kind = type(f.default)
        if kind is bool:  # --dynamic / --no-dynamic
            parser.add_argument(
                "--" + name.replace("_", "-"),
                dest=name,
                action=argparse.BooleanOptionalAction,
                default=default,
                help=f"{option_help(f)} (default: {default})",
            )
            continue
        parser.add_argument(
            "--" + name.replace("_", "-"),
            dest=name,
            type=kind,
            default=default,
            metavar=kind.__name__.upper(),
            help=f"{option_help(f)} (default: {default})",
        )


def int_list(text: str) -> list[int]:
    """'1,2' -> [1, 2]."""
    try:
        return [int(t) for t in text.split(",") if t.strip()]
    except ValueError:
        raise ValueError(f"expected comma-separated integers, got '{text}'") from None


def finish_table(rows: list[dict], comm, started: float, summary: str, out, write) -> None:
    """Rank 0 prints ``summary`` (formatted with the total time) and, with an output folder,
    writes the rows by ``write(rows, out, ranks, total)``; every rank waits for it."""
    if comm.rank == 0:
        total = time.perf_counter() - started
        print(summary.format(total=total))
        if out is not None:
            for path in write(rows, out, comm.size, total):
                print(f"wrote {path}")
    comm.barrier()
