"""Write a contactfx mesh to a gmsh ``.msh`` file (gmsh only: no dolfinx, no MPI).

Examples::

    python3 -m contactfx.meshes rectangle --x0 -1 --x1 1 --y0 -1 --y1 0 \\
        --refine-x0 -0.1 --refine-x1 0.1 --h-contact 0.005 --h-far 0.1 --out block.msh
    python3 -m contactfx.meshes box --x0 0 --x1 1 --y0 0 --y1 1 --z0 -1 --z1 0 \\
        --refine-center 0 0 --refine-radius 0.15 --h-contact 0.02 --h-far 0.2 --out quarter.msh
    python3 -m contactfx.meshes crack-plate --half-width 1 --crack-half-length 0.2 --angle 30 \
        --h-crack 0.005 --h-far 0.1 --split-at -0.1 0.1 --out crack.msh
    python3 -m contactfx.meshes penny-block --half-width 8 --crack-radius 1 --h-front 0.05 \\
        --h-crack 0.1 --h-far 2 --out penny.msh
    python3 -m contactfx.meshes joint-column --width 1 --block-height 1 --h 0.05 --out joint.msh
    python3 -m contactfx.meshes stacked-blocks --width 1 --h-lower 0.5 --h-upper 0.5 --h1 0.05 \\
        --ratio 0.7 --offset 0.3 --out blocks.msh
    python3 -m contactfx.meshes cylinders --radius-lower 2 --radius-upper 1 --h-contact 0.01 \\
        --h-far 0.1 --refine 0.1 --ratio 0.6 --out cylinders.msh
    python3 -m contactfx.meshes punch-foundation --width 3 --depth 2 --b 1 --rho 0.25 \\
        --h-punch 0.8 --h-contact 0.01 --h-far 0.2 --refine 0.05 --ratio 1.3 --out punch.msh
    python3 -m contactfx.meshes rounded-on-block --radius 1 --height 0.15 --left 0.8 \
        --right 1.2 --depth 0.5 --track 0.2 --h-contact 0.004 --h-far 0.1 --refine 0.06 \
        --ratio 0.8 --out sliding.msh

Invalid parameters print a one-line error to stderr and exit with code 2.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from functools import partial
from pathlib import Path

from contactfx.meshes._build import write_msh
from contactfx.meshes.box import box
from contactfx.meshes.crack_plate import crack_plate
from contactfx.meshes.joint_column import joint_column
from contactfx.meshes.penny_block import penny_block
from contactfx.meshes.rectangle import rectangle
from contactfx.meshes.two_body import (
    cylinders,
    punch_foundation,
    rounded_on_block,
    spheres,
    stacked_blocks,
    stacked_boxes,
)

__all__ = ["main"]

PROG = "python3 -m contactfx.meshes"


def _add_common(parser: argparse.ArgumentParser, axes: str) -> None:
    """Add the corner coordinates of ``axes``, the mesh sizes, the grading and the output."""
    for axis in axes:
        for end in "01":
            parser.add_argument(f"--{axis}{end}", type=float, required=True, metavar="X")
    parser.add_argument("--h-contact", type=float, required=True, metavar="H")
    parser.add_argument("--h-far", type=float, required=True, metavar="H")
    _add_grading(parser)
    _add_output(parser)


def _add_grading(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--grading", type=float, default=0.3, help="size increase per unit distance (0.3)"
    )


def _add_output(parser: argparse.ArgumentParser) -> None:
    """Add the model name and the output file."""
    parser.add_argument("--name", help="gmsh model name (default: the output file's stem)")
    parser.add_argument("--out", type=Path, required=True, help="output .msh file")


def _add_two_body(parser: argparse.ArgumentParser) -> None:
    """Add the size ratio and the offset of the two-body geometries."""
    parser.add_argument(
        "--ratio", type=float, required=True, help="element size of body 2 / body 1 at the contact"
    )
    parser.add_argument(
        "--offset",
        type=float,
        default=0.0,
        help="shift of body 2's contact nodes, fraction of an element in [0, 1) (0)",
    )


def _add_stacked(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--width", type=float, required=True, metavar="W")
    parser.add_argument("--upper-width", type=float, metavar="W", help="default: --width")
    parser.add_argument("--h-lower", type=float, required=True, metavar="H", help="height")
    parser.add_argument("--h-upper", type=float, required=True, metavar="H", help="height")
    parser.add_argument("--h1", type=float, required=True, metavar="H", help="lower mesh size")
    _add_two_body(parser)
    _add_output(parser)


def _add_graded_two_body(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--h-contact", type=float, required=True, metavar="H")
    parser.add_argument("--h-far", type=float, required=True, metavar="H")
    parser.add_argument("--refine", type=float, required=True, metavar="D")
    _add_grading(parser)
    _add_two_body(parser)
    _add_output(parser)


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog=PROG, description=__doc__.splitlines()[0])
    geometries = parser.add_subparsers(dest="geometry", required=True)

    rect = geometries.add_parser("rectangle", help="2D block refined near a top-edge segment")
    _add_common(rect, "xy")
    rect.add_argument("--refine-x0", type=float, required=True, metavar="X")
    rect.add_argument("--refine-x1", type=float, required=True, metavar="X")

    cube = geometries.add_parser("box", help="3D block refined near a point of the top face")
    _add_common(cube, "xyz")
    cube.add_argument("--refine-center", type=float, nargs=2, required=True, metavar=("CX", "CY"))
    cube.add_argument("--refine-radius", type=float, required=True, metavar="R")

    crack = geometries.add_parser(
        "crack-plate", help="2D square with an interior crack, refined near the crack"
    )
    crack.add_argument("--half-width", type=float, required=True, metavar="L")
    crack.add_argument("--crack-half-length", type=float, required=True, metavar="A")
    crack.add_argument(
        "--angle", type=float, required=True, metavar="DEG", help="from the x axis (degrees)"
    )
    crack.add_argument("--h-crack", type=float, required=True, metavar="H")
    crack.add_argument("--h-far", type=float, required=True, metavar="H")
    _add_grading(crack)
    crack.add_argument(
        "--split-at",
        type=float,
        nargs="+",
        default=[],
        metavar="S",
        help="positions -A < S < A along the crack that must be mesh nodes",
    )
    _add_output(crack)

    penny = geometries.add_parser(
        "penny-block", help="3D quarter block with a penny-shaped crack, refined at its front"
    )
    penny.add_argument("--half-width", type=float, required=True, metavar="L")
    penny.add_argument("--crack-radius", type=float, required=True, metavar="A")
    penny.add_argument("--h-front", type=float, required=True, metavar="H")
    penny.add_argument("--h-crack", type=float, required=True, metavar="H")
    penny.add_argument("--h-far", type=float, required=True, metavar="H")
    _add_grading(penny)
    penny.add_argument(
        "--half",
        action="store_true",
        help="the half block y >= 0 (one symmetry plane) instead of the quarter",
    )
    _add_output(penny)

    joint = geometries.add_parser(
        "joint-column", help="2D column of two blocks with a horizontal joint, uniform mesh"
    )
    joint.add_argument("--width", type=float, required=True, metavar="W")
    joint.add_argument("--block-height", type=float, required=True, metavar="H")
    joint.add_argument("--h", type=float, required=True, metavar="H")
    _add_output(joint)

    blocks = geometries.add_parser(
        "stacked-blocks", help="2D: two blocks touching along y = 0, non-matching meshes"
    )
    _add_stacked(blocks)
    boxes = geometries.add_parser(
        "stacked-boxes", help="3D: two boxes touching along z = 0, non-matching meshes"
    )
    _add_stacked(boxes)
    for name, help_text in (
        ("cylinders", "2D: quarter model of two cylinders touching at the origin"),
        ("spheres", "3D: eighth model of two spheres touching at the origin"),
    ):
        round_bodies = geometries.add_parser(name, help=help_text)
        round_bodies.add_argument("--radius-lower", type=float, required=True, metavar="R")
        round_bodies.add_argument("--radius-upper", type=float, required=True, metavar="R")
        _add_graded_two_body(round_bodies)
    punch = geometries.add_parser(
        "punch-foundation", help="2D: half model of a rounded flat punch on a block"
    )
    punch.add_argument("--width", type=float, required=True, metavar="W", help="block half width")
    punch.add_argument("--depth", type=float, required=True, metavar="D", help="block depth")
    punch.add_argument("--b", type=float, required=True, metavar="B", help="punch half width")
    punch.add_argument("--rho", type=float, required=True, metavar="R", help="edge radius")
    punch.add_argument("--h-punch", type=float, required=True, metavar="H", help="punch height")
    _add_graded_two_body(punch)
    rounded = geometries.add_parser(
        "rounded-on-block", help="2D: a rounded body on a wide block, full model"
    )
    rounded.add_argument("--radius", type=float, required=True, metavar="R", help="body radius")
    rounded.add_argument("--height", type=float, required=True, metavar="H", help="body height")
    rounded.add_argument("--left", type=float, required=True, metavar="L", help="block left")
    rounded.add_argument("--right", type=float, required=True, metavar="R", help="block right")
    rounded.add_argument("--depth", type=float, required=True, metavar="D", help="block depth")
    rounded.add_argument("--track", type=float, required=True, metavar="T", help="track length")
    _add_graded_two_body(rounded)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Parse ``argv``, write the mesh, print its size; return the exit code."""
    args = _parser().parse_args(argv)
    gdim, cells = 2, "triangles"
    if args.geometry == "rectangle":
        builder = partial(
            rectangle,
            x0=args.x0,
            x1=args.x1,
            y0=args.y0,
            y1=args.y1,
            refine_x0=args.refine_x0,
            refine_x1=args.refine_x1,
            h_contact=args.h_contact,
            h_far=args.h_far,
            grading=args.grading,
        )
    elif args.geometry == "box":
        gdim, cells = 3, "tetrahedra"
        builder = partial(
            box,
            x0=args.x0,
            x1=args.x1,
            y0=args.y0,
            y1=args.y1,
            z0=args.z0,
            z1=args.z1,
            refine_center=tuple(args.refine_center),
            refine_radius=args.refine_radius,
            h_contact=args.h_contact,
            h_far=args.h_far,
            grading=args.grading,
        )
    elif args.geometry == "crack-plate":
        builder = partial(
            crack_plate,
            half_width=args.half_width,
            crack_half_length=args.crack_half_length,
            angle=args.angle,
            h_crack=args.h_crack,
            h_far=args.h_far,
            grading=args.grading,
            split_at=tuple(args.split_at),
        )
    elif args.geometry == "penny-block":
        gdim, cells = 3, "tetrahedra"
        builder = partial(
            penny_block,
            half_width=args.half_width,
            crack_radius=args.crack_radius,
            h_front=args.h_front,
            h_crack=args.h_crack,
            h_far=args.h_far,
            grading=args.grading,
            half=args.half,
        )
    elif args.geometry == "joint-column":
        builder = partial(joint_column, width=args.width, block_height=args.block_height, h=args.h)
    elif args.geometry in ("stacked-blocks", "stacked-boxes"):
        if args.geometry == "stacked-boxes":
            gdim, cells = 3, "tetrahedra"
        builder = partial(
            stacked_blocks if gdim == 2 else stacked_boxes,
            width=args.width,
            h_lower=args.h_lower,
            h_upper=args.h_upper,
            h1=args.h1,
            ratio=args.ratio,
            offset=args.offset,
            upper_width=args.upper_width,
        )
    elif args.geometry in ("cylinders", "spheres"):
        if args.geometry == "spheres":
            gdim, cells = 3, "tetrahedra"
        builder = partial(
            cylinders if gdim == 2 else spheres,
            radius_lower=args.radius_lower,
            radius_upper=args.radius_upper,
            h_contact=args.h_contact,
            h_far=args.h_far,
            refine=args.refine,
            ratio=args.ratio,
            offset=args.offset,
            grading=args.grading,
        )
    elif args.geometry == "rounded-on-block":
        builder = partial(
            rounded_on_block,
            radius=args.radius,
            height=args.height,
            left=args.left,
            right=args.right,
            depth=args.depth,
            track=args.track,
            h_contact=args.h_contact,
            h_far=args.h_far,
            refine=args.refine,
            ratio=args.ratio,
            offset=args.offset,
            grading=args.grading,
        )
    else:
        builder = partial(
            punch_foundation,
            width=args.width,
            depth=args.depth,
            b=args.b,
            rho=args.rho,
            h_punch=args.h_punch,
            h_contact=args.h_contact,
            h_far=args.h_far,
            refine=args.refine,
            ratio=args.ratio,
            offset=args.offset,
            grading=args.grading,
        )
    try:
        info = write_msh(builder, gdim, args.out, args.name or args.out.stem)
    except (ValueError, OSError) as exc:
        print(f"{PROG}: error: {exc}", file=sys.stderr)
        return 2
    print(f"{info.path}: {info.num_nodes} nodes, {info.num_cells} {cells}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
