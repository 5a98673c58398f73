"""The driver: one pipeline for every problem kind.

Stages (docs/architecture.md, "Data flow"): check the request, build the mesh, set up the
problem kind (unknowns and spaces, measures and surfaces), compile the forms, build the solver
(the method attaches what it needs), start, run the load program (post-processing and output
at each converged step), and record the summary. A problem kind
(:class:`contactfx.driver.problem.Problem`) supplies its unknowns, surface, forms and
post-processing; it has no copy of the pipeline.
"""

from __future__ import annotations

import dataclasses
import json
import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager, nullcontext
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from mpi4py import MPI

from contactfx import _compat
from contactfx.contact.registry import methods_supporting
from contactfx.driver.inertia import EnergyLedger, initial_acceleration, plot_contact
from contactfx.driver.nested import NestedSolver, nested_levels
from contactfx.driver.restart import Checkpoints, Restart, run_identity
from contactfx.io.checkpoint import CHECKPOINT
from contactfx.io.process import peak_memory_mib, reset_peak_memory
from contactfx.io.provenance import versions, write_json, write_json_local
from contactfx.io.vtk import ResultsWriter
from contactfx.io.xdmf import XdmfWriter, h5py_mpi
from contactfx.results import RunSummary, StepLog, never_closed
from contactfx.solvers.dynamics import Dynamic, Scheme
from contactfx.solvers.interrupt import Interrupted, StopRequest
from contactfx.solvers.snes import GAMG_OPTIONS, ContactSNES, ConvergenceError
from contactfx.solvers.stepper import QuasiStatic, Stepper, StepRecord, march

if TYPE_CHECKING:
    from contactfx.driver.problem import Forms, Method, Numerics, Problem, Scene, Solver

__all__ = ["STAGES", "run", "setup", "prepare_output", "write_failed", "line_search_type"]


def run(
    scene: Scene,
    numerics: Numerics,
    *,
    comm: MPI.Comm = MPI.COMM_WORLD,
    out: str | Path | None = None,
    petsc_options: dict[str, Any] | None = None,
    verbose: bool = True,
    time_limit: float | None = None,
    output_format: str = "xdmf",
    restart: str | Path | None = None,
    checkpoint_every: int = 1,
) -> RunSummary:
    """Solve ``scene`` with ``numerics``; write the ParaView files (``output_format``: xdmf,
    XDMF3 + HDF5 written in parallel, or vtu, a PVD series of VTU files gathered on rank 0),
    run.json (and the kind's extra output) into ``out`` when given. Raises ValueError on a
    request the method or the problem kind does not support (before any collective),
    ConvergenceError when the solve fails, TimeLimitExceeded when the solves run past
    ``time_limit`` seconds of wall time from the start of the first (checked collectively at
    every residual). With ``out``, a checkpoint is written after every ``checkpoint_every``
    converged steps (0: none); ``restart``: the folder of a run to continue from its last
    checkpoint, appending to its ParaView series and run.json (``out`` must be that folder
    or None)."""
    folder = Path(restart) if out is None and restart is not None else out
    folder = None if folder is None else Path(folder)
    run_: _Run | None = None
    try:
        method = _checked_method(scene, numerics)
        run_ = _Run(
            scene,
            numerics,
            method,
            comm,
            folder,
            dict(petsc_options or {}),
            verbose,
            time_limit=time_limit,
            output_format=output_format,
            restart=None if restart is None else Path(restart),
            checkpoint_every=checkpoint_every,
        )
        return run_.execute()
    except Interrupted as stopped:
        if folder is not None and comm.rank == 0:
            write_interrupted(folder, stopped, scene, numerics, comm.size)
        raise
    except Exception as error:
        # a refused restart (another identity, another mesh) leaves the folder's run.json,
        # the stopped run's, as it is
        refused = restart is not None and (run_ is None or run_.stage != "solve")
        if folder is not None and not refused:
            stage = "input" if run_ is None else run_.stage
            write_failed(folder, error, stage, comm, scene=scene, numerics=numerics)
        raise


