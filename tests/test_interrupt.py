"""A run stopped by SIGTERM (a batch scheduler's) finishes its step in progress, keeps the
complete steps' output, writes run.json marked "interrupted", prints one line and exits
non-zero: serially, and at 2 ranks with the signal sent to every rank (as Slurm's scancel
does) or to one rank only (the others learn of it at the step boundary). No rank hangs: every
process ends within the timeout. (A SIGTERM to mpirun itself is the launcher's business: Open
MPI 4.1, Debian 12's, forwards it to the ranks and the run stops the same way; Open MPI 5,
Debian 13's, ends the ranks at once.) The same command with ``--restart`` then completes the
run from its last checkpoint."""

import json
import os
import signal
import subprocess
import time

import pytest

from conftest import clean_env, contactfx_cmd
from contactfx.io.xdmf import read_xdmf

pytestmark = pytest.mark.serial_only

#: hertz2d with a fine contact zone: about a second a load step, twelve steps
SLOW = ["run", "hertz2d", "--h-contact", "0.0006", "--steps", "12"]


def _ranks(pid: int) -> list[int]:
    """The rank processes mpirun ``pid`` started."""
    out = subprocess.run(
        ["pgrep", "-P", str(pid), "-f", "contactfx"], capture_output=True, text=True
    )
    return [int(p) for p in out.stdout.split()]


@pytest.mark.parametrize("target", ["serial", "every-rank", "one-rank"])
def test_sigterm_marks_the_run_interrupted(tmp_path, target):
    out = tmp_path / "out"
    ranks = 1 if target == "serial" else 2
    proc = subprocess.Popen(
        contactfx_cmd(*SLOW, "--out", str(out), ranks=ranks),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=clean_env(),
    )
    assert proc.stdout is not None
    seen = []
    deadline = time.monotonic() + 240
    for line in proc.stdout:  # wait for the second converged step
        seen.append(line)
        if line.lstrip().startswith("step   2") or time.monotonic() > deadline:
            break
    assert any(s.lstrip().startswith("step   2") for s in seen), "".join(seen)
    if target == "serial":
        proc.send_signal(signal.SIGTERM)
    else:
        pids = _ranks(proc.pid)
        assert len(pids) == 2
        for pid in pids if target == "every-rank" else pids[:1]:
            os.kill(pid, signal.SIGTERM)
    rest, err = proc.communicate(timeout=120)
    stdout = "".join(seen) + rest
    # non-zero: 128 + 15 from the process itself; mpirun reports a rank's non-zero status
    assert proc.returncode != 0
    if target == "serial":
        assert proc.returncode == 128 + signal.SIGTERM
    said = [line for line in err.splitlines() if "interrupted by SIGTERM" in line]
    assert len(said) == 1, err  # one line, from rank 0
    assert "Traceback" not in err and "Traceback" not in stdout
    data = json.loads((out / "run.json").read_text())
    assert data["status"] == "interrupted" and data["signal"] == "SIGTERM"
    done = data["last_complete_step"]
    # stopped after the step in progress when the signal came (step 3 or a later one), not
    # at the end of the program
    assert 2 <= done < 12
    assert len(data["steps"]) == done
    assert data["load"] == pytest.approx(done / 12)
    assert [s["step"] for s in data["steps"]] == list(range(1, done + 1))
    assert data["ranks"] == ranks
    # the ParaView index lists exactly the complete steps, each readable
    series = read_xdmf(out / "hertz2d.xdmf")
    assert series["times"] == pytest.approx([s["load"] for s in data["steps"]])
    for step in range(done):
        assert len(read_xdmf(out / "hertz2d.xdmf", step)["point_data"]["displacement"])
    assert f"step  {done + 1:2d}" not in stdout  # no step after the one in progress
    assert f"--restart {out}" in data["restart"] and f"after step {done}" in data["restart"]
    if target != "serial":  # at 2 ranks: tests/verification/test_restart.py, in-process
        return
    # the run continued from its checkpoint (the same command with --restart): the complete
    # steps kept as they were, the others appended, to run.json and the XDMF series
    res = subprocess.run(
        contactfx_cmd(*SLOW, "--restart", str(out), "--quiet", ranks=ranks),
        capture_output=True,
        text=True,
        env=clean_env(),
        timeout=300,
    )
    assert res.returncode == 0, res.stderr
    final = json.loads((out / "run.json").read_text())
    assert final["status"] == "completed" and len(final["steps"]) == 12
    assert final["steps"][:done] == data["steps"]
    assert read_xdmf(out / "hertz2d.xdmf")["times"] == pytest.approx(
        [s["load"] for s in final["steps"]]
    )
