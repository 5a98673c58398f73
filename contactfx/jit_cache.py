"""Concurrent runs share the form cache: a process waits for another's compile however long it
takes, and never for a compile that died.

FFCx (both stacks) marks a module being compiled by creating its ``<module>.c`` file in the cache
exclusively; a second process that needs the same module polls for ``<module>.c.cached`` once a
second and gives up after dolfinx's JIT ``timeout`` (10 s by default) with ``TimeoutError: JIT
compilation timed out, probably due to a failed previous compile``: two runs on a cold cache (a
parameter sweep, ``make test`` beside a run) fail as soon as one compile takes longer. A longer
timeout alone would make a compile killed half way (its ``.c`` file stays) hang every later run
for as long.

:func:`install` wraps FFCx's ``get_cached_module`` and ``compile_*`` functions: processes of
contactfx serialise on an advisory lock per module (``fcntl.flock`` on ``<module>.lock`` in the
cache directory), which the compiling process holds, with its pid written in it, until its compile
ends. A waiter blocks on the lock however long the compile takes. The kernel releases the lock of
a process that dies, so a waiter that gets the lock while the ``.c`` file exists without the
``.c.cached`` marker knows the compile is not going on: the pid left in the lock file says a
contactfx compile died (killed, interrupted), and the ``.c`` file is set aside at once
(``.c.stale``) and the module compiled again. An empty lock file with a ``.c`` file means another
program (plain dolfinx, which takes no lock) is compiling: it is waited for until the ``.c`` file
is :data:`STALE_SECONDS` old, then treated as a dead compile too (the trade-off: a foreign compile
that takes longer is compiled twice; a foreign compile that died costs that long once).
"""

from __future__ import annotations

import fcntl
import os
import time
from pathlib import Path
from typing import Any

__all__ = ["STALE_SECONDS", "install"]

#: a compile by another program (no lock) not finished after this long is treated as dead
STALE_SECONDS = 600

#: (lock file descriptor, the module's .c file) of the compiles this process is running
_held: list[tuple[int, Path]] = []


def _set_aside(c_file: Path) -> None:
    try:
        os.replace(c_file, c_file.with_suffix(".c.stale"))
    except FileNotFoundError:
        pass


def _wrap_get_cached_module(original):
    def get_cached_module(module_name, object_names, cache_dir, timeout):
        cache_dir = Path(cache_dir)
        c_file = cache_dir / f"{module_name}.c"
        ready = cache_dir / f"{module_name}.c.cached"
        if ready.exists():  # compiled: no lock needed
            return original(module_name, object_names, cache_dir, timeout)
        cache_dir.mkdir(parents=True, exist_ok=True)
        fd = os.open(cache_dir / f"{module_name}.lock", os.O_RDWR | os.O_CREAT, 0o666)
        try:
            try:
                fcntl.flock(fd, fcntl.LOCK_EX)  # waits while another contactfx process compiles
            except OSError:  # a file system without locks: FFCx's own wait, long
                os.close(fd)
                return original(module_name, object_names, cache_dir, STALE_SECONDS)
            if c_file.exists() and not ready.exists():
                owner = os.pread(fd, 64, 0).strip()
                age = time.time() - c_file.stat().st_mtime
                if owner or age >= STALE_SECONDS:
                    _set_aside(c_file)  # a contactfx compile that died, or a stale foreign one
                else:  # another program compiles without a lock: FFCx's wait, bounded
                    try:
                        return original(
                            module_name, object_names, cache_dir, int(STALE_SECONDS - age) + 1
                        )
                    except TimeoutError:
                        _set_aside(c_file)
            result = original(module_name, object_names, cache_dir, timeout)
        except BaseException:
            os.close(fd)
            raise
        if result[0] is not None:  # loaded from the cache
            os.close(fd)
            return result
        # this process compiles: the lock stays held, with its pid, until the compile ends
        os.ftruncate(fd, 0)
        os.pwrite(fd, str(os.getpid()).encode(), 0)
        _held.append((fd, c_file))
        return result

    get_cached_module.contactfx_wrapped = True  # type: ignore[attr-defined]
    return get_cached_module


def _wrap_compile(original):
    def compile_objects(*args: Any, **kwargs: Any):
        depth = len(_held)
        try:
            return original(*args, **kwargs)
        finally:
            while len(_held) > depth:
                fd, c_file = _held.pop()
                if c_file.exists() and not c_file.with_suffix(".c.cached").exists():
                    # interrupted (KeyboardInterrupt: FFCx moves the .c file only on Exception)
                    os.replace(c_file, c_file.with_suffix(".c.failed"))
                os.ftruncate(fd, 0)  # the compile ended: no dead owner to report
                os.close(fd)

    return compile_objects


def install() -> None:
    """Wrap FFCx's cache functions (once per process; both stacks' FFCx look them up as module
    attributes at call time)."""
    import ffcx.codegeneration.jit as jit

    if getattr(jit.get_cached_module, "contactfx_wrapped", False):
        return
    jit.get_cached_module = _wrap_get_cached_module(jit.get_cached_module)
    for name in ("forms", "expressions", "elements", "coordinate_maps"):
        name = f"compile_{name}"
        if hasattr(jit, name):
            setattr(jit, name, _wrap_compile(getattr(jit, name)))
