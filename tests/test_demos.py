"""Every demo runs, serially and with two ranks, and prints the same numbers."""

import re
import subprocess
import sys
from pathlib import Path

import pytest

from conftest import clean_env

DEMOS = sorted((Path(__file__).parents[1] / "demos").glob("*.py"))


@pytest.mark.serial_only
@pytest.mark.parametrize("demo", DEMOS, ids=[d.stem for d in DEMOS])
def test_demo_runs_serial_and_parallel(demo):
    outputs = []
    for ranks in (1, 2):
        cmd = [sys.executable, "-m", "mpi4py", str(demo)]
        if ranks > 1:
            cmd = ["mpirun", "-n", str(ranks), *cmd]
        res = subprocess.run(cmd, capture_output=True, text=True, timeout=600, env=clean_env())
        assert res.returncode == 0, res.stderr
        outputs.append(res.stdout)
    numbers = [re.findall(r"[-+]?\d+\.\d+(?:e[-+]?\d+)?", out) for out in outputs]
    assert numbers[0] and len(numbers[0]) == len(numbers[1])
    for a, b in zip(*numbers, strict=True):
        # printed to 4-8 significant digits: identical up to the last digit's round-off
        assert float(a) == pytest.approx(float(b), rel=1e-5, abs=1e-8)
