"""Steppers: the program over time that calls the nonlinear solver once per step.

:func:`march` is the one stepping loop: ask the stepper for the next time, let it predict the
step's start, set the loads for that time, solve, and on success let the stepper accept the
step (its history moves on), on failure let it cut the step back (it restores everything it
owns) or give up. What a step's history is belongs to the stepper:

* :class:`QuasiStatic`: the load factors t = 1/steps, ..., 1 (a quasi-static run's time is its
  load factor), a secant predictor through the last two converged states (or the last
  converged state), cut-back by halving;
* a dynamic stepper (Newmark, HHT-alpha, generalised-alpha) holds (u, v, a), predicts from
  them, restores all three on a cut-back, and asks the solver's bulk to assemble again when
  its step size changes (the effective stiffness K + c M depends on it).

The state a stepper restores is a :class:`Snapshot` of PETSc vectors (the unknown and any
other field: velocities, accelerations, multipliers): one copy per field, taken at each
accepted step.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, Protocol

from petsc4py import PETSc

from contactfx import _compat
from contactfx.solvers.interrupt import Interrupted, StopRequest
from contactfx.solvers.snes import ConvergenceError, SolveStats, TimeLimitExceeded

__all__ = [
    "StepRecord",
    "Snapshot",
    "Stepper",
    "CutBack",
    "QuasiStatic",
    "march",
    "run_load_program",
]


@dataclass
class StepRecord:
    """A converged step: its number (from 1), the time it ends at (a quasi-static run: the
    load factor), its size, the solve's counts and the cut-backs it needed."""

    step: int
    time: float
    dt: float
    stats: SolveStats
    cutbacks: int

    @property
    def load(self) -> float:
        """The load factor of a quasi-static step (its time)."""
        return self.time


class Snapshot:
    """Copies of ``fields`` (the ghosted PETSc vectors of Functions): :meth:`save` takes them,
    :meth:`restore` puts them back (ghosts updated, so every rank sees the same state)."""

    def __init__(self, fields: Sequence[PETSc.Vec]) -> None:
        self.fields = list(fields)
        self.copies = [f.copy() for f in self.fields]

    def save(self) -> None:
        for field, copy in zip(self.fields, self.copies, strict=True):
            field.copy(copy)

    def restore(self) -> None:
        for field, copy in zip(self.fields, self.copies, strict=True):
            copy.copy(field)
            _ghost_update(field)

    def destroy(self) -> None:
        for copy in self.copies:
            copy.destroy()


class SteppedSolver(Protocol):
    """What :func:`march` asks of a solver (a :class:`contactfx.solvers.base.Solver` has it)."""

    u: Any

    def assemble_load(self) -> None: ...

    def solve(self) -> SolveStats: ...


class Stepper(Protocol):
    """What :func:`march` asks of a program over time (see the module docstring)."""

    #: accepted steps so far
    step: int

    def start(self, x: PETSc.Vec) -> None:
        """Before the first step: ``x`` is the unknown (its value the starting iterate)."""

    def done(self) -> bool:
        """Whether the program has reached its end."""

    def next_time(self) -> float:
        """The time the next step ends at (with the current step size)."""

    def predict(self) -> None:
        """Set the unknown (and the stepper's other fields) to the next step's start."""

    def load_time(self) -> float:
        """The time the step's loads are set for (after :meth:`next_time`): the step's end,
        or a generalised-alpha scheme's intermediate time."""

    def accept(self, stats: SolveStats) -> StepRecord:
        """The step converged: it becomes the history of the next."""

    def cut_back(self) -> bool:
        """The step failed: a smaller step (True) or no more cut-backs (False)."""

    def reject(self, stats: SolveStats) -> bool:
        """The step converged, but asks to be repeated with a smaller one (an adaptive time
        step's error estimate); :func:`march` then cuts it back, or accepts it when no
        smaller step is left."""

    def restore(self) -> None:
        """Put back the state of the last accepted step (before an error propagates)."""

    def describe(self, t: float) -> str:
        """Where the program is at time t, for messages ('load factor 0.5')."""

    def destroy(self) -> None: ...


