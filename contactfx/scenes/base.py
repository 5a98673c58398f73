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
from contactfx.contact.augmented_lagrangian import (
    AugmentedLagrangianSSN,
    AugmentedLagrangianUzawa,
)
from contactfx.contact.gap import ContactSurface
from contactfx.contact.laws import active, friction_law, positive_part
from contactfx.contact.nitsche import Nitsche
from contactfx.contact.obstacles import Obstacle
from contactfx.contact.penalty import Penalty
from contactfx.io.provenance import versions, write_json
from contactfx.io.xdmf import ResultsWriter
from contactfx.mechanics.elasticity import Elastic
from contactfx.solvers.loadstep import StepRecord, run_load_program
from contactfx.solvers.snes import GAMG_OPTIONS, ContactSNES
from contactfx.solvers.uzawa import Uzawa

__all__ = ["param", "SceneParams", "Numerics", "Scene", "RunResult", "METHODS"]

METHODS = ("nitsche", "penalty", "vi", "al-uzawa", "al-ssn")
FRICTION_LAWS = ("none", "tresca", "coulomb")
FORMULATIONS = ("displacement", "mixed-up")
#: methods the mixed u-p formulation supports (al-ssn has its own mixed (u, lambda) space,
#: vi bounds the displacement dofs of a displacement-only space)
MIXED_UP_METHODS = ("nitsche", "penalty", "al-uzawa")


def param(
    default: Any,
    help: str,
    *,
    positive: bool = False,
    nonnegative: bool = False,
    choices: tuple | None = None,
):
    """A scene / numerics parameter with its help text and validation rule."""
    meta = {"help": help, "positive": positive, "nonnegative": nonnegative, "choices": choices}
    return field(default=default, metadata=meta)


