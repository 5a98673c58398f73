"""Fitted interfaces (docs/verification.md sections 6 and 7): Barton-Bandis joint column, Sneddon's
pressurised crack, the inclined frictional crack, the propped fracture.

Run serially and with ``mpirun -n 2 python -m mpi4py -m pytest``: the contact quantities are
the same on any number of ranks (the parallel check compares with a serial run in a child
process, see test_parallel_agrees).
"""

from __future__ import annotations

import math

import pytest

from contactfx.references import joint_column
from contactfx.scenes.crack import CrackInclined, CrackSneddon, ProppedFracture
from contactfx.scenes.joint import JointColumn

#: methods on interfaces; Nitsche's three variants and both augmented Lagrangian ones
CONSISTENT = [
    dict(method="nitsche", theta=1),
    dict(method="nitsche", theta=0),
    dict(method="nitsche", theta=-1),
    dict(method="al-uzawa"),
    dict(method="al-ssn"),
]
IDS = ["nitsche1", "nitsche0", "nitsche-1", "al-uzawa", "al-ssn"]


def _run(scene, **numerics):
    return scene.run(scene.default_numerics(**numerics), verbose=False)


# -- joint column: uniform states, exact on any mesh ---------------------------------------
@pytest.mark.parametrize("numerics", CONSISTENT, ids=IDS)
@pytest.mark.parametrize("s_c, p", [(30e6, 10e6), (30e6, 0.0), (60e6, 10e6)])
def test_joint_column_table(numerics, s_c, p):
    scene = JointColumn(JointColumn.Params(closure_stress=s_c, fluid_pressure=p))
    data = _run(scene, **numerics)
    ref = data.reference
    exact = joint_column(s_c, p, 10e9, 0.25, 1.0, 1e-3, 50e9, 3e-4)
    # the solution is uniform in each block: P1 represents it exactly, so the only error is
    # the solver's (Newton to rtol 1e-10 / round-off); 1e-6 is the requirement of
    # docs/verification.md section 7
    for key in ("closure", "aperture", "settlement"):
        assert ref[key] == pytest.approx(exact[key], rel=1e-6), key
    # the joint carries the effective stress: normal force = (s_c - p) L
    assert data.force == pytest.approx((s_c - p) * 0.5, rel=1e-9)


def test_joint_column_any_mesh():
    scene = JointColumn(JointColumn.Params(h=0.13, width=0.7))
    ref = _run(scene, method="nitsche").reference
    assert ref["settlement_rel_error"] < 1e-6
    assert ref["aperture_spread"] < 1e-9 * 1e-3  # uniform along the joint


# -- Sneddon: pressurised crack ----------------------------------------------------------
def test_sneddon_open_no_false_contact():
    data = _run(CrackSneddon(CrackSneddon.Params(pressure=1e6)), method="nitsche")
    # p > 0 opens the whole crack: the contact force is exactly zero (no node is closed)
    assert data.force == 0.0 and data.contact_size == 0.0
    # opening in L2 on the crack: 0.58 % on the default mesh (h_crack = a/40, h_tip = a/400),
    # converging about as h (bench: 1.0e-2, 5.8e-3, 3.4e-3 for h_crack = a/20, a/40, a/80)
    assert data.errors["opening_L2_rel"] < 0.01
    # K_I by displacement extrapolation: 1.0 % here (0.27 % on the next finer mesh)
    assert data.reference["K_rel_error"] < 0.02


def test_sneddon_opening_converges():
    errors = []
    for h in (0.1, 0.05, 0.025):
        params = CrackSneddon.Params(h_crack=h, h_tip=h / 10, h_far=20 * h, grading=6 * h)
        errors.append(_run(CrackSneddon(params), method="nitsche").errors["opening_L2_rel"])
    rates = [math.log2(e0 / e1) for e0, e1 in zip(errors[:-1], errors[1:], strict=True)]
    # docs/verification.md: about O(h); with the tips graded the observed rates are 1.5-1.7
    assert min(rates) > 0.9, (errors, rates)


@pytest.mark.parametrize(
    "numerics", CONSISTENT + [dict(method="al-uzawa", degree=2)], ids=IDS + ["al-uzawa-P2"]
)
def test_sneddon_suction_closes_with_uniform_pressure(numerics):
    data = _run(CrackSneddon(CrackSneddon.Params(pressure=-1e6)), **numerics)
    # the faces touch everywhere and carry -p; the body is unstressed: exact on any mesh up to
    # the solver tolerance, for every method (measured 7e-15). The augmented Lagrangian
    # methods carry the neighbour's traction over each tip element (al-ssn's multiplier tie,
    # al-uzawa's InterfaceSurface.tip_extended): with the tip's traction at zero instead the
    # force was short by the two tip elements, h_tip / a = 2.5e-3 each (al-uzawa P2 as well:
    # its multiplier is P1 whatever the displacement's degree)
    assert data.reference["force_rel_error"] < 1e-8
    assert data.max_penetration < 1e-12


