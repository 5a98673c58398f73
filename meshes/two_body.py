"""Two elastic bodies in contact, meshed independently: non-matching contact surfaces.

Each builder creates two bodies as separate gmsh surfaces (2D) or volumes (3D) of one model,
without any boolean operation between them: the bodies share no geometric entity, so their meshes
share no node, even where the contact surfaces touch and nodes happen to coincide (gmsh numbers
the nodes of each entity separately, and ``dolfinx.io.gmshio.model_to_mesh`` identifies nodes by
their gmsh tag, never by their coordinates). In dolfinx the mesh has two disconnected parts, one
per cell tag, and both contact surfaces are exterior facets. This is the setting of mortar and
segment-to-segment methods, which couple non-matching contact surfaces (M. A. Puso,
T. A. Laursen, A mortar segment-to-segment contact method for large deformation solid mechanics,
Comput. Methods Appl. Mech. Engrg. 193 (2004) 601-629; P. Wriggers, Computational Contact
Mechanics, 2nd ed., Springer 2006, doi:10.1007/978-3-540-32609-0).

Body 1 (the lower body, the block, the foundation) has the element size ``h`` at the contact
(``h1`` or ``h_contact``), body 2 (the upper body, the punch) the size ``ratio * h``. Non-matching
nodes come from the two sizes and from ``offset`` (0 <= offset < 1, a fraction of an element of
body 2): if offset > 0, body 2's contact curves are split at the distance

    l0 = (1 + offset) * h2   if offset < 0.5,     l0 = offset * h2   if offset >= 0.5

(h2 = ratio * h) from the symmetry plane x = 0 (the origin of the curved builders), and the
piece [0, l0] is one element (transfinite curve with two nodes); gmsh meshes the rest of the
curve with its size field, starting at l0. Body 2's contact nodes near x = 0 then lie at about
(k + offset) * h2 instead of k * h2, shifted by offset * h2 modulo h2, while the first element
stays between 0.5 h2 and 1.5 h2 long. In 3D the two contact edges of body 2 through the origin
(along x and along y) are split; the frontal surface mesher then places the interior nodes of
body 2's contact face differently too. With ratio = 1, offset = 0 and upper_width = width the
contact edges of :func:`stacked_blocks` have pairwise coinciding (but distinct) nodes.

Mesh sizes per body: each body gets its own graded size field (see
:func:`contactfx.meshes._build.set_graded_size`), restricted to the body and its boundary
entities by a gmsh ``Restrict`` field; the background field is the minimum of the two restricted
fields. Meshing: OpenCASCADE geometry, Frontal-Delaunay surfaces (gmsh ``Mesh.Algorithm`` 6),
Delaunay volumes (``Mesh.Algorithm3D`` 1), linear simplices.

Physical groups: the cells of each body carry its own tag (``LOWER``/``UPPER`` or
``BLOCK``/``PUNCH``); each boundary part of each body has its own facet tag, among them one per
contact surface; every boundary facet carries exactly one tag.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from enum import IntEnum
from typing import TYPE_CHECKING

from contactfx.meshes._build import (
    check_finite,
    check_less,
    check_less_equal,
    check_positive,
    distance_along_x,
    set_graded_size,
)

if TYPE_CHECKING:
    import gmsh

__all__ = [
    "CylindersCells",
    "CylindersFacets",
    "PunchFoundationCells",
    "PunchFoundationFacets",
    "RoundedOnBlockCells",
    "RoundedOnBlockFacets",
    "SpheresCells",
    "SpheresFacets",
    "StackedBlocksCells",
    "StackedBlocksFacets",
    "StackedBoxesCells",
    "StackedBoxesFacets",
    "cylinders",
    "offset_length",
    "punch_foundation",
    "rounded_on_block",
    "spheres",
    "stacked_blocks",
    "stacked_boxes",
]


class StackedBlocksCells(IntEnum):
    """Cell tags of :func:`stacked_blocks`."""

    LOWER = 1
    UPPER = 2


class StackedBlocksFacets(IntEnum):
    """Facet tags of :func:`stacked_blocks`: the four edges of each block.

    ``LOWER_TOP`` and ``UPPER_BOTTOM`` are the contact surfaces.
    """

    LOWER_BOTTOM = 1
    LOWER_RIGHT = 2
    LOWER_TOP = 3
    LOWER_LEFT = 4
    UPPER_BOTTOM = 5
    UPPER_RIGHT = 6
    UPPER_TOP = 7
    UPPER_LEFT = 8


class StackedBoxesCells(IntEnum):
    """Cell tags of :func:`stacked_boxes`."""

    LOWER = 1
    UPPER = 2


class StackedBoxesFacets(IntEnum):
    """Facet tags of :func:`stacked_boxes`: the faces x = 0 (X0), x = w (X1), y = 0 (Y0),
    y = w (Y1), bottom and top of each box.

    ``LOWER_TOP`` and ``UPPER_BOTTOM`` are the contact surfaces.
    """

    LOWER_X0 = 1
    LOWER_X1 = 2
    LOWER_Y0 = 3
    LOWER_Y1 = 4
    LOWER_BOTTOM = 5
    LOWER_TOP = 6
    UPPER_X0 = 7
    UPPER_X1 = 8
    UPPER_Y0 = 9
    UPPER_Y1 = 10
    UPPER_BOTTOM = 11
    UPPER_TOP = 12


class CylindersCells(IntEnum):
    """Cell tags of :func:`cylinders`."""

    LOWER = 1
    UPPER = 2


class CylindersFacets(IntEnum):
    """Facet tags of :func:`cylinders`: arc (contact), flat cut and symmetry segment of a body."""

    LOWER_CONTACT = 1
    LOWER_BOTTOM = 2
    LOWER_SYMMETRY = 3
    UPPER_CONTACT = 4
    UPPER_TOP = 5
    UPPER_SYMMETRY = 6


class SpheresCells(IntEnum):
    """Cell tags of :func:`spheres`."""

    LOWER = 1
    UPPER = 2


class SpheresFacets(IntEnum):
    """Facet tags of :func:`spheres`: spherical face (contact), flat cut and the symmetry planes
    x = 0 (X0) and y = 0 (Y0) of each body."""

    LOWER_CONTACT = 1
    LOWER_BOTTOM = 2
    LOWER_X0 = 3
    LOWER_Y0 = 4
    UPPER_CONTACT = 5
    UPPER_TOP = 6
    UPPER_X0 = 7
    UPPER_Y0 = 8


class PunchFoundationCells(IntEnum):
    """Cell tags of :func:`punch_foundation`."""

    BLOCK = 1
    PUNCH = 2


class PunchFoundationFacets(IntEnum):
    """Facet tags of :func:`punch_foundation`.

    ``BLOCK_TOP`` (the whole top edge) and ``PUNCH_CONTACT`` (the flat face and the rounded
    edge) are the contact surfaces.
    """

    BLOCK_TOP = 1
    BLOCK_RIGHT = 2
    BLOCK_BOTTOM = 3
    BLOCK_SYMMETRY = 4
    PUNCH_CONTACT = 5
    PUNCH_SIDE = 6
    PUNCH_TOP = 7
    PUNCH_SYMMETRY = 8


class RoundedOnBlockCells(IntEnum):
    """Cell tags of :func:`rounded_on_block`."""

    BLOCK = 1
    ROUNDED = 2


class RoundedOnBlockFacets(IntEnum):
    """Facet tags of :func:`rounded_on_block`.

    ``BLOCK_TOP`` (the whole top edge) and ``ROUNDED_CONTACT`` (the arc) are the contact
    surfaces.
    """

    BLOCK_TOP = 1
    BLOCK_RIGHT = 2
    BLOCK_BOTTOM = 3
    BLOCK_LEFT = 4
    ROUNDED_CONTACT = 5
    ROUNDED_TOP = 6


def offset_length(offset: float, h2: float) -> float:
    """Length l0 of the first element of body 2's contact curves for ``offset`` > 0.

    ``(1 + offset) * h2`` for offset < 0.5, ``offset * h2`` otherwise: between 0.5 h2 and
    1.5 h2, and l0 = offset * h2 modulo h2 (see the module docstring).
    """
    return (offset if offset >= 0.5 else 1.0 + offset) * h2


def _check_ratio_offset(ratio: float, offset: float) -> None:
    check_finite(ratio=ratio, offset=offset)
    check_positive(ratio=ratio)
    if not 0.0 <= offset < 1.0:
        raise ValueError(f"offset must be in [0, 1), got {offset}")


def _check_first_element(l0: float, curve: str, length: float) -> None:
    """Raise unless the offset's first element is shorter than the contact curve it starts."""
    if not l0 < length:
        raise ValueError(
            f"offset: the first element of {curve} (length {l0:g}) must be shorter than "
            f"{curve} (length {length:g}); reduce the element size or the offset"
        )


