"""Unit tests of :mod:`contactfx.solvers.snes` (ContactSNES) and :mod:`contactfx.solvers.loadstep`.

Problem with a known discrete root: a P1 bar (0, L) of N cells, u(0) = 0, stiffness E u' v',
body force t F, and a cubic spring K u^3 at x = L (the nonlinear "contact" residual). P1 is
nodally exact in 1D, so the discrete root is the exact solution u = -t F x^2 / (2 E) + c x at
the nodes, with u_L the only real root of the condensed equation

    g(u_L; t) = E u_L / L + K u_L^3 - t F L / 2 = 0

(solved here by bisection). The bulk equations are linear, so Newton's iterates on the full
system are Newton's iterates on g (the condensed residual of any iterate is g(u_L), and after
the first step the full residual is g(u_L) in the end row only): the iteration counts are
predicted by a scalar Newton loop with the SNES stopping test of DEFAULT_OPTIONS.

Tested: the root, the iteration count, ConvergenceError with the SNES reason, destroy()
removing the prefixed options, and run_load_program (:mod:`contactfx.solvers.stepper`'s
quasi-static program: steps, secant predictor, cut-back).
Run at 1 and 2 ranks (values compared at the dof coordinates, reductions with allreduce).
"""

from __future__ import annotations

import dolfinx.fem
import dolfinx.mesh
import numpy as np
import pytest
import ufl
from mpi4py import MPI
from petsc4py import PETSc

from contactfx import _compat
from contactfx.solvers.bulk import LinearBulk, NonlinearBulk
from contactfx.solvers.snes import DEFAULT_OPTIONS, ContactSNES, ConvergenceError
from contactfx.solvers.stepper import QuasiStatic, march, run_load_program

COMM = MPI.COMM_WORLD
L, N, E, F, K = 1.0, 4, 1.0, 3.0, 4.0
H = L / N
RTOL, ATOL = DEFAULT_OPTIONS["snes_rtol"], DEFAULT_OPTIONS["snes_atol"]


def g(u, t, e=E):
    return e / L * u + K * u**3 - t * F * L / 2.0


def root(t, e=E):
    """Bisection on g (increasing) over [0, t F L^2 / (2 E)] (the root lies below the
    spring-free end displacement): 200 halvings reach the last ulp. ``e``: Young's modulus."""
    lo, hi = 0.0, t * F * L**2 / (2.0 * e)
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if g(mid, t, e) < 0.0 else (lo, mid)
    return 0.5 * (lo + hi)


def f0_from_zero(t):
    """||F(0)||_2 of the full residual at u = 0: -b, i.e. t F h at the N - 1 interior nodes,
    t F h / 2 at x = L, and 0 in the Dirichlet row."""
    return t * F * H * np.sqrt(N - 1 + 0.25)


def newton_count(u, t, f0):
    """Newton steps on g from u until |g| < max(atol, rtol f0) (SNESConvergedDefault). In the
    cases below the last two |g| straddle that threshold by a factor >= 2 (quadratic
    convergence), far beyond the round-off (~1e-16) between this loop and the full system."""
    for it in range(1, 100):
        u -= g(u, t) / (E / L + 3.0 * K * u**2)
        if abs(g(u, t)) < max(ATOL, RTOL * f0):
            return it
    raise AssertionError("scalar Newton did not converge")


def tolerance(f0):
    """Bound on |u - u*| at the nodes when SNES stops: |F|_2 < max(atol, rtol f0) and the
    inverse Jacobian's entries (the Green's function of the bar fixed at 0, stiffened by the
    spring) are <= L / E, so |u - u*|_inf <= L / E sqrt(N + 1) |F|_2; plus round-off 1e-14."""
    return L / E * np.sqrt(N + 1) * max(ATOL, RTOL * f0) + 1e-14