class CutBack:
    """What the steppers share on a failed step: halve the step, up to ``max_cutbacks`` in a
    row and never below ``dt_min``, and put back the last accepted state (``previous``)."""

    dt: float
    dt_min: float
    cutbacks: int
    max_cutbacks: int
    previous: Snapshot

    def cut_back(self) -> bool:
        self.cutbacks += 1
        if self.cutbacks > self.max_cutbacks or 0.5 * self.dt < self.dt_min * (1.0 - 1e-12):
            return False
        self.dt *= 0.5
        return True

    def restore(self) -> None:
        self.previous.restore()

    def reject(self, stats: SolveStats) -> bool:
        return False  # a converged step is accepted (an adaptive stepper's is checked)


class QuasiStatic(CutBack):
    """Load factors t = 1/steps, 2/steps, ..., 1.

    Each step but the first starts from the secant extrapolation of the last two converged
    states, the unloaded state u = 0 at t = 0 being the first of them (not the starting
    iterate: that is a guess of the first step's solution, and a secant through it can carry a
    stiffly enforced contact off its obstacle everywhere, where the Jacobian is singular).
    With ``predictor="previous"`` each step starts from the last converged state (Abaqus's
    ``EXTRAPOLATION=NO``): where a contact moves over the mesh (a body dragged over several
    elements a step) the displacement of a surface node is a wave passing it, which the secant
    extrapolates wrongly to second order; the extrapolated start lifts most of the contact
    zone off the surface by more than the penalty's penetration, Newton's first step from
    there, without the stiffness of the open points, releases the dent, and the residual jumps
    by two orders of magnitude (the sliding-contact scene at finite strain: 35 load steps and
    240 Newton iterations for 20 asked with the secant, 24 and 194 without; docs/verification.md
    section 15). A
    failed step is retried with half the increment, up to ``max_cutbacks`` halvings in a row,
    and never below 1 / (steps 4^max_cutbacks) (the increment grows back only after a step
    that needed no cut-back, so without a floor steps that each fail once would shrink it
    without end). ``fields``: other (ghosted) vectors restored with the unknown on a cut-back (each
    step starts them from their last converged value).

    Adaptive growth (``max_increment`` > 1 / steps, large deformation): after a step that
    needed no cut-back and at most ``easy_newton`` Newton iterations the increment grows by
    ``growth``, up to ``max_increment`` (the stepping of Abaqus/Standard's automatic
    increments and of MOOSE's IterationAdaptiveDT: fewer steps where the response is mild,
    the cut-backs where it is not). Without it the increment never exceeds 1 / steps.
    """

    def __init__(
        self,
        steps: int,
        *,
        max_cutbacks: int = 6,
        fields: Sequence[PETSc.Vec] = (),
        max_increment: float | None = None,
        easy_newton: int = 5,
        growth: float = 1.5,
        predictor: str = "secant",
    ) -> None:
        if steps < 1:
            raise ValueError(f"load steps must be >= 1, got {steps}")
        if max_increment is not None and not 0.0 < max_increment <= 1.0:
            raise ValueError(f"the maximum increment must lie in (0, 1], got {max_increment}")
        self.steps, self.max_cutbacks, self.fields = steps, max_cutbacks, list(fields)
        self.max_increment = max_increment
        self.easy_newton, self.growth = easy_newton, growth
        if predictor not in ("secant", "previous"):
            raise ValueError(f"the predictor must be secant or previous, got {predictor!r}")
        self.secant = predictor == "secant"
        self.step = 0

    def start(self, x: PETSc.Vec) -> None:
        self.x = x
        self.previous = Snapshot([x, *self.fields])  # the last converged state
        self.older = x.duplicate()  # the one before, for the secant predictor: u = 0 at t = 0
        self.older.set(0.0)
        self.t_prev = self.t_older = 0.0
        self.dt = self.dt_base = min(1.0 / self.steps, self.max_increment or 1.0)
        self.dt_min = self.dt / 4**self.max_cutbacks
        self.cutbacks = 0
        self.step = 0

    def done(self) -> bool:
        return self.t_prev >= 1.0 - 1e-12

    def next_time(self) -> float:
        self.t = min(1.0, self.t_prev + self.dt)
        return self.t

    def load_time(self) -> float:
        return self.t

    def predict(self) -> None:
        """x = previous + factor (previous - older): the secant extrapolation of the last two
        converged states (previous alone, factor 0, in the first step: before it, previous
        is the starting iterate; and at every step with the predictor "previous"); the other
        fields at their last converged values."""
        t, t_prev = self.t, self.t_prev
        factor = (t - t_prev) / (t_prev - self.t_older) if self.step > 0 and self.secant else 0.0
        self.previous.restore()
        if factor != 0.0:
            self.x.axpy(factor, self.previous.copies[0])
            self.x.axpy(-factor, self.older)
            _ghost_update(self.x)

    def accept(self, stats: SolveStats) -> StepRecord:
        if self.step > 0:
            self.previous.copies[0].copy(self.older)
        self.step += 1
        self.previous.save()
        self.t_older, self.t_prev = self.t_prev, self.t
        record = StepRecord(
            step=self.step,
            time=self.t,
            dt=self.t - self.t_older,
            stats=stats,
            cutbacks=self.cutbacks,
        )
        if self.cutbacks == 0:
            if self.dt < self.dt_base * (1.0 - 1e-12):  # back towards the base increment
                self.dt = min(self.dt_base, 2.0 * self.dt)
            elif self.max_increment is not None and stats.newton <= self.easy_newton:
                self.dt = min(self.max_increment, self.growth * self.dt)
        self.cutbacks = 0
        return record

    def describe(self, t: float) -> str:
        return f"load factor {t:.6g}"

    def destroy(self) -> None:
        self.previous.destroy()
        self.older.destroy()


