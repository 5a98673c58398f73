"""Finite-strain bodies against a rigid obstacle: a contact patch test in uniaxial stress
(docs/verification.md section 15).

A block [-L/2, L/2] x [-H, 0] (plane strain, unstructured triangles) is pushed by a dead
(nominal) pressure p on its bottom face against the rigid frictionless plane y = 0; its left
face is a roller (u_x = 0), its right face free. The exact solution is homogeneous,
F = diag(l1, l2): the free sides give P11 = 0 and the bottom P22 = -p, two equations for
(l1, l2) from the strain energy alone (solved here with a NumPy energy and complex-step derivatives,
independently of UFL); the nominal contact pressure is p everywhere on the reference face, the
contact force p L, and P1 represents the solution exactly, so a consistent method reproduces
it to the solver's tolerance on any mesh. At p = 200 (E = 1000, nu = 0.3) the block shortens
by 16 % (neo-Hookean l2 = 0.844).

Measured (h = 0.1, two load steps):

    nitsche theta = 1, 0, -1, al-ssn   grad u error 2.1e-12 (|F - I| = 0.16), force and
                                       peak pressure 200 to 2.3e-11
    al-uzawa                           grad u error 1.5e-11, peak 7.6e-10 relative (its
                                       outer loop's tolerance)
    penalty (penalty = 10)             peak pressure +0.30 %: its stiffness kappa E / h
                                       follows the cell diameters' jitter (small strain on
                                       this block: +0.19 %)
    compliance                         peak +1.6 % (small strain: +1.0 %), likewise
    mixed u-p P2/P1, nu = 0.4999       grad u error 9e-15

Newton when a step inverts an element: a finite-strain energy is undefined at J = det F <= 0
(the neo-Hookean ln J), so such a step gives a NaN residual, SNES stops with
DIVERGED_FNORM_NAN and the load step is cut back; ``--inversion-check halve`` (the default at
finite strain) halves the step until no element inverts
(:class:`contactfx.driver.inversion.VolumeRatio`, ``ContactSNES.limit_steps``). Tested: the
sampled J of homogeneous stretches (P1, P2, mixed, axisymmetric), a first Newton step that
inverts elements at the contact edge of hertz2d (halved: one load step instead of a cut-back,
the same solution as eight load steps), and the diagnosis of an inversion that halving cannot
avoid.
"""

from __future__ import annotations

import dataclasses
import functools
import re
from pathlib import Path

import numpy as np
import pytest
import ufl
from mpi4py import MPI

from conftest import grad_error, psi
from contactfx import _compat
from contactfx.driver import setup as build_problem
from contactfx.io.xdmf import read_xdmf
from contactfx.meshes import RectangleFacets
from contactfx.scenes import Numerics
from contactfx.scenes._common import fix_component
from contactfx.scenes.hertz import Hertz2D
from contactfx.scenes.sliding_block import SlidingBlock
from contactfx.solvers.base import ConvergenceError

P = 200.0


def homogeneous_stretches(model: str, m, p: float, hoop: bool = False) -> np.ndarray:
    """(l1, l2) with P11 = 0 and P22 = -p under F = diag(l1, l2, 1) (plane strain) or, with
    ``hoop``, F = diag(l1, l2, l1) (a cylinder along its axis, (r, z, theta): P_tt = P_rr = 0
    by symmetry); P the complex-step derivative of psi (Squire and Trapp 1998,
    doi:10.1137/S003614459631241X). Linear: 1 + the small-strain strains (hoop only)."""
    if model == "linear":
        assert hoop, "the plane-strain patch uses finite-strain models"
        return np.array([1.0 + m.nu * p / m.E, 1.0 - p / m.E])

    def residual(lam):
        def energy(a, b):
            return psi(model, m, np.diag([a, b, lam[0] if hoop else 1.0]).astype(complex))

        e = 1e-30  # complex step: d psi / d l = Im psi(l + i e) / e, exact to round-off
        P11 = energy(lam[0] + 1j * e, lam[1]).imag / e
        P22 = energy(lam[0], lam[1] + 1j * e).imag / e
        return np.array([P11, P22 + p])

    lam = np.array([1.0, 1.0])
    for _ in range(30):  # Newton with a difference Jacobian
        r = residual(lam)
        Jm = np.column_stack([(residual(lam + d) - r) / 1e-7 for d in np.eye(2) * 1e-7])
        lam = lam - np.linalg.solve(Jm, r)
    # round-off of the energy's terms, the largest lambda (ln J)^2
    assert np.linalg.norm(residual(lam)) < 1e-12 * p + 1e-15 * m.lmbda
    return lam


