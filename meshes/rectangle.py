"""Rectangle [x0, x1] x [y0, y1] meshed with triangles graded towards a contact zone on its top.

The contact zone is the segment [refine_x0, refine_x1] x {y1} of the top edge, e.g. where a rigid
indenter touches an elastic block (Hertz, punch and ironing benchmarks). The element size is
``h_contact`` within the distance ``(refine_x1 - refine_x0) / 2`` of the zone and grows linearly
with the distance, by ``grading`` per unit distance, up to ``h_far`` (see
:func:`contactfx.meshes._build.set_graded_size`). ``h_contact == h_far`` gives a uniform mesh for
convergence studies. Optional horizontal ``interfaces`` y = const cut the rectangle into
layers (OpenCASCADE boolean fragment): the interface lines are mesh lines, so that no cell crosses
a material interface. Meshing: OpenCASCADE geometry, Frontal-Delaunay triangulation (gmsh
``Mesh.Algorithm`` 6), linear triangles.

Physical groups: the cells are tagged :attr:`RectangleCells.DOMAIN`, the four edges
:class:`RectangleFacets` (every boundary edge carries exactly one tag).
"""

from __future__ import annotations

from enum import IntEnum
from typing import TYPE_CHECKING

from contactfx.meshes._build import (
    add_physical_groups,
    check_finite,
    check_less,
    check_less_equal,
    check_positive,
    matheval_number,
    set_graded_size,
)

if TYPE_CHECKING:
    import gmsh

__all__ = ["RectangleCells", "RectangleFacets", "rectangle"]


class RectangleCells(IntEnum):
    """Cell tags of :func:`rectangle`."""

    DOMAIN = 1
    #: the cells above the highest interface (a layered block's top layer)
    LAYER = 2


class RectangleFacets(IntEnum):
    """Facet tags of :func:`rectangle`: the four edges."""

    BOTTOM = 1
    RIGHT = 2
    TOP = 3
    LEFT = 4


def rectangle(
    model: type[gmsh.model],
    *,
    x0: float,
    x1: float,
    y0: float,
    y1: float,
    refine_x0: float,
    refine_x1: float,
    h_contact: float,
    h_far: float,
    grading: float = 0.3,
    interfaces: tuple[float, ...] = (),
) -> None:
    """Build and mesh the rectangle [x0, x1] x [y0, y1] in ``model`` (a gmsh builder).

    ``model``: the ``gmsh.model`` namespace of an open gmsh session; ``x0``, ``x1``, ``y0``,
    ``y1``: the corners of the rectangle (length); ``refine_x0``, ``refine_x1``: the ends of the
    contact zone on the top edge y = y1, with x0 <= refine_x0 < refine_x1 <= x1 (length);
    ``h_contact``: the element size in and near the contact zone (length); ``h_far``: the
    element size far from the contact zone, >= h_contact (length); ``grading``: the size
    increase per unit distance from the contact zone (dimensionless); ``interfaces``: the
    heights y0 < y < y1 of horizontal lines across the rectangle that the mesh must resolve
    (material interfaces of a layered block; length). The cells above the highest one are the
    cell group ``layer``, the others ``domain``.

    Raises ValueError before any gmsh call if a parameter is invalid.
    """
    check_finite(
        x0=x0,
        x1=x1,
        y0=y0,
        y1=y1,
        refine_x0=refine_x0,
        refine_x1=refine_x1,
        h_contact=h_contact,
        h_far=h_far,
        grading=grading,
    )
    check_less("x0", x0, "x1", x1)
    check_less("y0", y0, "y1", y1)
    check_less_equal("x0", x0, "refine_x0", refine_x0)
    check_less("refine_x0", refine_x0, "refine_x1", refine_x1)
    check_less_equal("refine_x1", refine_x1, "x1", x1)
    check_positive(h_contact=h_contact, h_far=h_far, grading=grading)
    check_less_equal("h_contact", h_contact, "h_far", h_far)
    for y in interfaces:
        check_finite(interface=y)
        check_less("y0", y0, "interface", y)
        check_less("interface", y, "y1", y1)

    surface = model.occ.addRectangle(x0, y0, 0.0, x1 - x0, y1 - y0)
    lines = [
        (1, model.occ.addLine(model.occ.addPoint(x0, y, 0.0), model.occ.addPoint(x1, y, 0.0)))
        for y in interfaces
    ]
    if lines:
        model.occ.fragment([(2, surface)], lines)
    model.occ.synchronize()
    add_physical_groups(
        model,
        RectangleCells.DOMAIN,
        {
            RectangleFacets.BOTTOM: (1, y0),
            RectangleFacets.RIGHT: (0, x1),
            RectangleFacets.TOP: (1, y1),
            RectangleFacets.LEFT: (0, x0),
        },
    )
    if lines:
        top = max(interfaces)
        tol = 1e-6 * (y1 - y0)
        cells = [tag for _, tag in model.getEntities(2)]
        upper = [c for c in cells if model.getBoundingBox(2, c)[1] >= top - tol]
        model.removePhysicalGroups([(2, RectangleCells.DOMAIN.value)])
        for group, members in (
            (RectangleCells.DOMAIN, [c for c in cells if c not in upper]),
            (RectangleCells.LAYER, upper),
        ):
            model.addPhysicalGroup(2, members, group.value)
            model.setPhysicalName(2, group.value, group.name.lower())

    # Distance to the segment [a, b] x {y1}: (|x - a| + |x - b| - (b - a)) / 2 is the distance
    # of x to [a, b] along the x axis.
    a, b, c = (matheval_number(v) for v in (refine_x0, refine_x1, y1))
    along = f"(Fabs(x-{a})+Fabs(x-{b})-({b}-{a}))/2"
    distance = f"Sqrt(({along})^2+(y-{c})^2)"
    set_graded_size(
        model,
        distance,
        size_min=h_contact,
        size_max=h_far,
        dist_min=0.5 * (refine_x1 - refine_x0),
        grading=grading,
    )
    import gmsh

    gmsh.option.setNumber("Mesh.Algorithm", 6)
    model.mesh.generate(2)
