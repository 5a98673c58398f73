"""The seams of the solver: a nonlinear bulk in ContactSNES, and a stepper's state on cut-back.

1. A compressible neo-Hookean square (plane strain, two P1 triangles) stretched by l1 = 1.5
   along x, free laterally: the deformation is homogeneous, F = diag(l1, l2), so P1 represents
   it exactly and the discrete solution is the exact one. With the strain energy
   psi = mu/2 (I1 - 3 - 2 ln J) + lambda/2 (ln J)^2 (I1 = tr C + 1 in plane strain) the first
   Piola stress is P = mu (F - F^-T) + lambda ln J F^-T; the free lateral faces give P22 = 0,
   i.e. mu (l2^2 - 1) + lambda ln(l1 l2) = 0 (solved by bisection), and the reaction on the
   stretched face is P11 = mu (l1 - 1/l1) + lambda ln(l1 l2) / l1 per unit reference length.
   The bulk is a :class:`NonlinearBulk` (residual and Jacobian from UFL at every iteration),
   stepped by the quasi-static stepper; Newton converges quadratically.
2. The whole pipeline with a NonlinearBulk: Hertz 2D with the elastic material flagged as
   not linear, so that the obstacle kind assembles its bulk from the material's weak stress
   and ``ufl.derivative`` at every iteration, gives the LinearBulk's numbers (Nitsche; al-ssn,
   whose multiplier field takes the reduced system; the VI, whose pressure is the bulk's
   reaction).
3. :class:`QuasiStatic` restores every field it holds (the unknown and another field) when a
   step is cut back, and on giving up.

(test_snes: the cubic-spring bar with its linear part as a NonlinearBulk.) Run at 1 and 2
ranks.
"""

from __future__ import annotations

import dataclasses

import dolfinx.fem
import dolfinx.mesh
import numpy as np
import pytest
import ufl
from mpi4py import MPI
from petsc4py import PETSc

from contactfx import _compat
from contactfx.mechanics.elasticity import Elastic
from contactfx.scenes.hertz import Hertz2D
from contactfx.solvers.bulk import NonlinearBulk
from contactfx.solvers.snes import ContactSNES, ConvergenceError, SolveStats
from contactfx.solvers.stepper import QuasiStatic, march

COMM = MPI.COMM_WORLD
MU, LMBDA, L1 = 1.0, 2.0, 1.5


def lateral_stretch(l1: float) -> float:
    """l2 with mu (l2^2 - 1) + lambda ln(l1 l2) = 0 (increasing in l2; the root lies in
    (0, 1] for l1 >= 1): 200 bisections reach the last ulp."""
    lo, hi = 1e-6, 1.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        f = MU * (mid**2 - 1.0) + LMBDA * np.log(l1 * mid)
        lo, hi = (mid, hi) if f < 0.0 else (lo, mid)
    return 0.5 * (lo + hi)


