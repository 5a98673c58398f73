"""What every solver shares: its errors and counts, and the protocol the load program and the
pipeline call.

:class:`contactfx.solvers.snes.ContactSNES` is the one PETSc solver; a method or the driver
may wrap it (Uzawa's outer loop, the SNES-VI bounds, nested iteration's coarse chain). A
wrapper derives from :class:`SolverWrapper`, which hands every member of the :class:`Solver`
protocol to the solver inside and overrides what it changes: the pipeline and the steppers
never ask which solver they hold.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Protocol, runtime_checkable

from petsc4py import PETSc

__all__ = [
    "ConvergenceError",
    "TimeLimitExceeded",
    "SolveStats",
    "Timer",
    "Solver",
    "SolverWrapper",
]


@dataclass
class SolveStats:
    """Iterations of one nonlinear solve and the SNES reason."""

    newton: int = 0
    ksp: int = 0
    reason: str = ""
    outer: int = 1  # augmented Lagrangian (Uzawa) outer iterations
    coarse_newton: int = 0  # nested iteration: Newton iterations on the coarser meshes
    halvings: int = 0  # Newton steps halved before the line search (ContactSNES.limit_steps)


class ConvergenceError(RuntimeError):
    """The nonlinear solve failed; names the SNES reason, the load step and the load factor."""

    def __init__(
        self,
        reason: str,
        step: int | None = None,
        load: float | None = None,
        stats: SolveStats | None = None,
        *,
        detail: str = "",
        when: str | None = None,
    ) -> None:
        self.reason = reason
        #: the iteration counts up to the failure, when known
        self.stats = stats
        self.step = step
        self.load = load
        #: what the failed iterate shows (e.g. where an element inverted), or ""
        self.detail = detail
        # ``when``: the stepper's words for the time (a dynamic run's "time 0.5")
        when = when or ("" if load is None else f"load factor {load:.6g}")
        kind = "load step" if "load" in when else "time step"
        where = "" if step is None else f" at {kind} {step} ({when})"
        super().__init__(
            f"nonlinear solve diverged{where}: {reason}" + (f"; {detail}" if detail else "")
        )


class TimeLimitExceeded(ConvergenceError):
    """The solve ran past its deadline (not retried by cut-back)."""

    def __init__(self, where: str = "") -> None:
        RuntimeError.__init__(self, f"time limit exceeded{where}")
        self.reason, self.step, self.load, self.stats = "time limit", None, None, None


@dataclass
class Timer:
    """Accumulated wall time (s) of the assembly (bulk, loads, contact terms) and, within it,
    of the two-body coupling (its searches, residual and Jacobian terms)."""

    assembly: float = 0.0
    contact: float = 0.0


@runtime_checkable
class Solver(Protocol):
    """What the load program and the pipeline ask of a solver."""

    #: the unknown (a dolfinx Function) the solver updates in place
    u: Any
    timer: Timer

    def assemble_load(self) -> None:
        """Assemble the loads after the load program changed their constants."""

    def solve(self) -> SolveStats:
        """Solve from the current u; raise ConvergenceError on failure."""

    def converged(self) -> None:
        """The step just solved was accepted (a wrapper with history moves it on)."""

    def reactions(self) -> PETSc.Vec:
        """R(u) + F_c(u) on every row: the supports' reactions on their rows."""

    def bulk_residual(self) -> PETSc.Vec:
        """R(u) = f_int(u) - f_ext without the contact terms."""

    def reassemble_bulk(self, keep_preconditioner: bool = False) -> None:
        """The bulk's forms changed their constants: assemble its Jacobian again
        (``keep_preconditioner``: for the constants it had, a restarted run's)."""

    def reuse_factorisation(self, across_solves: bool = False) -> None:
        """Keep an LU factorisation across Newton iterations (starts close to the solution),
        and across solves (``across_solves``: a dynamic run's steps)."""

    def phase_timings(self) -> dict[str, float]:
        """Wall times of the solver's own phases, for run.json (e.g. the coarse chain's)."""

    def destroy(self) -> None: ...


class SolverWrapper:
    """A solver around ``inner`` (module docstring): every member of :class:`Solver` hands
    over to it."""

    def __init__(self, inner: Solver) -> None:
        self.inner = inner
        self.u = inner.u
        self.timer = inner.timer

    def assemble_load(self) -> None:
        self.inner.assemble_load()

    def solve(self) -> SolveStats:
        return self.inner.solve()

    def converged(self) -> None:
        self.inner.converged()

    def reactions(self) -> PETSc.Vec:
        return self.inner.reactions()

    def bulk_residual(self) -> PETSc.Vec:
        return self.inner.bulk_residual()

    def reassemble_bulk(self, keep_preconditioner: bool = False) -> None:
        self.inner.reassemble_bulk(keep_preconditioner)

    def reuse_factorisation(self, across_solves: bool = False) -> None:
        self.inner.reuse_factorisation(across_solves)

    def phase_timings(self) -> dict[str, float]:
        return self.inner.phase_timings()

    def destroy(self) -> None:
        self.inner.destroy()