def march(
    stepper: Stepper,
    solver: SteppedSolver,
    apply_load: Callable[[float], None],
    *,
    on_step: Callable[[StepRecord], None] | None = None,
    diagnose: Callable[[], str] | None = None,
    stop: StopRequest | None = None,
    resume: Callable[[], None] | None = None,
) -> list[StepRecord]:
    """Run ``stepper``'s program with ``solver`` (any solver of the :class:`ContactSNES`
    shape: ``u``, ``assemble_load()``, ``solve()``); ``apply_load(t)`` sets the loads'
    constants (obstacle position, tractions) for time t, ``on_step`` sees each converged
    step. When the stepper gives up, ``ConvergenceError`` names the SNES reason, the step
    and the time, and what ``diagnose()`` (collective) finds in the failed iterate (e.g. an
    inverted element), with the last converged state restored. ``stop``: asked at every step
    boundary (collective); a signal received raises :class:`Interrupted` after the step in
    progress (:mod:`contactfx.solvers.interrupt`). ``resume``: called once the stepper has
    started, to put a checkpoint's state back (the stepper's among it: a restart continues
    after the checkpoint's step)."""
    records: list[StepRecord] = []
    stepper.start(_compat.petsc_vec(solver.u))
    if resume is not None:
        resume()
    try:
        while not stepper.done():
            t = stepper.next_time()
            stepper.predict()
            apply_load(stepper.load_time())
            solver.assemble_load()
            try:
                stats = solver.solve()
            except TimeLimitExceeded:
                stepper.restore()
                raise TimeLimitExceeded(f" at {stepper.describe(t)}") from None
            except ConvergenceError as err:
                if not stepper.cut_back():
                    detail = diagnose() if diagnose is not None else ""
                    stepper.restore()
                    raise ConvergenceError(
                        err.reason,
                        stepper.step + 1,
                        t,
                        detail=detail,
                        when=stepper.describe(t),
                    ) from None
                continue
            if stepper.reject(stats) and stepper.cut_back():
                continue  # converged, but above the adaptive step's error estimate
            record = stepper.accept(stats)
            records.append(record)
            if on_step is not None:
                on_step(record)
            # parallel PETSc objects dropped without destroy() wait in petsc4py's garbage
            # until a collective cleanup (a full-size vector left per search grew a sliding
            # run by 1.1 MB a step); every rank gets here
            PETSc.garbage_cleanup(solver.u.function_space.mesh.comm)
            signum = stop.requested() if stop is not None else 0
            if signum and not stepper.done():
                raise Interrupted(signum, stepper.step, t, records, stepper.describe(t))
    finally:
        stepper.destroy()
    return records


def run_load_program(
    solver: SteppedSolver,
    apply_load: Callable[[float], None],
    *,
    steps: int,
    on_step: Callable[[StepRecord], None] | None = None,
    max_cutbacks: int = 6,
) -> list[StepRecord]:
    """:func:`march` over the :class:`QuasiStatic` load factors 1/steps, ..., 1."""
    return march(QuasiStatic(steps, max_cutbacks=max_cutbacks), solver, apply_load, on_step=on_step)


def _ghost_update(x: PETSc.Vec) -> None:
    x.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
