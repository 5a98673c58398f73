"""A TOML writer for the problem files ``contactfx init`` writes (the standard library reads
TOML, ``tomllib``, but does not write it).

Only what a problem file holds: tables, arrays of tables, and values that are strings,
booleans, numbers, arrays of them and inline tables of numbers. Floats are written with
``repr`` (the shortest text that reads back to the same double), so a file written and read
again gives the same numbers bit for bit.
"""

from __future__ import annotations

import math

__all__ = ["dumps"]


def _key(k: str) -> str:
    if k and all(c.isalnum() or c in "_-" for c in k):
        return k
    return _string(k)


def _string(s: str) -> str:
    out = s.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n").replace("\t", "\\t")
    return f'"{out}"'


def _value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if not math.isfinite(v):
            raise ValueError(f"TOML: {v} is not a finite number")
        return repr(v)
    if isinstance(v, str):
        return _string(v)
    if isinstance(v, list | tuple):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{_key(k)} = {_value(x)}" for k, x in v.items()) + " }"
    if hasattr(v, "item"):  # numpy scalars
        return _value(v.item())
    raise TypeError(f"TOML: cannot write {v!r}")


def _is_table_array(v) -> bool:
    return isinstance(v, list) and bool(v) and all(isinstance(x, dict) for x in v)


def dumps(data: dict, comments: dict[str, str] | None = None) -> str:
    """The TOML text of ``data``: plain values first, then its tables (``[name]``, one level)
    and arrays of tables (``[[name]]``); a table's inner dicts are written inline.
    ``comments`` maps a section name to a comment line written above it."""
    comments = comments or {}
    lines: list[str] = []
    for k, v in data.items():
        if not isinstance(v, dict) and not _is_table_array(v):
            lines.append(f"{_key(k)} = {_value(v)}")
    for k, v in data.items():
        if isinstance(v, dict):
            items = [v]
            head = f"[{_key(k)}]"
        elif _is_table_array(v):
            items = v
            head = f"[[{_key(k)}]]"
        else:
            continue
        for table in items:
            lines.append("")
            if k in comments:
                lines.append(f"# {comments[k]}")
            lines.append(head)
            lines += [f"{_key(kk)} = {_value(vv)}" for kk, vv in table.items()]
    return "\n".join(lines).lstrip("\n") + "\n"
