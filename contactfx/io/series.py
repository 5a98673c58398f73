"""The fields of a run's load steps as ParaView datasets: what the VTU (:mod:`contactfx.io.vtk`)
and XDMF (:mod:`contactfx.io.xdmf`) writers share.

Each load step of a run is one dataset of the body carrying every field: P1 fields as point
data, DG0 fields as cell data (fields of higher degree are interpolated to P1), vectors with
3 components (``Warp By Vector`` works in 2D too). Beside it, the contact surface alone
(lines in 2D, polygons in 3D) with the same fields at its nodes.

The body's nodes are the P1 dofs numbered by their global index. A cracked body (``split``)
has its crack faces as separate nodes: the interface's nodes once more, numbered after the
others in the order of their global index; a cell on the -side (H = -1) uses these, so
that ``displacement`` (u + H a) is each face's own displacement and ``Warp By Vector`` opens
the crack.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import dolfinx
import numpy as np

from contactfx import _compat

__all__ = ["FieldSeries", "Split", "FACET", "pad"]

#: dolfinx cell name -> the name of its facets
FACET = {
    "interval": "point",
    "triangle": "interval",
    "quadrilateral": "interval",
    "tetrahedron": "triangle",
    "hexahedron": "quadrilateral",
}
_FACET_VERTICES = {"point": 1, "interval": 2, "triangle": 3, "quadrilateral": 4}


@dataclass
class Split:
    """Duplicate the nodes of ``facets`` (a fitted interface) by the side of each cell: the
    DG0 sign ``side`` (+1 / -1). The vector field ``field`` is written as field + side * jump
    (the enriched displacement u + H a); a cell of the surface dataset takes the +side."""

    side: dolfinx.fem.Function
    facets: np.ndarray
    field: str = "displacement"
    jump: str = "enrichment"


class FieldSeries:
    """The body and surface of one run on this rank: the mesh's P1 nodes and their global
    numbers, the split of the crack faces, the surface's facets, and each step's values per
    (cell, vertex) and per cell. ``facets``: the contact surface's facets (local indices), or
    None. The writers add the files (``path``, ``surface_path``), ``write``, and ``state`` /
    ``resume``: what a checkpoint keeps of the series, and a series continued from it (the
    steps after the checkpoint's dropped)."""

    path: Path
    surface_path: Path | None

    def __init__(
        self, out: Path, name: str, mesh, facets=None, split: Split | None = None, resume=None
    ):
        self.out, self.name, self.mesh = Path(out), name, mesh
        self.resume = resume
        self.comm = mesh.comm
        self.facets = None if facets is None else np.asarray(facets, dtype=np.int32)
        self.split = split
        self._out: dict[str, dolfinx.fem.Function] = {}
        tdim = mesh.topology.dim
        self.cell_name = mesh.topology.cell_type.name
        if self.cell_name not in FACET:
            raise ValueError(f"no ParaView output for {self.cell_name} cells")
        self.facet_name = FACET[self.cell_name]
        mesh.topology.create_connectivity(tdim, 0)
        mesh.topology.create_connectivity(tdim - 1, 0)
        mesh.topology.create_connectivity(tdim - 1, tdim)
        self.Q1 = _compat.function_space(mesh, "Lagrange", 1)
        imap = self.Q1.dofmap.index_map
        self.n_global = imap.size_global
        self.q_dofs = _compat.cell_dofs(self.Q1)  # (cells incl. ghosts, vertices)
        local = np.arange(imap.size_local + imap.num_ghosts, dtype=np.int32)
        self.q_global = imap.local_to_global(local).astype(np.int64)
        self.q_x = _compat.dof_coordinates(self.Q1)
        self.n_owned_cells = mesh.topology.index_map(tdim).size_local
        self.split_nodes = None
        self.side = None  # H on the local cells (incl. ghosts) of a split body
        if split is not None:  # the global numbers of the interface's nodes, on every rank
            qd = _cell_facet_vertices(mesh, split.facets, self.q_dofs)
            mine = np.unique(self.q_global[qd]) if len(qd) else np.zeros(0, np.int64)
            self.split_nodes = np.unique(np.concatenate(self.comm.allgather(mine)))
            s = split.side
            self.side = s.x.array[_compat.cell_dofs(s.function_space)[:, 0]]
        self._surface: tuple[np.ndarray, np.ndarray] | None = None

    # -- fields ----------------------------------------------------------------------------
    def _output_function(self, f: dolfinx.fem.Function) -> dolfinx.fem.Function:
        if _compat.element_degree(f.function_space) <= 1:
            return f
        if f.name not in self._out:
            shape = f.ufl_shape
            V1 = _compat.function_space(self.mesh, "Lagrange", 1, shape if shape else None)
            self._out[f.name] = dolfinx.fem.Function(V1, name=f.name)
        g = self._out[f.name]
        g.interpolate(f)
        return g

    def values(self, functions, vertex_dofs: bool = False) -> tuple[dict, dict]:
        """Per (cell, vertex) values of the P1 fields (cells incl. ghosts, vertices, 3 or 1)
        and per cell values of the DG0 fields, vectors padded to 3 components; the split
        field is still u (:meth:`split_values` adds H a). A field of higher degree is
        interpolated to P1, or with ``vertex_dofs`` (Lagrange) its values at the vertices
        are its vertex dofs, the first of each cell's dofs: no round-off, which differs with
        the partition."""
        point, cell = {}, {}
        nv = self.q_dofs.shape[1]
        for f in functions:
            if vertex_dofs and _compat.element_degree(f.function_space) > 1:
                f.x.scatter_forward()
                bs = f.function_space.dofmap.index_map_bs
                dofs = _compat.cell_dofs(f.function_space)[:, :nv]
                point[f.name] = pad(f.x.array.reshape(-1, bs)[dofs])
                continue
            g = self._output_function(f)
            g.x.scatter_forward()
            V = g.function_space
            bs = V.dofmap.index_map_bs
            dofs = _compat.cell_dofs(V)
            arr = g.x.array.reshape(-1, bs)
            if _compat.element_degree(V) == 0:
                cell[g.name] = pad(arr[dofs[:, 0]])
            else:
                point[g.name] = pad(arr[dofs])  # (cells, vertices, bs)
        return point, cell

    def split_values(self, point: dict) -> dict:
        """``point`` with the split field of each cell u + H a (H the cell's side)."""
        s = self.split
        if s is None or s.field not in point or s.jump not in point:
            return point
        assert self.side is not None
        return {**point, s.field: point[s.field] + self.side[:, None, None] * point[s.jump]}

    # -- topology --------------------------------------------------------------------------
    def cell_nodes(self, cells, local=None, split: bool = True) -> tuple[np.ndarray, np.ndarray]:
        """(the local Q1 dofs, the global node numbers) of the vertices ``local`` of each of
        ``cells`` (all vertices when None); with ``split`` the -side cells' interface nodes
        are their duplicates (n_global + their position in ``split_nodes``)."""
        if local is None:
            local = np.broadcast_to(
                np.arange(self.q_dofs.shape[1]), (len(cells), self.q_dofs.shape[1])
            )
        rows = np.repeat(cells, local.shape[1]).reshape(local.shape)
        qd = self.q_dofs[rows, local]
        nodes = self.q_global[qd]
        if split and self.side is not None and self.split_nodes is not None:
            minus = (self.side[cells] < 0)[:, None] & np.isin(nodes, self.split_nodes)
            dup = self.n_global + np.searchsorted(self.split_nodes, nodes)
            nodes = np.where(minus, dup, nodes)
        return qd, nodes

    def surface_cells(self) -> tuple[np.ndarray, np.ndarray]:
        """For each owned contact facet: a local cell holding it (the +side's on a split
        interface) and the positions of the facet's vertices in that cell (computed once)."""
        if self._surface is not None:
            return self._surface
        assert self.facets is not None
        tdim = self.mesh.topology.dim
        f2c = self.mesh.topology.connectivity(tdim - 1, tdim)
        f2v = self.mesh.topology.connectivity(tdim - 1, 0)
        c2v = self.mesh.topology.connectivity(tdim, 0)
        n_owned = self.mesh.topology.index_map(tdim - 1).size_local
        side = self.side
        cells, local = [], []
        for f in self.facets[self.facets < n_owned]:
            cs = f2c.links(f)
            c = cs[0]
            if side is not None and len(cs) > 1 and side[cs[1]] > side[c]:
                c = cs[1]
            verts = list(c2v.links(c))
            cells.append(c)
            local.append([verts.index(v) for v in f2v.links(f)])
        nv = _FACET_VERTICES[self.facet_name]
        self._surface = (
            np.array(cells, dtype=np.int32),
            np.array(local, dtype=np.int32).reshape(-1, nv),
        )
        return self._surface


def pad(vals: np.ndarray) -> np.ndarray:
    """Vectors of 2 components padded to 3 (ParaView's vectors); scalars keep 1."""
    if vals.shape[-1] == 2:
        zeros = np.zeros(vals.shape[:-1] + (1,))
        return np.concatenate([vals, zeros], axis=-1)
    return vals


def _cell_facet_vertices(mesh, facets, q_dofs) -> np.ndarray:
    """The local Q1 dofs of the vertices of ``facets`` (through a cell holding each)."""
    tdim = mesh.topology.dim
    f2c = mesh.topology.connectivity(tdim - 1, tdim)
    f2v = mesh.topology.connectivity(tdim - 1, 0)
    c2v = mesh.topology.connectivity(tdim, 0)
    out = []
    for f in np.asarray(facets, dtype=np.int32):
        c = f2c.links(f)[0]
        verts = list(c2v.links(c))
        out.extend(q_dofs[c, verts.index(v)] for v in f2v.links(f))
    return np.array(out, dtype=np.int32)