class UniaxialBlock(SlidingBlock):
    """The sliding block with a roller on its left face instead of its bottom: a homogeneous
    uniaxial stress state; at every converged step it records the L2 error of grad u against
    the exact F - I (the in-plane block; an axisymmetric subclass's hoop stretch follows)."""

    name = "uniaxial-block"

    def dirichlet(self, V, facet_tags):
        return [fix_component(V, facet_tags, RectangleFacets.LEFT, 0)]

    def on_step(self, problem, solver, load, quantities) -> None:
        material = self.material_used = problem.material
        model = material.name if material.finite_strain else "linear"
        p = min(2.0 * load, 1.0) * self.p.pressure
        l1, l2 = homogeneous_stretches(model, material, p, hoop=self.axisymmetric)
        area = (0.5 if self.axisymmetric else 1.0) * self.p.width * self.p.height
        err = grad_error(problem, ufl.dx, l1, l2) / np.sqrt(area)
        self.grad_error = err / np.hypot(l1 - 1.0, l2 - 1.0)


PARAMS = dataclasses.replace(UniaxialBlock.Params(), pressure=P, shift=0.0, h=0.1)


class UniaxialCylinder(UniaxialBlock):
    """The block as a body of revolution: the cylinder r < L/2, -H < z < 0 (its section
    [0, L/2] x [-H, 0], the roller on r = 0 the axis) pushed by the dead pressure p on its
    bottom against the plane; the exact state is the homogeneous uniaxial stress
    F = diag(l1, l2, l1) in (r, z, theta), u_r = (l1 - 1) r."""

    name = "uniaxial-cylinder"
    axisymmetric = True
    symmetry = 2.0 * np.pi

    def mesh_builder(self):
        builder, gdim = super().mesh_builder()
        return functools.partial(builder, x0=0.0, refine_x0=0.0), gdim

    def contact_size(self, measure: float) -> float:
        return float(np.sqrt(measure / np.pi))

    def reference(self, force: float) -> dict[str, float]:
        return {"force": self.p.pressure * np.pi * (0.5 * self.p.width) ** 2}


def solve(comm=MPI.COMM_WORLD, pressure=P, **numerics):
    num = Numerics(**{"friction": "none", "mu": 0.0, "steps": 2, **numerics})
    scene = UniaxialBlock(dataclasses.replace(PARAMS, pressure=pressure))
    result = scene.run(num, comm=comm, verbose=False)
    return scene, result


EXACT = [
    ("nitsche", {"theta": 1}),
    ("nitsche", {"theta": 0}),
    ("nitsche", {"theta": -1}),
    ("al-ssn", {}),
]


#: (model, pressure): Saint Venant-Kirchhoff at 100, where l2 = 0.89: at 200 (l2 = 0.68) its
#: nominal stress is near its compressive maximum (the energy is not polyconvex) and a second
#: equilibrium exists (l2 = 0.46), which the second step's secant predictor reaches
MODELS = [("neo-hookean", P), ("mooney-rivlin:c10=150,c01=40", P), ("svk", 100.0)]


@pytest.mark.parametrize("model, pressure", MODELS)
@pytest.mark.parametrize("method, options", EXACT)
def test_uniaxial_patch_exact(model, pressure, method, options):
    scene, res = solve(pressure=pressure, method=method, material=model, **options)
    # a consistent method on a P1-exact solution: the solver's tolerance (Newton to 1e-10
    # relative; measured 2e-12 on grad u, 2e-11 on the pressure)
    assert scene.grad_error < 1e-9
    assert res.force == pytest.approx(pressure * PARAMS.width, rel=1e-9)
    assert res.peak_pressure == pytest.approx(pressure, rel=1e-9)


def test_finite_strain_fields(tmp_path):
    comm = MPI.COMM_WORLD
    out = Path(comm.bcast(str(tmp_path), root=0))
    num = Numerics(method="nitsche", friction="none", mu=0.0, steps=2, material="neo-hookean")
    scene = UniaxialBlock(PARAMS)
    scene.run(num, comm=comm, out=out, verbose=False)
    l1, l2 = homogeneous_stretches("neo-hookean", scene.material_used, P)
    body = read_xdmf(out / f"{scene.name}.xdmf", step=1)["cell_data"]
    surface = read_xdmf(out / f"{scene.name}_surface.xdmf", step=1)["point_data"]
    # the homogeneous state, exact in P1 (to the solver's tolerance, 1e-10): J = l1 l2, the
    # Cauchy stress sigma_yy = P22 l2 / J = -p / l1 (sigma_xx = 0), the nominal pressure p
    # and the Cauchy pressure on the deformed face p / l1 (its length grew by l1)
    np.testing.assert_allclose(body["volume_ratio"], l1 * l2, rtol=1e-9)
    sigma = body["cauchy_stress"].reshape(-1, 3, 3)
    np.testing.assert_allclose(sigma[:, 1, 1], -P / l1, rtol=1e-9)
    np.testing.assert_allclose(sigma[:, 0, 0], 0.0, atol=1e-9 * P)
    np.testing.assert_allclose(surface["contact_pressure"], P, rtol=1e-9)
    np.testing.assert_allclose(surface["contact_pressure_current"], P / l1, rtol=1e-9)


