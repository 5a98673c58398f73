"""A dynamic run's part of a problem kind: the inertia of the bodies and the energy balance.

:class:`Inertia` holds the velocity v, the acceleration a and the inertia load a* (Functions of
the unknown's space, the stepper's :class:`contactfx.solvers.dynamics.Dynamic` fields) and the
mass factor c, and gives the bulk its inertia terms: with density rho,

    linear bulk:    a(du, v) + c int rho du . v dx
    nonlinear bulk: f_int(u; v) + c int rho u . v dx
    load:           f_ext + int rho a* . v dx

(the effective stiffness K + c M of a linear bulk assembled once per step size). With a
contact dashpot (``--dashpot C``, the penalty's against a rigid obstacle:
:meth:`contactfx.contact.penalty.Penalty.dashpot_residual`) it holds C and the velocity at the
force time, c_v u - v* (:mod:`contactfx.solvers.dynamics`: the velocity factor c_v, a Constant,
and the velocity load v*, a Function). A static run has none of this (no mass matrix, no
velocity field), a dynamic run without a dashpot none of the latter.

The methods that hold the Signorini condition exactly at nodes (``vi``; the augmented
Lagrangian, ``al-ssn`` with its multiplier a field of the unknown, ``al-uzawa`` with its
nodal multiplier; dual ``mortar`` at the slave nodes between two bodies) run in time with the
redistributed mass only (Khenous, Laborde and Renard 2008; between two bodies the slave
surface's nodes lose their mass, as in Hager, Hueeber and Wohlmuth 2008, Int. J. Numer. Meth.
Engng 73, 205-225): a node without inertia takes its quasi-static place under the constraint
at every step, where a node with mass would be stopped in one step (an impact the time
scheme cannot resolve). A multiplier field has no inertia: its velocity and acceleration are
kept 0 (:attr:`Inertia.dynamic_dofs`), its value fixed by each step's contact law.

:class:`EnergyLedger` keeps the balance at every step: the kinetic energy 1/2 v . M v, the
strain energy (the material's density), the energy the contact terms store (the method's, e.g.
Nitsche's theta / (2 gamma_N) (P_n^2 - sigma_n^2), the penalty's kappa / 2 [-g]_+^2), the work
of the external loads (trapezoidal: 1/2 (f_ext,n + f_ext,n+1) . (u_n+1 - u_n)), friction's
dissipation (the sum over the steps of -int t_T . du_T ds, the traction at the step's end on
its slip increment: backward Euler's; between two bodies the pair's coupling sums the
traction of the step's balance, at t_{n+1-alpha_f}, on the step's slip), with a contact
dashpot its dissipation (trapezoidal:
D_dashpot += 1/2 (f_d,n + f_d,n+1) . (u_n+1 - u_n), f_d the dashpot's force vector at the
recorded state and velocity; with Newmark's average acceleration the rule under which the
discrete energy identity holds exactly, M (v_n+1 - v_n) = dt / 2 (F_n + F_n+1) and
u_n+1 - u_n = dt / 2 (v_n + v_n+1)), and the remainder W_ext - D_friction - D_dashpot
- (E - E_0): what the scheme dissipated (or gained: the error of a non-conserving
discretisation). A restart continues the balance (the ledger's totals and last force vectors
are in the checkpoint, :mod:`contactfx.io.checkpoint`). The supports are fixed in the scenes
that use it (no work); a moving support's or obstacle's work is not counted (it would appear
in the remainder), nor the energy a penalty or Nitsche friction term stores while sticking.
"""

from __future__ import annotations

import csv
from pathlib import Path
from typing import Any

import dolfinx
import numpy as np
import ufl
from petsc4py import PETSc

from contactfx import _compat
from contactfx.driver.fields import global_sum, surface_mask, vertex_rule
from contactfx.solvers.base import ConvergenceError

__all__ = ["Inertia", "EnergyLedger", "EnergyBlowUp", "plot_contact", "EXACT_CONSTRAINT"]

#: the methods whose converged state holds the Signorini condition exactly at the contact
#: nodes (bound constraints, the augmented Lagrangian's multiplier, dual mortar's at the slave
#: nodes): offered in time with the redistributed mass only (no inertia at the nodes where the
#: condition holds; Khenous, Laborde and Renard 2008, doi:10.1016/j.euromechsol.2007.12.001)
EXACT_CONSTRAINT = ("vi", "al-ssn", "al-uzawa", "mortar")


