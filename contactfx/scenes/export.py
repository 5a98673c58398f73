"""``contactfx init``: a built-in scene written as a problem file with its mesh beside it.

The scene gives its gmsh geometry (:meth:`contactfx.scenes.base.Scene.mesh_builder`), written
to ``<scene>.msh`` with its physical names, and its physics as the tables of a problem file
(:meth:`contactfx.scenes.base.Scene.problem_data`): bodies, supports and loads with their load
amplitudes, the obstacle, contact pair or interface, the initial state, the outputs. The
numerics are the run's. Solving the file (:mod:`contactfx.scenes.problem_file`) is the scene's
discrete problem: the same mesh, forms and load program, so the same numbers up to round-off
(docs/verification.md section 11).
"""

from __future__ import annotations

import dataclasses
import types
from pathlib import Path

from mpi4py import MPI

from contactfx.io.toml import dumps
from contactfx.meshes import write_msh
from contactfx.numerics import Numerics
from contactfx.scenes.problem_file.specs import DYNAMICS_NUMERICS, SECTIONS

__all__ = ["write_problem", "numerics_table", "Symbol", "SYMBOLIC"]

#: the sections in the order a problem file is read and written
ORDER = SECTIONS


def numerics_table(numerics: Numerics) -> dict:
    """The numerics that differ from the defaults, with the method and the steps always."""
    default = Numerics()
    out = {}
    for f in dataclasses.fields(Numerics):
        value = getattr(numerics, f.name)
        if f.name in ("method", "steps") or value != getattr(default, f.name):
            out[f.name] = value
    return out


def _numerics_tables(numerics: Numerics, dynamics: dict | None) -> dict:
    """``[numerics]``, and for a dynamic run ``[dynamics]``: the scene's table (gravity,
    initial velocity) with the time scheme, step and end time of the numerics (a [dynamics]
    section makes the run dynamic)."""
    table = numerics_table(numerics)
    if not numerics.dynamic:
        return {"numerics": table}
    table.pop("dynamic")
    table.pop("steps")  # a dynamic run steps in time
    timing = {k: table.pop(k) for k in DYNAMICS_NUMERICS if k in table}
    return {"dynamics": {**timing, **(dynamics or {})}, "numerics": table}


def write_problem(
    scene, numerics: Numerics, out: Path, command: str, comm: MPI.Comm = MPI.COMM_WORLD
) -> tuple[Path, Path]:
    """Write ``out/<scene>.msh`` and ``out/<scene>.toml``; returns their paths. Collective:
    rank 0 writes, an error there is raised on every rank."""
    try:
        tables = scene.problem_data(numerics)  # refuses what a problem file cannot say, first
    except NotImplementedError as exc:
        raise ValueError(str(exc)) from None
    builder, gdim = scene.mesh_builder()
    out = Path(out)
    msh, toml = out / f"{scene.name}.msh", out / f"{scene.name}.toml"
    failure = None
    if comm.rank == 0:
        try:
            out.mkdir(parents=True, exist_ok=True)
            write_msh(builder, gdim, msh, scene.name, binary=True)  # exact coordinates
            doc = {
                "title": scene.name,
                "mesh": {
                    "file": msh.name,
                    **({"axisymmetric": True} if scene.axisymmetric else {}),
                },
                **tables,
                **_numerics_tables(numerics, tables.get("dynamics")),
            }
            doc = {k: doc[k] for k in ORDER if k in doc}
            head = (
                f"# {scene.summary}\n# the built-in scene '{scene.name}' as a problem file, "
                f"written by: {command}\n# solve it with: contactfx solve {toml.name}\n\n"
            )
            toml.write_text(head + dumps(doc))
        except Exception as exc:
            failure = exc
    failure = comm.bcast(failure, root=0)
    if failure is not None:
        raise failure
    return msh, toml


# -- helpers of the scenes' problem_data ---------------------------------------------------

AXES = ("x", "y", "z")


def body(group: str, material, **extra) -> dict:
    """A ``[[bodies]]`` table (with the density of a material that has one)."""
    out = {"group": group, "E": float(material.E), "nu": float(material.nu)}
    if material.density is not None:
        out["density"] = float(material.density)
    return {**out, **extra}


def fixed(group: str, components) -> dict:
    """A ``[[boundary]]`` table fixing the components (indices) on the group."""
    return {"group": group, "fix": [AXES[c] for c in components]}


