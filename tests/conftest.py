"""Shared test helpers: MPI awareness and running the command line as a subprocess."""

from __future__ import annotations

import subprocess
import sys

import pytest
from mpi4py import MPI


def pytest_collection_modifyitems(config, items):
    if MPI.COMM_WORLD.size == 1:
        return
    skip = pytest.mark.skip(reason="launches subprocesses; covered by the serial session")
    for item in items:
        if "serial_only" in item.keywords:
            item.add_marker(skip)


def pytest_runtest_logreport(report):
    """Under MPI a test that fails on one rank leaves the others waiting in its next
    collective: print the failure and abort the job, so that the session fails instead of
    hanging."""
    comm = MPI.COMM_WORLD
    if comm.size > 1 and report.failed:
        rank = comm.rank
        sys.stderr.write(
            f"\nrank {rank}: {report.nodeid} failed ({report.when}):\n"
            f"{report.longreprtext}\nrank {rank}: aborting the MPI job\n"
        )
        sys.stderr.flush()
        comm.Abort(1)


def clean_env() -> dict[str, str]:
    """Environment for child processes: no MPI singleton state of the test process."""
    from contactfx.io.process import child_env

    return child_env()


def contactfx_cmd(*args: str, ranks: int = 1) -> list[str]:
    cmd = [sys.executable, "-m", "contactfx", *args]
    if ranks > 1:
        cmd = ["mpirun", "-n", str(ranks), *cmd]
    return cmd


def run_cli(*args: str, ranks: int = 1, timeout: float = 300, cwd=None):
    return subprocess.run(
        contactfx_cmd(*args, ranks=ranks),
        capture_output=True,
        text=True,
        timeout=timeout,
        env=clean_env(),
        cwd=cwd,
    )