def write_interrupted(
    out: Path, stopped: Interrupted, scene: Scene, numerics: Numerics, ranks: int
) -> None:
    """run.json of a run stopped by a signal (rank 0): ``"status": "interrupted"``, the
    signal, the last complete step and its load factor, those steps' records (their fields
    are in the ParaView files, whose index lists exactly them) and what a restart needs."""
    data: dict[str, Any] = {
        "status": "interrupted",
        "stage": "solve",
        "error": str(stopped),
        "signal": stopped.signal,
        "last_complete_step": stopped.step,
        "load": stopped.load,
        "scene": scene.name,
        "parameters": dataclasses.asdict(scene.p),
        "numerics": dataclasses.asdict(numerics),
        "steps": [s.to_json() for s in stopped.records],
        "restart": _restart_hint(out),
        "versions": versions(),
        "ranks": ranks,
    }
    _write_run_json(out, data)


def _restart_hint(out: Path) -> str:
    """How to continue a stopped run: from its last checkpoint, if it has one."""
    latest = Path(out) / CHECKPOINT / "latest.json"
    try:
        step = json.loads(latest.read_text())["step"]
    except (OSError, ValueError, KeyError):
        return "no checkpoint was written (--checkpoint-every 0): run the same command again"
    return (
        f"the same command with --restart {out} (and without --out) continues after step "
        f"{step}, the last checkpoint"
    )


def _write_run_json(out: Path, data: dict[str, Any]) -> None:
    """run.json of a run that did not complete, from this rank; an unwritable folder is
    passed over (the run's line is printed anyway)."""
    try:
        Path(out).mkdir(parents=True, exist_ok=True)
        write_json_local(Path(out) / "run.json", data)
    except (OSError, TypeError, ValueError):
        pass


#: the stages a run.json of a failed run names: the request and its input, the mesh, the
#: set-up (unknowns, surfaces, forms, solver, the start and its geometry checks), the solve
STAGES = ("input", "mesh", "set-up", "solve")

#: --format -> the ParaView writer
WRITERS: dict[str, Any] = {"xdmf": XdmfWriter, "vtu": ResultsWriter}


def write_failed(
    out: Path,
    error: BaseException,
    stage: str,
    comm: MPI.Comm,
    *,
    scene: Scene | str | None = None,
    numerics: Numerics | None = None,
    **fields: Any,
) -> None:
    """run.json marked failed: the ``stage`` the run failed in (:data:`STAGES`), the error's
    line, and what is known of the run (the scene, its parameters and numerics; the scene's
    name alone when its parameters were refused; the ``fields`` given, e.g. the problem
    file), so that no earlier result stays presented as this run's. No collective: an error
    every rank raises alike (ValueError, OSError, ConvergenceError: the contract of the
    pipeline) is written by rank 0; any other error by the rank it happened on (it may be on
    that rank only, and the job is then aborted). An unwritable folder is passed over (the
    error is reported anyway)."""
    collective = isinstance(error, ValueError | OSError | ConvergenceError)
    if collective and comm.rank != 0:
        return
    line = " ".join(str(error).split())
    data: dict[str, Any] = {
        "status": "failed",
        "stage": stage,
        "error": line if collective else f"{type(error).__name__}: {line}",
    }
    if isinstance(scene, str):  # its name: the parameters were refused
        data["scene"] = scene
    elif scene is not None:
        data.update(scene=scene.name, parameters=dataclasses.asdict(scene.p))
    if numerics is not None:
        data["numerics"] = dataclasses.asdict(numerics)
    data.update(fields)
    data.update(versions=versions(), ranks=comm.size)
    _write_run_json(out, data)


def setup(scene: Scene, numerics: Numerics, comm: MPI.Comm = MPI.COMM_WORLD) -> Problem:
    """The problem that :func:`run` solves, built (mesh, unknowns, surface) and not solved:
    to look at its forms (e.g. the contact residual ``method.residual(problem.surface)``)."""
    method = _checked_method(scene, numerics)
    mesh, facet_tags = scene.build_mesh(comm)
    return scene.problem(scene, numerics, method, mesh, facet_tags)


