"""Contact across a fitted interface inside one mesh: crack faces, fracture planes, joints.

Kinematics (Heaviside enrichment on a fitted interface). The interface Gamma is a set of tagged
interior facets; a sign field H (cellwise +1 on the side the interface normal n_I points to, -1
on the other, from the cells' midpoints) splits the cells that touch it. The displacement is

    w = u + H a,

u and a continuous Lagrange fields of the same degree, a nonzero only at the dofs on Gamma
(elsewhere fixed to zero, which removes them from the system), and zero at the crack tips, so
that the jump vanishes there. Across Gamma the jump is [[w]] = w(+side) - w(-side) = 2 a; across
every other facet w is continuous. (The shifted-Heaviside enrichment of extended finite
elements on a mesh that already resolves the crack: Moes, Dolbow & Belytschko 1999,
doi:10.1002/(SICI)1097-0207(19990910)46:1<131::AID-NME726>3.0.CO;2-J; for a fitted crack it is
the same space as doubled nodes.) Every contact term is an interior-facet integral of the jump
and of the averaged stress: pure UFL, exact Jacobians.

Interface contact as the contact of the +side ("body", outward normal n = -n_I) against the
-side ("obstacle"): the gap is the normal opening g = [[w]] . n_I (>= 0, faces may open but not
interpenetrate), the relative tangential motion is the tangential jump, and the traction on the
+side face is -p n + t_T. :class:`InterfaceSurface` offers the same members as
:class:`contactfx.contact.gap.ContactSurface`, so Nitsche's method and the augmented Lagrangian
methods write the same residuals for both (two-sided Nitsche with the averaged stress: Chouly,
Fabre, Hild, Pousin & Renard 2018, doi:10.1051/m2an/2017056; Annavarapu, Hautefeuille & Dolbow
2014, doi:10.1016/j.cma.2013.09.025 for crack faces).

Interface laws beyond Signorini, all through the gap (the laws module's forms are unchanged):

* a proppant floor of thickness h_p on part of Gamma: g = opening - h_p (aperture >= h_p there);
* fluid pressure p_f on both faces: a load on the faces, and the contact law acts on the
  effective normal stress sigma_n + p_f (so Nitsche's consistency term uses the stress plus
  p_f I; the tangential stress is unchanged);
* Barton-Bandis joint closure (Bandis, Lumsden & Barton 1983, doi:10.1016/0148-9062(83)90595-8):
  closure v = -opening and effective stress s' with s' = K_ni v / (1 - v / V_m), i.e.
  v = psi(s') = s' V_m / (K_ni V_m + s'). Written as Signorini with the stress-dependent gap
  g = opening + psi([s']_+), s' = -(sigma_n + p_f): g = 0 with s' > 0 is the closure law, s' = 0
  with g >= 0 a joint opened beyond its initial aperture. The pressure estimate in psi is the
  averaged interface stress for every method (Nitsche's consistency with a normal compliance,
  cf. Juntunen & Stenberg 2009, doi:10.1090/S0025-5718-08-02183-2).
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import ufl

from contactfx.contact.laws import positive_part, tangential
from contactfx.contact.surface import Expr, SurfaceData
from contactfx.references import bb_closure

if TYPE_CHECKING:
    from typing import Self

__all__ = ["BartonBandis", "InterfaceSurface", "oriented_jump", "interface_normal", "tangent"]


def oriented_jump(w: Expr, H: Expr) -> Expr:
    """[[w]] = w(+side) - w(-side) on facets where H changes sign (whatever dolfinx's '+' / '-'
    restriction of the facet is)."""
    return 0.5 * (H("+") - H("-")) * (w("+") - w("-"))


def tangent(n: Expr, axis: Iterable[float] | None = None) -> Expr:
    """The interface direction: in 2D the normal n_I rotated by -90 degrees; in 3D the unit
    projection of ``axis`` (a vector not normal to the interface) on the interface's plane."""
    if ufl.shape(n)[0] == 2:
        return ufl.as_vector([n[1], -n[0]])
    if axis is None:
        raise ValueError("a 3D interface's tangent needs an axis (InterfaceScene.slip_axis)")
    a = ufl.as_vector([float(c) for c in axis])
    t = a - ufl.dot(a, n) * n
    return t / ufl.sqrt(ufl.dot(t, t))


def interface_normal(H: Expr, n: Expr) -> Expr:
    """Unit normal n_I of the interface, pointing from the H = -1 side to the H = +1 side
    (n is ufl.FacetNormal: n('+') is the outward normal of the '+' cell)."""
    return -H("+") * n("+")


@dataclass(frozen=True)
class BartonBandis:
    """Hyperbolic normal closure of a rock joint: initial normal stiffness ``Kni`` (stress /
    length), maximal closure ``Vm`` (length), initial aperture ``w0`` (length, >= Vm)."""

    Kni: float
    Vm: float
    w0: float

    def __post_init__(self) -> None:
        if not (self.Kni > 0.0 and self.Vm > 0.0 and self.w0 > 0.0):
            raise ValueError("Barton-Bandis parameters K_ni, V_m and w0 must be > 0")
        if self.Vm > self.w0:
            raise ValueError(f"maximal closure V_m = {self.Vm} exceeds the aperture w0 = {self.w0}")

    def closure(self, s: Expr) -> Expr:
        """v = psi(s) for an effective normal stress s >= 0 (numbers or UFL)."""
        return bb_closure(s, self.Kni, self.Vm)


