"""gmsh geometry definitions (installed as :mod:`contactfx.meshes`).

Each geometry is a *builder* function with keyword-only parameters that creates the geometry,
its physical groups and a graded mesh in a gmsh model; :func:`build` runs a builder on rank 0
and distributes the mesh with dolfinx, :func:`write_msh` writes a gmsh ``.msh`` file::

    from functools import partial
    from mpi4py import MPI
    from contactfx.meshes import RectangleFacets, build, rectangle

    data = build(
        MPI.COMM_WORLD,
        partial(rectangle, x0=-1.0, x1=1.0, y0=-1.0, y1=0.0, refine_x0=-0.1, refine_x1=0.1,
                h_contact=0.005, h_far=0.1),
        gdim=2,
        name="block",
    )
    top = data.facet_tags.find(RectangleFacets.TOP)

Two-body geometries with non-matching contact surfaces (:mod:`contactfx.meshes.two_body`: the
bodies share no node): :func:`stacked_blocks`, :func:`stacked_boxes`, :func:`cylinders`,
:func:`spheres`, :func:`punch_foundation`, :func:`rounded_on_block`, :func:`die_on_block`;
:mod:`contactfx.meshes.sphere_on_block`: :func:`sphere_on_block`;
:mod:`contactfx.meshes.die_on_slab`: :func:`die_on_slab`.

Command line: ``python3 -m contactfx.meshes {rectangle,box,crack-plate,penny-block,joint-column,
stacked-blocks,stacked-boxes,cylinders,spheres,punch-foundation,rounded-on-block} ...
--out mesh.msh``.
"""

from contactfx.meshes._build import (
    Builder,
    Group,
    MeshData,
    MshInfo,
    build,
    build_file,
    build_grouped,
    builder_groups,
    file_groups,
    write_msh,
)
from contactfx.meshes.ball import BallCells, BallFacets, quarter_ball
from contactfx.meshes.box import BoxCells, BoxFacets, box
from contactfx.meshes.crack_plate import (
    CrackPlateCells,
    CrackPlateFacets,
    crack_plate,
    crack_set_plate,
    structured_plate,
)
from contactfx.meshes.die_on_slab import DieOnSlabCells, DieOnSlabFacets, die_on_slab
from contactfx.meshes.disc import DiscCells, DiscFacets, disc
from contactfx.meshes.interval import IntervalCells, IntervalFacets, interval
from contactfx.meshes.joint_column import JointColumnCells, JointColumnFacets, joint_column
from contactfx.meshes.penny_block import PennyBlockCells, PennyBlockFacets, penny_block
from contactfx.meshes.rectangle import RectangleCells, RectangleFacets, rectangle
from contactfx.meshes.sphere_on_block import (
    SphereOnBlockCells,
    SphereOnBlockFacets,
    sphere_on_block,
)
from contactfx.meshes.two_body import (
    CylindersCells,
    CylindersFacets,
    DieOnBlockCells,
    DieOnBlockFacets,
    PunchFoundationCells,
    PunchFoundationFacets,
    RoundedOnBlockCells,
    RoundedOnBlockFacets,
    SpheresCells,
    SpheresFacets,
    StackedBlocksCells,
    StackedBlocksFacets,
    StackedBoxesCells,
    StackedBoxesFacets,
    cylinders,
    die_on_block,
    punch_foundation,
    rounded_on_block,
    spheres,
    stacked_blocks,
    stacked_boxes,
)

#: the geometries by name (as in ``python3 -m contactfx.meshes NAME``, and a problem file's
#: ``mesh.builder``) with their dimension
BUILDERS = {
    "interval": (interval, 1),
    "disc": (disc, 2),
    "rectangle": (rectangle, 2),
    "box": (box, 3),
    "crack-plate": (crack_plate, 2),
    "joint-column": (joint_column, 2),
    "penny-block": (penny_block, 3),
    "stacked-blocks": (stacked_blocks, 2),
    "stacked-boxes": (stacked_boxes, 3),
    "cylinders": (cylinders, 2),
    "spheres": (spheres, 3),
    "punch-foundation": (punch_foundation, 2),
    "rounded-on-block": (rounded_on_block, 2),
    "die-on-block": (die_on_block, 2),
    "die-on-slab": (die_on_slab, 3),
    "sphere-on-block": (sphere_on_block, 3),
    "quarter-ball": (quarter_ball, 3),
}

__all__ = [
    "BUILDERS",
    "BallCells",
    "BallFacets",
    "BoxCells",
    "BoxFacets",
    "Builder",
    "CrackPlateCells",
    "CrackPlateFacets",
    "DiscCells",
    "DiscFacets",
    "IntervalCells",
    "IntervalFacets",
    "CylindersCells",
    "CylindersFacets",
    "DieOnBlockCells",
    "DieOnBlockFacets",
    "DieOnSlabCells",
    "DieOnSlabFacets",
    "Group",
    "JointColumnCells",
    "JointColumnFacets",
    "MeshData",
    "MshInfo",
    "PennyBlockCells",
    "PennyBlockFacets",
    "PunchFoundationCells",
    "PunchFoundationFacets",
    "RectangleCells",
    "RectangleFacets",
    "RoundedOnBlockCells",
    "RoundedOnBlockFacets",
    "SphereOnBlockCells",
    "SphereOnBlockFacets",
    "SpheresCells",
    "SpheresFacets",
    "StackedBlocksCells",
    "StackedBlocksFacets",
    "StackedBoxesCells",
    "StackedBoxesFacets",
    "box",
    "build",
    "disc",
    "build_file",
    "build_grouped",
    "builder_groups",
    "file_groups",
    "crack_plate",
    "crack_set_plate",
    "structured_plate",
    "interval",
    "cylinders",
    "die_on_block",
    "die_on_slab",
    "joint_column",
    "penny_block",
    "punch_foundation",
    "quarter_ball",
    "rectangle",
    "rounded_on_block",
    "sphere_on_block",
    "spheres",
    "stacked_blocks",
    "stacked_boxes",
    "write_msh",
]
