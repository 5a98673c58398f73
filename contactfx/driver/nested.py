"""Nested iteration: every load step solved first on coarser meshes of the same scene.

Semi-smooth Newton for contact spends its iterations finding the contact set: from the
undeformed start the first active set is the geometric overlap, and the iterations shrink it
a few elements at a time, so their count grows with refinement. Started from the solution on
a mesh twice as coarse, interpolated, the active set is already right to within a coarse
element and the fine solve needs two or three iterations; the coarse solve itself starts
from a coarser one, down the chain (nested iteration, the "full multigrid" start of
Hackbusch 1985, Multi-Grid Methods and Applications, ch. 5, doi:10.1007/978-3-662-02427-0).

:class:`NestedSolver` wraps the fine solver (whatever the method attached) and at each solve
(i) restores the coarse chain to its last converged state, (ii) solves the step's load on it,
(iii) interpolates its fields (the state, and a nodal multiplier) at the fine dofs as the fine
Newton start. A coarse failure leaves the fine start as the load program predicted it. The
coarse chain keeps its own friction history, advanced with the fine steps.
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING, NamedTuple

import dolfinx
import numpy as np
from mpi4py import MPI

from contactfx import _compat
from contactfx.solvers.base import ConvergenceError, SolverWrapper, SolveStats, TimeLimitExceeded
from contactfx.solvers.snes import owned_bc_dofs, owned_size

if TYPE_CHECKING:
    from contactfx.driver.problem import Problem, Solver

__all__ = ["NestedSolver", "Transfer", "transfer", "nested_levels", "MIN_DOFS"]

#: the coarsest mesh of a chain has about this many unknowns at least (below, a coarse
#: solve costs more in setup than it saves)
MIN_DOFS = 2000


def nested_levels(requested: int, dofs: int, tdim: int) -> int:
    """The coarser levels used: at most ``requested``, and no level whose mesh (the unknowns
    divide by 2^tdim per halving of the element sizes) would fall below MIN_DOFS."""
    levels = 0
    while levels < requested and dofs / 2.0 ** (tdim * (levels + 1)) >= MIN_DOFS:
        levels += 1
    return levels


def _leaves(
    f: dolfinx.fem.Function, split: bool
) -> list[tuple[dolfinx.fem.FunctionSpace, np.ndarray]]:
    """(collapsed space, indices into ``f.x.array``) per field of ``f`` (one for a plain
    space, one per sub-space of a mixed one)."""
    W = f.function_space
    if not split:
        return [(W, np.arange(len(f.x.array)))]
    out = []
    for i in range(W.num_sub_spaces):
        V, dofs = W.sub(i).collapse()
        out.append((V, np.asarray(dofs)))
    return out


class _Part(NamedTuple):
    """One field of a transfer: the coarse field (collapsed) and its dofs in the coarse
    Function, the fine dofs written (those of the moved nodes) and which of them are free,
    the moved nodes' points of all ranks and this rank's slice of them, the block size."""

    coarse: dolfinx.fem.Function
    coarse_dofs: np.ndarray
    dofs: np.ndarray
    free: np.ndarray
    points: np.ndarray
    mine: slice
    bs: int


class Transfer:
    """fine = the interpolant of ``coarse`` (another mesh of the same domain) at fine's owned
    dofs, each call; what depends on the meshes only (the fields' sub-spaces, the fine dof
    coordinates gathered on every rank, the coarse cell that holds each of them) is found
    once, the cells at the first call (so that a run's solve time counts it). A dof outside
    the coarse mesh keeps its value, and so do the ``fixed`` dofs (indices into
    ``fine.x.array``: a field confined to a surface is zero elsewhere, and only its surface
    nodes are interpolated). Collective."""

    def __init__(
        self,
        coarse: dolfinx.fem.Function,
        fine: dolfinx.fem.Function,
        split: bool,
        fixed: np.ndarray | None = None,
    ) -> None:
        self.coarse, self.fine = coarse, fine
        comm = fine.function_space.mesh.comm
        gdim = fine.function_space.mesh.geometry.dim
        free = np.ones(len(fine.x.array), dtype=bool)
        if fixed is not None:
            free[fixed] = False
        self.parts = []
        for (Vc, dc), (Vf, df) in zip(_leaves(coarse, split), _leaves(fine, split), strict=True):
            n_owned = Vf.dofmap.index_map.size_local
            bs = Vf.dofmap.index_map_bs
            nodes = df[: n_owned * bs].reshape(n_owned, bs)
            moved = free[nodes].any(axis=1)  # a node with a free component
            points = _compat.dof_coordinates(Vf)[:n_owned, :gdim][moved]
            start = sum(comm.allgather(len(points))[: comm.rank])
            everywhere = np.concatenate(comm.allgather(points))
            owned = slice(start, start + len(points))
            dofs = nodes[moved].reshape(-1)
            self.parts.append(
                _Part(dolfinx.fem.Function(Vc), dc, dofs, free[dofs], everywhere, owned, bs)
            )
        self.locators: list[_compat.PointLocator] | None = None

    def __call__(self) -> int:
        """Interpolate; returns the number of fine nodes outside the coarse mesh (all
        ranks)."""
        if self.locators is None:
            mesh = self.coarse.function_space.mesh
            tree = _compat.PointLocator.tree(mesh)
            self.locators = [_compat.PointLocator(mesh, part.points, tree) for part in self.parts]
        kept = 0
        for part, locate in zip(self.parts, self.locators, strict=True):
            part.coarse.x.array[:] = self.coarse.x.array[part.coarse_dofs]
            mine = locate(part.coarse)[part.mine].reshape(-1)
            found = np.isfinite(mine)
            write = found & part.free
            self.fine.x.array[part.dofs[write]] = mine[write]
            kept += int(np.count_nonzero(~found)) // part.bs
        self.fine.x.scatter_forward()
        return self.fine.function_space.mesh.comm.allreduce(kept, op=MPI.SUM)


def transfer(coarse: dolfinx.fem.Function, fine: dolfinx.fem.Function, split: bool) -> int:
    """One :class:`Transfer` from ``coarse`` to ``fine``."""
    return Transfer(coarse, fine, split)()


class NestedSolver(SolverWrapper):
    """The fine solver started, at every load step, from the coarse chain's solution.

    ``coarse`` is the coarse problem's solver (itself a NestedSolver further down the chain);
    ``problem`` / ``coarse_problem`` the two problem kinds, whose ``nested_fields()`` name the
    Functions carried from coarse to fine. The other members of the solver protocol are the
    fine solver's."""

    def __init__(
        self, fine: Solver, problem: Problem, coarse: Solver, coarse_problem: Problem
    ) -> None:
        super().__init__(fine)
        self.fine, self.problem = fine, problem
        self.coarse, self.coarse_problem = coarse, coarse_problem
        fine.reuse_factorisation()
        self.fields = coarse_problem.nested_fields()
        self._saved = [f.x.array.copy() for f in self.fields]
        # the state is mixed when the problem is split; a nodal multiplier never is
        pairs = zip(self.fields, problem.nested_fields(), strict=True)
        fixed = owned_bc_dofs(problem.confined, owned_size(problem.state.function_space))
        self.transfers = [
            Transfer(c, f, problem.split and i == 0, fixed if i == 0 else None)
            for i, (c, f) in enumerate(pairs)
        ]
        #: Newton iterations of the coarse chain in the last solve
        self.coarse_newton = 0
        #: wall time of the coarse chain's solves
        self.coarse_time = 0.0

    #: not state (contactfx.io.checkpoint): this run's timing
    checkpoint_skip = ("coarse_time",)

    def solve(self) -> SolveStats:
        t0 = time.perf_counter()
        self._restore()
        self.coarse_problem.apply_load(float(self.problem.tload.value))
        self.coarse.assemble_load()
        self.coarse_newton = 0
        try:
            stats = self.coarse.solve()
        except TimeLimitExceeded:
            raise
        except ConvergenceError:
            self._restore()
        else:
            self.coarse_newton = stats.newton + stats.coarse_newton
            for move in self.transfers:
                move()
        self.coarse_time += time.perf_counter() - t0
        stats = self.fine.solve()
        stats.coarse_newton = self.coarse_newton
        return stats

    def converged(self) -> None:
        """The fine step converged: the coarse chain's step becomes its history too."""
        self.fine.converged()
        self.coarse_problem.converged()
        self.coarse.converged()
        self._saved = [f.x.array.copy() for f in self.fields]

    def phase_timings(self) -> dict[str, float]:
        """Within the solve: the coarse chain's share (``nested``)."""
        return {**self.fine.phase_timings(), "nested": self.coarse_time}

    def _restore(self) -> None:
        """The coarse chain back at its last converged state."""
        for f, saved in zip(self.fields, self._saved, strict=True):
            f.x.array[:] = saved

    def destroy(self) -> None:
        self.coarse.destroy()
        self.fine.destroy()
