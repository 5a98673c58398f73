"""Fitted interfaces (BENCHMARKS sections 6 and 7): Barton-Bandis joint column, Sneddon's
pressurised crack, the inclined frictional crack, the propped fracture.

Run serially and with ``mpirun -n 2 python -m mpi4py -m pytest``: the contact quantities are
the same on any number of ranks (the parallel check compares with a serial run in a child
process, see test_parallel_agrees).
"""

from __future__ import annotations

import math

import pytest

from contactfx.scenes import Numerics
from contactfx.scenes.crack import CrackInclined, CrackSneddon, ProppedFracture
from contactfx.scenes.crack_fields import joint_column
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
    return scene.run(scene.default_numerics(**numerics), verbose=False).data


# -- joint column: uniform states, exact on any mesh ---------------------------------------
@pytest.mark.parametrize("numerics", CONSISTENT, ids=IDS)
@pytest.mark.parametrize("s_c, p", [(30e6, 10e6), (30e6, 0.0), (60e6, 10e6)])
def test_joint_column_table(numerics, s_c, p):
    scene = JointColumn(JointColumn.Params(closure_stress=s_c, fluid_pressure=p))
    data = _run(scene, **numerics)
    ref = data["reference"]
    exact = joint_column(s_c, p, 10e9, 0.25, 1.0, 1e-3, 50e9, 3e-4)
    # the solution is uniform in each block: P1 represents it exactly, so the only error is
    # the solver's (Newton to rtol 1e-10 / round-off); 1e-6 is BENCHMARKS' requirement
    for key in ("closure", "aperture", "settlement"):
        assert ref[key] == pytest.approx(exact[key], rel=1e-6), key
    # the joint carries the effective stress: normal force = (s_c - p) L
    assert data["normal_force"] == pytest.approx((s_c - p) * 0.5, rel=1e-9)


def test_joint_column_any_mesh():
    scene = JointColumn(JointColumn.Params(h=0.13, width=0.7))
    ref = _run(scene, method="nitsche")["reference"]
    assert ref["settlement_rel_error"] < 1e-6
    assert ref["aperture_spread"] < 1e-9 * 1e-3  # uniform along the joint