def validate(obj) -> None:
    """Check every field's rule; raise ValueError naming the parameter."""
    for f in dataclasses.fields(obj):
        value = getattr(obj, f.name)
        name = f.name.replace("_", "-")
        if f.metadata.get("positive") and not value > 0:
            raise ValueError(f"--{name} must be > 0, got {value}")
        if f.metadata.get("nonnegative") and not value >= 0:
            raise ValueError(f"--{name} must be >= 0, got {value}")
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
    """How the contact problem is discretised and solved, and the friction law (shared by all
    scenes)."""

    method: str = param("nitsche", "enforcement method", choices=METHODS)
    theta: int = param(1, "Nitsche variant: 1 symmetric, 0 incomplete, -1 skew", choices=(1, 0, -1))
    gamma0: float = param(10.0, "Nitsche parameter, gamma_N = gamma0 E / h", positive=True)
    penalty: float = param(10.0, "penalty parameter, kappa = penalty E / h", positive=True)
    r0: float = param(10.0, "augmented Lagrangian augmentation, r = r0 E / h", positive=True)
    ncp: str = param("min", "al-ssn complementarity function: min (Alart-Curnier) or fb "
                     "(Fischer-Burmeister)", choices=("min", "fb"))  # fmt: skip
    al_tol: float = param(1e-8, "al-uzawa stop: max nodal multiplier change / max multiplier",
                          positive=True)  # fmt: skip
    al_max_it: int = param(100, "al-uzawa maximal outer iterations", positive=True)
    friction: str = param("none", "friction law", choices=FRICTION_LAWS)
    mu: float = param(0.0, "Coulomb friction coefficient", nonnegative=True)
    threshold: float = param(0.0, "Tresca friction threshold (stress)", nonnegative=True)
    quadrature: str = param("gauss", "contact integrals of nitsche / penalty: gauss (degree "
                            "2k + 2) or nodal (at the vertices, P1 only)",
                            choices=("gauss", "nodal"))  # fmt: skip
    degree: int = param(1, "Lagrange degree of the displacement", choices=(1, 2))
    formulation: str = param("displacement", "bulk unknowns: displacement, or mixed-up "
                             "(Taylor-Hood P2 displacement / P1 pressure, near-incompressible "
                             "materials; needs --degree 2)", choices=FORMULATIONS)  # fmt: skip
    steps: int = param(1, "load steps", positive=True)
    solver: str = param("lu", "linear solver: MUMPS LU or GMRES + GAMG", choices=("lu", "gamg"))

    def __post_init__(self) -> None:
        validate(self)
        if self.friction != "none" and self.method == "vi":
            raise ValueError(
                f"friction law '{self.friction}' is not supported by method 'vi' (bound "
                "constraints are frictionless); use nitsche, penalty, al-uzawa or al-ssn"
            )
        if self.friction != "none" and self.method == "penalty":
            raise ValueError(
                f"friction law '{self.friction}' is not supported by method 'penalty' (its "
                "stick traction needs the tangential traction history); use nitsche, al-uzawa "
                "or al-ssn"
            )
        if self.mu > 0.0 and self.friction != "coulomb":
            raise ValueError(f"--mu needs --friction coulomb (got --friction {self.friction})")
        if self.threshold > 0.0 and self.friction != "tresca":
            raise ValueError(
                f"--threshold needs --friction tresca (got --friction {self.friction})"
            )
        if self.quadrature == "nodal" and (self.degree != 1 or self.method not in
                                           ("nitsche", "penalty")):  # fmt: skip
            raise ValueError(
                "--quadrature nodal needs --degree 1 and method nitsche or penalty (the "
                "augmented Lagrangian methods already collocate the contact law at the nodes)"
            )
        if self.method == "al-ssn" and self.solver != "lu":
            raise ValueError("method al-ssn is a saddle-point system: use --solver lu")
        if self.formulation == "mixed-up":
            if self.degree != 2:
                raise ValueError("formulation mixed-up is Taylor-Hood P2/P1: use --degree 2")
            if self.method not in MIXED_UP_METHODS:
                raise ValueError(
                    f"formulation mixed-up does not support method {self.method}; use "
                    + ", ".join(MIXED_UP_METHODS)
                )
            if self.solver != "lu":
                raise ValueError("formulation mixed-up is a saddle-point system: use --solver lu")

    def method_object(self):
        if self.method == "nitsche":
            return Nitsche(theta=self.theta, gamma0=self.gamma0)
        if self.method == "penalty":
            return Penalty(kappa0=self.penalty)
        if self.method == "al-uzawa":
            return AugmentedLagrangianUzawa(r0=self.r0)
        if self.method == "al-ssn":
            return AugmentedLagrangianSSN(r0=self.r0, ncp=self.ncp)
        return None

    def friction_law(self):
        return friction_law(self.friction, mu=self.mu, threshold=self.threshold)


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

    def modulus(self, mesh):
        """Young's modulus as a field over ``mesh`` (UFL) for a heterogeneous body, or None for
        the homogeneous ``material().E``."""
        return None

    def contact_modulus(self) -> float:
        """Young's modulus of the material at the contact surface: it scales the methods'
        parameters (gamma_N = gamma0 E / h, kappa, r)."""
        return self.material().E

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

    def exact_pressure(self, x, ref: dict):
        """UFL expression of the closed-form contact pressure on the contact boundary, or None.
        ``ref`` maps the keys of :meth:`reference` (at the computed force) to UFL constants."""
        return None

    def h_contact(self) -> float:
        return self.p.h_contact

    def pressure_scores(self, x: np.ndarray, p: np.ndarray, force: float) -> dict[str, float]:
        """Scene-specific pointwise scores (local maxima over this rank's surface nodes x with
        nodal pressure p); reduced with MAX over ranks."""
        return {}

    def initial_guess(self, u, t: float) -> None:
        """Set a starting state before the first load step (default: zero)."""

    #: multiplicity of the modelled part for each tangential force component
    tangential_symmetry: ClassVar[tuple] = (1.0, 1.0, 1.0)

    def friction_reference(self, summary: dict, friction) -> dict[str, float]:
        """Closed-form friction quantities (e.g. the stick size) at the computed forces."""
        return {}

    @classmethod
    def default_numerics(cls, **overrides) -> Numerics:
        """The scene's default numerics (what the command line starts from), overridden."""
        return Numerics(**{**cls.numerics_defaults, **overrides})

    def friction_scores(self, x, p, t, bound, status) -> dict[str, float]:
        """Scene-specific friction scores from the contact nodes' coordinates x, pressure p,
        tangential traction t, friction bound and status (0 open, 1 stick, 2 slip); local
        maxima, reduced with MAX over ranks."""
        return {}

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
        method = num.method_object()
        friction = num.friction_law()
        up = num.formulation == "mixed-up"
        if up and not material.lmbda > 0.0:
            raise ValueError(
                f"formulation mixed-up needs lambda > 0 (0 < nu < 0.5), got nu = {material.nu}"
            )
        if self.out is not None:
            _prepare_output(self.out, comm)

        t0 = time.perf_counter()
        mesh, facet_tags = scene.build_mesh(comm)
        self.timings["mesh"] = time.perf_counter() - t0
        modulus = scene.modulus(mesh)
        if modulus is not None:
            material = dataclasses.replace(material, modulus=modulus)
        gdim = mesh.geometry.dim
        fdim = mesh.topology.dim - 1
        if num.method == "al-uzawa" and fdim == 0:
            raise ValueError(
                "method al-uzawa needs a 2D or 3D mesh (its nodal multiplier update cannot be "
                "compiled on intervals); use al-ssn for 1D scenes"
            )
        contact_facets = facet_tags.indices[facet_tags.values == scene.contact_tag]

        # unknowns: the displacement, or (displacement, P1 field) with the field the contact
        # multiplier (al-ssn) or the pressure (mixed u-p formulation)
        mixed = method is not None and method.mixed
        split = mixed or up
        mult_shape = (gdim,) if friction is not None else ()
        extra = extra_trial = extra_test = None
        if split:
            W = _compat.mixed_space(mesh, num.degree, gdim, mult_shape if mixed else ())
            V = W.sub(0)
            V_out, out_map = V.collapse()
            state = dolfinx.fem.Function(W, name="state")
            displacement = dolfinx.fem.Function(V_out, name="displacement")
            trial, test = ufl.TrialFunction(W), ufl.TestFunction(W)
            u, extra = ufl.split(state)
            du, extra_trial = ufl.split(trial)
            v, extra_test = ufl.split(test)
        else:
            V = _compat.function_space(mesh, "Lagrange", num.degree, (gdim,))
            state = displacement = u = dolfinx.fem.Function(V, name="displacement")
            trial, test = ufl.TrialFunction(V), ufl.TestFunction(V)
            du, v = trial, test
        lam, lam_test = (extra, extra_test) if mixed else (None, None)
        p, dp, q = (extra, extra_trial, extra_test) if up else (None, None, None)
        bcs = scene.dirichlet(V, facet_tags)
        if mixed:
            bcs += _multiplier_bc(W, fdim, contact_facets, mult_shape)

        qdeg = 2 * num.degree + 2
        ds = ufl.Measure("ds", domain=mesh, subdomain_data=facet_tags)
        # nodal: the contact law at the P1 nodes only (trapezoidal rule), so a curved obstacle
        # does not over-constrain the piecewise linear surface when gamma0 / penalty is large
        rule = _vertex_rule(fdim) if num.quadrature == "nodal" else {"quadrature_degree": qdeg}
        dsc = ds(scene.contact_tag, metadata=rule)
        dsc_fine = ds(scene.contact_tag, metadata={"quadrature_degree": 12})
        ds_nodal = ds(scene.contact_tag, metadata=_vertex_rule(fdim)) if mixed else None
        offset = dolfinx.fem.Constant(mesh, np.zeros(gdim))
        tload = dolfinx.fem.Constant(mesh, 0.0)
        h = _compat.cell_diameter(mesh)

        prev = offset_prev = None  # last converged state, for the slip increment
        if friction is not None:
            prev = dolfinx.fem.Function(state.function_space)
            offset_prev = dolfinx.fem.Constant(mesh, np.zeros(gdim))
        multiplier = None
        if method is not None and method.name == "al-uzawa":
            shape = mult_shape if mult_shape else None
            multiplier = dolfinx.fem.Function(
                _compat.function_space(mesh, "Lagrange", 1, shape), name="multiplier"
            )
            lam = multiplier
        surface = ContactSurface(
            u, v, dsc, obstacle, offset, material.sigma(u, p), material.sigma(v, q),
            scene.contact_modulus(), h,
            friction=friction,
            u_prev=None if prev is None else (ufl.split(prev)[0] if split else prev),
            offset_prev=offset_prev, ds_nodal=ds_nodal, multiplier=lam, multiplier_test=lam_test,
        )  # fmt: skip

        t0 = time.perf_counter()
        a_ufl = ufl.inner(material.sigma(du, dp), ufl.sym(ufl.grad(v))) * ufl.dx
        if up:
            a_ufl += material.pressure_law(du, dp, q) * ufl.dx
        if mixed:  # a zero coupling of every component in every cell: the Jacobian's pattern
            zero = dolfinx.fem.Constant(mesh, 0.0)
            n_comp = ufl.shape(trial)[0]
            a_ufl += (
                zero
                * sum(trial[i] for i in range(n_comp))
                * sum(test[i] for i in range(n_comp))
                * ufl.dx
            )
        a_form = dolfinx.fem.form(a_ufl)
        L = scene.load(v, ds, tload)
        if L is None:
            L = ufl.inner(dolfinx.fem.Constant(mesh, np.zeros(gdim)), v) * ufl.dx
        L_form = dolfinx.fem.form(L)
        F_c = J_c = None
        if method is not None:
            Fc_ufl = method.residual(surface)
            F_c = dolfinx.fem.form(Fc_ufl)
            J_c = dolfinx.fem.form(ufl.derivative(Fc_ufl, state, trial))
        post = _PostProcessor(mesh, scene, num, surface, method, dsc, dsc_fine,
                              material.von_mises(u, p))  # fmt: skip
        update = None
        if multiplier is not None:
            update = _compat.expression(method.update(surface), multiplier.function_space)
        self.timings["compile"] = time.perf_counter() - t0

        options = dict(GAMG_OPTIONS) if num.solver == "gamg" else {}
        if num.method == "vi":
            options["snes_type"] = "vinewtonrsls"
        prefix = f"contactfx_{scene.name.replace('-', '_')}_"
        solver = ContactSNES(
            state,
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
        if multiplier is not None:
            mask = _boundary_mask(multiplier.function_space, fdim, contact_facets)
            solver = Uzawa(solver, multiplier, update, mask, tol=num.al_tol, max_it=num.al_max_it)
        bounds = _VIBounds(V, facet_tags, scene, obstacle) if num.method == "vi" else None

        def apply_load(t: float) -> None:
            tload.value = t
            offset.value[:] = scene.obstacle_offset(t, gdim)
            if bounds is not None:
                bounds.update(offset.value)
                solver.set_bounds(bounds.lower, bounds.upper)

        scene.initial_guess(state.sub(0) if split else state, 1.0 / num.steps)
        steps_log: list[dict] = []
        xdmf_path = None if self.out is None else self.out / f"{scene.name}.xdmf"
        last: dict[str, Any] = {}

        def on_step(rec: StepRecord) -> None:
            summary = post.evaluate(solver)
            last.clear()
            last.update(summary)
            if friction is not None:
                post.accumulate_slip()
            entry = {
                "step": rec.step,
                "load": rec.load,
                "newton": rec.stats.newton,
                "ksp": rec.stats.ksp,
                "outer": rec.stats.outer,
                "cutbacks": rec.cutbacks,
                "reason": rec.stats.reason,
                "force": summary["force"],
                "contact_half_width": summary["a"],
            }
            if friction is not None:
                entry["tangential_force"] = summary["tangential_force"]
                entry["stick_size"] = summary["stick_size"]
            steps_log.append(entry)
            if writer is not None:
                if split:
                    displacement.x.array[:] = state.x.array[out_map]
                _write_timed(writer, rec.load, post.fields(displacement), self.timings)
            if friction is not None:  # this step is the history of the next one
                prev.x.array[:] = state.x.array
                offset_prev.value[:] = offset.value
            outer = f"  outer {rec.stats.outer:3d}" if multiplier is not None else ""
            tangential = ""
            if friction is not None:
                tangential = f"  Q {summary['tangential_force'][0]:.6g}"
            _say(
                comm,
                self.verbose,
                f"  step {rec.step:3d}  load {rec.load:6.3f}  newton {rec.stats.newton:3d}{outer}"
                f"  ksp {rec.stats.ksp:4d}  force {summary['force']:.6g}  a {summary['a']:.6g}"
                f"{tangential}",
            )

        writer = None
        try:
            if xdmf_path is not None:
                writer = ResultsWriter(xdmf_path, mesh).__enter__()
            records = _timed_load_program(solver, apply_load, num.steps, on_step, self.timings)
        finally:
            if writer is not None:
                writer.__exit__(None, None, None)
            if bounds is not None:
                bounds.destroy()

        summary = last
        dofs = V.dofmap.index_map.size_global * V.dofmap.index_map_bs
        if split:
            dofs = state.function_space.dofmap.index_map.size_global
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
            "outer_iterations": sum(r.stats.outer for r in records),
            "steps": steps_log,
            "timings": dict(self.timings),
            "force": summary["force"],
            "contact_half_width": summary["a"],
            "peak_pressure": summary["p0"],
            "max_penetration": summary["penetration"],
            "complementarity": summary["complementarity"],
            "xdmf": None if xdmf_path is None else str(xdmf_path),
        }
        if friction is not None:
            for key in ("tangential_force", "friction_bound", "stick_size", "slip_fraction",
                        "friction_excess"):  # fmt: skip
                data[key] = summary[key]
        data["reference"] = post.reference_errors(summary)
        if friction is not None:
            data["reference"].update(scene.friction_reference(summary, friction))
        data["scores"] = post.scores(summary)
        data["errors"] = post.field_errors(summary)
        solver.destroy()
        if self.out is not None:
            write_json(self.out / "run.json", data, comm)
        return RunResult(data)