def _closure(model: type[gmsh.model], dim: int, tag: int) -> dict[int, list[int]]:
    """The entity (dim, tag) and all entities on its boundary, by dimension."""
    closure = {dim: [tag]}
    current = [(dim, tag)]
    for d in range(dim - 1, -1, -1):
        boundary = model.getBoundary(current, combined=False, oriented=False, recursive=False)
        closure[d] = sorted({t for _, t in boundary})
        current = [(d, t) for t in closure[d]]
    return closure


def add_body_groups(
    model: type[gmsh.model],
    bodies: Mapping[IntEnum, tuple[int, Mapping[IntEnum, Sequence[int]]]],
) -> None:
    """Tag each body and its boundary parts; check that the bodies share no entity.

    ``bodies`` maps each cell tag to (the body's entity of the top dimension, {facet tag: its
    boundary entities}); the facet tags of a body must cover its boundary exactly once. Physical
    names are the lower-case enum names. Call after the geometry is synchronised.
    """
    dim = model.getDimension()
    owner: dict[tuple[int, int], IntEnum] = {}
    for body, (entity, _) in bodies.items():
        for d, tags in _closure(model, dim, entity).items():
            for tag in tags:
                if (d, tag) in owner:
                    raise RuntimeError(
                        f"bodies {owner[d, tag].name} and {body.name} share the entity {(d, tag)}"
                    )
                owner[d, tag] = body
    for body, (entity, facets) in bodies.items():
        boundary = sorted(_closure(model, dim, entity)[dim - 1])
        tagged = sorted(tag for tags in facets.values() for tag in tags)
        if tagged != boundary:
            raise RuntimeError(
                f"facet groups of {body.name} cover {tagged}, its boundary is {boundary}"
            )
        model.addPhysicalGroup(dim, [entity], body.value)
        model.setPhysicalName(dim, body.value, body.name.lower())
        for group, tags in facets.items():
            if not tags:
                raise RuntimeError(f"no boundary entity in {group.name}")
            model.addPhysicalGroup(dim - 1, list(tags), group.value)
            model.setPhysicalName(dim - 1, group.value, group.name.lower())


def faces_by_plane(
    model: type[gmsh.model],
    dim: int,
    entity: int,
    planes: Mapping[IntEnum, tuple[int, float]],
    rest: IntEnum | None = None,
) -> dict[IntEnum, list[int]]:
    """The boundary entities of (dim, entity) grouped by the plane ``x[axis] == value`` they lie
    in; those in none of the planes (curved faces) go to ``rest``, which must then be given."""
    xmin, ymin, zmin, xmax, ymax, zmax = model.getBoundingBox(dim, entity)
    # OCC bounding boxes are enlarged by the geometric tolerance (~1e-7).
    tol = 1e-6 * max(xmax - xmin, ymax - ymin, zmax - zmin)
    groups: dict[IntEnum, list[int]] = {side: [] for side in planes}
    if rest is not None:
        groups[rest] = []
    for tag in _closure(model, dim, entity)[dim - 1]:
        box = model.getBoundingBox(dim - 1, tag)
        matches = [
            side
            for side, (axis, value) in planes.items()
            if abs(box[axis] - value) <= tol and abs(box[axis + 3] - value) <= tol
        ]
        if len(matches) > 1 or (not matches and rest is None):
            raise RuntimeError(f"boundary entity {tag} lies on {len(matches)} planes")
        groups[matches[0] if matches else rest].append(tag)
    return groups


def _split_at_points(
    model: type[gmsh.model],
    dim: int,
    entity: int,
    start: tuple[float, float, float],
    splits: Sequence[tuple[float, float, float]],
) -> int:
    """Split the edges of (dim, entity) at the points ``splits`` (OCC fragment of this entity
    alone, never of both bodies) and make each edge from ``start`` to a split point a
    one-element curve. Returns the tag of the entity after the fragment; synchronises.
    """
    points = [(0, model.occ.addPoint(*p)) for p in splits]
    out, _ = model.occ.fragment([(dim, entity)], points)
    model.occ.synchronize()
    (entity,) = [tag for d, tag in out if d == dim]
    for curve in _closure(model, dim, entity)[1]:
        vertices = model.getBoundary([(1, curve)], combined=False, oriented=False)
        ends = sorted(
            (math.dist(model.getValue(0, tag, []), start) > 1e-9, tuple(model.getValue(0, tag, [])))
            for _, tag in vertices
        )
        if (
            len(ends) == 2
            and not ends[0][0]
            and any(math.dist(ends[1][1], p) <= 1e-9 for p in splits)
        ):
            model.mesh.setTransfiniteCurve(curve, 2)
    return entity