def make_solver(prefix, bulk="linear", modulus=None, **kwargs):
    """(ContactSNES, u, load factor Constant) of the bar; kwargs go to ContactSNES. ``bulk``:
    its linear part as a LinearBulk (``"linear"``) or as the residual form of a NonlinearBulk,
    assembled at every iteration (``"nonlinear"``) or once (``"constant"``); ``modulus``: a
    function of the mesh giving E in the forms (default the float E)."""
    mesh = _compat.create_interval(COMM, N, L)
    V = _compat.function_space(mesh, "Lagrange", 1)
    u, v, du = dolfinx.fem.Function(V), ufl.TestFunction(V), ufl.TrialFunction(V)
    right = dolfinx.mesh.locate_entities_boundary(mesh, 0, lambda x: np.isclose(x[0], L))
    tags = dolfinx.mesh.meshtags(mesh, 0, right, np.full(len(right), 2, dtype=np.int32))
    ds = ufl.Measure("ds", domain=mesh, subdomain_data=tags)
    left = dolfinx.mesh.locate_entities_boundary(mesh, 0, lambda x: np.isclose(x[0], 0.0))
    bc = _compat.dirichletbc(PETSc.ScalarType(0.0), _compat.locate_dofs_topological(V, 0, left), V)
    t = dolfinx.fem.Constant(mesh, PETSc.ScalarType(1.0))
    e = E if modulus is None else modulus(mesh)
    Fc = K * u**3 * v * ds(2)
    load = dolfinx.fem.form(t * F * v * ufl.dx)
    if bulk == "linear":
        a = e * ufl.inner(ufl.grad(du), ufl.grad(v)) * ufl.dx
        bulk = LinearBulk(stiffness=dolfinx.fem.form(a), load=load)
    else:
        f_int = e * ufl.inner(ufl.grad(u), ufl.grad(v)) * ufl.dx
        bulk = NonlinearBulk(
            internal=dolfinx.fem.form(f_int),
            tangent=dolfinx.fem.form(ufl.derivative(f_int, u, du)),
            load=load,
            constant_jacobian=bulk == "constant",
        )
    solver = ContactSNES(
        u,
        bulk=bulk,
        contact_residual=dolfinx.fem.form(Fc),
        contact_jacobian=dolfinx.fem.form(ufl.derivative(Fc, u, du)),
        bcs=[bc],
        prefix=prefix,
        **kwargs,
    )
    return solver, u, t


def nodal_error(u, t, e=E):
    """max over the nodes of |u - exact discrete root at load t| (all ranks; ``e``: Young's
    modulus)."""
    uL = root(t, e)
    c = (uL + t * F * L**2 / (2.0 * e)) / L
    n = u.function_space.dofmap.index_map.size_local
    x = _compat.dof_coordinates(u.function_space)[:n, 0]
    err = np.abs(u.x.array[:n] - (-t * F * x**2 / (2.0 * e) + c * x))
    return COMM.allreduce(err.max(initial=0.0), op=MPI.MAX)


@pytest.mark.parametrize("bulk", ["linear", "nonlinear", "constant"])
def test_root_and_newton_count(bulk):
    """The same root and counts whether the bulk is assembled once or at every iteration."""
    solver, u, t = make_solver(f"cfx_unit_root_{bulk}_", bulk)
    solver.assemble_load()
    stats = solver.solve()
    R = solver.reactions()
    n = u.function_space.dofmap.index_map.size_local
    at_support = np.isclose(_compat.dof_coordinates(u.function_space)[:n, 0], 0.0)
    reaction = COMM.allreduce(float(R.getArray()[at_support].sum()), op=MPI.SUM)
    R.destroy()
    solver.destroy()
    assert stats.reason.startswith("CONVERGED_FNORM")
    assert nodal_error(u, 1.0) < tolerance(f0_from_zero(1.0))  # see tolerance()
    # the support carries the load F L less the spring's K u_L^3 (equilibrium of the whole
    # bar): the sum of all rows of the residual, the free ones each below the SNES tolerance
    f0 = f0_from_zero(1.0)
    assert abs(reaction + F * L - K * root(1.0) ** 3) < np.sqrt(N) * max(ATOL, RTOL * f0) + 1e-14
    # Newton on g from 0: the first step gives the spring-free u_L = 1.5, then g is convex and
    # increasing, so the iterates fall monotonically onto the root (0.607), the error shrinking
    # by >= 1/3 a step and quadratically at the end: the scalar loop needs 7 steps (<= 8), and
    # the full system takes exactly the same ones (module docstring)
    expected = newton_count(0.0, 1.0, f0_from_zero(1.0))
    assert expected <= 8
    assert stats.newton == expected