def test_sneddon_suction_penalty_carries_the_tip_elements():
    """The penalty's law is continued over each tip's element (MethodBase.tip_continued), as
    al-uzawa's: the tip element carries its neighbour's kappa [-g]_+ instead of a traction
    falling to zero at the tip, where the jump vanishes identically."""
    data = _run(CrackSneddon(CrackSneddon.Params(pressure=-1e6)), method="penalty", penalty=1000.0)
    # what remains is the penalty's consistency error: the overlap p / kappa follows the
    # graded nodal mesh size, so the body is slightly stressed, O(1 / penalty): measured
    # 9.6e-4 at penalty 10 and 9.6e-6 at 1000. With the tip traction falling to zero the
    # force was 7.7e-4 low at 1000 (the two tip elements)
    assert data.reference["force_rel_error"] < 3e-5


# -- inclined crack under compression: K_II table ------------------------------------------
KII_TABLE = {  # docs/verification.md section 6, K_II / (sigma sqrt(pi a)) at beta = 30 / 45 / 60
    0.0: (0.43301, 0.5, 0.43301),
    0.3: (0.20801, 0.35, 0.35801),
    0.6: (0.0, 0.2, 0.28301),
}


@pytest.mark.parametrize("mu", sorted(KII_TABLE))
@pytest.mark.parametrize("column, beta", [(0, 30.0), (1, 45.0), (2, 60.0)])
def test_inclined_crack_KII_table(mu, column, beta):
    scene = CrackInclined(CrackInclined.Params(beta=beta))
    data = _run(scene, method="nitsche", mu=mu)
    ref = data.reference
    expected = KII_TABLE[mu][column]
    assert ref["K_II_normalised_exact"] == pytest.approx(expected, abs=5e-6)
    if expected == 0.0:
        # stick (tan 30 < 0.6): no slip anywhere, to round-off of the opening scale
        assert ref["max_slip"] < 1e-12
        assert data.errors["slip_L2"] < 1e-12
        return
    # displacement extrapolation of the slip, 1.3-2.5 % on the default mesh:
    # docs/verification.md section 6 asks 5 %
    assert ref["K_II_normalised"] == pytest.approx(expected, rel=0.05)
    # the whole crack slides: the Coulomb law |t| = mu p holds at every node (to round-off:
    # t and p are the projections at the same points)
    assert ref["slipping_fraction"] == 1.0
    assert ref["friction_law_error"] < 1e-9
    # the contact pressure is sigma_n (the slip field has no normal stress on the faces); its
    # error comes from the mode II singularity at the tips polluting the P1 stress average:
    # proportional to the driving shear q, 2.7-3.6 % of q / sigma_n on this mesh
    q = ref["K_II_exact"] / math.sqrt(math.pi)
    assert data.errors["pressure_L2_rel"] < 0.045 * q / ref["sigma_n"]
    # a fixed distance from the tips (|s| <= 0.8 a) that pollution is O(h): 0.26-0.46 % of
    # q / sigma_n on this mesh over the table (section 6, "Tractions at the tips")
    assert data.errors["pressure_interior_L2_rel"] < 0.007 * q / ref["sigma_n"]


@pytest.mark.parametrize("method", ["nitsche", "al-ssn", "penalty"])
def test_inclined_crack_pressure_converges_away_from_tips(method):
    """beta = 45, mu = 0.3 at h_crack = 0.05, 0.025, 0.0125 (the bench's levels): on
    |s| <= 0.8 a the pressure error converges like O(h), while over the whole crack the tips
    keep it at a few per cent on every mesh (docs/verification.md section 6)."""
    errors = []
    for h in (0.05, 0.025, 0.0125):
        params = CrackInclined.Params(beta=45.0, h_crack=h, h_tip=h / 10, h_far=20 * h)
        errors.append(
            _run(CrackInclined(params), method=method, mu=0.3).errors["pressure_interior_L2_rel"]
        )
    rate = math.log2(errors[0] / errors[2]) / 2.0
    # O(h) expected. Measured over the three levels: 0.94 (al-ssn), 1.14 (Nitsche) and 0.79
    # (penalty 10, whose O(h) consistency error adds to the tips') on Debian 12's gmsh
    # meshes, 0.76 (Nitsche) on Debian 13's: the constant of the tips' pollution follows the
    # local mesh pattern. The whole-crack error, which cannot converge, gives -0.15 for both
    # Nitsche and al-ssn on Debian 12's meshes; the penalty with the facet-wise h gave 0.20
    assert rate > 0.6, errors