class Inertia:
    """See the module docstring. ``problem``: the kind (its state, measures, material)."""

    def __init__(self, problem: Any) -> None:
        if problem.up:
            raise ValueError(
                "--dynamic: the mixed u-p formulation is not offered in time yet; use "
                "--formulation displacement"
            )
        method, mass = problem.method.name, problem.num.mass
        if method in EXACT_CONSTRAINT and mass != "redistributed":
            raise ValueError(
                f"--dynamic --method {method} needs --mass redistributed: the exact Signorini "
                "condition on nodes that carry mass is ill-posed in time (the energy of "
                "bar-impact grows threefold over a period)"
            )
        rho = problem.material.density
        if rho is None:
            raise ValueError(
                f"--dynamic needs the body's density: scene '{problem.scene.name}' gives none "
                "(the dynamic scenes bar-impact, disc-drop and sliding-stop do; a problem "
                "file gives it per body, with [dynamics])"
            )
        field = problem.scene.density_field(problem.mesh)
        rho = rho if field is None else field
        W = problem.state.function_space
        self.v = dolfinx.fem.Function(W, name="velocity")
        self.a = dolfinx.fem.Function(W, name="acceleration")
        self.a_star = dolfinx.fem.Function(W, name="inertia_load")
        #: whether the unknown is mixed: (u, lambda) with a multiplier field, whose second
        #: field has no inertia (the stepper's updates leave it out: :meth:`dynamic_dofs`)
        self.split = problem.split
        #: a mixed unknown's indicator of its displacement dofs (1 there, 0 on the
        #: multiplier's): the stepper keeps the velocity and acceleration 0 on the multiplier,
        #: whose value each step's contact law fixes with no history of its own; None unless
        #: mixed
        self.dynamic_dofs = self._dynamic_dofs(W) if self.split else None
        self.c = dolfinx.fem.Constant(problem.mesh, 0.0)
        self.dx, self.rho = self._mass(problem, rho)
        #: the contact dashpot's coefficient C (``--dashpot``), the velocity factor c_v and the
        #: velocity load v* of the velocity at the force time c_v u - v*; None without one
        self.dashpot: dolfinx.fem.Constant | None = None
        self.c_v: dolfinx.fem.Constant | None = None
        self.v_star: dolfinx.fem.Function | None = None
        if problem.num.dashpot > 0.0:
            self.dashpot = dolfinx.fem.Constant(problem.mesh, float(problem.num.dashpot))
            self.c_v = dolfinx.fem.Constant(problem.mesh, 0.0)
            self.v_star = dolfinx.fem.Function(W, name="velocity_load")

    @staticmethod
    def _mass(problem: Any, rho: Any) -> tuple[ufl.Measure, Any]:
        """The mass's measure and density (``--mass``): consistent (dx, rho); lumped (the
        P1 cells' vertex rule: M_ii = the row sums); redistributed (lumped, with the density
        weighted by (1 - chi) / (1 - mean_K chi) at the vertices of cell K, chi the indicator
        of the contact surface's nodes: no mass at the contact, each cell's mass kept; a
        cell whose vertices are all on the contact loses its mass)."""
        mass = problem.num.mass
        if mass == "consistent":
            return problem.dx, rho
        mesh = problem.mesh
        dx = problem.dx(metadata=vertex_rule(mesh.topology.dim))
        if mass == "lumped":
            return dx, rho
        Q1 = _compat.function_space(mesh, "Lagrange", 1)
        chi = dolfinx.fem.Function(Q1, name="contact_nodes")
        chi.x.array[:] = surface_mask(Q1, problem.fdim, problem.contact_facets)
        mean = dolfinx.fem.Function(_compat.function_space(mesh, "DG", 0))
        mean.interpolate(chi)  # a P1 field's value at a simplex's centroid: its vertex mean
        weight = ufl.conditional(ufl.lt(mean, 1.0 - 1e-12), (1.0 - chi) / (1.0 - mean), 0.0)
        return dx, rho * weight

    def displacement(self, f: dolfinx.fem.Function) -> Any:
        """The displacement part of a Function of the unknown's space (all of it unless
        mixed)."""
        return ufl.split(f)[0] if self.split else f

    @staticmethod
    def _dynamic_dofs(W: Any) -> dolfinx.fem.Function:
        """A mixed space's indicator of its displacement dofs (1 there, 0 on the
        multiplier's)."""
        mask = dolfinx.fem.Function(W, name="dynamic_dofs")
        _, dofs = W.sub(0).collapse()
        mask.x.array[np.asarray(dofs)] = 1.0
        return mask

    def mass_term(self, du: Any, v: Any) -> ufl.Form:
        """c int rho du . v dx (bilinear: the linear bulk's K + c M)."""
        return self.c * self.rho * ufl.inner(du, v) * self.dx

    def load_term(self, v: Any) -> ufl.Form:
        """int rho a* . v dx (the bulk's extra load)."""
        return self.rho * ufl.inner(self.displacement(self.a_star), v) * self.dx

    def internal_term(self, u: Any, v: Any) -> ufl.Form:
        """c int rho u . v dx (a nonlinear bulk's inertia in its residual; its tangent is the
        mass term)."""
        return self.c * self.rho * ufl.inner(u, v) * self.dx

    def set_mass_factor(self, c: float) -> None:
        self.c.value = c

    def set_velocity_factor(self, c_v: float) -> None:
        assert self.c_v is not None  # (with a dashpot only)
        self.c_v.value = c_v

    def velocity(self, u: Any) -> Any:
        """The velocity at the force time of the step whose unknown is ``u``: c_v u - v* (with
        a dashpot only)."""
        assert self.c_v is not None and self.v_star is not None
        return self.c_v * u - self.v_star

    def mass_matrix(self, trial: Any, test: Any, bcs: list[Any]) -> PETSc.Mat:
        """M (rho du . v dx), its supported rows and columns replaced by the identity, and a
        unit diagonal where the mass is zero (the contact nodes of a redistributed mass:
        their acceleration is left 0; a multiplier field's rows, which the stepper zeroes)."""
        form = dolfinx.fem.form(self.rho * ufl.inner(trial, test) * self.dx)
        M = _compat.assemble_matrix(_compat.create_matrix(form), form, bcs)
        d = M.getDiagonal()
        d.array[d.array == 0.0] = 1.0
        M.setDiagonal(d, addv=PETSc.InsertMode.INSERT_VALUES)
        d.destroy()
        return M

    def kinetic_form(self) -> Any:
        v = self.displacement(self.v)
        return dolfinx.fem.form(0.5 * self.rho * ufl.inner(v, v) * self.dx)


