"""The smooth surface of P1 facets from their nodal normals (:mod:`contactfx.contact.smoothing`):
the deviation from the facets against the circle's and the sphere's sagittas, flat facets and
corners untouched, and the dual-basis moments against quadrature."""

from __future__ import annotations

import numpy as np
import pytest

from contactfx.contact.mortar import dual_triangle
from contactfx.contact.pair import facet_normals
from contactfx.contact.projection import gauss_triangle
from contactfx.contact.smoothing import bulges, conforming, deviation, dual_moments, mean_curvature


def _arc(R: float, n: int, turn: float = np.pi / 2):
    """n chords of a circle of radius R over ``turn`` (counter-clockwise: the disc on the left,
    the facet normals outward) and the exact normals at their ends."""
    th = np.linspace(0.0, turn, n + 1)
    pts = R * np.stack([np.cos(th), np.sin(th)], axis=1)
    x = np.stack([pts[:-1], pts[1:]], axis=1)
    return x, x / R


@pytest.mark.parametrize("n", [4, 16])
def test_circle_chord_deviation_is_the_arcs(n):
    R = 1.5
    x, normals = _arc(R, n)
    mid = deviation(bulges(x, normals), np.array([0.5, 0.5]))
    # the arc's sagitta R (1 - cos(theta / 2)) = L^2 / (8 R) (1 + O(theta^2)): the quadratic
    # with the exact end slopes tan(theta / 2) has L tan(theta / 2) / 4 at the middle, the
    # sagitta's relative error theta^2 / 8 (2.4 % at 4 chords on the quarter, 0.15 % at 16)
    theta = np.pi / 2 / n
    sagitta = R * (1.0 - np.cos(theta / 2))
    assert mid == pytest.approx(np.full(n, sagitta), rel=theta**2 / 6)
    assert np.all(mid > 0.0)  # the convex body's arc lies outside its chords
    # a concave surface (the bore: the body outside the circle, facets reversed) bulges inward
    inner = deviation(bulges(x[:, ::-1], -normals[:, ::-1]), np.array([0.5, 0.5]))
    assert inner == pytest.approx(-mid, rel=1e-12)


def test_sphere_triangle_centroid_deviation():
    """A small equilateral triangle inscribed in a sphere with the exact normals: at the
    centroid the sphere is r_c^2 / (2 R) = L^2 / (6 R) above the plane (to O(L^4))."""
    R, L = 2.0, 0.05
    rc = L / np.sqrt(3.0)
    angles = np.array([0.0, 2 * np.pi / 3, 4 * np.pi / 3])
    flat = np.stack([rc * np.cos(angles), rc * np.sin(angles)], axis=1)
    z = np.sqrt(R**2 - rc**2)
    x = np.concatenate([flat, np.full((3, 1), z)], axis=1)[None]
    A = bulges(x, x / R)
    centroid = deviation(A, np.full(3, 1.0 / 3.0))[0]
    assert centroid == pytest.approx(R - z, rel=1e-3)


def test_flat_facets_corners_and_junctions_are_untouched():
    # a flat strip along +y (facet normals +x): the nodal normals are the facets'
    x = np.array([[[0.0, 0.0], [0.0, 1.0]], [[0.0, 1.0], [0.0, 2.0]]])
    assert facet_normals(x) == pytest.approx(np.array([[1.0, 0.0], [1.0, 0.0]]))
    n = np.tile([[1.0, 0.0]], (2, 2, 1))
    assert np.all(bulges(x, n) == 0.0)
    # both ends turned alike: at 45 degrees (a square's corners, the averaged normal between
    # two facets at right angles) beyond FEATURE_ANGLE, the corners keep their chord; at 20
    # degrees a coarse curve, smoothed
    for angle, smoothed in ((45.0, False), (20.0, True)):
        a = np.radians(angle)
        ends = np.array([[[np.cos(a), -np.sin(a)], [np.cos(a), np.sin(a)]]])
        assert np.any(bulges(x[:1], ends) != 0.0) == smoothed
    # a flat facet whose end meets a curve (the averaged normal tilted there by 9 degrees):
    # its other end straight, no bulge (a punch's flat face next to its rounded edge)
    tilt = np.radians(9.0)
    ends = np.array([[[1.0, 0.0], [np.cos(tilt), -np.sin(tilt)]]])
    assert np.all(bulges(x[:1], ends) == 0.0)
    # ... and a convex curve's facet, both ends turned away from it, bulges out (A = L s)
    both = np.array([[[np.cos(tilt), -np.sin(tilt)], [np.cos(tilt), np.sin(tilt)]]])
    assert bulges(x[:1], both)[0, 0] == pytest.approx(np.tan(tilt), rel=1e-12)


