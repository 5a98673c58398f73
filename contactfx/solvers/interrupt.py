"""Stopping a run cleanly on SIGTERM (a batch scheduler's) or SIGINT (Ctrl-C).

While a load program runs, :class:`StopRequest` catches the two signals: the first one is
recorded and the step in progress is finished (its fields written, its quantities kept), then
:func:`contactfx.solvers.stepper.march` stops at the step boundary and raises
:class:`Interrupted`; a second one aborts at once (Python's default: KeyboardInterrupt for
SIGINT, termination for SIGTERM). Every rank asks at each step boundary whether any rank was
signalled (one collective maximum), so the ranks stop at the same step whether the signal
reached all of them (Slurm's scancel, mpirun's forwarding) or one."""

from __future__ import annotations

import signal
import threading
from types import FrameType
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from mpi4py import MPI

__all__ = ["StopRequest", "Interrupted", "SIGNALS"]

#: the signals that stop a run after its step in progress
SIGNALS = (signal.SIGTERM, signal.SIGINT)


class Interrupted(Exception):
    """The load program stopped on a signal after its last complete step ``step`` (0: none)
    at load factor ``load``; ``records`` the complete steps' records."""

    def __init__(
        self, signum: int, step: int, load: float, records: list[Any], when: str | None = None
    ) -> None:
        self.signum, self.step, self.load, self.records = signum, step, load, records
        self.signal = signal.Signals(signum).name
        # ``when``: the stepper's words for the time (a dynamic run's "time 0.5")
        when = when or f"load factor {load:.6g}"
        kind = "load step" if "load" in when else "time step"
        super().__init__(f"interrupted by {self.signal} after {kind} {step} ({when})")


class StopRequest:
    """A context that records SIGTERM and SIGINT instead of dying (main thread only; the
    previous handlers are restored on exit). ``requested()`` (collective) is the signal any
    rank received, or 0."""

    def __init__(self, comm: MPI.Comm) -> None:
        self.comm = comm
        self.signum = 0
        self._previous: dict[int, Any] = {}

    def __enter__(self) -> StopRequest:
        if threading.current_thread() is threading.main_thread():
            for sig in SIGNALS:
                self._previous[sig] = signal.signal(sig, self._caught)
        return self

    def __exit__(self, *exc: object) -> None:
        # a handler installed outside Python (PETSc's, which prints a banner and aborts MPI)
        # reads as None and cannot be put back: the default action then
        for sig, handler in self._previous.items():
            signal.signal(sig, signal.SIG_DFL if handler is None else handler)
        self._previous.clear()

    def _caught(self, signum: int, frame: FrameType | None) -> None:
        if self.signum:  # the second signal: the default action, now
            self.__exit__()
            signal.raise_signal(signum)
            return
        self.signum = signum

    def requested(self) -> int:
        """The signal number any rank received (the largest), 0 for none. Collective."""
        from mpi4py import MPI

        return int(self.comm.allreduce(self.signum, op=MPI.MAX))