def initial_acceleration(
    problem: Any, solver: Any, inertia: Inertia
) -> Any:  # a callable (x, a) -> None for the stepper
    """a_0 from the balance at the initial state, M a_0 = f_ext(0) - f_int(u_0) - f_c(u_0, v_0)
    on the free dofs (0 on the supported ones): the residual of the solver's equations with
    c = 0 and a* = 0 (and a dashpot's velocity c_v u - v* = v_0: c_v = 0, v* = -v_0), solved
    with M (LU: once per run)."""

    def solve(x: PETSc.Vec, a: PETSc.Vec) -> None:
        inertia.set_mass_factor(0.0)
        inertia.a_star.x.array[:] = 0.0
        if inertia.v_star is not None:
            inertia.set_velocity_factor(0.0)
            inertia.v_star.x.array[:] = -inertia.v.x.array
        solver.reassemble_bulk()  # K without c M
        problem.apply_load(0.0)
        solver.assemble_load()
        R = solver.reactions()  # f_int + f_c - f_ext on every row
        R.scale(-1.0)
        dolfinx.fem.petsc.set_bc(R, problem.bcs, x, 0.0)  # 0 on the supported rows
        M = inertia.mass_matrix(problem.dU, problem.V_test, problem.bcs)
        ksp = PETSc.KSP().create(problem.mesh.comm)
        ksp.setOperators(M)
        ksp.setType("preonly")
        ksp.getPC().setType("lu")
        ksp.getPC().setFactorSolverType("mumps")
        ksp.solve(R, a)
        a.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
        for obj in (ksp, M, R):
            obj.destroy()

    return solve


class EnergyBlowUp(ConvergenceError):
    """A dynamic run whose energy grew without bound (:meth:`EnergyLedger.check_stable`)."""

    def __init__(self, step: int, t: float, total: float, given: float) -> None:
        RuntimeError.__init__(
            self,
            f"unstable at time step {step} (time {t:.6g}): the energy grew to {total:.3g}, more "
            f"than {EnergyLedger.BLOW_UP:g} times what the run was given ({given:.3g}: its "
            "initial energy and the work of its loads); a smaller --dt, or with Nitsche "
            "theta = 1 a larger --gamma0",
        )
        self.reason, self.step, self.load, self.stats = "energy blow-up", step, t, None
        self.detail = ""


