"""Processes: child processes under mpirun (stress's parallel axis, the command-line tests)
and this process's peak memory (run summaries)."""

from __future__ import annotations

import os
import resource
from pathlib import Path

__all__ = ["child_env", "peak_memory_mib", "reset_peak_memory"]


def child_env() -> dict[str, str]:
    """Environment for a child mpirun: none of this process's MPI singleton state, root and
    oversubscription allowed, one thread per rank."""
    env = {k: v for k, v in os.environ.items() if not k.startswith(("OMPI_", "PMIX_", "PRTE_"))}
    env.update(
        OMPI_ALLOW_RUN_AS_ROOT="1",
        OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
        OMPI_MCA_rmaps_base_oversubscribe="1",
        PRTE_MCA_rmaps_default_mapping_policy=":oversubscribe",
        OPENBLAS_NUM_THREADS="1",
        OMP_NUM_THREADS="1",
    )
    return env


def reset_peak_memory() -> None:
    """Start a new peak of this process's resident memory (Linux: writing 5 to
    /proc/self/clear_refs resets VmHWM); elsewhere the peak stays the process's."""
    try:
        Path("/proc/self/clear_refs").write_text("5")
    except OSError:
        pass


def peak_memory_mib(comm) -> float:
    """Peak resident memory (MiB) since :func:`reset_peak_memory`, summed over the ranks
    (Linux VmHWM; elsewhere the process's peak, getrusage)."""
    kib = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    try:
        status = Path("/proc/self/status").read_text().splitlines()
        kib = next(float(line.split()[1]) for line in status if line.startswith("VmHWM:"))
    except (OSError, StopIteration):
        pass
    return comm.allreduce(kib / 1024.0)
