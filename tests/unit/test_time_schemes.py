"""The time stepper of the Newmark family (:mod:`contactfx.solvers.dynamics`) on an undamped
oscillator m u'' + k u = 0, u(0) = 1, v(0) = 0, whose discrete solutions are known in closed
form (Hughes 2000, The Finite Element Method, chapter 9; Chung and Hulbert 1993,
doi:10.1115/1.2900803):

1. the parameters of each scheme at rho_inf = 1 reduce to the average acceleration rule, and
   generalised-alpha's are Chung and Hulbert's formulas;
2. Newmark's average acceleration is the trapezoidal rule: u_n = cos(n Omega) with
   tan(Omega / 2) = omega dt / 2 exactly, and the energy 1/2 m v^2 + 1/2 k u^2 constant;
3. every scheme is second-order accurate (the error at t = 1 falls by 4 when dt halves), and
   with rho_inf < 1 the amplitude of a mode with omega dt = 1e4 falls by rho_inf per step;
4. a failed step is cut back: u, v, a restored, the step halved, the mass factor set anew.

The "solver" solves the step's linear equation (k + c m) w = m a* exactly on one value per
rank (each rank's own oscillator), so that the stepper alone is tested.
"""

from __future__ import annotations

import dolfinx.fem
import dolfinx.mesh
import numpy as np
import pytest
from mpi4py import MPI

from contactfx import _compat
from contactfx.solvers.dynamics import Dynamic, Scheme
from contactfx.solvers.snes import ConvergenceError, SolveStats
from contactfx.solvers.stepper import march

COMM = MPI.COMM_WORLD


class Oscillator:
    """m u'' + k u = f on every dof of a DG0 field (one cell per rank): what march asks of a
    solver, and the stepper's callbacks."""

    def __init__(self, k: float, m: float = 1.0, fail_at: float | None = None) -> None:
        mesh = dolfinx.mesh.create_unit_interval(COMM, 2 * COMM.size)
        V = _compat.function_space(mesh, "DG", 0)
        self.u, self.v, self.a, self.a_star = (dolfinx.fem.Function(V) for _ in range(4))
        self.k, self.m, self.c = k, m, 0.0
        self.fail_at, self.reassembled = fail_at, 0
        self.t = 0.0

    # the solver
    def assemble_load(self) -> None: ...

    def solve(self) -> SolveStats:
        if self.fail_at is not None and self.t > self.fail_at:
            self.fail_at = None  # fails once
            raise ConvergenceError("DIVERGED_MAX_IT")
        self.u.x.array[:] = self.m * self.a_star.x.array / (self.k + self.c * self.m)
        return SolveStats(newton=1, ksp=1)

    # the stepper's callbacks
    def set_mass_factor(self, c: float) -> None:
        self.c = c

    def reassemble(self, keep_preconditioner: bool = False) -> None:
        self.reassembled += 1

    def initial_acceleration(self, x, a) -> None:
        a.setArray(-self.k / self.m * x.getArray())

    def stepper(
        self,
        scheme: Scheme,
        dt: float,
        t_end: float,
        given: bool = False,
        time_tolerance: float = 0.0,
    ) -> Dynamic:
        vec = _compat.petsc_vec
        return Dynamic(
            scheme,
            dt=dt,
            t_end=t_end,
            v=vec(self.v),
            a=vec(self.a),
            a_star=vec(self.a_star),
            set_mass_factor=self.set_mass_factor,
            reassemble=self.reassemble,
            initial_acceleration=None if given else self.initial_acceleration,
            time_tolerance=time_tolerance,
        )

    def run(
        self, scheme: Scheme, dt: float, t_end: float, start: tuple | None = None
    ) -> list[tuple[float, float, float, float]]:
        """(t, u, v, a) after each step from u(0) = 1, v(0) = 0 (a(0) from the balance), or
        from the state ``start`` = (u, v, a)."""
        u0, v0, a0 = (1.0, 0.0, 0.0) if start is None else start
        self.u.x.array[:], self.v.x.array[:], self.a.x.array[:] = u0, v0, a0
        out: list[tuple[float, float, float, float]] = []

        def record(rec) -> None:
            arrays = (self.u, self.v, self.a)
            out.append((rec.time, *(float(f.x.array[0]) for f in arrays)))

        stepper = self.stepper(scheme, dt, t_end, given=start is not None)
        march(stepper, self, self.set_time, on_step=record)
        return out

    def set_time(self, t: float) -> None:
        self.t = t


