"""ParaView output as a PVD time series of VTU files (``--format vtu``; the default is XDMF,
:mod:`contactfx.io.xdmf`), one dataset per load step with every field
(:mod:`contactfx.io.series`).

Per run (``name`` the scene's name) in the output folder:

- ``name.pvd``: the body. One unstructured grid per load step (time = load factor) carrying
  every field: P1 fields as point data, DG0 fields as cell data (fields of higher degree are
  interpolated to P1). Colouring by any field works at once; vectors have 3 components, so
  ``Warp By Vector`` works in 2D too.
- ``name_surface.pvd``: the contact surface alone (lines in 2D, polygons in 3D: the obstacle's
  contact facets, the two-body slave surface, a fitted interface) with the same fields at its
  nodes, for ``Plot Over Line`` / ``Plot Data`` along it.

A cracked body (``split``) is written with its crack faces as separate nodes: each cell on the
+side (H = +1) takes u + a at the interface's nodes, on the -side u - a, so that
``displacement`` is the displacement of each face and ``Warp By Vector`` opens the crack.

Under MPI the ranks send their owned cells to rank 0, which writes one serial VTU per step
(one file per step is what ParaView opens as one dataset): rank 0 holds the whole mesh and
every field of a step, which the XDMF writer avoids.
The data are inline base64 (``binary``, UInt64 headers); :func:`read_vtu` reads them back
without VTK.
"""

from __future__ import annotations

import base64
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from contactfx.io.series import FieldSeries, Split

__all__ = ["ResultsWriter", "Split", "read_pvd", "read_vtu", "VTK_CELLS"]

#: dolfinx cell name -> (VTK cell type, permutation of dolfinx's vertices into VTK's order)
VTK_CELLS = {
    "interval": (3, [0, 1]),
    "triangle": (5, [0, 1, 2]),
    "quadrilateral": (9, [0, 1, 3, 2]),
    "tetrahedron": (10, [0, 1, 2, 3]),
    "hexahedron": (12, [0, 1, 3, 2, 4, 5, 7, 6]),
}
_VTK_VERTEX = 1


class _Local:
    """One rank's share of a dataset: owned cells as global node numbers, per cell-vertex
    coordinates and point values, per cell values."""

    def __init__(self, nodes, x, point, cell):
        self.nodes, self.x, self.point, self.cell = nodes, x, point, cell


class ResultsWriter(FieldSeries):
    """Context manager writing the named P1 / DG0 fields of each load step as a PVD series of
    VTU files (see the module docstring). ``facets``: the contact surface's facets (local
    indices), or None."""

    format = "vtu"
    suffix = ".pvd"

    def __init__(
        self, out: Path, name: str, mesh, facets=None, split: Split | None = None, resume=None
    ):
        super().__init__(out, name, mesh, facets, split, resume)
        self.path = self.out / f"{name}.pvd"
        self.surface_path = None if facets is None else self.out / f"{name}_surface.pvd"
        self._steps: list[tuple[float, str, str | None]] = []

    def __enter__(self) -> ResultsWriter:
        if self.resume is not None:
            self._steps = list(self.resume["steps"])
        if self.comm.rank == 0:  # a previous run's steps would linger next to the new ones
            self.out.mkdir(parents=True, exist_ok=True)
            keep = {f for step in self._steps for f in step[1:] if f is not None}
            for pattern in ("_[0-9][0-9][0-9][0-9].vtu", "_surface_[0-9][0-9][0-9][0-9].vtu"):
                for old in self.out.glob(self.name + pattern):
                    if old.name not in keep:
                        old.unlink()
            if self._steps:
                self._index()
        return self

    def state(self) -> dict:
        return {"steps": list(self._steps)}

    def __exit__(self, *exc) -> None:
        pass

    def write(self, t: float, functions) -> None:
        """Write the fields of the load step at load factor ``t``. Collective."""
        point, cell = self.values(functions)
        point = self.split_values(point)
        step = len(self._steps) + 1
        body = f"{self.name}_{step:04d}.vtu"
        owned = np.arange(self.n_owned_cells)
        self._write(self.out / body, self.cell_name, owned, None, point, cell, True)
        surface = None
        if self.facets is not None:
            surface = f"{self.name}_surface_{step:04d}.vtu"
            cells, local = self.surface_cells()
            self._write(self.out / surface, self.facet_name, cells, local, point, cell, False)
        self._steps.append((t, body, surface))
        if self.comm.rank == 0:
            self._index()

    def _index(self) -> None:
        _write_pvd(self.path, [(t, b) for t, b, _ in self._steps])
        if self.surface_path is not None:
            _write_pvd(self.surface_path, [(t, s) for t, _, s in self._steps])

    def _write(self, path, cell_name, cells, local, point, cell, split) -> None:
        """Gather the cells' data on rank 0 and write one VTU. ``local``: the vertices of
        each cell to keep (a facet of it), all when None."""
        qd, nodes = self.cell_nodes(cells, local, split)
        if local is None:
            local = np.broadcast_to(
                np.arange(self.q_dofs.shape[1]), (len(cells), self.q_dofs.shape[1])
            )
        rows = np.repeat(cells, local.shape[1]).reshape(local.shape)
        mine = _Local(
            nodes,
            self.q_x[qd],
            {k: v[rows, local] for k, v in point.items()},
            {k: v[cells] for k, v in cell.items()},
        )
        parts = self.comm.gather(mine, root=0)
        if self.comm.rank != 0:
            return
        nodes = np.concatenate([p.nodes for p in parts])
        used, inverse = np.unique(nodes, return_inverse=True)
        conn = inverse.reshape(nodes.shape)
        npts = len(used)
        x = np.zeros((npts, 3))
        x[conn.ravel()] = np.concatenate([p.x.reshape(-1, 3) for p in parts])
        pdata = {}
        for k in point:
            vals = np.concatenate([p.point[k] for p in parts])
            a = np.zeros((npts, vals.shape[-1]))
            a[conn.ravel()] = vals.reshape(-1, vals.shape[-1])
            pdata[k] = a
        cdata = {k: np.concatenate([p.cell[k] for p in parts]) for k in cell}
        write_vtu(path, x, conn, cell_name, pdata, cdata)