def neo_hookean_square(prefix: str):
    """(solver, u, the right face's x dofs, load factor Constant)."""
    mesh = dolfinx.mesh.create_unit_square(COMM, 1, 1)
    V = _compat.function_space(mesh, "Lagrange", 1, (2,))
    u, v, du = dolfinx.fem.Function(V), ufl.TestFunction(V), ufl.TrialFunction(V)
    F = ufl.Identity(2) + ufl.grad(u)
    J = ufl.det(F)
    FinvT = ufl.inv(F).T
    P = MU * (F - FinvT) + LMBDA * ufl.ln(J) * FinvT
    internal = ufl.inner(P, ufl.grad(v)) * ufl.dx
    load = ufl.inner(dolfinx.fem.Constant(mesh, np.zeros(2)), v) * ufl.dx
    t = dolfinx.fem.Constant(mesh, PETSc.ScalarType(0.0))
    Vx, _ = V.sub(0).collapse()
    left = _compat.locate_dofs_topological(
        (V.sub(0), Vx),
        1,
        dolfinx.mesh.locate_entities_boundary(mesh, 1, lambda x: np.isclose(x[0], 0.0)),
    )
    right_facets = dolfinx.mesh.locate_entities_boundary(mesh, 1, lambda x: np.isclose(x[0], 1.0))
    right = _compat.locate_dofs_topological((V.sub(0), Vx), 1, right_facets)
    Vy, _ = V.sub(1).collapse()
    corner = dolfinx.fem.locate_dofs_geometrical(
        (V.sub(1), Vy), lambda x: np.isclose(x[0], 0.0) & np.isclose(x[1], 0.0)
    )
    zero_x, zero_y, stretch = (dolfinx.fem.Function(W) for W in (Vx, Vy, Vx))
    stretch_value = dolfinx.fem.Constant(mesh, PETSc.ScalarType(L1 - 1.0))
    bcs = [
        _compat.dirichletbc(zero_x, left, V.sub(0)),
        _compat.dirichletbc(zero_y, corner, V.sub(1)),
        _compat.dirichletbc(stretch, right, V.sub(0)),
    ]
    bulk = NonlinearBulk(
        internal=dolfinx.fem.form(internal),
        tangent=dolfinx.fem.form(ufl.derivative(internal, u, du)),
        load=dolfinx.fem.form(load),
    )
    solver = ContactSNES(u, bulk=bulk, bcs=bcs, prefix=prefix)

    def apply_load(s: float) -> None:
        t.value = s
        stretch.x.array[:] = s * stretch_value.value

    return solver, u, np.asarray(right[0]), apply_load