def test_backtracking_line_search_finds_the_root():
    """With ``-snes_linesearch_type bt`` the full first step from 0 (u_L = 1.5, |g| = 13.5
    against 1.5 at 0) is backtracked, and the line search's trial points are X - lambda Y
    from the iterate X it started at: the solve reaches the same root as full Newton steps.
    (When the residual callback wrote its trial point into u, which was also SNES's iterate,
    every later trial started from the rejected full step, and the line search failed.)"""
    solver, u, _ = make_solver("cfx_unit_bt_", user_options={"snes_linesearch_type": "bt"})
    solver.assemble_load()
    stats = solver.solve()
    solver.destroy()
    assert stats.reason.startswith("CONVERGED_FNORM")
    assert nodal_error(u, 1.0) < tolerance(f0_from_zero(1.0))  # see tolerance()


def owned_max_at_most(bound, entries=None):
    """A collective predicate of a vector: its largest owned entry (of the local indices
    ``entries``, or all) is <= bound on every rank."""

    def admissible(x):
        values = x.getArray() if entries is None else x.getArray()[entries]
        return COMM.allreduce(bool(np.all(values <= bound)), op=MPI.LAND)

    return admissible


def test_step_halving():
    """Newton's first step from 0 is the spring-free bar, u = 3 x - 1.5 x^2 (u_L = 1.5, its
    largest value); with the steps limited to max u <= 1 it is halved once (u_L = 0.75), and
    from there the iterates are scalar Newton's on g from 0.75 (the next linear solve restores
    the bulk rows exactly): they fall onto the root 0.607 with max u <= 0.76 (at x = 0.7), so
    no other step is halved. The root is the bar's."""
    solver, u, _ = make_solver("cfx_unit_halving_")
    solver.limit_steps(owned_max_at_most(1.0))
    solver.assemble_load()
    stats = solver.solve()
    solver.destroy()
    assert stats.halvings == 1
    assert stats.newton == 1 + newton_count(0.75, 1.0, f0_from_zero(1.0))
    assert nodal_error(u, 1.0) < tolerance(f0_from_zero(1.0))  # see tolerance()


def test_step_halving_gives_up():
    """A bound that no step meets (max u <= -1, not even the start): every step is given up
    after MAX_HALVINGS halvings and taken whole, so Newton's iterates and count are the bar's
    own; none is counted as halved."""
    solver, u, _ = make_solver("cfx_unit_halving_none_")
    solver.limit_steps(owned_max_at_most(-1.0))
    solver.assemble_load()
    stats = solver.solve()
    given_up = solver.halving.given_up
    solver.destroy()
    assert stats.halvings == 0
    assert given_up == stats.newton == newton_count(0.0, 1.0, f0_from_zero(1.0))
    assert nodal_error(u, 1.0) < tolerance(f0_from_zero(1.0))  # see tolerance()


def test_max_it_raises_with_reason():
    assert newton_count(0.0, 1.0, f0_from_zero(1.0)) > 1  # one step is not enough
    solver, _, _ = make_solver("cfx_unit_maxit_", options={"snes_max_it": 1})
    solver.assemble_load()
    with pytest.raises(ConvergenceError, match="DIVERGED_MAX_IT") as err:
        solver.solve()
    solver.destroy()
    assert err.value.reason == "DIVERGED_MAX_IT"
    assert err.value.step is None and err.value.load is None