def _timed_load_program(solver, apply_load, steps: int, on_step, timings: dict) -> list:
    """run_load_program, recording the assembly time and the solve time (wall time less
    assembly and the output written by on_step, see :func:`_write_timed`) in ``timings``."""
    t0 = time.perf_counter()
    a_before = solver.timer.assembly
    records = run_load_program(solver, apply_load, steps=steps, on_step=on_step)
    total = time.perf_counter() - t0
    timings["assembly"] = solver.timer.assembly
    timings["solve"] = total - (solver.timer.assembly - a_before) - timings.get("output", 0.0)
    return records


def _write_timed(writer, t: float, fields, timings: dict) -> None:
    """writer.write(t, fields), adding its wall time to timings["output"]."""
    t0 = time.perf_counter()
    writer.write(t, fields)
    timings["output"] = timings.get("output", 0.0) + (time.perf_counter() - t0)


def _vertex_rule(fdim: int) -> dict:
    """Quadrature at the facet's vertices (trapezoidal rule): nodal collocation of the
    multiplier equations, exact nodal complementarity."""
    if fdim == 0:
        points, weights = ((),), (1.0,)
    elif fdim == 1:
        points, weights = ((0.0,), (1.0,)), (0.5, 0.5)
    else:
        points, weights = ((0.0, 0.0), (1.0, 0.0), (0.0, 1.0)), (1.0 / 6.0,) * 3
    return {
        "quadrature_rule": "custom",
        "quadrature_degree": 1,
        "quadrature_points": points,
        "quadrature_weights": weights,
    }


