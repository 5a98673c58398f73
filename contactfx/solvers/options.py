"""PETSc's options database under one solver's prefix: the defaults, the user's options on
top, and their removal when the solver is destroyed (Firedrake's OptionsManager is the model:
options sit in PETSc's global database only under a deterministic prefix)."""

from __future__ import annotations

from collections.abc import Mapping

from petsc4py import PETSc

__all__ = ["OptionsDB", "option_value"]


def option_value(value: object) -> str:
    """The string PETSc's database stores for a Python value (None: a flag)."""
    if value is None:
        return ""
    if isinstance(value, bool):
        return "true" if value else "false"
    return str(value)


class OptionsDB:
    """The options of ``prefix`` (``contactfx_<scene>_``): ``user`` holds the command line's
    options; an unprefixed one applies under this prefix, one starting with ``contactfx_`` as
    it is."""

    def __init__(self, prefix: str, user: Mapping[str, object] | None = None) -> None:
        self.prefix = prefix
        self.user = dict(user or {})

    def apply(self, defaults: Mapping[str, object]) -> None:
        """Set ``defaults`` under the prefix, then the user's options (which win)."""
        opts = PETSc.Options()
        for key, value in defaults.items():
            opts[self.prefix + key] = option_value(value)
        for key, value in self.user.items():
            name = key if key.startswith("contactfx_") else self.prefix + key
            opts[name] = option_value(value)

    def user_sets(self, key: str) -> bool:
        """Whether the user's options give ``key`` (a PETSc option name without the prefix),
        with or without this prefix."""
        return bool({key, self.prefix + key} & set(self.user))

    def set(self, key: str, value: object) -> None:
        """Set ``key`` under the prefix (read by the next ``setFromOptions`` or set-up)."""
        PETSc.Options()[self.prefix + key] = option_value(value)

    def clear(self) -> None:
        """Remove every option under the prefix."""
        opts = PETSc.Options()
        for key in list(opts.getAll()):
            if key.startswith(self.prefix):
                opts.delValue(key)
