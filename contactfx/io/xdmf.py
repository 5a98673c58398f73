"""XDMF time series for ParaView: one file per run, load steps as time, mesh written once."""

from __future__ import annotations

from pathlib import Path

import dolfinx
from dolfinx.io import XDMFFile

from contactfx import _compat

__all__ = ["ResultsWriter"]


class ResultsWriter:
    """Context manager writing named P1 / DG0 fields at each load step.

    Fields of higher degree are interpolated to first-order output spaces once per write
    (XDMF stores vertex or cell values).
    """

    def __init__(self, path: Path, mesh) -> None:
        self.path = Path(path)
        self.mesh = mesh
        self._file: XDMFFile | None = None
        self._out: dict[str, dolfinx.fem.Function] = {}

    def __enter__(self) -> ResultsWriter:
        self._file = XDMFFile(self.mesh.comm, str(self.path), "w")
        self._file.write_mesh(self.mesh)
        return self

    def __exit__(self, *exc) -> None:
        if self._file is not None:
            self._file.close()
            self._file = None

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

    def write(self, t: float, functions) -> None:
        assert self._file is not None, "ResultsWriter used outside its with-block"
        for f in functions:
            _compat.write_function(self._file, self._output_function(f), t)