def test_scheme_parameters():
    """rho_inf = 1: every scheme is the average acceleration rule's beta = 1/4, gamma = 1/2
    (generalised-alpha with alpha_m = alpha_f = 1/2); rho_inf = 0.5: Chung and Hulbert's
    alpha_m = 0, alpha_f = 1/3, the HHT scheme's alpha_f = 1/3 (exact fractions)."""
    for name in ("newmark", "hht", "generalized-alpha"):
        s = Scheme.named(name, 1.0)
        assert (s.beta, s.gamma) == (0.25, 0.5)
        assert s.alpha_m == s.alpha_f
    ga = Scheme.named("generalized-alpha", 0.5)
    assert ga.alpha_m == pytest.approx(0.0, abs=1e-15)
    assert ga.alpha_f == pytest.approx(1.0 / 3.0, rel=1e-15)
    assert ga.gamma == pytest.approx(0.5 + 1.0 / 3.0, rel=1e-15)
    assert ga.beta == pytest.approx(0.25 * (4.0 / 3.0) ** 2, rel=1e-15)
    hht = Scheme.named("hht", 0.5)
    assert (hht.alpha_m, hht.alpha_f) == (0.0, pytest.approx(1.0 / 3.0, rel=1e-15))
    with pytest.raises(ValueError, match="rho-inf in"):
        Scheme.named("hht", 0.4)
    with pytest.raises(ValueError, match=r"\[0, 1\]"):
        Scheme.named("generalized-alpha", 1.5)


def test_average_acceleration_is_the_trapezoidal_rule():
    """u_n = cos(n Omega), tan(Omega / 2) = omega dt / 2 (the trapezoidal rule's exact discrete
    solution), to 1e-12 after 400 steps (the round-off of 400 updates of values of order 1:
    1e-13); the energy constant to 1e-12 relative (measured 1e-13: the same round-off)."""
    omega, dt = 2.0 * np.pi, 0.05
    osc = Oscillator(k=omega**2)
    rows = osc.run(Scheme.named("newmark"), dt, 20.0)
    assert len(rows) == 400
    big_omega = 2.0 * np.arctan(omega * dt / 2.0)
    for n, (t, u, v, _) in enumerate(rows, start=1):
        assert t == pytest.approx(n * dt, rel=1e-12)
        assert abs(u - np.cos(n * big_omega)) <= 1e-12
        energy = 0.5 * v**2 + 0.5 * omega**2 * u**2
        assert energy == pytest.approx(0.5 * omega**2, rel=1e-12)


@pytest.mark.parametrize(
    "name, rho",
    [("newmark", 1.0), ("hht", 0.7), ("generalized-alpha", 0.5), ("generalized-alpha", 0.0)],
)
def test_second_order_and_the_spectral_radius(name, rho):
    """The error |u(t) - cos(omega t)| at t = 1.25 (where cos(omega t) = 0: the error is the
    phase error, not its square) at dt = 1/40, 1/80, 1/160 falls by 4 each time (the ratio
    within 3.6 and 4.4: the asymptotic constant is reached to 10 % at omega dt = 0.16); the
    spectral radius of the one-step map (u_n, v_n, a_n) -> (u_n+1, v_n+1, a_n+1), built column
    by column from three steps, is rho_inf at omega dt = 1e8 (to 1e-3: generalised-alpha's
    eigenvalues meet in a double one at the limit, so they differ from it by
    O((omega dt)^-1/2), 1e-4 here)."""
    scheme = Scheme.named(name, rho)
    omega = 2.0 * np.pi
    errors = []
    for n in (40, 80, 160):
        rows = Oscillator(k=omega**2).run(scheme, 1.0 / n, 1.25)
        errors.append(abs(rows[-1][1] - np.cos(1.25 * omega)))
    ratios = [errors[i] / errors[i + 1] for i in range(2)]
    assert all(3.6 <= r <= 4.4 for r in ratios), (errors, ratios)
    columns = [Oscillator(k=1e16).run(scheme, 1.0, 1.0, start=e)[0][1:] for e in np.eye(3)]
    radius = max(abs(np.linalg.eigvals(np.array(columns).T)))
    assert radius == pytest.approx(rho, abs=1e-3)


def test_a_failed_step_is_cut_back():
    """A step that fails is retried at dt / 2 from the restored state (u, v, a of the last
    accepted step); its mass factor is set for dt / 2 and the bulk re-assembled, then for dt
    again when the step grows back (after a step that needed no cut-back). The result equals
    a run whose steps are those sizes."""
    omega, dt = 2.0 * np.pi, 0.1
    osc = Oscillator(k=omega**2, fail_at=0.25)
    rows = osc.run(Scheme.named("newmark"), dt, 0.5)
    times = [r[0] for r in rows]
    assert times == pytest.approx([0.1, 0.2, 0.25, 0.3, 0.4, 0.5], abs=1e-12)
    # c for dt, dt / 2 (0.25 and 0.3), dt
    assert osc.reassembled == 3
    # the same program without the failure, stepped by hand: the trapezoidal rule's
    # amplification per step of size h applied to (u, v)
    u, v = 1.0, 0.0
    for h in np.diff([0.0, *times]):
        k = omega**2
        a = -k * u
        # (1 + k h^2 / 4) u1 = u + h v + h^2 / 4 a
        u1 = (u + h * v + 0.25 * h * h * a) / (1.0 + 0.25 * k * h * h)
        v = v + 0.5 * h * (a - k * u1)
        u = u1
    assert rows[-1][1] == pytest.approx(u, abs=1e-13)
    assert rows[-1][2] == pytest.approx(v, abs=1e-12)


