"""Output cost of the ParaView writers on a scene's mesh: time per step and rank 0's peak
memory, for the XDMF writer (every rank writes its rows) and the VTU writer (rank 0 gathers).

    mpirun -n 2 .venv/bin/python scripts/bench-output.py hertz3d --h-contact 0.006 \
        --format xdmf --steps 3

Builds the scene's problem (mesh and unknowns, not solved) and writes the fields an
obstacle run writes (displacement, contact_pressure, gap, contact_status at the nodes,
von_mises in the cells) with smooth values, ``--steps`` times. Prints one JSON line (rank 0):
dofs, cells, the mean and largest time of a step's write, and rank 0's peak resident memory
before the first write and after the last (``ru_maxrss``; one format per process, since the
peak never falls).
"""

from __future__ import annotations

import argparse
import json
import resource
import tempfile
import time
from pathlib import Path

import dolfinx
import numpy as np
from mpi4py import MPI

from contactfx import _compat
from contactfx.driver import setup
from contactfx.driver.pipeline import WRITERS
from contactfx.numerics import Numerics
from contactfx.scenes import get_scene


def peak_mib() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("scene")
    ap.add_argument("--h-contact", type=float, required=True)
    ap.add_argument("--format", choices=tuple(WRITERS), required=True)
    ap.add_argument("--steps", type=int, default=3)
    ap.add_argument("--out", type=Path, default=None)
    ns = ap.parse_args()
    comm = MPI.COMM_WORLD
    cls = get_scene(ns.scene)
    scene = cls(cls.Params(h_contact=ns.h_contact))
    problem = setup(scene, Numerics(method="nitsche"), comm)
    mesh = problem.mesh
    V = _compat.function_space(mesh, "Lagrange", 1, (mesh.geometry.dim,))
    Q = _compat.function_space(mesh, "Lagrange", 1)
    D = _compat.function_space(mesh, "DG", 0)
    fields = []
    for name, space, f in (
        (
            "displacement",
            V,
            lambda x: np.vstack([np.sin(x[i] + i) for i in range(V.num_sub_spaces)]),
        ),
        ("contact_pressure", Q, lambda x: np.cos(x[0]) * x[1]),
        ("gap", Q, lambda x: x[2] if len(x) > 2 else x[1]),
        ("contact_status", Q, lambda x: (x[0] > 0) * 1.0),
        ("von_mises", D, lambda x: x[0] ** 2 + x[1]),
    ):
        g = dolfinx.fem.Function(space, name=name)
        g.interpolate(f)
        fields.append(g)
    out = ns.out or Path(comm.bcast(tempfile.mkdtemp() if comm.rank == 0 else None, root=0))
    before = peak_mib()
    times = []
    writer = WRITERS[ns.format](
        out, scene.name, mesh, facets=getattr(problem, "contact_facets", None)
    )
    with writer:
        for k in range(ns.steps):
            comm.barrier()
            t0 = time.perf_counter()
            writer.write((k + 1) / ns.steps, fields)
            comm.barrier()
            times.append(time.perf_counter() - t0)
    after = peak_mib()
    peaks = comm.gather((before, after), root=0)
    if comm.rank == 0:
        size = sum(f.stat().st_size for f in out.iterdir())
        print(
            json.dumps(
                {
                    "format": ns.format,
                    "ranks": comm.size,
                    "dofs": V.dofmap.index_map.size_global * V.dofmap.index_map_bs,
                    "cells": mesh.topology.index_map(mesh.topology.dim).size_global,
                    "step_mean_s": float(np.mean(times)),
                    "step_max_s": float(np.max(times)),
                    "rank0_peak_before_mib": peaks[0][0],
                    "rank0_peak_after_mib": peaks[0][1],
                    "rank1_peak_after_mib": peaks[-1][1],
                    "files_mib": size / 2**20,
                }
            )
        )


if __name__ == "__main__":
    main()
