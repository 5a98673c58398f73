"""Checkpoints: what a run needs to continue after its last converged step, and the restart.

A checkpoint is a folder ``<out>/checkpoint/step_NNNNNN`` with one file per rank
(``rank_R.pkl``: that rank's share of the state) and ``<out>/checkpoint/latest.json``
(rank 0, written last and atomically: the step, the load or time, the scene, its parameters
and numerics, the ranks and the mesh's size) naming the complete one; the previous one is
removed after. A run stopped while writing keeps the last complete checkpoint.

The state is captured from the run's objects (the problem, its post-processor, the solver
and its wrappers, the stepper, the scene) by :func:`capture`: every dolfinx Function's
values, every Constant's, every PETSc vector's owned values, the nonzero pattern of the
matrices an object names in its ``checkpoint_patterns`` (:func:`_grow`: a two-body
Jacobian's) and the values of those it names in ``checkpoint_values`` (a kept
preconditioner's matrix), and the plain data (but the attributes it names in
``checkpoint_skip``: this run's clock, not state) (numbers, arrays, tuples, lists and dicts
of them) of every contactfx object they hold, by attribute
path. :func:`restore` puts them back into the same objects of a run built again from the
same input, so a restarted run continues with the same bits: the unknowns, multipliers,
friction histories, the couplings' closed sets and slip histories, the stepper's last two
states and increment. The files are Python pickles, read back only from the run's own
output folder (as trusted as the run's script).

A restart needs the same scene, parameters, numerics, number of ranks and mesh (each rank's
cells and coordinates, compared by a hash); anything else is refused in one line naming
what differs.
"""

from __future__ import annotations

import copy
import hashlib
import json
import pickle
import shutil
from pathlib import Path
from typing import Any

import dolfinx
import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

from contactfx.io.provenance import write_json_local

__all__ = ["capture", "restore", "write_checkpoint", "read_checkpoint", "mesh_hash", "CHECKPOINT"]

#: the checkpoint folder inside a run's output folder
CHECKPOINT = "checkpoint"
_LATEST = "latest.json"
_PLAIN = (int, float, bool, str, bytes, type(None), np.ndarray, np.generic)


def _plain(v: Any) -> bool:
    if isinstance(v, _PLAIN):
        return True
    if isinstance(v, list | tuple):
        return all(_plain(x) for x in v)
    if isinstance(v, dict):
        return all(isinstance(k, str | int) and _plain(x) for k, x in v.items())
    return False


def _ours(v: Any) -> bool:
    return type(v).__module__.startswith("contactfx") and hasattr(v, "__dict__")


def _item(v: Any, seen: set[int]) -> tuple[str, Any] | None:
    """The saved form of one value, or None (not state: forms, meshes, PETSc solvers)."""
    if isinstance(v, dolfinx.fem.Function):
        return ("F", v.x.array.copy())
    if isinstance(v, dolfinx.fem.Constant):
        return ("C", np.array(v.value, copy=True))
    if isinstance(v, PETSc.Vec):
        return ("V", v.getArray(readonly=True).copy())
    if _plain(v):
        return ("P", copy.deepcopy(v))
    if isinstance(v, list | tuple) and v and not all(_plain(x) for x in v):
        items = [_item(x, seen) for x in v]
        return ("L", items) if any(i is not None for i in items) else None
    if _ours(v):
        if id(v) in seen:
            return None
        seen.add(id(v))
        return ("O", _capture(v, seen))
    return None


def _capture(obj: Any, seen: set[int]) -> dict[str, Any]:
    out = {}
    grown = getattr(obj, "checkpoint_patterns", ())
    valued = getattr(obj, "checkpoint_values", ())
    skip = getattr(obj, "checkpoint_skip", ())
    for name, v in vars(obj).items():
        if name in skip:
            continue
        if name in grown and isinstance(v, PETSc.Mat) and v.isAssembled():
            out[name] = ("M", _pattern(v))
            continue
        if name in valued and isinstance(v, PETSc.Mat) and v.isAssembled():
            out[name] = ("MV", (_pattern(v), v.getValuesCSR()[2].copy()))
            continue
        item = _item(v, seen)
        if item is not None:
            out[name] = item
    return out


