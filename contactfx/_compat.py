"""Every difference between the supported dolfinx stacks, in one place.

Supported: dolfinx 0.5.2 / PETSc 3.18 (Debian 12) and dolfinx 0.9.0 / PETSc 3.22 (Debian 13).
No other module of contactfx checks a version; they call the functions below.
"""

from __future__ import annotations

import functools
from types import SimpleNamespace

import dolfinx
import dolfinx.fem.petsc
import dolfinx.graph
import dolfinx.mesh
import numpy as np
import ufl
from petsc4py import PETSc

from contactfx import jit_cache

__all__ = [
    "function_space",
    "petsc_vec",
    "element_degree",
    "model_to_mesh",
    "create_interval",
    "expression",
    "assemble_matrix",
    "create_matrix",
    "create_vector",
    "assemble_vector",
    "dof_coordinates",
    "cell_dofs",
    "bc_dofs",
    "locate_dofs_topological",
    "dirichletbc",
    "cell_diameter",
    "mixed_space",
    "quadrature_space",
    "quadrature_rule",
    "eval_expression",
    "geometry_nodes",
    "cell_coordinates",
    "numpy_math",
    "ufl_math",
    "PointLocator",
    "point_values",
]

_NEW = tuple(int(p) for p in dolfinx.__version__.split(".")[:2]) >= (0, 8)

# concurrent runs wait for each other's compiles of the same forms (contactfx/jit_cache.py)
jit_cache.install()


def function_space(mesh, family: str, degree: int, shape: tuple[int, ...] | None = None):
    """A (vector-valued when ``shape`` is given) Lagrange / DG function space."""
    if _NEW:
        element = (family, degree, shape) if shape else (family, degree)
        return dolfinx.fem.functionspace(mesh, element)
    if shape:
        return dolfinx.fem.VectorFunctionSpace(mesh, (family, degree), dim=shape[0])
    return dolfinx.fem.FunctionSpace(mesh, (family, degree))


def element_degree(space) -> int:
    """Polynomial degree of a function space's element."""
    degree = space.ufl_element().degree
    return degree() if callable(degree) else degree


def petsc_vec(u: dolfinx.fem.Function) -> PETSc.Vec:
    """The PETSc vector that wraps a Function's degrees of freedom (ghosted)."""
    return u.x.petsc_vec if _NEW else u.vector


def model_to_mesh(model, comm, rank: int, gdim: int):
    """gmsh model (built on ``rank``) -> (mesh, cell_tags, facet_tags) on ``comm``.

    The cells are distributed by :func:`partition_graph` (the same partition at every run).
    Ghost mode ``shared_facet`` on both stacks, so that interior-facet integrals (``dS``) include
    the facets on partition boundaries. dolfinx 0.5's ``model_to_mesh`` has no ``partitioner``
    argument, but its ``create_mesh`` defaults to ``GhostMode.shared_facet``; dolfinx >= 0.8
    defaults to ``GhostMode.none`` (a ``dS`` form over a facet on a partition boundary then
    raises RuntimeError), so the partitioner is passed explicitly.
    """
    from dolfinx.io import gmshio

    if _NEW:
        partitioner = dolfinx.mesh.create_cell_partitioner(
            partition_graph, dolfinx.mesh.GhostMode.shared_facet
        )
        out = gmshio.model_to_mesh(model, comm, rank, gdim=gdim, partitioner=partitioner)
    else:  # 0.5: model_to_mesh calls create_mesh without a partitioner: give it ours
        create_mesh = gmshio.create_mesh
        partitioner = dolfinx.mesh.create_cell_partitioner(partition_graph)
        gmshio.create_mesh = functools.partial(create_mesh, partitioner=partitioner)
        try:
            out = gmshio.model_to_mesh(model, comm, rank, gdim=gdim)
        finally:
            gmshio.create_mesh = create_mesh
    if hasattr(out, "mesh"):  # dolfinx >= 0.10 returns a MeshData named tuple
        return out.mesh, out.cell_tags, out.facet_tags
    return out[0], out[1], out[2]


