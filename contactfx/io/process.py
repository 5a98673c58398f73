"""Child processes under mpirun (stress's parallel axis, the command-line tests)."""

from __future__ import annotations

import os

__all__ = ["child_env"]


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
