"""The contact-method protocol: what the driver asks of an enforcement method, and what a method
declares it supports.

A method is a frozen dataclass whose fields (made with :func:`contactfx.params.param`) are its
parameters; they become command-line options and fields of
:class:`contactfx.numerics.Numerics`. It writes UFL against a contact surface
(:class:`contactfx.contact.surface.Surface`): the residual, the pressure and, with friction,
the tangential traction. Everything else the driver needs is declared here with a default:

* ``multiplier``: what the method asks of a problem kind beyond the displacement, a
  :class:`Multiplier` strategy: :data:`NO_MULTIPLIER` (displacement only),
  :data:`MULTIPLIER_FIELD` (a P1 multiplier solved with the displacement, one mixed unknown),
  or :data:`NODAL_MULTIPLIER` (a P1 multiplier updated between Newton solves by
  :meth:`update`; an outer loop, see :meth:`attach`);
* :meth:`snes_options`: PETSc options the method needs (e.g. an SNES-VI type);
* :meth:`attach`: wrap the nonlinear solver (an outer loop, bound constraints);
* ``sweep``: the option that distinguishes its variants in bench and stress tables;
* ``supports``: the friction laws, formulations, quadratures, problem kinds and dimensions it
  handles, with the reason for each it does not: :class:`contactfx.numerics.Numerics` and the
  driver check a run against it and name the methods that would do.

Adding a method: one module with its dataclass and one line in
:mod:`contactfx.contact.registry`.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, ClassVar, Protocol, runtime_checkable

from contactfx.contact.laws import active, ball_projection, norm

if TYPE_CHECKING:
    from typing import Self

    from contactfx.contact.coupling import PairCoupling
    from contactfx.contact.pair import ContactPair
    from contactfx.contact.surface import Expr, Form, Surface
    from contactfx.solvers.base import Solver
    from contactfx.solvers.snes import ContactSNES

__all__ = [
    "Supports",
    "ContactMethod",
    "MethodBase",
    "TrialFriction",
    "Multiplier",
    "NO_MULTIPLIER",
    "MULTIPLIER_FIELD",
    "NODAL_MULTIPLIER",
]


@dataclass(frozen=True)
class Multiplier:
    """What a method asks of a problem kind beyond the displacement (a strategy the method
    provides; the kind builds what it says and reads its own state afterwards). ``name``: as
    the documentation says it; ``field``: the unknown gains a P1 multiplier field solved with
    the displacement (its equations collocated at the surface's nodes); ``nodal``: the kind
    keeps a P1 multiplier Function on the surface that the method's outer loop updates between
    Newton solves (the progress shows the outer iterations)."""

    name: str
    field: bool = False
    nodal: bool = False

    def field_shape(self, traction: tuple[int, ...]) -> tuple[int, ...] | None:
        """The value shape of the multiplier field the unknown gains (``traction``: () for a
        normal pressure, (gdim,) for a traction with friction), None without one."""
        return traction if self.field else None

    def nodal_shape(self, traction: tuple[int, ...]) -> tuple[int, ...] | None:
        """The value shape of the nodal multiplier Function, None without one."""
        return traction if self.nodal else None


NO_MULTIPLIER = Multiplier("none")
MULTIPLIER_FIELD = Multiplier("field", field=True)
NODAL_MULTIPLIER = Multiplier("nodal", nodal=True)


@dataclass(frozen=True)
class Supports:
    """What a method handles. ``why_not`` maps a capability name (``friction``, ``obstacles``,
    ``mixed_up``, ``nodal_quadrature``, ``interfaces``, ``two_body``, ``two_body_friction``,
    ``two_body_tresca``, ``dim1``, ``iterative``, ``finite_strain``)
    to the reason it is not supported, quoted in the error a user sees."""

    friction: tuple[str, ...] = ("none",)
    obstacles: bool = True
    mixed_up: bool = False
    nodal_quadrature: bool = False
    interfaces: bool = False
    two_body: bool = False
    #: friction between two meshed bodies too (if it supports friction and two bodies)
    two_body_friction: bool = True
    #: Tresca friction between two meshed bodies (a given threshold, no pressure in the bound)
    two_body_tresca: bool = False
    dim1: bool = True
    iterative: bool = True
    #: finite-strain bodies (a hyperelastic ``--material``): the law in the deformed
    #: configuration
    finite_strain: bool = True
    #: axisymmetric bodies (integrals weighted by r): a law at Gauss points, none collocated
    #: at the nodes (whose weight vanishes at the axis)
    axisymmetric: bool = False
    why_not: dict[str, str] = field(default_factory=dict)


@runtime_checkable
class ContactMethod(Protocol):
    """The members the driver and the post-processing use (see the module docstring)."""

    name: ClassVar[str]
    multiplier: ClassVar[Multiplier]
    supports: ClassVar[Supports]

    def residual(self, s: Surface) -> Form | None: ...

    def pressure(self, s: Surface) -> Expr | None: ...

    def contact_indicator(self, s: Surface) -> Expr | None: ...

    def snes_options(self) -> dict[str, object]: ...

    def attach(self, solver: ContactSNES, problem: Any) -> Solver: ...


class MethodBase:
    """Defaults of the protocol for the dataclass methods."""

    name: ClassVar[str]
    multiplier: ClassVar[Multiplier] = NO_MULTIPLIER
    #: with friction, whether the method's law needs the tangential traction of the last
    #: converged step (the surface's ``traction_prev``, kept by the driver)
    traction_history: ClassVar[bool] = False
    #: whether the method's stiffness is scaled by a mesh size that must be continuous along
    #: the surface (the surface's ``h_nodal``, built by the driver)
    nodal_size: ClassVar[bool] = False
    #: whether the method writes its law on ``s.tip_extended()`` (continued over each crack
    #: tip's element from its neighbouring node; the driver then builds ``tip_step``)
    tip_continued: ClassVar[bool] = False
    supports: ClassVar[Supports] = Supports()
    #: Newton's line search under ``--line-search auto``: cp where the residual is the
    #: gradient of an energy (the penalised problems: cp shortens a step to the energy's
    #: minimum along it), basic for a multiplier's saddle point (cp's criterion does not hold
    #: there: on shallow-ironing with mortar it took 82 load steps with 39 cut-backs where
    #: full steps took 44 with 4; docs/verification.md section 15)
    line_search: ClassVar[str] = "basic"
    #: the option that tells the method's variants apart, and the values ``contactfx bench
    #: --method NAME`` runs ("": none)
    sweep: ClassVar[tuple[str, tuple]] = ("", ())

    if TYPE_CHECKING:
        # every method defines it (the ContactMethod protocol)
        def pressure(self, s: Surface) -> Expr | None: ...

    @classmethod
    def from_options(cls, options: Any) -> Self:
        """The method with its parameters read from ``options`` (a Numerics, by option name)."""
        from contactfx.params import option_name

        return cls(**{f.name: getattr(options, option_name(f)) for f in dataclasses.fields(cls)})

    def law_surface(self, s: Surface) -> Surface:
        """The surface the method's law reads: with ``tip_continued``, continued over each
        crack tip's element from its neighbouring node (``s.tip_extended()``), else ``s``."""
        return s.tip_extended() if self.tip_continued else s

    def contact_indicator(self, s: Surface) -> Expr | None:
        """> 0 exactly where the surfaces are closed (the pressure, unless a multiplier that
        vanishes only to solver tolerance where open needs a sharper test)."""
        return self.pressure(s)

    def snes_options(self) -> dict[str, object]:
        return {}

    def contact_energy(self, s: Surface) -> Expr | None:
        """The energy the contact terms store, a density on the contact surface (a dynamic
        run's energy balance), or None: a method whose contact stores none it can name (the
        multiplier methods: none at a converged solution), or one with friction (the
        tangential terms' share is in the balance's remainder)."""
        return None

    def traction_measure(self, s: Surface) -> Any:
        """The measure the method's traction acts on the displacement with (its work, e.g.
        friction's dissipation in a dynamic run's balance): the surface's Gauss rule."""
        return s.ds

    def trial_traction(self, s: Surface) -> tuple[Expr, Expr] | None:
        """With friction, the trial tangential traction and the friction bound that Newton's
        reversal guard compares between iterates (:func:`contactfx.contact.laws.reversal`);
        None: a method without the guard."""
        return None

    def coupling(self, pair: ContactPair) -> PairCoupling:
        """The terms between two separately meshed bodies
        (:class:`contactfx.contact.coupling.Coupling`) of a contact ``pair``
        (:class:`contactfx.contact.pair.ContactPair`); only methods that support two bodies."""
        raise NotImplementedError(f"method {self.name} has no two-body coupling")

    def attach(self, solver: ContactSNES, problem: Any) -> Solver:
        """The solver the load program drives (``solver`` itself unless wrapped). ``problem``
        is the driver's problem kind (:class:`contactfx.driver.problem.Problem`; the members a
        method reads, e.g. an obstacle's, differ from kind to kind)."""
        return solver


class TrialFriction:
    """Friction by a trial tangential traction: t_T = proj_{B(0, s(p))}(trial), the return map of
    the regularised law (Alart & Curnier 1991, doi:10.1016/0045-7825(91)90022-X). A method
    writes ``_trial_t(s)`` and ``pressure(s)``; this gives the traction, the trial with its
    bound (Newton's reversal guard, :func:`contactfx.contact.laws.reversal`) and the slip
    indicator."""

    if TYPE_CHECKING:
        # the method's own (its normal law)
        def pressure(self, s: Surface) -> Expr: ...

    def _trial_t(self, s: Surface) -> Expr:
        raise NotImplementedError

    # the friction terms are built only with a friction law (s.friction is not None)
    def tangential_traction(self, s: Surface) -> Expr:
        assert s.friction is not None
        return ball_projection(
            self._trial_t(s), s.friction.bound(self.pressure(s)), s.E, stick=s.stick
        )

    def trial_traction(self, s: Surface) -> tuple[Expr, Expr]:
        """The trial tangential traction and the friction bound."""
        assert s.friction is not None
        return self._trial_t(s), s.friction.bound(self.pressure(s))

    def slip_indicator(self, s: Surface) -> Expr:
        """1 where the friction bound is reached (slip), else 0."""
        assert s.friction is not None
        p = self.pressure(s)
        return active(p) * active(norm(self._trial_t(s), s.E) - s.friction.bound(p))
