"""Typed access to a problem file's TOML tables: every error is one line naming the file and
the key (:class:`ProblemError`); the ``--set`` overrides."""

from __future__ import annotations

import copy
import tomllib
from pathlib import Path
from typing import Any, NoReturn

import numpy as np

__all__ = ["ProblemError", "Reader", "apply_sets", "amplitude_at", "is_number", "numbers"]


class ProblemError(ValueError):
    """A problem file that cannot be solved as written (one line: the file, the key, why)."""


def is_number(value: Any) -> bool:
    """A TOML number (not a boolean)."""
    return isinstance(value, int | float) and not isinstance(value, bool)


def numbers(value: Any, length: int | tuple[int, ...] | None = None, minimum: int = 0) -> bool:
    """Whether ``value`` is a list of numbers (of ``length``, one of the lengths, or at least
    ``minimum`` entries)."""
    if not isinstance(value, list) or len(value) < minimum:
        return False
    if isinstance(length, int) and len(value) != length:
        return False
    if isinstance(length, tuple) and len(value) not in length:
        return False
    return all(is_number(v) for v in value)


def _parse_value(text: str) -> Any:
    """A --set value: TOML syntax when it parses (numbers, booleans, arrays, quoted strings),
    else the bare text as a string."""
    try:
        return tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        return text


def apply_sets(data: dict, sets: list[str], where: str) -> dict:
    """``data`` with the ``key.sub=value`` overrides applied (arrays of tables by index:
    ``bodies.0.E=2e5``)."""
    data = copy.deepcopy(data)
    for item in sets:
        if "=" not in item:
            raise ProblemError(f"{where}: --set expects key=value, got '{item}'")
        key, text = item.split("=", 1)
        parts = key.strip().split(".")
        node: Any = data
        for i, part in enumerate(parts[:-1]):
            if isinstance(node, list):
                if not part.isdigit() or int(part) >= len(node):
                    raise ProblemError(
                        f"{where}: --set {key}: no entry {part} in '{'.'.join(parts[:i])}'"
                    )
                node = node[int(part)]
            else:
                node = node.setdefault(part, {})
            if not isinstance(node, dict | list):
                raise ProblemError(f"{where}: --set {key}: '{part}' is not a table")
        if isinstance(node, list):
            raise ProblemError(f"{where}: --set {key}: give the entry's index")
        node[parts[-1]] = _parse_value(text.strip())
    return data


def amplitude_at(table: list[tuple[float, float]], t: float) -> float:
    """The piecewise-linear amplitude ``table`` of (load factor, multiplier) pairs at t."""
    ts, vs = zip(*table, strict=True)
    return float(np.interp(t, ts, vs))


class Reader:
    """Typed access to the file's tables with errors that name the file and the key."""

    def __init__(self, path: Path) -> None:
        self.path = path

    def fail(self, key: str, message: str) -> NoReturn:
        raise ProblemError(f"{self.path}: {key}: {message}")

    def table(self, data: Any, key: str, allowed: tuple[str, ...]) -> dict:
        if not isinstance(data, dict):
            self.fail(key, f"expected a table, got {data!r}")
        for k in data:
            if k not in allowed:
                self.fail(f"{key}.{k}", f"unknown key (allowed: {', '.join(allowed)})")
        return data

    def number(
        self, data: dict, key: str, name: str, default: Any = None, positive: bool = False
    ) -> float:
        value = data.get(name, default)
        if value is None:
            self.fail(f"{key}.{name}", "missing (a number)")
        if not is_number(value):
            self.fail(f"{key}.{name}", f"expected a number, got {value!r}")
        if not np.isfinite(value):
            self.fail(f"{key}.{name}", f"must be finite, got {value}")
        if positive and not value > 0:
            self.fail(f"{key}.{name}", f"must be > 0, got {value}")
        return float(value)

    def optional_number(self, data: dict, key: str, name: str, positive: bool = False):
        """The number ``name`` of ``data`` if given, else None."""
        return self.number(data, key, name, positive=positive) if name in data else None

    def flag(self, data: dict, key: str, name: str, default: bool = False) -> bool:
        """The boolean ``name`` of ``data`` (``true`` / ``false``)."""
        value = data.get(name, default)
        if not isinstance(value, bool):
            self.fail(f"{key}.{name}", f"expected true or false, got {value!r}")
        return value

    def string(
        self, data: dict, key: str, name: str, choices: Any = None, default: Any = None
    ) -> str:
        value = data.get(name, default)
        if not isinstance(value, str):
            self.fail(
                f"{key}.{name}",
                f"expected a string, got {value!r}" if value is not None else "missing (a string)",
            )
        if choices is not None and value not in choices:
            self.fail(f"{key}.{name}", f"must be one of {', '.join(choices)}, got '{value}'")
        return value

    def vector(self, value: Any, key: str, gdim: int) -> np.ndarray:
        """``value`` as ``gdim`` numbers (``key``: the value's own key)."""
        if not numbers(value, gdim):
            self.fail(key, f"expected {gdim} numbers, got {value!r}")
        return np.asarray(value, dtype=np.float64)

    def components(self, value: Any, key: str, axes: tuple[str, ...]) -> tuple[int, ...]:
        """A non-empty list of components among ``axes`` as sorted indices."""
        if not isinstance(value, list) or not value or any(c not in axes for c in value):
            self.fail(key, f"expected a list of components among x, y, z, got {value!r}")
        return tuple(sorted({axes.index(c) for c in value}))

    def amplitude(self, data: dict, key: str) -> tuple[tuple[float, float], ...]:
        value = data.get("amplitude", [[0.0, 0.0], [1.0, 1.0]])
        rows = isinstance(value, list) and len(value) >= 1 and all(numbers(r, 2) for r in value)
        if not rows:
            self.fail(
                f"{key}.amplitude",
                f"expected a table of [load factor, multiplier] pairs, got {value!r}",
            )
        self._increasing([r[0] for r in value], f"{key}.amplitude")
        return tuple((float(a), float(b)) for a, b in value)

    def offsets(self, data: dict, key: str) -> tuple[tuple[float, ...], ...]:
        value = data["path"]
        rows = (
            isinstance(value, list)
            and len(value) >= 1
            and all(numbers(r, minimum=2) for r in value)
            and len({len(r) for r in value}) == 1
        )
        if not rows:
            self.fail(
                f"{key}.path",
                f"expected a table of [load factor, offset components] rows, got {value!r}",
            )
        self._increasing([r[0] for r in value], f"{key}.path")
        return tuple(tuple(float(v) for v in r) for r in value)

    def _increasing(self, ts: list, key: str) -> None:
        if any(b <= a for a, b in zip(ts, ts[1:], strict=False)):
            self.fail(key, f"load factors must increase, got {ts}")