@pytest.mark.parametrize(
    "model, options",
    [
        ("linear", {}),
        ("neo-hookean", {}),
        ("mooney-rivlin:c10=150,c01=40", {}),
        ("neo-hookean:E=1000,nu=0.4999", {"degree": 2, "formulation": "mixed-up"}),
    ],
)
@pytest.mark.parametrize("method", ["nitsche", "penalty"])
def test_axisymmetric_patch(model, options, method):
    scene = UniaxialCylinder(PARAMS)
    num = Numerics(friction="none", mu=0.0, steps=2, method=method, material=model, **options)
    res = scene.run(num, verbose=False)
    # the weight r in every integral and the hoop term: the force is 2 pi int p r dr =
    # p pi (L/2)^2 (equilibrium, exact); Nitsche reproduces the homogeneous state to the solver's
    # tolerance (measured 1e-12), penalty's stiffness follows the facets' jitter (as in
    # plane strain, test_uniaxial_patch_stiffness_methods)
    assert res.force == pytest.approx(P * np.pi * (0.5 * PARAMS.width) ** 2, rel=1e-9)
    if method == "nitsche":
        assert scene.grad_error < 1e-9
        assert res.peak_pressure == pytest.approx(P, rel=1e-9)
    else:
        assert abs(res.peak_pressure / P - 1.0) < 5e-3


def test_uniaxial_patch_uzawa():
    scene, res = solve(method="al-uzawa", material="neo-hookean")
    # Uzawa's outer loop stops at its multiplier tolerance: measured 1.5e-11 on grad u and
    # 7.6e-10 on the peak pressure; bound 1e-8 (its r-scaled tolerance, contact.augmented_*)
    assert scene.grad_error < 1e-8
    assert res.peak_pressure == pytest.approx(P, rel=1e-8)


@pytest.mark.parametrize("method, bound", [("penalty", 5e-3), ("compliance", 2.5e-2)])
def test_uniaxial_patch_stiffness_methods(method, bound):
    _, res = solve(method=method, material="neo-hookean")
    # the force is equilibrium (exact); the pressure follows the stiffness kappa E / h of
    # each facet, whose cell diameters jitter on this unstructured mesh: measured +0.30 %
    # (penalty) and +1.6 % (compliance), as in small strain (+0.19 %, +1.0 %)
    assert res.force == pytest.approx(P * PARAMS.width, rel=1e-9)
    assert abs(res.peak_pressure / P - 1.0) < bound


def test_uniaxial_patch_mixed_near_incompressible():
    scene, res = solve(
        method="nitsche",
        material="neo-hookean:E=1000,nu=0.4999",
        degree=2,
        formulation="mixed-up",
    )
    # P2/P1 Taylor-Hood with the pressure p = -lambda ln J: exact (measured 9e-15)
    assert scene.grad_error < 1e-9
    assert res.peak_pressure == pytest.approx(P, rel=1e-9)


@pytest.mark.parametrize("method", ["nitsche", "al-ssn"])
def test_coulomb_gross_slip(method):
    # the sliding block pressed by p = 100 (10 % shortening, neo-Hookean) and dragged 0.3 by
    # the plane: the whole face slides, and Coulomb's law bounds every point's traction by
    # mu p, so Q = mu P (equilibrium, exact on any mesh; measured 30 / 30 to 1e-15)
    params = dataclasses.replace(SlidingBlock.Params(), pressure=100.0, shift=0.3)
    num = Numerics(method=method, friction="coulomb", mu=0.3, steps=10, material="neo-hookean")
    res = SlidingBlock(params).run(num, verbose=False)
    q = res.quantities.friction
    assert res.force == pytest.approx(100.0, rel=1e-9)
    assert abs(q.tangential_force[0]) == pytest.approx(0.3 * res.force, rel=1e-8)
    assert q.slip_fraction == pytest.approx(1.0)


