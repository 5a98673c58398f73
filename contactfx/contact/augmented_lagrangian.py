"""Augmented Lagrangian enforcement: Uzawa (outer multiplier loop) and monolithic semi-smooth
Newton on displacement and multiplier.

The multiplier lambda is the contact traction on the body: a scalar pressure lambda_n >= 0
without friction, a vector t = -lambda_n n + lambda_T with friction. With the augmentation
r = r0 E / h, the augmented pressure and tangential traction are

    p = [lambda_n - r g(u)]_+,    T = proj_{B(0, s(p))}(lambda_T - r du_T(u))

(Alart & Curnier 1991, doi:10.1016/0045-7825(91)90022-X; Simo & Laursen 1992,
doi:10.1016/0045-7949(92)90540-G). The Signorini and friction laws hold exactly when
lambda_n = p and lambda_T = T.

* ``AugmentedLagrangianUzawa``: for fixed lambda solve a(u, v) - L(v) + int (p v.n - T.v) = 0
  by Newton, then set lambda <- (p, T) at the nodes; repeat until the nodal multiplier stops
  changing. The converged state satisfies the laws at the nodes exactly (no O(1/r)
  penetration), whatever r; r only sets the speed of the outer loop.
* ``AugmentedLagrangianSSN``: lambda is a P1 field of a mixed space, solved together with u.
  u-equation a(u, v) - L(v) - int t(lambda) . v = 0; the multiplier equations are the
  complementarity functions collocated at the nodes (trapezoidal / vertex quadrature):
  C_n = lambda_n - p (``min``, Alart-Curnier: = min(lambda_n, r g)) or the Fischer-Burmeister
  function of (lambda_n, r g) (``fb``), and C_T = lambda_T - T (Alart-Curnier) with friction.
  They are stresses, tested like the tractions: every row of the residual is a force, so
  that one absolute tolerance fits all rows.
  The multiplier's dofs away from the contact boundary are fixed to zero (a trace space on
  dolfinx versions without mixed-dimensional assembly; Hueeber & Wohlmuth 2005,
  doi:10.1016/j.cma.2004.09.012 for the semi-smooth Newton view of these equations).
  The u-equation's int t(lambda) . v is integrated by the surface's Gauss rule (``al_coupling``
  consistent: the P1 multiplier against the P1 traces, a surface mass matrix M_s) or by the
  vertex rule (lumped: M_s diagonal, as a dual multiplier basis makes it, Wohlmuth 2000,
  doi:10.1137/S0036142998347966). In a static run they differ by the discretisation
  error (hertz2d: the contact half-width 0.02 % and 0.80 % from Hertz's, 0.07 h apart; the
  peak pressure 0.17 % and 0.16 %); in time only the lumped one does no work in a closed
  contact: its work on a step is sum_i lambda_i m_i dg_i, zero where lambda_i > 0 holds
  g_i = 0, while the consistent sum_ij lambda_i (M_s)_ij dg_j picks up the gap rates of
  the open neighbours of the contact's edge nodes (disc-drop's balance took up 0.9 % of the
  impact energy during the contact on its default mesh, 2.5 % on its test's, and gave most
  of it back at the release). ``auto`` (the default) is lumped with ``--dynamic``.

At a crack tip the gap vanishes identically, so no contact law fixes the multiplier there:
al-ssn ties it to its neighbour's (:meth:`contactfx.contact.surface.SurfaceData.collocated`);
al-uzawa writes its augmented traction on the tip's element with the neighbour's multiplier,
gap and slip (:meth:`contactfx.contact.interface.InterfaceSurface.tip_extended`), so that the
tip carries its neighbour's augmented traction inside each Newton solve. (A tie in its nodal
update alone, the tip taking its neighbour's last multiplier as a fixed traction without the
augmentation's stiffness, stopped the outer loop converging on propped-fracture's closing
branch.)
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import ufl

from contactfx.contact.laws import (
    active,
    ball_projection,
    fischer_burmeister,
    norm,
    positive_part,
    tangential,
)
from contactfx.contact.method import MULTIPLIER_FIELD, NODAL_MULTIPLIER, MethodBase, Supports
from contactfx.contact.surface import Expr, Form, Surface
from contactfx.params import param, validate

if TYPE_CHECKING:
    from typing import Self

    from contactfx.solvers.snes import ContactSNES
    from contactfx.solvers.uzawa import Uzawa

__all__ = ["AugmentedLagrangianUzawa", "AugmentedLagrangianSSN", "split_multiplier"]


def split_multiplier(lam: Expr, n: Expr) -> tuple[Expr, Expr | None]:
    """(lambda_n, lambda_T) of a scalar pressure or a traction vector t = -lambda_n n + lambda_T
    (lambda_T is None for a scalar multiplier)."""
    if ufl.shape(lam) == ():
        return lam, None
    return -ufl.dot(lam, n), tangential(lam, n)


_R0 = "augmented Lagrangian augmentation, r = r0 E / h"
_FRICTION = ("none", "tresca", "coulomb")


@dataclass(frozen=True)
class _AugmentedBase(MethodBase):
    if TYPE_CHECKING:
        # the augmentation factor, a field of each subclass (r = r0 E / h); declared for the
        # checker only (here it would be a field of this dataclass)
        r0: float

    def __post_init__(self) -> None:
        validate(self)

    def r(self, s: Surface) -> Expr:
        return self.r0 * s.E / s.h

    def _augmented(self, s: Surface) -> tuple[Expr, Expr | None, Expr | None]:
        """(p, T trial, T) from the surface's multiplier; T and its trial are None without
        friction."""
        s = self.law_surface(s)
        n = s.normal()
        lam_n, lam_t = split_multiplier(s.multiplier, n)
        p = positive_part(lam_n - self.r(s) * s.gap())
        if s.friction is None:
            return p, None, None
        trial = lam_t - self.r(s) * s.slip_increment(n)
        return p, trial, ball_projection(trial, s.friction.bound(p), s.E, stick=s.stick)

    # the friction terms are built only with a friction law (s.friction is not None)
    def trial_traction(self, s: Surface) -> tuple[Expr, Expr]:
        """The trial tangential traction lambda_T - r du_T and the friction bound (with
        friction)."""
        assert s.friction is not None
        p, trial, _ = self._augmented(s)
        return trial, s.friction.bound(p)

    def _slip(self, s: Surface) -> Expr:
        assert s.friction is not None
        p, trial, _ = self._augmented(s)
        return active(p) * active(norm(trial, s.E) - s.friction.bound(p))


@dataclass(frozen=True)
class AugmentedLagrangianUzawa(_AugmentedBase):
    """r0 > 0 (r = r0 E / h). ``s.multiplier`` is the nodal multiplier Function (scalar P1
    without friction, vector P1 with); the outer loop is :class:`contactfx.solvers.uzawa.Uzawa`."""

    r0: float = param(10.0, _R0, positive=True)
    al_tol: float = param(
        1e-8, "al-uzawa stop: max nodal multiplier change / max multiplier", positive=True
    )
    al_max_it: int = param(100, "al-uzawa maximal outer iterations", positive=True)
    name = "al-uzawa"
    sweep = ("r0", ())
    multiplier = NODAL_MULTIPLIER
    #: at a crack tip the gap and the slip vanish identically, so the augmented traction
    #: there would be the held multiplier alone: the tip's element takes its neighbour's
    #: augmented traction instead (``tip_extended``), with its derivative in the Jacobian
    tip_continued = True
    supports = Supports(
        friction=_FRICTION,
        mixed_up=True,
        interfaces=True,
        dim1=False,
        why_not={
            "nodal_quadrature": "it already collocates the contact law at the nodes",
            "dim1": "its nodal multiplier update cannot be compiled on intervals; use "
            "al-ssn for 1D scenes",
        },
    )

    def attach(self, solver: ContactSNES, problem: Any) -> Uzawa:
        """Uzawa's outer loop around the Newton solver (the problem gives the multiplier
        Function, its nodal update and the contact nodes)."""
        from contactfx.solvers.uzawa import Uzawa

        update = problem.surface_update(self.update)
        return Uzawa(
            solver,
            problem.multiplier,
            update,
            problem.multiplier_mask,
            tol=self.al_tol,
            max_it=self.al_max_it,
        )

    def pressure(self, s: Surface) -> Expr:
        return self._augmented(s)[0]

    def tangential_traction(self, s: Surface) -> Expr | None:
        return self._augmented(s)[2]

    def slip_indicator(self, s: Surface) -> Expr:
        return self._slip(s)

    def update(self, s: Surface) -> Expr:
        """The multiplier's next value (UFL, interpolated at the nodes by the outer loop)."""
        p, _, t_T = self._augmented(s)
        if t_T is None:
            return p
        return -p * s.normal() + t_T

    def residual(self, s: Surface) -> Form:
        p, _, t_T = self._augmented(s)
        form = p * ufl.dot(s.v, s.normal()) * s.ds
        if t_T is not None:
            form -= ufl.dot(t_T, s.v) * s.ds
        return form


