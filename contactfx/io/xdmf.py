"""ParaView output as XDMF3 + HDF5, written in parallel: the default (``--format xdmf``).

Per run (``name`` the scene's name) in the output folder:

- ``name.h5``: the data. ``/body/geometry`` (nodes, 3) and ``/body/topology`` (cells, k) once;
  ``/body/step_NNNN/<field>`` per load step; ``/surface/...`` likewise for the contact surface.
- ``name.xdmf``: the body. One temporal collection (time = the load factor); each step a grid
  that references the mesh and carries every field as an attribute (P1 fields at the nodes,
  DG0 fields in the cells, vectors with 3 components, the Cauchy stress as a 3 x 3 tensor),
  so that ParaView's XDMF reader gives one dataset per step and colouring by any field works
  at once (:mod:`contactfx.io.series`: the fields, and the crack faces' nodes of a split body).
- ``name_surface.xdmf``: the contact surface alone, with the same fields at its nodes.

Every rank writes its own rows of each dataset with a collective MPI-IO write (h5py built
against parallel HDF5: Debian's ``python3-h5py-mpi``): its owned nodes (a contiguous range of
global numbers), its owned cells, its owned surface facets and nodes. Nothing is gathered
on one rank, so a rank's memory and time grow with its own share of the mesh. The HDF5 file
is opened and closed for each step, and the XDMF index rewritten after it (its tail only):
a run stopped between steps leaves both readable up to the last complete step.

The rows are the nodes' global numbers, which depend on the partition; the reference
coordinates identify a node (:func:`read_xdmf` reads a step back, e.g. to sort by them).
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from mpi4py import MPI

from contactfx import _compat
from contactfx.io.series import FieldSeries, Split

__all__ = ["XdmfWriter", "read_xdmf", "h5py_mpi", "XDMF_CELLS"]

#: dolfinx cell name -> (XDMF topology type, permutation of dolfinx's vertices into its order)
XDMF_CELLS = {
    "point": ("Polyvertex", [0]),
    "interval": ("Polyline", [0, 1]),
    "triangle": ("Triangle", [0, 1, 2]),
    "quadrilateral": ("Quadrilateral", [0, 1, 3, 2]),
    "tetrahedron": ("Tetrahedron", [0, 1, 2, 3]),
    "hexahedron": ("Hexahedron", [0, 1, 3, 2, 4, 5, 7, 6]),
}
_ATTRIBUTE = {1: "Scalar", 3: "Vector", 6: "Tensor6", 9: "Tensor"}
_TAIL = b"    </Grid>\n  </Domain>\n</Xdmf>\n"


def h5py_mpi():
    """h5py built against parallel HDF5. Debian ships it as ``python3-h5py-mpi``, the module
    ``h5py._debian_h5py_mpi``; Debian 12's ``h5py`` wrapper (of python3-h5py-serial) would
    pick it only under mpirun unless ``H5PY_ALWAYS_USE_MPI`` is set, and the serial build
    would load a second libhdf5 beside dolfinx's parallel one; Debian 13's python3-h5py-mpi
    comes without the wrapper. Elsewhere: an ``h5py`` built with MPI."""
    os.environ.setdefault("H5PY_ALWAYS_USE_MPI", "1")
    try:
        from h5py import _debian_h5py_mpi as h5py
    except ImportError:
        try:
            import h5py
        except ImportError:
            h5py = None
    if h5py is None or not getattr(h5py, "get_config", None) or not h5py.get_config().mpi:
        raise RuntimeError(
            "XDMF output needs h5py with MPI (Debian: apt-get install python3-h5py-mpi); "
            "or write VTU with --format vtu"
        )
    return h5py


def _write_rows(h5py, group, name: str, size: int, pieces, dtype) -> None:
    """Create ``group[name]`` of ``size`` rows (collective) and write each rank's pieces
    (start row, values), one collective write per piece: every rank passes the same number
    of pieces; a rank with an empty one takes part with an empty selection (h5py's slicing
    skips an empty write, and the other ranks would wait for it)."""
    shape = (size,) + np.shape(pieces[0][1])[1:]
    dset = group.create_dataset(name, shape=shape, dtype=dtype)
    dxpl = h5py.h5p.create(h5py.h5p.DATASET_XFER)
    dxpl.set_dxpl_mpio(h5py.h5fd.MPIO_COLLECTIVE)
    for start, values in pieces:
        values = np.ascontiguousarray(values, dtype=dtype)
        fspace = dset.id.get_space()
        if len(values):
            fspace.select_hyperslab((start,) + (0,) * (len(shape) - 1), values.shape)
            mspace = h5py.h5s.create_simple(values.shape)
        else:
            fspace.select_none()
            mspace = h5py.h5s.create_simple((1,))
            mspace.select_none()
            values = np.zeros(1, dtype=dtype)
        dset.id.write(mspace, fspace, values, dxpl=dxpl)


def _exscan(comm, n: int) -> int:
    start = comm.exscan(n, op=MPI.SUM)
    return 0 if start is None else int(start)


@dataclass
class _Layout:
    """The rows of one dataset (body or surface) this rank writes. Nodes: the local Q1 dofs
    ``node_dofs``, the first ``n_owned`` to rows from ``node_start``, the rest (the split
    body's duplicates of the owned interface nodes) to rows from ``dup_start`` (None: no
    split). Cells: the local ``cells`` (their nodes ``conn`` as rows) to rows from
    ``cell_start``."""

    n_nodes: int
    node_start: int
    node_dofs: np.ndarray
    n_owned: int
    dup_start: int | None
    n_cells: int
    cell_start: int
    cells: np.ndarray
    conn: np.ndarray

    def node_pieces(self, values: np.ndarray, duplicates: np.ndarray | None = None) -> list:
        """The (start, rows) of a node field from its values at the local Q1 dofs (the
        duplicates' from ``duplicates``, default the same)."""
        own = values[self.node_dofs[: self.n_owned]]
        if self.dup_start is None:
            return [(self.node_start, own)]
        dup = (values if duplicates is None else duplicates)[self.node_dofs[self.n_owned :]]
        return [(self.node_start, own), (self.dup_start, dup)]


class XdmfWriter(FieldSeries):
    """Context manager writing the named P1 / DG0 fields of each load step as XDMF3 + HDF5
    (see the module docstring). ``facets``: the contact surface's facets (local indices), or
    None. Collective: every rank constructs it and calls ``write``."""

    format = "xdmf"
    suffix = ".xdmf"

    def __init__(
        self, out: Path, name: str, mesh, facets=None, split: Split | None = None, resume=None
    ):
        super().__init__(out, name, mesh, facets, split, resume)
        self.h5py = h5py_mpi()
        self.path = self.out / f"{name}.xdmf"
        self.surface_path = None if facets is None else self.out / f"{name}_surface.xdmf"
        self.h5 = self.out / f"{name}.h5"
        #: each step's (time, name, point field sizes, cell field sizes): the index's grids
        self.grids: list[tuple[float, str, dict, dict]] = []
        imap = self.Q1.dofmap.index_map
        self.r0 = int(imap.local_range[0])
        self.r1 = self.r0 + imap.size_local
        self.body = self._body_layout()
        self.surface = None if facets is None else self._surface_layout()

    # -- layout ----------------------------------------------------------------------------
    def _body_layout(self) -> _Layout:
        """The owned nodes (rows: their global numbers), then the owned interface nodes'
        duplicates (rows n_global + their position among the interface's nodes)."""
        r0, r1 = self.r0, self.r1
        node_dofs = np.arange(r1 - r0, dtype=np.int32)
        n_nodes, dup_start = self.n_global, None
        if self.split_nodes is not None:
            n_nodes += len(self.split_nodes)
            d0, d1 = np.searchsorted(self.split_nodes, [r0, r1])
            dups = (self.split_nodes[d0:d1] - r0).astype(np.int32)
            node_dofs = np.concatenate([node_dofs, dups])
            dup_start = self.n_global + int(d0)
        tdim = self.mesh.topology.dim
        cmap = self.mesh.topology.index_map(tdim)
        cells = np.arange(self.n_owned_cells, dtype=np.int32)
        _, conn = self.cell_nodes(cells)
        return _Layout(
            n_nodes, r0, node_dofs, r1 - r0, dup_start,
            cmap.size_global, int(cmap.local_range[0]), cells, conn,
        )  # fmt: skip

    def _surface_layout(self) -> _Layout:
        """The surface's nodes numbered by the rank of their global number among all the
        surface's nodes (a rank holds its owned ones: a contiguous range); its facets by rank
        and then local order."""
        cells, local = self.surface_cells()
        _, nodes = self.cell_nodes(cells, local, split=False)
        mine = np.unique(nodes)
        every = np.unique(np.concatenate(self.comm.allgather(mine)))
        s0, s1 = np.searchsorted(every, [self.r0, self.r1])
        node_dofs = (every[s0:s1] - self.r0).astype(np.int32)
        return _Layout(
            len(every), int(s0), node_dofs, len(node_dofs), None,
            self.comm.allreduce(len(cells), op=MPI.SUM), _exscan(self.comm, len(cells)),
            cells, np.searchsorted(every, nodes),
        )  # fmt: skip

    # -- files -----------------------------------------------------------------------------
    def __enter__(self) -> XdmfWriter:
        if self.resume is not None:
            return self._resume(self.resume)
        if self.comm.rank == 0:  # a previous run's series would be appended to
            self.out.mkdir(parents=True, exist_ok=True)
            for old in (self.path, self.surface_path, self.h5):
                if old is not None and old.exists():
                    old.unlink()
        self.comm.barrier()
        with self._open("w") as f:
            self._mesh(f.create_group("body"), self.body, self.cell_name)
            if self.surface is not None:
                self._mesh(f.create_group("surface"), self.surface, self.facet_name)
        if self.comm.rank == 0:
            for path in (self.path, self.surface_path):
                if path is not None:
                    path.write_bytes(_HEAD + _TAIL)
        return self

    def __exit__(self, *exc) -> None:
        pass

    def state(self) -> dict:
        return {"grids": list(self.grids)}

    def _resume(self, state: dict) -> XdmfWriter:
        """Continue the series after the checkpoint's steps: later steps' datasets (written
        before the run stopped) are deleted, the indexes rewritten with the kept steps."""
        self.grids = list(state["grids"])
        kept = {name for _, name, _, _ in self.grids}
        with self._open("a") as f:
            for group in ("body", "surface"):
                if group in f:
                    for name in sorted(set(f[group]) - {"geometry", "topology"} - kept):
                        del f[group][name]  # collective: the same on every rank
        if self.comm.rank == 0:
            for path, group, layout, cell_name in self._indexes():
                text = "".join(
                    _grid(self.h5.name, group, layout, cell_name, *g) for g in self.grids
                )
                path.write_bytes(_HEAD + text.encode() + _TAIL)
        self.comm.barrier()
        return self

    def _indexes(self) -> list:
        """(XDMF file, HDF5 group, layout, cell name) of the body and the surface."""
        out = [(self.path, "body", self.body, self.cell_name)]
        if self.surface_path is not None:
            out.append((self.surface_path, "surface", self.surface, self.facet_name))
        return out

    def node_coordinates(self) -> np.ndarray:
        """(local Q1 dofs, 3): the mesh's own coordinates of the nodes (the same bits on
        every partition; the dofs' tabulated coordinates differ at round-off)."""
        nv = self.q_dofs.shape[1]
        x = np.zeros((len(self.q_global), 3))
        x[self.q_dofs.ravel()] = self.mesh.geometry.x[
            _compat.geometry_nodes(self.mesh)[:, :nv]
        ].reshape(-1, 3)
        return x

    def _open(self, mode: str):
        return self.h5py.File(self.h5, mode, driver="mpio", comm=self.comm)

    def _mesh(self, group, layout: _Layout, cell_name: str) -> None:
        x = self.node_coordinates()
        _write_rows(self.h5py, group, "geometry", layout.n_nodes, layout.node_pieces(x), "f8")
        perm = XDMF_CELLS[cell_name][1]
        conn = layout.conn.reshape(-1, len(perm))[:, perm]
        pieces = [(layout.cell_start, conn)]
        _write_rows(self.h5py, group, "topology", layout.n_cells, pieces, "i8")

    # -- steps -----------------------------------------------------------------------------
    def nodal(self, point: dict) -> tuple[dict, dict]:
        """The P1 fields at the local Q1 dofs (incl. ghosts) from their per (cell, vertex)
        values, and the values of the split body's duplicate nodes: the split field is
        u + H a from each cell, at the interface's nodes u + a (the +side's, the original
        nodes) and u - a (the duplicates)."""
        n = len(self.q_global)
        flat = self.q_dofs.ravel()

        def scatter(v):
            a = np.zeros((n, v.shape[-1]))
            a[flat] = v.reshape(-1, v.shape[-1])
            return a

        out = {k: scatter(v) for k, v in point.items()}
        minus = dict(out)
        s = self.split
        if s is not None and s.field in out and s.jump in out:
            u, jump = out[s.field], out[s.jump]
            total = scatter(self.split_values(point)[s.field])
            on = np.isin(self.q_global, self.split_nodes)
            total[on] = u[on] + jump[on]
            out[s.field], minus[s.field] = total, u - jump
        return out, minus

    def write(self, t: float, functions) -> None:
        """Write the fields of the load step at load factor ``t``. Collective."""
        point, cell = self.values(functions, vertex_dofs=True)
        nodal, minus = self.nodal(point)
        step = f"step_{len(self.grids) + 1:04d}"
        with self._open("a") as f:
            self._step(f["body"].create_group(step), self.body, nodal, minus, cell)
            if self.surface is not None:
                self._step(f["surface"].create_group(step), self.surface, nodal, nodal, cell)
        point_sizes = {k: v.shape[-1] for k, v in point.items()}
        cell_sizes = {k: v.shape[-1] for k, v in cell.items()}
        self.grids.append((float(t), step, point_sizes, cell_sizes))
        if self.comm.rank == 0:
            for path, group, layout, cell_name in self._indexes():
                _append(path, _grid(self.h5.name, group, layout, cell_name, *self.grids[-1]))

    def _step(self, group, layout: _Layout, nodal: dict, minus: dict, cell: dict) -> None:
        """One step's fields (scalars as 1D datasets, as the index declares them)."""
        for k, v in nodal.items():
            pieces = layout.node_pieces(_flat(v), _flat(minus[k]))
            _write_rows(self.h5py, group, k, layout.n_nodes, pieces, "f8")
        for k, v in cell.items():
            pieces = [(layout.cell_start, _flat(v)[layout.cells])]
            _write_rows(self.h5py, group, k, layout.n_cells, pieces, "f8")


def _flat(v: np.ndarray) -> np.ndarray:
    return v[:, 0] if v.shape[-1] == 1 else v


def _grid(h5: str, group: str, layout: _Layout, cell_name: str, t, step, point, cell) -> str:
    """One step's grid of the XDMF index: the mesh's datasets and every field's."""
    kind, perm = XDMF_CELLS[cell_name]

    def item(dims: str, number: str, ref: str) -> str:
        return (
            f'          <DataItem Dimensions="{dims}" NumberType="{number}" Precision="8" '
            f'Format="HDF">{h5}:/{group}/{ref}</DataItem>'
        )

    nodes_per = f' NodesPerElement="{len(perm)}"' if kind.startswith("Poly") else ""
    lines = [
        f'      <Grid Name="{step}" GridType="Uniform">',
        f'        <Time Value="{float(t)!r}"/>',
        f'        <Topology TopologyType="{kind}" NumberOfElements="{layout.n_cells}"{nodes_per}>',
        item(f"{layout.n_cells} {len(perm)}", "Int", "topology"),
        "        </Topology>",
        '        <Geometry GeometryType="XYZ">',
        item(f"{layout.n_nodes} 3", "Float", "geometry"),
        "        </Geometry>",
    ]
    for centre, fields, n in (("Node", point, layout.n_nodes), ("Cell", cell, layout.n_cells)):
        for k, c in fields.items():
            dims = f"{n}" if c == 1 else f"{n} {c}"
            lines += [
                f'        <Attribute Name="{k}" AttributeType="{_ATTRIBUTE.get(c, "Matrix")}" '
                f'Center="{centre}">',
                item(dims, "Float", f"{step}/{k}"),
                "        </Attribute>",
            ]
    lines.append("      </Grid>")
    return "\n".join(lines) + "\n"


def _append(path: Path, grid: str) -> None:
    """Add a grid to the XDMF index: its closing tail is replaced by the grid and the tail,
    so that the file is well formed after each step."""
    with open(path, "r+b") as fh:
        fh.seek(-len(_TAIL), os.SEEK_END)
        fh.write(grid.encode() + _TAIL)
        fh.truncate()


_HEAD = (
    b'<?xml version="1.0"?>\n'
    b'<Xdmf Version="3.0" xmlns:xi="http://www.w3.org/2001/XInclude">\n'
    b"  <Domain>\n"
    b'    <Grid Name="steps" GridType="Collection" CollectionType="Temporal">\n'
)


# -- reading back (tests, ``contactfx plot``) --------------------------------------------------
def read_xdmf(path: Path, step: int = -1) -> dict:
    """One step of an XDMF series written by :class:`XdmfWriter` (serial h5py or the MPI
    build on one rank): the times of every step, points (n, 3), cells (m, k) in XDMF's
    order, the topology type, point_data and cell_data (name -> array)."""
    h5py = h5py_mpi()
    path = Path(path)
    grids = ET.parse(path).getroot().findall("Domain/Grid/Grid")
    if not grids:
        raise ValueError(f"{path.name} holds no step")
    times = [float(g.find("Time").get("Value")) for g in grids]
    grid = grids[step]

    def load(item):
        name, ref = item.text.strip().split(":", 1)
        with h5py.File(path.parent / name, "r", driver="mpio", comm=MPI.COMM_SELF) as f:
            return f[ref][...]

    topo = grid.find("Topology")
    out = {
        "times": times,
        "time": times[step],
        "points": load(grid.find("Geometry/DataItem")),
        "cells": load(topo.find("DataItem")),
        "type": topo.get("TopologyType"),
        "point_data": {},
        "cell_data": {},
    }
    for a in grid.findall("Attribute"):
        key = "point_data" if a.get("Center") == "Node" else "cell_data"
        out[key][a.get("Name")] = load(a.find("DataItem"))
    return out
