"""The coupling layer between separately meshed bodies: contact terms that UFL cannot express
(they join a point of one body to the projected point on the other), evaluated pointwise and
written into the same PETSc vector and matrix as the bulk terms.

A :class:`Coupling` is what a two-body method gives the nonlinear solver
(:class:`contactfx.solvers.snes.ContactSNES`):

* ``update(u)``: the search at the current configuration (once per load step, or at every
  residual evaluation with ``--search-update newton``);
* ``residual(u, F)``: on entry F holds the bulk residual R(u) = f_int(u) - f_ext (owned rows,
  before the Dirichlet rows; :mod:`contactfx.solvers.bulk`); the coupling adds to it or
  transforms it in place;
* ``jacobian(u, K, J, bulk_changed=...)``: J receives the Jacobian of that residual; K is the
  bulk's Jacobian K(u), ``bulk_changed`` whether it may differ from the last call's (a
  nonlinear bulk: products with K cached by the coupling are formed again);
* ``missed(u)``: how many contact points a search at u would find that the last search did
  not (the solver searches again and continues Newton while there are any: a step's search
  at its start only reaches points about a facet size apart).

Global numbering: the P1 vector space's node (dof block) i, component c is the global row
``i * bs + c``. Values for rows that another rank owns go through PETSc's stash
(``setValues(..., ADD_VALUES)`` then assembly), so the couplings of facets that face each
other across ranks are assembled like any other entry; the matrices accept new nonzeros, so
the extended sparsity (rows of one body, columns of the other) appears as the search finds it.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Protocol

import dolfinx
import numpy as np
from petsc4py import PETSc

from contactfx import _compat

if TYPE_CHECKING:
    from mpi4py import MPI

__all__ = ["Coupling", "PairCoupling", "NodeLayout", "aij", "blocked_rows"]


class Coupling(Protocol):
    """What the solver calls (module docstring): ``u`` in ``update`` and ``missed`` is the
    state's local array (owned and ghost entries), in ``residual`` and ``jacobian`` its PETSc
    vector."""

    search_each_newton: bool

    def update(self, u: np.ndarray) -> None: ...

    def residual(self, u: PETSc.Vec, F: PETSc.Vec) -> None: ...

    def jacobian(
        self, u: PETSc.Vec, K: PETSc.Mat, J: PETSc.Mat, *, bulk_changed: bool = False
    ) -> None: ...

    def missed(self, u: np.ndarray) -> int: ...


class PairCoupling(Coupling, Protocol):
    """A two-body coupling also gives the two-body kind's post-processing its nodal state at
    the last converged solve: ``nodal()`` (the slave contact nodes, their weights, pressure
    and gap), ``nodal_friction()``, ``friction_state()`` and ``friction_work()`` (with
    friction; the last: friction's dissipation on the step), ``force()`` (the total normal
    force), ``slave_force()`` (the force vector on the slave body; ``force_parts()`` its normal
    and tangential parts), ``search_gaps()`` (the gaps the last search measured) and
    ``nodal_normals()`` (a unit normal per node of ``nodal()``);
    ``record_start()`` takes the last search's gaps (at the start) as an interference fit's
    initial overlaps (hidden by ``pair.hidden()``).
    ``converged()`` is called when a load step converged (a coupling that keeps a history,
    penalty friction's, moves it on)."""

    def nodal(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]: ...

    def nodal_normals(self) -> np.ndarray: ...

    def converged(self) -> None: ...

    def nodal_friction(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]: ...

    def friction_state(self) -> dict[str, float]: ...

    def friction_work(self) -> float: ...

    def force(self) -> float: ...

    def slave_force(self) -> np.ndarray: ...

    def force_parts(self) -> tuple[np.ndarray, np.ndarray]: ...

    def search_gaps(self, facets: bool = False) -> np.ndarray:
        """The gaps of the last search; ``facets``: between the facets, without a smoothing
        of the surfaces (what the overlap check at the start reads)."""
        ...

    def record_start(self) -> None: ...


def aij(comm: MPI.Comm, rows_local: int, rows_global: int, per_row: int = 16) -> PETSc.Mat:
    """An empty square parallel AIJ matrix that accepts entries anywhere (new nonzeros are
    allocated on the fly)."""
    A = PETSc.Mat().createAIJ(
        ((rows_local, rows_global), (rows_local, rows_global)), nnz=(per_row, per_row), comm=comm
    )
    A.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, False)
    A.setUp()
    return A


def blocked_rows(nodes: np.ndarray, bs: int) -> np.ndarray:
    """Global rows (nodes * bs + c) of ``nodes`` (..., ) as (..., bs)."""
    return (np.asarray(nodes, dtype=np.int64)[..., None] * bs + np.arange(bs)).astype(PETSc.IntType)


class NodeLayout:
    """The P1 vector space's layout seen from the coupling: global sizes, owned ranges, the
    reference coordinates as a vector, and scalar / blocked node vectors to assemble nodal
    quantities on the owners of the nodes."""

    def __init__(self, V: dolfinx.fem.FunctionSpace) -> None:
        self.V = V
        self.comm = V.mesh.comm
        self.imap = V.dofmap.index_map
        self.bs = V.dofmap.index_map_bs
        self.gdim = V.mesh.geometry.dim
        self.n_owned = self.imap.size_local
        self.start = self.imap.local_range[0]
        self.X = self.vector(self.bs)
        coords = _compat.dof_coordinates(V)[: self.n_owned, : self.gdim]
        self.X.getArray()[:] = coords.ravel()

    def vector(self, bs: int) -> PETSc.Vec:
        """A zero vector over the nodes with ``bs`` entries per node (owned + ghosts)."""
        return dolfinx.la.create_petsc_vector(self.imap, bs)

    def node_sum(self, nodes: np.ndarray, values: np.ndarray, bs: int) -> np.ndarray:
        """Sum the contributions ``values`` (n, bs) at global ``nodes`` (n,) on their owners;
        the owned nodes' sums (n_owned, bs)."""
        vec = self.vector(bs)
        rows = blocked_rows(nodes, bs).ravel()
        vec.setValues(
            rows, np.asarray(values, dtype=np.float64).ravel(), addv=PETSc.InsertMode.ADD_VALUES
        )
        vec.assemblyBegin()
        vec.assemblyEnd()
        out = vec.getArray().reshape(-1, bs).copy()
        vec.destroy()
        return out

    def matrix(self, per_row: int = 16) -> PETSc.Mat:
        n = self.n_owned * self.bs
        return aij(self.comm, n, self.imap.size_global * self.bs, per_row)
