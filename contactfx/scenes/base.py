"""Scenes: a named contact problem (geometry, material, supports, obstacle, load program,
optional closed-form reference) and the driver that solves it with a chosen method.
"""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar

import dolfinx
import dolfinx.fem.petsc
import numpy as np
import ufl
from mpi4py import MPI
from petsc4py import PETSc

from contactfx import _compat
from contactfx.contact.gap import ContactSurface
from contactfx.contact.laws import active
from contactfx.contact.nitsche import Nitsche
from contactfx.contact.obstacles import Obstacle
from contactfx.contact.penalty import Penalty
from contactfx.io.provenance import versions, write_json
from contactfx.io.xdmf import ResultsWriter
from contactfx.mechanics.elasticity import Elastic
from contactfx.solvers.loadstep import StepRecord, run_load_program
from contactfx.solvers.snes import GAMG_OPTIONS, ContactSNES

__all__ = ["param", "SceneParams", "Numerics", "Scene", "RunResult", "METHODS"]

METHODS = ("nitsche", "penalty", "vi")


def param(default: Any, help: str, *, positive: bool = False, choices: tuple | None = None):
    """A scene / numerics parameter with its help text and validation rule."""
    return field(default=default, metadata={"help": help, "positive": positive, "choices": choices})


def validate(obj) -> None:
    """Check every field's rule; raise ValueError naming the parameter."""
    for f in dataclasses.fields(obj):
        value = getattr(obj, f.name)
        name = f.name.replace("_", "-")
        if f.metadata.get("positive") and not value > 0:
            raise ValueError(f"--{name} must be > 0, got {value}")
        choices = f.metadata.get("choices")
        if choices is not None and value not in choices:
            allowed = ", ".join(str(c) for c in choices)
            raise ValueError(f"--{name} must be one of {allowed}, got {value}")


@dataclass(frozen=True)
class SceneParams:
    """Base of every scene's parameter dataclass: fields made with :func:`param` are
    validated on construction."""

    def __post_init__(self) -> None:
        validate(self)


@dataclass(frozen=True)
class Numerics:
    """How the contact problem is discretised and solved (shared by all scenes)."""

    method: str = param("nitsche", "enforcement method", choices=METHODS)
    theta: int = param(1, "Nitsche variant: 1 symmetric, 0 incomplete, -1 skew", choices=(1, 0, -1))
    gamma0: float = param(10.0, "Nitsche parameter, gamma_N = gamma0 E / h", positive=True)
    penalty: float = param(10.0, "penalty parameter, kappa = penalty E / h", positive=True)
    degree: int = param(1, "Lagrange degree of the displacement", choices=(1, 2))
    steps: int = param(1, "load steps", positive=True)
    solver: str = param("lu", "linear solver: MUMPS LU or GMRES + GAMG", choices=("lu", "gamg"))

    def __post_init__(self) -> None:
        validate(self)

    def method_object(self):
        if self.method == "nitsche":
            return Nitsche(theta=self.theta, gamma0=self.gamma0)
        if self.method == "penalty":
            return Penalty(kappa0=self.penalty)
        return None


@dataclass
class RunResult:
    """Summary of a run (what run.json holds)."""

    data: dict

    def __getitem__(self, key: str):
        return self.data[key]