def test_small_load_limit_hertz2d():
    # a rigid cylinder (circle, R = 1) on a neo-Hookean and on a linear block, same mesh, at
    # three depths. The linear run's distance to Hertz is the discretisation (and finite
    # block) error; the neo-Hookean run's distance to the linear one is the geometric and
    # material nonlinearity, which vanishes with the load like a / R (docs/verification.md
    # section 15; measured peak pressure -0.24 %, -0.51 %, -0.87 % at a / R = 0.026, 0.059,
    # 0.133, i.e. 0.07-0.09 a / R)
    base = dataclasses.replace(
        Hertz2D.Params(), profile="circle", refine_half_width=0.15, h_contact=0.003
    )
    deviations = []
    for depth in (0.0015, 0.006, 0.024):
        runs = [
            Hertz2D(dataclasses.replace(base, depth=depth)).run(
                Numerics(material=m, steps=2), verbose=False
            )
            for m in ("linear", "neo-hookean")
        ]
        a_over_r = runs[1].contact_size / base.radius
        dp = runs[1].peak_pressure / runs[0].peak_pressure - 1.0
        deviations.append((a_over_r, dp))
    # the nonlinearity softens the peak, by at most 0.1 a / R, and more at larger loads
    assert all(-0.1 * a <= dp < 0.0 for a, dp in deviations)
    assert abs(deviations[0][1]) < abs(deviations[1][1]) < abs(deviations[2][1])
    # as the load goes to zero the two agree (0.24 % at a / R = 0.026)
    assert abs(deviations[0][1]) < 5e-3


@pytest.mark.ranks_compare
def test_serial_and_parallel_agree():
    _, serial = solve(MPI.COMM_SELF, method="nitsche", material="neo-hookean")
    _, parallel = solve(MPI.COMM_WORLD, method="nitsche", material="neo-hookean")
    assert serial.cells == parallel.cells
    # same mesh, same discrete problem, Newton converged to 1e-10: round-off only
    for key in ("force", "contact_size", "peak_pressure"):
        assert getattr(parallel, key) == pytest.approx(getattr(serial, key), rel=1e-8), key


@pytest.mark.parametrize("check", ["halve", "off"])
def test_inverted_element_is_named(check):
    # a cylinder (R = 1) pressed 0.9 deep into a unit-high neo-Hookean block: the elements at
    # the contact edge invert near a load factor of 0.89 whatever the step (measured: the
    # stepper cuts back to 1/64 increments, then gives up at load factor 0.892 with J = -0.24
    # at (-0.21, -0.05), or with the steps halved J = -2.4 at (-0.23, -0.07)). Halving cannot
    # avoid it: the message says how many halvings it made and that it took one step whole
    params = dataclasses.replace(
        Hertz2D.Params(),
        E=1.0,
        profile="circle",
        depth=0.9,
        h_contact=0.05,
        h_far=0.2,
        refine_half_width=0.5,
    )
    num = Numerics(material="neo-hookean", steps=1, inversion_check=check)
    with pytest.raises(ConvergenceError, match=r"an element inverted \(J .*\) at \(") as err:
        Hertz2D(params).run(num, verbose=False)
    assert 0.8 < err.value.load < 0.95
    assert err.value.reason.startswith("DIVERGED_FNORM_NAN")
    halved = re.search(
        r"step halvings: (\d+); steps not admissible, taken whole: 1\)", str(err.value)
    )
    assert (halved is not None and int(halved[1]) > 0) == (check == "halve")


#: a homogeneous stretch F = diag(L1, L2) (in plane)
L1, L2 = 1.1, 0.8


@pytest.mark.parametrize(
    "scene, options",
    [
        (UniaxialBlock, {}),
        (UniaxialBlock, {"degree": 2}),
        (UniaxialBlock, {"degree": 2, "formulation": "mixed-up"}),
        (UniaxialCylinder, {}),
    ],
)
def test_volume_ratio_of_a_homogeneous_stretch(scene, options):
    num = Numerics(friction="none", mu=0.0, material="neo-hookean", **options)
    problem = build_problem(scene(PARAMS), num)
    u = problem.state.sub(0) if problem.split else problem.state
    ratio = problem.volume_ratio
    x = _compat.petsc_vec(problem.state)
    hoop = L1 if scene.axisymmetric else 1.0  # 1 + u_r / r
    for l2 in (L2, -L2):
        u.interpolate(lambda X, l2=l2: np.vstack([(L1 - 1.0) * X[0], (l2 - 1.0) * X[1]]))
        problem.state.x.scatter_forward()
        # P1 and P2 interpolate the linear displacement exactly: J = l1 l2 (times the hoop
        # stretch l1) at every sample point of every cell, to round-off
        np.testing.assert_allclose(ratio.values(x), L1 * l2 * hoop, rtol=1e-12)
        assert ratio.positive(x) == (l2 > 0.0)
        j_min, where = ratio.smallest(x)
        assert j_min == pytest.approx(L1 * l2 * hoop, rel=1e-12)
        assert len(where) >= 2


