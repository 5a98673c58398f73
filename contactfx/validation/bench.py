"""``contactfx bench SCENE --levels N``: refinement study with timings and a linear yardstick.

Per level: dofs, Newton and KSP iterations, time per phase, errors in a and p0, and the time of
one linear-elastic assemble + solve on the same mesh with the same linear solver. Under
``mpirun -n 2`` each level also runs on one rank (rank 0 alone) to give the parallel speed-up,
next to the machine's ceiling measured by a trivially parallel NumPy loop.
"""

from __future__ import annotations

import argparse
import csv
import dataclasses
import time
from pathlib import Path

import numpy as np
import ufl
from mpi4py import MPI
from petsc4py import PETSc

__all__ = ["bench_main", "linear_elastic_time", "parallel_ceiling"]


def linear_elastic_time(scene, degree: int, comm, solver: str = "lu") -> tuple[float, int]:
    """Wall time of assembling and solving the scene's linear-elastic problem (the contact
    boundary loaded by a uniform pressure) with MUMPS LU or GMRES + GAMG; and its dofs."""
    import dolfinx
    import dolfinx.fem.petsc

    from contactfx import _compat
    from contactfx.solvers.snes import GAMG_OPTIONS, rigid_body_modes

    mesh, facet_tags = scene.build_mesh(comm)
    gdim = mesh.geometry.dim
    V = _compat.function_space(mesh, "Lagrange", degree, (gdim,))
    material = scene.material()
    du, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    ds = ufl.Measure("ds", domain=mesh, subdomain_data=facet_tags)
    a = dolfinx.fem.form(ufl.inner(material.sigma(du), ufl.sym(ufl.grad(v))) * ufl.dx)
    L = dolfinx.fem.form(-1.0 * v[gdim - 1] * ds(scene.contact_tag))
    bcs = scene.dirichlet(V, facet_tags)
    u = dolfinx.fem.Function(V)
    ksp = PETSc.KSP().create(comm)
    prefix = "contactfx_linear_"
    opts = PETSc.Options()
    defaults = GAMG_OPTIONS if solver == "gamg" else {
        "ksp_type": "preonly", "pc_type": "lu", "pc_factor_mat_solver_type": "mumps"}  # fmt: skip
    for key, value in defaults.items():
        opts[prefix + key] = str(value)
    ksp.setOptionsPrefix(prefix)
    comm.barrier()
    t0 = time.perf_counter()
    A = dolfinx.fem.petsc.assemble_matrix(a, bcs=bcs)
    A.assemble()
    if solver == "gamg":
        A.setNearNullSpace(rigid_body_modes(V))
    b = dolfinx.fem.petsc.assemble_vector(L)
    dolfinx.fem.petsc.apply_lifting(b, [a], [bcs])
    b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    dolfinx.fem.petsc.set_bc(b, bcs)
    ksp.setOperators(A)
    ksp.setFromOptions()
    ksp.solve(b, _compat.petsc_vec(u))
    comm.barrier()
    elapsed = time.perf_counter() - t0
    for obj in (ksp, A, b):
        obj.destroy()
    for key in defaults:
        opts.delValue(prefix + key)
    return elapsed, V.dofmap.index_map.size_global * V.dofmap.index_map_bs


def parallel_ceiling(comm, n: int = 3_000_000, repeats: int = 3) -> float:
    """Speed-up this machine's ranks give at all: the same NumPy work on rank 0 alone, then
    on every rank at once (each rank does the full work; ideal = 1 x time of one)."""

    def work() -> float:
        x = np.linspace(0.0, 1.0, n)
        t0 = time.perf_counter()
        for _ in range(repeats):
            np.sqrt(x * x + 1.0).sum()
        return time.perf_counter() - t0

    comm.barrier()
    alone = work() if comm.rank == 0 else 0.0
    comm.barrier()
    together = comm.allreduce(work(), op=MPI.MAX)
    alone = comm.bcast(alone, root=0)
    return comm.size * alone / together


def _parser(scenes) -> argparse.ArgumentParser:
    from contactfx.cli import _Parser

    p = _Parser(prog="contactfx bench", description="refinement study with timings")
    p.add_argument("scene", choices=sorted(scenes))
    p.add_argument("--levels", type=int, default=3, help="refinement levels (h halves)")
    p.add_argument("--method", default="nitsche", help="comma-separated methods")
    p.add_argument("--theta", type=int, default=1)
    p.add_argument("--gamma0", type=float, default=10.0)
    p.add_argument("--degree", type=int, default=1)
    p.add_argument("--solver", default="lu", choices=("lu", "gamg"))
    p.add_argument("--out", type=Path, default=None, help="folder for bench.csv")
    return p