def set_body_sizes(
    model: type[gmsh.model],
    dim: int,
    bodies: Sequence[tuple[int, float, float]],
    distance: str | Sequence[str],
    *,
    dist_min: float,
    grading: float,
) -> None:
    """Give each body (entity, size_min, size_max) its own graded size field
    (``set_graded_size``) of the distance to its zone (one expression for all bodies, or one
    per body), restricted to the body and its boundary entities; the background field is their
    minimum."""
    field = model.mesh.field
    lists = {3: "VolumesList", 2: "SurfacesList", 1: "CurvesList", 0: "PointsList"}
    restricted = []
    distances = [distance] * len(bodies) if isinstance(distance, str) else list(distance)
    for (entity, size_min, size_max), body_distance in zip(bodies, distances, strict=True):
        size = set_graded_size(
            model,
            body_distance,
            size_min=size_min,
            size_max=size_max,
            dist_min=dist_min,
            grading=grading,
        )
        restrict = field.add("Restrict")
        field.setNumber(restrict, "InField", size)
        for d, tags in _closure(model, dim, entity).items():
            field.setNumbers(restrict, lists[d], tags)
        restricted.append(restrict)
    minimum = field.add("Min")
    field.setNumbers(minimum, "FieldsList", restricted)
    field.setAsBackgroundMesh(minimum)


def generate_mesh(model: type[gmsh.model], dim: int) -> None:
    import gmsh

    gmsh.option.setNumber("Mesh.Algorithm", 6)
    if dim == 3:
        gmsh.option.setNumber("Mesh.Algorithm3D", 1)
    model.mesh.generate(dim)


def _polyline(model: type[gmsh.model], points: Sequence[int]) -> list[int]:
    """Lines between consecutive points."""
    return [model.occ.addLine(a, b) for a, b in zip(points[:-1], points[1:], strict=True)]


def _surface(model: type[gmsh.model], curves: Sequence[int]) -> int:
    return model.occ.addPlaneSurface([model.occ.addCurveLoop(list(curves))])


def stacked_blocks(
    model: type[gmsh.model],
    *,
    width: float,
    h_lower: float,
    h_upper: float,
    h1: float,
    ratio: float,
    offset: float = 0.0,
    upper_width: float | None = None,
) -> None:
    """Build and mesh two stacked blocks touching along y = 0 in ``model`` (a gmsh builder).

    The lower block is [0, width] x [-h_lower, 0], the upper block [0, upper_width] x [0, h_upper]
    (from x = 0); uniform meshes of sizes h1 (lower) and h2 = ratio * h1 (upper). With offset > 0
    the upper block's bottom edge is split at x = l0 (:func:`offset_length`).

    ``model``: the ``gmsh.model`` namespace of an open gmsh session; ``width``: the width of the
    lower block (length); ``h_lower``: the height of the lower block (length); ``h_upper``: the
    height of the upper block (length); ``h1``: the element size of the lower block (length);
    ``ratio``: the element size of the upper block / h1 (dimensionless); ``offset``: the shift
    of the upper block's contact nodes, a fraction of its element (in [0, 1));
    ``upper_width``: the width of the upper block, <= width (length), width by default.

    Raises ValueError before any gmsh call if a parameter is invalid.
    """
    if upper_width is None:
        upper_width = width
    check_finite(width=width, h_lower=h_lower, h_upper=h_upper, h1=h1, upper_width=upper_width)
    check_positive(width=width, h_lower=h_lower, h_upper=h_upper, h1=h1, upper_width=upper_width)
    check_less_equal("upper_width", upper_width, "width", width)
    _check_ratio_offset(ratio, offset)
    h2 = ratio * h1
    l0 = offset_length(offset, h2)
    if offset > 0:
        _check_first_element(l0, "the upper block's bottom edge", upper_width)

    occ = model.occ
    lower_points = [
        occ.addPoint(x, y, 0.0) for x, y in ((0, -h_lower), (width, -h_lower), (width, 0), (0, 0))
    ]
    bottom, right, top, left = _polyline(model, [*lower_points, lower_points[0]])
    lower = _surface(model, [bottom, right, top, left])

    xs = [0.0, l0, upper_width] if offset > 0 else [0.0, upper_width]
    contact = [occ.addPoint(x, 0.0, 0.0) for x in xs]
    corners = [occ.addPoint(upper_width, h_upper, 0.0), occ.addPoint(0.0, h_upper, 0.0)]
    upper_lines = _polyline(model, [*contact, *corners, contact[0]])
    upper_bottom, (upper_right, upper_top, upper_left) = upper_lines[:-3], upper_lines[-3:]
    upper = _surface(model, upper_lines)
    occ.synchronize()
    if offset > 0:
        model.mesh.setTransfiniteCurve(upper_bottom[0], 2)

    f = StackedBlocksFacets
    add_body_groups(
        model,
        {
            StackedBlocksCells.LOWER: (
                lower,
                {
                    f.LOWER_BOTTOM: [bottom],
                    f.LOWER_RIGHT: [right],
                    f.LOWER_TOP: [top],
                    f.LOWER_LEFT: [left],
                },
            ),
            StackedBlocksCells.UPPER: (
                upper,
                {
                    f.UPPER_BOTTOM: upper_bottom,
                    f.UPPER_RIGHT: [upper_right],
                    f.UPPER_TOP: [upper_top],
                    f.UPPER_LEFT: [upper_left],
                },
            ),
        },
    )
    # Uniform sizes: size_min == size_max makes the distance irrelevant.
    set_body_sizes(model, 2, [(lower, h1, h1), (upper, h2, h2)], "0", dist_min=0.0, grading=1.0)
    generate_mesh(model, 2)


