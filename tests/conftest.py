"""Shared test helpers: MPI awareness and running the command line as a subprocess."""

from __future__ import annotations

import signal
import subprocess
import sys
import weakref

import pytest
from mpi4py import MPI


def pytest_collection_modifyitems(config, items):
    if MPI.COMM_WORLD.size == 1:
        # one rank against all ranks: the same run twice in a serial session
        alone = pytest.mark.skip(reason="compares 1 rank with all: run by the MPI session")
        for item in items:
            if "ranks_compare" in item.keywords:
                item.add_marker(alone)
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


#: runs each argv of a JSON list (stdin) through contactfx's main in this one process, every
#: output (Python's and PETSc's) caught at the file descriptors: [(status, stdout, stderr)]
_BATCH = r"""
import json, os, sys, tempfile
from contactfx.cli import main
out = []
for argv in json.load(sys.stdin):
    with tempfile.TemporaryFile() as o, tempfile.TemporaryFile() as e:
        sys.stdout.flush(); sys.stderr.flush()
        saved = os.dup(1), os.dup(2)
        os.dup2(o.fileno(), 1); os.dup2(e.fileno(), 2)
        try:
            status = main(argv)
        except BaseException as exc:
            status = f"raised {exc!r}"
        sys.stdout.flush(); sys.stderr.flush()
        os.dup2(saved[0], 1); os.dup2(saved[1], 2)
        os.close(saved[0]); os.close(saved[1])
        o.seek(0); e.seek(0)
        out.append((status, o.read().decode(), e.read().decode()))
with open(sys.argv[1], "w") as fh:  # not stdout: a library may print there at exit
    json.dump(out, fh)
"""


def run_cli_batch(cases: list[list[str]], timeout: float = 600) -> list[tuple]:
    """(status, stdout, stderr) of ``contactfx`` with each argv of ``cases``, one after the
    other in a single process (one rank): for the many one-line refusals, which a process
    each would spend in imports."""
    import json
    import tempfile

    with tempfile.TemporaryDirectory() as tmp:
        out = f"{tmp}/refusals.json"
        res = subprocess.run(
            [sys.executable, "-c", _BATCH, out],
            input=json.dumps(cases),
            capture_output=True,
            text=True,
            timeout=timeout,
            env=clean_env(),
        )
        assert res.returncode == 0, res.stdout + res.stderr
        with open(out) as fh:
            return [tuple(r) for r in json.load(fh)]


def jacobian_check(
    scene, num, displace, *, freeze: bool = True, prefix: str = "fd_", history=None, noise=1e-5
):
    """(error(eps), coupling, solver) of a two-body scene: the relative error of J du against
    the central difference of the residual (contact terms included) at the state
    ``displace(X, upper)`` (X: the owned nodes' reference coordinates, upper: the upper body's
    nodes among them) plus noise. ``freeze``: the projection searched once at that state (else
    the coupling's own search at every residual, as finite strain does). ``noise``: the size
    of the random displacement added to every node. ``history(coupling)``
    sets a history (penalty friction's last converged traction, gap and normal) before the
    residuals."""
    import numpy as np

    from contactfx.driver import setup
    from contactfx.solvers.snes import ContactSNES

    pb = setup(scene, num)
    forms = pb.forms()
    solver = ContactSNES(
        pb.state,
        bulk=forms.bulk(),
        bcs=[],
        prefix=f"{prefix}{num.method}_",
        coupling=pb.coupling(),
    )
    x = solver.u.x.petsc_vec if hasattr(solver.u.x, "petsc_vec") else solver.u.vector
    rng = np.random.default_rng(7)
    X = pb.layout.X.getArray().reshape(-1, pb.layout.gdim)
    # the upper body's owned nodes (coordinates cannot tell the coinciding contact faces)
    tags = scene.cell_tags
    cells = tags.indices[tags.values == scene.cells["upper"]]
    nodes = np.unique([pb.V.dofmap.cell_dofs(c) for c in cells]) if len(cells) else []
    upper = np.zeros(len(X), dtype=bool)
    nodes = np.asarray(nodes, dtype=np.int64)
    upper[nodes[nodes < len(X)]] = True
    u = displace(X, upper) + noise * rng.standard_normal(X.shape)
    x.getArray()[:] = u.ravel()
    x.ghostUpdate()
    solver._sync(x)
    if history is not None:
        history(solver.coupling)
    if freeze:
        solver.coupling.update(solver.u.x.array)
    x0 = x.copy()  # x is the solver's state: every residual evaluation overwrites it
    F0, F1, F2 = (solver.bulk.create_vector() for _ in range(3))
    solver._residual(None, x0, F0)
    J = solver.J
    solver._jacobian(None, x0, J, J)
    du = x.duplicate()
    du.getArray()[:] = rng.standard_normal(len(du.getArray())) * 1e-4
    Jdu = J.createVecLeft()
    J.mult(du, Jdu)

    def error(eps):
        for sign, F in ((1.0, F1), (-1.0, F2)):
            xs = x0.copy()
            xs.axpy(sign * eps, du)
            solver._residual(None, xs, F)
        fd = F1.copy()
        fd.axpy(-1.0, F2)
        fd.scale(0.5 / eps)
        fd.axpy(-1.0, Jdu)
        return fd.norm() / Jdu.norm()

    return error, solver.coupling, solver