def partition_graph(comm, nparts: int, graph, ghosting: bool):
    """A deterministic partition of the cells' dual graph into ``nparts`` parts: the reverse
    Cuthill-McKee order of the whole graph (on rank 0) cut into parts of equal size, so that
    each part is a band of neighbouring cells. SCOTCH, dolfinx's default, gives another
    partition at each run of the same input (Debian's threaded build), so a run on several
    ranks could not be repeated to the last bit, nor continued from a checkpoint; a band
    partition is as good for the few ranks of contactfx's runs. With ``ghosting`` each
    cell's destinations are its part and then the parts of its neighbours across a facet
    (the ``shared_facet`` halo). Returns the destinations of this rank's cells."""
    from scipy.sparse import csr_matrix
    from scipy.sparse.csgraph import reverse_cuthill_mckee

    offsets = np.asarray(graph.offsets, dtype=np.int64)
    n_local = len(offsets) - 1
    parts = comm.gather((n_local, np.asarray(graph.array, dtype=np.int64), offsets), root=0)
    dest = None
    if comm.rank == 0:
        counts = [p[0] for p in parts]
        n = sum(counts)
        adj = np.concatenate([p[1] for p in parts])
        rows = np.concatenate(
            [
                np.repeat(np.arange(p[0]) + sum(counts[:r]), np.diff(p[2]))
                for r, p in enumerate(parts)
            ]
        )
        A = csr_matrix((np.ones(len(adj), dtype=np.int8), (rows, adj)), shape=(n, n))
        order = reverse_cuthill_mckee(A, symmetric_mode=True)
        part = np.empty(n, dtype=np.int32)
        part[order] = (np.arange(n, dtype=np.int64) * nparts // max(n, 1)).astype(np.int32)
        if ghosting:
            other = part[adj] != part[rows]
            pairs = np.unique(np.column_stack([rows[other], part[adj][other]]), axis=0)
            extra = np.bincount(pairs[:, 0], minlength=n)
            data_offsets = np.zeros(n + 1, dtype=np.int64)
            data_offsets[1:] = np.cumsum(1 + extra)
            data = np.empty(data_offsets[-1], dtype=np.int32)
            data[data_offsets[:-1]] = part
            # the ghost parts after the owner, in increasing order (pairs are sorted)
            first = np.searchsorted(pairs[:, 0], pairs[:, 0], side="left")
            data[data_offsets[pairs[:, 0]] + 1 + np.arange(len(pairs)) - first] = pairs[:, 1]
        else:
            data_offsets = np.arange(n + 1, dtype=np.int64)
            data = part
        starts = np.concatenate([[0], np.cumsum(counts)])
        dest = [
            (
                data[data_offsets[starts[r]] : data_offsets[starts[r + 1]]],
                (data_offsets[starts[r] : starts[r + 1] + 1] - data_offsets[starts[r]]),
            )
            for r in range(comm.size)
        ]
    data, offs = comm.scatter(dest, root=0)
    return _adjacency_int32(data.astype(np.int32), offs.astype(np.int32))


def _adjacency_int32(data: np.ndarray, offsets: np.ndarray):
    make = getattr(dolfinx.graph, "adjacencylist", None) or dolfinx.graph.create_adjacencylist
    return make(data, offsets)


def create_rectangle(comm, points, n, diagonal: str = "right"):
    """Structured triangle mesh of the rectangle between ``points`` with ``n`` = (nx, ny) cells a
    side, its cells distributed by :func:`partition_graph` (the same partition at every run,
    as the gmsh meshes': a checkpoint's mesh is found again at the restart) with the
    ``shared_facet`` halo; ``diagonal`` one of dolfinx's DiagonalType names."""
    kind = getattr(dolfinx.mesh.DiagonalType, diagonal)
    if _NEW:
        partitioner = dolfinx.mesh.create_cell_partitioner(
            partition_graph, dolfinx.mesh.GhostMode.shared_facet
        )
    else:
        partitioner = dolfinx.mesh.create_cell_partitioner(partition_graph)
    return dolfinx.mesh.create_rectangle(
        comm,
        [np.asarray(points[0], dtype=float), np.asarray(points[1], dtype=float)],
        list(n),
        dolfinx.mesh.CellType.triangle,
        partitioner=partitioner,
        diagonal=kind,
    )


def create_interval(comm, n: int, length: float):
    """Interval mesh (0, length) with n cells."""
    return dolfinx.mesh.create_interval(comm, n, [0.0, length])


def expression(expr, space) -> dolfinx.fem.Expression:
    """A compiled UFL expression evaluated at the interpolation points of ``space``."""
    element = space.element
    points = element.interpolation_points() if _NEW else element.interpolation_points
    if callable(points):
        points = points()
    return dolfinx.fem.Expression(expr, points)


def create_matrix(form) -> PETSc.Mat:
    return dolfinx.fem.petsc.create_matrix(form)


def create_vector(form) -> PETSc.Vec:
    return dolfinx.fem.petsc.create_vector(form)


def assemble_matrix(A: PETSc.Mat, form, bcs: list | None = None) -> PETSc.Mat:
    """Zero ``A`` and assemble ``form`` into it, finalised; with ``bcs`` their rows and
    columns zero and a unit diagonal."""
    A.zeroEntries()
    if bcs:  # (both versions dispatch on the matrix: A, form, bcs positional)
        dolfinx.fem.petsc.assemble_matrix(A, form, bcs)
    else:
        dolfinx.fem.petsc.assemble_matrix(A, form)
    A.assemble()
    return A


def assemble_vector(b: PETSc.Vec, form) -> PETSc.Vec:
    """Zero ``b``, assemble ``form`` and accumulate ghost contributions on the owners."""
    with b.localForm() as b_local:
        b_local.set(0.0)
    dolfinx.fem.petsc.assemble_vector(b, form)
    b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    return b


def cell_dofs(space) -> np.ndarray:
    """The dofmap as an array (cells incl. ghosts, dofs per cell) of local (block) dofs."""
    dofmap = space.dofmap.list
    if isinstance(dofmap, np.ndarray):  # dolfinx >= 0.7
        return dofmap
    n = space.dofmap.cell_dofs(0).size if dofmap.num_nodes else 0
    return dofmap.array.reshape(-1, n)


def dof_coordinates(space) -> np.ndarray:
    """Coordinates (num_dofs_local + ghosts, 3) of the (scalar) space's dofs."""
    return space.tabulate_dof_coordinates()


def locate_dofs_topological(space, dim: int, entities: np.ndarray) -> np.ndarray:
    return dolfinx.fem.locate_dofs_topological(space, dim, entities)


def dirichletbc(value, dofs, space=None):
    if space is None:
        return dolfinx.fem.dirichletbc(value, dofs)
    return dolfinx.fem.dirichletbc(value, dofs, space)


def bc_dofs(bc) -> np.ndarray:
    """Local indices (owned and ghost) of the dofs a Dirichlet condition fixes."""
    dofs, _ = bc.dof_indices()
    return dofs


def cell_diameter(mesh):
    return ufl.CellDiameter(mesh)


def mixed_space(mesh, degree: int, gdim: int, multiplier_shape: tuple[int, ...]):
    """[P_degree]^gdim x P1 (scalar, or vector of ``multiplier_shape``): displacement and
    contact multiplier in one space."""
    if _NEW:
        import basix.ufl

        cell = mesh.basix_cell()
        Ve = basix.ufl.element("Lagrange", cell, degree, shape=(gdim,))
        Qe = basix.ufl.element("Lagrange", cell, 1, shape=multiplier_shape or None)
        return dolfinx.fem.functionspace(mesh, basix.ufl.mixed_element([Ve, Qe]))
    cell = mesh.ufl_cell()
    Ve = ufl.VectorElement("Lagrange", cell, degree, dim=gdim)
    if multiplier_shape:
        Qe = ufl.VectorElement("Lagrange", cell, 1, dim=multiplier_shape[0])
    else:
        Qe = ufl.FiniteElement("Lagrange", cell, 1)
    return dolfinx.fem.FunctionSpace(mesh, ufl.MixedElement([Ve, Qe]))


def quadrature_rule(mesh, degree: int) -> tuple[np.ndarray, np.ndarray]:
    """(points (n, tdim), weights (n,)) of the reference cell's default rule of ``degree``:
    the rule of a form with ``{"quadrature_degree": degree, "quadrature_rule": "default"}``
    and the points of :func:`quadrature_space`."""
    import basix

    cell = mesh.basix_cell() if _NEW else getattr(basix.CellType, mesh.topology.cell_name())
    points, weights = basix.make_quadrature(cell, degree)
    return np.asarray(points), np.asarray(weights)


def quadrature_space(mesh, degree: int, shape: tuple[int, ...] = ()):
    """A space of values at the points of :func:`quadrature_rule` (one dof per cell and point,
    in the rule's order; a block of ``shape[0]`` components per dof for a vector)."""
    if _NEW:
        import basix.ufl

        element = basix.ufl.quadrature_element(
            mesh.basix_cell(), value_shape=tuple(shape), scheme="default", degree=degree
        )
        return dolfinx.fem.functionspace(mesh, element)
    cell = mesh.ufl_cell()
    if shape:
        element = ufl.VectorElement("Quadrature", cell, degree, dim=shape[0], quad_scheme="default")
    else:
        element = ufl.FiniteElement("Quadrature", cell, degree, quad_scheme="default")
    return dolfinx.fem.FunctionSpace(mesh, element)


def eval_expression(expr: dolfinx.fem.Expression, mesh, cells: np.ndarray) -> np.ndarray:
    """Values (len(cells), points * value size) of a compiled expression on local cells."""
    cells = np.asarray(cells, dtype=np.int32)
    return expr.eval(mesh, cells) if _NEW else expr.eval(cells)


def geometry_nodes(mesh) -> np.ndarray:
    """(cells incl. ghosts, nodes per cell): the indices into ``mesh.geometry.x`` of every local
    cell's geometry nodes (0.9: an array already; 0.5: an adjacency list)."""
    dofmap = mesh.geometry.dofmap
    if not isinstance(dofmap, np.ndarray):
        n = dofmap.links(0).size if dofmap.num_nodes else 0
        dofmap = dofmap.array.reshape(-1, n)
    return dofmap


def cell_coordinates(mesh) -> np.ndarray:
    """(cells incl. ghosts, nodes per cell, gdim): the coordinates of every local cell's
    geometry nodes (its vertices for an affine mesh)."""
    return mesh.geometry.x[geometry_nodes(mesh)][:, :, : mesh.geometry.dim]


def entity_coordinates(mesh, dim: int, entities: np.ndarray) -> np.ndarray:
    """(entities, nodes per entity, gdim): the coordinates of the entities' geometry nodes."""
    entities = np.asarray(entities, dtype=np.int32)
    if _NEW:
        nodes = dolfinx.mesh.entities_to_geometry(mesh, dim, entities, False)
    else:
        # (Debian's 0.5 wraps the C++ mesh in ``_mesh``; upstream's Mesh is the C++ one)
        cpp = getattr(mesh, "_mesh", mesh)
        nodes = dolfinx.cpp.mesh.entities_to_geometry(cpp, dim, entities, False)
    return mesh.geometry.x[nodes][:, :, : mesh.geometry.dim]


# Math namespaces (sqrt, atan2, cos, sin) for closed forms written once for numpy arrays and UFL
# expressions (contactfx.references). numpy < 2 has no atan2 alias, UFL < 2023 names it atan_2.
numpy_math = SimpleNamespace(
    sqrt=np.sqrt, atan2=np.arctan2, cos=np.cos, sin=np.sin, maximum=np.maximum
)
ufl_math = SimpleNamespace(
    sqrt=ufl.sqrt,
    atan2=getattr(ufl, "atan2", None) or ufl.atan_2,
    cos=ufl.cos,
    sin=ufl.sin,
    maximum=ufl.max_value,
)


def _bb_tree(mesh, tdim: int, entities: np.ndarray, padding: float = 0.0):
    """The bounding-box tree of the mesh's entities of dimension ``tdim``."""
    import dolfinx.geometry as geo

    if _NEW:
        return geo.bb_tree(mesh, tdim, entities, padding=padding)
    return geo.BoundingBoxTree(mesh, tdim, entities, padding=padding)


class PointLocator:
    """Where points (n, gdim) lie in a mesh, found once: each point is evaluated by the lowest
    rank that owns a cell containing it; a point outside the mesh gives NaN. Calling it with
    a Function on that mesh gives the values (n, value size) on every rank. Collective."""

    def __init__(self, mesh, points: np.ndarray, tree=None) -> None:
        import dolfinx.geometry as geo
        from mpi4py import MPI

        self.comm = mesh.comm
        n = len(points)
        self.points = np.zeros((n, 3))
        self.points[:, : points.shape[1]] = points
        tree = self.tree(mesh) if tree is None else tree
        if _NEW:
            candidates = geo.compute_collisions_points(tree, self.points)
        else:
            candidates = geo.compute_collisions(tree, self.points)
        colliding = geo.compute_colliding_cells(mesh, candidates, self.points)
        offsets = np.asarray(colliding.offsets)
        found = np.diff(offsets) > 0
        ranks = np.where(found, self.comm.rank, self.comm.size).astype(np.int64)
        first = np.empty_like(ranks)
        self.comm.Allreduce(ranks, first, op=MPI.MIN)
        self.outside = first == self.comm.size
        self.mine = np.flatnonzero(first == self.comm.rank)
        self.cells = np.asarray(colliding.array)[offsets[self.mine]].astype(np.int32)

    @staticmethod
    def tree(mesh):
        """The bounding-box tree of the mesh's owned cells (to share between locators)."""
        tdim = mesh.topology.dim
        cells = np.arange(mesh.topology.index_map(tdim).size_local, dtype=np.int32)
        return _bb_tree(mesh, tdim, cells)

    def __call__(self, f: dolfinx.fem.Function) -> np.ndarray:
        from mpi4py import MPI

        size = int(np.prod(f.ufl_shape)) if f.ufl_shape else 1
        local = np.zeros((len(self.points), size))
        if len(self.mine):
            values = f.eval(self.points[self.mine], self.cells)
            local[self.mine] = values.reshape(len(self.mine), size)
        values = np.zeros_like(local)
        self.comm.Allreduce(local, values, op=MPI.SUM)
        values[self.outside] = np.nan
        return values


def point_values(f: dolfinx.fem.Function, points: np.ndarray) -> np.ndarray:
    """Values (n, value size) of ``f`` at the points (n, gdim) on every rank (NaN outside the
    mesh): one :class:`PointLocator`, called once. Collective."""
    return PointLocator(f.function_space.mesh, points)(f)