def stacked_boxes(
    model: type[gmsh.model],
    *,
    width: float,
    h_lower: float,
    h_upper: float,
    h1: float,
    ratio: float,
    offset: float = 0.0,
    upper_width: float | None = None,
) -> None:
    """Build and mesh two stacked boxes touching along z = 0 in ``model`` (a gmsh builder).

    The lower box is [0, width]^2 x [-h_lower, 0], the upper box [0, upper_width]^2 x
    [0, h_upper]; uniform tetrahedral meshes of sizes h1 (lower) and h2 = ratio * h1 (upper).
    With offset > 0 the upper box's bottom edges along the x and y axes are split at the
    distance l0 (:func:`offset_length`) from the origin (OCC fragment of the upper box alone).

    ``model``: the ``gmsh.model`` namespace of an open gmsh session; ``width``: the side of the
    lower box's square cross-section (length); ``h_lower``: the height of the lower box
    (length); ``h_upper``: the height of the upper box (length); ``h1``: the element size of
    the lower box (length); ``ratio``: the element size of the upper box / h1 (dimensionless);
    ``offset``: the shift of the upper box's contact nodes, a fraction of its element (in
    [0, 1)); ``upper_width``: the side of the upper box, <= width (length), width by default.

    Raises ValueError before any gmsh call if a parameter is invalid.
    """
    if upper_width is None:
        upper_width = width
    check_finite(width=width, h_lower=h_lower, h_upper=h_upper, h1=h1, upper_width=upper_width)
    check_positive(width=width, h_lower=h_lower, h_upper=h_upper, h1=h1, upper_width=upper_width)
    check_less_equal("upper_width", upper_width, "width", width)
    _check_ratio_offset(ratio, offset)
    h2 = ratio * h1
    l0 = offset_length(offset, h2)
    if offset > 0:
        _check_first_element(l0, "the upper box's bottom edges", upper_width)

    lower = model.occ.addBox(0.0, 0.0, -h_lower, width, width, h_lower)
    upper = model.occ.addBox(0.0, 0.0, 0.0, upper_width, upper_width, h_upper)
    if offset > 0:
        upper = _split_at_points(model, 3, upper, (0, 0, 0), [(l0, 0, 0), (0, l0, 0)])
    model.occ.synchronize()

    f = StackedBoxesFacets
    lower_faces = faces_by_plane(
        model,
        3,
        lower,
        {
            f.LOWER_X0: (0, 0.0),
            f.LOWER_X1: (0, width),
            f.LOWER_Y0: (1, 0.0),
            f.LOWER_Y1: (1, width),
            f.LOWER_BOTTOM: (2, -h_lower),
            f.LOWER_TOP: (2, 0.0),
        },
    )
    upper_faces = faces_by_plane(
        model,
        3,
        upper,
        {
            f.UPPER_X0: (0, 0.0),
            f.UPPER_X1: (0, upper_width),
            f.UPPER_Y0: (1, 0.0),
            f.UPPER_Y1: (1, upper_width),
            f.UPPER_BOTTOM: (2, 0.0),
            f.UPPER_TOP: (2, h_upper),
        },
    )
    add_body_groups(
        model,
        {
            StackedBoxesCells.LOWER: (lower, lower_faces),
            StackedBoxesCells.UPPER: (upper, upper_faces),
        },
    )
    set_body_sizes(model, 3, [(lower, h1, h1), (upper, h2, h2)], "0", dist_min=0.0, grading=1.0)
    generate_mesh(model, 3)


def check_graded(
    h_contact: float, h_far: float, refine: float, grading: float, ratio: float, offset: float
) -> None:
    """Validate the size parameters shared by the graded builders."""
    check_finite(h_contact=h_contact, h_far=h_far, refine=refine, grading=grading)
    check_positive(h_contact=h_contact, h_far=h_far, refine=refine, grading=grading)
    _check_ratio_offset(ratio, offset)
    check_less_equal("h_contact", h_contact, "h_far", h_far)
    check_less_equal("ratio * h_contact", ratio * h_contact, "h_far", h_far)


def cylinders(
    model: type[gmsh.model],
    *,
    radius_lower: float,
    radius_upper: float,
    h_contact: float,
    h_far: float,
    refine: float,
    ratio: float,
    offset: float = 0.0,
    grading: float = 0.3,
    full: bool = False,
) -> None:
    """Build and mesh two cylinders touching at the origin, quarter model (a gmsh builder).

    Plane strain cross-sections, symmetry plane x = 0 (2D Hertz contact of two cylinders,
    K. L. Johnson, Contact Mechanics, Cambridge University Press 1985,
    doi:10.1017/CBO9781139171731, section 4.2). The upper body is the part x >= 0, y <= R1 of the
    disk of radius R1 = ``radius_upper`` centred at (0, R1): the quarter arc from the origin to
    (R1, R1) is its contact surface, the segment y = R1 its top (where the displacement is
    prescribed), the segment on x = 0 its symmetry plane. The lower body is the part x >= 0,
    y >= -R2 of the disk of radius R2 = ``radius_lower`` centred at (0, -R2), with its flat
    bottom y = -R2. The element size is h_contact (lower) and ratio * h_contact (upper) within
    the distance ``refine`` of the origin and grows by ``grading`` per unit distance up to
    ``h_far``. With offset > 0 the upper arc is split at the arc length l0 (:func:`offset_length`)
    from the origin. With ``full`` the bodies are the half disks (both sides of x = 0, no
    symmetry segment: for tangential loading); the contact arcs run from x = -R to x = R and
    the upper arc is split at -l0 and l0.

    ``model``: the ``gmsh.model`` namespace of an open gmsh session; ``radius_lower``,
    ``radius_upper``: the radii R2 and R1 of the lower and upper cylinders (length);
    ``h_contact``: the element size of the lower body near the origin (length); ``h_far``: the
    element size far from the origin, >= h_contact and >= ratio * h_contact (length);
    ``refine``: the radius of the disk around the origin meshed with the contact sizes (length);
    ``ratio``: the element size of the upper body / that of the lower body (dimensionless);
    ``offset``: the shift of the upper body's contact nodes, a fraction of its element (in
    [0, 1)); ``grading``: the size increase per unit distance from the refinement disk
    (dimensionless); ``full``: half disks instead of quarter disks.

    Raises ValueError before any gmsh call if a parameter is invalid.
    """
    if full:
        _full_cylinders(
            model, radius_lower, radius_upper, h_contact, h_far, refine, ratio, offset, grading
        )
        return
    check_finite(radius_lower=radius_lower, radius_upper=radius_upper)
    check_positive(radius_lower=radius_lower, radius_upper=radius_upper)
    check_graded(h_contact, h_far, refine, grading, ratio, offset)
    r1, r2 = radius_upper, radius_lower
    l0 = offset_length(offset, ratio * h_contact)
    if offset > 0:
        _check_first_element(l0, "the upper contact arc", 0.5 * math.pi * r1)

    occ = model.occ
    # Lower body: arc from the origin to (R2, -R2) around (0, -R2), bottom, symmetry segment.
    origin, end, centre = (occ.addPoint(x, y, 0.0) for x, y in ((0.0, 0.0), (r2, -r2), (0.0, -r2)))
    lower_arc = occ.addCircleArc(origin, centre, end)
    lower_bottom, lower_symmetry = _polyline(model, [end, centre, origin])
    lower = _surface(model, [lower_arc, lower_bottom, lower_symmetry])

    # Upper body: its own origin point (no shared entity), arc to (R1, R1) around (0, R1).
    origin, end, centre = (occ.addPoint(x, y, 0.0) for x, y in ((0.0, 0.0), (r1, r1), (0.0, r1)))
    arc_points = [origin]
    if offset > 0:
        angle = l0 / r1
        arc_points.append(occ.addPoint(r1 * math.sin(angle), r1 * (1 - math.cos(angle)), 0.0))
    arc_points.append(end)
    upper_arc = [
        occ.addCircleArc(a, centre, b) for a, b in zip(arc_points[:-1], arc_points[1:], strict=True)
    ]
    upper_top, upper_symmetry = _polyline(model, [end, centre, origin])
    upper = _surface(model, [*upper_arc, upper_top, upper_symmetry])
    occ.synchronize()
    if offset > 0:
        model.mesh.setTransfiniteCurve(upper_arc[0], 2)

    f = CylindersFacets
    add_body_groups(
        model,
        {
            CylindersCells.LOWER: (
                lower,
                {
                    f.LOWER_CONTACT: [lower_arc],
                    f.LOWER_BOTTOM: [lower_bottom],
                    f.LOWER_SYMMETRY: [lower_symmetry],
                },
            ),
            CylindersCells.UPPER: (
                upper,
                {
                    f.UPPER_CONTACT: upper_arc,
                    f.UPPER_TOP: [upper_top],
                    f.UPPER_SYMMETRY: [upper_symmetry],
                },
            ),
        },
    )
    set_body_sizes(
        model,
        2,
        [(lower, h_contact, h_far), (upper, ratio * h_contact, h_far)],
        "Sqrt(x^2+y^2)",
        dist_min=refine,
        grading=grading,
    )
    generate_mesh(model, 2)