#: the compiled gradient-error forms of each problem, by measure (see grad_error)
_GRAD_FORMS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def grad_error(problem, measure, l1: float, l2: float) -> float:
    """sqrt(int |grad u - diag(l1 - 1, l2 - 1)|^2) over ``measure``, u the problem's
    displacement (2D): the distance to a homogeneous stretch. The stretch is a Constant, so the
    form is compiled once per problem and measure (and found in the JIT cache for the next
    problem), whatever the stretches."""
    import dolfinx.fem
    import numpy as np
    import ufl

    forms = _GRAD_FORMS.setdefault(problem, {})
    key = repr(measure)
    if key not in forms:
        G = dolfinx.fem.Constant(problem.mesh, np.zeros((2, 2)))
        diff = ufl.grad(problem.U) - G
        forms[key] = (G, dolfinx.fem.form(ufl.inner(diff, diff) * measure))
    G, form = forms[key]
    G.value[:] = np.diag([l1 - 1.0, l2 - 1.0])
    total = problem.mesh.comm.allreduce(dolfinx.fem.assemble_scalar(form), op=MPI.SUM)
    return float(np.sqrt(total))


def psi(model: str, m, F):
    """The strain energies of contactfx.mechanics.hyperelastic written in NumPy, independently
    of UFL (Bonet and Wood 2008, doi:10.1017/CBO9780511755446, 6.4.3; Holzapfel 2000, ISBN
    978-0-471-82319-3, 6.5), of a 3 x 3 F (complex: a complex step passes through); ``m``
    has mu and lmbda (neo-hookean, svk) or c10, c01 and bulk (mooney-rivlin)."""
    import numpy as np

    C = F.T @ F
    J, I1 = np.linalg.det(F), np.trace(C)
    if model == "svk":
        E = 0.5 * (C - np.eye(3))
        return 0.5 * m.lmbda * np.trace(E) ** 2 + m.mu * np.sum(E * E)
    if model == "mooney-rivlin":
        I2 = 0.5 * (I1**2 - np.trace(C @ C))
        return (
            m.c10 * (J ** (-2 / 3) * I1 - 3)
            + m.c01 * (J ** (-4 / 3) * I2 - 3)
            + 0.5 * m.bulk * np.log(J) ** 2
        )
    return 0.5 * m.mu * (I1 - 3 - 2 * np.log(J)) + 0.5 * m.lmbda * np.log(J) ** 2


class StopAt:
    """A StopRequest that answers SIGTERM at the k-th step boundary (monkeypatched for
    ``contactfx.driver.pipeline.StopRequest``: a run stopped there, as by a signal)."""

    k = 0

    def __init__(self, comm) -> None:
        self.n = 0

    def __enter__(self) -> StopAt:
        return self

    def __exit__(self, *exc) -> None:
        pass

    def requested(self) -> int:
        self.n += 1
        return signal.SIGTERM if self.n == self.k else 0
