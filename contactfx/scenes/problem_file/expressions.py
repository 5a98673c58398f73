"""Closed forms written in a problem file: expressions in x, y, z (signed distances of rigid
obstacles, stress fields on a boundary, initial displacements) parsed into UFL, nothing
evaluated as Python."""

from __future__ import annotations

import ast
import re

import numpy as np
import ufl

from contactfx import _compat
from contactfx.contact.obstacles import Obstacle

__all__ = ["parse_expression", "DistanceObstacle"]

_FUNCTIONS = {
    "sqrt": ufl.sqrt,
    "sin": ufl.sin,
    "cos": ufl.cos,
    "tan": ufl.tan,
    "exp": ufl.exp,
    "ln": ufl.ln,
    "abs": abs,
    "atan2": _compat.ufl_math.atan2,
    "min": ufl.min_value,
    "max": ufl.max_value,
}
_BINARY = {
    ast.Add: lambda a, b: a + b,
    ast.Sub: lambda a, b: a - b,
    ast.Mult: lambda a, b: a * b,
    ast.Div: lambda a, b: a / b,
    ast.Pow: lambda a, b: a**b,
}


def parse_expression(text: str):
    """A function y -> UFL of the expression ``text`` in x, y, z (the coordinates of the point
    in the obstacle's frame), numbers, + - * / **, pi and the functions sqrt, sin, cos, tan,
    exp, ln, abs, atan2, min, max. Definitions ``name = expression`` may come first, separated
    by ';' or new lines, the last statement being the value: a long closed form names its
    repeated parts once (``r = sqrt(x**2 + y**2); 1 / r``). Anything else is refused (nothing
    is evaluated as Python)."""
    shown = re.sub(r"\s+", " ", text.strip())
    shown = shown if len(shown) <= 80 else shown[:77] + "..."
    try:
        module = ast.parse("\n".join(line.strip() for line in text.strip().splitlines()))
    except SyntaxError:
        raise ValueError(f"not an expression: '{shown}'") from None
    *defs, last = module.body or [None]
    if not isinstance(last, ast.Expr) or not all(
        isinstance(d, ast.Assign) and len(d.targets) == 1 and isinstance(d.targets[0], ast.Name)
        for d in defs
    ):
        raise ValueError(
            f"not an expression: '{shown}' (definitions name = expression, then the value)"
        )
    for d in defs:
        if d.targets[0].id in ("x", "y", "z", "pi", *_FUNCTIONS):
            raise ValueError(f"'{d.targets[0].id}' cannot be redefined in '{shown}'")

    def build(node, y, env):
        if isinstance(node, ast.Constant) and isinstance(node.value, int | float):
            return float(node.value)
        if isinstance(node, ast.Name) and node.id in env:
            return env[node.id]
        if isinstance(node, ast.Name) and node.id in ("x", "y", "z"):
            i = "xyz".index(node.id)
            if i >= ufl.shape(y)[0]:
                raise ValueError(f"'{node.id}' in a {ufl.shape(y)[0]}D problem")
            return y[i]
        if isinstance(node, ast.Name) and node.id == "pi":
            return float(np.pi)
        if isinstance(node, ast.BinOp) and type(node.op) in _BINARY:
            return _BINARY[type(node.op)](build(node.left, y, env), build(node.right, y, env))
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub | ast.UAdd):
            v = build(node.operand, y, env)
            return -v if isinstance(node.op, ast.USub) else v
        if (
            isinstance(node, ast.Call)
            and isinstance(node.func, ast.Name)
            and node.func.id in _FUNCTIONS
            and not node.keywords
        ):
            return _FUNCTIONS[node.func.id](*(build(a, y, env) for a in node.args))
        raise ValueError(
            f"'{ast.unparse(node)}' is not allowed in '{shown}' (numbers, x, y, "
            "z, pi, + - * / **, " + ", ".join(_FUNCTIONS) + ")"
        )

    def evaluate(y):
        env = {}
        for d in defs:
            env[d.targets[0].id] = build(d.value, y, env)
        return build(last.value, y, env)

    # check the names and operators once, in 3D
    evaluate(ufl.as_vector([1.0, 1.0, 1.0]))
    return evaluate


class DistanceObstacle(Obstacle):
    """A rigid obstacle given by a signed distance expression phi(y) (> 0 outside it) in the
    obstacle's frame; the normal is -grad phi / |grad phi|."""

    def __init__(self, phi) -> None:
        self._phi = phi

    def phi(self, y):
        return self._phi(y)

    def height(self, t: np.ndarray) -> np.ndarray:
        raise ValueError(
            "the vi method needs an obstacle with a height function (plane, "
            "circle, cylinder, sphere), not a distance expression"
        )