def _full_cylinders(model, r2, r1, h_contact, h_far, refine, ratio, offset, grading) -> None:
    """:func:`cylinders` with ``full``: the half disks below y = R1 (upper) and above
    y = -R2 (lower)."""
    check_finite(radius_lower=r2, radius_upper=r1)
    check_positive(radius_lower=r2, radius_upper=r1)
    check_graded(h_contact, h_far, refine, grading, ratio, offset)
    l0 = offset_length(offset, ratio * h_contact)
    if offset > 0:
        _check_first_element(l0, "the upper contact arc", 0.5 * math.pi * r1)
    occ = model.occ
    # lower: the arc (-R2, -R2) -> origin -> (R2, -R2) around (0, -R2), closed by its bottom
    left, origin, right, centre = (
        occ.addPoint(x, y, 0.0) for x, y in ((-r2, -r2), (0.0, 0.0), (r2, -r2), (0.0, -r2))
    )
    lower_arc = [occ.addCircleArc(left, centre, origin), occ.addCircleArc(origin, centre, right)]
    (lower_bottom,) = _polyline(model, [right, left])
    lower = _surface(model, [*lower_arc, lower_bottom])
    # upper: its own points; the arc (-R1, R1) -> origin -> (R1, R1) around (0, R1), split at
    # the arc lengths -l0 and l0 from the origin (the offset of its nodes)
    centre = occ.addPoint(0.0, r1, 0.0)
    angles = [-0.5 * math.pi, 0.5 * math.pi]
    if offset > 0:
        angles[1:1] = [-l0 / r1, l0 / r1]
    else:
        angles[1:1] = [0.0]
    points = [occ.addPoint(r1 * math.sin(t), r1 * (1 - math.cos(t)), 0.0) for t in angles]
    upper_arc = [
        occ.addCircleArc(a, centre, b) for a, b in zip(points[:-1], points[1:], strict=True)
    ]
    (upper_top,) = _polyline(model, [points[-1], points[0]])
    upper = _surface(model, [*upper_arc, upper_top])
    occ.synchronize()
    if offset > 0:
        model.mesh.setTransfiniteCurve(upper_arc[1], 2)
    f = CylindersFacets
    add_body_groups(
        model,
        {
            CylindersCells.LOWER: (
                lower,
                {f.LOWER_CONTACT: lower_arc, f.LOWER_BOTTOM: [lower_bottom]},
            ),
            CylindersCells.UPPER: (upper, {f.UPPER_CONTACT: upper_arc, f.UPPER_TOP: [upper_top]}),
        },
    )
    set_body_sizes(
        model,
        2,
        [(lower, h_contact, h_far), (upper, ratio * h_contact, h_far)],
        "Sqrt(x^2+y^2)",
        dist_min=refine,
        grading=grading,
    )
    generate_mesh(model, 2)


