"""A die with a rounded bottom on a block, both extruded through a thickness: the 3D slab of the
shallow ironing benchmark (meshed independently, non-matching contact surfaces as in
:mod:`contactfx.meshes.two_body`).
"""

from __future__ import annotations

import math
from enum import IntEnum
from typing import TYPE_CHECKING

from contactfx.meshes._build import check_finite, check_positive, distance_along_x
from contactfx.meshes.two_body import (
    add_body_groups,
    check_die,
    check_graded,
    faces_by_plane,
    generate_mesh,
    set_body_sizes,
)

if TYPE_CHECKING:
    import gmsh

__all__ = ["DieOnSlabCells", "DieOnSlabFacets", "die_on_slab"]


class DieOnSlabCells(IntEnum):
    """Cell tags of :func:`die_on_slab`."""

    BLOCK = 1
    DIE = 2


class DieOnSlabFacets(IntEnum):
    """Facet tags of :func:`die_on_slab`.

    ``BLOCK_TOP`` (the block's whole top) and ``DIE_CONTACT`` (the die's cylindrical bottom)
    are the contact surfaces; ``BLOCK_Z0`` and ``DIE_Z0`` the faces z = 0 of each body;
    ``BLOCK_SIDES`` the block's faces x = -left, x = right and z = thickness; ``DIE_SIDES`` the
    die's faces x = -w, x = w and z = thickness.
    """

    BLOCK_TOP = 1
    BLOCK_BOTTOM = 2
    BLOCK_Z0 = 3
    BLOCK_SIDES = 4
    DIE_CONTACT = 5
    DIE_SIDES = 6
    DIE_TOP = 7
    DIE_Z0 = 8


class _DiePlane(IntEnum):
    TOP = 1
    Z0 = 2
    Z1 = 3
    LEFT = 4
    RIGHT = 5
    ARC = 6


def die_on_slab(
    model: type[gmsh.model],
    *,
    radius: float,
    half_width: float,
    height: float,
    left: float,
    right: float,
    depth: float,
    thickness: float,
    track: float,
    h_contact: float,
    h_far: float,
    refine: float,
    ratio: float,
    grading: float = 0.3,
) -> None:
    """Build and mesh the section of :func:`contactfx.meshes.die_on_block` extruded along z
    through [0, ``thickness``] (a gmsh builder).

    The block is [-left, right] x [-depth, 0] x [0, thickness]. The die is the strip
    |x| <= w = ``half_width``, y <= ``height`` cut from below by the cylinder of radius
    R = ``radius`` whose axis is the line x = 0, y = R: its contact surface is the cylindrical
    face from x = -w through the line x = y = 0 (an edge of the mesh) to x = w. The block's
    element size is h_contact within ``refine`` of the track [0, track] x {0} x [0, thickness]
    (the distance measured in the x-y plane), the die's ratio * h_contact within ``refine`` of
    its lowest line; both grow by ``grading`` per unit distance up to ``h_far``.

    ``model``: the ``gmsh.model`` namespace of an open gmsh session; ``radius``: the radius R of
    the die's bottom (length); ``half_width``: the die's half-width w, in (0, R] (length);
    ``height``: the height of the die's top above its lowest line, > the arc's rise (length);
    ``left``, ``right``: the extent of the block left and right of the origin, left > w,
    right > track + w (length); ``depth``: the depth of the block (length); ``thickness``: the
    extent of both bodies along z (length); ``track``: the length of the refined track, >= 0
    (length); ``h_contact``: the element size of the block along the track (length); ``h_far``:
    the element size far from the contact zones, >= h_contact and >= ratio * h_contact
    (length); ``refine``: the distance from the track / the die's lowest line meshed with the
    contact sizes (length); ``ratio``: the element size of the die / that of the block
    (dimensionless); ``grading``: the size increase per unit distance from the refined zones
    (dimensionless).

    Raises ValueError before any gmsh call if a parameter is invalid.
    """
    half = check_die(radius, half_width, height, left, right, depth, track)
    check_finite(thickness=thickness)
    check_positive(thickness=thickness)
    check_graded(h_contact, h_far, refine, grading, ratio, 0.0)
    r, w = radius, half_width

    occ = model.occ
    block = occ.addBox(-left, -depth, 0.0, left + right, depth, thickness)
    # the die's section in the plane z = 0: the arc split at its lowest point, the right side,
    # the top and the left side; then extruded through the thickness
    centre = occ.addPoint(0.0, r, 0.0)
    arc = [occ.addPoint(r * math.sin(a), r * (1.0 - math.cos(a)), 0.0) for a in (-half, 0, half)]
    corners = [occ.addPoint(w, height, 0.0), occ.addPoint(-w, height, 0.0)]
    curves = [occ.addCircleArc(a, centre, b) for a, b in zip(arc[:-1], arc[1:], strict=True)]
    ring = [arc[-1], *corners, arc[0]]
    curves += [occ.addLine(a, b) for a, b in zip(ring[:-1], ring[1:], strict=True)]
    section = occ.addPlaneSurface([occ.addCurveLoop(curves)])
    (die,) = [tag for d, tag in occ.extrude([(2, section)], 0.0, 0.0, thickness) if d == 3]
    occ.remove([(0, centre)])
    occ.synchronize()

    f = DieOnSlabFacets
    block_faces = faces_by_plane(
        model,
        3,
        block,
        {f.BLOCK_TOP: (1, 0.0), f.BLOCK_BOTTOM: (1, -depth), f.BLOCK_Z0: (2, 0.0)},
        rest=f.BLOCK_SIDES,
    )
    p = _DiePlane
    planes = faces_by_plane(
        model,
        3,
        die,
        {
            p.TOP: (1, height),
            p.Z0: (2, 0.0),
            p.Z1: (2, thickness),
            p.LEFT: (0, -w),
            p.RIGHT: (0, w),
        },
        rest=p.ARC,
    )
    die_faces = {
        f.DIE_CONTACT: planes[p.ARC],
        f.DIE_SIDES: planes[p.LEFT] + planes[p.RIGHT] + planes[p.Z1],
        f.DIE_TOP: planes[p.TOP],
        f.DIE_Z0: planes[p.Z0],
    }
    add_body_groups(
        model,
        {DieOnSlabCells.BLOCK: (block, block_faces), DieOnSlabCells.DIE: (die, die_faces)},
    )
    set_body_sizes(
        model,
        3,
        [(block, h_contact, h_far), (die, ratio * h_contact, h_far)],
        [f"Sqrt(({distance_along_x(track)})^2+y^2)", "Sqrt(x^2+y^2)"],
        dist_min=refine,
        grading=grading,
    )
    generate_mesh(model, 3)