@pytest.mark.parametrize(
    "numerics", CONSISTENT[2:] + [dict(method="penalty")], ids=IDS[2:] + ["penalty"]
)
def test_inclined_crack_methods_agree(numerics):
    scene = CrackInclined(CrackInclined.Params(beta=45.0))
    data = _run(scene, mu=0.3, **numerics)
    ref = data.reference
    # the same discretisation of the same law: K within 0.5 % of Nitsche's 1.3 % (penalty 10,
    # not consistent: 1.27 % measured)
    assert ref["K_rel_error"] < 0.03
    q = ref["K_II_exact"] / math.sqrt(math.pi)
    if numerics["method"] in ("al-ssn", "al-uzawa"):
        # the pressure as Nitsche's in test_inclined_crack_KII_table: the tip oscillation's
        # bound of 4.5 % of q / sigma_n. Measured 2.6 % for both (al-uzawa equals al-ssn to
        # 1e-8: the same nodal law, the same tip treatment); 4.7 % while their tip multiplier
        # was held at zero (the traction fell to zero over the tip elements;
        # docs/verification.md section 6)
        assert data.errors["pressure_L2_rel"] < 0.045 * q / ref["sigma_n"]
        # away from the tips as Nitsche's bound in test_inclined_crack_KII_table (0.37 % of
        # q / sigma_n measured for both)
        assert data.errors["pressure_interior_L2_rel"] < 0.007 * q / ref["sigma_n"]
    if numerics["method"] == "penalty":
        # away from the tips the same bound: 0.44 % of q / sigma_n measured. The penalty's
        # stiffness kappa = penalty E / h takes the continuous nodal mesh size
        # (SurfaceData.h_nodal); with the facet-wise h it measured 3.7 %, whatever the
        # penalty, from the cell-size jitter between neighbouring facets
        assert data.errors["pressure_interior_L2_rel"] < 0.007 * q / ref["sigma_n"]
        # over the whole crack the AL methods' bound: 2.4 % of q / sigma_n measured, its law
        # continued over the tip elements (4.6 % with the traction falling to zero there)
        assert data.errors["pressure_L2_rel"] < 0.045 * q / ref["sigma_n"]


def test_inclined_crack_augmented_lagrangian_methods_coincide():
    """With P1, al-uzawa and al-ssn discretise the same law the same way: both collocate it
    at the nodes, and both carry the neighbour's traction over each tip element (al-ssn by
    its multiplier tie, al-uzawa by ``InterfaceSurface.tip_extended``). Where no facet is
    open at one node only (this mesh) their solutions are the same up to the solvers'
    tolerances; on such a facet al-uzawa's traction [lambda - r g]_+ at the Gauss points
    differs from al-ssn's interpolated lambda (docs/verification.md section 6)."""
    scene = CrackInclined(CrackInclined.Params(beta=45.0))
    uzawa, ssn = (_run(scene, method=m, mu=0.3) for m in ("al-uzawa", "al-ssn"))
    # Uzawa stops at a multiplier change of 1e-8 of the multiplier, Newton at rtol 1e-10:
    # measured 1e-8 apart (the pressure error, K_II); held at zero, al-uzawa's tip traction
    # made its pressure L2 error 3.30 % against al-ssn's 1.82 %
    for key in ("pressure_L2_rel", "pressure_interior_L2_rel", "slip_L2"):
        assert uzawa.errors[key] == pytest.approx(ssn.errors[key], rel=1e-6), key
    assert uzawa.reference["K_II"] == pytest.approx(ssn.reference["K_II"], rel=1e-6)
    assert uzawa.force == pytest.approx(ssn.force, rel=1e-6)


def test_inclined_crack_tresca():
    # beta 45: tau = 5 MPa; Tresca threshold 2 MPa slides the crack with q = 3 MPa
    scene = CrackInclined(CrackInclined.Params(beta=45.0))
    data = _run(scene, method="nitsche", friction="tresca", threshold=2e6, mu=0.0)
    ref = data.reference
    assert ref["K_II_normalised_exact"] == pytest.approx(0.3, rel=1e-12)
    assert ref["K_rel_error"] < 0.05  # as the Coulomb table (1.3-2.5 % measured)
    assert ref["friction_law_error"] < 1e-9  # |t| = threshold at every sliding node


# -- propped fracture ------------------------------------------------------------------------
def test_propped_open_branch_is_sneddon():
    scene = ProppedFracture(ProppedFracture.Params(net_pressure=1e6))
    assert scene.p_star() < 1e6  # p* = 3.08e5
    data = _run(scene, method="nitsche")
    assert data.interface.proppant_force == 0.0  # the proppant carries nothing
    assert data.errors["opening_L2_rel"] < 0.01  # Sneddon, as test_sneddon_open
    assert data.reference["min_aperture_propped_over_h"] > 1.0


@pytest.mark.parametrize("numerics", CONSISTENT, ids=IDS)
def test_propped_closing_branch(numerics):
    scene = ProppedFracture(ProppedFracture.Params(net_pressure=-1e6))
    data = _run(scene, **numerics)
    # below p* the proppant carries load: more than the net suction over the propped part
    # 2 b |p_net| (the faces beyond it touch and the proppant is stiffer than the rock there)
    assert data.interface.proppant_force > 2 * 0.5 * 1e6
    # aperture >= h on the propped part: exactly at the nodes for the multiplier methods,
    # within Nitsche's penetration (1.4e-3 h on this mesh, O(1 / gamma0)) otherwise
    tol = 1e-9 if numerics["method"].startswith("al-") else 5e-3
    assert data.reference["min_aperture_propped_over_h"] > 1.0 - tol