class Scene:
    """Base class of scenes. Subclasses set ``name``, ``summary``, ``Params`` and implement the
    geometry / physics hooks below; ``run`` is shared."""

    name: ClassVar[str]
    summary: ClassVar[str]
    Params: ClassVar[type]
    numerics_defaults: ClassVar[dict] = {}
    #: multiplicity of the modelled part (4 for a quarter model) for forces
    symmetry: ClassVar[float] = 1.0

    def __init__(self, params) -> None:
        self.p = params

    # -- hooks -------------------------------------------------------------------------
    def material(self) -> Elastic:
        return Elastic(self.p.E, self.p.nu)

    def build_mesh(self, comm):
        """Return (mesh, facet_tags)."""
        raise NotImplementedError

    contact_tag: ClassVar[int]

    def obstacle(self) -> Obstacle:
        raise NotImplementedError

    def obstacle_offset(self, t: float, gdim: int) -> np.ndarray:
        """Rigid displacement of the obstacle at load factor t."""
        return np.zeros(gdim)

    def dirichlet(self, V, facet_tags) -> list:
        raise NotImplementedError

    def load(self, v, ds, t):
        """External load (linear form in v); t is the load-factor Constant. None for none."""
        return None

    def contact_size(self, measure: float) -> float:
        """Contact half-width / radius from the measure of the contact set (full model)."""
        return 0.5 * measure

    def reference(self, force: float) -> dict[str, float]:
        """Closed-form contact half-width ``a`` and peak pressure ``p0`` at ``force``."""
        return {}

    def exact_displacement(self, x):
        """UFL expression of the exact displacement, or None."""
        return None

    def h_contact(self) -> float:
        return self.p.h_contact

    def pressure_scores(self, x: np.ndarray, p: np.ndarray, force: float) -> dict[str, float]:
        """Scene-specific pointwise scores (local maxima over this rank's surface nodes x with
        nodal pressure p); reduced with MAX over ranks."""
        return {}

    def initial_guess(self, u, t: float) -> None:
        """Set a starting state before the first load step (default: zero)."""

    # -- driver ------------------------------------------------------------------------
    def run(
        self,
        numerics: Numerics,
        *,
        comm: MPI.Comm = MPI.COMM_WORLD,
        out: Path | None = None,
        petsc_options: dict | None = None,
        verbose: bool = True,
    ) -> RunResult:
        return _Run(self, numerics, comm, out, petsc_options or {}, verbose).execute()


def _say(comm, verbose: bool, msg: str) -> None:
    if verbose and comm.rank == 0:
        print(msg, flush=True)