def punch_foundation(
    model: type[gmsh.model],
    *,
    width: float,
    depth: float,
    b: float,
    rho: float,
    h_punch: float,
    h_contact: float,
    h_far: float,
    refine: float,
    ratio: float,
    offset: float = 0.0,
    grading: float = 0.3,
) -> None:
    """Build and mesh an elastic flat punch with rounded edges on a block, half model.

    Symmetry plane x = 0. The block (foundation) is [0, width] x [-depth, 0]. The punch, of half
    width ``b`` and height ``h_punch``, rests on y = 0 with its flat face 0 <= x <= b - rho;
    its edge is rounded by the quarter circle of radius ``rho`` centred at (b - rho, rho), from
    (b - rho, 0) to (b, rho), then its side x = b rises to the top y = h_punch (the rounded flat
    punch of M. Ciavarella, D. A. Hills, G. Monno, The influence of rounded edges on indentation
    by a flat punch, Proc. Inst. Mech. Eng. C 212 (1998) 319-328). The element size is
    h_contact (block) and ratio * h_contact (punch) within the distance ``refine`` of the
    segment [0, b] x {0}, the potential contact zone, and grows by ``grading`` per unit distance
    up to ``h_far``. With offset > 0 the punch's flat face is split at x = l0
    (:func:`offset_length`).

    ``model``: the ``gmsh.model`` namespace of an open gmsh session; ``width``: the half width
    of the block, > b (length); ``depth``: the depth of the block (length); ``b``: the half width
    of the punch (length); ``rho``: the edge radius of the punch, < b and < h_punch (length);
    ``h_punch``: the height of the punch (length); ``h_contact``: the element size of the block
    near the contact zone (length); ``h_far``: the element size far from it, >= h_contact and
    >= ratio * h_contact (length); ``refine``: the distance from the contact zone meshed with
    the contact sizes (length); ``ratio``: the element size of the punch / that of the block
    (dimensionless); ``offset``: the shift of the punch's contact nodes, a fraction of its
    element (in [0, 1)); ``grading``: the size increase per unit distance from the refined band
    (dimensionless).

    Raises ValueError before any gmsh call if a parameter is invalid.
    """
    check_finite(width=width, depth=depth, b=b, rho=rho, h_punch=h_punch)
    check_positive(width=width, depth=depth, b=b, rho=rho, h_punch=h_punch)
    check_less("rho", rho, "b", b)
    check_less("rho", rho, "h_punch", h_punch)
    check_less("b", b, "width", width)
    check_graded(h_contact, h_far, refine, grading, ratio, offset)
    l0 = offset_length(offset, ratio * h_contact)
    if offset > 0:
        _check_first_element(l0, "the punch's flat face", b - rho)

    occ = model.occ
    block_points = [
        occ.addPoint(x, y, 0.0) for x, y in ((0, 0), (width, 0), (width, -depth), (0, -depth))
    ]
    block_top, block_right, block_bottom, block_symmetry = _polyline(
        model, [*block_points, block_points[0]]
    )
    block = _surface(model, [block_top, block_right, block_bottom, block_symmetry])

    xs = [0.0, l0, b - rho] if offset > 0 else [0.0, b - rho]
    flat_points = [occ.addPoint(x, 0.0, 0.0) for x in xs]
    flat = _polyline(model, flat_points)
    centre = occ.addPoint(b - rho, rho, 0.0)
    edge_end = occ.addPoint(b, rho, 0.0)
    rounded = occ.addCircleArc(flat_points[-1], centre, edge_end)
    top_corners = [occ.addPoint(b, h_punch, 0.0), occ.addPoint(0.0, h_punch, 0.0)]
    punch_side, punch_top, punch_symmetry = _polyline(
        model, [edge_end, *top_corners, flat_points[0]]
    )
    punch = _surface(model, [*flat, rounded, punch_side, punch_top, punch_symmetry])
    occ.remove([(0, centre)])  # the arc's centre is no vertex of the punch: no free point
    occ.synchronize()
    if offset > 0:
        model.mesh.setTransfiniteCurve(flat[0], 2)

    f = PunchFoundationFacets
    add_body_groups(
        model,
        {
            PunchFoundationCells.BLOCK: (
                block,
                {
                    f.BLOCK_TOP: [block_top],
                    f.BLOCK_RIGHT: [block_right],
                    f.BLOCK_BOTTOM: [block_bottom],
                    f.BLOCK_SYMMETRY: [block_symmetry],
                },
            ),
            PunchFoundationCells.PUNCH: (
                punch,
                {
                    f.PUNCH_CONTACT: [*flat, rounded],
                    f.PUNCH_SIDE: [punch_side],
                    f.PUNCH_TOP: [punch_top],
                    f.PUNCH_SYMMETRY: [punch_symmetry],
                },
            ),
        },
    )
    # Distance to the segment [0, b] x {0}, as in rectangle().
    along = distance_along_x(b)
    set_body_sizes(
        model,
        2,
        [(block, h_contact, h_far), (punch, ratio * h_contact, h_far)],
        f"Sqrt(({along})^2+y^2)",
        dist_min=refine,
        grading=grading,
    )
    generate_mesh(model, 2)


def rounded_on_block(
    model: type[gmsh.model],
    *,
    radius: float,
    height: float,
    left: float,
    right: float,
    depth: float,
    track: float,
    h_contact: float,
    h_far: float,
    refine: float,
    ratio: float,
    offset: float = 0.0,
    grading: float = 0.3,
) -> None:
    """Build and mesh a rounded body touching a wide block at the origin (a gmsh builder).

    Full model (no symmetry plane), for a body dragged along the block. The block is
    [-left, right] x [-depth, 0]. The rounded body is the part y <= ``height`` of the disk of
    radius R = ``radius`` centred at (0, R): its contact surface is the arc from (-w, height)
    through the origin to (w, height), w = sqrt(height (2 R - height)), split at the origin (a
    half cylinder for height = R); its top is the segment y = height. The block's element size
    is h_contact within the distance ``refine`` of the track [0, track] x {0} (where the contact
    travels when the body is dragged by ``track`` towards +x), the rounded body's ratio *
    h_contact within ``refine`` of the origin; both grow by ``grading`` per unit distance up to
    ``h_far``. With offset > 0 the arc is also split at the arc length l0
    (:func:`offset_length`) right of the origin.

    ``model``: the ``gmsh.model`` namespace of an open gmsh session; ``radius``: the radius R of
    the rounded body (length); ``height``: the height of the rounded body, in (0, R] (length);
    ``left``, ``right``: the extent of the block left and right of the origin, right > track
    (length); ``depth``: the depth of the block (length); ``track``: the length of the refined
    track on the block, >= 0 (length); ``h_contact``: the element size of the block along the
    track (length); ``h_far``: the element size far from the contact zones, >= h_contact and
    >= ratio * h_contact (length); ``refine``: the distance from the track / the origin meshed
    with the contact sizes (length); ``ratio``: the element size of the rounded body / that of
    the block (dimensionless); ``offset``: the shift of the rounded body's contact nodes, a
    fraction of its element (in [0, 1)); ``grading``: the size increase per unit distance from
    the refined zones (dimensionless).

    Raises ValueError before any gmsh call if a parameter is invalid.
    """
    check_finite(radius=radius, height=height, left=left, right=right, depth=depth, track=track)
    check_positive(radius=radius, height=height, left=left, right=right, depth=depth)
    check_less_equal("height", height, "radius", radius)
    if not track >= 0.0:
        raise ValueError(f"track must be >= 0, got {track}")
    check_less("track", track, "right", right)
    check_graded(h_contact, h_far, refine, grading, ratio, offset)
    r = radius
    half = math.acos((r - height) / r)  # half the arc's angle
    w = r * math.sin(half)
    check_less("the arc half-width", w, "left", left)
    check_less("the arc half-width", w, "right", right)
    l0 = offset_length(offset, ratio * h_contact)
    if offset > 0:
        _check_first_element(l0, "the right half of the arc", half * r)

    # The arc from (-w, height) through the origin (and the offset point) to (w, height).
    block, block_lines, arc_points, arcs, centre = _block_and_arc(
        model, left, right, depth, r, half, l0 if offset > 0 else None
    )
    (top,) = _polyline(model, [arc_points[-1], arc_points[0]])
    rounded = _surface(model, [*arcs, top])
    f = RoundedOnBlockFacets
    _mesh_body_on_block(
        model,
        centre,
        arcs if offset > 0 else None,
        (RoundedOnBlockCells.BLOCK, block, dict(zip(_BLOCK_SIDES, block_lines, strict=True))),
        (RoundedOnBlockCells.ROUNDED, rounded, {f.ROUNDED_CONTACT: arcs, f.ROUNDED_TOP: [top]}),
        track=track,
        sizes=(h_contact, h_far, ratio, refine, grading),
    )