def _one_step(scheme: Scheme, omega: float, t0: float, dt: float, tolerance: float):
    """One step of ``scheme`` from the exact state of u = cos(omega t) at t0, with the
    adaptive step's estimate on: (u_1, the stepper's eta, whether it asked for a smaller
    step)."""
    osc = Oscillator(k=omega**2)
    exact = (np.cos(omega * t0), -omega * np.sin(omega * t0), -(omega**2) * np.cos(omega * t0))
    osc.u.x.array[:], osc.v.x.array[:], osc.a.x.array[:] = exact
    stepper = osc.stepper(scheme, dt, dt, given=True, time_tolerance=tolerance)
    stepper.start(_compat.petsc_vec(osc.u))
    stepper.next_time()
    stepper.predict()
    osc.solve()
    asked = stepper.reject(SolveStats(newton=1, ksp=1))
    u1 = float(osc.u.x.array[0])
    stepper.destroy()
    return u1, stepper.eta, asked


@pytest.mark.parametrize(
    "name, rho, limit",
    [("newmark", 1.0, 1.0), ("hht", 0.7, 1.25), ("generalized-alpha", 0.5, 1.43)],
)
def test_error_estimate_is_the_local_error(name, rho, limit):
    """Zienkiewicz and Xie's estimate (beta - 1/6) dt^2 (a_1 - a_0) is the leading term of one
    Newmark step's error in u from an exact state, (beta - 1/6) dt^3 d3u/dt3: on
    u = cos(omega t) from t0 = 0.3 (d3u/dt3 != 0) the estimate over the true error tends to 1,
    at first order in omega dt (measured 1.052, 1.021, 1.0093, 1.0043 at omega dt = 0.2, 0.1,
    0.05, 0.025: asserted within 0.3 omega dt of 1). The alpha schemes' error has another
    constant: there the estimate is proportional to it, the ratio tending to 1.25 (HHT,
    rho_inf 0.7) and 1.43 (generalised-alpha, rho_inf 0.5) (measured 1.297 ... 1.252 and
    1.480 ... 1.433: asserted within 0.3 omega dt of the measured limit, to 0.01)."""
    scheme = Scheme.named(name, rho)
    omega, t0 = 2.0 * np.pi, 0.3
    for wdt in (0.2, 0.1, 0.05, 0.025):
        dt = wdt / omega
        u1, eta, _ = _one_step(scheme, omega, t0, dt, tolerance=1e30)
        if scheme.alpha_f != 0.0:  # the unknown is w = u_{n+1-alpha_f}: the step's u_{n+1}
            u0 = np.cos(omega * t0)
            u1 = (u1 - scheme.alpha_f * u0) / (1.0 - scheme.alpha_f)
        true = u1 - np.cos(omega * (t0 + dt))
        estimate = eta * abs(u1)  # every dof holds the same value: the norms' ratio
        ratio = estimate / abs(true)
        assert abs(ratio - limit) <= 0.3 * wdt + 0.01 * (limit != 1.0), (wdt, ratio)


def test_adaptive_step_rejects_above_the_tolerance_and_grows_below():
    """A step whose estimate exceeds the tolerance is repeated at half the size (and never
    accepted above it while a smaller step is left); each accepted step is dt / 2^k; after
    steps far below the tolerance the step doubles. On the oscillator u = cos(2 pi t) with
    dt = 0.2 (omega dt = 1.26) and a tolerance of 1e-3 the steps take sizes from 0.05 down to
    0.003 (the estimate is relative to |u|, which the single dof's cosine passes through 0)
    and back."""
    omega, dt, tol = 2.0 * np.pi, 0.2, 1e-3
    osc = Oscillator(k=omega**2)
    etas, sizes = [], []
    stepper = osc.stepper(Scheme.named("newmark"), dt, 1.0, time_tolerance=tol)
    osc.u.x.array[:] = 1.0

    def record(rec) -> None:
        etas.append(stepper.eta)
        sizes.append(rec.dt)

    march(stepper, osc, osc.set_time, on_step=record)
    assert max(etas) <= tol
    # (the last step: what is left to t_end)
    powers = [np.log2(dt / h) for h in sizes[:-1]]
    assert all(k == pytest.approx(round(k), abs=1e-9) for k in powers), sizes
    assert min(sizes) < dt
    assert sum(sizes) == pytest.approx(1.0, abs=1e-12)
    # the growth: a step follows one whose estimate was below tol / 16 at twice its size
    grew = [i for i in range(1, len(sizes)) if sizes[i] > sizes[i - 1] * (1.0 + 1e-12)]
    assert all(16.0 * etas[i - 1] <= tol for i in grew)
