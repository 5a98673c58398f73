"""The contact-surface protocol: what a method may use to write its terms.

A surface is where contact is enforced: the boundary of a body facing a rigid obstacle
(:class:`contactfx.contact.gap.ContactSurface`) or the two faces of a fitted interface
(:class:`contactfx.contact.interface.InterfaceSurface`). Both present the same members, so
every method writes one residual for both. Conventions (docs/architecture.md): gap g >= 0 when
apart, n the outward normal of the body whose surface is integrated, pressure p >= 0 in
compression; ``u`` is the motion of the surface relative to its counterpart (the displacement
against an obstacle, the oriented jump across an interface).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Protocol, TypeAlias, runtime_checkable

import ufl

from contactfx.contact.laws import Expr, Friction, tangential

if TYPE_CHECKING:
    from typing import Self

__all__ = ["Expr", "Form", "Surface", "SurfaceData"]

# Expr (from laws, re-exported here): a UFL expression (a Function, a component of a mixed
# one, a test function, a Constant)
#: a UFL form (an integrand times a measure): what a method's residual is
Form: TypeAlias = ufl.Form


@runtime_checkable
class Surface(Protocol):
    """u, v: relative motion of the state and of the test functions; ds: the contact measure
    (``ds_nodal`` the same with the vertex rule); traction(n) / traction_test(n): the traction
    of the state on a plane of unit normal n at the surface and its directional derivative in
    the direction of the test functions (the material's :meth:`contactfx.mechanics.material.
    Material.traction` and ``traction_derivative``; ``traction_n`` / ``traction_t`` their
    normal and tangential parts); E: modulus scaling the method parameters; h: local mesh size;
    friction: the friction law or None; multiplier / multiplier_test: a method's multiplier
    (None without one)."""

    # read-only members: a surface has them as (frozen) dataclass fields or as properties
    @property
    def u(self) -> Expr: ...

    @property
    def v(self) -> Expr: ...

    @property
    def ds(self) -> ufl.Measure: ...

    @property
    def ds_nodal(self) -> ufl.Measure | None: ...

    @property
    def E(self) -> float: ...

    @property
    def h(self) -> Expr: ...

    @property
    def friction(self) -> Friction | None: ...

    @property
    def multiplier(self) -> Expr | None: ...

    @property
    def multiplier_test(self) -> Expr | None: ...

    # the members of SurfaceData some methods read (see there)
    @property
    def traction_prev(self) -> Expr | None: ...

    @property
    def stick(self) -> Expr | None: ...

    @property
    def h_continuous(self) -> Expr: ...

    def gap(self, w: Expr | None = None) -> Expr: ...

    def normal(self, w: Expr | None = None) -> Expr: ...

    def traction(self, n: Expr) -> Expr: ...

    def traction_test(self, n: Expr) -> Expr: ...

    def traction_n(self, n: Expr, test: bool = False) -> Expr: ...

    def traction_t(self, n: Expr, test: bool = False) -> Expr: ...

    def slip_increment(self, n: Expr) -> Expr: ...

    def collocated(self, law: Expr) -> Expr: ...

    def tip_extended(self) -> Surface: ...


@dataclass(frozen=True, kw_only=True)
class SurfaceData:
    """The members every surface carries for the methods (keyword-only): the friction law and
    ``u_prev``, the relative motion of the last converged load step (friction only, the slip
    increment is measured from it); ``ds_nodal``, the contact measure with the vertex
    (trapezoidal) rule for laws collocated at the nodes; a method's ``multiplier`` and its test
    function; ``traction_prev``, a method's traction history; ``stick``, Newton's reversal
    guard."""

    friction: Friction | None = None
    u_prev: Expr | None = None
    ds_nodal: ufl.Measure | None = None
    multiplier: Expr | None = None
    multiplier_test: Expr | None = None
    #: with friction, the tangential traction of the last converged step at the surface, for a
    #: method whose law has it as history (``traction_history``); else None
    traction_prev: Expr | None = None
    #: with friction, where > 0 a closed point takes the stick branch of the friction law
    #: whatever its trial traction (Newton's reversal guard, :func:`contactfx.contact.laws.
    #: reversal`); None: the law itself
    stick: Expr | None = None
    #: a multiplier's tie at the tips of a crack, where the jump and so the gap vanish
    #: identically and the contact law cannot fix the multiplier: at a tip node, the
    #: multiplier's value at the neighbouring node of the interface minus its own; zero at the
    #: other nodes. None: no tips, or no multiplier
    multiplier_tie: Expr | None = None
    #: with ``multiplier_tie``: 1 at the tip nodes, 0 at the other nodes
    at_tips: Expr | None = None
    #: the mesh size as a continuous P1 field along the surface (at each node the
    #: length-weighted mean of its facets' h), for a method whose traction is a stiffness
    #: kappa ~ 1 / h times the overlap (``nodal_size``); else None. With the facet-wise h,
    #: neighbouring facets of different sizes have different stiffnesses: a uniform pressure
    #: would need an overlap that jumps at the node between them, which a continuous
    #: displacement cannot give, and the traction error is of the order of the relative
    #: jitter of the cell sizes at every refinement
    h_nodal: Expr | None = None
    #: finite strain: the reference facet's unit normal N on which ``stress`` (the first Piola
    #: stress P) gives the traction P N, whatever the normal a method projects it on (the
    #: obstacle's, in the deformed configuration: Mlika, Renard and Chouly 2017,
    #: doi:10.1016/j.cma.2017.01.003); None: small strain, sigma n on the plane of n
    reference_normal: Expr | None = None

    if TYPE_CHECKING:
        # what every surface provides as a field or a property (declared for the checker
        # only: a property here would shadow the subclasses' dataclass fields)
        @property
        def ds(self) -> ufl.Measure: ...

        @property
        def h(self) -> Expr: ...

        @property
        def stress(self) -> Expr: ...

        @property
        def stress_test(self) -> Expr: ...

    # the stress tensors of the state and of the test functions (``stress`` / ``stress_test``:
    # fields or properties of each surface, from its kind's material) are the surface's own
    # business; the methods read tractions
    def traction(self, n: Expr) -> Expr:
        """The traction of the state on a plane of unit normal n: small strain sigma(u) n;
        finite strain the first Piola traction P(F) N on the reference facet (n only the
        direction the methods project it on)."""
        return ufl.dot(self.stress, n if self.reference_normal is None else self.reference_normal)

    def traction_test(self, n: Expr) -> Expr:
        """The directional derivative of :meth:`traction` in the direction of the test
        functions (small strain: sigma(v) n, linear in v; finite strain dP[grad v] N)."""
        N = n if self.reference_normal is None else self.reference_normal
        return ufl.dot(self.stress_test, N)

    def traction_n(self, n: Expr, test: bool = False) -> Expr:
        """Normal traction n . t (< 0 in compression), of the state or (``test``) of the test
        functions."""
        return ufl.dot(n, self.traction_test(n) if test else self.traction(n))

    def traction_t(self, n: Expr, test: bool = False) -> Expr:
        """Tangential traction (I - n n) t, of the state or (``test``) of the test
        functions."""
        return tangential(self.traction_test(n) if test else self.traction(n), n)

    @property
    def mesh(self) -> ufl.Mesh:
        return self.ds.ufl_domain()

    def collocated(self, law: Expr) -> Expr:
        """A multiplier's equation at the nodes (vertex rule): ``law``, the multiplier minus
        its law's value, and at a crack tip the tie lambda(tip) = lambda(neighbour) instead.
        This merges the tip node's multiplier basis function into its neighbour's, so that
        the multiplier is constant on the tip element (the modified multiplier basis at the
        ends of a contact surface: Wohlmuth 2000, doi:10.1137/S0036142999350929). Held to
        zero there instead, the traction would fall to zero across the tip element."""
        if self.multiplier_tie is None:
            return law
        assert self.at_tips is not None  # set with multiplier_tie
        return (1.0 - self.at_tips) * law - self.multiplier_tie

    @property
    def h_continuous(self) -> Expr:
        """``h_nodal`` where the driver built it, else the facet-wise h."""
        return self.h if self.h_nodal is None else self.h_nodal

    def tip_extended(self) -> Self:
        """The surface whose motion and multiplier are continued over each crack tip's
        element from its other node (see :meth:`contactfx.contact.interface.InterfaceSurface.
        tip_extended`); without crack tips the surface itself."""
        return self
