"""Checking a residual written by hand against the one a method builds (demos, tests): both
assembled at an arbitrary state of the problem, compared in the Euclidean norm."""

from __future__ import annotations

import dolfinx
import numpy as np

from contactfx import _compat
from contactfx.solvers.snes import owned_size

__all__ = ["random_state", "relative_difference"]


def random_state(f, scale: float, seed: int = 7) -> None:
    """Uniform random owned values in [-scale, scale] (ghosts updated) of the Function f."""
    n = owned_size(f.function_space)
    f.x.array[:n] = scale * np.random.default_rng(seed).uniform(-1.0, 1.0, n)
    f.x.scatter_forward()


def relative_difference(F, G) -> float:
    """|b(F - G)| / |b(F)| for the assembled vectors b of the linear forms F and G (UFL)."""

    def norm(form) -> float:
        compiled = dolfinx.fem.form(form)
        b = _compat.assemble_vector(_compat.create_vector(compiled), compiled)
        value = b.norm()
        b.destroy()
        return value

    return norm(F - G) / norm(F)
