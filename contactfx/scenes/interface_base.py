"""Scenes with a fitted interface inside one body (cracks, fractures, joints): the hooks of
the problem kind :class:`contactfx.driver.interface.InterfaceProblem`."""

from __future__ import annotations

from typing import Any, ClassVar

import numpy as np

from contactfx.contact.interface import BartonBandis
from contactfx.driver.fields import near_points
from contactfx.driver.interface import InterfaceProblem
from contactfx.driver.unfitted import UnfittedProblem
from contactfx.scenes.base import Scene

__all__ = ["InterfaceScene"]


class InterfaceScene(Scene):
    """Base of the fitted-interface scenes. Subclasses give the mesh, the interface (tag, sides,
    tips, frame), the supports and loads, and the closed-form references."""

    interface_tag: ClassVar[int]

    @property
    def problem(self):
        """The fitted-interface kind, or with ``--crack unfitted`` (the scenes that have that
        parameter) the unfitted crack's."""
        if getattr(self.p, "crack", "fitted") == "unfitted":
            return UnfittedProblem
        return InterfaceProblem

    def _fitted_only(self) -> None:
        """Raise for ``--crack unfitted``: problem files carry fitted interfaces only."""
        if self.problem is UnfittedProblem:
            raise ValueError(
                f"scene '{self.name}' with --crack unfitted cannot be written as a "
                "problem file: problem files carry fitted interfaces only"
            )

    def dimension(self) -> int:
        """The space dimension of the scene's mesh (2: plane strain)."""
        return 2

    def supports(self) -> list[tuple[int, int]]:
        """Component supports: (facet tag, component) pairs with zero displacement; they hold
        for the total displacement, so for u and a alike."""
        return []

    def pinned(self) -> list[tuple[np.ndarray, int]]:
        """(point, component) pairs of zero displacement at mesh vertices (removing the rigid
        motions of a body loaded by tractions only)."""
        return []

    def side(self, x: np.ndarray) -> np.ndarray:
        """Signed distance-like function of the points x (3, n): > 0 on the side the interface
        normal points to."""
        raise NotImplementedError

    def tips(self) -> list[np.ndarray]:
        """Crack tips (points where the jump vanishes); [] for an interface across the body."""
        return []

    def on_front(self, x: np.ndarray, tol: float) -> np.ndarray:
        """Bool per point of x (3, n): on the crack's tip or front, where the jump vanishes
        (within ``tol``). By default: at one of :meth:`tips` (2D); a 3D crack gives its front
        curve."""
        return near_points([(np.asarray(tip, dtype=float), tol) for tip in self.tips()])(x)

    def frame(self) -> tuple[np.ndarray, np.ndarray]:
        """(origin, unit direction) of the interface coordinate s = (x - origin) . direction."""
        raise NotImplementedError

    def coordinate(self, x):
        """The interface coordinate s of the points x (UFL ``SpatialCoordinate``, or numpy
        (gdim, n)) along which the profile, the closed forms and the proppant floor are
        written: by default the distance along :meth:`frame`'s direction; a penny-shaped
        crack's radius."""
        origin, direction = (np.asarray(v, dtype=float) for v in self.frame())
        return sum((x[i] - origin[i]) * direction[i] for i in range(len(origin)))

    def slip_axis(self) -> np.ndarray | None:
        """3D: the direction whose projection on the interface's plane is the reported slip and
        tangential traction direction; None in 2D (the interface direction)."""
        return None

    def length_scale(self) -> float:
        """A typical length of the body (tolerances of point location)."""
        raise NotImplementedError

    def floor(self, s):
        """Proppant thickness along the interface (UFL in the coordinate s), or None."""
        return None

    def joint(self) -> BartonBandis | None:
        return None

    def fluid_pressure(self) -> float | None:
        """Fluid pressure on the faces at load factor 1, or None (no fluid)."""
        return None

    def extra_quantities(self, mesh, w, ds) -> dict[str, Any]:
        """Named UFL functionals (integrals, summed over ranks) the scene reports."""
        return {}

    # -- closed forms ----------------------------------------------------------------------
    def exact_opening(self, s) -> Any:
        """Closed-form normal opening (UFL in s), or None."""
        return None

    def exact_slip(self, s) -> Any:
        return None

    def exact_pressure_interface(self, s) -> Any:
        """Closed-form contact pressure on the interface (UFL in s), or None."""
        return None

    def away_from_tips(self, s) -> Any:
        """Indicator (UFL in s) of the part of the interface a fixed distance away from the
        crack tips, where the pressure error is measured once more ('pressure_interior'), or
        None (no tips, or no such measure)."""
        return None

    def reference_profile(self, s: np.ndarray) -> dict[str, np.ndarray]:
        """Closed-form 'opening' / 'slip' at the coordinates s (numpy) for the plots."""
        return {}

    def front_profile(self, prof) -> dict[str, np.ndarray] | None:
        """3D: the stress intensity along the crack front from the gathered profile ``prof``,
        {"angle": front angle (degrees), "K": computed, "K_exact": closed form} (written as
        ``front.csv`` and plotted as ``front.png``); None for a 2D interface."""
        return None

    def interface_reference(self, prof, q, friction) -> dict[str, float]:
        """Closed-form comparisons from the gathered profile ``prof``
        (:class:`contactfx.driver.interface_post.Profile`, rank 0) and the computed state ``q``
        (:class:`contactfx.results.Quantities`) under the ``friction`` law."""
        return {}