def _boundary_mask(Q, fdim: int, facets: np.ndarray) -> np.ndarray:
    """Bool per local (owned + ghost) dof block of Q: on one of the facets on any rank."""
    marker = dolfinx.fem.Function(Q)
    dofs = _compat.locate_dofs_topological(Q, fdim, facets)
    bs = Q.dofmap.index_map_bs
    marker.x.array.reshape(-1, bs)[dofs] = 1.0
    vec = _compat.petsc_vec(marker)
    vec.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    vec.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
    return marker.x.array.reshape(-1, bs)[:, 0] > 0.0


def _multiplier_bc(W, fdim: int, facets: np.ndarray, shape: tuple):
    """The multiplier is zero away from the contact boundary: its other dofs are fixed."""
    Wl = W.sub(1)
    Q, q_to_w = Wl.collapse()
    on = _boundary_mask(Q, fdim, facets)
    bs = Q.dofmap.index_map_bs
    q_to_w = np.asarray(q_to_w).reshape(-1, bs)
    if not shape:
        return [_compat.dirichletbc(np.float64(0.0), q_to_w[~on, 0].astype(np.int32), Wl)]
    return [
        _compat.dirichletbc(np.float64(0.0), q_to_w[~on, i].astype(np.int32), Wl.sub(i))
        for i in range(bs)
    ]


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
    """Contact force, pressure, contact size, penetration, friction quantities and field
    errors, compiled once."""

    def __init__(self, mesh, scene, num, surface: ContactSurface, method, dsc, dsc_fine,
                 von_mises):  # fmt: skip
        self.scene, self.num, self.surface, self.method = scene, num, surface, method
        self.mesh, self.dsc_fine = mesh, dsc_fine
        gdim = mesh.geometry.dim
        self.gdim = gdim
        u = surface.u
        friction = surface.friction
        self.friction = friction
        Q1 = _compat.function_space(mesh, "Lagrange", 1)
        self.Q1 = Q1
        q = ufl.TestFunction(Q1)
        self.pressure = dolfinx.fem.Function(Q1, name="contact_pressure")
        self.gap = dolfinx.fem.Function(Q1, name="gap")
        self.status = dolfinx.fem.Function(Q1, name="contact_status")
        DG0 = _compat.function_space(mesh, "DG", 0)
        self.vm = dolfinx.fem.Function(DG0, name="von_mises")
        self.vm_expr = _compat.expression(von_mises, DG0)
        self.gap_expr = _compat.expression(surface.gap(), Q1)
        self.mass1 = _assemble_vec(dolfinx.fem.form(q * dsc))
        n = surface.normal()
        if method is not None:
            p = method.pressure(surface)
            self.force_form = dolfinx.fem.form(p * n[gdim - 1] * dsc)
            self.p_form = dolfinx.fem.form(p * q * dsc)
            closed = getattr(method, "contact_indicator", method.pressure)(surface)
            self.measure_form = dolfinx.fem.form(active(closed) * dsc_fine)
        else:
            Qk = _compat.function_space(mesh, "Lagrange", num.degree)
            self.Qk = Qk
            self.massk = _assemble_vec(dolfinx.fem.form(ufl.TestFunction(Qk) * dsc))
            self.pk = dolfinx.fem.Function(Qk)
            self.measure_form = dolfinx.fem.form(self.status * dsc)
        if friction is not None:
            V1 = _compat.function_space(mesh, "Lagrange", 1, (gdim,))
            qv = ufl.TestFunction(V1)
            t_T = method.tangential_traction(surface)
            # the bound plus a zero that keeps the forms' arguments when mu = 0 or the
            # threshold is 0 (UFL would simplify the bound away)
            bound = friction.bound_where(p, closed) + dolfinx.fem.Constant(mesh, 0.0)
            slipping = method.slip_indicator(surface)
            self.traction = dolfinx.fem.Function(V1, name="tangential_traction")
            self.slip = dolfinx.fem.Function(V1, name="slip")
            self._increment = dolfinx.fem.Function(V1)
            self._slipping = dolfinx.fem.Function(Q1)
            self.increment_expr = _compat.expression(surface.slip_increment(n), V1)
            self.t_form = dolfinx.fem.form(ufl.dot(t_T, qv) * dsc)
            self.slip_form = dolfinx.fem.form(slipping * q * dsc)
            self.tforce_forms = [dolfinx.fem.form(t_T[i] * dsc) for i in range(gdim)]
            t_abs = ufl.sqrt(ufl.dot(t_T, t_T))
            self.excess_form = dolfinx.fem.form(positive_part(t_abs - bound) * dsc)
            self.bound_form = dolfinx.fem.form(bound * dsc)
            self.bound_nodal_form = dolfinx.fem.form(bound * q * dsc)
            self._bound = dolfinx.fem.Function(Q1)
            self.stick_form = dolfinx.fem.form(active(closed) * (1.0 - slipping) * dsc_fine)
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

    def _lumped(self, form, target, mass: np.ndarray) -> None:
        """target = (int f q ds) / (int q ds) at the contact boundary's nodes, 0 elsewhere."""
        b = _assemble_vec(form)
        bs = target.function_space.dofmap.index_map_bs
        vec = _compat.petsc_vec(target)
        arr = vec.getArray().reshape(-1, bs)
        on = mass > 0.0
        arr[:] = 0.0
        arr[on] = b.getArray().reshape(-1, bs)[on] / mass[on, None]
        b.destroy()
        vec.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)

    def evaluate(self, solver) -> dict[str, Any]:
        m = self.mass1.getArray()
        on_surface = m > 0.0
        if self.method is not None:
            force = self._sum(self.force_form)
            self._lumped(self.p_form, self.pressure, m)
        else:
            force = self._vi_pressure(solver)
        p_local = self.pressure.x.array
        p_max = self.mesh.comm.allreduce(float(p_local.max(initial=0.0)), op=MPI.MAX)
        st = self.status.x.array
        st[:] = (p_local > 1e-10 * max(p_max, 1e-300)).astype(float)  # 0 open, 1 closed (stick)
        self.gap.interpolate(self.gap_expr)
        gap_surface = self.gap.x.array[: len(m)][on_surface]
        penetration = self.mesh.comm.allreduce(
            float(max(-gap_surface.min(initial=0.0), 0.0)), op=MPI.MAX
        )
        measure = self._sum(self.measure_form) * self.scene.symmetry
        p_surface = p_local[: len(m)][on_surface]
        complementarity = self.mesh.comm.allreduce(
            float(np.max(np.abs(gap_surface * p_surface), initial=0.0)), op=MPI.MAX
        )
        out: dict[str, Any] = {
            "force": force * self.scene.symmetry,
            "a": self.scene.contact_size(measure),
            "p0": p_max,
            "penetration": penetration,
            "complementarity": complementarity,
        }
        if self.friction is not None:
            self._lumped(self.t_form, self.traction, m)
            self._lumped(self.slip_form, self._slipping, m)
            st[:] += (st > 0.0) & (self._slipping.x.array > 0.5)  # 2 where slipping
            bound = self._sum(self.bound_form)
            excess = self._sum(self.excess_form)
            stick = self._sum(self.stick_form) * self.scene.symmetry
            out["tangential_force"] = [
                self._sum(f) * self.scene.tangential_symmetry[i]
                for i, f in enumerate(self.tforce_forms)
            ]
            out["stick_size"] = self.scene.contact_size(stick)
            out["slip_fraction"] = 1.0 - stick / measure if measure > 0.0 else 0.0
            out["friction_excess"] = excess / bound if bound > 0.0 else excess
            out["friction_bound"] = bound * self.scene.tangential_symmetry[0]
        return out

    def accumulate_slip(self) -> None:
        """slip += tangential slip increment of this step, on the contact boundary's nodes."""
        self._increment.interpolate(self.increment_expr)
        m = self.mass1.getArray()
        vec = _compat.petsc_vec(self.slip)
        arr = vec.getArray().reshape(-1, self.gdim)
        inc = self._increment.x.array[: arr.size].reshape(-1, self.gdim)
        arr[m > 0.0] += inc[m > 0.0]
        vec.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)

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

    def scores(self, summary: dict) -> dict[str, float]:
        m = self.mass1.getArray()
        on = m > 0.0
        x = _compat.dof_coordinates(self.Q1)[: len(m)][on]
        p = self.pressure.x.array[: len(m)][on]
        local = self.scene.pressure_scores(x, p, summary["force"])
        if self.friction is not None:
            t = self.traction.x.array[: len(m) * self.gdim].reshape(-1, self.gdim)[on]
            status = self.status.x.array[: len(m)][on]
            self._lumped(self.bound_nodal_form, self._bound, m)
            bound = self._bound.x.array[: len(m)][on]
            local.update(self.scene.friction_scores(x, p, t, bound, status))
        return {k: self.mesh.comm.allreduce(v, op=MPI.MAX) for k, v in local.items()}

    def fields(self, u) -> list:
        self.vm.interpolate(self.vm_expr)
        out = [u, self.vm, self.pressure, self.gap, self.status]
        if self.friction is not None:
            out += [self.traction, self.slip]
        return out

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

    def field_errors(self, summary: dict) -> dict[str, float]:
        out = self._pressure_error(summary)
        if self.exact is None:
            return out
        for key in ("L2", "H1"):
            err = np.sqrt(self._sum(self.err_forms[key]))
            norm = np.sqrt(self._sum(self.norm_forms[key]))
            out[f"displacement_{key}"] = err
            out[f"displacement_{key}_rel"] = err / norm
        return out

    def _pressure_error(self, summary: dict) -> dict[str, float]:
        """Relative L2(contact boundary) error of the pressure against the closed form at the
        computed force: the method's pressure at quadrature points (the lumped nodal pressure
        for vi and nodal quadrature), integrated with a degree-12 rule."""
        ref = self.scene.reference(summary["force"])
        consts = {k: dolfinx.fem.Constant(self.mesh, float(v)) for k, v in ref.items()}
        exact = self.scene.exact_pressure(ufl.SpatialCoordinate(self.mesh), consts)
        if exact is None:
            return {}
        if self.method is not None and self.num.quadrature == "gauss":
            p_h = self.method.pressure(self.surface)
        else:  # the nodal pressure (vi, nodal quadrature): piecewise linear between nodes
            p_h = self.pressure
        dsf = self.dsc_fine
        err = np.sqrt(self._sum(dolfinx.fem.form((p_h - exact) ** 2 * dsf)))
        norm = np.sqrt(self._sum(dolfinx.fem.form(exact**2 * dsf)))
        return {"pressure_L2": err, "pressure_L2_rel": err / norm}


def _assemble_vec(form) -> PETSc.Vec:
    b = _compat.create_vector(form)
    return _compat.assemble_vector(b, form)