#: the block's sides in :func:`_block_and_arc`'s order, as RoundedOnBlockFacets (which
#: DieOnBlockFacets numbers alike)
_BLOCK_SIDES = (
    RoundedOnBlockFacets.BLOCK_TOP,
    RoundedOnBlockFacets.BLOCK_RIGHT,
    RoundedOnBlockFacets.BLOCK_BOTTOM,
    RoundedOnBlockFacets.BLOCK_LEFT,
)


def _block_and_arc(
    model: type[gmsh.model],
    left: float,
    right: float,
    depth: float,
    r: float,
    half: float,
    l0: float | None,
) -> tuple[int, list[list[int]], list[int], list[int], int]:
    """The block [-left, right] x [-depth, 0] (its surface and its sides' curves, top, right,
    bottom, left) and the arc of radius r centred at (0, r) from the angle -half through the
    origin (and the point at arc length l0 when given) to +half: its points, its arcs and the
    centre point (removed by :func:`_mesh_body_on_block`)."""
    occ = model.occ
    block_points = [
        occ.addPoint(x, y, 0.0)
        for x, y in ((-left, 0.0), (right, 0.0), (right, -depth), (-left, -depth))
    ]
    lines = _polyline(model, [*block_points, block_points[0]])
    block = _surface(model, lines)
    centre = occ.addPoint(0.0, r, 0.0)
    angles = [-half, 0.0, *([l0 / r] if l0 is not None else []), half]
    arc_points = [occ.addPoint(r * math.sin(a), r * (1 - math.cos(a)), 0.0) for a in angles]
    arcs = [
        occ.addCircleArc(a, centre, b) for a, b in zip(arc_points[:-1], arc_points[1:], strict=True)
    ]
    return block, [[line] for line in lines], arc_points, arcs, centre


def _mesh_body_on_block(
    model: type[gmsh.model],
    centre: int,
    split_arcs: list[int] | None,
    block: tuple[int, int, dict[int, list[int]]],
    body: tuple[int, int, dict[int, list[int]]],
    *,
    track: float,
    sizes: tuple[float, float, float, float, float],
) -> None:
    """Finish and mesh a body on the block of :func:`_block_and_arc`: the arc's centre
    removed (no vertex of the body), the first element past the offset point on the arcs
    ``split_arcs`` (if given), the groups (cell tag, surface, facet groups) of the block and of
    the body, the sizes (h_contact, h_far, ratio, refine, grading): the block's by the distance
    to the track [0, track] x {0}, as in rectangle(), the body's by the distance to the
    origin."""
    h_contact, h_far, ratio, refine, grading = sizes
    model.occ.remove([(0, centre)])
    model.occ.synchronize()
    if split_arcs is not None:
        model.mesh.setTransfiniteCurve(split_arcs[1], 2)
    add_body_groups(model, {block[0]: block[1:], body[0]: body[1:]})
    along = distance_along_x(track)
    set_body_sizes(
        model,
        2,
        [(block[1], h_contact, h_far), (body[1], ratio * h_contact, h_far)],
        [f"Sqrt(({along})^2+y^2)", "Sqrt(x^2+y^2)"],
        dist_min=refine,
        grading=grading,
    )
    generate_mesh(model, 2)


def spheres(
    model: type[gmsh.model],
    *,
    radius_lower: float,
    radius_upper: float,
    h_contact: float,
    h_far: float,
    refine: float,
    ratio: float,
    offset: float = 0.0,
    grading: float = 0.3,
) -> None:
    """Build and mesh two spheres touching at the origin, eighth model (a gmsh builder).

    Symmetry planes x = 0 and y = 0 (3D Hertz contact of two spheres, K. L. Johnson, Contact
    Mechanics, Cambridge University Press 1985, doi:10.1017/CBO9781139171731, section 4.2). The
    upper body is the part x >= 0, y >= 0, z <= R1 of the ball of radius R1 = ``radius_upper``
    centred at (0, 0, R1): an eighth of the sphere is its contact surface, the quarter disk
    z = R1 its top. The lower body is the part x >= 0, y >= 0, z >= -R2 of the ball of radius
    R2 = ``radius_lower`` centred at (0, 0, -R2), with its flat bottom z = -R2. Sizes as in
    :func:`cylinders`. With offset > 0 the two meridian arcs of the upper sphere (in the planes
    x = 0 and y = 0) are split at the arc length l0 (:func:`offset_length`) from the origin.

    ``model``: the ``gmsh.model`` namespace of an open gmsh session; ``radius_lower``,
    ``radius_upper``: the radii R2 and R1 of the lower and upper spheres (length);
    ``h_contact``: the element size of the lower body near the origin (length); ``h_far``: the
    element size far from the origin, >= h_contact and >= ratio * h_contact (length);
    ``refine``: the radius of the ball around the origin meshed with the contact sizes (length);
    ``ratio``: the element size of the upper body / that of the lower body (dimensionless);
    ``offset``: the shift of the upper body's contact nodes, a fraction of its element (in
    [0, 1)); ``grading``: the size increase per unit distance from the refinement ball
    (dimensionless).

    Raises ValueError before any gmsh call if a parameter is invalid.
    """
    check_finite(radius_lower=radius_lower, radius_upper=radius_upper)
    check_positive(radius_lower=radius_lower, radius_upper=radius_upper)
    check_graded(h_contact, h_far, refine, grading, ratio, offset)
    r1, r2 = radius_upper, radius_lower
    l0 = offset_length(offset, ratio * h_contact)
    if offset > 0:
        _check_first_element(l0, "the upper meridian arcs", 0.5 * math.pi * r1)

    quarter = 0.5 * math.pi
    # Latitudes [0, pi/2] (upper hemisphere of the lower ball), longitudes [0, pi/2] (x, y >= 0).
    lower = model.occ.addSphere(0.0, 0.0, -r2, r2, angle1=0.0, angle2=quarter, angle3=quarter)
    upper = model.occ.addSphere(0.0, 0.0, r1, r1, angle1=-quarter, angle2=0.0, angle3=quarter)
    if offset > 0:
        s, c = math.sin(l0 / r1), math.cos(l0 / r1)
        splits = [(r1 * s, 0.0, r1 * (1 - c)), (0.0, r1 * s, r1 * (1 - c))]
        upper = _split_at_points(model, 3, upper, (0, 0, 0), splits)
    model.occ.synchronize()

    f = SpheresFacets
    lower_faces = faces_by_plane(
        model,
        3,
        lower,
        {f.LOWER_BOTTOM: (2, -r2), f.LOWER_X0: (0, 0.0), f.LOWER_Y0: (1, 0.0)},
        rest=f.LOWER_CONTACT,
    )
    upper_faces = faces_by_plane(
        model,
        3,
        upper,
        {f.UPPER_TOP: (2, r1), f.UPPER_X0: (0, 0.0), f.UPPER_Y0: (1, 0.0)},
        rest=f.UPPER_CONTACT,
    )
    add_body_groups(
        model,
        {SpheresCells.LOWER: (lower, lower_faces), SpheresCells.UPPER: (upper, upper_faces)},
    )
    set_body_sizes(
        model,
        3,
        [(lower, h_contact, h_far), (upper, ratio * h_contact, h_far)],
        "Sqrt(x^2+y^2+z^2)",
        dist_min=refine,
        grading=grading,
    )
    generate_mesh(model, 3)