def test_dual_moments_against_quadrature():
    """int psi_i d over a facet: the closed forms (L A / 12 on a segment; |T| / 20 and
    -|T| / 60 on a triangle) against a degree-6 rule and Gauss on the segment."""
    rng = np.random.default_rng(3)
    x2 = rng.random((4, 2, 2))
    A2 = rng.random((4, 1))
    xi, w = np.polynomial.legendre.leggauss(4)
    xi, w = 0.5 * (xi + 1.0), 0.5 * w
    lam = np.stack([1.0 - xi, xi], axis=1)
    psi = np.stack([2.0 - 3.0 * xi, 3.0 * xi - 1.0], axis=1)
    L = np.linalg.norm(x2[:, 1] - x2[:, 0], axis=1)
    ref = np.einsum("q,fq,qi->fi", w, deviation(A2[:, None, :], lam[None]), psi) * L[:, None]
    assert dual_moments(x2, A2) == pytest.approx(ref, rel=1e-12)

    x3 = rng.random((4, 3, 3))
    A3 = rng.random((4, 3))
    pts, wts = gauss_triangle(6)
    area = 0.5 * np.linalg.norm(np.cross(x3[:, 1] - x3[:, 0], x3[:, 2] - x3[:, 0]), axis=1)
    d = deviation(A3[:, None, :], pts[None])
    ref3 = np.einsum("q,fq,qi->fi", wts, d, dual_triangle(pts)) * area[:, None]
    assert dual_moments(x3, A3) == pytest.approx(ref3, rel=1e-12)


def test_mean_curvature_and_conforming_pairs():
    """The mean curvature of an arc's chords is 1 / R (convex > 0, concave < 0); a fit (radii
    1.5 and 1.495, opposite sides) conforms, two convex cylinders and a cylinder on a flat
    face do not."""
    from mpi4py import MPI

    comm = MPI.COMM_SELF
    x, normals = _arc(1.5, 32)
    convex = mean_curvature(comm, x, bulges(x, normals))
    # the chords' quadratic: 2 A / L^2 = 2 tan(theta / 2) / L = 1 / R (1 + O(theta^2))
    assert convex == pytest.approx(1.0 / 1.5, rel=1e-3)
    xb, nb = _arc(1.495, 32)
    bore = mean_curvature(comm, xb[:, ::-1], bulges(xb[:, ::-1], -nb[:, ::-1]))
    assert bore == pytest.approx(-1.0 / 1.495, rel=1e-3)
    assert conforming(bore, convex) and conforming(convex, bore)
    assert not conforming(convex, convex)
    assert not conforming(convex, 0.0) and not conforming(0.0, 0.0)


def test_flat_surface_is_flat_on_every_partition():
    """Straight facets whose nodal normals carry round-off (1e-16, of either sign: the same
    surface summed in another order on another partition) have a mean curvature of exactly
    0, so two flat faces are never read as a conforming pair by the round-off's signs (a
    problem file's patch test smoothed on one meshing and not on the other)."""
    from mpi4py import MPI

    comm = MPI.COMM_SELF
    s = np.linspace(0.0, 1.0, 9)
    x = np.stack([np.stack([s[:-1], np.zeros(8)], 1), np.stack([s[1:], np.zeros(8)], 1)], 1)
    rng = np.random.default_rng(1)
    for _ in range(5):
        normals = np.zeros((8, 2, 2))
        normals[..., 1] = -1.0
        normals[..., 0] = 1e-16 * rng.standard_normal((8, 2))
        normals /= np.linalg.norm(normals, axis=2)[..., None]
        A = bulges(x, normals)
        assert np.max(np.abs(A)) > 0.0  # the round-off is there
        assert mean_curvature(comm, x, A) == 0.0
        assert not conforming(mean_curvature(comm, x, A), -mean_curvature(comm, x, -A))