def capture(roots: dict[str, Any]) -> dict[str, Any]:
    """The state of ``roots`` (name -> object) and of everything they hold (module
    docstring); an object reachable twice is saved at its first path."""
    seen: set[int] = set()
    out = {}
    for name, obj in roots.items():
        item = _item(obj, seen)
        if item is not None:
            out[name] = item
    return out


def _put(target: Any, item: tuple[str, Any], grows: list) -> Any:
    """Put a saved value into ``target`` in place where it holds memory; returns the value
    to set (plain data), or the target itself."""
    kind, value = item
    if kind == "F" and isinstance(target, dolfinx.fem.Function):
        target.x.array[:] = value  # the same space: the same size
    elif kind == "C" and isinstance(target, dolfinx.fem.Constant):
        target.value[...] = value
    elif kind == "V" and isinstance(target, PETSc.Vec):
        # a vector of another size is sized by a contact search, which builds it again
        # (the owned values: no collective here, a restore may differ between ranks; the
        # Functions' arrays carry their ghosts, the stepper updates the unknown's)
        if target.getLocalSize() == len(value):
            target.setArray(value)
    elif kind == "M" and isinstance(target, PETSc.Mat):
        grows.append((target, value))  # collective: after the walk
    elif kind == "MV" and isinstance(target, PETSc.Mat):
        grows.append((target, value))  # (its pattern, its values)
    elif kind == "P":
        return copy.deepcopy(value)
    elif kind == "L" and isinstance(target, list | tuple):
        for t, i in zip(target, value, strict=False):
            if i is not None:
                _put(t, i, grows)
    elif kind == "O" and _ours(target):
        _restore(target, value, grows)
    return target


def _restore(obj: Any, saved: dict[str, Any], grows: list) -> None:
    for name, item in saved.items():
        target = getattr(obj, name, None)
        new = _put(target, item, grows)
        if item[0] == "P" and not _same(target, new):
            object.__setattr__(obj, name, new)


def _same(a: Any, b: Any) -> bool:
    """Plain data equal to the last bit (arrays by shape, type and values)."""
    if type(a) is not type(b):
        return False
    if isinstance(a, np.ndarray):
        return a.shape == b.shape and a.dtype == b.dtype and np.array_equal(a, b, equal_nan=True)
    if isinstance(a, list | tuple):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b, strict=True))
    if isinstance(a, dict):
        return a.keys() == b.keys() and all(_same(a[k], b[k]) for k in a)
    return bool(a == b) or (a != a and b != b)  # NaN


def _pattern(A: PETSc.Mat) -> tuple[tuple, np.ndarray, np.ndarray]:
    """The nonzero pattern of this rank's rows: ((first row, global shape), row offsets,
    global columns)."""
    indptr, indices, _ = A.getValuesCSR()
    return (A.getOwnershipRange()[0], A.getSize()), indptr.copy(), indices.copy()


def _grow(A: PETSc.Mat, saved: tuple[tuple, np.ndarray, np.ndarray]) -> None:
    """Give ``A`` the entries of a saved pattern it lacks (explicit zeros). A matrix whose
    pattern grew over the steps (a two-body Jacobian gains the couplings of every search)
    keeps its past entries as zeros, and the factorisation's ordering follows the pattern: a
    restarted run must factorise the same pattern to continue with the same bits."""
    (start, shape), indptr, indices = saved
    comm = A.getComm().tompi4py()
    same_rows = (A.getOwnershipRange()[0], A.getSize()) == (start, tuple(shape)) and (
        A.getLocalSize()[0] == len(indptr) - 1
    )
    # a matrix of other rows is built by a contact search, again at the next; one not yet
    # assembled takes its pattern from its form's sparsity at its first assembly
    if not comm.allreduce(same_rows and A.isAssembled(), op=MPI.LAND):
        return
    now = _pattern(A)
    same = np.array_equal(now[1], indptr) and np.array_equal(now[2], indices)
    if comm.allreduce(same, op=MPI.LAND):
        return
    n, cols = len(indptr) - 1, A.getSize()[1]

    def keys(ptr, idx):
        return np.repeat(np.arange(n, dtype=np.int64), np.diff(ptr)) * cols + idx

    missing = np.setdiff1d(keys(indptr, indices), keys(now[1], now[2]))
    rows, columns = np.divmod(missing, cols)  # sorted by row, then column
    add = PETSc.InsertMode.ADD_VALUES
    try:
        for r in np.unique(rows):  # the rows of past contacts: few
            c = columns[rows == r].astype(PETSc.IntType)
            A.setValues([start + int(r)], c, np.zeros(len(c), dtype=PETSc.ScalarType), addv=add)
    except PETSc.Error:
        pass  # a matrix that takes no new entries: built by a contact search, again at the next
    A.assemble()  # on every rank, whatever each inserted


