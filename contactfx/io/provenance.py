"""run.json: the full parameter set, versions, iterations, timings and errors of a run."""

from __future__ import annotations

import json
import os
import platform
from pathlib import Path

import dolfinx
from petsc4py import PETSc

import contactfx

__all__ = ["versions", "write_json", "write_json_local"]


def versions() -> dict[str, str]:
    petsc = ".".join(str(v) for v in PETSc.Sys.getVersion())
    return {
        "contactfx": contactfx.__version__,
        "dolfinx": dolfinx.__version__,
        "petsc": petsc,
        "python": platform.python_version(),
    }


def write_json(path: Path, data: dict, comm) -> None:
    """Write ``data`` as JSON on rank 0 (atomically: a complete file or none)."""
    if comm.rank == 0:
        write_json_local(path, data)
    comm.barrier()


def write_json_local(path: Path, data: dict) -> None:
    """Write ``data`` as JSON from this process alone (no collective), atomically."""
    path = Path(path)
    tmp = path.with_suffix(path.suffix + f".{os.getpid()}.tmp")
    tmp.write_text(json.dumps(data, indent=2, default=float) + "\n")
    tmp.replace(path)