def bench_main(argv: list[str], petsc_options: dict, comm) -> int:
    from contactfx.scenes import SCENES, Numerics

    ns = _parser(SCENES).parse_args(argv)
    if ns.levels < 1:
        raise ValueError(f"--levels must be >= 1, got {ns.levels}")
    scene_cls = SCENES[ns.scene]
    base = scene_cls.Params()
    if not hasattr(base, "h_contact"):
        raise ValueError(f"scene {ns.scene} has no mesh size to refine")
    ceiling = parallel_ceiling(comm) if comm.size > 1 else 1.0
    rows = []
    for level in range(ns.levels):
        scale = 0.5**level
        sizes = {"h_contact": base.h_contact * scale}
        params = dataclasses.replace(base, **sizes)
        scene = scene_cls(params)
        for method in ns.method.split(","):
            num = Numerics(
                method=method, theta=ns.theta, gamma0=ns.gamma0, degree=ns.degree,
                solver=ns.solver, **scene_cls.numerics_defaults,
            )  # fmt: skip
            res = scene.run(num, comm=comm, petsc_options=petsc_options, verbose=False).data
            lin, _ = linear_elastic_time(scene, ns.degree, comm, ns.solver)
            t = res["timings"]
            contact = t["assembly"] + t["solve"]
            row = {
                "level": level,
                "method": method,
                "h": params.h_contact,
                "dofs": res["dofs"],
                "ranks": comm.size,
                "newton": res["newton_iterations"],
                "ksp": res["ksp_iterations"],
                "t_mesh": t["mesh"],
                "t_compile": t["compile"],
                "t_assembly": t["assembly"],
                "t_solve": t["solve"],
                "t_linear": lin,
                "contact_over_linear": contact / lin,
                "a_err": res["reference"].get("a_rel_error", np.nan),
                "p0_err": res["reference"].get("p0_rel_error", np.nan),
            }
            if comm.size > 1:
                serial = None
                if comm.rank == 0:
                    serial = scene.run(num, comm=MPI.COMM_SELF, verbose=False).data
                serial = comm.bcast(serial, root=0)
                ts = serial["timings"]
                speedup = (ts["assembly"] + ts["solve"]) / contact
                row["newton_serial"] = serial["newton_iterations"]
                row["speedup"] = speedup
                row["speedup_over_ceiling"] = speedup / ceiling
            rows.append(row)
            if comm.rank == 0:
                print(_format_row(row), flush=True)
    if comm.rank == 0:
        if comm.size > 1:
            print(f"parallel ceiling of this machine with {comm.size} ranks: {ceiling:.2f}x")
        if ns.out is not None:
            ns.out.mkdir(parents=True, exist_ok=True)
            with open(ns.out / "bench.csv", "w", newline="") as fh:
                writer = csv.DictWriter(fh, fieldnames=list(rows[0]))
                writer.writeheader()
                writer.writerows(rows)
            print(f"table: {ns.out / 'bench.csv'}")
    return 0


_HEADER_DONE = False


def _format_row(row: dict) -> str:
    global _HEADER_DONE
    cols = [
        ("level", "{:>5d}"), ("method", "{:>8s}"), ("dofs", "{:>8d}"), ("newton", "{:>6d}"),
        ("ksp", "{:>5d}"), ("t_mesh", "{:>7.2f}"), ("t_compile", "{:>9.2f}"),
        ("t_assembly", "{:>10.2f}"), ("t_solve", "{:>7.2f}"), ("t_linear", "{:>8.2f}"),
        ("contact_over_linear", "{:>19.2f}"), ("a_err", "{:>7.2%}"), ("p0_err", "{:>7.2%}"),
    ]  # fmt: skip
    if "speedup" in row:
        cols += [("newton_serial", "{:>13d}"), ("speedup", "{:>7.2f}"),
                 ("speedup_over_ceiling", "{:>20.2f}")]  # fmt: skip
    line = " ".join(fmt.format(row[k]) for k, fmt in cols)
    if not _HEADER_DONE:
        _HEADER_DONE = True
        header = " ".join(f"{k:>{len(fmt.format(row[k]))}s}" for k, fmt in cols)
        return header + "\n" + line
    return line