def _checked_method(scene: Scene, numerics: Numerics) -> Method:
    """The method of ``numerics``, checked against the scene's problem kind (before any
    collective); the scene reads the numerics' physical choices."""
    method = numerics.method_object()
    scene.problem.check(scene, numerics, method)
    material = numerics.bulk_material(scene.material())
    if not material.linear and not scene.problem.nonlinear_bulk:
        raise ValueError(
            f"scene '{scene.name}': its problem kind needs a linear material (small-strain "
            f"elasticity), not --material {numerics.material}; finite strain is offered "
            "against rigid obstacles"
        )
    if scene.axisymmetric:
        if not scene.problem.axisymmetric:
            raise ValueError(f"scene '{scene.name}': its problem kind is not offered axisymmetric")
        if not method.supports.axisymmetric or numerics.quadrature != "gauss":
            raise ValueError(
                f"axisymmetric scene '{scene.name}': method {method.name} with --quadrature "
                f"{numerics.quadrature} is not offered (a law collocated at the nodes has no "
                "weight at the axis r = 0); use --quadrature gauss with "
                + ", ".join(methods_supporting(lambda c: c.axisymmetric))
            )
    if material.finite_strain and not method.supports.finite_strain:
        raise ValueError(
            f"--material {numerics.material}: method {method.name} is small-strain only ("
            f"{method.supports.why_not.get('finite_strain', '')}); use "
            + ", ".join(methods_supporting(lambda c: c.finite_strain and c.obstacles))
        )
    if numerics.nested:
        if not scene.problem.nested:
            raise ValueError(
                f"--nested: nested iteration is offered for obstacle scenes, not "
                f"for scene '{scene.name}'"
            )
        if scene.coarsened(2.0**numerics.nested) is None:
            raise ValueError(
                f"--nested: scene '{scene.name}' cannot mesh itself coarser "
                "(its mesh comes from a file)"
            )
    if numerics.dynamic and not scene.problem.dynamic:
        raise ValueError(
            f"--dynamic: scene '{scene.name}': its problem kind is offered static only (time "
            "integration is offered against rigid obstacles and between two bodies)"
        )
    if numerics.dashpot > 0.0 and not scene.problem.dashpot:
        raise ValueError(
            f"--dashpot: scene '{scene.name}': the contact dashpot is offered against a rigid "
            "obstacle only (not between two bodies)"
        )
    scene.configure(numerics)
    return method


def prepare_output(out: Path, comm: MPI.Comm, keep: bool = False) -> None:
    """Create the output folder and remove a previous run.json (``keep``: a restart's,
    replaced when the run ends); fail on every rank alike."""
    error = None
    if comm.rank == 0:
        try:
            out.mkdir(parents=True, exist_ok=True)
            probe = out / ".write-test"
            probe.write_text("")
            probe.unlink()
            if not keep:
                (out / "run.json").unlink(missing_ok=True)
        except OSError as err:
            error = f"output folder {out} is not writable: {err.strerror or err}"
    error = comm.bcast(error, root=0)
    if error is not None:
        raise ValueError(error)