class _Run:
    def __init__(self, scene: Scene, numerics: Numerics, comm, out, petsc_options, verbose):
        self.scene, self.num, self.comm = scene, numerics, comm
        self.out = None if out is None else Path(out)
        self.petsc_options = petsc_options
        self.verbose = verbose
        self.timings: dict[str, float] = {}

    def execute(self) -> RunResult:
        scene, num, comm = self.scene, self.num, self.comm
        material = scene.material()
        obstacle = scene.obstacle()
        if self.out is not None:
            _prepare_output(self.out, comm)

        t0 = time.perf_counter()
        mesh, facet_tags = scene.build_mesh(comm)
        self.timings["mesh"] = time.perf_counter() - t0
        gdim = mesh.geometry.dim

        V = _compat.function_space(mesh, "Lagrange", num.degree, (gdim,))
        u = dolfinx.fem.Function(V, name="displacement")
        du, v = ufl.TrialFunction(V), ufl.TestFunction(V)
        bcs = scene.dirichlet(V, facet_tags)
        qdeg = 2 * num.degree + 2
        ds = ufl.Measure("ds", domain=mesh, subdomain_data=facet_tags)
        dsc = ds(scene.contact_tag, metadata={"quadrature_degree": qdeg})
        dsc_fine = ds(scene.contact_tag, metadata={"quadrature_degree": 12})
        offset = dolfinx.fem.Constant(mesh, np.zeros(gdim))
        tload = dolfinx.fem.Constant(mesh, 0.0)
        h = _compat.cell_diameter(mesh)
        surface = ContactSurface(u, v, dsc, obstacle, offset, material.sigma, material.E, h)
        method = num.method_object()

        t0 = time.perf_counter()
        eps = ufl.sym(ufl.grad(v))
        a_form = dolfinx.fem.form(ufl.inner(material.sigma(du), eps) * ufl.dx)
        L = scene.load(v, ds, tload)
        if L is None:
            L = ufl.inner(dolfinx.fem.Constant(mesh, np.zeros(gdim)), v) * ufl.dx
        L_form = dolfinx.fem.form(L)
        F_c = J_c = None
        if method is not None:
            Fc_ufl = method.residual(surface)
            F_c = dolfinx.fem.form(Fc_ufl)
            J_c = dolfinx.fem.form(ufl.derivative(Fc_ufl, u, du))
        post = _PostProcessor(scene, num, surface, method, dsc, dsc_fine, material)
        self.timings["compile"] = time.perf_counter() - t0

        options = dict(GAMG_OPTIONS) if num.solver == "gamg" else {}
        if num.method == "vi":
            options["snes_type"] = "vinewtonrsls"
        prefix = f"contactfx_{scene.name.replace('-', '_')}_"
        solver = ContactSNES(
            u,
            stiffness=a_form,
            load=L_form,
            contact_residual=F_c,
            contact_jacobian=J_c,
            bcs=bcs,
            prefix=prefix,
            options=options,
            user_options=self.petsc_options,
            near_nullspace=num.solver == "gamg",
        )
        bounds = _VIBounds(V, facet_tags, scene, obstacle) if num.method == "vi" else None

        def apply_load(t: float) -> None:
            tload.value = t
            offset.value[:] = scene.obstacle_offset(t, gdim)
            if bounds is not None:
                bounds.update(offset.value)
                solver.set_bounds(bounds.lower, bounds.upper)

        scene.initial_guess(u, 1.0 / num.steps)
        steps_log: list[dict] = []
        xdmf_path = None if self.out is None else self.out / f"{scene.name}.xdmf"

        def on_step(rec: StepRecord) -> None:
            summary = post.evaluate(solver)
            entry = {
                "step": rec.step,
                "load": rec.load,
                "newton": rec.stats.newton,
                "ksp": rec.stats.ksp,
                "cutbacks": rec.cutbacks,
                "reason": rec.stats.reason,
                "force": summary["force"],
                "contact_half_width": summary["a"],
            }
            steps_log.append(entry)
            if writer is not None:
                t_out = time.perf_counter()
                writer.write(rec.load, post.fields(u))
                self.timings["output"] = self.timings.get("output", 0.0) + (
                    time.perf_counter() - t_out
                )
            _say(
                comm,
                self.verbose,
                f"  step {rec.step:3d}  load {rec.load:6.3f}  newton {rec.stats.newton:3d}  "
                f"ksp {rec.stats.ksp:4d}  force {summary['force']:.6g}  a {summary['a']:.6g}",
            )

        writer = None
        try:
            if xdmf_path is not None:
                writer = ResultsWriter(xdmf_path, mesh).__enter__()
            t_solve0 = time.perf_counter()
            a_before = solver.timer.assembly
            records = run_load_program(solver, apply_load, steps=num.steps, on_step=on_step)
            total = time.perf_counter() - t_solve0
            self.timings["assembly"] = solver.timer.assembly
            self.timings["solve"] = (
                total - (solver.timer.assembly - a_before) - self.timings.get("output", 0.0)
            )
        finally:
            if writer is not None:
                writer.__exit__(None, None, None)
            if bounds is not None:
                bounds.destroy()

        summary = post.evaluate(solver)
        dofs = V.dofmap.index_map.size_global * V.dofmap.index_map_bs
        data: dict[str, Any] = {
            "status": "completed",
            "scene": scene.name,
            "parameters": dataclasses.asdict(scene.p),
            "numerics": dataclasses.asdict(num),
            "petsc_options": {k: str(v) for k, v in self.petsc_options.items()},
            "petsc_prefix": prefix,
            "versions": versions(),
            "ranks": comm.size,
            "dofs": dofs,
            "cells": mesh.topology.index_map(mesh.topology.dim).size_global,
            "h_contact": scene.h_contact(),
            "newton_iterations": sum(r.stats.newton for r in records),
            "ksp_iterations": sum(r.stats.ksp for r in records),
            "steps": steps_log,
            "timings": dict(self.timings),
            "force": summary["force"],
            "contact_half_width": summary["a"],
            "peak_pressure": summary["p0"],
            "max_penetration": summary["penetration"],
            "xdmf": None if xdmf_path is None else str(xdmf_path),
        }
        data["reference"] = post.reference_errors(summary)
        data["scores"] = post.scores(summary["force"])
        data["errors"] = post.field_errors()
        solver.destroy()
        if self.out is not None:
            write_json(self.out / "run.json", data, comm)
        return RunResult(data)


def _prepare_output(out: Path, comm) -> None:
    """Create the output folder and remove a previous run.json; fail on every rank alike."""
    error = None
    if comm.rank == 0:
        try:
            out.mkdir(parents=True, exist_ok=True)
            probe = out / ".write-test"
            probe.write_text("")
            probe.unlink()
            (out / "run.json").unlink(missing_ok=True)
        except OSError as err:
            error = f"output folder {out} is not writable: {err.strerror or err}"
    error = comm.bcast(error, root=0)
    if error is not None:
        raise ValueError(error)


