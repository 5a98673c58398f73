"""PETSc SNES wrapper for contact problems: a bulk and a nonlinear contact boundary.

The residual is split into the bulk part (:mod:`contactfx.solvers.bulk`: the bodies' own
equations) and the contact part, which lives on the contact facets only:

    F(u) = R(u) + F_c(u),        J(u) = K(u) + dF_c/du(u),

with R(u) = f_int(u) - f_ext and K(u) = d f_int / du. For a linear bulk K is assembled once per
run and every Newton iteration assembles only the boundary integrals, which makes an iteration
cheap compared with a linear-elastic solve on the same mesh; a nonlinear bulk is assembled at
every iteration. Dirichlet conditions are imposed on the rows and columns of J (identity) and F
(u - g).
Bound constraints (SNES-VI, ``vinewtonrsls``) are supported for the reference solutions.

Options live in PETSc's database under a deterministic prefix (``contactfx_<scene>_``); the
defaults are overridden by the user's command-line options (unprefixed options given by the
user are copied under the prefix as well).
"""

from __future__ import annotations

import itertools
import time
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import dolfinx
import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from contactfx import _compat
from contactfx.contact.coupling import Coupling
from contactfx.solvers.base import ConvergenceError, SolveStats, TimeLimitExceeded, Timer
from contactfx.solvers.bulk import Bulk
from contactfx.solvers.guards import ReversalGuard, RoundOffStop
from contactfx.solvers.kept import KeptPreconditioner
from contactfx.solvers.mumps import MumpsWorkspace
from contactfx.solvers.options import OptionsDB
from contactfx.solvers.pattern import nonzeros, rebuilt
from contactfx.solvers.reduced import ReducedSystem

__all__ = [
    "ContactSNES",
    "ConvergenceError",
    "DEFAULT_OPTIONS",
    "GAMG_OPTIONS",
    "SolveStats",
    "TimeLimitExceeded",
    "Timer",
    "owned_bc_dofs",
    "owned_size",
    "rigid_body_modes",
    "snes_reason_name",
]


#: Newton (full steps: ``-snes_linesearch_type bt`` for a backtracking line search), MUMPS LU.
DEFAULT_OPTIONS: dict[str, object] = {
    "snes_type": "newtonls",
    "snes_linesearch_type": "basic",
    "snes_rtol": 1e-10,
    "snes_atol": 1e-12,
    "snes_stol": 0.0,
    "snes_max_it": 50,
    "ksp_type": "preonly",
    "pc_type": "lu",
    "pc_factor_mat_solver_type": "mumps",
}

#: Iterative alternative: GMRES + smoothed aggregation AMG with the rigid-body near-nullspace,
#: in an inexact Newton method: each Krylov solve is stopped at the relative tolerance that
#: the Eisenstat-Walker forcing chooses from Newton's progress (Eisenstat & Walker 1996,
#: doi:10.1137/0917003), tight near the solution and at most 1e-2 far from it (looser
#: solves stalled Newton's active set on Hertz 3D near 1e6 dofs). The AMG hierarchy is kept
#: across Newton iterations (:meth:`ContactSNES.reuse_preconditioner`).
GAMG_OPTIONS: dict[str, object] = {
    "snes_ksp_ew": True,
    "snes_ksp_ew_rtol0": 1e-2,
    "snes_ksp_ew_rtolmax": 1e-2,
    "ksp_type": "gmres",
    "ksp_rtol": 1e-10,
    "ksp_max_it": 500,
    "pc_type": "gamg",
    "pc_gamg_type": "agg",
    "pc_gamg_agg_nsmooths": 1,
    "pc_gamg_threshold": 0.01,
    "mg_levels_ksp_type": "chebyshev",
    "mg_levels_pc_type": "jacobi",
}

_REASONS = {
    v: k for k, v in vars(PETSc.SNES.ConvergedReason).items() if isinstance(v, int) and k[0] != "_"
}


def snes_reason_name(reason: int) -> str:
    return _REASONS.get(reason, str(reason))


def owned_size(space: dolfinx.fem.FunctionSpace) -> int:
    """Number of owned (unrolled) dofs of a function space on this rank."""
    return space.dofmap.index_map.size_local * space.dofmap.index_map_bs


def owned_bc_dofs(bcs: Sequence[Any], n_owned: int) -> np.ndarray:
    """The owned dofs (local indices, each once) that the DirichletBCs ``bcs`` fix."""
    dofs = [np.asarray(_compat.bc_dofs(bc)) for bc in bcs]
    rows = np.unique(np.concatenate(dofs)) if dofs else np.zeros(0, dtype=np.int32)
    return rows[rows < n_owned].astype(np.int32)


