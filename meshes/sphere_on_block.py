"""A sphere cap on a block, half model, for a sphere pressed into the block and slid along it
(meshed independently, non-matching contact surfaces as in :mod:`contactfx.meshes.two_body`).
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
    distance_along_x,
)
from contactfx.meshes.two_body import (
    add_body_groups,
    check_graded,
    faces_by_plane,
    generate_mesh,
    set_body_sizes,
)

if TYPE_CHECKING:
    import gmsh

__all__ = ["SphereOnBlockCells", "SphereOnBlockFacets", "sphere_on_block"]


class SphereOnBlockCells(IntEnum):
    """Cell tags of :func:`sphere_on_block`."""

    BLOCK = 1
    SPHERE = 2


class SphereOnBlockFacets(IntEnum):
    """Facet tags of :func:`sphere_on_block`.

    ``BLOCK_TOP`` (the whole top face) and ``SPHERE_CONTACT`` (the spherical face) are the
    contact surfaces; ``BLOCK_Y0`` and ``SPHERE_Y0`` the symmetry plane y = 0 of each body;
    ``BLOCK_SIDES`` the block's faces x = -left, x = right and y = width.
    """

    BLOCK_TOP = 1
    BLOCK_BOTTOM = 2
    BLOCK_Y0 = 3
    BLOCK_SIDES = 4
    SPHERE_CONTACT = 5
    SPHERE_TOP = 6
    SPHERE_Y0 = 7


def sphere_on_block(
    model: type[gmsh.model],
    *,
    radius: float,
    height: float,
    left: float,
    right: float,
    width: float,
    depth: float,
    track: float,
    h_contact: float,
    h_far: float,
    refine: float,
    ratio: float,
    grading: float = 0.3,
) -> None:
    """Build and mesh a sphere cap touching a block at the origin, half model y >= 0 (a gmsh
    builder).

    The block is [-left, right] x [0, width] x [-depth, 0]. The upper body is the part
    y >= 0, z <= ``height`` of the ball of radius R = ``radius`` centred at (0, 0, R): its
    spherical face is the contact surface, the half disk z = height its top (a half hemisphere
    for height = R). The block's element size is h_contact within the distance ``refine`` of the
    track [0, track] x {0} x {0} (where the contact travels when the sphere slides by ``track``
    along +x), the sphere's ratio * h_contact within ``refine`` of the origin; both grow by
    ``grading`` per unit distance up to ``h_far``.

    ``model``: the ``gmsh.model`` namespace of an open gmsh session; ``radius``: the radius R
    of the sphere (length); ``height``: the height of the cap's flat top above its lowest
    point, in (0, R] (length); ``left``, ``right``: the extent of the block behind and ahead of
    the origin along x, left > the top's radius, right > track + the top's radius (length);
    ``width``: the extent of the block along y, > the top's radius (length); ``depth``: the
    depth of the block (length); ``track``: the length of the refined track, >= 0 (length);
    ``h_contact``: the element size of the block along the track (length); ``h_far``: the
    element size far from the contact zones, >= h_contact and >= ratio * h_contact (length);
    ``refine``: the distance from the track / the origin meshed with the contact sizes
    (length); ``ratio``: the element size of the sphere / that of the block (dimensionless);
    ``grading``: the size increase per unit distance from the refined zones (dimensionless).

    Raises ValueError before any gmsh call if a parameter is invalid.
    """
    check_finite(
        radius=radius,
        height=height,
        left=left,
        right=right,
        width=width,
        depth=depth,
        track=track,
    )
    check_positive(radius=radius, height=height, left=left, right=right, width=width, depth=depth)
    check_less_equal("height", height, "radius", radius)
    if not track >= 0.0:
        raise ValueError(f"track must be >= 0, got {track}")
    check_graded(h_contact, h_far, refine, grading, ratio, 0.0)
    r = radius
    top = math.sqrt(height * (2.0 * r - height))  # the radius of the cap's flat top
    check_less("the top's radius", top, "left", left)
    check_less("track + the top's radius", track + top, "right", right)
    check_less("the top's radius", top, "width", width)

    occ = model.occ
    block = occ.addBox(-left, 0.0, -depth, left + right, width, depth)
    # the half ball y >= 0 (azimuth 0 to pi from +x), cut at z = height
    ball = occ.addSphere(0.0, 0.0, r, r, angle3=math.pi)
    cut = occ.addBox(-2.0 * r, -r, -r, 4.0 * r, 3.0 * r, r + height)
    out, _ = occ.intersect([(3, ball)], [(3, cut)])
    (sphere,) = [tag for d, tag in out if d == 3]
    occ.synchronize()

    f = SphereOnBlockFacets
    block_faces = faces_by_plane(
        model,
        3,
        block,
        {
            f.BLOCK_TOP: (2, 0.0),
            f.BLOCK_BOTTOM: (2, -depth),
            f.BLOCK_Y0: (1, 0.0),
        },
        rest=f.BLOCK_SIDES,
    )
    sphere_faces = faces_by_plane(
        model,
        3,
        sphere,
        {f.SPHERE_TOP: (2, height), f.SPHERE_Y0: (1, 0.0)},
        rest=f.SPHERE_CONTACT,
    )
    add_body_groups(
        model,
        {
            SphereOnBlockCells.BLOCK: (block, block_faces),
            SphereOnBlockCells.SPHERE: (sphere, sphere_faces),
        },
    )
    along = distance_along_x(track)
    set_body_sizes(
        model,
        3,
        [(block, h_contact, h_far), (sphere, ratio * h_contact, h_far)],
        [f"Sqrt(({along})^2+y^2+z^2)", "Sqrt(x^2+y^2+z^2)"],
        dist_min=refine,
        grading=grading,
    )
    generate_mesh(model, 3)