class _Run:
    def __init__(
        self,
        scene: Scene,
        numerics: Numerics,
        method: Method,
        comm: MPI.Comm,
        out: Path | None,
        petsc_options: dict[str, Any],
        verbose: bool,
        time_limit: float | None = None,
        output_format: str = "xdmf",
        restart: Path | None = None,
        checkpoint_every: int = 1,
    ) -> None:
        if output_format not in WRITERS:
            raise ValueError(f"output format '{output_format}': choose one of {', '.join(WRITERS)}")
        self.scene, self.num, self.method, self.comm = scene, numerics, method, comm
        self.out, self.petsc_options, self.verbose = out, petsc_options, verbose
        self.writer = WRITERS[output_format]
        if checkpoint_every < 0:
            raise ValueError(f"--checkpoint-every must be >= 0, got {checkpoint_every}")
        if restart is not None and out is not None and Path(out).resolve() != restart.resolve():
            raise ValueError(
                f"--restart {restart} continues the run in its own folder: leave out --out "
                f"(given: {out})"
            )
        self.checkpoint_every = checkpoint_every if out is not None else 0
        self.identity = run_identity(scene, numerics, output_format, comm)
        #: the checkpoint to continue from, read and checked (scene, numerics) at once
        self.restart = None if restart is None else Restart(restart, self.identity, comm)
        if out is not None and output_format == "xdmf":
            h5py_mpi()  # refused before the mesh is built when h5py has no MPI
        self.timings: dict[str, float] = {}
        self.prefix = f"contactfx_{scene.name.replace('-', '_')}_"
        #: seconds of wall time the solves may take, or None (see run)
        self.time_limit: float | None = time_limit
        self.deadline: float | None = None
        #: the stage the run is in (STAGES): a failure's run.json names it
        self.stage = "input"

    @contextmanager
    def timed(self, phase: str) -> Iterator[None]:
        t0 = time.perf_counter()
        yield
        self.timings[phase] = self.timings.get(phase, 0.0) + time.perf_counter() - t0

    #: a progress line is open on the terminal (:meth:`progress`)
    _open_line = False

    def say(self, msg: str) -> None:
        if self.verbose and self.comm.rank == 0:
            print(msg, flush=True)

    def progress(self, msg: str) -> None:
        """A step's progress line: on a terminal one line rewritten in place (the steps are
        in run.json), else one line per step (logs, pipes, batch jobs). Under mpirun one line
        per step always: Open MPI hands its ranks a pseudo-terminal whatever mpirun's own
        output is (a file, a pipe)."""
        if not (self.verbose and self.comm.rank == 0):
            return
        if self.comm.size == 1 and sys.stdout.isatty():
            print("\r" + msg.strip() + "\x1b[K", end="", flush=True)
            self._open_line = True
        else:
            print(msg, flush=True)

    def end_progress(self) -> None:
        """Close the terminal's progress line before anything else is printed."""
        if self._open_line:
            print(flush=True)
            self._open_line = False

    def execute(self) -> RunSummary:
        reset_peak_memory()
        if self.time_limit is not None:
            self.deadline = time.perf_counter() + self.time_limit
        if self.out is not None:
            prepare_output(self.out, self.comm, keep=self.restart is not None)
        problem, post, solver = self.build()
        if self.restart is not None:
            self.restart.check_mesh(problem.mesh)
        self.stage = "solve"
        try:
            try:
                steps = self.load_program(problem, solver, post)
            finally:
                self.end_progress()
            extra = post.finish(steps[-1].quantities, self.out)
        finally:
            solver.destroy()
        return self.record(problem, problem.mesh, steps, extra)

    def build(self) -> tuple[Problem, Any, Solver]:
        """(problem, post-processor, solver): the stages up to the load program. With
        ``--nested N``, the solver is started at every step by the chain of N coarser meshes
        (built here; their mesh and compile times count in this run's)."""
        self.stage = "mesh"
        with self.timed("mesh"):
            mesh, facet_tags = self.scene.build_mesh(self.comm)
        self.stage = "set-up"
        problem = self.scene.problem(self.scene, self.num, self.method, mesh, facet_tags)
        with self.timed("compile"):
            forms = problem.forms()
            post = problem.post_processor()
        solver: Solver = self.build_solver(problem, forms)
        try:
            with self.timed("initial_guess"):
                problem.start(solver)
            solver = self.method.attach(solver, problem)
            if problem.inertia is not None and problem.material.linear:
                # K + c M factorised once per step size (ContactSNES.reuse_factorisation)
                solver.reuse_factorisation(across_solves=True)
            levels = nested_levels(self.num.nested, problem.dofs(), mesh.topology.dim)
            if levels:
                solver = self.nested(problem, solver, levels)
        except BaseException:
            solver.destroy()
            raise
        return problem, post, solver

    def nested(self, problem: Problem, solver: Solver, levels: int) -> NestedSolver:
        """The fine solver wrapped by the coarse chain: the scene meshed twice as coarse,
        with one level of nesting less."""
        scene = self.scene.coarsened(2.0)
        num = dataclasses.replace(self.num, nested=levels - 1)
        method = _checked_method(scene, num)
        coarse = _Run(scene, num, method, self.comm, None, self.petsc_options, False)
        coarse.prefix = self.prefix + f"coarse{num.nested + 1}_"
        coarse.deadline = self.deadline
        c_problem, _, c_solver = coarse.build()
        for phase in ("mesh", "compile", "initial_guess", "chain_assembly"):
            self.timings[phase] = self.timings.get(phase, 0.0) + coarse.timings.get(phase, 0.0)
        # the coarse solver's matrices, made and assembled before the load program: part of
        # this run's assembly (what the coarse solves assemble later is in the solve's time)
        self.timings["chain_assembly"] += c_solver.timer.assembly
        return NestedSolver(solver, problem, c_solver, c_problem)

    # -- solver --------------------------------------------------------------------------
    def build_solver(self, problem: Problem, forms: Forms) -> ContactSNES:
        options = dict(GAMG_OPTIONS) if self.num.solver == "gamg" else {}
        options["snes_linesearch_type"] = line_search_type(self.num.line_search, self.method)
        options.update(self.method.snes_options())
        t0 = time.perf_counter()
        bulk = forms.bulk()
        assembly = time.perf_counter() - t0
        solver = ContactSNES(
            problem.state,
            bulk=bulk,
            contact_residual=forms.contact_residual,
            contact_jacobian=forms.contact_jacobian,
            bcs=problem.bcs,
            prefix=self.prefix,
            options=options,
            user_options=self.petsc_options,
            near_nullspace=self.num.solver == "gamg",
            coupling=problem.coupling(),
            confined=problem.confined,
            iterate=problem.iterate,
            deadline=self.deadline,
            # (a dynamic step's residual holds c M w, 1 / (beta dt^2) times the state: its
            # round-off floor lies far above 1e-10 of a well-predicted step's first residual)
            roundoff_stop=(
                problem.material.finite_strain
                or problem.roundoff_stop
                or problem.inertia is not None
            ),
            load_scale=problem.inertia is not None,
        )
        solver.timer.assembly += assembly
        if problem.material.finite_strain and self.num.inversion_check == "halve":
            # a step that would invert an element (a NaN residual) is halved instead
            solver.limit_steps(problem.volume_ratio.positive)
        return solver

    # -- load program ----------------------------------------------------------------------
    def load_program(self, problem: Problem, solver: Solver, post: Any) -> list[StepLog]:
        """Solve at the load factors of the program; at each converged step evaluate the
        contact quantities, write the fields and keep the step as the history of the next."""
        steps: list[StepLog] = []
        restart = self.restart
        if restart is not None:
            steps = list(restart.state["steps"])
        writer = None
        if self.out is not None:
            writer = self.writer(
                self.out,
                self.scene.name,
                problem.mesh,
                facets=getattr(problem, "contact_facets", None),
                split=problem.output_split(),
                resume=None if restart is None else restart.state["writer"],
            )
        checkpoints = None
        if self.out is not None and self.checkpoint_every:
            checkpoints = Checkpoints(
                self.out, self.checkpoint_every, self.identity, problem.mesh, self.comm
            )
        with writer or nullcontext():

            def on_step(rec: StepRecord) -> None:
                quantities = post.evaluate(solver)
                self.scene.on_step(problem, solver, rec.time, quantities)
                s = rec.stats
                steps.append(
                    StepLog(
                        rec.step,
                        rec.time,
                        s.newton,
                        s.ksp,
                        s.outer,
                        rec.cutbacks,
                        s.reason,
                        s.coarse_newton,
                        s.halvings,
                        quantities,
                    )
                )
                if self.energy is not None:  # (before the friction history moves on)
                    steps[-1] = dataclasses.replace(steps[-1], energy=self.energy.record(rec.time))
                    self.energy.check_stable(rec.step)
                if writer is not None:
                    with self.timed("output"):
                        writer.write(rec.time, post.fields())
                problem.converged()
                solver.converged()
                if checkpoints is not None and checkpoints.due(rec.step, stepper.done()):
                    with self.timed("checkpoint"):
                        checkpoints.write(rec.step, rec.time, roots(), steps, writer)
                elapsed = time.perf_counter() - t0
                self.progress(
                    _progress(steps[-1], problem.method.multiplier.nodal)
                    + _remaining(elapsed, rec.time - t_start, self.end_time - t_start)
                )

            def roots() -> dict[str, Any]:
                """The objects that hold the run's state (contactfx.io.checkpoint)."""
                return {
                    "stepper": stepper,
                    "energy": self.energy,
                    "problem": problem,
                    "post": post,
                    "solver": solver,
                    "scene": self.scene,
                }

            def resume() -> None:
                assert restart is not None
                restart.resume(roots())
                self.say(f"  restarted after step {restart.step} (load {restart.load:.6g})")

            t0 = time.perf_counter()
            t_start = 0.0 if restart is None else restart.load
            a0 = solver.timer.assembly
            stepper = self.stepper(problem, solver)
            if self.energy is not None and restart is None:  # the balance at t = 0
                problem.apply_load(t_start)
                self.energy.record(t_start)
            with StopRequest(self.comm) as stop:
                try:
                    march(
                        stepper,
                        solver,
                        problem.apply_load,
                        on_step=on_step,
                        diagnose=problem.diagnose,
                        stop=stop,
                        resume=None if restart is None else resume,
                    )
                except Interrupted as err:
                    err.records = steps  # the complete steps, with their quantities
                    raise
            total = time.perf_counter() - t0
        self.timings["assembly"] = solver.timer.assembly + self.timings.pop("chain_assembly", 0.0)
        if problem.coupling() is not None:  # two bodies: the coupling's share of the assembly
            self.timings["contact"] = solver.timer.contact
        output = self.timings.get("output", 0.0) + self.timings.get("checkpoint", 0.0)
        self.timings["solve"] = total - (solver.timer.assembly - a0) - output
        self.timings.update(solver.phase_timings())  # within the solve (nested: the coarse chain)
        return steps

    #: a dynamic run's energy balance (:class:`contactfx.driver.inertia.EnergyLedger`)
    energy: EnergyLedger | None = None

    @property
    def end_time(self) -> float:
        """The program's end: the last load factor 1, or a dynamic run's t_end."""
        return self.num.t_end if self.num.dynamic else 1.0

    def stepper(self, problem: Problem, solver: Solver) -> Stepper:
        """The program over time: load factors (:class:`QuasiStatic`), or a dynamic run's
        time steps (:class:`contactfx.solvers.dynamics.Dynamic`, its energy balance kept in
        :attr:`energy`)."""
        if not self.num.dynamic:
            return QuasiStatic(
                self.num.steps,
                max_increment=self.num.max_increment or None,
                predictor=self.num.predictor,
            )
        inertia = problem.inertia
        assert inertia is not None  # built by the problem for a dynamic run
        self.scene.initial_velocity(inertia.v.sub(0) if problem.split else inertia.v)
        if problem.prev is not None:  # the friction history starts at the initial state
            problem.prev.x.array[:] = problem.state.x.array
        scheme = Scheme.named(self.num.scheme, self.num.rho_inf)
        self.energy = EnergyLedger(problem, inertia, problem.load_form, alpha_f=scheme.alpha_f)
        vec = _compat.petsc_vec
        extra: dict[str, Any] = {}
        if inertia.v_star is not None:  # the velocity c_v w - v* of the dashpot's law
            extra = dict(
                v_star=vec(inertia.v_star), set_velocity_factor=inertia.set_velocity_factor
            )
        if inertia.dynamic_dofs is not None:  # a multiplier field: no inertia, no history
            extra["dynamic_dofs"] = vec(inertia.dynamic_dofs)
        if problem.multiplier is not None:  # a nodal multiplier: restored with a step's state
            extra["fields"] = [vec(problem.multiplier)]
        return Dynamic(
            scheme,
            dt=self.num.dt,
            t_end=self.num.t_end,
            v=vec(inertia.v),
            a=vec(inertia.a),
            a_star=vec(inertia.a_star),
            set_mass_factor=inertia.set_mass_factor,
            reassemble=solver.reassemble_bulk,
            initial_acceleration=initial_acceleration(problem, solver, inertia),
            time_tolerance=self.num.time_tolerance,
            **extra,
        )

    def _output(self, suffix: str) -> str | None:
        return None if self.out is None else str(self.out / f"{self.scene.name}{suffix}")

    # -- record --------------------------------------------------------------------------
    def record(
        self, problem: Problem, mesh: Any, steps: list[StepLog], extra: dict[str, Any]
    ) -> RunSummary:
        # a problem file's pair: the element size in the contact zone (post-processor's)
        h_contact = extra.pop("h_contact", None) or self.scene.h_contact()
        summary = RunSummary(
            scene=self.scene.name,
            parameters=dataclasses.asdict(self.scene.p),
            numerics=dataclasses.asdict(self.num),
            petsc_options={k: str(v) for k, v in self.petsc_options.items()},
            petsc_prefix=self.prefix,
            versions=versions(),
            ranks=self.comm.size,
            dofs=problem.dofs(),
            cells=mesh.topology.index_map(mesh.topology.dim).size_global,
            h_contact=h_contact,
            steps=steps,
            timings=dict(self.timings),
            quantities=steps[-1].quantities,
            paraview=self._output(self.writer.suffix),
            paraview_surface=(
                self._output("_surface" + self.writer.suffix)
                if getattr(problem, "contact_facets", None) is not None
                else None
            ),
            memory_mib=peak_memory_mib(self.comm),
            warnings=self.warnings(problem, steps) + extra.pop("warnings", []),
            restarted=(
                None
                if self.restart is None
                else {"step": self.restart.step, "load": self.restart.load}
            ),
            energy=None if self.energy is None else self.energy.summary(),
            **extra,
        )
        if self.energy is not None and self.out is not None:
            self.energy.write(self.out)
            if self.comm.rank == 0:
                q = [s.quantities for s in steps]
                plot_contact(
                    [s.load for s in steps],
                    [x.force for x in q],
                    [x.peak_pressure for x in q],
                    self.out / "contact.png",
                )
        if self.out is not None:
            write_json(self.out / "run.json", summary.to_json(), self.comm)
        return summary

    def warnings(self, problem: Problem, steps: list[StepLog]) -> list[str]:
        """run.json's ``warnings``: a contact pair or obstacle that never closed (with the
        pair's smallest gap at the last search). Collective."""
        pair = getattr(problem, "pair", None) is not None
        coupling = problem.coupling() if pair else None
        gap = None
        if coupling is not None and hasattr(coupling, "search_gaps"):
            local = float(np.min(coupling.search_gaps(), initial=np.inf))
            gap = self.comm.allreduce(local, op=MPI.MIN)
        return never_closed(steps, "pair" if pair else "obstacle", gap)