@dataclass(frozen=True)
class InterfaceSurface(SurfaceData):
    """What a method needs to write its terms on a fitted interface (see the module docstring).

    w, v: total displacement of the state and of the test functions (u + H a); H: the DG0 sign
    field; ds: interior-facet measure restricted to the interface; stress(_test): sigma(w),
    sigma(v) (cellwise); E: modulus scaling the method parameters; h: cell diameter (UFL).
    floor: proppant thickness (UFL, 0 where unpropped) or None; fluid: fluid pressure on the
    faces (UFL) or None; joint: a :class:`BartonBandis` law or None. Friction, previous state
    ``u_prev`` (total displacement of the last converged step), ``ds_nodal`` and the multiplier
    as in :class:`contactfx.contact.gap.ContactSurface`.
    """

    w: Expr
    v_total: Expr
    H: Expr
    ds: ufl.Measure
    stress_cell: Expr
    stress_test_cell: Expr
    E: float
    h_cell: Expr
    floor: Expr | None = None
    fluid: Expr | None = None
    joint: BartonBandis | None = None
    #: P1 vector field: at each crack tip's node the vector to its neighbouring node on the
    #: interface, zero at the other nodes (unrestricted); None without tips
    tip_step: Expr | None = None

    # -- the ContactSurface members the methods use -----------------------------------------
    @property
    def u(self) -> Expr:
        """The oriented displacement jump [[w]] (the +side's motion relative to the -side)."""
        return oriented_jump(self.w, self.H)

    @property
    def v(self) -> Expr:
        return oriented_jump(self.v_total, self.H)

    @property
    def h(self) -> Expr:
        return ufl.avg(self.h_cell)

    def _identity(self) -> Expr:
        return ufl.Identity(ufl.shape(self.w)[0])

    @property
    def stress(self) -> Expr:
        """Averaged stress of the state, plus p_f I (the contact law acts on the effective
        stress)."""
        s = ufl.avg(self.stress_cell)
        if self.fluid is not None:
            s = s + self.fluid * self._identity()
        return s

    @property
    def stress_test(self) -> Expr:
        return ufl.avg(self.stress_test_cell)

    def interface_normal(self) -> Expr:
        """n_I: from the -side to the +side."""
        return interface_normal(self.H, ufl.FacetNormal(self.mesh))

    def normal(self, w: Expr | None = None) -> Expr:
        """Outward normal of the +side face: -n_I."""
        return -self.interface_normal()

    def opening(self, w: Expr | None = None) -> Expr:
        """Normal opening [[w]] . n_I (> 0 open)."""
        jump = self.u if w is None else oriented_jump(w, self.H)
        return ufl.dot(jump, self.interface_normal())

    def effective_pressure(self) -> Expr:
        """s' = -(n . sigma n + p_f): the normal stress the faces (or the joint) carry."""
        n = self.normal()
        return -self.traction_n(n)

    def gap(self, w: Expr | None = None) -> Expr:
        """opening - proppant floor (+ joint closure psi(s'))."""
        g = self.opening(w)
        if self.floor is not None:
            g = g - self.floor
        if self.joint is not None:
            g = g + self.joint.closure(positive_part(self.effective_pressure()))
        return g

    def tip_extended(self) -> Self:
        """This surface with the motion w, the previous motion, the multiplier and the nodal
        fields of a law (the traction history, the nodal mesh size) replaced, on each tip's
        element, by their values at the tip's neighbour, and unchanged elsewhere.
        With d = ``tip_step`` = (x_neighbour - x_tip) phi_tip (phi_tip the tip node's P1 basis
        function), x + d is the neighbour's node at every point x of the tip's facet and x
        elsewhere, so the Taylor expansion f + grad(f) . d + d . grad(grad(f)) . d / 2 is the
        constant f(neighbour) on the tip's element for any field of degree <= 2 in the cell
        (P1 and P2). The jump, and so the gap and the slip, vanish identically at a tip, so a
        law written on them alone (al-uzawa's augmented pressure [lambda - r g]_+ with a
        multiplier held at the nodes, the penalty's kappa [-g]_+) would otherwise let the
        traction fall to the tip's value across the element; continued, the tip element
        carries its neighbour's traction, with its derivative in Newton's Jacobian. This is
        al-ssn's tie (``collocated``) written into the law instead of a multiplier row."""
        if self.tip_step is None:
            return self
        d = self.tip_step

        def extend(f: Expr) -> Expr:
            if isinstance(f, ufl.classes.Restricted):  # a nodal field seen from one side
                return extend(f.ufl_operands[0])(f.side())
            return f + ufl.dot(ufl.grad(f), d) + 0.5 * ufl.dot(ufl.dot(ufl.grad(ufl.grad(f)), d), d)

        def extend_optional(f: Expr | None) -> Expr | None:
            return None if f is None else extend(f)

        lam = self.multiplier
        if lam is not None and self.multiplier_tie is not None:
            lam = lam + self.multiplier_tie
        return replace(
            self,
            w=extend(self.w),
            u_prev=extend_optional(self.u_prev),
            multiplier=lam,
            traction_prev=extend_optional(self.traction_prev),
            h_nodal=extend_optional(self.h_nodal),
            tip_step=None,
        )

    def slip_increment(self, n: Expr) -> Expr:
        """Tangential jump increment since the last converged step."""
        if self.u_prev is None:
            raise ValueError("the slip increment needs the previous state (friction only)")
        return tangential(self.u - oriented_jump(self.u_prev, self.H), n)
