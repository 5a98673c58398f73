"""The registry of contact methods: name -> the class implementing
:class:`contactfx.contact.method.ContactMethod`. Adding a method is one module and one line
here."""

from __future__ import annotations

import importlib
from collections.abc import Callable
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from contactfx.contact.method import MethodBase, Supports

__all__ = ["METHODS", "method_class", "methods_supporting"]

#: name -> "module:class", in the order the command line lists them
METHODS: dict[str, str] = {
    "nitsche": "contactfx.contact.nitsche:Nitsche",
    "penalty": "contactfx.contact.penalty:Penalty",
    "compliance": "contactfx.contact.compliance:NormalCompliance",
    "vi": "contactfx.contact.bounds:BoundConstraints",
    "al-uzawa": "contactfx.contact.augmented_lagrangian:AugmentedLagrangianUzawa",
    "al-ssn": "contactfx.contact.augmented_lagrangian:AugmentedLagrangianSSN",
    "mortar": "contactfx.contact.mortar:Mortar",
}


def method_class(name: str) -> type[MethodBase]:
    """The class registered as ``name``."""
    try:
        module, cls = METHODS[name].split(":")
    except KeyError:
        raise ValueError(f"unknown method '{name}' (known: {', '.join(METHODS)})") from None
    return getattr(importlib.import_module(module), cls)


def methods_supporting(predicate: Callable[[Supports], bool]) -> list[str]:
    """Names of the methods whose ``supports`` satisfies ``predicate``."""
    return [name for name in METHODS if predicate(method_class(name).supports)]
