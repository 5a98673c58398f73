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

__all__ = [
    "CrackPlateCells",
    "CrackPlateFacets",
    "crack_plate",
    "crack_set_plate",
    "structured_plate",
]


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

    ``model``: the ``gmsh.model`` namespace of an open gmsh session; ``half_width``: half the
    side of the square plate (length); ``crack_half_length``: the half-length a < half_width of
    the crack, centred at the origin (length), so that the crack tips are inside the plate at
    any angle; ``angle``: the angle of the crack from the x axis, counter-clockwise (degrees);
    ``h_crack``: the element size along and near the crack (length); ``h_far``: the element
    size far from the crack, >= h_crack (length); ``grading``: the size increase per unit
    distance from the crack (dimensionless).

    ``split_at``: distinct positions -a < s < a along the crack (signed distance from the
    centre) that must be mesh nodes, e.g. the ends of a proppant layer (length). ``h_tip``: the
    element size at the crack tips, <= h_crack (default h_crack): the size grows from h_tip at
    the tips by ``grading`` per unit distance up to h_crack (length). ``embed``: whether the
    crack is a chain of mesh edges; with False the plate's mesh ignores the crack (a background
    mesh for an unfitted crack, graded towards the crack as the fitted one; no ``CRACK`` group,
    ``split_at`` unused).

    Raises ValueError before any gmsh call if a parameter is invalid.
    """
    check_finite(
        half_width=half_width,
        crack_half_length=crack_half_length,
        angle=angle,
        h_crack=h_crack,
        h_far=h_far,
        grading=grading,
    )
    check_positive(
        half_width=half_width,
        crack_half_length=crack_half_length,
        h_crack=h_crack,
        h_far=h_far,
        grading=grading,
    )
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
        lines = [(1, model.occ.addLine(p, q)) for p, q in zip(points[:-1], points[1:], strict=True)]
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
        refine_near(
            model,
            size,
            f"Sqrt((Fabs({along})-{a})^2+{across}^2)",
            size_min=h_tip,
            size_max=h_far,
            grading=grading,
        )
    import gmsh

    gmsh.option.setNumber("Mesh.Algorithm", 6)
    model.mesh.generate(2)


def _outer_cells(width: float, h: float, growth: float) -> tuple[int, float]:
    """(cells, ratio) of a geometric progression over ``width`` whose first cell is h and whose
    ratio is at most ``growth``."""
    n = max(1, math.ceil(math.log(1.0 + width * (growth - 1.0) / h) / math.log(growth)))
    lo, hi = 1.0, growth  # h (r^n - 1) / (r - 1) = width for r in [1, growth]
    for _ in range(200):
        r = 0.5 * (lo + hi)
        if h * (r**n - 1.0) / (r - 1.0) < width:
            lo = r
        else:
            hi = r
    return n, 0.5 * (lo + hi)


def structured_plate(
    model: type[gmsh.model],
    *,
    half_width: float,
    inner_half_width: float,
    h: float,
    growth: float = 1.1,
) -> None:
    """Mesh the square [-half_width, half_width]^2 as a structured triangle grid: uniform
    spacing ``h`` in the inner square [-inner_half_width, inner_half_width]^2 (node lines at
    x, y = k h, k = 0, +-1, ...; the inner half-width is rounded to a whole number of cells)
    and cells growing geometrically by at most ``growth`` per cell outside it. A background
    for unfitted cracks whose position against the nodes is known (through nodes, along
    edges). Facet tags as :func:`crack_plate` (no ``CRACK`` group); the triangles are the
    grid's squares split along their (1, 1) diagonals.

    Raises ValueError before any gmsh call if a parameter is invalid.
    """
    check_finite(half_width=half_width, inner_half_width=inner_half_width, h=h, growth=growth)
    check_positive(half_width=half_width, inner_half_width=inner_half_width, h=h)
    check_less("inner_half_width", inner_half_width, "half_width", half_width)
    check_less("1", 1.0, "growth", growth)
    k = max(1, round(inner_half_width / h))
    b = k * h
    check_less("inner_half_width", b, "half_width", half_width)
    n_out, ratio = _outer_cells(half_width - b, h, growth)
    w = half_width
    geo = model.geo
    xs = (-w, -b, b, w)
    pt = {(i, j): geo.addPoint(xs[i], xs[j], 0.0) for i in range(4) for j in range(4)}
    counts = (n_out, 2 * k, n_out)

    def line(p, q, piece):
        tag = geo.addLine(p, q)
        return tag, piece

    # lines along x (j fixed) and along y (i fixed); piece 0 / 2: outer (cells grow outwards)
    hl = {(i, j): line(pt[i, j], pt[i + 1, j], i) for i in range(3) for j in range(4)}
    vl = {(i, j): line(pt[i, j], pt[i, j + 1], j) for i in range(4) for j in range(3)}
    geo.synchronize()
    surfaces = []
    for i in range(3):
        for j in range(3):
            loop = geo.addCurveLoop([hl[i, j][0], vl[i + 1, j][0], -hl[i, j + 1][0], -vl[i, j][0]])
            surfaces.append((geo.addPlaneSurface([loop]), loop))
    geo.synchronize()
    for tag, piece in list(hl.values()) + list(vl.values()):
        # outer pieces: from the plate's edge (piece 0, the line runs inwards: cells shrink)
        # or towards it (piece 2: they grow)
        if piece == 1:
            model.mesh.setTransfiniteCurve(tag, counts[1] + 1)
        else:
            r = 1.0 / ratio if piece == 0 else ratio
            model.mesh.setTransfiniteCurve(tag, counts[piece] + 1, "Progression", r)
    for tag, _ in surfaces:
        model.mesh.setTransfiniteSurface(tag, "Right")
    add_physical_groups(
        model,
        CrackPlateCells.DOMAIN,
        {
            CrackPlateFacets.BOTTOM: (1, -w),
            CrackPlateFacets.RIGHT: (0, w),
            CrackPlateFacets.TOP: (1, w),
            CrackPlateFacets.LEFT: (0, -w),
        },
    )
    model.mesh.generate(2)


def crack_set_plate(
    model: type[gmsh.model],
    *,
    half_width: float,
    cracks: tuple[tuple[float, float, float], ...],
    crack_half_length: float,
    h_crack: float,
    h_tip: float,
    h_far: float,
    grading: float = 0.3,
) -> None:
    """Mesh the square [-half_width, half_width]^2 graded towards several straight cracks that
    it does not follow (a background for unfitted cracks): ``cracks`` are (x, y, angle in
    degrees) of each crack's centre and direction, all of half-length ``crack_half_length``.
    The size is ``h_crack`` within a / 2 of each crack and ``h_tip`` at its tips, growing by
    ``grading`` per unit distance up to ``h_far`` (the smallest over the cracks holds).
    Facet tags as :func:`crack_plate` (no ``CRACK`` group).

    Raises ValueError before any gmsh call if a parameter is invalid.
    """
    check_finite(
        half_width=half_width,
        crack_half_length=crack_half_length,
        h_crack=h_crack,
        h_tip=h_tip,
        h_far=h_far,
        grading=grading,
    )
    check_positive(
        half_width=half_width,
        crack_half_length=crack_half_length,
        h_crack=h_crack,
        h_tip=h_tip,
        h_far=h_far,
        grading=grading,
    )
    check_less_equal("h_tip", h_tip, "h_crack", h_crack)
    check_less_equal("h_crack", h_crack, "h_far", h_far)
    if not cracks:
        raise ValueError("crack_set_plate needs at least one crack")
    w = half_width
    model.occ.addRectangle(-w, -w, 0.0, 2.0 * w, 2.0 * w)
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
    )
    size = None
    a = matheval_number(crack_half_length)
    for x0, y0, angle in cracks:
        theta = math.radians(angle)
        c, n = matheval_number(math.cos(theta)), matheval_number(math.sin(theta))
        x, y = f"(x-{matheval_number(x0)})", f"(y-{matheval_number(y0)})"
        along, across = f"({x}*{c}+{y}*{n})", f"({y}*{c}-{x}*{n})"
        beyond_tips = f"(Fabs({along}-{a})+Fabs({along}+{a})-2*{a})/2"
        distance = f"Sqrt(({beyond_tips})^2+{across}^2)"
        if size is None:
            size = set_graded_size(
                model,
                distance,
                size_min=h_crack,
                size_max=h_far,
                dist_min=0.5 * crack_half_length,
                grading=grading,
            )
        else:
            zone = f"({distance}-{matheval_number(0.5 * crack_half_length)})"
            size = refine_near(model, size, zone, size_min=h_crack, size_max=h_far, grading=grading)
        if h_tip < h_crack:
            size = refine_near(
                model,
                size,
                f"Sqrt((Fabs({along})-{a})^2+{across}^2)",
                size_min=h_tip,
                size_max=h_far,
                grading=grading,
            )
    import gmsh

    gmsh.option.setNumber("Mesh.Algorithm", 6)
    model.mesh.generate(2)
