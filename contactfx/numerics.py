"""How a contact problem is discretised and solved: :class:`Numerics`, shared by all scenes.

Its fields are the general choices (method, friction law, quadrature, degree, formulation,
load steps, linear solver) followed by every registered method's parameters
(:mod:`contactfx.contact.registry`), so that a new method's options appear here, on the
command line and in run.json without further code. Each method's own parameter set is its
dataclass (``method_object()``); an option several methods declare (``r0``, ``ncp``,
``penalty``) means the same thing in each of them, checked at import (:func:`shared_option`).
Whether a combination is supported is asked of the method
(:class:`contactfx.contact.method.Supports`).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from contactfx.contact.laws import friction_law
from contactfx.contact.registry import METHODS, method_class, methods_supporting
from contactfx.mechanics.hyperelastic import material_from_spec, parse_spec
from contactfx.params import option_name, param, validate
from contactfx.solvers.dynamics import SCHEMES, Scheme

__all__ = ["Numerics", "FRICTION_LAWS", "FORMULATIONS", "method_parameters", "shared_option"]

FRICTION_LAWS = ("none", "tresca", "coulomb")
FORMULATIONS = ("displacement", "mixed-up")


@dataclass(frozen=True)
class _General:
    method: str = param("nitsche", "enforcement method", choices=tuple(METHODS))
    friction: str = param("none", "friction law", choices=FRICTION_LAWS)
    mu: float = param(0.0, "Coulomb friction coefficient", nonnegative=True)
    threshold: float = param(0.0, "Tresca friction threshold (stress)", nonnegative=True)
    quadrature: str = param(
        "gauss",
        "contact integrals of nitsche / penalty: gauss (degree "
        "2k + 2) or nodal (at the vertices, P1 only; not between two bodies)",
        choices=("gauss", "nodal"),
    )
    degree: int = param(1, "Lagrange degree of the displacement", choices=(1, 2))
    material: str = param(
        "linear",
        "bulk material: linear (small strain), or finite strain neo-hookean, mooney-rivlin or "
        "svk, with parameters as model:key=value,... (neo-hookean: E,nu or mu,kappa; "
        "mooney-rivlin: c10,c01,kappa; svk: E,nu); omitted ones keep the scene's small-strain "
        "E and nu",
    )
    formulation: str = param(
        "displacement",
        "bulk unknowns: displacement, or mixed-up "
        "(Taylor-Hood P2 displacement / P1 pressure, near-incompressible "
        "materials; needs --degree 2)",
        choices=FORMULATIONS,
    )
    steps: int = param(1, "load steps", positive=True)
    max_increment: float = param(
        0.0,
        "adaptive load stepping: after a step that converges in at most 5 Newton iterations "
        "the increment grows by 1.5, up to this load increment (0: at most 1 / steps)",
        nonnegative=True,
    )
    predictor: str = param(
        "secant",
        "start of each load step: secant (the extrapolation of the last two converged steps), "
        "or previous (the last converged state: for a body dragged over many elements, where "
        "the secant lifts the contact off the surface it has moved on)",
        choices=("secant", "previous"),
    )
    line_search: str = param(
        "basic",
        "Newton's line search: basic (full steps), bt (backtracking on the residual norm), "
        "cp (the step length where the residual is orthogonal to the step: a minimum of the "
        "energy along it; the penalty and hyperelastic problems are energy minimisations) or "
        "auto (cp with penalty and compliance, basic with the multiplier methods)",
        choices=("basic", "bt", "cp", "auto"),
    )
    inversion_check: str = param(
        "halve",
        "finite strain: halve a Newton step (up to 10 times) until no element inverts "
        "(J = det F > 0 in every cell), or off (an inverting step gives a NaN residual, and "
        "the load step is cut back)",
        choices=("halve", "off"),
    )
    solver: str = param(
        "lu",
        "linear solver: MUMPS LU, or GMRES + GAMG in an inexact Newton method (large 3D meshes)",
        choices=("lu", "gamg"),
    )
    nested: int = param(
        0,
        "nested iteration: solve every load step first on this many "
        "coarser meshes (element sizes x2, x4, ...), each solution the start "
        "of the next finer Newton solve (obstacle scenes)",
        nonnegative=True,
    )
    search_update: str = param(
        "step",
        "two-body contact search: once per load step, or at every Newton iteration (always "
        "with a finite-strain --material: the contact in the deformed configuration)",
        choices=("step", "newton"),
    )
    dynamic: bool = param(
        False,
        "implicit dynamics: time steps of --dt up to --t-end with --scheme, the inertia from "
        "the bodies' density (a static run has no mass matrix and no velocity)",
    )
    scheme: str = param(
        "newmark",
        "time scheme of --dynamic: newmark (average acceleration), hht (Hilber-Hughes-Taylor) "
        "or generalized-alpha (Chung-Hulbert), the last two with --rho-inf",
        choices=SCHEMES,
    )
    rho_inf: float = param(
        1.0,
        "spectral radius at infinite time step of hht ([0.5, 1]) and generalized-alpha "
        "([0, 1]): 1 no numerical dissipation, smaller damps the highest frequencies",
        nonnegative=True,
    )
    mass: str = param(
        "consistent",
        "mass matrix of --dynamic: consistent, lumped (P1: the row sums) or redistributed "
        "(lumped, the contact nodes' mass moved to the other nodes of their cells: no inertia "
        "at the contact, after Khenous, Laborde and Renard 2008)",
        choices=("consistent", "lumped", "redistributed"),
    )
    dt: float = param(
        0.0,
        "time step of --dynamic (0: the scene's); with --time-tolerance the first and the "
        "largest step",
        nonnegative=True,
    )
    time_tolerance: float = param(
        0.0,
        "adaptive time step of --dynamic: the largest local error of a step, estimated from "
        "the change of the acceleration (Zienkiewicz and Xie 1991), relative to the step's "
        "displacement; a step above it is repeated at half the size, the step doubles (up to "
        "--dt) where the estimate allows; 0: a fixed step",
        nonnegative=True,
    )
    t_end: float = param(0.0, "end time of --dynamic (0: the scene's)", nonnegative=True)
    dashpot: float = param(
        0.0,
        "contact dashpot C of the penalty method in time (--dynamic), against a rigid "
        "obstacle: where the body penetrates, the normal traction gains C times the rate at "
        "which the gap closes "
        "(a Kelvin-Voigt contact; C is absolute: traction per unit gap rate, not scaled by E "
        "or h); 0: none",
        nonnegative=True,
    )


def method_parameters() -> dict[str, list[tuple[str, dataclasses.Field]]]:
    """Every registered method's parameters by option name: (method, field) of each method
    that declares the option. Each method's own parameter set is its dataclass
    (:meth:`_Checks.method_object` builds it from the options)."""
    out: dict[str, list[tuple[str, dataclasses.Field]]] = {}
    for name in METHODS:
        for f in dataclasses.fields(method_class(name)):
            out.setdefault(option_name(f), []).append((name, f))
    return out


def shared_option(key: str, declared: list[tuple[str, dataclasses.Field]]) -> dataclasses.Field:
    """The Numerics field of an option that one or more methods declare. Methods that share
    an option share its meaning: the same type, default and rule (else the option needs two
    names: a developer's error, raised at import); the help names every method that reads it,
    with each one's own text where they differ."""
    first = declared[0][1]
    rule = ("positive", "nonnegative", "choices")
    for method, f in declared[1:]:
        same = (f.type, f.default) == (first.type, first.default) and all(
            f.metadata.get(r) == first.metadata.get(r) for r in rule
        )
        if not same:
            raise TypeError(
                f"option --{key}: methods {declared[0][0]} and {method} declare it with "
                "different types, defaults or rules; give one of them another name"
            )
    helps = list(dict.fromkeys(f.metadata["help"] for _, f in declared))
    names = ", ".join(m for m, _ in declared)
    if len(helps) == 1:
        text = helps[0] + (f" ({names})" if len(declared) > 1 else "")
    else:
        text = "; ".join(f"{m}: {f.metadata['help']}" for m, f in declared)
    meta = {**first.metadata, "option": None, "help": text}
    return dataclasses.field(default=first.default, metadata=meta)


def _method_fields() -> list[tuple[str, type, dataclasses.Field]]:
    """Every registered method's parameters under their option names (:func:`shared_option`)."""
    return [
        (key, declared[0][1].type, shared_option(key, declared))
        for key, declared in method_parameters().items()
    ]


def _unsupported(what: str, test, reason_key: str, method: str) -> str:
    cls = method_class(method)
    reason = cls.supports.why_not.get(reason_key)
    others = methods_supporting(test)
    return (
        f"{what} is not supported by method '{method}'"
        + (f" ({reason})" if reason else "")
        + ("; use " + ", ".join(others) if others else "")
    )


class _Checks:
    """Validation against the method's declared support (mixed into :class:`Numerics`)."""

    def __post_init__(self) -> None:
        validate(self)
        model, _ = parse_spec(self.material)
        s = method_class(self.method).supports
        if self.friction not in s.friction:
            raise ValueError(
                _unsupported(
                    f"friction law '{self.friction}'",
                    lambda c: self.friction in c.friction,
                    "friction",
                    self.method,
                )
            )
        if self.mu > 0.0 and self.friction != "coulomb":
            raise ValueError(f"--mu needs --friction coulomb (got --friction {self.friction})")
        if self.threshold > 0.0 and self.friction != "tresca":
            raise ValueError(
                f"--threshold needs --friction tresca (got --friction {self.friction})"
            )
        if self.max_increment > 1.0:
            raise ValueError(
                f"--max-increment must lie in [0, 1] (a load increment), got {self.max_increment}"
            )
        if self.quadrature == "nodal" and (self.degree != 1 or not s.nodal_quadrature):
            raise ValueError(
                "--quadrature nodal needs --degree 1 and one of the methods "
                + ", ".join(methods_supporting(lambda c: c.nodal_quadrature))
                + (
                    f" (method {self.method}: {s.why_not['nodal_quadrature']})"
                    if "nodal_quadrature" in s.why_not
                    else ""
                )
            )
        if self.solver != "lu" and not s.iterative:
            raise ValueError(f"method {self.method} is {s.why_not['iterative']}: use --solver lu")
        if self.formulation == "mixed-up":
            if self.degree != 2:
                raise ValueError("formulation mixed-up is Taylor-Hood P2/P1: use --degree 2")
            if not s.mixed_up:
                raise ValueError(
                    _unsupported(
                        "formulation mixed-up", lambda c: c.mixed_up, "mixed_up", self.method
                    )
                )
            if self.solver != "lu":
                raise ValueError("formulation mixed-up is a saddle-point system: use --solver lu")
            if model == "svk":
                raise ValueError(
                    "formulation mixed-up needs a volumetric-isochoric split of the energy: "
                    "use --material neo-hookean or mooney-rivlin (svk has none)"
                )

        if self.dynamic:
            Scheme.named(self.scheme, self.rho_inf)  # --rho-inf's range, one line
            if not self.dt > 0.0:
                raise ValueError(f"--dynamic needs a time step --dt > 0, got {self.dt}")
            if not self.t_end >= self.dt * (1.0 - 1e-12):
                raise ValueError(
                    f"--t-end ({self.t_end}) must be at least one time step (--dt {self.dt})"
                )
            if self.nested:
                raise ValueError("--nested is offered for static load steps, not with --dynamic")
            if self.mass != "consistent" and self.degree != 1:
                raise ValueError(f"--mass {self.mass} is a P1 lumping: use --degree 1")
        elif self.time_tolerance > 0.0:
            raise ValueError(
                f"--time-tolerance {self.time_tolerance}: an adaptive time step needs --dynamic"
            )
        if self.dashpot > 0.0:
            if not self.dynamic:
                raise ValueError(
                    f"--dashpot {self.dashpot}: a contact dashpot acts in time, use it with "
                    "--dynamic"
                )
            if self.method != "penalty":
                raise ValueError(
                    f"--dashpot {self.dashpot}: the dashpot is the penalty contact's, use "
                    f"--method penalty (got --method {self.method})"
                )

    def method_object(self):
        """The configured contact method."""
        return method_class(self.method).from_options(self)

    def bulk_material(self, base):
        """The body's material: ``base`` (the scene's elastic material) under ``--material``
        (:func:`contactfx.mechanics.hyperelastic.material_from_spec`). A ``base`` that is
        finite-strain already (a problem file's body of its own hyperelastic model) is kept
        under the default ``--material linear``; any other ``--material`` would replace the
        model the file gives, and is refused (ValueError, one line): ``--material`` turns a
        linear body's E and nu into a model."""
        model, params = parse_spec(self.material)
        if model == "linear" and not params:
            return base
        if base.finite_strain:
            raise ValueError(
                f"--material {self.material}: the body's material is {base.name} already (its "
                "problem file's [[bodies]] material); --material applies to linear bodies only"
            )
        return material_from_spec(model, params, base)

    def friction_law(self):
        return friction_law(self.friction, mu=self.mu, threshold=self.threshold)


Numerics = dataclasses.make_dataclass(
    "Numerics",
    [
        (f.name, f.type, dataclasses.field(default=f.default, metadata=f.metadata))
        for f in dataclasses.fields(_General)
    ][:1]
    + _method_fields()
    + [
        (f.name, f.type, dataclasses.field(default=f.default, metadata=f.metadata))
        for f in dataclasses.fields(_General)
    ][1:],
    bases=(_Checks,),
    frozen=True,
)
Numerics.__module__ = __name__
Numerics.__doc__ = """The numerics of a run (see the module docstring); validated on
construction against the chosen method's declared support."""
