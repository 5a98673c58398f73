"""Load stepping with a secant predictor and automatic cut-back on divergence."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from petsc4py import PETSc

from contactfx import _compat
from contactfx.solvers.snes import ContactSNES, ConvergenceError, SolveStats, TimeLimitExceeded

__all__ = ["StepRecord", "run_load_program"]


@dataclass
class StepRecord:
    step: int
    load: float
    stats: SolveStats
    cutbacks: int


def run_load_program(
    solver: ContactSNES,
    apply_load: Callable[[float], None],
    *,
    steps: int,
    on_step: Callable[[StepRecord], None] | None = None,
    max_cutbacks: int = 6,
) -> list[StepRecord]:
    """Solve at load factors t = 1/steps, 2/steps, ..., 1.

    ``apply_load(t)`` sets the load program's constants (obstacle position, tractions) for the
    load factor t. Each step but the first starts from the secant extrapolation of the last two
    converged states, the unloaded state u = 0 at t = 0 being the first of them (not the
    starting iterate: that is a guess of the first step's solution, and a secant through it can
    carry a stiffly enforced contact off its obstacle everywhere, where the Jacobian is
    singular). A failed step is retried with half the increment, up to ``max_cutbacks`` halvings in
    a row, and never below 1 / (steps 4^max_cutbacks) (the increment grows back only after a
    step that needed no cut-back, so without a floor steps that each fail once would shrink it
    without end); then ``ConvergenceError`` names the SNES reason, the step and the load
    factor.
    """
    if steps < 1:
        raise ValueError(f"load steps must be >= 1, got {steps}")
    x = _compat.petsc_vec(solver.u)
    previous = x.copy()  # last converged state
    older = x.duplicate()  # the one before, for the secant predictor: u = 0 at t = 0
    older.set(0.0)
    t_prev, t_older = 0.0, 0.0
    records: list[StepRecord] = []
    dt = 1.0 / steps
    dt_min = dt / 4**max_cutbacks
    cutbacks = 0
    step = 0
    try:
        while t_prev < 1.0 - 1e-12:
            t = min(1.0, t_prev + dt)
            # before the first converged step ``previous`` is the starting iterate
            factor = (t - t_prev) / (t_prev - t_older) if step > 0 else 0.0
            _predict(x, previous, older, factor)
            apply_load(t)
            solver.assemble_load()
            try:
                stats = solver.solve()
            except TimeLimitExceeded:
                _restore(previous, x)
                raise TimeLimitExceeded(f" at load factor {t:.6g}") from None
            except ConvergenceError as err:
                cutbacks += 1
                if cutbacks > max_cutbacks or 0.5 * dt < dt_min * (1.0 - 1e-12):
                    _restore(previous, x)
                    raise ConvergenceError(err.reason, step + 1, t) from None
                dt *= 0.5
                continue
            if step > 0:
                previous.copy(older)
            step += 1
            x.copy(previous)
            t_older, t_prev = t_prev, t
            record = StepRecord(step=step, load=t, stats=stats, cutbacks=cutbacks)
            records.append(record)
            if on_step is not None:
                on_step(record)
            if cutbacks == 0:
                dt = min(1.0 / steps, 2.0 * dt)
            cutbacks = 0
    finally:
        previous.destroy()
        older.destroy()
    return records


def _predict(x: PETSc.Vec, previous: PETSc.Vec, older: PETSc.Vec, factor: float) -> None:
    """x = previous + factor (previous - older): the secant extrapolation of the last two
    converged states (previous alone, factor 0, in the first step)."""
    previous.copy(x)
    if factor != 0.0:
        x.axpy(factor, previous)
        x.axpy(-factor, older)
    x.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)


def _restore(previous: PETSc.Vec, x: PETSc.Vec) -> None:
    """x = the last converged state, ghosts included (every rank sees the same state)."""
    previous.copy(x)
    x.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
