"""Write a contactfx mesh to a gmsh ``.msh`` file (gmsh only: no dolfinx, no MPI).

Examples::

    python3 -m contactfx.meshes rectangle --x0 -1 --x1 1 --y0 -1 --y1 0 \\
        --refine-x0 -0.1 --refine-x1 0.1 --h-contact 0.005 --h-far 0.1 --out block.msh
    python3 -m contactfx.meshes box --x0 0 --x1 1 --y0 0 --y1 1 --z0 -1 --z1 0 \\
        --refine-center 0 0 --refine-radius 0.15 --h-contact 0.02 --h-far 0.2 --out quarter.msh
    python3 -m contactfx.meshes crack-plate --half-width 1 --crack-half-length 0.2 --angle 30 \
        --h-crack 0.005 --h-far 0.1 --split-at -0.1 0.1 --out crack.msh
    python3 -m contactfx.meshes joint-column --width 1 --block-height 1 --h 0.05 --out joint.msh

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
from contactfx.meshes.rectangle import rectangle

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

    joint = geometries.add_parser(
        "joint-column", help="2D column of two blocks with a horizontal joint, uniform mesh"
    )
    joint.add_argument("--width", type=float, required=True, metavar="W")
    joint.add_argument("--block-height", type=float, required=True, metavar="H")
    joint.add_argument("--h", type=float, required=True, metavar="H")
    _add_output(joint)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Parse ``argv``, write the mesh, print its size; return the exit code."""
    args = _parser().parse_args(argv)
    gdim, cells = 2, "triangles"
    if args.geometry == "rectangle":
        builder = partial(
            rectangle,
            x0=args.x0, x1=args.x1, y0=args.y0, y1=args.y1,
            refine_x0=args.refine_x0, refine_x1=args.refine_x1,
            h_contact=args.h_contact, h_far=args.h_far, grading=args.grading,
        )  # fmt: skip
    elif args.geometry == "box":
        gdim, cells = 3, "tetrahedra"
        builder = partial(
            box,
            x0=args.x0, x1=args.x1, y0=args.y0, y1=args.y1, z0=args.z0, z1=args.z1,
            refine_center=tuple(args.refine_center), refine_radius=args.refine_radius,
            h_contact=args.h_contact, h_far=args.h_far, grading=args.grading,
        )  # fmt: skip
    elif args.geometry == "crack-plate":
        builder = partial(
            crack_plate,
            half_width=args.half_width, crack_half_length=args.crack_half_length,
            angle=args.angle, h_crack=args.h_crack, h_far=args.h_far, grading=args.grading,
            split_at=tuple(args.split_at),
        )  # fmt: skip
    else:
        builder = partial(joint_column, width=args.width, block_height=args.block_height, h=args.h)
    try:
        info = write_msh(builder, gdim, args.out, args.name or args.out.stem)
    except (ValueError, OSError) as exc:
        print(f"{PROG}: error: {exc}", file=sys.stderr)
        return 2
    print(f"{info.path}: {info.num_nodes} nodes, {info.num_cells} {cells}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
