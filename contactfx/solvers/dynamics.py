"""Implicit time integration: the Newmark family as a :class:`contactfx.solvers.stepper.Stepper`.

One step of the generalised-alpha method (Chung and Hulbert 1993, doi:10.1115/1.2900803)
solves the balance at the intermediate times t_{n+1-alpha_m} (inertia) and t_{n+1-alpha_f}
(internal, contact and external forces)

    M a_{n+1-alpha_m} + f_int(u_{n+1-alpha_f}) + f_c(u_{n+1-alpha_f}) = f_ext(t_{n+1-alpha_f})

with x_{n+1-alpha} = (1 - alpha) x_{n+1} + alpha x_n and Newmark's updates (Newmark 1959)

    u_{n+1} = u_n + dt v_n + dt^2 ((1/2 - beta) a_n + beta a_{n+1})
    v_{n+1} = v_n + dt ((1 - gamma) a_n + gamma a_{n+1}).

The unknown the nonlinear solver iterates on is w = u_{n+1-alpha_f} (the state the forces are
evaluated at: a nonlinear bulk, the contact and friction laws read it as they read a static
state). With u_{n+1} = (w - alpha_f u_n) / (1 - alpha_f) the inertia term is

    M a_{n+1-alpha_m} = c M w - M a*,   c = (1 - alpha_m) / ((1 - alpha_f) beta dt^2),
    a* = (1 - alpha_m) ((u_n / (1 - alpha_f) + dt v_n) / (beta dt^2) + (1 / (2 beta) - 1) a_n)
         - alpha_m a_n,

so a step is a static solve of the bulk plus c M (its Jacobian K + c M: a linear bulk
assembles it once per step size) under the extra load M a*. The velocity at the force time is
affine in w too: Newmark's updates give v_{n+1} = gamma / (beta dt) (u_{n+1} - u_n)
+ (1 - gamma / beta) v_n + dt (1 - gamma / (2 beta)) a_n, and with (1 - alpha_f)(u_{n+1} - u_n)
= w - u_n,

    v_{n+1-alpha_f} = c_v w - v*,   c_v = gamma / (beta dt),
    v* = c_v u_n - (1 - alpha_f) ((1 - gamma / beta) v_n + dt (1 - gamma / (2 beta)) a_n)
         - alpha_f v_n

(a force that reads the velocity, a contact dashpot, is a law of w alone; with Newmark's
average acceleration v_{n+1} = 2 (u_{n+1} - u_n) / dt - v_n, the trapezoidal rule). The
schemes:

* ``newmark``: alpha_m = alpha_f = 0, beta = 1/4, gamma = 1/2 (average acceleration: no
  numerical dissipation, the energy of a linear system conserved);
* ``hht``: Hilber, Hughes and Taylor 1977 (doi:10.1002/eqe.4290050306), alpha_m = 0,
  alpha_f = (1 - rho_inf) / (1 + rho_inf) in [0, 1/3] (rho_inf in [1/2, 1]),
  gamma = 1/2 + alpha_f, beta = (1 + alpha_f)^2 / 4;
* ``generalized-alpha``: alpha_m = (2 rho_inf - 1) / (rho_inf + 1),
  alpha_f = rho_inf / (rho_inf + 1), gamma = 1/2 - alpha_m + alpha_f,
  beta = (1 - alpha_m + alpha_f)^2 / 4 (rho_inf in [0, 1]: the spectral radius at
  dt -> infinity; 1 is the average acceleration rule).

All are second-order accurate and unconditionally stable for linear problems (the alpha-method
sign convention here is Chung and Hulbert's: HHT's alpha is -alpha_f).

The adaptive step (``time_tolerance`` > 0) estimates each converged step's local error in the
displacement from the change of the acceleration (Zienkiewicz and Xie 1991,
doi:10.1002/eqe.4290200905): Newmark's displacement update is exact to dt^2 / 2 a and its
leading error term is (beta - 1/6) dt^3 da/dt, so

    e_{n+1} = (beta - 1/6) dt^2 (a_{n+1} - a_n),   eta = |e_{n+1}| / |u_{n+1}|

(Euclidean norms over the unknown's dofs: the error relative to the displacement, as
Zienkiewicz and Xie's; relative to the step's increment instead, the acceleration's jumps at
the nodes whose contact status changes, which no step size removes, shrank disc-drop's steps
to a sixtieth of the fixed step's throughout the contact).
A step with eta above the tolerance is repeated at half the size; after a step with eta below
the tolerance / 16 (a cubic estimate grows eightfold when the step doubles) the next step
doubles, up to ``dt``. The steps stay ``dt`` / 2^k, so that the effective stiffness K + c M
takes few values (each change of the step assembles and factorises it again). A free flight
under a constant load has a_{n+1} = a_n: no error, the largest step; an impact shrinks the
steps around it.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

from petsc4py import PETSc

from contactfx.solvers.snes import SolveStats
from contactfx.solvers.stepper import CutBack, Snapshot, StepRecord

__all__ = ["Scheme", "SCHEMES", "Dynamic"]

SCHEMES = ("newmark", "hht", "generalized-alpha")


@dataclass(frozen=True)
class Scheme:
    """The four parameters of a generalised-alpha scheme (module docstring)."""

    name: str
    alpha_m: float
    alpha_f: float
    beta: float
    gamma: float

    @classmethod
    def named(cls, name: str, rho_inf: float = 1.0) -> Scheme:
        """``newmark`` (rho_inf unused), ``hht`` (rho_inf in [1/2, 1]) or
        ``generalized-alpha`` (rho_inf in [0, 1]); ValueError otherwise."""
        if not 0.0 <= rho_inf <= 1.0:
            raise ValueError(f"--rho-inf must lie in [0, 1], got {rho_inf}")
        if name == "newmark":
            return cls(name, 0.0, 0.0, 0.25, 0.5)
        if name == "hht":
            if rho_inf < 0.5:
                raise ValueError(
                    f"--scheme hht needs --rho-inf in [0.5, 1] (alpha in [-1/3, 0]), got "
                    f"{rho_inf}; use --scheme generalized-alpha below 0.5"
                )
            af = (1.0 - rho_inf) / (1.0 + rho_inf)
            return cls(name, 0.0, af, 0.25 * (1.0 + af) ** 2, 0.5 + af)
        if name == "generalized-alpha":
            am = (2.0 * rho_inf - 1.0) / (rho_inf + 1.0)
            af = rho_inf / (rho_inf + 1.0)
            return cls(name, am, af, 0.25 * (1.0 - am + af) ** 2, 0.5 - am + af)
        raise ValueError(f"unknown time scheme {name!r}; one of {', '.join(SCHEMES)}")

    def mass_factor(self, dt: float) -> float:
        """c of the inertia term c M w - M a* (module docstring)."""
        return (1.0 - self.alpha_m) / ((1.0 - self.alpha_f) * self.beta * dt * dt)

    def velocity_factor(self, dt: float) -> float:
        """c_v of the velocity at the force time c_v w - v* (module docstring)."""
        return self.gamma / (self.beta * dt)


class Dynamic(CutBack):
    """The time steps t = dt, 2 dt, ..., t_end of a :class:`Scheme` (see the module
    docstring): holds u_n, v_n, a_n, sets the inertia load a* and the mass factor c for each
    step, and on a converged step computes u_{n+1}, v_{n+1}, a_{n+1}. A failed step is retried
    with half the step, up to ``max_cutbacks`` halvings in a row; after a converged step the
    step doubles back towards ``dt`` (a fixed step with cut-back; with ``time_tolerance`` the
    adaptive step of the module docstring, :meth:`reject`). Each change of the step size
    changes c: ``set_mass_factor(c)`` sets it in the forms and ``reassemble()`` re-assembles
    the bulk (K + c M); ``reassemble(keep_preconditioner=True)`` after a restart, whose c is
    the checkpoint's.

    ``v``, ``a``, ``a_star``: the (ghosted) vectors of the velocity, acceleration and inertia
    load Functions, in the unknown's layout; ``initial_acceleration(x, a)``: a_0 from the
    balance at the initial state (collective), called at :meth:`start` unless ``a`` holds
    it already (``a0_given``). ``fields``: other vectors restored on a cut-back (a multiplier).
    ``v_star`` (optional: a law that reads the velocity, the contact dashpot): the vector of
    the velocity load v*, set with the velocity factor ``set_velocity_factor(c_v)`` at every
    step (the velocity at the force time is c_v w - v*); without it neither is computed.
    ``dynamic_dofs`` (optional: a mixed unknown with a multiplier field): 1 on the dofs with
    inertia, 0 on the multiplier's, whose velocity and acceleration are kept 0 (the multiplier
    each step's contact law fixes is no state of the time integration).
    """

    #: not restored by a restart: the restarted run's bulk was assembled with c = 0, and is
    #: assembled again at its first step (its kept preconditioner, restored, stays)
    checkpoint_skip = ("_ready",)
    #: how far the adaptive step may shrink: dt / 2^ADAPTIVE_HALVINGS
    ADAPTIVE_HALVINGS = 12

    def __init__(
        self,
        scheme: Scheme,
        *,
        dt: float,
        t_end: float,
        v: PETSc.Vec,
        a: PETSc.Vec,
        a_star: PETSc.Vec,
        set_mass_factor: Callable[[float], None],
        reassemble: Callable[..., None],
        initial_acceleration: Callable[[PETSc.Vec, PETSc.Vec], None] | None = None,
        max_cutbacks: int = 6,
        fields: Sequence[PETSc.Vec] = (),
        t_start: float = 0.0,
        time_tolerance: float = 0.0,
        v_star: PETSc.Vec | None = None,
        set_velocity_factor: Callable[[float], None] | None = None,
        dynamic_dofs: PETSc.Vec | None = None,
    ) -> None:
        if not dt > 0.0:
            raise ValueError(f"--dt must be > 0, got {dt}")
        if not t_end >= t_start + dt * (1.0 - 1e-12):
            raise ValueError(f"--t-end ({t_end}) must be at least one step (--dt {dt})")
        self.scheme, self.dt_base, self.t_end = scheme, dt, t_end
        self.v, self.a, self.a_star = v, a, a_star
        self.set_mass_factor, self.reassemble = set_mass_factor, reassemble
        self.initial_acceleration = initial_acceleration
        self.max_cutbacks, self.fields = max_cutbacks, list(fields)
        self.t_start = t_start
        if (v_star is None) != (set_velocity_factor is None):
            raise TypeError("v_star and set_velocity_factor go together")
        self.v_star, self.set_velocity_factor = v_star, set_velocity_factor
        #: 1 on the dofs the updates apply to, 0 on an algebraic field's (a multiplier: its
        #: velocity and acceleration are kept 0, the predictor leaves it at its last value,
        #: the error estimate leaves it out); None: every dof
        self.dynamic_dofs = dynamic_dofs
        if not time_tolerance >= 0.0:
            raise ValueError(f"--time-tolerance must be >= 0, got {time_tolerance}")
        #: the adaptive step's tolerance (module docstring); 0: a fixed step with cut-back
        self.time_tolerance = time_tolerance
        if time_tolerance > 0.0:  # the estimate may halve the step 12 times (dt / 4096)
            self.max_cutbacks = max(self.max_cutbacks, self.ADAPTIVE_HALVINGS)
        #: the last step's error estimate eta (0 without the adaptive step)
        self.eta = 0.0
        self.step = 0

    # -- the Stepper protocol ------------------------------------------------------------------
    def start(self, x: PETSc.Vec) -> None:
        self.x = x
        if self.initial_acceleration is not None:
            self.initial_acceleration(x, self.a)
        if self.dynamic_dofs is not None:
            self._algebraic_zero(self.v, self.a)
            _ghost_update(self.v)
            _ghost_update(self.a)
        #: u_n, v_n, a_n (and the other fields) of the last accepted step
        self.previous = Snapshot([x, self.v, self.a, *self.fields])
        self.t_prev = self.t_start
        self.dt = self.dt_base
        self.dt_min = self.dt / 2**self.max_cutbacks
        if self.time_tolerance > 0.0:  # u_{n+1} and the error estimate (work vectors)
            self._u_new, self._error = x.duplicate(), x.duplicate()
        self._c: float | None = None
        self._ready = False  # the bulk assembled with the mass factor _c
        self.cutbacks = 0
        self.step = 0

    def done(self) -> bool:
        return self.t_prev >= self.t_end - 1e-9 * self.dt_base

    def next_time(self) -> float:
        self.t = min(self.t_end, self.t_prev + self.dt)
        if self.t_end - self.t < 1e-6 * self.dt:  # no sliver of a last step
            self.t = self.t_end
        #: the step's size: the nominal one unless the end clipped it (so that the times'
        #: round-off does not change c M and re-assemble the bulk)
        self.h = self.t - self.t_prev
        if abs(self.h - self.dt) <= 1e-9 * self.dt:
            self.h = self.dt
        return self.t

    def load_time(self) -> float:
        """The time the step's forces are evaluated at: t_{n+1-alpha_f}."""
        af = self.scheme.alpha_f
        return (1.0 - af) * self.t + af * self.t_prev

    def predict(self) -> None:
        """a* and c of the step (with ``v_star``, v* and c_v too); w starts at
        u_n + (1 - alpha_f)(dt v_n + dt^2 / 2 a_n)."""
        s, dt = self.scheme, self.h
        self.previous.restore()
        c = s.mass_factor(dt)
        if c != self._c:  # K + c M assembled again (the first time: it had c = 0)
            self.set_mass_factor(c)
            self.reassemble()
            self._c, self._ready = c, True
        elif not self._ready:  # a restarted run: c restored, the bulk not yet assembled
            self.set_mass_factor(c)
            self.reassemble(keep_preconditioner=True)
            self._ready = True
        u_n, v_n, a_n = self.previous.copies[:3]
        af, am, b = s.alpha_f, s.alpha_m, s.beta
        # a* = (1 - am) / (b dt^2) (u_n / (1 - af) + dt v_n) + ((1 - am)(1/(2b) - 1) - am) a_n
        k = (1.0 - am) / (b * dt * dt)
        self.a_star.set(0.0)
        self.a_star.axpy(k / (1.0 - af), u_n)
        self.a_star.axpy(k * dt, v_n)
        self.a_star.axpy((1.0 - am) * (0.5 / b - 1.0) - am, a_n)
        _ghost_update(self.a_star)
        if self.v_star is not None and self.set_velocity_factor is not None:
            # v* = c_v u_n - ((1 - af)(1 - g / b) + af) v_n - (1 - af) dt (1 - g / (2 b)) a_n
            g = s.gamma
            c_v = s.velocity_factor(dt)
            self.set_velocity_factor(c_v)
            self.v_star.set(0.0)
            self.v_star.axpy(c_v, u_n)
            self.v_star.axpy(-((1.0 - af) * (1.0 - g / b) + af), v_n)
            self.v_star.axpy(-(1.0 - af) * dt * (1.0 - 0.5 * g / b), a_n)
            _ghost_update(self.v_star)
        self.x.axpy((1.0 - af) * dt, v_n)
        self.x.axpy((1.0 - af) * 0.5 * dt * dt, a_n)
        _ghost_update(self.x)

    def _end_displacement(self, w: PETSc.Vec) -> None:
        """w (the unknown, u_{n+1-alpha_f}) made u_{n+1} = (w - alpha_f u_n) / (1 - alpha_f),
        in place (ghosts not updated)."""
        af = self.scheme.alpha_f
        if af != 0.0:
            w.axpy(-af, self.previous.copies[0])
            w.scale(1.0 / (1.0 - af))

    def _end_acceleration(self, u: PETSc.Vec, out: PETSc.Vec) -> None:
        """Newmark's a_{n+1} = (u_{n+1} - u_n - dt v_n) / (b dt^2) - (1 / (2 b) - 1) a_n of the
        step's end displacement ``u`` into ``out`` (ghosts not updated)."""
        b, dt = self.scheme.beta, self.h
        u_n, v_n, a_n = self.previous.copies[:3]
        u.copy(out)
        out.axpy(-1.0, u_n)
        out.axpy(-dt, v_n)
        out.scale(1.0 / (b * dt * dt))
        out.axpy(-(0.5 / b - 1.0), a_n)

    def reject(self, stats: SolveStats) -> bool:
        """Whether a converged step's error estimate asks for a smaller step (the adaptive
        step, module docstring; always False at a fixed step). Sets ``eta``."""
        if not self.time_tolerance > 0.0:
            return False
        b, dt = self.scheme.beta, self.h
        u = self._u_new
        self.x.copy(u)
        self._end_displacement(u)
        e = self._error  # (b - 1/6) dt^2 (a_{n+1} - a_n)
        self._end_acceleration(u, e)
        e.axpy(-1.0, self.previous.copies[2])
        e.scale((b - 1.0 / 6.0) * dt * dt)
        self._algebraic_zero(u, e)
        size, error = u.norm(), e.norm()
        self.eta = error / size if size > 0.0 else (0.0 if error == 0.0 else float("inf"))
        return self.eta > self.time_tolerance

    def accept(self, stats: SolveStats) -> StepRecord:
        """u_{n+1} from w, then a_{n+1} and v_{n+1} (Newmark's updates); the unknown is set
        to u_{n+1} (the state of the output and of the next step's history)."""
        dt, g = self.h, self.scheme.gamma
        _, v_n, a_n = self.previous.copies[:3]
        self._end_displacement(self.x)
        _ghost_update(self.x)
        a = self.a
        self._end_acceleration(self.x, a)
        self._algebraic_zero(a)
        _ghost_update(a)
        # v_{n+1} = v_n + dt ((1 - g) a_n + g a_{n+1})
        v = self.v
        v_n.copy(v)
        v.axpy(dt * (1.0 - g), a_n)
        v.axpy(dt * g, a)
        self._algebraic_zero(v)
        _ghost_update(v)
        self.step += 1
        self.previous.save()
        record = StepRecord(step=self.step, time=self.t, dt=dt, stats=stats, cutbacks=self.cutbacks)
        self.t_prev = self.t
        grow = self.cutbacks == 0 and self.dt < self.dt_base * (1.0 - 1e-12)
        if self.time_tolerance > 0.0:  # where the estimate allows twice the step
            grow = grow and 16.0 * self.eta <= self.time_tolerance
        if grow:
            self.dt = min(self.dt_base, 2.0 * self.dt)
        self.cutbacks = 0
        return record

    def _algebraic_zero(self, *vectors: PETSc.Vec) -> None:
        """0 on the dofs without inertia (``dynamic_dofs``), in place (ghosts not updated)."""
        if self.dynamic_dofs is not None:
            for vec in vectors:
                vec.pointwiseMult(vec, self.dynamic_dofs)

    def describe(self, t: float) -> str:
        return f"time {t:.6g}"

    def destroy(self) -> None:
        self.previous.destroy()
        for work in ("_u_new", "_error"):
            if hasattr(self, work):
                getattr(self, work).destroy()


def _ghost_update(x: PETSc.Vec) -> None:
    x.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