def test_destroy_removes_prefixed_options():
    opts = PETSc.Options()
    opts["cfx_other_snes_rtol"] = "0.5"  # another solver's option: must survive
    solver, _, _ = make_solver("cfx_unit_destroy_", user_options={"snes_max_it": 7})
    assert opts.getString("cfx_unit_destroy_snes_rtol") == str(DEFAULT_OPTIONS["snes_rtol"])
    assert opts.getString("cfx_unit_destroy_snes_max_it") == "7"  # the user's value wins
    assert solver.snes.getTolerances()[3] == 7
    solver.destroy()
    assert not [k for k in opts.getAll() if k.startswith("cfx_unit_destroy_")]
    assert opts.getString("cfx_other_snes_rtol") == "0.5"
    opts.delValue("cfx_other_snes_rtol")


def test_load_program_steps():
    solver, u, t = make_solver("cfx_unit_steps_")
    states = []

    def on_step(rec):
        states.append(nodal_error(u, rec.load))

    records = run_load_program(solver, lambda s: setattr(t, "value", s), steps=3, on_step=on_step)
    solver.destroy()
    loads = [1 / 3, 2 / 3, 1.0]
    assert [r.step for r in records] == [1, 2, 3] and [r.cutbacks for r in records] == [0, 0, 0]
    np.testing.assert_allclose([r.load for r in records], loads, rtol=1e-15)  # t_prev + 1/3
    # starts: 0, then the secant predictors 2 u(1/3) and 2 u(2/3) - u(1/3); their bulk rows
    # vanish (linear in the load), so ||F0|| = |g| of the predicted end value
    r1, r2 = root(1 / 3), root(2 / 3)
    starts = [(0.0, f0_from_zero(1 / 3)), (2 * r1, abs(g(2 * r1, 2 / 3)))]
    starts.append((2 * r2 - r1, abs(g(2 * r2 - r1, 1.0))))
    for err, (_, f0) in zip(states, starts, strict=True):
        assert err < tolerance(f0)  # see tolerance()
    counts = [newton_count(u0, s, f0) for s, (u0, f0) in zip(loads, starts, strict=True)]
    assert [r.stats.newton for r in records] == counts
    assert counts[2] < counts[0]  # the predictor pays off


def test_load_program_previous_predictor():
    """With the predictor "previous" each step starts from the last converged state: 0, u(1/3)
    and u(2/3). The bulk is linear and u(s) is the root at load s, so the residual at the start
    of a step to load s + 1/3 is the load increment alone (the residual of 0 at load 1/3): the
    same norm at every step (the secant's starts have other norms). Newton's iterates are scalar
    Newton's on g from the start's end value (module docstring)."""
    solver, u, t = make_solver("cfx_unit_previous_")
    first = []  # the residual norm each solve starts from
    solver.snes.setMonitor(lambda snes, its, norm: first.append(norm) if its == 0 else None)
    records = march(QuasiStatic(3, predictor="previous"), solver, lambda s: setattr(t, "value", s))
    error = nodal_error(u, 1.0)
    solver.destroy()
    loads, f0 = [1 / 3, 2 / 3, 1.0], f0_from_zero(1 / 3)
    assert error < tolerance(f0)  # see tolerance()
    # the converged roots differ from the bisection's by the SNES tolerance (< 1e-10)
    np.testing.assert_allclose(first, [f0] * 3, rtol=1e-9)
    starts = [0.0, root(1 / 3), root(2 / 3)]
    counts = [newton_count(u0, s, f0) for s, u0 in zip(loads, starts, strict=True)]
    assert [r.stats.newton for r in records] == counts
    with pytest.raises(ValueError, match="secant or previous"):
        QuasiStatic(3, predictor="linear")


