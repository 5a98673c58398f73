"""A disc of radius R whose lowest point is the origin, meshed with triangles graded towards it.

The disc's centre is (0, R). The element size is ``h_contact`` within ``contact_width / 2`` of
the lowest point and grows linearly with the distance, by ``grading`` per unit distance, up to
``h_far`` (:func:`contactfx.meshes._build.set_graded_size`): a disc that falls or is pressed
onto a plane below it. Physical groups: the cells ``disc``, the boundary's lower half
``lower`` (the contact side) and upper half ``upper``.
"""

from __future__ import annotations

from enum import IntEnum
from typing import TYPE_CHECKING

from contactfx.meshes._build import (
    check_finite,
    check_less_equal,
    check_positive,
    set_graded_size,
)

if TYPE_CHECKING:
    import gmsh

__all__ = ["DiscCells", "DiscFacets", "disc"]


class DiscCells(IntEnum):
    """Cell tag of :func:`disc`."""

    DISC = 1


class DiscFacets(IntEnum):
    """Facet tags of :func:`disc`: the boundary's lower and upper halves."""

    LOWER = 1
    UPPER = 2


def disc(
    model: type[gmsh.model],
    *,
    radius: float,
    h_contact: float,
    h_far: float,
    contact_width: float,
    grading: float = 0.3,
) -> None:
    """Build and mesh the disc of ``radius`` centred at (0, radius) in ``model`` (a gmsh
    builder): ``h_contact`` the element size within ``contact_width / 2`` of the lowest point
    (length), ``h_far`` the size far from it (>= h_contact), ``grading`` the size increase per
    unit distance. Raises ValueError before any gmsh call if a parameter is invalid."""
    check_finite(radius=radius, h_contact=h_contact, h_far=h_far, contact_width=contact_width)
    check_positive(radius=radius, h_contact=h_contact, h_far=h_far, contact_width=contact_width)
    check_less_equal("h_contact", h_contact, "h_far", h_far)
    occ = model.occ
    R = radius
    centre = occ.addPoint(0.0, R, 0.0)
    left, bottom = occ.addPoint(-R, R, 0.0), occ.addPoint(0.0, 0.0, 0.0)
    right, top = occ.addPoint(R, R, 0.0), occ.addPoint(0.0, 2.0 * R, 0.0)
    lower = [occ.addCircleArc(left, centre, bottom), occ.addCircleArc(bottom, centre, right)]
    upper = [occ.addCircleArc(right, centre, top), occ.addCircleArc(top, centre, left)]
    surface = occ.addPlaneSurface([occ.addCurveLoop(lower + upper)])
    occ.synchronize()
    model.addPhysicalGroup(2, [surface], DiscCells.DISC.value)
    model.setPhysicalName(2, DiscCells.DISC.value, "disc")
    for group, curves in ((DiscFacets.LOWER, lower), (DiscFacets.UPPER, upper)):
        model.addPhysicalGroup(1, curves, group.value)
        model.setPhysicalName(1, group.value, group.name.lower())
    set_graded_size(
        model,
        "Sqrt(x^2+y^2)",
        size_min=h_contact,
        size_max=h_far,
        dist_min=0.5 * contact_width,
        grading=grading,
    )
    import gmsh

    gmsh.option.setNumber("Mesh.Algorithm", 6)
    model.mesh.generate(2)