def test_neo_hookean_bulk_stretch():
    solver, u, right, apply_load = neo_hookean_square("cfx_seam_nh_")
    norms: list[list[float]] = []
    solver.snes.setMonitor(
        lambda snes, it, norm: (norms.append([]) if it == 0 else None, norms[-1].append(norm))
    )
    records = march(QuasiStatic(3), solver, apply_load)
    R = solver.reactions()
    n_owned = u.function_space.dofmap.index_map.size_local * 2
    mine = right[right < n_owned]
    force = COMM.allreduce(float(np.sum(R.getArray()[mine])), op=MPI.SUM)
    R.destroy()
    solver.destroy()
    assert [r.time for r in records] == pytest.approx([1 / 3, 2 / 3, 1.0], rel=1e-15)
    l2 = lateral_stretch(L1)
    x = _compat.dof_coordinates(u.function_space)[: n_owned // 2, :2]
    exact = np.stack([(L1 - 1.0) * x[:, 0], (l2 - 1.0) * x[:, 1]], axis=1)
    err = np.abs(u.x.array[:n_owned].reshape(-1, 2) - exact).max(initial=0.0)
    # the exact solution is in the space; SNES stops at |F| <= 1e-10 |F_0| (|F_0| < 1, the
    # stiffness O(mu + lambda)): the nodal error is below 1e-9, round-off 1e-15
    assert COMM.allreduce(err, op=MPI.MAX) < 1e-9
    P11 = MU * (L1 - 1.0 / L1) + LMBDA * np.log(L1 * l2) / L1
    assert force == pytest.approx(P11, rel=1e-9)  # the same bound through the residual
    # Newton converges quadratically: near the root each residual is at most C times the
    # square of the one before, with C of the order of |J^-1| |J'| (~1 here); measured
    # ratios r_{k+1} / r_k^2 are below 2 on this problem
    for hist in norms:
        tail = [(a, b) for a, b in zip(hist[:-1], hist[1:], strict=True) if a < 1e-2 and b > 1e-14]
        assert tail and all(b <= 10.0 * a**2 for a, b in tail), hist
    assert all(r.stats.newton <= 6 for r in records)


@dataclasses.dataclass(frozen=True)
class _Flagged(Elastic):
    """Small-strain elasticity declared not linear: the bulk goes through NonlinearBulk."""

    linear = False


class _FlaggedHertz(Hertz2D):
    def material(self) -> Elastic:
        return _Flagged(self.p.E, self.p.nu)


@pytest.mark.parametrize("method", ["nitsche", "al-ssn", "vi"])
def test_pipeline_with_a_nonlinear_bulk(method):
    params = Hertz2D.Params(h_contact=6e-3)
    runs = []
    for cls in (Hertz2D, _FlaggedHertz):
        scene = cls(params)
        runs.append(scene.run(scene.default_numerics(method=method), verbose=False))
    linear, nonlinear = runs
    # the same equations assembled in another order: the iterates agree to round-off, so the
    # iteration counts are equal and the contact quantities agree to the Newton tolerance
    # (relative residual 1e-10) times the conditioning, measured below 1e-11
    assert [s.newton for s in nonlinear.steps] == [s.newton for s in linear.steps]
    for name in ("force", "contact_size", "peak_pressure"):
        assert getattr(nonlinear, name) == pytest.approx(getattr(linear, name), rel=1e-9), name


class _FieldStub:
    """A solver stand-in with a second field w beside u: a step converges iff its load
    increment is at most ``limit`` (then u = t and w = 10 t everywhere); a failing solve
    leaves garbage (NaN) in both before raising. Records t, u and w at each solve's entry
    and whether it converged."""

    def __init__(self, limit: float) -> None:
        mesh = _compat.create_interval(COMM, 4, 1.0)
        V = _compat.function_space(mesh, "Lagrange", 1)
        self.u, self.w = dolfinx.fem.Function(V), dolfinx.fem.Function(V)
        self.limit, self.t, self.t_done = limit, 0.0, 0.0
        self.entries: list[tuple[float, np.ndarray, np.ndarray, bool]] = []

    def set_load(self, t: float) -> None:
        self.t = t

    def assemble_load(self) -> None:
        pass

    def solve(self) -> SolveStats:
        ok = self.t - self.t_done <= self.limit
        self.entries.append((self.t, self.u.x.array.copy(), self.w.x.array.copy(), ok))
        if not ok:
            self.u.x.array[:] = np.nan
            self.w.x.array[:] = np.nan
            raise ConvergenceError("DIVERGED_MAX_IT")
        self.u.x.array[:] = self.t
        self.w.x.array[:] = 10.0 * self.t
        self.t_done = self.t
        return SolveStats()


def test_stepper_restores_every_field_on_cutback():
    stub = _FieldStub(limit=0.3)
    w = _compat.petsc_vec(stub.w)
    records = march(QuasiStatic(2, fields=[w]), stub, stub.set_load)
    # 1/2 fails (increment 0.5 > 0.3), 1/4 and 1/2 converge, the increment grows back to 1/2:
    # 1 fails, 3/4 and 1 converge
    assert [r.time for r in records] == [0.25, 0.5, 0.75, 1.0]
    assert [r.cutbacks for r in records] == [1, 0, 1, 0]
    assert [(e[0], e[3]) for e in stub.entries] == [
        (0.5, False),
        (0.25, True),
        (0.5, True),
        (1.0, False),
        (0.75, True),
        (1.0, True),
    ]
    # every solve starts from the last converged state, not a failed solve's NaNs: w at its
    # last converged value, u at the secant predictor (exact for u linear in t; the start
    # u = 0 before the first converged step)
    converged = 0.0
    for t, u_in, w_in, ok in stub.entries:
        np.testing.assert_allclose(u_in, t if converged > 0.0 else 0.0, rtol=1e-15)
        assert np.all(w_in == 10.0 * converged)
        converged = t if ok else converged

    # giving up: every field back at the last converged state
    stub = _FieldStub(limit=0.3)
    w = _compat.petsc_vec(stub.w)
    records = []

    def shrink(rec):
        stub.limit = 0.0  # nothing converges after the first step
        records.append(rec)

    with pytest.raises(ConvergenceError) as err:
        march(QuasiStatic(4, max_cutbacks=2, fields=[w]), stub, stub.set_load, on_step=shrink)
    assert err.value.step == 2 and len(records) == 1
    assert np.all(stub.u.x.array == 0.25) and np.all(stub.w.x.array == 2.5)


def test_stepper_adaptive_growth():
    # SolveStats() has newton = 0: every step is easy. Increments 0.1 (1 / steps), then x 1.5
    # up to max_increment = 0.3: 0.1, 0.15, 0.225, 0.3, 0.225 (the rest to 1)
    stub = _FieldStub(limit=1.0)
    records = march(QuasiStatic(10, max_increment=0.3), stub, stub.set_load)
    np.testing.assert_allclose(
        [r.time for r in records], [0.1, 0.25, 0.475, 0.775, 1.0], rtol=1e-14
    )
    # after a cut-back the increment first returns to the base, then grows: limit 0.2 makes
    # 0.225 fail (halved to 0.1125), then 0.1 (the base, from 2 x 0.1125 capped), 0.15 ...
    stub = _FieldStub(limit=0.2)
    records = march(QuasiStatic(10, max_increment=0.3), stub, stub.set_load)
    dts = np.diff([0.0] + [r.time for r in records])
    assert dts.max() <= 0.2 + 1e-12 and records[-1].time == 1.0
    assert [r.cutbacks for r in records][:3] == [0, 0, 1]
    # without max_increment the increment never exceeds 1 / steps (today's program)
    stub = _FieldStub(limit=1.0)
    records = march(QuasiStatic(4), stub, stub.set_load)
    assert [r.time for r in records] == [0.25, 0.5, 0.75, 1.0]
    with pytest.raises(ValueError, match="maximum increment"):
        QuasiStatic(4, max_increment=1.5)


def test_stepper_failure_carries_the_diagnosis():
    stub = _FieldStub(limit=0.0)
    with pytest.raises(ConvergenceError, match="at load step 1 .*; an element inverted") as err:
        march(
            QuasiStatic(1, max_cutbacks=1),
            stub,
            stub.set_load,
            diagnose=lambda: "an element inverted",
        )
    assert err.value.detail == "an element inverted"


def test_stepper_rejects_no_steps():
    with pytest.raises(ValueError, match="load steps must be >= 1"):
        QuasiStatic(0)


@pytest.mark.parametrize("gdim", [2, 3])
def test_one_hookes_law_for_ufl_and_the_couplings(gdim):
    """The two-body couplings' tractions of the P1 basis, sigma(N_a e_c) n, come from the
    material's Hooke's law: equal (to round-off) to UFL's Elastic.sigma of the same
    displacement interpolated on one cell, and zero for n = 0 (a Gauss point with no master
    facet: its Nitsche terms vanish; a shortcut that assumed |n| = 1 once left
    lambda d_c N_a there)."""
    from contactfx.mechanics.elasticity import basis_tractions, lame

    E, nu = 3.0, 0.3
    lmbda, mu = lame(E, nu)
    mesh = (
        dolfinx.mesh.create_unit_square(MPI.COMM_SELF, 1, 1)
        if gdim == 2
        else dolfinx.mesh.create_unit_cube(MPI.COMM_SELF, 1, 1, 1)
    )
    V = _compat.function_space(mesh, "Lagrange", 1, (gdim,))
    x = _compat.dof_coordinates(V)[:, :gdim]
    cell_nodes = np.asarray(V.dofmap.cell_dofs(0))
    X = x[cell_nodes]
    # P1 gradients of the cell's basis: rows of the inverse of [1 x]
    grads = np.linalg.inv(np.hstack([np.ones((gdim + 1, 1)), X]))[1:].T  # (A, d)
    rng = np.random.default_rng(3)
    n = rng.normal(size=gdim)
    n /= np.linalg.norm(n)
    T = basis_tractions(
        grads[None], np.stack([n, np.zeros(gdim)]), np.full(2, lmbda), np.full(2, mu)
    )
    assert np.all(T[1] == 0.0)
    material = Elastic(E, nu)
    w = dolfinx.fem.Function(V)
    expr = _compat.expression(ufl.dot(material.sigma(w), ufl.as_vector(n)), V)
    for a, node in enumerate(cell_nodes):
        for c in range(gdim):
            w.x.array[:] = 0.0
            w.x.array[node * gdim + c] = 1.0
            # sigma is constant on the cell: its traction at the cell's first point
            t = _compat.eval_expression(expr, mesh, np.array([0], dtype=np.int32))
            t = np.asarray(t).reshape(-1)[:gdim]
            np.testing.assert_allclose(T[0, a, c], t, rtol=1e-13, atol=1e-13)  # round-off