def rigid_body_modes(V: dolfinx.fem.FunctionSpace) -> PETSc.NullSpace:
    """Orthonormalised rigid-body modes of a 2D / 3D vector space (near-nullspace for AMG)."""
    mesh = V.mesh
    gdim = mesh.geometry.dim
    bs = V.dofmap.index_map_bs
    n_local = V.dofmap.index_map.size_local
    x = _compat.dof_coordinates(V)[:n_local]
    num_modes = 3 if gdim == 2 else 6
    vecs = [dolfinx.la.create_petsc_vector(V.dofmap.index_map, bs) for _ in range(num_modes)]
    arrays = [np.zeros((n_local, bs)) for _ in range(num_modes)]
    for i in range(gdim):
        arrays[i][:, i] = 1.0
    if gdim == 2:
        arrays[2][:, 0] = -x[:, 1]
        arrays[2][:, 1] = x[:, 0]
    else:
        arrays[3][:, 0], arrays[3][:, 1] = -x[:, 1], x[:, 0]
        arrays[4][:, 0], arrays[4][:, 2] = x[:, 2], -x[:, 0]
        arrays[5][:, 2], arrays[5][:, 1] = x[:, 1], -x[:, 2]
    for vec, arr in zip(vecs, arrays, strict=True):
        vec.array[:] = arr.ravel()
    # modified Gram-Schmidt (dolfinx.la.orthonormalize takes PETSc vectors in 0.5, its own
    # vectors in 0.9)
    for i, vec in enumerate(vecs):
        for prev in vecs[:i]:
            vec.axpy(-vec.dot(prev), prev)
        vec.normalize()
    return PETSc.NullSpace().create(vectors=vecs, comm=mesh.comm)


class _StepHalving:
    """Newton's line-search pre-check (PETSc's SNESLineSearchSetPreCheck, called before every
    line search with the iterate x and the Newton direction y; the line search then tries
    x - lambda y): y is halved until ``admissible(x - y)`` holds, at most MAX_HALVINGS times.

    It gives up on a step, which is then left as Newton gave it (the line search meets what it
    would have met without the check: an inadmissible iterate, a NaN residual, a failed solve
    and a cut-back), when even the last halving is not admissible, or when the steps of the
    solve's last MAX_IN_A_ROW iterations were all halved: a Newton iteration that keeps
    running into the boundary of the admissible set, from a start too far from the solution,
    which the load step's cut-back leaves sooner. Measured on hertz2d (neo-Hookean, Nitsche,
    eight meshes, depths and thetas; docs/verification.md section 15): without a limit the
    solves that failed halved every step from their first iteration on, for 10 to 34
    iterations; with a limit of 1, 2 or 5 the runs took 29, 29 and 28 load steps (37 without
    halving) and 308, 327 and 381 Newton iterations, failed solves included (330). A halved
    step is what the check is for: a step, often the first of a load increment, that
    overshoots into an inverted element from an iterate that Newton then corrects.

    ``admissible`` is collective and answers alike on every rank, so every rank scales y
    alike. ``halvings`` (halvings applied) and ``given_up`` (steps left whole) count since the
    solver was made; :meth:`start` begins a solve."""

    #: halvings per Newton step at most (a step of 2^-10 of Newton's)
    MAX_HALVINGS = 10
    #: halved steps in a row at most
    MAX_IN_A_ROW = 1

    def __init__(self, snes: PETSc.SNES, admissible: Callable[[PETSc.Vec], bool]) -> None:
        self.admissible = admissible
        self.halvings = 0
        self.given_up = 0
        self.in_a_row = 0
        self.trial: PETSc.Vec | None = None
        snes.setLineSearchPreCheck(self._precheck)

    def start(self) -> None:
        """A new solve: no halved steps in a row."""
        self.in_a_row = 0

    def _precheck(self, x: PETSc.Vec, y: PETSc.Vec) -> bool:
        if self.trial is None:
            self.trial = x.duplicate()
        scale = 1.0
        for halvings in range(self.MAX_HALVINGS + 1):
            x.copy(self.trial)
            self.trial.axpy(-scale, y)
            if self.admissible(self.trial):
                if halvings == 0:
                    self.in_a_row = 0
                    return False
                y.scale(scale)
                self.halvings += halvings
                self.in_a_row += 1
                return True
            if self.in_a_row >= self.MAX_IN_A_ROW:
                break
            scale *= 0.5
        self.given_up += 1
        return False

    def destroy(self) -> None:
        if self.trial is not None:
            self.trial.destroy()


