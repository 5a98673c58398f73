"""Square plate with a straight interior crack, meshed with triangles graded towards the crack.

The plate is the square [-half_width, half_width]^2; the crack is the segment of half-length
``a = crack_half_length`` centred at the origin at ``angle`` degrees from the x axis
(counter-clockwise), i.e. the points s (cos(angle), sin(angle)) for -a <= s <= a, where s is the
signed distance from the centre along the crack. The crack is a chain of mesh edges inside the
surface (OpenCASCADE boolean fragment of the square with the crack lines): the mesh is conforming
and the crack edges are interior facets; no node is duplicated, the displacement jump across the
crack is left to the solver. The crack tips s = +-a and the points ``split_at`` (e.g. the ends
of a proppant layer) are mesh nodes.

The element size is ``h_crack`` within the distance ``min(a / 2, gap)`` of the crack segment,
where ``gap = half_width - a * max(|cos(angle)|, |sin(angle)|)`` is the distance from the crack
to the plate's edges, and grows linearly with the distance, by ``grading`` per unit distance, up
to ``h_far`` (see :func:`contactfx.meshes._build.set_graded_size`). Meshing: OpenCASCADE
geometry, Frontal-Delaunay triangulation (gmsh ``Mesh.Algorithm`` 6), linear triangles.

Physical groups: the cells are tagged :attr:`CrackPlateCells.DOMAIN`, the four edges and the
crack :class:`CrackPlateFacets` (every boundary edge carries exactly one tag; the crack edges,
interior facets, carry :attr:`CrackPlateFacets.CRACK`).
"""

from __future__ import annotations

import math
from enum import IntEnum
from typing import TYPE_CHECKING

from contactfx.meshes._build import (
    add_physical_groups,
    check_finite,
    check_less,
    check_less_equal,
    check_positive,
    matheval_number,
    refine_near,
    set_graded_size,
)

if TYPE_CHECKING:
    import gmsh

__all__ = ["CrackPlateCells", "CrackPlateFacets", "crack_plate"]


class CrackPlateCells(IntEnum):
    """Cell tags of :func:`crack_plate`."""

    DOMAIN = 1


class CrackPlateFacets(IntEnum):
    """Facet tags of :func:`crack_plate`: the four edges and the crack (interior facets)."""

    BOTTOM = 1
    RIGHT = 2
    TOP = 3
    LEFT = 4
    CRACK = 5


def crack_plate(
    model: type[gmsh.model],
    *,
    half_width: float,
    crack_half_length: float,
    angle: float,
    h_crack: float,
    h_far: float,
    grading: float = 0.3,
    split_at: tuple[float, ...] = (),
    h_tip: float | None = None,
    embed: bool = True,
) -> None:
    """Build and mesh the cracked square [-half_width, half_width]^2 in ``model`` (a gmsh builder).

    Args:
        model: The ``gmsh.model`` namespace of an open gmsh session.
        half_width: Half the side of the square plate (length).
        crack_half_length: Half-length a < half_width of the crack, centred at the origin
            (length); the crack tips are then inside the plate at any angle.
        angle: Angle of the crack from the x axis, counter-clockwise (degrees).
        h_crack: Element size along and near the crack (length).
        h_far: Element size far from the crack, >= h_crack (length).
        grading: Size increase per unit distance from the crack (dimensionless).
        split_at: Distinct positions -a < s < a along the crack (signed distance from the
            centre) that must be mesh nodes, e.g. the ends of a proppant layer (length).
        h_tip: Element size at the crack tips, <= h_crack (default h_crack): the size grows
            from h_tip at the tips by ``grading`` per unit distance up to h_crack (length).
        embed: Whether the crack is a chain of mesh edges; False: the plate's mesh ignores
            the crack (a background mesh for an unfitted crack, graded towards the crack as
            the fitted one; no ``CRACK`` group, ``split_at`` unused).

    Raises:
        ValueError: Before any gmsh call, if a parameter is invalid.
    """
    check_finite(
        half_width=half_width, crack_half_length=crack_half_length, angle=angle,
        h_crack=h_crack, h_far=h_far, grading=grading,
    )  # fmt: skip
    check_positive(
        half_width=half_width, crack_half_length=crack_half_length,
        h_crack=h_crack, h_far=h_far, grading=grading,
    )  # fmt: skip
    # a < half_width keeps the crack inside the plate's inscribed circle, whatever the angle:
    # the tips' distance to the edges, half_width - a * max(|cos|, |sin|), is then > 0.
    check_less("crack_half_length", crack_half_length, "half_width", half_width)
    check_less_equal("h_crack", h_crack, "h_far", h_far)
    h_tip = h_crack if h_tip is None else h_tip
    check_finite(h_tip=h_tip)
    check_positive(h_tip=h_tip)
    check_less_equal("h_tip", h_tip, "h_crack", h_crack)
    for s in split_at:
        check_finite(split_at=s)
        check_less("-crack_half_length", -crack_half_length, "split_at", s)
        check_less("split_at", s, "crack_half_length", crack_half_length)
    if len(set(split_at)) != len(split_at):
        raise ValueError(f"split_at must be distinct, got {split_at}")

    theta = math.radians(angle)
    cos, sin = math.cos(theta), math.sin(theta)
    gap = half_width - crack_half_length * max(abs(cos), abs(sin))
    w = half_width
    surface = model.occ.addRectangle(-w, -w, 0.0, 2.0 * w, 2.0 * w)
    interior = {}
    if embed:
        stations = sorted((-crack_half_length, *split_at, crack_half_length))
        points = [model.occ.addPoint(s * cos, s * sin, 0.0) for s in stations]
        lines = [(1, model.occ.addLine(p, q))
                 for p, q in zip(points[:-1], points[1:], strict=True)]  # fmt: skip
        # The square comes out as one surface with the crack lines embedded in it (they do
        # not cut it in two); children[1:] are the crack lines' images.
        _, children = model.occ.fragment([(2, surface)], lines)
        interior = {CrackPlateFacets.CRACK: [tag for images in children[1:] for _, tag in images]}
    model.occ.synchronize()
    add_physical_groups(
        model,
        CrackPlateCells.DOMAIN,
        {
            CrackPlateFacets.BOTTOM: (1, -w),
            CrackPlateFacets.RIGHT: (0, w),
            CrackPlateFacets.TOP: (1, w),
            CrackPlateFacets.LEFT: (0, -w),
        },
        interior=interior,
    )

    # Distance to the crack segment in the crack's frame: s = x cos + y sin along the crack,
    # t = -x sin + y cos across it; (|s - a| + |s + a| - 2a) / 2 is the distance of s to [-a, a].
    a, c, n = (matheval_number(v) for v in (crack_half_length, cos, sin))
    along = f"(x*{c}+y*{n})"
    across = f"(y*{c}-x*{n})"
    beyond_tips = f"(Fabs({along}-{a})+Fabs({along}+{a})-2*{a})/2"
    distance = f"Sqrt(({beyond_tips})^2+{across}^2)"
    size = set_graded_size(
        model,
        distance,
        size_min=h_crack,
        size_max=h_far,
        dist_min=min(0.5 * crack_half_length, gap),
        grading=grading,
    )
    if h_tip < h_crack:  # the smaller of that size and h_tip + grading * (distance to a tip)
        refine_near(model, size, f"Sqrt((Fabs({along})-{a})^2+{across}^2)", size_min=h_tip,
                    size_max=h_far, grading=grading)  # fmt: skip
    import gmsh

    gmsh.option.setNumber("Mesh.Algorithm", 6)
    model.mesh.generate(2)