class EnergyLedger:
    """The energy balance of a dynamic run, one row per step (module docstring)."""

    KEYS = (
        "time",
        "kinetic",
        "strain",
        "contact",
        "total",
        "external_work",
        "friction_dissipation",
        "remainder",
    )

    def __init__(
        self, problem: Any, inertia: Inertia, load_form: Any, alpha_f: float = 0.0
    ) -> None:
        self.comm = problem.mesh.comm
        self.u = problem.state
        self.kinetic = inertia.kinetic_form()
        self.strain = dolfinx.fem.form(problem.material.strain_energy(problem.U) * problem.dx)
        energy = None
        #: between two bodies the coupling's (its terms are not UFL forms): its ``energy(x)``
        self.coupling = None
        if problem.surface is not None:
            energy = problem.method.contact_energy(problem.surface)
        elif hasattr(problem, "coupling") and problem.coupling().stores_energy:
            self.coupling = problem.coupling()
        #: whether the contact's stored energy is counted (else it is in the remainder)
        self.contact_counted = energy is not None or self.coupling is not None
        self.contact = None if energy is None else dolfinx.fem.form(energy * problem.surface.ds)
        #: friction's dissipation per step, -int t_T . du_T ds (the work the friction
        #: traction t_T on the body does on the step's slip), or None without friction;
        #: between two bodies the pair's coupling sums it (``friction_work()``): its traction
        #: and slip are the last residual's, at the force time t_{n+1-alpha_f} of the time
        #: scheme (:mod:`contactfx.solvers.dynamics`), where the slip is (1 - alpha_f) times
        #: the step's; ``pair_scale`` = 1 / (1 - alpha_f) makes it the traction that entered
        #: the step's balance on the step's slip
        self.friction = None
        self.pair_friction = None
        self.pair_scale = 1.0 / (1.0 - alpha_f)
        surface = problem.surface
        if surface is not None and problem.friction is not None:
            t_T = problem.method.tangential_traction(surface)
            slip = surface.slip_increment(surface.normal())
            ds = problem.method.traction_measure(surface)
            self.friction = dolfinx.fem.form(-ufl.dot(t_T, slip) * ds)
        elif hasattr(problem, "coupling") and problem.friction is not None:
            self.pair_friction = problem.coupling()
        self.dissipated = 0.0
        self.load_form = load_form
        self.f = _compat.create_vector(load_form)
        self.f_prev = self.f.duplicate()
        self.u_prev = _compat.petsc_vec(self.u).copy()
        self.du = self.u_prev.duplicate()  # a step's displacement (work vector)
        self.rows: list[dict[str, float]] = []
        self.work = 0.0
        #: the columns of the balance: with a dashpot its dissipation too
        self.keys: tuple[str, ...] = self.KEYS
        #: the contact dashpot's force vector (its residual at the state, at the velocity v),
        #: None without a dashpot; ``f_d_prev`` the last step's, ``dashpot_dissipated`` the
        #: trapezoidal sum of its work on the steps' displacements
        self.dashpot = None
        if inertia.dashpot is not None and problem.surface is not None:
            self.dashpot = dolfinx.fem.form(
                problem.method.dashpot_residual(problem.surface, inertia.dashpot, inertia.v)
            )
            self.f_d = _compat.create_vector(self.dashpot)
            self.f_d_prev = self.f_d.duplicate()
            self.keys = self.KEYS[:-1] + ("dashpot_dissipation", self.KEYS[-1])
        self.dashpot_dissipated = 0.0

    def _load(self, out: PETSc.Vec) -> None:
        _compat.assemble_vector(out, self.load_form)

    def record(self, t: float) -> dict[str, float]:
        """The balance at the state just accepted (time t): collective."""
        u = _compat.petsc_vec(self.u)
        self._load(self.f)
        if self.dashpot is not None:
            _compat.assemble_vector(self.f_d, self.dashpot)
        if self.rows:  # W += 1/2 (f_n + f_n+1) . (u_n+1 - u_n)
            du = self.du
            u.copy(du)
            du.axpy(-1.0, self.u_prev)
            self.work += 0.5 * (self.f.dot(du) + self.f_prev.dot(du))
            if self.dashpot is not None:  # D += 1/2 (f_d,n + f_d,n+1) . (u_n+1 - u_n)
                self.dashpot_dissipated += 0.5 * (self.f_d.dot(du) + self.f_d_prev.dot(du))
        u.copy(self.u_prev)
        self.f.copy(self.f_prev)
        if self.dashpot is not None:
            self.f_d.copy(self.f_d_prev)
        if self.friction is not None and self.rows:
            self.dissipated += global_sum(self.friction, self.comm)
        if self.pair_friction is not None and self.rows:
            self.dissipated += self.pair_scale * self.pair_friction.friction_work()
        kin = global_sum(self.kinetic, self.comm)
        strain = global_sum(self.strain, self.comm)
        contact = 0.0 if self.contact is None else global_sum(self.contact, self.comm)
        if self.coupling is not None:
            contact = self.coupling.energy(u)
        total = kin + strain + contact
        e0 = self.rows[0]["total"] if self.rows else total
        row = {
            "time": t,
            "kinetic": kin,
            "strain": strain,
            "contact": contact,
            "total": total,
            "external_work": self.work,
            "friction_dissipation": self.dissipated,
        }
        given = self.work - self.dissipated  # the work done on the body, less what it lost
        if self.dashpot is not None:
            row["dashpot_dissipation"] = self.dashpot_dissipated
            given -= self.dashpot_dissipated
        row["remainder"] = given - (total - e0)
        self.rows.append(row)
        return row

    #: the energy gained beyond what the run was given (its initial energy, the work of its
    #: loads, friction's and a dashpot's dissipation) at which the run counts as unstable: a
    #: stable scheme gains at most its balance error, a small fraction of that
    BLOW_UP = 10.0

    def check_stable(self, step: int) -> None:
        """Raise :class:`EnergyBlowUp` if the last step's energy grew beyond BLOW_UP times
        what the run was given (the growth: minus the balance's remainder)."""
        row = self.rows[-1]
        given = abs(self.rows[0]["total"]) + max(abs(r["external_work"]) for r in self.rows)
        given += row["friction_dissipation"] + row.get("dashpot_dissipation", 0.0)
        if -row["remainder"] > self.BLOW_UP * given and given > 0.0:
            raise EnergyBlowUp(step, row["time"], row["total"], given)

    def summary(self) -> dict[str, Any]:
        """run.json's ``energy``: initial and final total, the external work, friction's (and
        a dashpot's) dissipation, the largest |remainder| (absolute and relative to the
        largest energy of the run), whether the contact's energy is counted."""
        if not self.rows:
            return {}
        scale = max(max(abs(r["total"]) for r in self.rows), 1e-300)
        worst = max(abs(r["remainder"]) for r in self.rows)
        out = {
            "initial_total": self.rows[0]["total"],
            "final_total": self.rows[-1]["total"],
            "external_work": self.rows[-1]["external_work"],
            "friction_dissipation": self.rows[-1]["friction_dissipation"],
        }
        if self.dashpot is not None:
            out["dashpot_dissipation"] = self.rows[-1]["dashpot_dissipation"]
        return out | {
            "largest_remainder": worst,
            "largest_remainder_relative": worst / scale,
            "contact_counted": self.contact_counted,
        }

    def write(self, out: Path) -> list[Path]:
        """energy.csv and energy.png in ``out`` (rank 0)."""
        if self.comm.rank != 0 or not self.rows:
            return []
        path = out / "energy.csv"
        with path.open("w", newline="") as fh:
            writer = csv.DictWriter(fh, fieldnames=list(self.keys))
            writer.writeheader()
            for row in self.rows:
                writer.writerow({k: f"{row[k]:.12g}" for k in self.keys})
        return [path, self._plot(out / "energy.png")]

    def _plot(self, path: Path) -> Path:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        t = np.array([r["time"] for r in self.rows])
        fig, ax = plt.subplots(figsize=(7, 4))
        keys = ("kinetic", "strain", "contact", "total", "external_work")
        for key in keys + ("friction_dissipation", "dashpot_dissipation", "remainder"):
            if (
                (key == "contact" and not self.contact_counted)
                or (
                    key == "friction_dissipation"
                    and self.friction is None
                    and self.pair_friction is None
                )
                or (key == "dashpot_dissipation" and self.dashpot is None)
            ):
                continue
            ax.plot(t, [r[key] for r in self.rows], label=key.replace("_", " "))
        ax.set_xlabel("time")
        ax.set_ylabel("energy")
        ax.legend(loc="best", fontsize=8)
        ax.grid(alpha=0.3)
        fig.tight_layout()
        fig.savefig(path, dpi=120)
        plt.close(fig)
        return path

    def destroy(self) -> None:
        for v in (self.f, self.f_prev, self.u_prev, self.du):
            v.destroy()
        if self.dashpot is not None:
            self.f_d.destroy()
            self.f_d_prev.destroy()


def plot_contact(times: list[float], force: list[float], peak: list[float], path: Path) -> Path:
    """contact.png: a dynamic run's contact force and peak contact pressure over time (the
    impacts, the contact phases, the chatter of a consistent mass). Rank 0."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 1, figsize=(7, 5), sharex=True)
    axes[0].plot(times, force, lw=1.0)
    axes[0].set_ylabel("contact force")
    axes[1].plot(times, peak, lw=1.0, color="C3")
    axes[1].set_ylabel("peak contact pressure")
    axes[1].set_xlabel("time")
    for ax in axes:
        ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path