class DieOnBlockCells(IntEnum):
    """Cell tags of :func:`die_on_block`."""

    BLOCK = 1
    DIE = 2


class DieOnBlockFacets(IntEnum):
    """Facet tags of :func:`die_on_block`.

    ``BLOCK_TOP`` (the whole top edge) and ``DIE_CONTACT`` (the die's arc) are the contact
    surfaces.
    """

    BLOCK_TOP = 1
    BLOCK_RIGHT = 2
    BLOCK_BOTTOM = 3
    BLOCK_LEFT = 4
    DIE_CONTACT = 5
    DIE_SIDES = 6
    DIE_TOP = 7


def check_die(
    radius: float,
    half_width: float,
    height: float,
    left: float,
    right: float,
    depth: float,
    track: float,
) -> float:
    """Validate a die with a rounded bottom on a block (:func:`die_on_block` and its 3D
    extrusion): finite, positive sizes, the die's half-width within its radius and the block,
    its arc below its top; return half the arc's angle."""
    check_finite(
        radius=radius,
        half_width=half_width,
        height=height,
        left=left,
        right=right,
        depth=depth,
        track=track,
    )
    check_positive(
        radius=radius, half_width=half_width, height=height, left=left, right=right, depth=depth
    )
    check_less_equal("half_width", half_width, "radius", radius)
    if not track >= 0.0:
        raise ValueError(f"track must be >= 0, got {track}")
    check_less("half_width", half_width, "left", left)
    check_less("track + half_width", track + half_width, "right", right)
    half = math.asin(half_width / radius)
    check_less("the arc's height", radius * (1.0 - math.cos(half)), "height", height)
    return half


def die_on_block(
    model: type[gmsh.model],
    *,
    radius: float,
    half_width: float,
    height: float,
    left: float,
    right: float,
    depth: float,
    track: float,
    h_contact: float,
    h_far: float,
    refine: float,
    ratio: float,
    offset: float = 0.0,
    grading: float = 0.3,
) -> None:
    """Build and mesh a die with a rounded bottom touching a wide block at the origin (a gmsh
    builder; the ironing problem's geometry).

    Full model, for a die dragged along the block. The block is [-left, right] x [-depth, 0].
    The die is the strip |x| <= w = ``half_width`` below y = ``height`` cut from below by the
    circle of radius R = ``radius`` centred at (0, R): its contact surface is the arc from
    (-w, e) through the origin to (w, e), e = R - sqrt(R^2 - w^2), split at the origin; its
    sides are the segments x = -w and x = w from y = e to y = height; its top is the segment
    y = height. Sizes as in :func:`rounded_on_block`: the block's element size is h_contact
    within ``refine`` of the track [0, track] x {0}, the die's ratio * h_contact within
    ``refine`` of its arc's lowest point; both grow by ``grading`` per unit distance up to
    ``h_far``. With offset > 0 the arc is also split at the arc length l0
    (:func:`offset_length`) right of the origin.

    ``model``: the ``gmsh.model`` namespace of an open gmsh session; ``radius``: the radius R of
    the die's arc (length); ``half_width``: the die's half-width w, in (0, R] (length);
    ``height``: the height of the die's top above its lowest point, > e (length); ``left``,
    ``right``: the extent of the block left and right of the origin, left > w, right > track + w
    (length); ``depth``: the depth of the block (length); ``track``: the length of the refined
    track on the block, >= 0 (length); ``h_contact``: the element size of the block along the
    track (length); ``h_far``: the element size far from the contact zones, >= h_contact and
    >= ratio * h_contact (length); ``refine``: the distance from the track / the origin meshed
    with the contact sizes (length); ``ratio``: the element size of the die / that of the block
    (dimensionless); ``offset``: the shift of the die's contact nodes, a fraction of its element
    (in [0, 1)); ``grading``: the size increase per unit distance from the refined zones
    (dimensionless).

    Raises ValueError before any gmsh call if a parameter is invalid.
    """
    half = check_die(radius, half_width, height, left, right, depth, track)
    check_graded(h_contact, h_far, refine, grading, ratio, offset)
    r, w = radius, half_width
    l0 = offset_length(offset, ratio * h_contact)
    if offset > 0:
        _check_first_element(l0, "the right half of the arc", half * r)

    # The arc from (-w, e) through the origin (and the offset point) to (w, e), then the
    # right side, the top and the left side.
    block, block_lines, arc_points, arcs, centre = _block_and_arc(
        model, left, right, depth, r, half, l0 if offset > 0 else None
    )
    occ = model.occ
    corners = [occ.addPoint(w, height, 0.0), occ.addPoint(-w, height, 0.0)]
    right_side, top, left_side = _polyline(model, [arc_points[-1], *corners, arc_points[0]])
    die = _surface(model, [*arcs, right_side, top, left_side])
    f = DieOnBlockFacets
    _mesh_body_on_block(
        model,
        centre,
        arcs if offset > 0 else None,
        (DieOnBlockCells.BLOCK, block, dict(zip(_BLOCK_SIDES, block_lines, strict=True))),
        (
            DieOnBlockCells.DIE,
            die,
            {f.DIE_CONTACT: arcs, f.DIE_SIDES: [right_side, left_side], f.DIE_TOP: [top]},
        ),
        track=track,
        sizes=(h_contact, h_far, ratio, refine, grading),
    )
