"""Hertz line contact (2D) and sphere contact (3D) against the closed form at the computed force
(docs/verification.md section 1)."""

import pytest

from contactfx.scenes import Numerics
from contactfx.scenes.hertz import Hertz2D, Hertz2DParams, Hertz3D, Hertz3DParams

# Default 2D scene: R = 1, depth 1.5e-3 gives a = 0.026 (a/R < 0.03, block 1 x 1, L/a = 38),
# h = 3e-3 in the contact zone: about 9 elements across a.
COARSE = Hertz2DParams()
FINE = Hertz2DParams(h_contact=1.5e-3, refine_half_width=0.04)

METHODS = [
    Numerics(method="nitsche", theta=1),
    Numerics(method="nitsche", theta=0),
    Numerics(method="nitsche", theta=-1),
    Numerics(method="penalty"),
]


def _ids(num):
    return f"{num.method}-theta{num.theta}" if num.method == "nitsche" else num.method


@pytest.mark.parametrize("degree", [1, 2])
@pytest.mark.parametrize("num", METHODS, ids=_ids)
def test_hertz2d_coarse(num, degree):
    num = Numerics(**{**num.__dict__, "degree": degree})
    ref = Hertz2D(COARSE).run(num, verbose=False).reference
    # the contact edge within a quarter element: |a_h - a| <= h / 4 (the zero contour of
    # p - (E* / h) g between the last closed node and the first open one)
    assert ref["a_error_over_h"] <= 0.25
    # about 10 elements across a: a few percent on the peak (docs/verification.md section 1)
    assert ref["p0_rel_error"] < 0.03


@pytest.mark.parametrize("num", METHODS[:1] + METHODS[3:], ids=_ids)
def test_hertz2d_fine(num):
    ref = Hertz2D(FINE).run(num, verbose=False).reference
    # about 18 elements across a: 1 % on the peak pressure
    assert ref["a_error_over_h"] <= 0.25
    assert ref["p0_rel_error"] < 0.01


@pytest.mark.parametrize("degree", [1, 2])
def test_nitsche_and_vi_agree(degree):
    nit = Hertz2D(COARSE).run(Numerics(method="nitsche", degree=degree), verbose=False)
    vi = Hertz2D(COARSE).run(Numerics(method="vi", degree=degree), verbose=False)
    # independent enforcement (bounds at the nodes vs Nitsche at quadrature points), same mesh:
    # they agree to the discretisation error of either (a few tenths of a percent in force,
    # the contact edge to a quarter element, the peak to 1.5 %)
    assert vi.force == pytest.approx(nit.force, rel=5e-3)
    assert abs(vi.contact_size - nit.contact_size) <= 0.25 * COARSE.h_contact
    assert vi.peak_pressure == pytest.approx(nit.peak_pressure, rel=1.5e-2)


def test_hertz3d():
    result = Hertz3D(Hertz3DParams(h_contact=0.015)).run(Numerics(), verbose=False)
    ref = result.reference
    # quarter model, about 7 tetrahedra across a = 0.1: 5 % on p0 (docs/verification.md
    # section 1), the contact radius within h / 4
    assert ref["a_error_over_h"] <= 0.25
    assert ref["p0_rel_error"] < 0.05


@pytest.mark.parametrize(
    "num",
    [Numerics(method="al-uzawa"), Numerics(method="al-ssn"), Numerics(method="al-ssn", ncp="fb")],
    ids=["al-uzawa", "al-ssn-min", "al-ssn-fb"],
)
def test_augmented_lagrangian_hertz2d(num):
    res = Hertz2D(COARSE).run(num, verbose=False)
    nit = Hertz2D(COARSE).run(Numerics(method="nitsche"), verbose=False)
    ref = res.reference
    # the same discretisation bounds as Nitsche (a within h/4, p0 within 3 %)
    assert ref["a_error_over_h"] <= 0.25
    assert ref["p0_rel_error"] < 0.03
    # and the same force as Nitsche on this mesh to its discretisation error
    assert res.force == pytest.approx(nit.force, rel=5e-3)
    # the constraint holds at the nodes to solver tolerance, not O(1/r): nodal penetration
    # below 1e-9 of the indentation depth
    assert res.max_penetration < 1e-9 * COARSE.depth


@pytest.mark.parametrize(
    "scene, num",
    [
        (Hertz3D(Hertz3DParams()), Numerics(solver="gamg")),
        (Hertz3D(Hertz3DParams()), Numerics(theta=-1, solver="gamg")),
        (Hertz3D(Hertz3DParams()), Numerics(method="penalty", solver="gamg")),
        (Hertz2D(COARSE), Numerics(solver="gamg", steps=2)),
    ],
    ids=["hertz3d-nitsche", "hertz3d-skew", "hertz3d-penalty", "hertz2d-nitsche-2-steps"],
)
def test_iterative_solver_matches_lu(scene, num):
    """GMRES + AMG in an inexact Newton method (Eisenstat-Walker forcing, the AMG hierarchy
    kept across Newton iterations) converges to the same discrete solution as Newton with
    MUMPS LU."""
    res = scene.run(num, verbose=False)
    lu = scene.run(Numerics(**{**num.__dict__, "solver": "lu"}), verbose=False)
    # both Newton solves stop at a relative residual of 1e-10 (the inexact one's last Krylov
    # solves are tight near the solution): the contact quantities agree to well within 1e-7
    for key in ("force", "contact_size", "peak_pressure"):
        assert getattr(res, key) == pytest.approx(getattr(lu, key), rel=1e-7), key
    assert res.ksp_iterations > res.newton_iterations  # GMRES really ran (LU: one each)