class _VIBounds:
    """u_d <= height(x_t + offset_t) - x_d + offset_d on the contact facets' dofs (linearised
    vertical gap): the bound constraints of the SNES-VI reference."""

    def __init__(self, V, facet_tags, scene: Scene, obstacle: Obstacle) -> None:
        mesh = V.mesh
        gdim = mesh.geometry.dim
        self.V, self.obstacle, self.gdim = V, obstacle, gdim
        facets = facet_tags.indices[facet_tags.values == scene.contact_tag]
        Vd, collapse_map = V.sub(gdim - 1).collapse()
        dofs = _compat.locate_dofs_topological((V.sub(gdim - 1), Vd), gdim - 1, facets)
        self.dofs = np.asarray(dofs[0])  # indices into V's local (unrolled) dofs
        coords = _compat.dof_coordinates(Vd)[np.asarray(dofs[1])]
        self.coords = coords[:, :gdim]
        self._template = dolfinx.fem.Function(V)  # owns the memory the bounds are copied from
        x = _compat.petsc_vec(self._template)
        self.lower = x.copy()
        self.upper = x.copy()
        self.lower.set(PETSc.NINFINITY)
        self.upper.set(PETSc.INFINITY)
        bs = V.dofmap.index_map_bs
        n_owned = V.dofmap.index_map.size_local * bs
        keep = self.dofs < n_owned
        self.dofs, self.coords = self.dofs[keep], self.coords[keep]

    def update(self, offset: np.ndarray) -> None:
        t = self.coords[:, : self.gdim - 1] - offset[: self.gdim - 1]
        bound = self.obstacle.height(t) + offset[self.gdim - 1] - self.coords[:, self.gdim - 1]
        bound = np.where(np.isfinite(bound), bound, PETSc.INFINITY)
        arr = self.upper.getArray()
        arr[self.dofs] = bound

    def destroy(self) -> None:
        self.lower.destroy()
        self.upper.destroy()


