"""Two separately meshed bodies (docs/verification.md section 10): the mortar patch test in 2D
and 3D, Hertz contact of two elastic cylinders and of two spheres, serial against parallel,
the bad input a user can give, and the matching-mesh check of the two-body Nitsche coupling
against Nitsche on a fitted interface.

Run at 1 and 2 ranks (``make test``); the serial / parallel comparison solves the same mesh on
COMM_SELF and COMM_WORLD.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import dolfinx
import numpy as np
import pytest
import ufl
from mpi4py import MPI

from conftest import jacobian_check
from contactfx import _compat
from contactfx.contact.projection import gauss_segment
from contactfx.driver.fields import global_sum
from contactfx.driver.interface import InterfaceProblem
from contactfx.driver.two_body import TwoBodyProblem
from contactfx.mechanics.elasticity import Elastic
from contactfx.meshes import (
    JointColumnCells,
    JointColumnFacets,
    StackedBlocksCells,
    StackedBlocksFacets,
)
from contactfx.meshes._build import set_graded_size
from contactfx.params import param
from contactfx.scenes import Numerics
from contactfx.scenes._common import fix_component, gmsh_mesh
from contactfx.scenes.interface_base import InterfaceScene
from contactfx.scenes.two_body import HertzCylinders, HertzSpheres, PatchTest
from contactfx.scenes.two_body_base import TwoBodyScene, two_elastic


@pytest.mark.parametrize(
    "params",
    [
        dict(),
        dict(slave="lower"),
        dict(ratio=0.33, offset=0.7),
        dict(ratio=2.3, slave="lower", E_upper=200.0, nu_upper=0.45),
        dict(ratio=1.0, offset=0.0),  # coincident (but distinct) nodes
    ],
    ids=["upper-slave", "lower-slave", "fine-upper", "coarse-upper-soft", "matching"],
)
@pytest.mark.parametrize("ncp", ["min", "fb"])
def test_mortar_patch_test(params, ncp):
    scene = PatchTest(PatchTest.Params(**params))
    res = scene.run(Numerics(method="mortar", ncp=ncp), verbose=False)
    q = scene.p.pressure
    # exact integration of the mortar matrices makes the uniform state an exact discrete
    # solution: the contact pressure and force are q and q * width to round-off (Newton's
    # relative tolerance 1e-10 on a residual that starts at the load; 1e-10 leaves room)
    assert res.scores["pressure_deviation"] < 1e-10
    assert res.force == pytest.approx(q * scene.p.width, rel=1e-10)
    assert res.peak_pressure == pytest.approx(q, rel=1e-10)
    assert res.max_penetration < 1e-12 * scene.p.height


@pytest.mark.parametrize("slave", ["upper", "lower"])
@pytest.mark.parametrize("ratio", [0.7, 1.6])
def test_mortar_patch_test_3d(slave, ratio):
    # two boxes 1 x 1 x 0.5, tetrahedra of sizes 0.2 (lower) and 0.2 ratio (upper), the upper
    # box's contact nodes shifted (offset 0.3): non-matching triangulations of the contact face
    scene = PatchTest(PatchTest.Params(dim=3, h=0.2, ratio=ratio, slave=slave))
    res = scene.run(Numerics(method="mortar"), verbose=False)
    q, width = scene.p.pressure, scene.p.width
    # exact integration of the mortar matrices on the clip polygons (degree-2 rule on their fan
    # triangles) makes the uniform state sigma_zz = -q an exact discrete solution: pressure
    # and force are q and q width^2 to round-off (Newton's relative tolerance 1e-10 on a
    # residual that starts at the load; round-off of the clipping ~1e-15 per entry)
    assert res.scores["pressure_deviation"] < 1e-10
    assert res.force == pytest.approx(q * width**2, rel=1e-10)
    assert res.peak_pressure == pytest.approx(q, rel=1e-10)
    assert res.max_penetration < 1e-12 * scene.p.height
    # a flat touching start: the round-off gaps of either sign are a tie of the active set,
    # taken as closed, so the linear problem is solved by one Newton step
    assert res.newton_iterations == 1


def test_hertz_spheres_mortar():
    scene = HertzSpheres(HertzSpheres.Params())
    res = scene.run(Numerics(method="mortar"), verbose=False)
    ref = res.reference
    # default mesh: h = 0.0065 in the lower body, 0.0085 on the (slave) upper surface,
    # a ~ 0.1 (about 12 slave elements across the radius). The radius from the p^2
    # extrapolation of the outermost rings of closed nodes is within a fraction of h (5 % of a
    # = 0.6 h; measured 0.47 %); the peak is the largest nominal nodal pressure (nodal force
    # per reference area), within the scatter of the P1 tetrahedra's surface tractions on
    # unstructured, non-matching meshes (measured 0.38 %): the 3 %
    assert ref["a_rel_error"] < 0.05
    assert ref["p0_rel_error"] < 0.03
    assert res.newton_iterations <= 12


def test_hertz_cylinders_mortar():
    scene = HertzCylinders(HertzCylinders.Params())
    res = scene.run(Numerics(method="mortar"), verbose=False)
    ref = res.reference
    # default mesh: h = 2e-3 in the lower body, 1.5e-3 in the upper, a ~ 0.034 (17 lower
    # elements): the edge from the p^2 extrapolation is within a few % of h (2 % of a = 0.35 h;
    # measured 0.18 %), the peak nominal pressure at a node within the O(h^2 / a^2) = 0.3 %
    # interpolation error (measured 0.20 %; per current area it would be 1.2 % high, the
    # surface strain): the 1 %
    assert ref["a_rel_error"] < 0.02
    assert ref["p0_rel_error"] < 0.01
    assert res.newton_iterations <= 10


@pytest.mark.parametrize("dim", [2, 3])
def test_mortar_patch_test_searched_each_newton(dim):
    """The pressure is nominal (per reference area): the search at the deformed state (the
    upper block's contact face stretched by the lateral expansion nu (1 + nu) q / E) gives the
    uniform q as the search at the start does."""
    scene = PatchTest(PatchTest.Params(dim=dim, h=0.1 if dim == 2 else 0.2))
    res = scene.run(Numerics(method="mortar", search_update="newton"), verbose=False)
    # as test_mortar_patch_test (per current area the deviation is 3.9e-4 in 2D)
    assert res.scores["pressure_deviation"] < 1e-10
    assert res.contact_size == pytest.approx(
        scene.contact_size(scene.p.width ** (dim - 1)), rel=1e-10
    )


_COARSE_SPHERES = HertzSpheres.Params(h_contact=0.04, h_far=0.5, refine=0.2, depth=0.03)


@pytest.mark.ranks_compare
@pytest.mark.parametrize(
    "scene, num",
    [
        (PatchTest(PatchTest.Params(h=0.05)), Numerics(method="mortar")),
        (HertzCylinders(HertzCylinders.Params()), Numerics(method="mortar", ncp="fb")),
        (PatchTest(PatchTest.Params(dim=3, h=0.2)), Numerics(method="mortar")),
        (HertzSpheres(_COARSE_SPHERES), Numerics(method="nitsche")),
        (HertzSpheres(_COARSE_SPHERES), Numerics(method="penalty")),
    ],
    ids=[
        "patch-test",
        "hertz-cylinders-fb",
        "patch-test-3d",
        "hertz-spheres-nitsche",
        "hertz-spheres-penalty",
    ],
)
def test_two_body_serial_and_parallel_agree(scene, num):
    serial = scene.run(num, comm=MPI.COMM_SELF, verbose=False)
    parallel = scene.run(num, comm=MPI.COMM_WORLD, verbose=False)
    # the same discrete problem (the search gathers the master facets of every rank, and a
    # Gauss point equally far from two master facets takes the same one on every partition),
    # solved to a relative residual of 1e-10: forces and sizes agree to the solver tolerance.
    # (Before the partition-free tie-break, 3D Nitsche differed by 2e-7 between partitions.)
    for key in ("force", "contact_size", "peak_pressure"):
        assert getattr(parallel, key) == pytest.approx(getattr(serial, key), rel=1e-8), key


def test_distribution_keeps_the_contact_surfaces():
    """Distributed over the ranks, the contact surfaces keep every facet once: the owned
    slave and master facets of all ranks add up to the one-rank surfaces. (Whether the
    partitioner's cut, which varies from run to run, gives both ranks contact facets is not
    asserted: tests/unit/test_mortar.py checks the search across ranks on fixed mixed
    distributions.)"""
    from contactfx.driver import setup

    scene = HertzCylinders(HertzCylinders.Params())
    serial = setup(scene, Numerics(method="mortar"), comm=MPI.COMM_SELF)
    pb = setup(scene, Numerics(method="mortar"))
    counts = MPI.COMM_WORLD.allgather((len(pb.pair.slave), len(pb.pair.master)))
    assert len(serial.pair.slave) > 0 and len(serial.pair.master) > 0
    assert sum(s for s, _ in counts) == len(serial.pair.slave)
    assert sum(m for _, m in counts) == len(serial.pair.master)


@pytest.mark.parametrize(
    "scene, num, message",
    [
        (
            PatchTest(PatchTest.Params()),
            Numerics(method="vi"),
            "not offered between two meshed bodies",
        ),
        (PatchTest(PatchTest.Params()), Numerics(method="mortar", degree=2), "P1"),
    ],
    ids=["vi", "mortar-P2"],
)
def test_two_body_refuses(scene, num, message):
    with pytest.raises(ValueError, match=message):
        scene.run(num, verbose=False)


def test_mortar_refused_on_obstacles():
    from contactfx.scenes.hertz import Hertz2D

    scene = Hertz2D(Hertz2D.Params())
    with pytest.raises(ValueError, match="not offered against rigid obstacles"):
        scene.run(Numerics(method="mortar"), verbose=False)


def test_bad_pair_parameters():
    with pytest.raises(ValueError, match="slave"):
        PatchTest.Params(slave="middle")
    with pytest.raises(ValueError, match="nu"):
        PatchTest.Params(nu_upper=0.5)
    assert np.isfinite(PatchTest.Params().pressure)


@pytest.mark.parametrize(
    "num",
    [
        Numerics(method="nitsche", theta=1),
        Numerics(method="nitsche", theta=-1),
        Numerics(method="nitsche", theta=0, search_update="newton"),
        Numerics(method="penalty"),
    ],
    ids=["nitsche", "nitsche-skew", "nitsche-incomplete-newton-search", "penalty"],
)
def test_hertz_cylinders_gauss_point_methods(num):
    scene = HertzCylinders(HertzCylinders.Params())
    res = scene.run(num, verbose=False)
    ref = res.reference
    # as for mortar (default mesh, a / h ~ 17); penalty's O(p h / kappa) penetration adds
    # 0.5 % to the peak (measured 0.7 %), within the 1 % of p0
    assert ref["a_rel_error"] < 0.02
    assert ref["p0_rel_error"] < 0.01


@pytest.mark.parametrize(
    "method, dim, bound",
    [("nitsche", 2, 0.05), ("penalty", 2, 0.05), ("nitsche", 3, 0.05), ("penalty", 3, 0.08)],
)
def test_gauss_point_methods_patch_test(method, dim, bound):
    """Report, not exactness: quadrature at slave Gauss points does not integrate the master
    basis (kinked inside a slave facet) exactly, so the uniform pressure is not reproduced;
    the force is (the upper block rests on the contact alone: equilibrium)."""
    scene = PatchTest(PatchTest.Params(dim=dim, h=0.1 if dim == 2 else 0.2))
    res = scene.run(Numerics(method=method), verbose=False)
    # equilibrium of the upper block: force = q * width^(dim - 1) to the solver tolerance
    q, width = scene.p.pressure, scene.p.width
    assert res.force == pytest.approx(q * width ** (dim - 1), rel=1e-9)
    # measured 1.1-1.3 % in 2D (h = 0.1, ratio 0.7), 2.5 % (nitsche) and 4.5 % (penalty) in
    # 3D (h = 0.2); the bound catches a wrong coupling (a missing master term is O(1))
    assert 1e-6 < res.scores["pressure_deviation"] < bound
    # the flat touching start is a tie of the law's branches, taken as closed: the linear
    # problem is solved in one Newton step
    assert res.newton_iterations == 1


@pytest.mark.parametrize("dim", [2, 3])
def test_unbiased_nitsche_patch_force(dim):
    scene = PatchTest(PatchTest.Params(dim=dim, h=0.1 if dim == 2 else 0.2))
    res = scene.run(Numerics(method="nitsche", sides="unbiased"), verbose=False)
    # both bodies carry half of the contact terms; equilibrium holds for their sum
    q, width = scene.p.pressure, scene.p.width
    assert res.force == pytest.approx(q * width ** (dim - 1), rel=1e-9)


@pytest.mark.parametrize(
    "num",
    [
        Numerics(method="nitsche", theta=1),
        Numerics(method="penalty"),
        Numerics(method="mortar", friction="coulomb", mu=0.3),
    ],
    ids=["nitsche", "penalty", "mortar-coulomb"],
)
def test_hertz_spheres_coarse(num):
    """Hertz between two spheres on a coarse mesh (h_contact 0.013, 5.8k dofs)."""
    scene = HertzSpheres(HertzSpheres.Params(h_contact=0.013))
    res = scene.run(num, verbose=False)
    ref = res.reference
    # a / h ~ 8 on the lower surface (6 on the slave): the radius from the outer rings is
    # within about 0.3 h (measured 2.4 % nitsche, 0.30 % mortar with Coulomb); the peak is the
    # largest of scattered nodal pressures (measured 2.4 % nitsche, 1.9 % penalty, 1.98 %
    # mortar with Coulomb): the 3 %
    assert ref["a_rel_error"] < 0.05
    assert ref["p0_rel_error"] < 0.03
    if num.friction == "coulomb":
        # |lambda_T| <= mu (lambda - c g) holds exactly; against mu lambda it holds to the
        # weighted gaps of the closed nodes, zero to the solver's tolerance (measured 1.3e-8
        # relative: the gap rows converge to the residual tolerance 1e-10 times c)
        assert res.friction.excess < 1e-6


def _check_both_friction_branches(num, c) -> None:
    """Closed points in stick and in slip are both present (Coulomb)."""
    sticks = [c.stick[c.xi > 0]] if num.method == "mortar" else [s[3][s[0] > 0] for s in c.state]
    comm = MPI.COMM_WORLD
    assert comm.allreduce(any(np.any(s) for s in sticks), op=MPI.LOR)
    assert comm.allreduce(any(np.any(~s) for s in sticks), op=MPI.LOR)


@pytest.mark.parametrize(
    "num",
    [
        Numerics(method="nitsche", theta=1),
        Numerics(method="nitsche", theta=-1, sides="unbiased"),
        Numerics(method="penalty"),
        Numerics(method="mortar", ncp="fb"),
        Numerics(method="mortar"),
        Numerics(method="nitsche", friction="coulomb", mu=0.3),
        Numerics(method="nitsche", theta=0, sides="unbiased", friction="coulomb", mu=0.5),
        Numerics(method="mortar", friction="coulomb", mu=0.3),
    ],
    ids=[
        "nitsche",
        "unbiased-skew",
        "penalty",
        "mortar-fb",
        "mortar",
        "nitsche-coulomb",
        "unbiased-incomplete-coulomb",
        "mortar-coulomb",
    ],
)
def test_coupling_jacobian_is_consistent(num):
    """J du against the central difference of the residual at a state with open and closed
    points, on a coarse hertz-cylinders mesh."""
    scene = HertzCylinders(HertzCylinders.Params(h_contact=0.01, refine=0.1, h_far=0.2))

    def displace(X, upper):
        # a pressed state: the upper body moved down by 0.004, and sideways: a little near
        # the first contact point (stick: gamma |du_T| < mu P), much farther out (slip; the
        # mortar's nodal bound mu (lambda - c g) is larger than the Nitsche bound at these
        # penetrations: a larger slip reaches it)
        u = np.zeros_like(X)
        u[upper, 1] = -4e-3
        far = 5e-3 if num.method == "mortar" else 1e-3
        u[upper, 0] = np.where(X[upper, 0] < 0.01, 1e-7, far)
        return u

    error, coupling, solver = jacobian_check(scene, num, displace)
    # the residual is piecewise linear in u for the min / max laws (a frozen projection,
    # linear elasticity): away from a switch of the active set the central difference is
    # exact up to round-off (measured 2e-11), a switch within eps du would show as an O(1)
    # error; Fischer-Burmeister is smooth: its central difference errs by O(eps^2) (measured
    # 4e-5 at eps = 1e-4), so a consistent Jacobian shows as second-order decay
    if num.friction == "coulomb":
        _check_both_friction_branches(num, coupling)
    e1 = error(1e-4)
    if num.method == "mortar" and num.ncp == "fb":
        assert error(2.5e-5) < e1 / 8.0 + 1e-9
    else:
        assert e1 < 1e-9
    solver.destroy()


@pytest.mark.parametrize(
    "num",
    [
        Numerics(method="nitsche", theta=1),
        Numerics(method="nitsche", theta=0, sides="unbiased"),
        Numerics(method="penalty"),
        Numerics(method="mortar"),
        Numerics(method="nitsche", theta=-1, friction="coulomb", mu=0.3),
        Numerics(method="mortar", friction="coulomb", mu=0.3),
    ],
    ids=[
        "nitsche",
        "unbiased-incomplete",
        "penalty",
        "mortar",
        "nitsche-coulomb",
        "mortar-coulomb",
    ],
)
def test_coupling_jacobian_is_consistent_3d(num):
    """The same in 3D, on the coarse stacked boxes: the upper box tilted into the lower one
    and, with friction, moved along x where x > 0.5 (stick on x < 0.5, slip beyond)."""
    scene = PatchTest(PatchTest.Params(dim=3, h=0.25))

    def displace(X, up):
        u = np.zeros_like(X)
        u[up, 2] = -1e-3 * (1.0 + X[up, 0])
        if num.friction == "coulomb":
            # gamma |du_T| against mu P: about 0 against 12 for x < 0.5 (stick), 40 against
            # 12 beyond (slip, in directions that vary with y), whatever the noise
            slide = X[up, 0] >= 0.5
            u[up, 0] = np.where(slide, 1e-3, 0.0)
            u[up, 1] = np.where(slide, 1e-3 * X[up, 1], 0.0)
        return u

    error, coupling, solver = jacobian_check(scene, num, displace)
    if num.friction == "coulomb":
        _check_both_friction_branches(num, coupling)
    # exact central differences up to round-off away from a switch of the active set or of
    # stick / slip (measured 1e-11 frictionless, 7e-11 with Coulomb, at 1 to 3 ranks): the
    # ball projection's curvature term, O(eps^2 |du|^2 / |z|^2), is far below that
    # A switch within eps du shows as an O(1) error: 8e-3 once at 2 ranks on Debian 13, where
    # the 2-rank partition varies from run to run and with it the nodes the seeded noise
    # moves. A consistent Jacobian then still matches at the smaller eps (measured 3e-11 to
    # 7e-11 at 2e-5, at 1 and 2 ranks), a wrong one at neither
    assert min(error(1e-4), error(2e-5)) < 1e-9
    solver.destroy()


class _Moved(PatchTest):
    """The patch test with the upper block moved up by ``lift`` (< 0: into the lower block),
    optionally without its roller (then nothing holds it but the contact)."""

    lift = 0.0
    roller = True

    def build_mesh(self, comm):
        mesh, facet_tags = super().build_mesh(comm)
        upper = self.cell_tags.indices[self.cell_tags.values == self.cells["upper"]]
        nodes = np.unique(
            mesh.geometry.dofmap.array.reshape(-1, 3)[upper]
            if hasattr(mesh.geometry.dofmap, "array")
            else mesh.geometry.dofmap[upper]
        )
        mesh.geometry.x[nodes, 1] += self.lift
        return mesh, facet_tags

    def dirichlet(self, V, facet_tags):
        bcs = super().dirichlet(V, facet_tags)
        return bcs if self.roller else bcs[:2]


def test_overlapping_bodies_refused():
    scene = _Moved(PatchTest.Params())
    scene.lift = -0.05  # half an element into the lower block
    with pytest.raises(ValueError, match="overlap by 0.05"):
        scene.run(Numerics(method="mortar"), verbose=False)


def test_unsupported_body_apart_refused():
    scene = _Moved(PatchTest.Params())
    scene.lift, scene.roller = 0.2, False
    with pytest.raises(ValueError, match="upper body has no support"):
        scene.run(Numerics(method="nitsche"), verbose=False)


#: the width of the upper box of :class:`_StripOnBox` (along x)
STRIP = 0.55


def _strip_on_box(
    model, *, width: float, h_lower: float, h_upper: float, h1: float, ratio: float, offset: float
) -> None:
    """gmsh builder: the stacked boxes of :func:`contactfx.meshes.two_body.stacked_boxes`
    (``offset`` 0) with the upper box a strip [0, STRIP] x [0, width] x [0, h_upper] on the
    lower box [0, width]^2 x [-h_lower, 0], whose top is split into two faces along the line
    x = STRIP: its facets tile [0, STRIP] x [0, width] exactly."""
    from contactfx.meshes import StackedBoxesCells as C
    from contactfx.meshes import StackedBoxesFacets as F
    from contactfx.meshes.two_body import (
        add_body_groups,
        faces_by_plane,
        generate_mesh,
        set_body_sizes,
    )

    assert offset == 0.0
    lower = model.occ.addBox(0.0, 0.0, -h_lower, width, width, h_lower)
    upper = model.occ.addBox(0.0, 0.0, 0.0, STRIP, width, h_upper)
    line = model.occ.addLine(
        model.occ.addPoint(STRIP, 0.0, 0.0), model.occ.addPoint(STRIP, width, 0.0)
    )
    # the lower box cut by the line: its top split into two faces along x = STRIP
    out, _ = model.occ.fragment([(3, lower)], [(1, line)])
    (lower,) = [tag for d, tag in out if d == 3]
    model.occ.synchronize()
    planes = {}
    for body, top, size in ((lower, 0.0, width), (upper, h_upper, STRIP)):
        low = body == lower
        planes[body] = faces_by_plane(
            model,
            3,
            body,
            {
                F.LOWER_X0 if low else F.UPPER_X0: (0, 0.0),
                F.LOWER_X1 if low else F.UPPER_X1: (0, size),
                F.LOWER_Y0 if low else F.UPPER_Y0: (1, 0.0),
                F.LOWER_Y1 if low else F.UPPER_Y1: (1, width),
                F.LOWER_BOTTOM if low else F.UPPER_BOTTOM: (2, -h_lower if low else 0.0),
                F.LOWER_TOP if low else F.UPPER_TOP: (2, top),
            },
        )
    add_body_groups(model, {C.LOWER: (lower, planes[lower]), C.UPPER: (upper, planes[upper])})
    set_body_sizes(
        model, 3, [(lower, h1, h1), (upper, ratio * h1, ratio * h1)], "0", dist_min=0.0, grading=1.0
    )
    generate_mesh(model, 3)


class _StripOnBox(PatchTest):
    """The 3D patch test with the upper box a strip x < STRIP (:func:`_strip_on_box`)."""

    def mesh_builder(self):
        builder, dim = super().mesh_builder()
        return functools.partial(_strip_on_box, **builder.keywords), dim


def test_slave_points_beyond_the_master_surface_unpaired():
    """Gauss-point Nitsche, the lower box's top the slave, the strip's bottom the master:
    the slave face reaches past the master's boundary edge x = STRIP (and meets the master's
    other edges on x = 0, y = 0, y = 1). At the state u_z = -q z / (lambda + 2 mu) in the
    lower box (sigma_zz = -q, its top in place) and the strip at rest, the gap is 0 and the
    law's pressure -sigma_n - gamma g = q at every paired point: the slave points under the
    strip are paired, those beyond its edge are not (their closest point on the master
    surface is on its boundary edge or at a vertex of it), and the contact force is q times
    the overlap area STRIP x width (the slave facets tile it exactly). Before the boundary
    edges were told from the interior ones in 3D, every point beyond was paired with a
    vertex of the edge, with the same pressure q: a force of q width^2."""
    scene = _StripOnBox(PatchTest.Params(dim=3, h=0.2, offset=0.0, slave="lower"))
    num = Numerics(method="nitsche", theta=1)
    E, nu, q = scene.p.E_lower, scene.p.nu_lower, scene.p.pressure
    strain = -q * (1.0 + nu) * (1.0 - 2.0 * nu) / (E * (1.0 - nu))  # -q / (lambda + 2 mu)

    def displace(X, up):
        u = np.zeros_like(X)
        u[~up, 2] = strain * X[~up, 2]
        return u

    _, coupling, solver = jacobian_check(scene, num, displace, noise=0.0)
    dr, points = coupling.dirs[0], coupling.points[0]
    X = np.einsum("qb,mbg->mqg", dr.qbary, dr.slave.X).reshape(-1, 3)
    under = X[:, 0] < STRIP
    # no Gauss point on the edge (the slave facets do not cross it)
    assert np.all(np.abs(X[:, 0] - STRIP) > 1e-3)
    comm = MPI.COMM_WORLD
    total = comm.allreduce(len(X), op=MPI.SUM)
    wrong = comm.allreduce(int(np.sum(points["paired"] != under)), op=MPI.SUM)
    beyond = comm.allreduce(int(np.sum(~under)), op=MPI.SUM)
    assert 0 < beyond < total and wrong == 0
    P = coupling.state[0][0]
    # the pressure q of the exact state at round-off (the P1 gradient of a linear field)
    assert np.allclose(P[under], q, rtol=1e-10, atol=0.0)
    assert np.all(P[~under] == 0.0)
    width = scene.p.width
    assert coupling.force() == pytest.approx(q * STRIP * width, rel=1e-10)
    solver.destroy()


def _sliding_coulomb(method: str = "nitsche"):
    from contactfx.scenes.two_body_2d import SlidingContact

    scene = SlidingContact(SlidingContact.Params(slide=0.05, h_contact=8e-3))
    return scene, SlidingContact.default_numerics(
        method=method, friction="coulomb", mu=0.3, steps=12
    )


@pytest.mark.parametrize("method", ["nitsche", "mortar"])
def test_sliding_contact_coulomb(method):
    scene, num = _sliding_coulomb(method)
    res = scene.run(num, verbose=False)
    f = res.friction
    # steady sliding (the drag is 6 contact half-widths): gross slip, Q = -mu P on the
    # dragged body. Q / P is the ratio of the force's x and y components: it differs from
    # mu by the tilt of the contact normals of the pressed, curved surface (the normal
    # pressure has an x component, the tangential traction a y one; measured 0.3 % for
    # nitsche and 0.4 % for mortar); 1 % as the issue asks
    assert f.slip_fraction == pytest.approx(1.0, abs=1e-12)
    assert res.scores["Q_over_P"] == pytest.approx(-0.3, rel=0.01)
    # in the contact's own frame the tangential traction is the bound: |t_T| = mu p at every
    # point, to the solver's tolerance (measured 1e-13)
    assert res.scores["tangential_over_bound"] == pytest.approx(1.0, abs=1e-8)
    # the traction is projected onto the Coulomb ball: no excess beyond round-off
    assert f.excess < 1e-10


@pytest.mark.ranks_compare
@pytest.mark.parametrize("method", ["nitsche", "mortar"])
def test_sliding_contact_coulomb_serial_and_parallel_agree(method):
    scene, num = _sliding_coulomb(method)
    serial = scene.run(num, comm=MPI.COMM_SELF, verbose=False)
    parallel = scene.run(num, comm=MPI.COMM_WORLD, verbose=False)
    # every step converged to the relative residual 1e-10: forces agree to the tolerance
    assert parallel.force == pytest.approx(serial.force, rel=1e-8)
    assert parallel.friction.tangential_force[0] == pytest.approx(
        serial.friction.tangential_force[0], rel=1e-8
    )


def test_mortar_slip_is_objective_under_translation():
    """A rigid translation of both bodies from the last converged state gives no weighted slip
    (the rows of M / D sum to 1 on the contact nodes), at any rank count."""
    from contactfx.driver import setup
    from contactfx.solvers.snes import ContactSNES

    scene = HertzCylinders(HertzCylinders.Params(h_contact=0.01, refine=0.1, h_far=0.2))
    pb = setup(scene, Numerics(method="mortar", friction="coulomb", mu=0.3))
    forms = pb.forms()
    solver = ContactSNES(
        pb.state, bulk=forms.bulk(), bcs=[], prefix="objective_", coupling=pb.coupling()
    )
    x = solver.u.x.petsc_vec if hasattr(solver.u.x, "petsc_vec") else solver.u.vector
    X = pb.layout.X.getArray().reshape(-1, 2)
    # the last converged state presses the bodies together; the new one moves both by c
    prev = np.zeros_like(X)
    prev[X[:, 1] > 0, 1] = -4e-3
    pb.prev.x.array[: prev.size] = prev.ravel()
    pb.prev.x.scatter_forward()
    shifted = prev + np.array([3e-3, -1e-3])
    x.getArray()[:] = shifted.ravel()
    x.ghostUpdate()
    solver._sync(x)
    coupling = solver.coupling
    # the search at the step's start (the converged state), then the residual at the shift
    coupling.update(pb.prev.x.array)
    F = solver.bulk.create_vector()
    solver._residual(None, x.copy(), F)
    rows = coupling.tangent_rows()[coupling.tmask]
    slip = coupling._g.getArray()[rows]
    n_closed = MPI.COMM_WORLD.allreduce(int(np.sum(coupling.xi > 0)), op=MPI.SUM)
    assert n_closed > 5  # a real contact zone
    # v_j = t_j . (c - sum_k M_jk / D_j c) = 0: round-off of coordinates of order 1
    assert MPI.COMM_WORLD.allreduce(float(np.max(np.abs(slip), initial=0.0)), op=MPI.MAX) < 1e-14
    solver.destroy()


# -- the matching-mesh check: two-body Nitsche against the fitted interface ------------------
#
# Two stacked blocks [0, L] x [0, H] and [0, L] x [H, 2 H] on one triangulation, solved as one
# body with a fitted interface (w = u + H a, contactfx.contact.interface) and as two bodies in
# contact (contactfx.contact.point_coupling). The lower block is meshed by gmsh (unstructured,
# graded along x), the upper block is its mirror image about y = H: the two cells of every
# interface facet are mirror images, so the interface's avg(h) and each slave cell's largest
# edge are the same number and both Nitsche parameters gamma = gamma0 E / h agree. The
# two-body mesh is the same mesh with the interface nodes duplicated for the upper cells.


def _mirrored_blocks(model, *, width: float, height: float, h: float, split: bool) -> None:
    """gmsh builder: the lower block [0, width] x [0, height] meshed with triangles
    (Frontal-Delaunay) of size h at x = 0 growing linearly to 2 h at x = width, the upper
    block its mirror image about y = height, both as discrete entities of a second model.
    ``split``: separate nodes on the interface for the upper cells (two bodies, tags
    :class:`StackedBlocksCells` / :class:`StackedBlocksFacets`), else one mesh with the
    interface as interior facets (:class:`JointColumnCells` / :class:`JointColumnFacets`)."""
    import gmsh

    model.occ.addRectangle(0.0, 0.0, 0.0, width, height)
    model.occ.synchronize()
    set_graded_size(model, "x", size_min=h, size_max=2.0 * h, dist_min=0.0, grading=h / width)
    gmsh.option.setNumber("Mesh.Algorithm", 6)
    model.mesh.generate(2)
    tags, xyz, _ = model.mesh.getNodes()
    order = np.argsort(tags)
    x = xyz.reshape(-1, 3)[order, :2]
    _, _, conn = model.mesh.getElements(2)
    cells = np.searchsorted(tags[order], np.asarray(conn[0], dtype=np.int64)).reshape(-1, 3)
    # the block's edges exactly on their lines (the mirror then keeps the interface at y = H)
    tol = 1e-9 * max(width, height)
    for c, value in ((0, 0.0), (0, width), (1, 0.0), (1, height)):
        x[np.abs(x[:, c] - value) < tol, c] = value
    model.remove()
    model.add("mirrored-blocks")

    # the lower block's boundary edges (the edges of one cell only), by side
    edges = np.sort(cells[:, [[0, 1], [1, 2], [2, 0]]].reshape(-1, 2), axis=1)
    uniq, count = np.unique(edges, axis=0, return_counts=True)
    boundary = uniq[count == 1]
    ends = x[boundary]  # (edges, 2, 2)
    lines = {"bottom": (1, 0.0), "top": (1, height), "left": (0, 0.0), "right": (0, width)}
    low = {k: boundary[np.all(ends[:, :, c] == v, axis=1)] for k, (c, v) in lines.items()}
    # the upper block: the nodes mirrored (on the interface the lower nodes themselves unless
    # split), the cells reoriented, bottom and top swapped
    n = len(x)
    on = np.zeros(n, dtype=bool) if split else x[:, 1] == height
    upper = np.where(on, np.arange(n), n + np.cumsum(~on) - 1)
    coords = np.vstack([x, np.column_stack([x[~on, 0], 2.0 * height - x[~on, 1]])])
    high = {k: upper[low[k]] for k in ("left", "right")}
    high["bottom"], high["top"] = upper[low["top"]], upper[low["bottom"]]
    for tag, cell_nodes, nodes in (
        (1, cells, np.arange(n)),
        (2, upper[cells[:, [0, 2, 1]]], np.arange(n, len(coords))),
    ):
        model.addDiscreteEntity(2, tag)
        xyz = np.column_stack([coords[nodes], np.zeros(len(nodes))])
        model.mesh.addNodes(2, tag, nodes + 1, xyz.ravel())
        model.mesh.addElementsByType(tag, 2, [], (cell_nodes + 1).ravel())
    if split:
        F = StackedBlocksFacets
        groups = {StackedBlocksCells.LOWER: [1], StackedBlocksCells.UPPER: [2]}
        curves = {
            F.LOWER_BOTTOM: [low["bottom"]],
            F.LOWER_RIGHT: [low["right"]],
            F.LOWER_TOP: [low["top"]],
            F.LOWER_LEFT: [low["left"]],
            F.UPPER_BOTTOM: [high["bottom"]],
            F.UPPER_RIGHT: [high["right"]],
            F.UPPER_TOP: [high["top"]],
            F.UPPER_LEFT: [high["left"]],
        }
    else:
        F = JointColumnFacets
        groups = {JointColumnCells.DOMAIN: [1, 2]}
        curves = {
            F.BOTTOM: [low["bottom"]],
            F.RIGHT: [low["right"], high["right"]],
            F.TOP: [high["top"]],
            F.LEFT: [low["left"], high["left"]],
            F.JOINT: [low["top"]],
        }
    for group, entities in groups.items():
        model.addPhysicalGroup(2, entities, group.value)
    for k, (group, parts) in enumerate(curves.items(), start=1):
        model.addDiscreteEntity(1, k)
        model.mesh.addElementsByType(k, 1, [], (np.vstack(parts) + 1).ravel())
        model.addPhysicalGroup(1, [k], group.value)


def _recording(kind):
    """The problem kind ``kind`` that leaves the problem it builds on its scene (``solved``),
    to read the solution after :meth:`Scene.run`."""

    class Recorded(kind):
        def __init__(self, scene, *args) -> None:
            super().__init__(scene, *args)
            scene.solved = self

    return Recorded


@dataclass(frozen=True)
class _StackParams(two_elastic(1000.0, 0.3)):
    width: float = param(1.0, "width L of the blocks", positive=True)
    height: float = param(0.5, "height H of each block", positive=True)
    h: float = param(0.05, "element size", positive=True)
    pressure: float = param(1.0, "q0: pressure q0 (1 + 2 x / L) on the top", positive=True)


def _top_load(p, v, ds, t, tag):
    """The pressure q(x) = q0 (1 + 2 x / L) on the facets ``tag`` (downwards)."""
    x = ufl.SpatialCoordinate(ds.ufl_domain())
    return -t * p.pressure * (1.0 + 2.0 * x[0] / p.width) * v[1] * ds(tag)


class _FittedStack(InterfaceScene):
    """The stacked blocks as one body with a fitted interface y = H, plain Signorini (no
    joint, no fluid): bottom on rollers, rollers on x = 0 and x = L, q(x) on the top."""

    name = "matching-fitted"
    summary = "stacked blocks, fitted interface"
    Params = _StackParams
    interface_tag = JointColumnFacets.JOINT
    problem = _recording(InterfaceProblem)

    def material(self) -> Elastic:
        return Elastic(self.p.E_lower, self.p.nu_lower)

    def build_mesh(self, comm):
        p = self.p
        return gmsh_mesh(
            comm, _mirrored_blocks, 2, self.name, width=p.width, height=p.height, h=p.h, split=False
        )

    def length_scale(self) -> float:
        return self.p.height

    def h_contact(self) -> float:
        return self.p.h

    def supports(self):
        F = JointColumnFacets
        return [(F.BOTTOM, 1), (F.LEFT, 0), (F.RIGHT, 0)]

    def side(self, x):
        return x[1] - self.p.height

    def frame(self):
        return np.array([0.0, self.p.height]), np.array([1.0, 0.0])

    def load(self, v, ds, t):
        return _top_load(self.p, v, ds, t, JointColumnFacets.TOP)

    def interface_reference(self, prof, q, friction):
        return {"min_pressure": float(np.min(prof.p))}


class _SplitStack(TwoBodyScene):
    """The same blocks as two bodies (the interface nodes duplicated), the same supports."""

    name = "matching-two-body"
    summary = "stacked blocks, two bodies"
    Params = _StackParams
    cells = {"lower": StackedBlocksCells.LOWER, "upper": StackedBlocksCells.UPPER}
    surfaces = {"lower": StackedBlocksFacets.LOWER_TOP, "upper": StackedBlocksFacets.UPPER_BOTTOM}
    problem = _recording(TwoBodyProblem)

    def build_mesh(self, comm):
        p = self.p
        builder = functools.partial(
            _mirrored_blocks, width=p.width, height=p.height, h=p.h, split=True
        )
        return self.mesh_of(comm, builder, 2)

    def h_contact(self) -> float:
        return self.p.h

    def dirichlet(self, V, facet_tags) -> list:
        f = StackedBlocksFacets
        return [fix_component(V, facet_tags, f.LOWER_BOTTOM, 1)] + [
            fix_component(V, facet_tags, tag, 0)
            for tag in (f.LOWER_LEFT, f.LOWER_RIGHT, f.UPPER_LEFT, f.UPPER_RIGHT)
        ]

    def load(self, v, ds, t):
        return _top_load(self.p, v, ds, t, StackedBlocksFacets.UPPER_TOP)


def _gather_rows(comm, rows: np.ndarray, keys: int, scale: float) -> np.ndarray | None:
    """This rank's rows gathered on rank 0, sorted by their first ``keys`` columns rounded to
    1e-9 ``scale`` (coordinates tabulated from different cells differ by round-off); None on
    the other ranks."""
    parts = comm.gather(rows, root=0)
    if comm.rank != 0:
        return None
    a = np.vstack(parts)
    k = np.round(a[:, :keys] / (1e-9 * scale)).astype(np.int64)
    return a[np.lexsort(k.T[::-1])]


def _cells(pb, height: float) -> np.ndarray:
    """Owned cells as rows (side, the vertices' coordinates in lexicographic order, rounded
    to 1e-9 height as in :func:`_gather_rows`): side -1 below the interface, +1 above."""
    V = pb.state.function_space
    mesh = V.mesh
    X = _compat.dof_coordinates(V)[:, :2]
    n = mesh.topology.index_map(mesh.topology.dim).size_local
    rows = []
    for c in range(n):
        xc = X[V.dofmap.cell_dofs(c)]
        key = np.round(xc / (1e-9 * height)).astype(np.int64)
        xc = xc[np.lexsort(key.T[::-1])]
        rows.append([np.sign(xc[:, 1].mean() - height), *xc.ravel()])
    return np.array(rows).reshape(-1, 7)


def _nodes_fitted(pb, height: float) -> np.ndarray:
    """Owned nodes as rows (side, x, y, w_x, w_y): w = u - a below and u + a above the
    interface (both rows at an interface node)."""
    V = pb.state.function_space
    n = V.dofmap.index_map.size_local
    X = _compat.dof_coordinates(V)[:n, :2]
    U = pb.state.x.array.reshape(-1, 4)[:n]
    u, a = U[:, :2], U[:, 2:]
    on = np.abs(X[:, 1] - height) < 1e-9 * height
    off = ~on
    side = np.sign(X[off, 1] - height)
    return np.vstack(
        [
            np.column_stack([side, X[off], u[off]]),
            np.column_stack([-np.ones(on.sum()), X[on], u[on] - a[on]]),
            np.column_stack([np.ones(on.sum()), X[on], u[on] + a[on]]),
        ]
    )


def _nodes_two_body(pb, scene) -> np.ndarray:
    """Owned nodes as rows (side, x, y, u_x, u_y), side -1 for the lower body, +1 upper."""
    V = pb.V
    n = V.dofmap.index_map.size_local
    X = _compat.dof_coordinates(V)[:n, :2]
    upper = np.zeros(len(pb.state.x.array) // 2, dtype=bool)
    tags = scene.cell_tags
    for c in tags.indices[tags.values == scene.cells["upper"]]:
        upper[V.dofmap.cell_dofs(c)] = True
    side = np.where(upper[:n], 1.0, -1.0)
    return np.column_stack([side, X, pb.state.x.array.reshape(-1, 2)[:n]])


def _gauss_pressure_ends(coupling) -> float:
    """The smallest value over the slave facets of both directions of the Nitsche argument
    -sigma_n - gamma g at the facets' ends, extrapolated from its two Gauss points (linear on
    a facet while the law is active); -inf when a Gauss point is open or unpaired.
    Collective."""
    q, _ = gauss_segment(2)
    least = np.inf
    for p, s in zip(coupling.points, coupling.state, strict=True):
        P = s[0].reshape(-1, 2)
        if not np.all(p["paired"]) or np.any(P <= 0.0):
            least = -np.inf
            continue
        slope = (P[:, 1] - P[:, 0]) / (q[1] - q[0])
        ends = np.stack([P[:, 0] - slope * q[0], P[:, 0] + slope * (1.0 - q[0])])
        least = min(least, float(ends.min(initial=np.inf)))
    return coupling.comm.allreduce(least, op=MPI.MIN)


def _matching_pair(theta: int, sides: str):
    """Solve the stacked blocks with Nitsche ``theta`` on the fitted interface and between two
    bodies (``sides``): (fitted summary, two-body summary, fitted scene, two-body scene, same
    cells and nodes, relative force difference, largest nodal displacement difference
    relative to the largest displacement); the last three on every rank."""
    params = _StackParams()
    fitted, split = _FittedStack(params), _SplitStack(params)
    res_i = fitted.run(Numerics(method="nitsche", theta=theta), verbose=False)
    res_b = split.run(Numerics(method="nitsche", theta=theta, sides=sides), verbose=False)
    comm = MPI.COMM_WORLD
    H = params.height
    L = params.width
    cells_i = _gather_rows(comm, _cells(fitted.solved, H), 7, H)
    cells_b = _gather_rows(comm, _cells(split.solved, H), 7, H)
    nodes_i = _gather_rows(comm, _nodes_fitted(fitted.solved, H), 3, L)
    nodes_b = _gather_rows(comm, _nodes_two_body(split.solved, split), 3, L)
    out = None
    if comm.rank == 0:
        # the same cells and nodes: coordinates equal to round-off of the tabulation
        same = cells_i.shape == cells_b.shape and np.allclose(
            cells_i, cells_b, rtol=0.0, atol=1e-12 * L
        )
        same &= nodes_i.shape == nodes_b.shape and np.allclose(
            nodes_i[:, :3], nodes_b[:, :3], rtol=0.0, atol=1e-12 * L
        )
        du = np.max(np.abs(nodes_i[:, 3:] - nodes_b[:, 3:])) / np.max(np.abs(nodes_i[:, 3:]))
        out = same, float(du)
    same, du = comm.bcast(out, root=0)
    df = abs(res_b.force - res_i.force) / abs(res_i.force)
    return res_i, res_b, fitted, split, same, df, du


def _slave_h(coupling) -> list[np.ndarray]:
    """Per direction, on rank 0: rows (facet midpoint x, facet length, slave cell's largest
    edge h) sorted by x; empty elsewhere."""
    comm = coupling.comm
    out = []
    for dr in coupling.dirs:
        X = dr.slave.X
        rows = np.column_stack(
            [X.mean(axis=1)[:, 0], np.linalg.norm(X[:, 1] - X[:, 0], axis=1), dr.h]
        )
        rows = comm.gather(rows, root=0)
        if comm.rank == 0:
            rows = np.vstack(rows)
            rows = rows[np.argsort(rows[:, 0])]
        out.append(rows)
    return out


def test_nitsche_matches_fitted_interface():
    """Unbiased incomplete (theta = 0) Nitsche between two bodies equals Nitsche on a fitted
    interface (averaged stress) on the same triangulation: where both directions are closed
    and the two cells of every interface facet have the same diameter, the half-weighted
    laws of the two directions add up to the interface's, 1/2 (-s_1 - gamma g) + 1/2 (-s_2 -
    gamma g) = -{s} - gamma g, and w = u + H a with a on the whole interface is the space of
    doubled nodes (Chouly, Mlika & Renard 2018, doi:10.1007/s00211-018-0959-1, unbiased;
    Chouly, Fabre, Hild, Pousin & Renard 2018, doi:10.1051/m2an/2017056, averaged stress).

    The load q(x) = q0 (1 + 2 x / L) makes the interface stress vary along x (a uniform
    column is reproduced by any method) and keeps it in compression, so that both
    directions are active everywhere. Equal quadrature: the interface's contact terms use
    a degree-4 Gauss rule on each facet (3 points, Problem.contact_rule: 2 k + 2), the
    two-body coupling the 2-point Gauss rule (exact to degree 3) at the slave facets; the
    integrands are P [v].n with P and v linear on a facet (degree 2) while the law is active
    on the whole facet (checked below), and the master's basis is evaluated on the same
    facet (matching facets): both rules are exact. The force is integrated exactly on both
    sides too (degree-12 rule on the interface, the 2-point rule of a linear P)."""
    res_i, res_b, fitted, split, same, df, du = _matching_pair(0, "unbiased")
    p, comm = fitted.p, MPI.COMM_WORLD
    # the same triangulation: the cells (sorted vertex coordinates) and nodes of each side
    # (body) agree to the round-off of the coordinates' tabulation (1e-12 L)
    assert same
    coupling = split.solved.coupling()
    # gamma: each interface facet's two cells are mirror images: the slave cell's largest
    # edge is the same number in both directions (to the round-off of the mirror
    # 2 H - y), and the interface's integral of avg(h) over the facets is the
    # length-weighted sum of the slave cells' h (round-off); h varies along the interface
    # (measured 0.052 to 0.097: the mesh is graded), so gamma is not one constant
    rows = _slave_h(coupling)
    H_int = global_sum(
        dolfinx.fem.form(fitted.solved.surface.h * fitted.solved.dS(fitted.interface_tag)), comm
    )
    if comm.rank == 0:
        lower, upper = rows
        assert np.allclose(lower[:, :2], upper[:, :2], rtol=0.0, atol=1e-12 * p.width)
        assert np.max(np.abs(lower[:, 2] - upper[:, 2]) / lower[:, 2]) < 1e-14
        assert np.sum(lower[:, 1] * lower[:, 2]) == pytest.approx(H_int, rel=1e-13)
        assert np.max(lower[:, 2]) / np.min(lower[:, 2]) > 1.2
    # closed everywhere, in both directions: the law's argument is positive at both ends of
    # every slave facet (linear on a facet, extrapolated from its Gauss points) and the
    # interface's nodal pressure is positive; and not uniform: the load grows threefold
    # from x = 0 to x = L, the interface pressure (measured 1.46 to 2.54) by more than 1.5
    assert _gauss_pressure_ends(coupling) > 0.0
    assert res_i.reference["min_pressure"] > 0.0
    assert res_i.peak_pressure > 1.5 * res_i.reference["min_pressure"]
    # equilibrium of the upper block: both forces are the load q0 (L + L) = 2 q0 L
    assert res_i.force == pytest.approx(2.0 * p.pressure * p.width, rel=1e-10)
    assert res_b.force == pytest.approx(2.0 * p.pressure * p.width, rel=1e-10)
    # the same discrete problem, each solved by one Newton step from a closed start (the law
    # is linear on the active set): the solutions agree to the round-off of the linear
    # solves (measured 2e-15 of the largest displacement, 5e-15 at 2 ranks). The forces
    # carry the round-off of the two-body gap, a difference of reference positions (1e-16 L)
    # amplified by gamma = gamma0 E / h ~ 2e5 q0 / L (measured 4.6e-12). 1e-10 is Newton's
    # relative tolerance; a broken identity shows far above it: gamma0 0.1 % off on one side
    # moves the displacement by 5e-8, the biased law (theta = 0) by 2e-5
    assert df < 1e-10
    assert du < 1e-10


def test_biased_nitsche_near_fitted_interface():
    """Report, not exactness: biased symmetric Nitsche (theta = 1, the upper body the slave)
    against the interface's symmetric Nitsche on the same problem. The biased law reads the
    slave cell's stress instead of the average, so its gap differs by (s_1 - {s}) / gamma,
    the stress jump across the interface (the P1 stress's O(h) error) over gamma."""
    res_i, res_b, *_, same, df, du = _matching_pair(1, "biased")
    assert same
    # equilibrium of the upper block fixes both forces (measured 4e-12 apart, the round-off
    # of the two-body gap as in test_nitsche_matches_fitted_interface)
    assert df < 1e-10
    # measured 2.7e-5 of the largest displacement: not the same discrete problem (above
    # round-off), close to it (a coupling error, e.g. a missing master term, is O(1))
    assert 1e-8 < du < 1e-3


@pytest.mark.parametrize("method", ["nitsche", "penalty"])  # mortar refuses it (not symmetric)
def test_hertz_cylinders_with_the_iterative_solver(method):
    """``--solver gamg`` between two linear-elastic bodies (the kept AMG preconditioner,
    refreshed at a solve's first iteration with the pattern the search grew): the forces are
    the direct solver's to Newton's tolerance (measured 3e-13 with Nitsche), asserted to 1e-8
    (the Eisenstat-Walker Krylov tolerance is 1e-2 to 1e-10; Newton converges the same
    residual). Before, the refreshed preconditioner failed: PETSc 3.18's GAMG set the new
    pattern's matrix into its old coarse levels (PETSc error 60, or a GMRES breakdown after
    inexact steps with the old one), at the first step."""
    from contactfx.scenes.two_body import HertzCylinders

    force = {}
    for solver in ("lu", "gamg"):
        num = HertzCylinders.default_numerics(method=method, solver=solver)
        res = HertzCylinders(HertzCylinders.Params()).run(num, verbose=False)
        force[solver] = res.quantities.force
    assert force["gamg"] == pytest.approx(force["lu"], rel=1e-8)