def restore(roots: dict[str, Any], saved: dict[str, Any], comm) -> None:
    """Put the state of :func:`capture` back into the same objects of a run built again.
    Collective (the matrices' patterns are assembled on every rank)."""
    grows: list = []
    for name, item in saved.items():
        if name in roots:
            _put(roots[name], item, grows)
    if comm.allreduce(len(grows), op=MPI.MIN) != comm.allreduce(len(grows), op=MPI.MAX):
        raise ValueError("the checkpoint's matrices differ between the ranks: cannot restart")
    for A, saved in grows:
        if len(saved) == 2:  # a matrix whose values are state
            _set_values(A, *saved)
        else:
            _grow(A, saved)


def _set_values(A: PETSc.Mat, pattern: tuple, values: np.ndarray) -> None:
    """Put a matrix's saved values back (``checkpoint_values``: a kept preconditioner's
    matrix, whose factorisation a restarted run must rebuild to continue with the same bits);
    left alone where its pattern differs from the saved one on some rank (collective)."""
    (start, shape), indptr, indices = pattern
    now = _pattern(A) if A.isAssembled() else None
    same = now is not None and (
        (now[0] == (start, tuple(shape)) or now[0] == (start, shape))
        and np.array_equal(now[1], indptr)
        and np.array_equal(now[2], indices)
    )
    if not A.getComm().tompi4py().allreduce(same, op=MPI.LAND):
        return
    A.zeroEntries()
    A.setValuesCSR(indptr, indices, values)
    A.assemble()


def mesh_hash(mesh) -> str:
    """This rank's cells (global numbers of their vertices' geometry) and coordinates."""
    h = hashlib.sha256()
    h.update(np.ascontiguousarray(mesh.geometry.x).tobytes())
    imap = mesh.topology.index_map(mesh.topology.dim)
    h.update(np.int64(imap.size_local).tobytes() + np.int64(imap.local_range[0]).tobytes())
    return h.hexdigest()


def write_checkpoint(out: Path, comm, step: int, meta: dict, state: Any) -> None:
    """Write this rank's ``state`` for ``step`` and, once every rank has, ``latest.json``
    (rank 0, atomically) with ``meta``; then remove the older checkpoints. Collective."""
    root = Path(out) / CHECKPOINT
    folder = root / f"step_{step:06d}"
    if comm.rank == 0:
        folder.mkdir(parents=True, exist_ok=True)
    comm.barrier()
    path = folder / f"rank_{comm.rank}.pkl"
    tmp = path.with_suffix(".tmp")
    with open(tmp, "wb") as fh:
        pickle.dump(state, fh, protocol=pickle.HIGHEST_PROTOCOL)
    tmp.replace(path)
    comm.barrier()
    if comm.rank == 0:
        write_json_local(root / _LATEST, {**meta, "step": step, "folder": folder.name})
        for old in root.glob("step_*"):
            if old.name != folder.name:
                shutil.rmtree(old, ignore_errors=True)
    comm.barrier()


def read_checkpoint(folder: Path, comm) -> tuple[dict, Any]:
    """(meta, this rank's state) of the last complete checkpoint of the run in ``folder``;
    ValueError in one line when there is none or it was written on another number of
    ranks."""
    root = Path(folder) / CHECKPOINT
    latest = root / _LATEST
    if not latest.exists():
        raise ValueError(f"--restart {folder}: no checkpoint there ({latest} missing)")
    meta = json.loads(latest.read_text())
    if meta.get("ranks") != comm.size:
        raise ValueError(
            f"--restart {folder}: the checkpoint was written on {meta.get('ranks')} rank(s), "
            f"this run has {comm.size}: restart on the same number of ranks"
        )
    path = root / meta["folder"] / f"rank_{comm.rank}.pkl"
    with open(path, "rb") as fh:
        state = pickle.load(fh)
    return meta, state
