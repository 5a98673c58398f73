"""Contact quantities must not depend on the number of ranks.

Under ``mpirun -n 2`` every rank solves the scene alone (COMM_SELF) and together (COMM_WORLD)
on the same gmsh mesh; in a serial session both are the same run and the test is a no-op
comparison, the real check happens in the MPI session that ``make test`` runs.
"""

import pytest
from mpi4py import MPI

from contactfx.scenes import Numerics
from contactfx.scenes.hertz import Hertz2D, Hertz2DParams, Hertz3D, Hertz3DParams
from contactfx.scenes.sliding_block import SlidingBlock, SlidingBlockParams


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
    for key in ("force", "contact_half_width", "peak_pressure"):
        assert parallel[key] == pytest.approx(serial[key], rel=1e-8), key
    assert abs(parallel["newton_iterations"] - serial["newton_iterations"]) <= 1


@pytest.mark.parametrize(
    "scene, num",
    [
        (Hertz2D(Hertz2DParams()), Numerics(method="al-uzawa")),
        (Hertz2D(Hertz2DParams()), Numerics(method="al-ssn", ncp="fb")),
        (SlidingBlock(SlidingBlockParams()), SlidingBlock.default_numerics(method="nitsche")),
        (SlidingBlock(SlidingBlockParams()), SlidingBlock.default_numerics(method="al-ssn")),
    ],
    ids=["hertz2d-al-uzawa", "hertz2d-al-ssn-fb", "sliding-nitsche", "sliding-al-ssn"],
)
def test_serial_and_parallel_agree_al_and_friction(scene, num):
    serial = scene.run(num, comm=MPI.COMM_SELF, verbose=False)
    parallel = scene.run(num, comm=MPI.COMM_WORLD, verbose=False)
    # Newton (and Uzawa, tolerance 1e-8 on the multiplier) converged: contact quantities
    # agree to the solver tolerance
    for key in ("force", "contact_half_width", "peak_pressure"):
        assert parallel[key] == pytest.approx(serial[key], rel=1e-7), key
    if "tangential_force" in serial.data:
        assert parallel["tangential_force"][0] == pytest.approx(
            serial["tangential_force"][0], rel=1e-7, abs=1e-9 * serial["force"]
        )