def test_load_program_cutback():
    # snes_max_it = M with M < (steps from 0 to the full load) but enough from 0 to t = 1/2
    # and from the predictor 2 u(1/2) to t = 1: one halving, then two steps
    full = newton_count(0.0, 1.0, f0_from_zero(1.0))
    half = newton_count(0.0, 0.5, f0_from_zero(0.5))
    r = root(0.5)
    second = newton_count(2 * r, 1.0, abs(g(2 * r, 1.0)))
    m = full - 1
    assert half <= m and second <= m
    solver, u, t = make_solver("cfx_unit_cut_", options={"snes_max_it": m})
    records = run_load_program(solver, lambda s: setattr(t, "value", s), steps=1)
    assert [(r.load, r.cutbacks) for r in records] == [(0.5, 1), (1.0, 0)]
    assert [r.stats.newton for r in records] == [half, second]
    assert nodal_error(u, 1.0) < tolerance(abs(g(2 * r, 1.0)))  # see tolerance()

    # never converging (max_it 1): 1, 1/2, 1/4 fail, ConvergenceError names step 1, load 1/4
    # and u is back at the last converged state (here: the start, u = 0)
    solver.destroy()
    solver, u, t = make_solver("cfx_unit_cut1_", options={"snes_max_it": 1})
    with pytest.raises(ConvergenceError) as err:
        run_load_program(solver, lambda s: setattr(t, "value", s), steps=1, max_cutbacks=2)
    solver.destroy()
    assert (err.value.step, err.value.load, err.value.reason) == (1, 0.25, "DIVERGED_MAX_IT")
    # owned entries restored exactly (run_load_program does not update the ghosts then)
    assert _compat.petsc_vec(u).norm(3) == 0.0


class _ShrinkingWindow:
    """A solver stand-in whose step converges only if its load increment is at most ``limit``,
    and each success halves the limit: steps that each need one cut-back, the pattern that
    shrank the increment without end (a Nitsche contact cycling at one load factor)."""

    def __init__(self, limit: float) -> None:
        mesh = _compat.create_interval(COMM, N, L)
        self.u = dolfinx.fem.Function(_compat.function_space(mesh, "Lagrange", 1))
        self.limit, self.t, self.t_done = limit, 0.0, 0.0

    def set_load(self, t: float) -> None:
        self.t = t

    def assemble_load(self) -> None:
        pass

    def solve(self):
        from contactfx.solvers.snes import SolveStats

        if self.t - self.t_done > self.limit:
            raise ConvergenceError("DIVERGED_MAX_IT")
        self.limit, self.t_done = 0.5 * (self.t - self.t_done), self.t
        return SolveStats()


def test_load_program_increment_floor():
    # max_cutbacks 2, steps 1: the increment never drops below 1 / 4^2. Increments 1, 1/2 fail,
    # 1/4 converges (t = 1/4); 1/4 fails, 1/8 converges (3/8); 1/8 fails, 1/16 converges
    # (7/16); 1/16 fails and 1/32 would be below the floor: ConvergenceError at step 4,
    # t = 7/16 + 1/16. Without the floor t crept towards 1/2 until t - t_prev was 0
    stub = _ShrinkingWindow(limit=0.3)
    with pytest.raises(ConvergenceError) as err:
        run_load_program(stub, stub.set_load, steps=1, max_cutbacks=2)
    assert (err.value.step, err.value.load) == (4, 0.5)
    assert stub.t_done == 7 / 16


