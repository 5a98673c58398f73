"""Validated parameters: a dataclass field made with :func:`param` carries its help text and
its rule (positive, non-negative, one of given choices); :func:`validate` checks them all and
names the offending command-line option. Scenes, numerics and methods declare their
parameters this way, and the command line builds its options from them."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Any

__all__ = ["param", "validate", "Params", "option_name", "option_help"]


def param(
    default: Any,
    help: str,
    *,
    positive: bool = False,
    nonnegative: bool = False,
    choices: tuple | None = None,
    option: str | None = None,
):
    """A parameter with its help text and validation rule. ``option``: the name it has on the
    command line and in :class:`contactfx.numerics.Numerics` when it differs from the field's
    (a method's ``kappa0`` is the option ``penalty``)."""
    meta = {
        "help": help,
        "positive": positive,
        "nonnegative": nonnegative,
        "choices": choices,
        "option": option,
    }
    return field(default=default, metadata=meta)


def option_name(f: dataclasses.Field) -> str:
    """The option name of a field made with :func:`param`."""
    return f.metadata.get("option") or f.name


def option_help(f: dataclasses.Field) -> str:
    """The help text of a field made with :func:`param`, its choices appended (``--help`` and
    ``contactfx list``: ``enforcement method; one of nitsche, penalty, ...``)."""
    text = f.metadata.get("help", "")
    choices = f.metadata.get("choices")
    if choices is not None and len(choices) > 1:
        text += "; one of " + ", ".join(str(c) for c in choices)
    return text


def validate(obj) -> None:
    """Check every field's rule; raise ValueError naming the parameter."""
    for f in dataclasses.fields(obj):
        value = getattr(obj, f.name)
        name = option_name(f).replace("_", "-")
        if f.metadata.get("positive") and not value > 0:
            raise ValueError(f"--{name} must be > 0, got {value}")
        if f.metadata.get("nonnegative") and not value >= 0:
            raise ValueError(f"--{name} must be >= 0, got {value}")
        choices = f.metadata.get("choices")
        if choices is not None and value not in choices:
            allowed = ", ".join(str(c) for c in choices)
            raise ValueError(f"--{name} must be one of {allowed}, got {value}")


@dataclass(frozen=True)
class Params:
    """Base of the parameter dataclasses: fields made with :func:`param` are validated on
    construction."""

    def __post_init__(self) -> None:
        validate(self)
