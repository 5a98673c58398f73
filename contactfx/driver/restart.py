"""Checkpoints of a run's load program and its restart (:mod:`contactfx.io.checkpoint`).

:class:`Checkpoints` writes one every ``every`` converged steps (and at the last); a
:class:`Restart` reads the last complete one of a run's folder, refuses a run that differs
from it (scene, parameters, numerics, output format, ranks, mesh) in one line naming what
differs, and puts the state back once the run is built again.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any

from mpi4py import MPI

from contactfx.io.checkpoint import capture, mesh_hash, read_checkpoint, restore, write_checkpoint

__all__ = ["Checkpoints", "Restart", "run_identity"]


def run_identity(scene: Any, numerics: Any, output_format: str, comm: MPI.Comm) -> dict:
    """What a restart must share with the checkpoint's run."""
    return {
        "scene": scene.name,
        "parameters": dataclasses.asdict(scene.p),
        "numerics": dataclasses.asdict(numerics),
        "format": output_format,
        "ranks": comm.size,
    }


class Checkpoints:
    """Write the state after every ``every``-th converged step and after the last one."""

    def __init__(self, out: Path, every: int, identity: dict, mesh: Any, comm: MPI.Comm):
        self.out, self.every, self.identity, self.comm = out, every, identity, comm
        self.cells = mesh.topology.index_map(mesh.topology.dim).size_global
        self.hash = mesh_hash(mesh)

    def due(self, step: int, last: bool) -> bool:
        return self.every > 0 and (step % self.every == 0 or last)

    def write(self, step: int, load: float, roots: dict, steps: list, writer: Any) -> None:
        state = {
            "objects": capture(roots),
            "steps": steps,
            "writer": None if writer is None else writer.state(),
            "mesh": self.hash,
        }
        meta = {**self.identity, "load": load, "cells": self.cells}
        write_checkpoint(self.out, self.comm, step, meta, state)


class Restart:
    """The last complete checkpoint of the run in ``folder``, checked against this run's
    identity (every rank raises the same ValueError)."""

    def __init__(self, folder: Path, identity: dict, comm: MPI.Comm) -> None:
        self.folder, self.comm = Path(folder), comm
        error, meta, state = None, None, None
        try:
            meta, state = read_checkpoint(self.folder, comm)
        except (OSError, ValueError, EOFError) as err:
            error = str(err)
        errors = [e for e in comm.allgather(error) if e is not None]
        if errors:
            raise ValueError(errors[0])
        assert meta is not None and state is not None
        self.meta: dict[str, Any] = meta
        self.state: dict[str, Any] = state
        self.step, self.load = int(meta["step"]), float(meta["load"])
        different = _difference(meta, identity)
        if different:
            raise ValueError(f"--restart {self.folder}: {different}")

    def check_mesh(self, mesh: Any) -> None:
        """Refuse a mesh other than the checkpoint's (its size, or any rank's cells and
        coordinates: another mesh or another partition). Collective."""
        cells = mesh.topology.index_map(mesh.topology.dim).size_global
        if cells != self.meta["cells"]:
            raise ValueError(
                f"--restart {self.folder}: the mesh differs from the checkpoint's "
                f"({cells} cells here, {self.meta['cells']} there)"
            )
        same = self.comm.allreduce(int(mesh_hash(mesh) == self.state["mesh"]), op=MPI.MIN)
        if not same:
            raise ValueError(
                f"--restart {self.folder}: the mesh differs from the checkpoint's (the same "
                "number of cells, other coordinates or another partition)"
            )

    def resume(self, roots: dict) -> None:
        """Put the checkpoint's state into the run's objects (built again)."""
        restore(roots, self.state["objects"], self.comm)


def _difference(meta: dict, identity: dict) -> str:
    """The first difference between the checkpoint's run and this one, as a phrase."""
    for key in ("scene", "format"):  # the ranks: read_checkpoint
        if meta.get(key) != identity[key]:
            what = {"format": "output format"}.get(key, key)
            return f"the {what} is {identity[key]} here, {meta.get(key)} in the checkpoint"
    for group in ("parameters", "numerics"):
        theirs, ours = meta.get(group, {}), identity[group]
        for key in sorted(set(theirs) | set(ours)):
            if not _equal(theirs.get(key), ours.get(key)):
                return (
                    f"{group} {key} is {ours.get(key)!r} here, {theirs.get(key)!r} in the "
                    "checkpoint"
                )
    return ""


def _equal(a: Any, b: Any) -> bool:
    """JSON turns tuples into lists."""
    if isinstance(a, list | tuple) and isinstance(b, list | tuple):
        return len(a) == len(b) and all(_equal(x, y) for x, y in zip(a, b, strict=True))
    return bool(a == b)