def motion(offset, gdim: int, kinks=(0.0, 1.0)) -> dict:
    """The obstacle's motion keys from its rigid offset ``offset(t, gdim)``, piecewise linear
    in the load factor with the kinks ``kinks``: ``position`` and ``motion`` when it is linear,
    else a ``path`` table."""
    rows = [[float(t), *(float(v) for v in offset(t, gdim))] for t in kinks]
    if len(rows) == 2 and rows[0][0] == 0.0 and rows[1][0] == 1.0:
        start, end = rows[0][1:], rows[1][1:]
        out = {}
        if any(start):
            out["position"] = start
        if any(e - s for s, e in zip(start, end, strict=True)):
            out["motion"] = [e - s for s, e in zip(start, end, strict=True)]
        return out
    return {"path": rows}


def pins(pinned) -> list[dict]:
    """``[[pins]]`` tables from the scene's (point, component) pairs, one table per point."""
    out: list[dict] = []
    for point, comp in pinned:
        point = [float(v) for v in point]
        for entry in out:
            if entry["point"] == point:
                entry["fix"].append(AXES[comp])
                break
        else:
            out.append({"point": point, "fix": [AXES[comp]]})
    return out


class Symbol:
    """An expression in x, y, z built by running a closed form's own arithmetic on it (the
    ``m`` namespace of :mod:`contactfx.references` is :data:`SYMBOLIC`) and written as
    problem-file text (:func:`contactfx.scenes.problem_file.parse_expression`) by
    :func:`text`: the file then evaluates the same formula, with the same operations in the
    same order. Products with an exact zero and sums with it are dropped."""

    def __init__(self, op: str, args: tuple = ()) -> None:
        self.op, self.args = op, args  # a variable name (no args), an operator or a function

    @staticmethod
    def _binary(a, b, op: str):
        a, b = (v if isinstance(v, Symbol) else float(v) for v in (a, b))
        if op == "*" and (a == 0.0 or b == 0.0):
            return 0.0
        if op == "+" and (a == 0.0 or b == 0.0):
            return b if a == 0.0 else a
        if op == "-" and b == 0.0:
            return a
        return Symbol(op, (a, b))

    def __add__(self, o):
        return Symbol._binary(self, o, "+")

    def __radd__(self, o):
        return Symbol._binary(o, self, "+")

    def __sub__(self, o):
        return Symbol._binary(self, o, "-")

    def __rsub__(self, o):
        return Symbol._binary(o, self, "-")

    def __mul__(self, o):
        return Symbol._binary(self, o, "*")

    def __rmul__(self, o):
        return Symbol._binary(o, self, "*")

    def __truediv__(self, o):
        return Symbol._binary(self, o, "/")

    def __rtruediv__(self, o):
        return Symbol._binary(o, self, "/")

    def __pow__(self, o):
        return Symbol._binary(self, o, "**")

    def __neg__(self):
        return Symbol("neg", (self,))

    def __eq__(self, other) -> bool:  # a symbol is never an exact zero
        return False

    __hash__ = object.__hash__


def _call(name: str):
    return lambda *args: Symbol(name, args)


#: the math namespace of the closed forms (:mod:`contactfx.references`) on :class:`Symbol`
SYMBOLIC = types.SimpleNamespace(
    sqrt=_call("sqrt"),
    atan2=_call("atan2"),
    cos=_call("cos"),
    sin=_call("sin"),
    maximum=_call("max"),
)
_OPERATORS = ("+", "-", "*", "/", "**")


def text(v) -> str | float:
    """A number as a float; a :class:`Symbol` as an expression whose parts used more than once
    are named first (``t0 = ...; t1 = ...; value``), as the closed form computes them."""
    if not isinstance(v, Symbol):
        return float(v)
    uses: dict[int, int] = {}
    order: list[Symbol] = []

    def visit(s) -> None:
        if not isinstance(s, Symbol) or not s.args:
            return
        uses[id(s)] = uses.get(id(s), 0) + 1
        if uses[id(s)] == 1:
            for a in s.args:
                visit(a)
            order.append(s)  # after its parts

    visit(v)
    names: dict[int, str] = {}

    def write(s) -> str:
        if not isinstance(s, Symbol):
            return f"({float(s)!r})"
        if not s.args:
            return s.op
        if id(s) in names:
            return names[id(s)]
        parts = [write(a) for a in s.args]
        if s.op in _OPERATORS:
            return f"({parts[0]} {s.op} {parts[1]})"
        if s.op == "neg":
            return f"(-{parts[0]})"
        return f"{s.op}({', '.join(parts)})"

    lines = []
    for s in order:
        if uses[id(s)] > 1 and s is not v:
            lines.append(f"t{len(names)} = {write(s)}")
            names[id(s)] = f"t{len(names)}"
    return "; ".join([*lines, write(v)])