class _PostProcessor:
    """Contact force, pressure, contact size, penetration and field errors, compiled once."""

    def __init__(self, scene, num, surface: ContactSurface, method, dsc, dsc_fine, material):
        self.scene, self.num, self.surface, self.method = scene, num, surface, method
        mesh = surface.u.function_space.mesh
        self.mesh = mesh
        gdim = mesh.geometry.dim
        self.gdim = gdim
        u = surface.u
        Q1 = _compat.function_space(mesh, "Lagrange", 1)
        self.Q1 = Q1
        q = ufl.TestFunction(Q1)
        self.pressure = dolfinx.fem.Function(Q1, name="contact_pressure")
        self.gap = dolfinx.fem.Function(Q1, name="gap")
        self.status = dolfinx.fem.Function(Q1, name="contact_status")
        DG0 = _compat.function_space(mesh, "DG", 0)
        self.vm = dolfinx.fem.Function(DG0, name="von_mises")
        self.vm_expr = _compat.expression(material.von_mises(u), DG0)
        self.gap_expr = _compat.expression(surface.gap(), Q1)
        self.mass1 = _assemble_vec(dolfinx.fem.form(q * dsc))
        n = surface.normal()
        if method is not None:
            p = method.pressure(surface)
            self.force_form = dolfinx.fem.form(p * n[gdim - 1] * dsc)
            self.p_form = dolfinx.fem.form(p * q * dsc)
            self.measure_form = dolfinx.fem.form(active(p) * dsc_fine)
        else:
            Qk = _compat.function_space(mesh, "Lagrange", num.degree)
            self.Qk = Qk
            self.massk = _assemble_vec(dolfinx.fem.form(ufl.TestFunction(Qk) * dsc))
            self.pk = dolfinx.fem.Function(Qk)
            self.measure_form = dolfinx.fem.form(self.status * dsc)
        self.exact = scene.exact_displacement(ufl.SpatialCoordinate(mesh))
        if self.exact is not None:
            e = u - self.exact
            dxq = ufl.dx(metadata={"quadrature_degree": 2 * num.degree + 4})
            self.err_forms = {
                "L2": dolfinx.fem.form(ufl.inner(e, e) * dxq),
                "H1": dolfinx.fem.form(ufl.inner(ufl.grad(e), ufl.grad(e)) * dxq),
            }
            self.norm_forms = {
                "L2": dolfinx.fem.form(ufl.inner(self.exact, self.exact) * dxq),
                "H1": dolfinx.fem.form(ufl.inner(ufl.grad(self.exact), ufl.grad(self.exact)) * dxq),
            }

    def _sum(self, form) -> float:
        return self.mesh.comm.allreduce(dolfinx.fem.assemble_scalar(form), op=MPI.SUM)

    def evaluate(self, solver: ContactSNES) -> dict[str, float]:
        pv = _compat.petsc_vec(self.pressure)
        m = self.mass1.getArray()
        on_surface = m > 0.0
        if self.method is not None:
            force = self._sum(self.force_form)
            b = _assemble_vec(self.p_form)
            arr = pv.getArray()
            arr[:] = 0.0
            arr[on_surface] = b.getArray()[on_surface] / m[on_surface]
            b.destroy()
        else:
            force = self._vi_pressure(solver)
        pv.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
        p_local = self.pressure.x.array
        p_max = self.mesh.comm.allreduce(float(p_local.max(initial=0.0)), op=MPI.MAX)
        st = self.status.x.array
        st[:] = (p_local > 1e-10 * max(p_max, 1e-300)).astype(float)
        self.gap.interpolate(self.gap_expr)
        gap_surface = self.gap.x.array[: len(m)][on_surface]
        penetration = self.mesh.comm.allreduce(
            float(max(-gap_surface.min(initial=0.0), 0.0)), op=MPI.MAX
        )
        measure = self._sum(self.measure_form) * self.scene.symmetry
        return {
            "force": force * self.scene.symmetry,
            "a": self.scene.contact_size(measure),
            "p0": p_max,
            "penetration": penetration,
        }

    def _vi_pressure(self, solver: ContactSNES) -> float:
        """Nodal contact pressure from the reaction K u - b at the constrained dofs."""
        r = solver.K.createVecLeft()
        solver.K.mult(_compat.petsc_vec(self.surface.u), r)
        r.axpy(-1.0, solver.b)
        bs = self.gdim
        mk = self.massk.getArray()
        reac = -r.getArray()[self.gdim - 1 :: bs]
        pk = _compat.petsc_vec(self.pk).getArray()
        pk[:] = 0.0
        on = mk > 0.0
        pk[on] = np.maximum(reac[on], 0.0) / mk[on]
        force = self.mesh.comm.allreduce(float(np.sum(np.maximum(reac[on], 0.0))), op=MPI.SUM)
        r.destroy()
        _compat.petsc_vec(self.pk).ghostUpdate(
            addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD
        )
        self.pressure.interpolate(self.pk)
        return force

    def scores(self, force: float) -> dict[str, float]:
        m = self.mass1.getArray()
        on = m > 0.0
        x = _compat.dof_coordinates(self.Q1)[: len(m)][on]
        p = self.pressure.x.array[: len(m)][on]
        local = self.scene.pressure_scores(x, p, force)
        return {k: self.mesh.comm.allreduce(v, op=MPI.MAX) for k, v in local.items()}

    def fields(self, u) -> list:
        self.vm.interpolate(self.vm_expr)
        return [u, self.vm, self.pressure, self.gap, self.status]

    def reference_errors(self, summary: dict) -> dict[str, float]:
        ref = self.scene.reference(summary["force"])
        out: dict[str, float] = {}
        if "force" in ref:
            out["force"] = ref["force"]
            out["force_rel_error"] = abs(summary["force"] - ref["force"]) / abs(ref["force"])
        for key in ("a", "p0"):
            if key in ref:
                computed = summary[key]
                out[key] = ref[key]
                out[f"{key}_computed"] = computed
                out[f"{key}_rel_error"] = abs(computed - ref[key]) / abs(ref[key])
        if "a" in ref:
            out["a_error_over_h"] = abs(summary["a"] - ref["a"]) / self.scene.h_contact()
        for key, value in ref.items():
            out.setdefault(key, value)
        return out

    def field_errors(self) -> dict[str, float]:
        if self.exact is None:
            return {}
        out = {}
        for key in ("L2", "H1"):
            err = np.sqrt(self._sum(self.err_forms[key]))
            norm = np.sqrt(self._sum(self.norm_forms[key]))
            out[f"displacement_{key}"] = err
            out[f"displacement_{key}_rel"] = err / norm
        return out


def _assemble_vec(form) -> PETSc.Vec:
    b = _compat.create_vector(form)
    return _compat.assemble_vector(b, form)