@pytest.mark.parametrize("halving", [False, True])
def test_confined_field_leaves_the_system(halving):
    """The spring force as a second field lam of a mixed space [P1] x P1, confined to the end
    node x = L (``confined``: zero at every other node): u-equation E u'v' - t F v + lam v at
    x = L, lam-equation (lam - K u^3) mu at x = L. Its root is the cubic-spring bar's with
    lam = K u_L^3, and Newton's iterates are the bar's (lam is eliminated exactly by each
    linear solve), so the root, the count and the system size are all predicted: SNES works on
    the N + 1 displacement dofs and the one kept multiplier dof, not on 2 (N + 1).

    ``halving``: the steps limited to max u <= 1 as in test_step_halving, the predicate asked
    on the full layout (the kept dofs put back in place): the first step is halved, the rest
    are the bar's from u_L = 0.75."""
    from contactfx.driver.fields import confine, surface_mask

    mesh = _compat.create_interval(COMM, N, L)
    W = _compat.mixed_space(mesh, 1, 1, ())
    w, dw, tw = dolfinx.fem.Function(W), ufl.TrialFunction(W), ufl.TestFunction(W)
    (u, lam), (du, _), (v, mu) = ufl.split(w), ufl.split(dw), ufl.split(tw)
    right = dolfinx.mesh.locate_entities_boundary(mesh, 0, lambda x: np.isclose(x[0], L))
    tags = dolfinx.mesh.meshtags(mesh, 0, right, np.full(len(right), 2, dtype=np.int32))
    ds = ufl.Measure("ds", domain=mesh, subdomain_data=tags)
    left = dolfinx.mesh.locate_entities_boundary(mesh, 0, lambda x: np.isclose(x[0], 0.0))
    U = W.sub(0).sub(0) if W.sub(0).num_sub_spaces else W.sub(0)  # [P1]^1 (dolfinx 0.5) or P1
    dofs = _compat.locate_dofs_topological(U, 0, left)
    bc = _compat.dirichletbc(PETSc.ScalarType(0.0), dofs, U)
    confined = confine(W.sub(1), lambda Q: surface_mask(Q, 0, right))
    Fc = lam * v[0] * ds(2) + (lam - K * u[0] ** 3) * mu * ds(2)
    solver = ContactSNES(
        w,
        bulk=LinearBulk(
            stiffness=dolfinx.fem.form(E * ufl.inner(ufl.grad(du), ufl.grad(v)) * ufl.dx),
            load=dolfinx.fem.form(F * v[0] * ufl.dx),
        ),
        contact_residual=dolfinx.fem.form(Fc),
        contact_jacobian=dolfinx.fem.form(ufl.derivative(Fc, w, dw)),
        bcs=[bc, *confined],
        prefix=f"cfx_unit_confined_{halving}_",
        confined=confined,
    )
    if halving:
        u_dofs = np.asarray(W.sub(0).collapse()[1])
        n_owned = W.dofmap.index_map.size_local * W.dofmap.index_map_bs
        solver.limit_steps(owned_max_at_most(1.0, u_dofs[u_dofs < n_owned]))
    solver.assemble_load()
    stats = solver.solve()
    size = solver.J.getSize()[0]
    solver.destroy()
    assert size == N + 2  # the displacement and the one multiplier dof at x = L
    u_h = w.sub(0).sub(0).collapse() if W.sub(0).num_sub_spaces else w.sub(0).collapse()
    lam_h = w.sub(1).collapse()
    assert nodal_error(u_h, 1.0) < tolerance(f0_from_zero(1.0))  # see tolerance()
    # lam = K u_L^3 at the root (a residual row, met to the same tolerance times the spring's
    # stiffness 3 K u_L^2 <= 3 K), zero at the other nodes exactly (confined)
    n = lam_h.function_space.dofmap.index_map.size_local
    x = _compat.dof_coordinates(lam_h.function_space)[:n, 0]
    end = np.isclose(x, L)
    err = np.abs(lam_h.x.array[:n][end] - K * root(1.0) ** 3).max(initial=0.0)
    assert COMM.allreduce(err, op=MPI.MAX) < 3 * K * tolerance(f0_from_zero(1.0)) + 1e-13
    assert COMM.allreduce(np.abs(lam_h.x.array[:n][~end]).max(initial=0.0), op=MPI.MAX) == 0.0
    if halving:
        assert stats.halvings == 1
        assert stats.newton == 1 + newton_count(0.75, 1.0, f0_from_zero(1.0))
    else:
        assert stats.newton == newton_count(0.0, 1.0, f0_from_zero(1.0))


@pytest.mark.parametrize("gdim", [2, 3])
def test_rigid_body_modes(gdim):
    """The AMG near-nullspace: orthonormal, and in the kernel of the unconstrained
    elasticity stiffness (rigid motions have zero strain, exactly for P1)."""
    from contactfx.solvers.snes import rigid_body_modes

    comm = MPI.COMM_WORLD
    if gdim == 2:
        mesh = dolfinx.mesh.create_unit_square(comm, 4, 3)
    else:
        mesh = dolfinx.mesh.create_unit_cube(comm, 3, 2, 2)
    V = _compat.function_space(mesh, "Lagrange", 1, (gdim,))
    u, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    a = dolfinx.fem.form(ufl.inner(ufl.sym(ufl.grad(u)), ufl.sym(ufl.grad(v))) * ufl.dx)
    K = _compat.assemble_matrix(_compat.create_matrix(a), a)
    modes = rigid_body_modes(V).getVecs()
    assert len(modes) == (3 if gdim == 2 else 6)
    Kz = K.createVecLeft()
    for i, z in enumerate(modes):
        for j, w in enumerate(modes):
            # Gram-Schmidt in double precision: orthonormal to round-off
            assert z.dot(w) == pytest.approx(1.0 if i == j else 0.0, abs=1e-12)
        K.mult(z, Kz)
        # K's entries are O(1) on this mesh, z has unit norm: K z is round-off
        assert Kz.norm() < 1e-12