def indentation(check: str, steps: int, comm=MPI.COMM_WORLD):
    """hertz2d in neo-Hookean material (E = 1000, nu = 0.3): a true circle R = 1 pressed
    0.006 deep (a / R = 0.06), h = 0.003 at the contact, Nitsche theta = 1."""
    params = dataclasses.replace(
        Hertz2D.Params(), profile="circle", depth=0.006, h_contact=0.003, refine_half_width=0.15
    )
    num = Numerics(
        material="neo-hookean", method="nitsche", theta=1, steps=steps, inversion_check=check
    )
    return Hertz2D(params).run(num, comm=comm, verbose=False)


def test_inverting_first_step_is_halved():
    # the indentation in one load step: Newton's first step from the unloaded block inverts
    # elements at the contact edge (with theta != 0 the tangent's term
    # p theta / gamma d(sigma_n(v))/du, p / gamma the penetration, is large while the
    # penetration is two elements deep; docs/verification.md section 15)
    unchecked = indentation("off", 1)
    checked = indentation("halve", 1)
    reference = indentation("off", 8)
    # without the check the first solve fails (measured: DIVERGED_FNORM_NAN at Newton's first
    # step) and the step is cut back to load 1/2: two load steps
    assert unchecked.cutbacks >= 1 and unchecked.halvings == 0
    # with it: the inverting step halved, no more cut-backs and no more Newton iterations.
    # Measured on Debian 12 (dolfinx 0.5, PETSc 3.18): one halving, no cut-back, one load
    # step, 10 Newton iterations against 12 + 8. On Debian 13 (dolfinx 0.9, PETSc 3.22) the
    # halved step is followed by a second inverting one, which the check takes whole (never
    # two halved steps in a row, _StepHalving.MAX_IN_A_ROW) and the step is cut back as
    # without the check (11 + 7 both): the halving's effect is the stack's Newton path, its
    # counting is tested on the bar (tests/unit/test_snes.py)
    assert checked.cutbacks <= unchecked.cutbacks
    assert checked.newton_iterations <= unchecked.newton_iterations
    assert reference.cutbacks == 0  # eight steps: no inversion on the way
    # halving shortens steps and leaves the discrete problem alone: the solution of eight
    # load steps (frictionless and hyperelastic: no path dependence), to Newton's tolerance
    # (rtol 1e-10 on the residual; measured 5e-13 on the force and the peak pressure, the
    # same contact size; bound 1e-8, well above round-off and Newton's stopping error)
    for key in ("force", "contact_size", "peak_pressure"):
        assert getattr(checked, key) == pytest.approx(getattr(reference, key), rel=1e-8), key
        assert getattr(unchecked, key) == pytest.approx(getattr(reference, key), rel=1e-8), key


@pytest.mark.ranks_compare
def test_inverting_first_step_serial_and_parallel_agree():
    serial = indentation("halve", 1, MPI.COMM_SELF)
    parallel = indentation("halve", 1, MPI.COMM_WORLD)
    # the same steps halved (the check's answer is collective: every rank scales alike) and
    # the same Newton path up to round-off
    assert [(s.newton, s.halvings, s.cutbacks) for s in parallel.steps] == [
        (s.newton, s.halvings, s.cutbacks) for s in serial.steps
    ]
    # same mesh, same discrete problem, Newton converged to 1e-10: round-off only
    for key in ("force", "contact_size", "peak_pressure"):
        assert getattr(parallel, key) == pytest.approx(getattr(serial, key), rel=1e-8), key


@pytest.mark.parametrize(
    "numerics, message",
    [
        ({"method": "vi", "material": "neo-hookean"}, "method vi is small-strain only"),
        (
            {"material": "svk", "degree": 2, "formulation": "mixed-up"},
            "svk has none",
        ),
        ({"material": "neo-hookean:mu=0"}, "mu must be > 0"),
    ],
)
def test_refused(numerics, message):
    with pytest.raises(ValueError, match=message):
        solve(**numerics)
