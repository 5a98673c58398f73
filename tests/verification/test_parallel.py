"""Contact quantities must not depend on the number of ranks.

Under ``mpirun -n 2`` every rank solves the scene alone (COMM_SELF) and together (COMM_WORLD)
on the same gmsh mesh; in a serial session both would be the same run, so the tests are
skipped there (``ranks_compare``): the check happens in the MPI session that ``make test``
runs.
"""

import pytest
from mpi4py import MPI

from contactfx.scenes import Numerics
from contactfx.scenes.hertz import Hertz2D, Hertz2DParams, Hertz3D, Hertz3DParams
from contactfx.scenes.sliding_block import SlidingBlock, SlidingBlockParams

pytestmark = pytest.mark.ranks_compare


@pytest.mark.parametrize(
    "scene, num",
    [
        (Hertz2D(Hertz2DParams()), Numerics(method="nitsche", theta=1)),
        (Hertz2D(Hertz2DParams()), Numerics(method="nitsche", theta=-1, degree=2)),
        (Hertz2D(Hertz2DParams()), Numerics(method="penalty")),
        (Hertz2D(Hertz2DParams()), Numerics(method="vi")),
        (Hertz3D(Hertz3DParams()), Numerics(method="nitsche")),
    ],
    ids=["hertz2d-nitsche", "hertz2d-skew-P2", "hertz2d-penalty", "hertz2d-vi", "hertz3d"],
)
def test_serial_and_parallel_agree(scene, num):
    serial = scene.run(num, comm=MPI.COMM_SELF, verbose=False)
    parallel = scene.run(num, comm=MPI.COMM_WORLD, verbose=False)
    # same mesh, same discrete problem, Newton converged to a relative residual of 1e-10:
    # the partition changes only round-off
    for key in ("force", "contact_size", "peak_pressure"):
        assert getattr(parallel, key) == pytest.approx(getattr(serial, key), rel=1e-8), key
    assert abs(parallel.newton_iterations - serial.newton_iterations) <= 1


@pytest.mark.parametrize(
    "scene, num",
    [
        (Hertz2D(Hertz2DParams()), Numerics(method="al-uzawa")),
        (Hertz2D(Hertz2DParams()), Numerics(method="al-ssn", ncp="fb")),
        (SlidingBlock(SlidingBlockParams()), SlidingBlock.default_numerics(method="nitsche")),
        (SlidingBlock(SlidingBlockParams()), SlidingBlock.default_numerics(method="al-ssn")),
        (
            SlidingBlock(SlidingBlockParams(shift=1e-4)),
            SlidingBlock.default_numerics(method="penalty", penalty=1.0, mu=2.0),
        ),
        (
            Hertz2D(Hertz2DParams(shift=5e-4)),
            Hertz2D.default_numerics(
                method="nitsche",
                gamma0=1000.0,
                quadrature="nodal",
                friction="coulomb",
                mu=0.3,
                steps=8,
            ),
        ),
    ],
    ids=[
        "hertz2d-al-uzawa",
        "hertz2d-al-ssn-fb",
        "sliding-nitsche",
        "sliding-al-ssn",
        "sliding-penalty-stick",
        "hertz2d-shift-stiff",
    ],
)
def test_serial_and_parallel_agree_al_and_friction(scene, num):
    serial = scene.run(num, comm=MPI.COMM_SELF, verbose=False)
    parallel = scene.run(num, comm=MPI.COMM_WORLD, verbose=False)
    # Newton (and Uzawa, tolerance 1e-8 on the multiplier) converged: contact quantities
    # agree to the solver tolerance
    for key in ("force", "contact_size", "peak_pressure"):
        assert getattr(parallel, key) == pytest.approx(getattr(serial, key), rel=1e-7), key
    if serial.friction is not None:
        assert parallel.friction.tangential_force[0] == pytest.approx(
            serial.friction.tangential_force[0], rel=1e-7, abs=1e-9 * serial.force
        )