def _remaining(elapsed: float, load: float, total: float = 1.0) -> str:
    """The wall time since the load program started and an estimate of the time left, from
    the share ``load`` of the program's ``total`` done (the steps' cost taken as even)."""
    left = elapsed * (total - load) / load if load > 0.0 else float("nan")
    return f"  time {elapsed:.1f} s  left ~{left:.0f} s"


def _progress(step: StepLog, outer: bool) -> str:
    q = step.quantities
    when = "time" if step.energy is not None else "load"  # a dynamic run's steps are in time
    head = f"  step {step.step:3d}  {when} {step.load:6.3f}  newton {step.newton:3d}"
    head += f"  outer {step.outer:3d}" if outer else ""
    if q.interface is not None:
        return (
            f"{head}  normal force {q.force:.6g}  tangential force "
            f"{q.interface.tangential_force:.6g}"
        )
    tangential = "" if q.friction is None else f"  Q {q.friction.tangential_force[0]:.6g}"
    return f"{head}  ksp {step.ksp:4d}  force {q.force:.6g}  a {q.contact_size:.6g}{tangential}"


def line_search_type(asked: str, method: object) -> str:
    """PETSc's line search type for ``--line-search`` ``asked``: ``auto`` is the method's
    (:attr:`contactfx.contact.method.MethodBase.line_search`: cp for the penalised methods,
    basic for the multiplier methods), any other value itself."""
    if asked != "auto":
        return asked
    return str(getattr(method, "line_search", "basic"))
