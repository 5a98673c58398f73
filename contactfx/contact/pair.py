"""Contact pairs between separately meshed bodies: the two surfaces, their current
configuration, and the search for the opposite surface across ranks.

A *side* is one body's contact surface on this rank: its owned facets (segments in 2D,
triangles in 3D) of a P1 vector space, each with the local and global node (dof block)
indices of its vertices, ordered so that the facet's normal (:func:`facet_normals`) points out
of the body. The current configuration is x = X + u at the vertices.

Search across ranks (:func:`gather_near`): every rank publishes the bounding box of the
region it searches (its slave facets in the current configuration, enlarged by the search
radius); every rank sends each other rank the master facets (current coordinates and global
node indices) that meet that box; candidates are then found in a bounding-box tree of the
received facets (:class:`contactfx.contact.boxes.FacetTree`), every facet's box
enlarged by its own diameter (a uniform padding by the largest facet would give thousands of
candidates per facet on a graded mesh). The cost is one
``alltoall`` of the facets near each rank's slave region: at 1 rank nothing is sent, at p
ranks each master facet is sent to the ranks whose slave region it meets (usually one or
two), never the whole surface to everybody.

The rim of a surface (:func:`surface_rim`): which vertices and edges of its facets lie on the
surface's boundary (3D: an edge of one facet only, and its end vertices; 2D: a vertex of one
segment only), found once by global node numbers when the side is built (each facet sent to
the ranks that own its vertices by the rule node % size, one ``alltoall`` there and back) and
carried with the facets through the search: what tells a point beyond the master surface
from a point at a kink of it (:mod:`contactfx.contact.point_coupling`) on any partition. In
3D an edge of one facet on a symmetry plane is not on the rim (:func:`mirror_edges`: the
mirror image continues the surface there); the Dirichlet flags of the facets' nodes (a
ghost's from its owner, :func:`node_held`) travel with them in the same exchange.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
from mpi4py import MPI

from contactfx import _compat
from contactfx.contact.boxes import FacetTree

if TYPE_CHECKING:
    import dolfinx

    from contactfx.contact.coupling import NodeLayout

__all__ = [
    "Side",
    "Facets",
    "ContactPair",
    "side_of",
    "facet_normals",
    "gather_near",
    "owners",
    "facet_order",
    "facet_rim",
    "mirror_edges",
    "node_held",
    "surface_rim",
]

#: reference coordinates of the nodes of an edge on a symmetry plane: equal to this fraction
#: of the surface's size (the bounding box's diagonal)
PLANE_TOL = 1e-12


@dataclass
class Facets:
    """Facets in the current configuration: ``x`` (m, d, gdim) vertex coordinates and
    ``nodes`` (m, d) global node (dof block) indices; ``X`` (m, d, gdim) the reference
    coordinates (the same bits on every partition, unlike the global indices: what orders
    facets independently of the partition, :func:`facet_order`); ``open_vertex`` and
    ``open_edge`` (m, d) bool the rim of the surface they belong to (:func:`surface_rim`),
    or None (unknown)."""

    x: np.ndarray
    nodes: np.ndarray
    X: np.ndarray | None = None
    open_vertex: np.ndarray | None = None
    open_edge: np.ndarray | None = None
    #: (m, edges) the smooth surface's deviation from each facet
    #: (:func:`contactfx.contact.smoothing.bulges`), or None: the facets are the surface
    bulge: np.ndarray | None = None
    #: (m, d, gdim) the vertices' displacement since the last converged step (the mortar's
    #: consistent tangent with friction, :mod:`.mortar_tangent`), or None
    shift: np.ndarray | None = None

    def subset(self, keep: np.ndarray) -> Facets:
        """The facets selected by ``keep`` (a mask or indices), with their fields."""

        def sub(a: np.ndarray | None) -> np.ndarray | None:
            return None if a is None else a[keep]

        return Facets(
            self.x[keep],
            self.nodes[keep],
            sub(self.X),
            sub(self.open_vertex),
            sub(self.open_edge),
            sub(self.bulge),
            sub(self.shift),
        )

    def __len__(self) -> int:
        return len(self.nodes)

    def diameters(self) -> np.ndarray:
        """(m,) the longest edge of every facet."""
        d = self.x.shape[1]
        edges = [
            np.linalg.norm(self.x[:, i] - self.x[:, (i + 1) % d], axis=1)
            for i in range(d if d > 2 else 1)
        ]
        return np.max(edges, axis=0) if len(self) else np.zeros(0)

    def diameter(self) -> float:
        """The largest edge length (0 for no facet)."""
        return float(np.max(self.diameters(), initial=0.0))


@dataclass
class Side:
    """One body's contact surface on this rank (owned facets). ``local`` (m, d): local node
    indices of the vertices (of the P1 vector space's index map), ``nodes`` (m, d): their
    global indices, ``X`` (m, d, gdim): reference coordinates; ``cell`` (m,): the local cell
    of each facet, ``cell_local`` / ``cell_nodes`` (m, d + 1) its nodes (local, global) and
    ``cell_X`` (m, d + 1, gdim) their reference coordinates (the stress of the body at its
    surface, for Nitsche); ``open_vertex`` / ``open_edge`` the rim of the whole surface
    (:func:`surface_rim`)."""

    tag: int
    local: np.ndarray
    nodes: np.ndarray
    X: np.ndarray
    cell: np.ndarray
    cell_local: np.ndarray
    cell_nodes: np.ndarray
    cell_X: np.ndarray
    #: (m, d) the rim of the whole surface (:func:`surface_rim`), None: unknown
    open_vertex: np.ndarray | None = None
    open_edge: np.ndarray | None = None

    def current(self, u: np.ndarray) -> Facets:
        """The facets at x = X + u; ``u`` the local (owned + ghost) array, blocked (n, gdim)."""
        return Facets(self.X + u[self.local], self.nodes, self.X, self.open_vertex, self.open_edge)

    def __len__(self) -> int:
        return len(self.local)


def side_of(
    V: dolfinx.fem.FunctionSpace, facet_tags: Any, tag: int, fixed: np.ndarray | None = None
) -> Side:
    """The owned facets tagged ``tag`` of the P1 vector space V, oriented outwards
    (``facet_tags``: dolfinx's mesh tags, whose class differs between its versions), and the
    rim of their surface; ``fixed``: the owned Dirichlet dofs (bool (n_owned * bs,), as
    ``ContactPair.fixed``), whose symmetry planes are then not part of the rim
    (:func:`mirror_edges`). Collective."""
    mesh = V.mesh
    tdim = mesh.topology.dim
    fdim = tdim - 1
    mesh.topology.create_connectivity(fdim, tdim)
    mesh.topology.create_connectivity(fdim, 0)
    mesh.topology.create_connectivity(tdim, 0)
    n_owned = mesh.topology.index_map(fdim).size_local
    facets = facet_tags.indices[facet_tags.values == tag]
    facets = facets[facets < n_owned]
    f2c = mesh.topology.connectivity(fdim, tdim)
    f2v = mesh.topology.connectivity(fdim, 0)
    c2v = mesh.topology.connectivity(tdim, 0)
    gdim = mesh.geometry.dim
    X = _compat.dof_coordinates(V)[:, :gdim]
    d = fdim + 1
    local = np.zeros((len(facets), d), dtype=np.int64)
    cells = np.zeros(len(facets), dtype=np.int64)
    cell_local = np.zeros((len(facets), d + 1), dtype=np.int64)
    for i, f in enumerate(facets):
        cells[i] = f2c.links(f)[0]
        vertices = f2v.links(f)
        cell_vertices = c2v.links(cells[i])
        dofs = V.dofmap.cell_dofs(cells[i])
        # P1: the cell's dofs follow its vertices
        local[i] = [dofs[np.flatnonzero(cell_vertices == v)[0]] for v in vertices]
        cell_local[i] = dofs
    Xf = X[local]
    normals = facet_normals(Xf)
    inward = X[cell_local].mean(axis=1)
    flip = np.einsum("ij,ij->i", normals, inward - Xf.mean(axis=1)) > 0.0
    local[flip, :2] = local[flip, 1::-1]
    imap = V.dofmap.index_map

    def glob(a: np.ndarray) -> np.ndarray:
        out = imap.local_to_global(a.ravel().astype(np.int32))
        return np.asarray(out, dtype=np.int64).reshape(a.shape)

    nodes = glob(local)
    held = None if fixed is None else node_held(V, fixed)[local]
    open_vertex, open_edge = surface_rim(mesh.comm, nodes, X[local], held)
    return Side(
        tag,
        local,
        nodes,
        X[local],
        cells,
        cell_local,
        glob(cell_local),
        X[cell_local],
        open_vertex,
        open_edge,
    )


def node_held(V: dolfinx.fem.FunctionSpace, fixed: np.ndarray) -> np.ndarray:
    """(n, gdim) bool: which displacement components of each local node (owned and ghost) of
    the P1 vector space V a Dirichlet condition holds, from the owned Dirichlet dofs ``fixed``
    (bool (n_owned * bs,)): a ghost's flags are its owner's (one scatter). Collective."""
    import dolfinx.fem  # here: the module imports dolfinx for its annotations only

    bs = V.dofmap.index_map_bs
    flags = dolfinx.fem.Function(V)
    flags.x.array[:] = 0.0
    flags.x.array[: len(fixed)] = np.asarray(fixed, dtype=bool)
    flags.x.scatter_forward()
    return np.real(flags.x.array).reshape(-1, bs)[:, : V.mesh.geometry.dim] != 0.0


def mirror_edges(X: np.ndarray, held: np.ndarray, tol: float) -> np.ndarray:
    """(m, 3) bool: the edge of each triangle opposite vertex i lies on a symmetry plane.
    ``X`` (m, 3, 3) the reference coordinates of the triangles' vertices, ``held`` (m, 3, 3)
    which of their displacement components a Dirichlet condition holds (:func:`node_held`).
    An edge is on a symmetry plane if, for some axis k, both its nodes hold component k and
    lie on one plane normal to axis k (their k-th coordinates equal to ``tol``): a roller
    plane, where the mirror image of the body continues its surface. Not if both nodes hold
    every component: a clamped or rigidly driven face (``sphere-slide``: the hemisphere's rim
    on its driven flat top), where the surface ends. The held value is not looked at: a face
    driven along its normal only (a frictionless platen, ``hertz-spheres``' flat cuts) counts
    as a symmetry plane too. 2D is left as it was (:func:`facet_rim`)."""
    ends = np.array([[1, 2], [2, 0], [0, 1]])
    Xa, Xb = X[:, ends[:, 0]], X[:, ends[:, 1]]
    ha, hb = held[:, ends[:, 0]], held[:, ends[:, 1]]
    roller = np.any(ha & hb & (np.abs(Xa - Xb) <= tol), axis=2)
    clamped = np.all(ha, axis=2) & np.all(hb, axis=2)
    return roller & ~clamped


def _size(X: np.ndarray, comm: MPI.Comm | None = None) -> float:
    """The diagonal of the bounding box of the points ``X`` (..., gdim) (of all ranks)."""
    gdim = X.shape[-1]
    pts = X.reshape(-1, gdim)
    lo = pts.min(axis=0) if len(pts) else np.full(gdim, np.inf)
    hi = pts.max(axis=0) if len(pts) else np.full(gdim, -np.inf)
    if comm is not None and comm.size > 1:
        lo = np.min(comm.allgather(lo), axis=0)
        hi = np.max(comm.allgather(hi), axis=0)
    return float(np.linalg.norm(hi - lo)) if np.all(hi >= lo) else 0.0


def facet_rim(
    nodes: np.ndarray,
    X: np.ndarray | None = None,
    held: np.ndarray | None = None,
    tol: float | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """The rim of the surface made of the facets ``nodes`` (m, d) (global node indices):
    ``open_vertex`` (m, d), vertex i of the facet on the surface's boundary, and ``open_edge``
    (m, d), the facet's edge opposite vertex i on it (3D). 2D: a vertex of one segment only
    (the end of an open curve), ``open_edge`` all False (the closest point of a segment off
    it is a vertex). 3D: an edge of one triangle only, and the vertices of such edges; with
    the reference coordinates ``X`` (m, d, gdim) and the held components ``held`` (m, d,
    gdim) of the facets' nodes, an edge of one triangle on a symmetry plane is not on the
    rim (:func:`mirror_edges`; ``tol``: absolute, default :data:`PLANE_TOL` times the size
    of the facets)."""
    m, d = nodes.shape
    if d == 2:
        uniq, count = np.unique(nodes, return_counts=True)
        open_vertex = count[np.searchsorted(uniq, nodes)] == 1
        return open_vertex.reshape(m, d), np.zeros((m, d), dtype=bool)
    # edge i: the vertices other than i, sorted
    edges = np.sort(nodes[:, [[1, 2], [2, 0], [0, 1]]], axis=2)
    flat = edges.reshape(-1, 2)
    if len(flat) == 0:
        return np.zeros((m, d), dtype=bool), np.zeros((m, d), dtype=bool)
    _, inverse, count = np.unique(flat, axis=0, return_inverse=True, return_counts=True)
    open_edge = (count[inverse.reshape(-1)] == 1).reshape(m, d)
    if X is not None and held is not None:
        open_edge &= ~mirror_edges(X, held, PLANE_TOL * _size(X) if tol is None else tol)
    open_vertex = np.isin(nodes, np.unique(edges[open_edge]))
    return open_vertex, open_edge


def surface_rim(
    comm: MPI.Comm,
    nodes: np.ndarray,
    X: np.ndarray | None = None,
    held: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`facet_rim` of the surface whose facets are distributed over the ranks of
    ``comm`` (``nodes`` (m, d): this rank's facets, each facet on one rank; ``X`` and
    ``held`` (m, d, gdim) their nodes' reference coordinates and held components, or None),
    for this rank's facets; the same on any partition. Each facet goes to the ranks that own
    one of its vertices (node % size), with its coordinates and flags: there are all the
    facets around each of their vertices, so the rank sees each vertex it owns, and each edge
    with an end it owns, as the whole surface does; it answers for those, and the answers
    are joined. The plane tolerance is :data:`PLANE_TOL` of the whole surface's size.
    Collective."""
    m, d = nodes.shape
    size = comm.size
    tol = None if X is None or held is None else PLANE_TOL * _size(X, comm)
    if size == 1:
        return facet_rim(nodes, X, held, tol)
    chosen = [np.flatnonzero(np.any(nodes % size == r, axis=1)) for r in range(size)]
    if X is None or held is None:
        received = comm.alltoall([(nodes[c],) for c in chosen])
    else:
        received = comm.alltoall([(nodes[c], X[c], held[c]) for c in chosen])
    counts = [len(g[0]) for g in received]

    def joined(i: int, *shape: int) -> np.ndarray:
        return np.concatenate([np.reshape(g[i], (-1, *shape)) for g in received])

    got = joined(0, d).astype(np.int64)
    if X is None or held is None:
        open_vertex, open_edge = facet_rim(got)
    else:
        gdim = X.shape[2]
        open_vertex, open_edge = facet_rim(got, joined(1, d, gdim), joined(2, d, gdim), tol)
    mine = got % size == comm.rank
    open_vertex &= mine
    # the edge opposite vertex i: an end of it owned here
    open_edge &= np.roll(mine, -1, axis=1) | np.roll(mine, -2, axis=1)
    bounds = np.cumsum([0, *counts])
    answers = comm.alltoall(
        [(open_vertex[a:b], open_edge[a:b]) for a, b in zip(bounds[:-1], bounds[1:], strict=True)]
    )
    out_vertex, out_edge = np.zeros((m, d), dtype=bool), np.zeros((m, d), dtype=bool)
    for c, (v, e) in zip(chosen, answers, strict=True):
        out_vertex[c] |= v
        out_edge[c] |= e
    return out_vertex, out_edge


def facet_normals(x: np.ndarray) -> np.ndarray:
    """Unit normals of facets (m, d, gdim): (t_y, -t_x) for a segment with t = x1 - x0
    (outward for a body on the left of t), (x1 - x0) x (x2 - x0) normalised for a triangle."""
    if x.shape[1] == 2:
        t = x[:, 1] - x[:, 0]
        n = np.stack([t[:, 1], -t[:, 0]], axis=1)
    else:
        n = np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0])
    return n / np.linalg.norm(n, axis=1)[:, None]


def _boxes_meet(lo: np.ndarray, hi: np.ndarray, box: np.ndarray) -> np.ndarray:
    return np.all((hi >= box[0]) & (lo <= box[1]), axis=1)


def gather_near(comm: MPI.Comm, master: Facets, region: Facets, radius: float) -> Facets:
    """The master facets of every rank that meet this rank's ``region`` (its bounding box
    enlarged by ``radius``), in rank order. Collective."""
    gdim = master.x.shape[2]
    if len(region):
        box = np.stack([region.x.min(axis=(0, 1)) - radius, region.x.max(axis=(0, 1)) + radius])
    else:
        box = np.stack([np.full(gdim, np.inf), np.full(gdim, -np.inf)])
    boxes = comm.allgather(box)
    lo, hi = master.x.min(axis=1), master.x.max(axis=1)
    if comm.size == 1:
        return master.subset(_boxes_meet(lo, hi, boxes[0]))
    # the optional fields travel with their facets (None on every rank alike)
    optional = [master.X, master.open_vertex, master.open_edge, master.bulge, master.shift]
    sends = []
    for b in boxes:
        keep = _boxes_meet(lo, hi, b)
        part = [master.x[keep], master.nodes[keep]]
        part += [a[keep] for a in optional if a is not None]
        sends.append(tuple(part))
    received = comm.alltoall(sends)

    def joined(i: int, like: np.ndarray) -> np.ndarray:
        return np.concatenate([r[i] for r in received]).reshape(-1, *like.shape[1:])

    x, nodes = joined(0, master.x), joined(1, master.nodes)
    fields: list[np.ndarray | None] = []
    i = 2
    for a in optional:
        fields.append(None if a is None else joined(i, a))
        i += a is not None
    return Facets(x, nodes, *fields)


def facet_order(X: np.ndarray) -> np.ndarray:
    """(m,) the rank of each facet (reference vertex coordinates X (m, d, gdim)) in the
    lexicographic order of its vertices' coordinates, the vertices sorted first: an order of
    the facets that does not depend on the partition or on the order they came in."""
    m, d, gdim = X.shape
    if m == 0:
        return np.zeros(0, dtype=np.int64)
    vertices = X[np.arange(m)[:, None], np.lexsort(np.moveaxis(X[..., ::-1], -1, 0))]
    flat = vertices.reshape(m, d * gdim)
    order = np.lexsort(flat.T[::-1])
    rank = np.empty(m, dtype=np.int64)
    rank[order] = np.arange(m)
    return rank


def owners(imap: Any, comm: MPI.Comm) -> np.ndarray:
    """The first global index of every rank's owned range (and the total), for
    ``np.searchsorted(ranges, i, side='right') - 1`` = the owner of global index i."""
    start = imap.local_range[0]
    return np.array(comm.allgather(start) + [imap.size_global], dtype=np.int64)


def global_max(comm: MPI.Comm, value: float) -> float:
    return comm.allreduce(value, op=MPI.MAX)


@dataclass
class ContactPair:
    """A (slave, master) pair of contact surfaces of one mesh's bodies, the node layout of the
    displacement, the modulus E that scales the methods' parameters, the search policy, the
    owned Dirichlet dofs (``fixed``: bool (n_owned * bs,), local unrolled dof indices, or
    None), and the search's counters (number of searches, wall time)."""

    layout: NodeLayout
    slave: Side
    master: Side
    E: float
    search_each_newton: bool = False
    fixed: np.ndarray | None = None
    #: finite-strain bodies: the couplings linearise the variation of the master normal and
    #: of the projection (:mod:`contactfx.contact.point_coupling`)
    finite_strain: bool = False
    searches: int = 0
    search_time: float = 0.0
    radius: float = field(default=0.0)
    #: (m, 3) E, lambda, mu of the cell of each slave / master facet (set by the problem)
    slave_lame: np.ndarray | None = None
    master_lame: np.ndarray | None = None
    #: (m,) the stress model of the cell of each slave / master facet (finite-strain Nitsche:
    #: ``mechanics.piola.LINEAR``, ``NEO_HOOKEAN``, ``SVK``; None: linear), set by the problem
    slave_model: np.ndarray | None = None
    master_model: np.ndarray | None = None
    #: Coulomb friction coefficient (None: frictionless or Tresca) and the last converged
    #: displacement (a Function: the history of the slip increments), set by the problem
    mu: float | None = None
    previous: dolfinx.fem.Function | None = None
    #: Tresca friction's threshold (None: Coulomb with ``mu``, or frictionless)
    threshold: float | None = None
    #: an initial overlap removed over the load program (``contact.interference = "ramp"``):
    #: the couplings record each point's / node's gap g0 at the start and their laws take
    #: g + (1 - t) max(-g0, 0) for the gap g, t the load factor ``load`` (set by the problem)
    interference: bool = False
    load: float = 1.0
    #: the surfaces smoothed by their nodal normals (:mod:`contactfx.contact.smoothing`):
    #: the gap between the curved surfaces the facets approximate (mortar); None: decided
    #: by the coupling's first search (``smoothing = "auto"``: conforming surfaces)
    smooth: bool | None = False

    def hidden(self) -> float:
        """The fraction (1 - t) of the initial overlap still hidden at the load factor t
        (t clipped to [0, 1]); 0 without ``interference``."""
        if not self.interference:
            return 0.0
        return 1.0 - min(max(float(self.load), 0.0), 1.0)

    def search(
        self, slave: Facets, master: Facets, pairs: bool = True
    ) -> tuple[Facets, tuple[np.ndarray, np.ndarray] | None]:
        """The master facets near this rank's slave facets (from every rank: those meeting the
        rank's slave box enlarged by the largest facet of either surface) and, with ``pairs``,
        the candidate pairs (slave facet, near master facet) whose boxes, each enlarged by its
        own facet's diameter, meet: pairs up to about h_s + h_m apart, a bounded number per
        facet on graded meshes. Collective."""
        t0 = time.perf_counter()
        comm = self.layout.comm
        self.radius = global_max(comm, max(slave.diameter(), master.diameter()))
        near = gather_near(comm, master, slave, self.radius)
        found = None
        if pairs:
            tree = FacetTree(near.x, near.diameters())
            found = tree.collide(FacetTree(slave.x, slave.diameters()))
        self.searches += 1
        self.search_time += time.perf_counter() - t0
        return near, found
