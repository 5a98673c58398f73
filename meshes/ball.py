"""A quarter of a ball of radius R whose lowest point is the origin, meshed with tetrahedra graded
towards it: the quarter model (x >= 0, y >= 0) of a sphere that falls or is pressed onto a plane
below it.

The ball's centre is (0, 0, R). The element size is ``h_contact`` within ``refine_radius`` of the
lowest point and grows linearly with the distance, by ``grading`` per unit distance, up to
``h_far`` (:func:`contactfx.meshes._build.set_graded_size`). The spherical surface is split at
the height ``cap`` into the contact side (the cap z <= cap, tag ``lower``) and the rest
(``upper``), so that a mass redistributed away from the contact nodes touches the cap only.
Physical groups: the cells ``ball``; the facets ``lower``, ``upper``, ``xmin`` (the plane
x = 0) and ``ymin`` (the plane y = 0), every boundary facet in exactly one.
"""

from __future__ import annotations

import math
from enum import IntEnum
from typing import TYPE_CHECKING

from contactfx.meshes._build import (
    check_finite,
    check_less,
    check_less_equal,
    check_positive,
    set_graded_size,
)

if TYPE_CHECKING:
    import gmsh

__all__ = ["BallCells", "BallFacets", "quarter_ball"]


class BallCells(IntEnum):
    """Cell tag of :func:`quarter_ball`."""

    BALL = 1


class BallFacets(IntEnum):
    """Facet tags of :func:`quarter_ball`: the spherical cap z <= cap, the rest of the sphere,
    the symmetry planes x = 0 and y = 0."""

    LOWER = 1
    UPPER = 2
    XMIN = 3
    YMIN = 4


def quarter_ball(
    model: type[gmsh.model],
    *,
    radius: float,
    h_contact: float,
    h_far: float,
    refine_radius: float,
    cap: float,
    grading: float = 0.3,
) -> None:
    """Build and mesh the quarter ball x, y >= 0 of ``radius`` centred at (0, 0, radius) in
    ``model`` (a gmsh builder): ``h_contact`` the element size within ``refine_radius`` of the
    lowest point (length), ``h_far`` the size far from it (>= h_contact), ``cap`` the height
    of the contact side's upper edge (0 < cap < 2 radius), ``grading`` the size increase per
    unit distance. Raises ValueError before any gmsh call if a parameter is invalid."""
    check_finite(
        radius=radius, h_contact=h_contact, h_far=h_far, refine_radius=refine_radius, cap=cap
    )
    check_positive(
        radius=radius,
        h_contact=h_contact,
        h_far=h_far,
        refine_radius=refine_radius,
        cap=cap,
        grading=grading,
    )
    check_less_equal("h_contact", h_contact, "h_far", h_far)
    check_less("cap", cap, "2 radius", 2.0 * radius)
    occ = model.occ
    R = radius
    ball = occ.addSphere(0.0, 0.0, R, R, -1, -math.pi / 2, math.pi / 2, math.pi / 2)
    # the slab below z = cap cuts the ball in two conforming volumes (the cap, the rest)
    slab = occ.addBox(-2.0 * R, -2.0 * R, -R, 4.0 * R, 4.0 * R, R + cap)
    pieces, _ = occ.fragment([(3, ball)], [(3, slab)])
    occ.synchronize()
    inside = []
    for dim, tag in pieces:
        x, y, z = occ.getCenterOfMass(dim, tag)
        if (x * x + y * y + (z - R) ** 2) < R * R:  # a piece of the ball, not of the slab
            inside.append(tag)
        else:
            occ.remove([(dim, tag)], recursive=True)
    occ.synchronize()
    model.addPhysicalGroup(3, inside, BallCells.BALL.value)
    model.setPhysicalName(3, BallCells.BALL.value, "ball")
    groups: dict[BallFacets, list[int]] = {f: [] for f in BallFacets}
    eps = 1e-9 * R
    for _, face in model.getBoundary([(3, t) for t in inside], oriented=False):
        x, y, z = occ.getCenterOfMass(2, face)
        if abs(x) < eps:
            groups[BallFacets.XMIN].append(face)
        elif abs(y) < eps:
            groups[BallFacets.YMIN].append(face)
        else:
            groups[BallFacets.LOWER if z < cap else BallFacets.UPPER].append(face)
    for group, faces in groups.items():
        model.addPhysicalGroup(2, faces, group.value)
        model.setPhysicalName(2, group.value, group.name.lower())
    set_graded_size(
        model,
        "Sqrt(x^2+y^2+z^2)",
        size_min=h_contact,
        size_max=h_far,
        dist_min=refine_radius,
        grading=grading,
    )
    import gmsh

    gmsh.option.setNumber("Mesh.Algorithm", 6)
    gmsh.option.setNumber("Mesh.Algorithm3D", 1)
    model.mesh.generate(3)