def _interface_cases():
    from contactfx.scenes.crack import CrackInclined, CrackSet, CrackSneddon, ProppedFracture
    from contactfx.scenes.joint import JointColumn
    from contactfx.scenes.penny import FaultBlock, PennyCrack, PennyShear

    inclined = CrackInclined(CrackInclined.Params(beta=45.0))
    propped = ProppedFracture(ProppedFracture.Params())
    return [
        ("sneddon-nitsche", CrackSneddon(CrackSneddon.Params()), {"method": "nitsche"}),
        ("inclined-nitsche", inclined, {"method": "nitsche", "mu": 0.3}),
        ("inclined-al-uzawa", inclined, {"method": "al-uzawa", "mu": 0.3}),
        ("inclined-penalty", inclined, {"method": "penalty", "mu": 0.3}),
        ("propped-al-ssn", propped, {"method": "al-ssn"}),
        ("propped-nitsche", propped, {"method": "nitsche", "theta": -1}),
        ("joint-al-ssn", JointColumn(JointColumn.Params()), {"method": "al-ssn"}),
        (
            "sneddon-unfitted",
            CrackSneddon(CrackSneddon.Params(crack="unfitted")),
            {"method": "nitsche"},
        ),
        (
            "inclined-unfitted",
            CrackInclined(CrackInclined.Params(beta=30.0, crack="unfitted")),
            {"method": "nitsche", "mu": 0.3},
        ),
        (
            "inclined-unfitted-penalty",
            CrackInclined(CrackInclined.Params(beta=45.0, crack="unfitted")),
            {"method": "penalty", "mu": 0.3},
        ),
        (
            "inclined-unfitted-al-uzawa",
            CrackInclined(CrackInclined.Params(beta=45.0, crack="unfitted")),
            {"method": "al-uzawa", "mu": 0.3},
        ),
        (
            "inclined-unfitted-al-ssn",
            CrackInclined(CrackInclined.Params(beta=45.0, crack="unfitted")),
            {"method": "al-ssn", "mu": 0.3},
        ),
        (
            "propped-unfitted",
            ProppedFracture(ProppedFracture.Params(crack="unfitted")),
            {"method": "nitsche", "theta": 0},
        ),
        ("crack-set", CrackSet(CrackSet.Params()), {"method": "nitsche"}),
        (
            "joint-unfitted",
            JointColumn(JointColumn.Params(crack="unfitted", joint_offset=0.0123, h=0.1)),
            {"method": "al-uzawa", "friction": "coulomb"},
        ),
        (
            "penny-nitsche",
            PennyCrack(PennyCrack.Params(h_front=0.2, h_crack=0.4, front_bins=3)),
            {"method": "nitsche", "degree": 2},
        ),
        (
            "penny-shear-nitsche",
            PennyShear(PennyShear.Params(h_front=0.2, h_crack=0.4, front_bins=3)),
            {"method": "nitsche"},
        ),
        (
            "penny-shear-al-ssn",
            PennyShear(PennyShear.Params(h_front=0.2, h_crack=0.4, front_bins=3)),
            {"method": "al-ssn"},
        ),
        (
            "fault-block",
            FaultBlock(FaultBlock.Params(h_front=0.2, h_crack=0.4, overpressure=3e6)),
            {},
        ),
        (
            "penny-suction-nitsche",
            PennyCrack(PennyCrack.Params(h_front=0.2, h_crack=0.4, pressure=-1e6)),
            {"method": "nitsche", "theta": 0},
        ),
    ]


@pytest.mark.parametrize("case", _interface_cases(), ids=lambda c: c[0])
def test_serial_and_parallel_agree_interfaces(case):
    """Crack and joint interfaces cut by the partition: interior-facet integrals on shared
    facets count once, the enrichment and multiplier dofs are shared consistently."""
    _, scene, overrides = case
    num = scene.default_numerics(**overrides)
    serial = scene.run(num, comm=MPI.COMM_SELF, verbose=False)
    parallel = scene.run(num, comm=MPI.COMM_WORLD, verbose=False)
    # Newton / Uzawa converged (rtol 1e-10, Uzawa 1e-8): the partition changes round-off only
    # (measured at most 6e-12 relative over these cases): required to 1e-8
    scale = max(abs(serial.force), 1.0)
    pairs = {
        "force": (serial.force, parallel.force),
        "tangential force": (
            serial.interface.tangential_force,
            parallel.interface.tangential_force,
        ),
        "closed length": (serial.contact_size, parallel.contact_size),
        "peak pressure": (serial.peak_pressure, parallel.peak_pressure),
    }
    for key, (s, p) in pairs.items():
        assert p == pytest.approx(s, rel=1e-8, abs=1e-10 * scale), key
    for key, value in serial.errors.items():
        # an exact solution's error is round-off: relative to the norm of the field it measures
        # (the absolute error over the relative one), e.g. 1e-11 Pa on pressures of 1e6 Pa
        rel = serial.errors.get(f"{key}_rel", 0.0)
        norm = value / rel if rel > 0.0 else 1.0
        assert parallel.errors[key] == pytest.approx(value, rel=1e-6, abs=1e-12 * norm), key
    for key, value in serial.reference.items():
        assert parallel.reference[key] == pytest.approx(value, rel=1e-6, abs=1e-12), key
