# contactfx: make install | demo | test | lint | clean
# Everything runs from the venv that scripts/install.sh builds (./.venv, Debian's FEniCSx).
SHELL := /bin/bash
.SHELLFLAGS := -euo pipefail -c

VENV := .venv
PY := $(VENV)/bin/python
NP ?= 2

# Single-node Open MPI: allowed as root (containers, CI), more ranks than cores allowed
# (Open MPI 4: OMPI_MCA_*, 5: PRTE_MCA_*), TCP only on loopback (shared memory carries the
# traffic; Open MPI 5 otherwise warns about unreachable interfaces on some hosts).
export OMPI_ALLOW_RUN_AS_ROOT := 1
export OMPI_ALLOW_RUN_AS_ROOT_CONFIRM := 1
export OMPI_MCA_rmaps_base_oversubscribe := 1
export PRTE_MCA_rmaps_default_mapping_policy := :oversubscribe
export OMPI_MCA_btl_tcp_if_include := lo
# One thread per MPI rank (OpenBLAS under MUMPS, OpenMP).
export OPENBLAS_NUM_THREADS := 1
export OMP_NUM_THREADS := 1

.PHONY: install demo test lint clean results

install:
	bash scripts/install.sh

demo: install
	mpirun -n $(NP) $(VENV)/bin/contactfx run hertz2d --out results/hertz2d

# The serial session runs its tests on NP workers (pytest-xdist: each test in one process, as
# alone; the tests of an xdist_group, the ParaView probes, on one worker); the MPI session runs
# every test on NP ranks together.
test: install
	$(PY) -m pytest -q -n $(NP) --dist loadgroup --durations=15 tests
	mpirun -n $(NP) $(PY) -m mpi4py -m pytest -q -m "not serial_only" --durations=15 tests

# The committed results page docs/results.md (over an hour on 2 cores: up to 850 runs): error against run time
# for every case and method, and the robustness matrix.
BENCH_METHODS := nitsche,nitsche@1+nodal,penalty,al-uzawa,al-ssn,vi,mortar
results: install
	mpirun -n $(NP) $(VENV)/bin/contactfx bench --scene all --method $(BENCH_METHODS) \
		--degree 1,2 --levels 3 --out docs/results/bench
	$(VENV)/bin/contactfx stress --out docs/results/stress
	$(PY) -m contactfx.validation.report docs/results docs/results.md

lint: install
	@test -x $(VENV)/bin/ruff || $(PY) -m pip install -q --disable-pip-version-check ruff
	$(VENV)/bin/ruff check .
	$(VENV)/bin/ruff format --check .
	@$(PY) -m mypy --version >/dev/null 2>&1 || apt-get install -y -q mypy >/dev/null
	$(PY) -m mypy

clean:
	rm -rf $(VENV) results .pytest_cache .ruff_cache build dist *.egg-info
	find . -name __pycache__ -type d -prune -exec rm -rf {} +