# -- VTK XML ---------------------------------------------------------------------------------
def _b64(a: np.ndarray) -> str:
    data = np.ascontiguousarray(a).tobytes()
    return base64.b64encode(np.uint64(len(data)).tobytes() + data).decode("ascii")


def _array(parent, name: str, a: np.ndarray, components: int = 1) -> None:
    types = {
        np.dtype(np.float64): "Float64",
        np.dtype(np.int64): "Int64",
        np.dtype(np.uint8): "UInt8",
    }
    e = ET.SubElement(parent, "DataArray", type=types[a.dtype], Name=name, format="binary")
    if components > 1:
        e.set("NumberOfComponents", str(components))
    e.text = _b64(a)


def write_vtu(
    path: Path, x: np.ndarray, conn: np.ndarray, cell_name: str, point: dict, cell: dict
) -> None:
    """One unstructured grid: points x (n, 3), cells conn (m, k) of dolfinx's ``cell_name``
    (``point`` for vertex cells), point and cell data (n or m rows, 1 or 3 components)."""
    if cell_name == "point":
        vtk_type, perm = _VTK_VERTEX, [0]
    else:
        vtk_type, perm = VTK_CELLS[cell_name]
    conn = np.asarray(conn, dtype=np.int64)[:, perm] if len(conn) else conn.astype(np.int64)
    root = ET.Element(
        "VTKFile",
        type="UnstructuredGrid",
        version="1.0",
        byte_order="LittleEndian",
        header_type="UInt64",
    )
    piece = ET.SubElement(
        ET.SubElement(root, "UnstructuredGrid"),
        "Piece",
        NumberOfPoints=str(len(x)),
        NumberOfCells=str(len(conn)),
    )
    _array(ET.SubElement(piece, "Points"), "Points", np.asarray(x, dtype=np.float64), 3)
    cells = ET.SubElement(piece, "Cells")
    k = conn.shape[1] if conn.ndim == 2 else 0
    _array(cells, "connectivity", conn.ravel())
    _array(cells, "offsets", np.arange(1, len(conn) + 1, dtype=np.int64) * k)
    _array(cells, "types", np.full(len(conn), vtk_type, dtype=np.uint8))
    for tag, data in (("PointData", point), ("CellData", cell)):
        e = ET.SubElement(piece, tag)
        for name, a in data.items():
            a = np.asarray(a, dtype=np.float64).reshape(len(a), -1)
            _array(e, name, a.ravel() if a.shape[1] == 1 else a, a.shape[1])
    ET.ElementTree(root).write(path, xml_declaration=True, encoding="utf-8")


def _write_pvd(path: Path, steps: list[tuple[float, str]]) -> None:
    root = ET.Element("VTKFile", type="Collection", version="1.0", byte_order="LittleEndian")
    coll = ET.SubElement(root, "Collection")
    for t, f in steps:
        ET.SubElement(coll, "DataSet", timestep=repr(float(t)), part="0", file=f)
    tmp = path.with_suffix(".pvd.tmp")
    ET.ElementTree(root).write(tmp, xml_declaration=True, encoding="utf-8")
    tmp.replace(path)


# -- reading back (tests, ``contactfx plot``) --------------------------------------------------
def read_pvd(path: Path) -> list[tuple[float, Path]]:
    """The (time, VTU path) of each step of a PVD collection."""
    path = Path(path)
    root = ET.parse(path).getroot()
    return [(float(d.get("timestep")), path.parent / d.get("file")) for d in root.iter("DataSet")]


_NUMPY = {"Float64": np.float64, "Int64": np.int64, "UInt8": np.uint8}


def _decode(e) -> np.ndarray:
    raw = base64.b64decode(e.text)
    a = np.frombuffer(raw[8:], dtype=_NUMPY[e.get("type")])
    k = int(e.get("NumberOfComponents", "1"))
    return a.reshape(-1, k) if k > 1 else a


def read_vtu(path: Path) -> dict:
    """A VTU written by :func:`write_vtu`: points, cells (m, k) in VTK order, the VTK cell
    type, point_data and cell_data (name -> array)."""
    piece = ET.parse(path).getroot().find("UnstructuredGrid/Piece")
    x = _decode(piece.find("Points/DataArray"))
    cells = {e.get("Name"): _decode(e) for e in piece.find("Cells")}
    m = len(cells["types"])
    conn = cells["connectivity"].reshape(m, -1) if m else np.zeros((0, 0), dtype=np.int64)
    data = {
        tag: {e.get("Name"): _decode(e) for e in piece.find(tag)}
        for tag in ("PointData", "CellData")
    }
    return {
        "points": x.reshape(-1, 3),
        "cells": conn,
        "type": int(cells["types"][0]) if m else 0,
        "point_data": data["PointData"],
        "cell_data": data["CellData"],
    }
