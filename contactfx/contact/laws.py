"""Pointwise contact laws as UFL expressions.

Conventions (ARCHITECTURE.md): gap g >= 0 when apart, pressure p >= 0 in compression, g p = 0.
The Signorini conditions are equivalent, for any r > 0, to p = [p - r g]_+ (Alart & Curnier
1991, doi:10.1016/0045-7825(91)90022-X), which is the form every method here discretises.
"""

from __future__ import annotations

import ufl

__all__ = ["positive_part", "active"]


def positive_part(x):
    """[x]_+ = max(x, 0), with the derivative 0 at x = 0 (semi-smooth Newton)."""
    return ufl.conditional(ufl.gt(x, 0.0), x, 0.0)


def active(x):
    """Indicator 1 where x > 0, else 0."""
    return ufl.conditional(ufl.gt(x, 0.0), 1.0, 0.0)
