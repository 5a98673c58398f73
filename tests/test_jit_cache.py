"""Concurrent runs on a cold form cache (contactfx/jit_cache.py): a run waits for another's
compile of the same forms however long it takes, and not for a compile that was killed.

The C compiler is a wrapper (CC) whose first call of all sleeps longer than FFCx's own wait
(10 s): the run that compiles that module holds it, the other run needs the same module at
the same time (FFCx alone: ``TimeoutError: JIT compilation timed out``)."""

import os
import signal
import subprocess
import time
from pathlib import Path

import pytest

from conftest import clean_env, contactfx_cmd

pytestmark = pytest.mark.serial_only

RUN = ["run", "hertz2d", "--h-contact", "2e-2", "--steps", "1"]


def _slow_cc(tmp_path: Path, seconds: float) -> dict[str, str]:
    """Environment with an empty form cache and a compiler whose first call sleeps."""
    script = tmp_path / "slow-cc"
    script.write_text(
        "#!/bin/sh\n"
        f'mkdir "{tmp_path}/slow-once" 2>/dev/null && sleep {seconds}\n'
        'exec x86_64-linux-gnu-gcc "$@"\n'
        if Path("/usr/bin/x86_64-linux-gnu-gcc").exists()
        else f'#!/bin/sh\nmkdir "{tmp_path}/slow-once" 2>/dev/null && sleep {seconds}\n'
        'exec cc "$@"\n'
    )
    script.chmod(0o755)
    return {**clean_env(), "XDG_CACHE_HOME": str(tmp_path / "cache"), "CC": str(script)}


def _start(env, out: Path, **kwargs) -> subprocess.Popen:
    cmd = contactfx_cmd(*RUN, "--out", str(out))
    return subprocess.Popen(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, **kwargs)


def test_two_runs_on_an_empty_cache_both_succeed(tmp_path):
    env = _slow_cc(tmp_path, 14)
    runs = [_start(env, tmp_path / f"out{i}") for i in range(2)]
    for run in runs:
        out, err = run.communicate(timeout=120)
        assert run.returncode == 0, err.decode()
        assert b"contact force" in out
    assert (tmp_path / "slow-once").exists()  # one compile outlasted FFCx's 10 s
    assert list((tmp_path / "cache" / "fenics").glob("*.lock"))  # the runs took the locks


def test_a_killed_compile_is_not_waited_for(tmp_path):
    env = _slow_cc(tmp_path, 60)
    killed = _start(env, tmp_path / "killed", start_new_session=True)
    deadline = time.time() + 60
    while not (tmp_path / "slow-once").exists():  # the killed run is inside the compiler
        assert time.time() < deadline and killed.poll() is None, killed.stderr.read().decode()
        time.sleep(0.2)
    os.killpg(killed.pid, signal.SIGKILL)
    killed.communicate()
    assert list((tmp_path / "cache" / "fenics").glob("*.c"))  # left behind: no .c.cached
    start = time.time()
    run = _start(env, tmp_path / "out")
    out, err = run.communicate(timeout=120)
    assert run.returncode == 0, err.decode()
    assert time.time() - start < 50  # not the killed compile's 60 s, nor FFCx's timeout
    assert list((tmp_path / "cache" / "fenics").glob("*.c.stale"))  # set aside, recompiled
