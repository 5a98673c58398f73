"""The interval [x0, x0 + length] with ``cells`` equal elements (a 1D bar)."""

from __future__ import annotations

from enum import IntEnum
from typing import TYPE_CHECKING

from contactfx.meshes._build import check_finite, check_positive

if TYPE_CHECKING:
    import gmsh

__all__ = ["IntervalCells", "IntervalFacets", "interval"]


class IntervalCells(IntEnum):
    """Cell tag of the bar."""

    BAR = 1


class IntervalFacets(IntEnum):
    """Facet (end point) tags."""

    LEFT = 1
    RIGHT = 2


def interval(model: type[gmsh.model], *, length: float, cells: int, x0: float = 0.0) -> None:
    """Build and mesh [x0, x0 + length] with ``cells`` elements of equal size in ``model``;
    the end points are the physical groups ``left`` and ``right``, the line ``bar``."""
    check_finite(length=length, x0=x0)
    check_positive(length=length, cells=cells)
    left = model.geo.addPoint(x0, 0.0, 0.0)
    right = model.geo.addPoint(x0 + length, 0.0, 0.0)
    line = model.geo.addLine(left, right)
    model.geo.mesh.setTransfiniteCurve(line, int(cells) + 1)
    model.geo.synchronize()
    model.addPhysicalGroup(1, [line], IntervalCells.BAR.value)
    model.setPhysicalName(1, IntervalCells.BAR.value, "bar")
    for point, tag in ((left, IntervalFacets.LEFT), (right, IntervalFacets.RIGHT)):
        model.addPhysicalGroup(0, [point], tag.value)
        model.setPhysicalName(0, tag.value, tag.name.lower())
    model.mesh.generate(1)
