"""al-ssn's multiplier on unfitted cracks: a P1 field on the cut cells' nodes whose equation is
a projection onto the crack's coarse grid (:class:`contactfx.contact.cut.CoarseGrid`), written
into the Newton system as a :class:`contactfx.contact.coupling.Coupling`.

On a fitted interface al-ssn collocates its complementarity function at the interface's nodes.
An unfitted crack has no nodes: its Gauss points lie inside the cut cells, and the P1 trace of
the background mesh is not a stable multiplier space (a node whose support the crack clips
carries a multiplier that nothing bounds; Bechet, Moes & Wohlmuth 2009,
doi:10.1002/nme.2515). So the multiplier lambda, the mixed unknown's P1 component on the nodes
of the cut cells (zero elsewhere), satisfies at every such node i

    lambda_i = sum_j N_j(psi_i) (int N_j f ds) / (int N_j ds),

with f the augmented traction at the crack's Gauss points (al-ssn's ``projected_law``: p, or
-p n + T with friction) and N_j the hat functions of the crack's grid in the crack's coordinate
psi (psi_i the node's): lambda is the interpolant of the lumped L2 projection of f onto the
grid, a field as coarse as al-uzawa's (:meth:`contactfx.driver.unfitted.UnfittedProblem.
surface_update`), the MorteX coarse-graining (Akula, Vignollet & Yastrebov 2019,
arXiv:1902.04000). The u-equation carries lambda's trace at the Gauss points.

With R the matrix of the map from the weighted values (omega_q f_q) at the Gauss points to the
nodes, the residual of the multiplier rows is lambda - R b(f) and their Jacobian I - R G, where
b and G are assembled by dolfinx: b(f)_q = omega_q f_q and G = d b / d(u, lambda), forms whose
test function lives in the quadrature space of the cells' rule (one dof per Gauss point). The
Jacobian is exact; R couples a node with the Gauss points of the grid's elements around it,
beyond its own cells, which the forms' cell-local assembly cannot express.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any, Protocol

import dolfinx
import numpy as np
import ufl
from numpy.typing import NDArray
from petsc4py import PETSc

from contactfx import _compat

if TYPE_CHECKING:
    from contactfx.contact.cut import CoarseGrid, CutSurface
    from contactfx.contact.surface import Expr

    #: a law on a crack's surface (a UFL expression of the surface)
    Law = Callable[[CutSurface], Expr]

__all__ = ["GridMultiplier"]


class _CrackView(Protocol):
    """What the multiplier reads of an unfitted crack
    (``contactfx.driver.unfitted_cracks.Crack``)."""

    @property
    def ds(self) -> ufl.Measure: ...

    @property
    def cut_owned(self) -> NDArray[np.int32]: ...

    @property
    def psi_q(self) -> NDArray[np.float64]: ...

    @property
    def weight_q(self) -> NDArray[np.float64]: ...

    @property
    def grid(self) -> CoarseGrid: ...

    def nodes(self, Q: Any) -> NDArray[np.bool_]: ...

    def coordinate(self, x: Any) -> Any: ...


class CrackedKind(Protocol):
    """What the multiplier reads of its problem kind, a
    :class:`contactfx.driver.unfitted.UnfittedProblem` (a protocol: that module imports this
    one)."""

    @property
    def mesh(self) -> dolfinx.mesh.Mesh: ...

    @property
    def state(self) -> dolfinx.fem.Function: ...

    @property
    def trial(self) -> Expr: ...

    @property
    def mult_shape(self) -> tuple[int, ...]: ...

    @property
    def cracks(self) -> Sequence[_CrackView]: ...

    @property
    def surfaces(self) -> Sequence[CutSurface]: ...

    def surface_space(self, shape: tuple[int, ...]) -> Any: ...

    def newton_surface(self, s: CutSurface) -> CutSurface: ...


class GridMultiplier:
    """The multiplier equations of al-ssn on the unfitted cracks of ``pb`` (module docstring);
    ``law(s)`` is the traction the multiplier projects on the crack surface s."""

    search_each_newton = False

    def __init__(self, pb: CrackedKind, law: Law) -> None:
        self.comm = pb.mesh.comm
        self.W = W = pb.state.function_space
        self.bs = pb.mult_shape[0] if pb.mult_shape else 1
        self.Qq = pb.surface_space(pb.mult_shape)
        self.test = ufl.TestFunction(self.Qq)
        self.pb = pb
        L = self.weighted(lambda s: law(pb.newton_surface(s)))
        self.L = dolfinx.fem.form(L)
        self.a = dolfinx.fem.form(ufl.derivative(L, pb.state, pb.trial))
        self.b = _compat.create_vector(self.L)
        self.G = _compat.create_matrix(self.a)
        imap = W.dofmap.index_map
        self.n_owned = imap.size_local * W.dofmap.index_map_bs
        self.R, self.rows = self._projection()
        self.y = self.R.createVecLeft()
        self._grown = False

    def weighted(self, law: Law) -> ufl.Form:
        """sum over the cracks of int q . law(s) ds, q the quadrature space's test function:
        the vector omega_q law_q at the Gauss points."""
        pb = self.pb
        terms = [
            ufl.inner(self.test, law(s)) * c.ds for c, s in zip(pb.cracks, pb.surfaces, strict=True)
        ]
        return sum(terms[1:], terms[0])

    def _global(self, local: NDArray[np.int64]) -> NDArray[np.int64]:
        """Global indices of local (owned or ghost) dofs of the mixed space."""
        bs = self.W.dofmap.index_map_bs
        blocks = self.W.dofmap.index_map.local_to_global(np.asarray(local // bs, np.int32))
        return np.asarray(blocks, dtype=np.int64) * bs + local % bs

    def _projection(self) -> tuple[PETSc.Mat, NDArray[np.int32]]:
        """(R, the owned local rows of the multiplier's dofs on the cracks)."""
        comm, W, bs, Qq = self.comm, self.W, self.bs, self.Qq
        q_map = Qq.dofmap.index_map
        q_cells = _compat.cell_dofs(Qq)
        W1 = W.sub(1)
        subs = [W1.sub(c) for c in range(bs)] if self.pb.mult_shape else [W1]
        # owned local row: [(columns, values), ...]
        entries: dict[int, list[tuple[NDArray[np.int64], NDArray[np.float64]]]] = {}
        for crack in self.pb.cracks:
            cells = crack.cut_owned
            parts = comm.allgather(
                (
                    np.asarray(q_map.local_to_global(q_cells[cells].ravel().astype(np.int32))),
                    crack.psi_q[cells].ravel(),
                    crack.weight_q[cells].ravel(),
                )
            )
            gq, psi_q, w_q = (np.concatenate([p[k] for p in parts]) for k in range(3))
            grid = crack.grid
            left, t = grid.hats(psi_q)
            j_q = np.concatenate([left, left + 1])  # (grid node, Gauss point, hat value)
            q_of = np.concatenate([gq, gq])
            n_q = np.concatenate([1.0 - t, t])
            _, den = grid.moments(psi_q, w_q, np.zeros((len(psi_q), 0)))  # int N_j ds
            by_node = [np.flatnonzero(j_q == j) for j in range(len(grid.nodes))]
            for c, Wc in enumerate(subs):
                Qc, to_w = Wc.collapse()
                nodes = np.flatnonzero(crack.nodes(Qc))
                w_local = np.asarray(to_w)[nodes]
                own = w_local < self.n_owned
                nodes, w_local = nodes[own], w_local[own]
                x = _compat.dof_coordinates(Qc)[nodes]
                i_left, ti = grid.hats(crack.coordinate(x[:, :2].T))
                for row, jl, tj in zip(w_local, i_left, ti, strict=True):
                    for j, a in ((jl, 1.0 - tj), (jl + 1, tj)):
                        if a > 0.0 and den[j] > 0.0:
                            k = by_node[j]
                            entries.setdefault(int(row), []).append(
                                (q_of[k] * bs + c, a / den[j] * n_q[k])
                            )
        rows = np.array(sorted(entries), dtype=np.int32)
        indptr = [0]
        indices: list[np.ndarray] = []
        values: list[np.ndarray] = []
        for row in range(self.n_owned):
            if row in entries:
                cols = np.concatenate([e[0] for e in entries[row]])
                vals = np.concatenate([e[1] for e in entries[row]])
                cols, inverse = np.unique(cols, return_inverse=True)
                indices.append(cols)
                values.append(np.bincount(inverse, weights=vals))
                indptr.append(indptr[-1] + len(cols))
            else:
                indptr.append(indptr[-1])
        empty = np.zeros(0)
        R = PETSc.Mat().createAIJ(
            ((self.n_owned, PETSc.DETERMINE), (q_map.size_local * bs, PETSc.DETERMINE)),
            csr=(
                np.asarray(indptr, PETSc.IntType),
                np.concatenate(indices or [empty]).astype(PETSc.IntType),
                np.concatenate(values or [empty]),
            ),
            comm=comm,
        )
        R.assemble()
        return R, rows

    # -- the Coupling protocol ---------------------------------------------------------------
    def update(self, u: NDArray[np.float64]) -> None:
        """No search: the cracks' points are fixed."""

    def missed(self, u: NDArray[np.float64]) -> int:
        return 0

    def residual(self, x: PETSc.Vec, F: PETSc.Vec) -> None:
        """F += lambda - R b(f) on the multiplier rows (the u-equation's rows: the forms')."""
        _compat.assemble_vector(self.b, self.L)
        self.R.mult(self.b, self.y)
        F.axpy(-1.0, self.y)
        f = F.getArray()
        f[self.rows] += x.getArray(readonly=True)[self.rows]

    def jacobian(
        self, x: PETSc.Vec, K: PETSc.Mat, J: PETSc.Mat, *, bulk_changed: bool = False
    ) -> None:
        """J = K + I - R G on the multiplier rows (the contact forms' Jacobian is added by the
        solver)."""
        _compat.assemble_matrix(self.G, self.a)
        RG = self.R.matMult(self.G)
        S = PETSc.Mat.Structure
        J.zeroEntries()
        J.axpy(1.0, K, structure=S.SUBSET_NONZERO_PATTERN)
        # R G reaches beyond a cell's dofs: J's pattern grows once, at the first Jacobian
        J.axpy(
            -1.0,
            RG,
            structure=S.SUBSET_NONZERO_PATTERN if self._grown else S.DIFFERENT_NONZERO_PATTERN,
        )
        self._grown = True
        diagonal = J.getDiagonal()  # (the multiplier's diagonal is in K's zero pattern)
        diagonal.getArray()[self.rows] += 1.0
        J.setDiagonal(diagonal)
        diagonal.destroy()
        RG.destroy()

    def project(self, law: Law) -> NDArray[np.float64]:
        """The nodal values R b(law) on the owned multiplier rows (a start: ``law`` evaluated
        at the current state)."""
        L = dolfinx.fem.form(self.weighted(law))
        b = _compat.assemble_vector(_compat.create_vector(L), L)
        self.R.mult(b, self.y)
        b.destroy()
        return self.y.getArray(readonly=True)[self.rows].copy()

    def destroy(self) -> None:
        for obj in (self.R, self.G, self.b, self.y):
            obj.destroy()