class ContactSNES:
    """Newton (or SNES-VI) for F(u) = R(u) + F_c(u) = 0 with Dirichlet conditions.

    Parameters are keyword-only: ``bulk`` (a :class:`contactfx.solvers.bulk.Bulk` over u's
    space: R(u) and K(u); the solver destroys it with itself), ``contact_residual`` /
    ``contact_jacobian`` (compiled forms, or None), ``bcs`` (dolfinx DirichletBCs), ``prefix``
    (PETSc options prefix), ``options`` (defaults, overridden by the command line),
    ``user_options`` (from the command line), ``near_nullspace`` (the rigid-body modes for
    AMG), ``coupling`` (a two-body :class:`contactfx.contact.coupling.Coupling`), ``confined``
    (those of ``bcs`` that confine a field to a surface: a multiplier or an interface
    enrichment that the unknown carries on the whole mesh), ``iterate`` (a Function of u's
    space that the contact forms read as Newton's previous iterate: the friction law's
    reversal guard), ``deadline`` (a ``time.perf_counter()`` value past which a solve stops
    with :class:`TimeLimitExceeded`, checked collectively at every residual),
    ``roundoff_stop`` (finite strain: Newton also stops at the residual's round-off level,
    :class:`_RoundOffStop`), ``load_scale`` (that level also measured against the load's
    size: a dynamic step's, which holds the inertia M a*).

    Its collaborators: the options database (:class:`contactfx.solvers.options.OptionsDB`),
    the reduced system on the kept dofs (:class:`contactfx.solvers.reduced.ReducedSystem`:
    the confined dofs are not unknowns of Newton's linear systems; not with a two-body
    coupling or the AMG near-nullspace), a kept preconditioner, the reversal guard, and the
    MUMPS workspace policy (:class:`contactfx.solvers.mumps.MumpsWorkspace`) for every linear
    solve. A :class:`contactfx.solvers.base.Solver`.
    """

    #: Krylov iterations at most with a reused factorisation (then it is refactorised)
    REUSE_MAX_IT = 20
    #: FGMRES's relative tolerance on the factorisation kept across solves (a dynamic run):
    #: Newton's steps exact to 1e-6 (hertz-impact's 3D steps 30 % faster than at 1e-12, at
    #: the same Newton iterations; docs/verification.md section 18, speed)
    REUSE_RTOL_ACROSS = 1e-6
    #: Krylov iterations above which a kept AMG preconditioner is rebuilt at the next Jacobian
    AMG_REBUILD_IT = 30
    #: continued solves with the reversal guard before one without it (see _newton)
    GUARD_ROUNDS = 3
    #: searches per load step at most (``--search-update step``)
    SEARCH_ROUNDS = 5
    #: Newton iterations at most when continuing from a solution with a new pairing (a
    #: converging continuation takes a few; a cycling one is solved again from the step's
    #: start)
    CONTINUE_MAX_IT = 15
    #: a two-body Jacobian past this factor of the bulk's nonzeros is rebuilt at a step's start
    COMPACT_GROWTH = 1.5

    def __init__(
        self,
        u: dolfinx.fem.Function,
        *,
        bulk: Bulk,
        contact_residual: Any = None,
        contact_jacobian: Any = None,
        bcs: Sequence[Any] = (),
        prefix: str,
        options: Mapping[str, object] | None = None,
        user_options: Mapping[str, object] | None = None,
        near_nullspace: bool = False,
        coupling: Coupling | None = None,
        confined: Sequence[Any] = (),
        iterate: dolfinx.fem.Function | None = None,
        deadline: float | None = None,
        roundoff_stop: bool = False,
        load_scale: bool = False,
    ) -> None:
        self.u = u
        self.comm = u.function_space.mesh.comm
        self.bcs = list(bcs)
        self._a_c = contact_jacobian
        self._F_c = contact_residual
        self.coupling = coupling
        self.deadline = deadline
        self.options = OptionsDB(prefix, user_options)
        self.mumps = MumpsWorkspace(self.options)
        self.timer = Timer()

        t0 = time.perf_counter()
        self.bulk = bulk
        K = bulk.jacobian(_compat.petsc_vec(u))
        # couplings between the bodies' dofs appear with the search
        self.J = K.duplicate(copy=True) if coupling is None else rebuilt(K)
        self._bulk_nonzeros = nonzeros(K)
        self.Jc = None if contact_jacobian is None else _compat.create_matrix(contact_jacobian)
        self.fc = None if contact_residual is None else _compat.create_vector(contact_residual)
        self.timer.assembly += time.perf_counter() - t0

        n_owned = owned_size(u.function_space)
        self._bc_rows = owned_bc_dofs(self.bcs, n_owned)
        self.reduced: ReducedSystem | None = None
        if confined and coupling is None and not near_nullspace:
            keep = np.ones(n_owned, dtype=bool)
            keep[owned_bc_dofs(confined, n_owned)] = False
            self.reduced = ReducedSystem(K, np.flatnonzero(keep), self._bc_rows)
            self.J.destroy()
            self.J = self.reduced.K.duplicate(copy=True)

        self.nullspace = None
        if near_nullspace and u.function_space.mesh.geometry.dim > 1:
            self.nullspace = rigid_body_modes(u.function_space)
            self.J.setNearNullSpace(self.nullspace)

        self.snes = PETSc.SNES().create(self.comm)
        self.snes.setOptionsPrefix(prefix)
        defaults = {**DEFAULT_OPTIONS, **(options or {})}
        guarded = iterate is not None or getattr(coupling, "guarded", False)
        if guarded:
            # the reversal guard's stick branch is unbounded (t_T = trial): at an iterate just
            # after a reversal the residual may grow by orders of magnitude, and the next step,
            # linear there, removes it. It is no merit function, so no divergence test on it
            # (max_it still bounds a solve). Not -1: PETSc >= 3.22 reads it as "the default"
            defaults.setdefault("snes_divergence_tolerance", 1e300)
        self.options.apply(defaults)
        self.residual_vec = self.J.createVecLeft()
        self.snes.setFunction(self._residual, self.residual_vec)
        self.snes.setJacobian(self._jacobian, self.J, self.J)
        self.snes.setFromOptions()
        self.snes.getKSP().setFromOptions()
        self.guard = ReversalGuard(iterate, u, self.snes, coupling) if guarded else None
        #: finite strain: PETSc's convergence test and a stop at the round-off level
        self.roundoff = None
        if roundoff_stop:
            divergence = PETSc.Options().getReal(f"{prefix}snes_divergence_tolerance", 1e4)
            self.roundoff = RoundOffStop(self.snes, divergence)
        #: the round-off stop's depth also measured against |f_ext| (a dynamic run, whose
        #: load holds the inertia M a*)
        self.load_scale = load_scale
        self.kept: KeptPreconditioner | None = None
        self.reuse_preconditioner()
        self.halving: _StepHalving | None = None
        #: how often the Jacobian was rebuilt on the bulk's pattern (_compact)
        self.compactions = 0
        self._full: PETSc.Vec | None = None

    # -- options -------------------------------------------------------------------------
    @property
    def prefix(self) -> str:
        return self.options.prefix

    def user_sets(self, key: str) -> bool:
        """Whether the user's options give ``key`` (a PETSc option name without the
        prefix), with or without this solver's prefix."""
        return self.options.user_sets(key)

    #: not state (contactfx.io.checkpoint): this run's wall-time deadline and timings
    checkpoint_skip = ("deadline", "timer")

    @property
    def checkpoint_patterns(self) -> tuple[str, ...]:
        """The matrices whose nonzero pattern a checkpoint keeps (contactfx.io.checkpoint):
        with a two-body coupling the Jacobian gains the entries of every search and keeps
        them, and the factorisation's ordering follows the pattern."""
        return ("J",) if self.coupling is not None else ()

    def tolerances(self) -> dict[str, float]:
        """SNES's tolerances: ``rtol``, ``atol``, ``stol``, ``max_it``."""
        return dict(zip(("rtol", "atol", "stol", "max_it"), self.snes.getTolerances(), strict=True))

    def set_tolerances(self, **tolerances: float) -> None:
        """Set some of SNES's tolerances (``rtol``, ``atol``, ``stol``, ``max_it``)."""
        self.snes.setTolerances(**tolerances)

    # -- preconditioner reuse --------------------------------------------------------------
    def reuse_factorisation(self, across_solves: bool = False) -> None:
        """From the second Newton iteration of a solve on, keep the LU factorisation of an earlier
        Jacobian as GMRES's preconditioner while GMRES converges with it within REUSE_MAX_IT
        iterations; refactorise at the first iteration of every solve and after a Krylov solve that
        needed more. For starts close to the solution (nested iteration), where the later Jacobians
        differ from the first in a few contact rows only. Only with a direct solver whose Krylov
        type is preonly (what the defaults give). ``across_solves``: not refactorised at a solve's
        start either, only after a slow or failed Krylov solve and after the bulk is re-assembled (a
        dynamic run with a linear bulk: K + c M factorised once per step size, the contact's rows
        changing the Jacobian only when the contact status changes; an unchanged Jacobian costs one
        back-substitution). Across solves FGMRES stops at REUSE_RTOL_ACROSS (1e-6; 1e-12 between two
        bodies), within a solve at 1e-12: the Jacobians of a step's Newton iterations differ from
        the kept one in the rows of the nodes whose contact status changed since, a low-rank change
        that FGMRES resolves in about as many iterations as its rank (a 3D contact zone's ring of
        nodes: 13 back-substitutions a Newton iteration at 1e-12, 10 at 1e-6, the Newton iterations
        unchanged; a fresh factorisation at every step's start saved fewer back-substitutions than
        it cost)."""
        ksp = self.snes.getKSP()
        if ksp.getPC().getType() != "lu" or ksp.getType() != "preonly":
            return
        # flexible GMRES (preconditioned on the right) keeps the preconditioned directions, so
        # k iterations cost k back-substitutions (left-preconditioned GMRES takes one more)
        ksp.setType("fgmres")
        # (between two bodies, where each Newton iteration searches, 1e-6 added Newton
        # iterations: two-bars 157 -> 273)
        loose = across_solves and self.coupling is None
        rtol = self.REUSE_RTOL_ACROSS if loose else 1e-12
        ksp.setTolerances(rtol=rtol, atol=0.0, max_it=self.REUSE_MAX_IT)
        # a Krylov solve stopped at REUSE_MAX_IT is still a descent step: take it, refactorise
        self.snes.setMaxLinearSolveFailures(10**6)
        self._keep_preconditioner(self.REUSE_MAX_IT, every_solve=not across_solves)

    def reuse_preconditioner(self) -> None:
        """Keep an iterative solver's preconditioner (the AMG hierarchy, whose Galerkin
        products cost most of a Newton step) across Newton iterations: rebuild it at the
        first iteration of every solve, after a failed Krylov solve and after one that needed
        more than AMG_REBUILD_IT iterations. With a bulk of constant Jacobian only the contact
        rows change between Newton iterations, so an earlier Jacobian's hierarchy still
        preconditions well. No-op with a direct solver or a bulk whose Jacobian changes (the
        hierarchy is rebuilt at every iteration)."""
        if self.snes.getKSP().getPC().getType() in ("lu", "cholesky"):
            return
        if not self.bulk.constant_jacobian:
            return
        if self.coupling is not None:
            # between two bodies the contact rows change the operator as the contact set
            # grows: a hierarchy of a solve's first iterate preconditioned hertz-cylinders so
            # badly that Newton crawled (40 iterations at 2 ranks, with GMRES at its tolerance
            # in the preconditioned norm) or GMRES broke down; each Jacobian's own is used
            return
        self._keep_preconditioner(self.AMG_REBUILD_IT)

    def _keep_preconditioner(self, rebuild_it: int, every_solve: bool = True) -> None:
        if self.kept is not None:
            self.kept.destroy()
        self.kept = KeptPreconditioner(
            self.J,
            self.nullspace,
            rebuild_it,
            coupled=self.coupling is not None,
            every_solve=every_solve,
        )
        self.snes.setJacobian(self._jacobian, self.J, self.kept.P)

    # -- step halving ------------------------------------------------------------------------
    def limit_steps(self, admissible: Callable[[PETSc.Vec], bool]) -> None:
        """Halve every Newton step until ``admissible`` accepts the iterate it leads to, at
        most _StepHalving.MAX_HALVINGS times (e.g. until no element of a finite-strain body
        inverts: :class:`contactfx.driver.inversion.VolumeRatio`). ``admissible`` is a
        collective predicate of a vector of u's layout (its owned entries set). The halvings
        are counted in the solves' :class:`SolveStats` and named in a failed solve's
        message."""
        check = admissible
        if self.reduced is not None:  # SNES's vectors hold the kept dofs only
            reduced = self.reduced
            full = self._full = reduced.F.duplicate()
            full.set(0.0)  # the confined entries stay zero

            def check(x: PETSc.Vec) -> bool:
                reduced.extend(x, full)
                return admissible(full)

        self.halving = _StepHalving(self.snes, check)

    def set_bounds(self, lower: PETSc.Vec, upper: PETSc.Vec) -> None:
        """Bound constraints lower <= u <= upper (requires -snes_type vinewtonrsls)."""
        if self.reduced is not None:
            lower, upper = self.reduced.restrict(lower), self.reduced.restrict(upper)
        self.snes.setVariableBounds(lower, upper)

    # -- callbacks -----------------------------------------------------------------------
    def _sync(self, x: PETSc.Vec) -> None:
        """Make u (which the compiled forms read) equal to the SNES iterate x (or to x on all
        dofs)."""
        uvec = _compat.petsc_vec(self.u)
        if self.reduced is not None and x.getSize() != uvec.getSize():
            self.reduced.extend(x, uvec)
        elif x.handle != uvec.handle:
            x.copy(uvec)
        uvec.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)

    def assemble_load(self) -> None:
        """Assemble f_ext for the current load (call after the load program changed
        constants)."""
        t0 = time.perf_counter()
        self.bulk.assemble_load()
        self.timer.assembly += time.perf_counter() - t0

    def _residual(self, snes: PETSc.SNES, x: PETSc.Vec, F: PETSc.Vec) -> None:
        t0 = time.perf_counter()
        if self.deadline is not None and self.comm.allreduce(t0 > self.deadline, op=MPI.LOR):
            # stop SNES through its own divergence test (a NaN residual): raising here would
            # leave x read-locked on PETSc >= 3.20
            self._late = True
            F.set(np.nan)
            return
        self._sync(x)
        if self.guard is not None and not self.guard.active:  # the law's own residual
            self.guard.remember()
        uvec = _compat.petsc_vec(self.u)  # = x on all dofs
        full = F if self.reduced is None else self.reduced.F
        self._unconstrained_residual(uvec, full, search=True)
        dolfinx.fem.petsc.set_bc(full, self.bcs, uvec, -1.0)
        if self.reduced is not None:  # its kept rows
            self.reduced.restrict(full, F)
        self.timer.assembly += time.perf_counter() - t0

    def _unconstrained_residual(self, x: PETSc.Vec, F: PETSc.Vec, search: bool) -> None:
        """F = R(x) + F_c(x), every row (the Dirichlet rows not replaced)."""
        self.bulk.residual(x, F)
        if self._F_c is not None:
            _compat.assemble_vector(self.fc, self._F_c)
            F.axpy(1.0, self.fc)
        if self.coupling is not None:
            t1 = time.perf_counter()
            if search and self.coupling.search_each_newton:
                self._search()
            self.coupling.residual(x, F)
            self.timer.contact += time.perf_counter() - t1

    def reactions(self) -> PETSc.Vec:
        """The forces the supports exert at the current (converged) u: at a solution
        R(u) + F_c(u) vanishes on the free rows, and on a supported row it is the reaction.
        Collective; the caller destroys the vector."""
        x = _compat.petsc_vec(self.u)
        self._sync(x)
        R = self.bulk.create_vector()
        self._unconstrained_residual(x, R, search=False)
        return R

    def reassemble_bulk(self, keep_preconditioner: bool = False) -> None:
        """The bulk's forms changed their constants (a dynamic stepper's step size): K is
        assembled again (the kept block of the reduced system with it) and the preconditioner
        is set up anew at the next solve. ``keep_preconditioner``: K is assembled for the
        values its forms had already (a restarted run's bulk), a kept preconditioner stays."""
        t0 = time.perf_counter()
        self.bulk.reassemble()
        K = self.bulk.jacobian(_compat.petsc_vec(self.u))
        if self.reduced is not None and self.bulk.constant_jacobian:
            self.reduced.bulk_block(K)
        if self.kept is not None and not keep_preconditioner:
            self.kept.stale = True
        self.snes.getKSP().getPC().reset()
        self.timer.assembly += time.perf_counter() - t0

    def bulk_residual(self) -> PETSc.Vec:
        """The bulk's residual R(u) = f_int(u) - f_ext at the current u, without the contact
        terms: minus the force the contact (and the supports) exert on each dof. Collective;
        the caller destroys the vector."""
        x = _compat.petsc_vec(self.u)
        R = self.bulk.create_vector()
        self.bulk.residual(x, R)
        return R

    def _search(self) -> None:
        """The coupling's search at the current u. The Jacobian's sparsity may change with it:
        reset the preconditioner so that the factorisation is set up anew (PETSc 3.22 reuses
        the symbolic LU of the old pattern after the coupling's MatAXPY with a different
        pattern, and MUMPS fails)."""
        if self.coupling is None:
            return
        self.coupling.update(self.u.x.array)
        self.snes.getKSP().getPC().reset()

    def _jacobian(self, snes: PETSc.SNES, x: PETSc.Vec, J: PETSc.Mat, P: PETSc.Mat) -> None:
        t0 = time.perf_counter()
        self._sync(x)
        red = self.reduced
        K = self.bulk.jacobian(_compat.petsc_vec(self.u))
        if self.coupling is not None:
            t1 = time.perf_counter()
            self.coupling.jacobian(x, K, J, bulk_changed=not self.bulk.constant_jacobian)
            self.timer.contact += time.perf_counter() - t1
        else:
            if red is not None:
                K = red.K if self.bulk.constant_jacobian else red.bulk_block(K)
            K.copy(J, structure=PETSc.Mat.Structure.SAME_NONZERO_PATTERN)
        if self._a_c is not None:
            _compat.assemble_matrix(self.Jc, self._a_c)
            Jc = self.Jc if red is None else red.kept_block(self.Jc)
            J.axpy(1.0, Jc, structure=PETSc.Mat.Structure.SUBSET_NONZERO_PATTERN)
        if red is None:
            J.zeroRowsColumnsLocal(self._bc_rows, diag=1.0)
        else:
            J.zeroRowsColumns(red.bc_rows, diag=1.0)
        if self.kept is not None:
            self.kept.update(snes, J)
        elif (
            snes is not None
            and self.coupling is not None
            and snes.getKSP().getPC().getType() == "gamg"
        ):
            # two bodies keep no AMG preconditioner (reuse_preconditioner), and the search grows
            # the pattern: GAMG (PETSc 3.18) would set the new matrix into the coarse levels of
            # the last one ("Cannot change local size of Amat after use"); a new one is set up
            pc = snes.getKSP().getPC()
            pc.setType("none")
            pc.setType("gamg")
            pc.setFromOptions()
        self._remember()
        self.timer.assembly += time.perf_counter() - t0

    def _remember(self) -> None:
        """The iterate the contact forms compare with becomes the current u (at every Jacobian,
        so the next residual and Jacobian see the step just taken)."""
        if self.guard is not None:
            self.guard.remember()

    def solve_linear(self, free: np.ndarray, extra: Any = None) -> None:
        """u = the solution of (K + extra) u = f_ext with the owned dofs not marked ``free``
        (and the Dirichlet dofs) fixed to zero, by this solver's linear solver (its options
        prefix and the command line apply): a linear start for the Newton solve (a linear bulk
        only: K is the bulk's constant Jacobian)."""
        if not self.bulk.constant_jacobian:
            raise NotImplementedError("a linear start needs a linear bulk")
        rows = np.flatnonzero(~free).astype(np.int32)
        rows = np.union1d(rows, self._bc_rows).astype(np.int32)
        A = self.bulk.jacobian(_compat.petsc_vec(self.u)).copy()
        if extra is not None:
            S = _compat.assemble_matrix(_compat.create_matrix(extra), extra)
            A.axpy(1.0, S, structure=PETSc.Mat.Structure.SUBSET_NONZERO_PATTERN)
            S.destroy()
        A.zeroRowsColumnsLocal(rows, diag=1.0)
        if self.nullspace is not None:
            A.setNearNullSpace(self.nullspace)
        b = self.bulk.load.copy()
        b.getArray()[rows] = 0.0
        x = _compat.petsc_vec(self.u)
        try:
            for attempt in itertools.count():
                ksp = PETSc.KSP().create(self.comm)
                ksp.setOptionsPrefix(self.prefix)
                ksp.setOperators(A)
                ksp.setFromOptions()
                ksp.solve(b, x)
                try:
                    if ksp.getConvergedReason() >= 0:
                        break
                    if not self.mumps.enlarge(ksp, attempt):  # else again, a new factor
                        raise ConvergenceError(
                            f"the linear start's solve failed: {self.mumps.describe(ksp)}"
                        )
                finally:
                    ksp.destroy()
        finally:
            for obj in (A, b):
                obj.destroy()
        x.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)

    # -- solve ---------------------------------------------------------------------------
    def solve(self) -> SolveStats:
        """Solve from the current u (its Dirichlet values are set first); raise on failure.

        With a two-body coupling searched once per step: the search at the step's start, and
        once Newton has converged, a search at the solution that finds contact points the
        step's search could not reach (farther apart at its start than the candidates'
        padding). With new points, Newton continues from the solution with the new pairing
        (a few iterations when the contact set grew by a few nodes), and if that fails
        (semi-smooth Newton can cycle between two active sets when many nodes change status at
        once, as with Coulomb friction), it solves the step again from its start with that
        pairing; up to SEARCH_ROUNDS searches."""
        x = _compat.petsc_vec(self.u)
        dolfinx.fem.petsc.set_bc(x, self.bcs)
        self._sync(x)
        self._compact()
        if self.roundoff is not None and self.load_scale:
            self.roundoff.scale = self.bulk.load.norm()
        self._late = False
        self._remember()
        if self.guard is not None:
            self.guard.start()
        stats = SolveStats(newton=0, ksp=0, reason="")
        if self.coupling is None or self.coupling.search_each_newton:
            if self.coupling is not None:
                self._timed_search()
            stats = self._newton(x, stats)
        else:
            stats = self._search_rounds(x, stats)
        lost = getattr(self.coupling, "lost", None)  # a coupling's check of the solution
        why = None if lost is None else lost()
        if why is not None:
            raise ConvergenceError(why, stats=stats)
        return stats

    def _compact(self) -> None:
        """The Jacobian rebuilt on the bulk's pattern once past COMPACT_GROWTH times its
        nonzeros (:mod:`.pattern`; decided from the pattern, which a restart restores)."""
        if self.coupling is None or nonzeros(self.J) <= self.COMPACT_GROWTH * self._bulk_nonzeros:
            return
        J = rebuilt(self.bulk.jacobian(_compat.petsc_vec(self.u)), self.nullspace)
        self.J.destroy()
        self.J = J
        self.compactions += 1
        if self.kept is not None:
            self._keep_preconditioner(self.kept.rebuild_it, self.kept.every_solve)
        else:
            self.snes.setJacobian(self._jacobian, self.J, self.J)

    def _search_rounds(self, x: PETSc.Vec, stats: SolveStats) -> SolveStats:
        """Newton with a search at the step's start and again at each solution (solve())."""
        start = x.copy()
        try:
            self._timed_search()
            stats = self._newton(x, stats)
            for _ in range(self.SEARCH_ROUNDS - 1):
                if self._searched_all():
                    return stats
                self._timed_search()
                try:
                    stats = self._newton(x, stats, max_it=self.CONTINUE_MAX_IT)
                except TimeLimitExceeded:
                    raise
                except ConvergenceError as err:
                    stats = err.stats or stats
                    start.copy(x)
                    self._sync(x)
                    stats = self._newton(x, stats)
            if not self._searched_all():
                raise ConvergenceError(
                    f"the search found new contact points after {self.SEARCH_ROUNDS} rounds"
                )
            return stats
        finally:
            start.destroy()

    def _newton(self, x: PETSc.Vec, before: SolveStats, max_it: int | None = None) -> SolveStats:
        """SNES solves from x (each at most ``max_it`` iterations when given and below the
        SNES's own limit); the counts added to ``before``. Raises ConvergenceError (with the
        counts) on divergence, TimeLimitExceeded past the deadline.

        With the reversal guard, a solve converged on the guarded residual is continued while
        the law's own residual is not converged (a point that reversed in the last step), up
        to GUARD_ROUNDS times; a point that keeps flipping between stick and slip across the
        converged iterates (a 2-cycle of the guard itself) then gets one last solve with the
        guard off, the law's plain semi-smooth Newton from there."""
        stats = self._snes_solve(x, before, max_it)
        if self.guard is None:
            return stats
        for _ in range(self.GUARD_ROUNDS):
            if self._law_converged(x):
                return stats
            stats = self._snes_solve(x, stats, max_it)  # from the law's own residual
        if self._law_converged(x):
            return stats
        self.guard.active = False
        try:
            return self._snes_solve(x, stats, max_it)
        finally:
            self.guard.active = True

    def _snes_solve(self, x: PETSc.Vec, before: SolveStats, max_it: int | None) -> SolveStats:
        """One SNES solve from x (again from x with a larger MUMPS workspace, by the
        workspace policy); the counts added to ``before``; raises on failure."""
        limit = self.snes.getTolerances()[3]
        if max_it is not None and max_it < limit:
            self.snes.setTolerances(max_it=max_it)
        # SNES iterates on its own vector: the callbacks copy their argument into u, and a line
        # search evaluates F at trial points W = X - lambda Y while it still needs X
        xs = x.copy() if self.reduced is None else self.reduced.restrict(x, self.reduced.x)
        start = xs.copy()
        ksp = self.snes.getKSP()
        linear_failure = PETSc.SNES.ConvergedReason.DIVERGED_LINEAR_SOLVE
        halving = self.halving
        halved = given_up = 0
        if halving is not None:
            halving.start()
            halved, given_up = halving.halvings, halving.given_up
        try:
            for attempt in itertools.count():
                self.snes.solve(None, xs)
                if self.snes.getConvergedReason() != linear_failure or not self.mumps.enlarge(
                    ksp, attempt
                ):
                    break
                ksp.getPC().reset()  # the next set-up makes a new factor with the workspace
                start.copy(xs)
        except PETSc.Error as err:  # e.g. a singular factorisation: a failed step
            raise ConvergenceError(f"linear solver failed (PETSc error {err.ierr})") from None
        finally:
            start.destroy()
            self.snes.setTolerances(max_it=limit)
            self._sync(xs)  # into x = u
            if self.reduced is None:
                xs.destroy()
        if self._late:
            raise TimeLimitExceeded()
        self._sync(x)
        reason = self.snes.getConvergedReason()
        if halving is not None:
            halved, given_up = halving.halvings - halved, halving.given_up - given_up
        stats = SolveStats(
            newton=before.newton + self.snes.getIterationNumber(),
            ksp=before.ksp + self.snes.getLinearSolveIterations(),
            reason=snes_reason_name(reason),
            halvings=before.halvings + halved,
        )
        if reason <= 0:
            message = stats.reason
            if reason == linear_failure:
                message += f" ({self.mumps.describe(ksp)})"
            if halving is not None and (halved or given_up):  # what the step halving did
                message += f" (step halvings: {halved}"
                if given_up:
                    message += f"; steps not admissible, taken whole: {given_up}"
                message += ")"
            raise ConvergenceError(message, stats=stats)
        return stats

    def _law_converged(self, x: PETSc.Vec) -> bool:
        """After a converged solve with the reversal guard: the guard compared the last iterate
        with the one before; with the iterate remembered the residual is the law's own. True
        if it meets the solve's own tolerances (it fails only if a point reversed in the
        last, vanishing step)."""
        self._remember()
        xs = x if self.reduced is None else self.reduced.restrict(x, self.reduced.x)
        F = self.residual_vec.duplicate()
        try:
            self._residual(self.snes, xs, F)
            rtol, atol = self.snes.getTolerances()[:2]
            initial = 0.0 if self.guard is None else self.guard.initial_norm
            return F.norm() <= max(atol, rtol * initial)
        finally:
            F.destroy()

    def _timed_search(self) -> None:
        t0 = time.perf_counter()
        self._search()
        dt = time.perf_counter() - t0
        self.timer.assembly += dt
        self.timer.contact += dt

    def _searched_all(self) -> bool:
        """Whether a search at the current u finds no contact point that the last search
        missed (collective; True without a coupling)."""
        if self.coupling is None:
            return True
        t0 = time.perf_counter()
        missed = self.coupling.missed(self.u.x.array)
        dt = time.perf_counter() - t0
        self.timer.assembly += dt
        self.timer.contact += dt
        return missed == 0

    # -- the Solver protocol's other members ---------------------------------------------------
    def converged(self) -> None:
        """Nothing to move on: the load program keeps the state's history."""

    def phase_timings(self) -> dict[str, float]:
        return {}

    def destroy(self) -> None:
        for obj in (
            self.snes,
            self.bulk,
            self.J,
            self.kept,
            self.Jc,
            self.fc,
            self.residual_vec,
            self.halving,
            self._full,
        ):
            if obj is not None:
                obj.destroy()
        if self.reduced is not None:
            self.reduced.destroy()
        self.options.clear()