def test_linear_start_failure_names_the_reason():
    """A singular linear start (the stiffness minus itself on the free dofs) raises
    ConvergenceError naming the KSP reason and MUMPS's INFOG(1) (-10: numerically singular),
    instead of leaving PETSc's Inf in u as the Newton solve's start."""
    solver, u, _ = make_solver("cfx_unit_linear_")
    solver.assemble_load()
    V = u.function_space
    du, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    minus_k = dolfinx.fem.form(-E * ufl.inner(ufl.grad(du), ufl.grad(v)) * ufl.dx)
    free = np.ones(V.dofmap.index_map.size_local, dtype=bool)
    with pytest.raises(ConvergenceError, match=r"linear start.*INFOG\(1\) = -10"):
        solver.solve_linear(free, minus_k)
    solver.solve_linear(free)  # the regular start still solves: the spring-free bar
    solver.destroy()
    assert not [k for k in PETSc.Options().getAll() if k.startswith("cfx_unit_linear_")]
    n = V.dofmap.index_map.size_local
    x = _compat.dof_coordinates(V)[:n, 0]
    exact = -F * x**2 / (2.0 * E) + F * L * x / E  # u' (L) = 0, t = 1
    # P1 is nodally exact in 1D; the LU solve is exact to round-off
    assert COMM.allreduce(np.abs(u.x.array[:n] - exact).max(initial=0.0), op=MPI.MAX) < 1e-12


@pytest.mark.parametrize("bulk", ["linear", "nonlinear", "constant"])
def test_bulk_reassembled_when_its_constants_change(bulk):
    """E a Constant of the bulk's forms, doubled after a first solve (as a dynamic stepper
    changes its step size in K + c M): after ``reassemble_bulk`` the solver finds the root of
    the stiffer bar, for a bulk assembled once (K again, in place) or at every iteration. The
    first solve is the root with E; a linear bulk not reassembled would keep solving it."""
    moduli = []

    def modulus(mesh):
        moduli.append(dolfinx.fem.Constant(mesh, PETSc.ScalarType(E)))
        return moduli[-1]

    solver, u, t = make_solver(f"cfx_unit_reassemble_{bulk}_", bulk, modulus=modulus)
    solver.assemble_load()
    solver.solve()
    first = nodal_error(u, 1.0)
    moduli[0].value = 2.0 * E
    solver.reassemble_bulk()
    solver.solve()
    second = nodal_error(u, 1.0, 2.0 * E)
    solver.destroy()
    # tolerance(): the bound of the SNES stopping test (with E; the stiffer bar's is smaller)
    assert first < tolerance(f0_from_zero(1.0))
    assert second < tolerance(f0_from_zero(1.0))
    assert root(1.0, 2.0 * E) < 0.9 * root(1.0)  # the two roots differ far beyond that


def test_auto_line_search_follows_the_method():
    """``--line-search auto``: cp for the penalised methods (their residual is an energy's
    gradient), basic for the multiplier methods (a saddle point: on shallow-ironing with mortar
    cp took 82 load steps with 39 cut-backs, full steps 44 with 4); another value is kept."""
    from contactfx.contact.registry import method_class
    from contactfx.driver.pipeline import line_search_type

    expected = {"penalty": "cp", "compliance": "cp", "mortar": "basic", "nitsche": "basic"}
    for name, kind in expected.items():
        assert line_search_type("auto", method_class(name)) == kind
        assert line_search_type("bt", method_class(name)) == "bt"
