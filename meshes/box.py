"""Box [x0, x1] x [y0, y1] x [z0, z1] meshed with tetrahedra graded towards a point on its top.

The refinement centre is the point (cx, cy, z1) on the top face, e.g. the first contact point of
a spherical indenter; a quarter model passes a corner of the top face. The element size is
``h_contact`` within the distance ``refine_radius`` of that point and grows linearly with the
distance, by ``grading`` per unit distance, up to ``h_far`` (see
:func:`contactfx.meshes._build.set_graded_size`). ``h_contact == h_far`` gives a uniform mesh.
Meshing: OpenCASCADE geometry, Frontal-Delaunay surface meshes (gmsh ``Mesh.Algorithm`` 6),
Delaunay volume mesh (``Mesh.Algorithm3D`` 1), linear tetrahedra.

Physical groups: the cells are tagged :attr:`BoxCells.DOMAIN`, the six faces :class:`BoxFacets`
(every boundary facet carries exactly one tag).
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

__all__ = ["BoxCells", "BoxFacets", "box"]


class BoxCells(IntEnum):
    """Cell tags of :func:`box`."""

    DOMAIN = 1


class BoxFacets(IntEnum):
    """Facet tags of :func:`box`: the faces x = x0, x = x1, y = y0, y = y1, z = z0, z = z1."""

    XMIN = 1
    XMAX = 2
    YMIN = 3
    YMAX = 4
    ZMIN = 5
    ZMAX = 6


def box(
    model: type[gmsh.model],
    *,
    x0: float,
    x1: float,
    y0: float,
    y1: float,
    z0: float,
    z1: float,
    refine_center: tuple[float, float],
    refine_radius: float,
    h_contact: float,
    h_far: float,
    grading: float = 0.3,
) -> None:
    """Build and mesh the box [x0, x1] x [y0, y1] x [z0, z1] in ``model`` (a gmsh builder).

    ``model``: the ``gmsh.model`` namespace of an open gmsh session; ``x0``, ``x1``, ``y0``,
    ``y1``, ``z0``, ``z1``: the corners of the box (length); ``refine_center``: (cx, cy) of the
    refinement centre (cx, cy, z1) on the top face, x0 <= cx <= x1, y0 <= cy <= y1 (length);
    ``refine_radius``: the radius of the ball around the centre meshed with h_contact (length);
    ``h_contact``: the element size near the refinement centre (length); ``h_far``: the element
    size far from it, >= h_contact (length); ``grading``: the size increase per unit distance
    from the refinement ball (dimensionless).

    Raises ValueError before any gmsh call if a parameter is invalid.
    """
    if len(refine_center) != 2:
        raise ValueError(f"refine_center must be (cx, cy), got {refine_center}")
    cx, cy = refine_center
    check_finite(
        x0=x0,
        x1=x1,
        y0=y0,
        y1=y1,
        z0=z0,
        z1=z1,
        refine_radius=refine_radius,
        h_contact=h_contact,
        h_far=h_far,
        grading=grading,
        **{"refine_center[0]": cx, "refine_center[1]": cy},
    )
    check_less("x0", x0, "x1", x1)
    check_less("y0", y0, "y1", y1)
    check_less("z0", z0, "z1", z1)
    check_less_equal("x0", x0, "refine_center[0]", cx)
    check_less_equal("refine_center[0]", cx, "x1", x1)
    check_less_equal("y0", y0, "refine_center[1]", cy)
    check_less_equal("refine_center[1]", cy, "y1", y1)
    check_positive(refine_radius=refine_radius, h_contact=h_contact, h_far=h_far, grading=grading)
    check_less_equal("h_contact", h_contact, "h_far", h_far)

    model.occ.addBox(x0, y0, z0, x1 - x0, y1 - y0, z1 - z0)
    model.occ.synchronize()
    add_physical_groups(
        model,
        BoxCells.DOMAIN,
        {
            BoxFacets.XMIN: (0, x0),
            BoxFacets.XMAX: (0, x1),
            BoxFacets.YMIN: (1, y0),
            BoxFacets.YMAX: (1, y1),
            BoxFacets.ZMIN: (2, z0),
            BoxFacets.ZMAX: (2, z1),
        },
    )

    a, b, c = (matheval_number(v) for v in (cx, cy, z1))
    set_graded_size(
        model,
        f"Sqrt((x-{a})^2+(y-{b})^2+(z-{c})^2)",
        size_min=h_contact,
        size_max=h_far,
        dist_min=refine_radius,
        grading=grading,
    )
    import gmsh

    gmsh.option.setNumber("Mesh.Algorithm", 6)
    gmsh.option.setNumber("Mesh.Algorithm3D", 1)
    model.mesh.generate(3)
