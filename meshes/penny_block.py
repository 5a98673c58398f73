"""A quarter of a block with a circular (penny-shaped) crack in its mid-plane, meshed with
tetrahedra graded towards the crack and refined further at the crack front.

The block is [0, half_width]^2 x [-half_width, half_width]; the crack is the quarter disk
x^2 + y^2 <= a^2, z = 0 (``a = crack_radius``), so the planes x = 0 and y = 0 are planes of
symmetry of the whole cracked block (the caller supports them). With ``half``, the block is
[-half_width, half_width] x [0, half_width] x [-half_width, half_width] and the crack the half
disk y >= 0 (y = 0 the one plane of symmetry: a load with no y component, e.g. a shear along
x). The crack is a set of mesh
triangles inside the volume (OpenCASCADE boolean fragment of the box with the quarter disk): the
mesh is conforming and the crack triangles are interior facets; no node is duplicated, the
displacement jump is left to the solver. The crack front, the arc r = a, is a chain of mesh
edges.

Element sizes (see :func:`contactfx.meshes._build.set_graded_size`): ``h_crack`` within the
distance a / 2 of the crack disk, growing by ``grading`` per unit distance up to ``h_far``;
and at the front the smaller size ``h_front``, growing by ``grading`` per unit distance from the
front. Meshing: OpenCASCADE geometry, Frontal-Delaunay surface meshes (gmsh ``Mesh.Algorithm``
6), Delaunay volume mesh (``Mesh.Algorithm3D`` 1), linear tetrahedra.

Physical groups: the cells are tagged :attr:`PennyBlockCells.DOMAIN`, the six faces
:class:`PennyBlockFacets` (every boundary facet carries exactly one tag) and the crack's
triangles, interior facets, :attr:`PennyBlockFacets.CRACK`.
"""

from __future__ import annotations

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

__all__ = ["PennyBlockCells", "PennyBlockFacets", "penny_block"]


class PennyBlockCells(IntEnum):
    """Cell tags of :func:`penny_block`."""

    DOMAIN = 1


class PennyBlockFacets(IntEnum):
    """Facet tags of :func:`penny_block`: the symmetry planes x = 0 (quarter) and y = 0, the
    outer faces (x = -half_width: half only) and the crack (interior facets)."""

    XSYM = 1
    YSYM = 2
    XMAX = 3
    YMAX = 4
    BOTTOM = 5
    TOP = 6
    CRACK = 7
    XMIN = 8


def penny_block(
    model: type[gmsh.model],
    *,
    half_width: float,
    crack_radius: float,
    h_front: float,
    h_crack: float,
    h_far: float,
    grading: float = 0.3,
    half: bool = False,
) -> None:
    """Build and mesh the quarter (or half) block with its penny crack in ``model``.

    ``model``: the ``gmsh.model`` namespace of an open gmsh session; ``half_width``: the block
    is [0, half_width]^2 x [-half_width, half_width] (length); ``crack_radius``: the radius
    a < half_width of the crack, centred at the origin in z = 0 (length); ``h_front``: the
    element size at the crack front r = a, <= h_crack (length); ``h_crack``: the element size on
    and near the crack, <= h_far (length); ``h_far``: the element size far from the crack
    (length); ``grading``: the size increase per unit distance (dimensionless); ``half``: the
    half block y >= 0 instead of the quarter x, y >= 0.

    Raises ValueError before any gmsh call if a parameter is invalid.
    """
    check_finite(
        half_width=half_width,
        crack_radius=crack_radius,
        h_front=h_front,
        h_crack=h_crack,
        h_far=h_far,
        grading=grading,
    )
    check_positive(
        half_width=half_width,
        crack_radius=crack_radius,
        h_front=h_front,
        h_crack=h_crack,
        h_far=h_far,
        grading=grading,
    )
    check_less("crack_radius", crack_radius, "half_width", half_width)
    check_less_equal("h_front", h_front, "h_crack", h_crack)
    check_less_equal("h_crack", h_crack, "h_far", h_far)

    w, a = half_width, crack_radius
    x0 = -w if half else 0.0
    occ = model.occ
    block = occ.addBox(x0, 0.0, -w, w - x0, w, 2.0 * w)
    disk = occ.addDisk(0.0, 0.0, 0.0, a, a)
    cut = occ.addRectangle(-a if half else 0.0, 0.0, 0.0, 2.0 * a if half else a, a)
    part, _ = occ.intersect([(2, disk)], [(2, cut)])
    # The block comes out as one volume with the part of the disk embedded in it (it touches
    # the symmetry planes but does not cut the volume in two); children[1] is its image.
    _, children = occ.fragment([(3, block)], part)
    occ.synchronize()
    crack = [tag for _, tag in children[1]]
    sides = {
        PennyBlockFacets.XMIN if half else PennyBlockFacets.XSYM: (0, x0),
        PennyBlockFacets.YSYM: (1, 0.0),
        PennyBlockFacets.XMAX: (0, w),
        PennyBlockFacets.YMAX: (1, w),
        PennyBlockFacets.BOTTOM: (2, -w),
        PennyBlockFacets.TOP: (2, w),
    }
    add_physical_groups(
        model, PennyBlockCells.DOMAIN, sides, interior={PennyBlockFacets.CRACK: crack}
    )

    # Distances: to the crack disk, sqrt(max(r - a, 0)^2 + z^2) = sqrt(((|r - a| + r - a) / 2)^2
    # + z^2), and to the front circle, sqrt((r - a)^2 + z^2), with r = sqrt(x^2 + y^2).
    am = matheval_number(a)
    r = "Sqrt(x^2+y^2)"
    beyond = f"((Fabs({r}-{am})+{r}-{am})/2)"
    size = set_graded_size(
        model,
        f"Sqrt({beyond}^2+z^2)",
        size_min=h_crack,
        size_max=h_far,
        dist_min=0.5 * a,
        grading=grading,
    )
    if h_front < h_crack:  # the smaller of that size and h_front + grading * (distance to front)
        refine_near(
            model,
            size,
            f"Sqrt(({r}-{am})^2+z^2)",
            size_min=h_front,
            size_max=h_far,
            grading=grading,
        )
    import gmsh

    gmsh.option.setNumber("Mesh.Algorithm", 6)
    gmsh.option.setNumber("Mesh.Algorithm3D", 1)
    model.mesh.generate(3)