@dataclass(frozen=True)
class AugmentedLagrangianSSN(_AugmentedBase):
    """r0 > 0; ncp 'min' (Alart-Curnier) or 'fb' (Fischer-Burmeister) for the normal law.
    ``s.multiplier`` / ``s.multiplier_test`` are the multiplier component of the mixed unknown
    and its test function; ``s.ds_nodal`` is the vertex-quadrature contact measure."""

    r0: float = param(10.0, _R0, positive=True)
    ncp: str = param(
        "min",
        "complementarity function: min (Alart-Curnier) or fb (Fischer-Burmeister)",
        choices=("min", "fb"),
    )
    al_coupling: str = param(
        "auto",
        "al-ssn: where the multiplier acts on the displacement: consistent (the contact "
        "surface's Gauss rule), lumped (at the nodes, where its law holds: a closed contact "
        "does no work, so that a dynamic run's energy balance closes) or auto (lumped with "
        "--dynamic)",
        choices=("auto", "consistent", "lumped"),
    )
    name = "al-ssn"
    sweep = ("r0", ())
    multiplier = MULTIPLIER_FIELD
    supports = Supports(
        friction=_FRICTION,
        interfaces=True,
        iterative=False,
        why_not={
            "nodal_quadrature": "it already collocates the contact law at the nodes",
            "mixed_up": "it has its own mixed (u, lambda) space",
            "iterative": "a saddle-point system",
        },
    )

    @classmethod
    def from_options(cls, options: Any) -> Self:
        """``al_coupling`` auto made lumped in a dynamic run (``options.dynamic``), consistent
        otherwise."""
        method = super().from_options(options)
        if method.al_coupling != "auto":
            return method
        lumped = bool(getattr(options, "dynamic", False))
        return dataclasses.replace(method, al_coupling="lumped" if lumped else "consistent")

    def traction_measure(self, s: Surface) -> Any:
        """The vertex rule with the lumped coupling (module docstring), else the Gauss rule."""
        lumped = self.al_coupling == "lumped" and s.ds_nodal is not None
        return s.ds_nodal if lumped else s.ds

    def pressure(self, s: Surface) -> Expr:
        if s.ds_nodal is None:  # a projected multiplier (projected_law)
            return self._augmented(s)[0]
        return split_multiplier(s.multiplier, s.normal())[0]

    def tangential_traction(self, s: Surface) -> Expr | None:
        if s.ds_nodal is None:
            return self._augmented(s)[2]
        return split_multiplier(s.multiplier, s.normal())[1]

    def contact_indicator(self, s: Surface) -> Expr:
        """[lambda_n - r g]_+: > 0 exactly where the surfaces are closed (between the nodes
        too; lambda_n itself only vanishes up to the solver tolerance where open)."""
        return self._augmented(s)[0]

    def slip_indicator(self, s: Surface) -> Expr:
        return self._slip(s)

    def law_surface(self, s: Surface) -> Surface:
        """A projected multiplier (``s.ds_nodal`` None): the law reads the surface as
        al-uzawa's does (its motion at each unfitted piece's midpoint, ``tip_extended``)."""
        return s.tip_extended() if s.ds_nodal is None else s

    def projected_law(self, s: Surface) -> Expr:
        """The augmented traction p (scalar multiplier) or -p n + T (traction).

        Where the multiplier has no nodal collocation (``s.ds_nodal`` None: an unfitted
        crack, :mod:`contactfx.driver.unfitted`), the driver writes the multiplier's equation
        as lambda = the projection of this law onto a coarser multiplier space, and the faces
        carry the augmented traction itself (``pressure``, ``tangential_traction``, the
        u-equation): al-uzawa's fixed point (lambda the projection of the augmented traction
        it produces), solved by Newton for u and lambda together. The faces carrying lambda
        instead would see only the coarse field, and the traction where it jumps (a proppant
        zone's ends) would be spread over a coarse element."""
        p, _, t_T = self._augmented(s)
        return p if t_T is None else -p * s.normal() + t_T

    def residual(self, s: Surface) -> Form:
        n = s.normal()
        lam, mu = s.multiplier, s.multiplier_test
        lam_n, lam_t = split_multiplier(lam, n)
        if s.ds_nodal is None:  # the u-equation only (see projected_law)
            if lam_t is None:
                return self.projected_law(s) * ufl.dot(s.v, n) * s.ds
            return -ufl.dot(self.projected_law(s), s.v) * s.ds
        r = self.r(s)
        p, _, t_T = self._augmented(s)
        if self.ncp == "min":
            c_n = lam_n - p
        else:
            c_n = fischer_burmeister(lam_n, r * s.gap(), s.E)
        ds = self.traction_measure(s)
        if lam_t is None:  # scalar pressure multiplier
            return lam * ufl.dot(s.v, n) * ds + s.collocated(c_n) * mu * s.ds_nodal
        # traction multiplier t = lam: -int t . v, and C(lam, u) = -c_n n + (lam_T - T) = 0
        c = s.collocated(-c_n * n + lam_t - t_T)
        return -ufl.dot(lam, s.v) * ds + ufl.dot(c, mu) * s.ds_nodal
