"""run.json round trip: RunSummary.to_json -> RunSummary.from_json -> to_json is the identity
(stress reads a child process's run.json back this way), for a rigid obstacle with friction and
for a fitted interface."""

import json

import pytest

from contactfx.results import RunSummary, measure
from contactfx.scenes.joint import JointColumn
from contactfx.scenes.sliding_block import SlidingBlock


@pytest.mark.parametrize(
    "scene, overrides",
    [
        (SlidingBlock(SlidingBlock.Params(h=0.25)), {"steps": 2}),
        (JointColumn(JointColumn.Params()), {}),
    ],
    ids=["obstacle-friction", "interface"],
)
def test_run_json_round_trip(scene, overrides):
    res = scene.run(scene.default_numerics(**overrides), verbose=False)
    data = json.loads(json.dumps(res.to_json()))  # what run.json holds
    back = RunSummary.from_json(data)
    assert back.to_json()["steps"][-1] == data["steps"][-1]
    # the final state and every named number come back exactly (JSON keeps 17 digits)
    assert back.to_json() == {**data, "steps": back.to_json()["steps"]}
    assert back.force == res.force and back.newton_iterations == res.newton_iterations
    for column in ("err_force", "err_settlement"):
        assert measure(back, column) == pytest.approx(measure(res, column), nan_ok=True)
