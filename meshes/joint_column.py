"""Two stacked blocks separated by a horizontal joint, meshed with uniform triangles.

The column is [0, width] x [0, 2 H] with H = ``block_height``: the lower block [0, width] x [0, H]
and the upper block [0, width] x [H, 2 H] share the joint y = H, which spans the full width
(OpenCASCADE boolean fragment of the column with the joint line). The mesh is conforming across
the joint: the joint edges are interior facets and no node is duplicated, the displacement jump
across the joint is left to the solver. Element size ``h`` everywhere. Meshing: OpenCASCADE
geometry, Frontal-Delaunay triangulation (gmsh ``Mesh.Algorithm`` 6), linear triangles.

Physical groups: the cells of both blocks are tagged :attr:`JointColumnCells.DOMAIN`, the
column's edges and the joint :class:`JointColumnFacets` (every boundary edge carries exactly one
tag; the joint edges, interior facets, carry :attr:`JointColumnFacets.JOINT`).

With ``fitted=False`` the column is one rectangle meshed without the joint line (no ``JOINT``
group): the background of an unfitted joint, which the mesh's edges do not follow.
"""

from __future__ import annotations

from enum import IntEnum
from typing import TYPE_CHECKING

from contactfx.meshes._build import (
    add_physical_groups,
    check_finite,
    check_positive,
    set_graded_size,
)

if TYPE_CHECKING:
    import gmsh

__all__ = ["JointColumnCells", "JointColumnFacets", "joint_column"]


class JointColumnCells(IntEnum):
    """Cell tags of :func:`joint_column` (one tag for both blocks)."""

    DOMAIN = 1


class JointColumnFacets(IntEnum):
    """Facet tags of :func:`joint_column`: the column's edges and the joint (interior facets).

    ``RIGHT`` and ``LEFT`` cover the lateral edges of both blocks.
    """

    BOTTOM = 1
    RIGHT = 2
    TOP = 3
    LEFT = 4
    JOINT = 5


def joint_column(
    model: type[gmsh.model],
    *,
    width: float,
    block_height: float,
    h: float,
    fitted: bool = True,
) -> None:
    """Build and mesh the two-block column [0, width] x [0, 2 H] in ``model`` (a gmsh builder).

    ``model``: the ``gmsh.model`` namespace of an open gmsh session; ``width``: the width of
    the column and length of the joint (length); ``block_height``: the height H of each block
    (length), the joint being the line y = H; ``h``: the element size (length); ``fitted``:
    whether the mesh follows the joint (False: one rectangle, no ``JOINT``).

    Raises ValueError before any gmsh call if a parameter is invalid.
    """
    check_finite(width=width, block_height=block_height, h=h)
    check_positive(width=width, block_height=block_height, h=h)

    height = 2.0 * block_height
    surface = model.occ.addRectangle(0.0, 0.0, 0.0, width, height)
    interior = None
    if fitted:
        line = model.occ.addLine(
            model.occ.addPoint(0.0, block_height, 0.0),
            model.occ.addPoint(width, block_height, 0.0),
        )
        # The column comes out as the two blocks; children[1] is the joint line's image.
        _, children = model.occ.fragment([(2, surface)], [(1, line)])
        interior = {JointColumnFacets.JOINT: [tag for _, tag in children[1]]}
    model.occ.synchronize()
    add_physical_groups(
        model,
        JointColumnCells.DOMAIN,
        {
            JointColumnFacets.BOTTOM: (1, 0.0),
            JointColumnFacets.RIGHT: (0, width),
            JointColumnFacets.TOP: (1, height),
            JointColumnFacets.LEFT: (0, 0.0),
        },
        interior=interior,
    )

    # Uniform size: size_min == size_max makes the distance irrelevant.
    set_graded_size(model, "0", size_min=h, size_max=h, dist_min=0.0, grading=1.0)
    import gmsh

    gmsh.option.setNumber("Mesh.Algorithm", 6)
    model.mesh.generate(2)
