"""Post-processing of a fitted interface: nodal fields along the interface, forces, errors
against the closed forms, the gathered profile (CSV and a line plot)."""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol

import dolfinx
import numpy as np
import ufl
from mpi4py import MPI
from numpy.typing import NDArray

from contactfx import _compat
from contactfx.contact.interface import tangent
from contactfx.contact.laws import active
from contactfx.driver.fields import NodalProjection, global_sum, nodal_contact
from contactfx.results import InterfaceQuantities, Quantities

if TYPE_CHECKING:
    from contactfx.contact.interface import InterfaceSurface
    from contactfx.contact.laws import Friction
    from contactfx.contact.surface import Expr
    from contactfx.driver.problem import Method, Scene, Solver

__all__ = [
    "InterfaceKind",
    "InterfacePost",
    "Profile",
    "STATUS",
    "plot_front",
    "plot_profile",
    "pyplot",
]

#: interface status codes of the ``interface_status`` field
STATUS = {"open": 0, "stick": 1, "slip": 2, "propped": 3}


class InterfaceKind(Protocol):
    """What the post-processing reads of its problem kind, a
    :class:`contactfx.driver.interface.InterfaceProblem` (a protocol: that module imports
    this one)."""

    @property
    def scene(self) -> Scene: ...

    @property
    def method(self) -> Method: ...

    @property
    def mesh(self) -> dolfinx.mesh.Mesh: ...

    @property
    def surface(self) -> InterfaceSurface: ...

    @property
    def material(self) -> Any: ...

    @property
    def friction(self) -> Friction | None: ...

    @property
    def gdim(self) -> int: ...

    @property
    def U(self) -> Expr: ...

    @property
    def ds(self) -> ufl.Measure: ...

    @property
    def dS_nodal(self) -> ufl.Measure: ...

    @property
    def dS_fine(self) -> ufl.Measure: ...

    @property
    def s_coord(self) -> Expr: ...


@dataclasses.dataclass
class Profile:
    """Nodal values along the interface (rank 0 holds all, sorted by s; other ranks empty):
    coordinate s, position x (n, gdim), opening (normal jump), slip (tangential jump, along the
    interface direction), normal contact pressure p, tangential traction t (on the +side,
    along the direction), status codes, and the proppant floor."""

    s: np.ndarray
    x: np.ndarray
    opening: np.ndarray
    slip: np.ndarray
    p: np.ndarray
    t: np.ndarray
    status: np.ndarray
    floor: np.ndarray
    #: with several (unfitted) cracks: the crack of each point, from 1; s is its coordinate
    crack: np.ndarray | None = None

    FIELDS = "opening,slip,normal_traction,tangential_traction,status,proppant"

    def write_csv(self, path: Path) -> None:
        """One row per interface node (or Gauss point), sorted by s (and crack)."""
        cols = [self.s, self.x, self.opening, self.slip, self.p, self.t, self.status, self.floor]
        header = f"s,{','.join('xyz'[: self.x.shape[1]])},{self.FIELDS}"
        if self.crack is not None:
            cols, header = cols + [self.crack], header + ",crack"
        np.savetxt(path, np.column_stack(cols), delimiter=",", comments="", header=header)


class InterfacePost:
    """Nodal interface fields, forces, errors against the closed forms, the profile."""

    def __init__(self, pb: InterfaceKind) -> None:
        self.pb, self.scene, self.comm = pb, pb.scene, pb.mesh.comm
        mesh, s, method = pb.mesh, pb.surface, pb.method
        self.Q1 = _compat.function_space(mesh, "Lagrange", 1)
        self.nodal = NodalProjection(pb.dS_nodal, self.Q1, "+")
        t_I = tangent(s.interface_normal(), self.scene.slip_axis())
        p = method.pressure(s)
        closed = method.contact_indicator(s)
        joint = s.joint
        self.w0 = 0.0 if joint is None else joint.w0
        quantities = {
            "aperture": s.opening() + self.w0,
            "slip": ufl.dot(s.u, t_I),
            "normal_traction": p,
            "gap": s.gap(),
        }
        if s.friction is not None:
            quantities["tangential_traction"] = ufl.dot(method.tangential_traction(s), t_I)
            quantities["slipping"] = method.slip_indicator(s)
        if s.floor is not None:
            quantities["proppant"] = s.floor
        self.fields_nodal = {
            name: dolfinx.fem.Function(self.Q1, name=name)
            for name in quantities
            if name != "slipping"
        }
        self._slipping = dolfinx.fem.Function(self.Q1)
        self.forms = {name: self.nodal.form(expr) for name, expr in quantities.items()}
        self.status = dolfinx.fem.Function(self.Q1, name="interface_status")
        dSf = pb.dS_fine
        self.force_form = dolfinx.fem.form(p * dSf)
        self.closed_form = dolfinx.fem.form(active(closed) * dSf)
        self.tforce_form: Any = None
        extra = {}
        if s.friction is not None:
            self.tforce_form = dolfinx.fem.form(quantities["tangential_traction"] * dSf)
            # the slipping part of the interface (its length in 2D, area in 3D)
            extra["slipping_size"] = quantities["slipping"] * dSf
        self.propped_form: Any = None
        if s.floor is not None:
            self.propped_form = dolfinx.fem.form(p * active(s.floor) * dSf)
        self.err_forms = self._error_forms(s, p, t_I)
        extra.update(self.scene.extra_quantities(mesh, s.w, pb.ds))
        self.extra = {k: dolfinx.fem.form(v) for k, v in extra.items()}
        DG0 = _compat.function_space(mesh, "DG", 0)
        self.vm_expr = _compat.expression(pb.material.von_mises(s.w), DG0)
        self.vm = dolfinx.fem.Function(DG0, name="von_mises")
        V1 = _compat.function_space(mesh, "Lagrange", 1, (pb.gdim,))
        self.u_out = dolfinx.fem.Function(V1, name="displacement")
        self.a_out = dolfinx.fem.Function(V1, name="enrichment")
        U, d = pb.U, pb.gdim
        self.u_expr = _compat.expression(ufl.as_vector([U[i] for i in range(d)]), V1)
        self.a_expr = _compat.expression(ufl.as_vector([U[d + i] for i in range(d)]), V1)

    def _error_forms(self, s: InterfaceSurface, p: Expr, t_I: Expr) -> dict[str, tuple[Any, Any]]:
        """Errors against the closed forms (the pressure also away from the tips), integrated
        with a degree-12 rule."""
        out: dict[str, tuple[Any, Any]] = {}
        sc, dSf = self.pb.s_coord, self.pb.dS_fine
        exact_p, interior = self.scene.exact_pressure_interface(sc), self.scene.away_from_tips(sc)
        for name, computed, exact, weight in (
            ("opening", s.opening(), self.scene.exact_opening(sc), 1.0),
            ("slip", ufl.dot(s.u, t_I), self.scene.exact_slip(sc), 1.0),
            ("pressure", p, exact_p, 1.0),
            ("pressure_interior", p, None if interior is None else exact_p, interior),
        ):
            if exact is not None:
                out[name] = (
                    dolfinx.fem.form(weight * (computed - exact) ** 2 * dSf),
                    dolfinx.fem.form(weight * exact**2 * dSf),
                )
        return out

    def evaluate(self, solver: Solver) -> Quantities:
        for name, f in self.fields_nodal.items():
            self.nodal(self.forms[name], f)
        on, n = self.nodal.on, len(self.nodal.on)
        st = self.status.x.array
        st[:] = 0.0
        peak, closed, penetration, complementarity = nodal_contact(
            self.fields_nodal["normal_traction"].x.array,
            self.fields_nodal["gap"].x.array,
            on,
            self.comm,
        )
        st[closed] = STATUS["stick"]
        if "slipping" in self.forms:
            self.nodal(self.forms["slipping"], self._slipping)
            st[closed & (self._slipping.x.array > 0.5)] = STATUS["slip"]
        if "proppant" in self.fields_nodal:
            st[closed & (self.fields_nodal["proppant"].x.array > 0.0)] = STATUS["propped"]
        interface = InterfaceQuantities(
            tangential_force=0.0
            if self.tforce_form is None
            else global_sum(self.tforce_form, self.comm),
            extra={k: global_sum(form, self.comm) for k, form in self.extra.items()},
        )
        if self.propped_form is not None:
            ap = self.fields_nodal["aperture"].x.array[:n]
            propped = on & (self.fields_nodal["proppant"].x.array[:n] > 0.0)
            interface = dataclasses.replace(
                interface,
                proppant_force=global_sum(self.propped_form, self.comm),
                min_aperture_propped=self.comm.allreduce(
                    float(np.min(ap[propped], initial=np.inf)), op=MPI.MIN
                ),
            )
        return Quantities(
            force=global_sum(self.force_form, self.comm),
            contact_size=global_sum(self.closed_form, self.comm),
            peak_pressure=peak,
            max_penetration=penetration,
            complementarity=complementarity,
            interface=interface,
        )

    def fields(self) -> list[dolfinx.fem.Function]:
        self.u_out.interpolate(self.u_expr)
        self.a_out.interpolate(self.a_expr)
        self.vm.interpolate(self.vm_expr)
        return [self.u_out, self.a_out, self.vm, *self.fields_nodal.values(), self.status]

    def profile(self) -> Profile:
        """Gather the owned interface nodes' values on rank 0, sorted by s."""
        on = self.nodal.on
        n = len(on)
        owned = np.zeros(n, dtype=bool)
        owned[: self.Q1.dofmap.index_map.size_local] = True
        sel = owned & on
        d = self.pb.gdim
        xs = _compat.dof_coordinates(self.Q1)[:n][sel][:, :d]
        s = self.scene.coordinate(xs.T)

        def col(name: str) -> NDArray[np.float64]:
            f = self.fields_nodal.get(name)
            return np.zeros(len(s)) if f is None else f.x.array[:n][sel]

        local = np.column_stack(
            [
                s,
                xs,
                col("aperture"),
                col("slip"),
                col("normal_traction"),
                col("tangential_traction"),
                self.status.x.array[:n][sel],
                col("proppant"),
            ]
        )
        parts = self.comm.gather(local, root=0)
        if self.comm.rank != 0:
            return Profile(np.zeros(0), np.zeros((0, d)), *(np.zeros(0) for _ in range(6)))
        a = np.vstack(parts)
        a = a[np.argsort(a[:, 0], kind="stable")]
        f = a[:, d + 1 :]
        return Profile(
            a[:, 0], a[:, 1 : d + 1], f[:, 0] - self.w0, f[:, 1], f[:, 2], f[:, 3], f[:, 4], f[:, 5]
        )

    def finish(self, q: Quantities, out: Path | None) -> dict[str, Any]:
        """Closed-form comparisons from the gathered profile, field errors, the CSV and the
        line plot."""
        prof = self.profile()
        reference: dict[str, float] = {}
        if self.comm.rank == 0:
            reference = self.scene.interface_reference(prof, q, self.pb.friction)
        reference = self.comm.bcast(reference, root=0)
        plot = None
        if out is not None:
            plot = out / "interface.png"
            if self.comm.rank == 0:
                plot_profile(prof, self.scene, plot)
                prof.write_csv(out / "interface.csv")
                front = self.scene.front_profile(prof)
                if front is not None:
                    plot_front(front, self.scene, out / "front.png")
                    np.savetxt(
                        out / "front.csv",
                        np.column_stack(list(front.values())),
                        delimiter=",",
                        comments="",
                        header=",".join(front),
                    )
        errors = {}
        for name, (err, norm) in self.err_forms.items():
            e, nrm = np.sqrt(global_sum(err, self.comm)), np.sqrt(global_sum(norm, self.comm))
            errors[f"{name}_L2"] = e
            errors[f"{name}_L2_rel"] = e / nrm if nrm > 0.0 else e
        return {
            "reference": reference,
            "errors": errors,
            "plot": None if plot is None else str(plot),
        }


def pyplot() -> Any:
    """matplotlib.pyplot on the Agg backend (files only, no display)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def plot_profile(prof: Profile, scene: Scene, path: Path) -> None:
    """Line plots along the interface: aperture and slip (with the closed forms where the
    scene has them), normal and tangential traction, status."""
    plt = pyplot()
    fig, axes = plt.subplots(3, 1, figsize=(7.0, 8.0), sharex=True)
    s = prof.s
    ref = scene.reference_profile(s)
    # a 3D interface's nodes at one s lie at different places on it: points, not a line
    line = "-" if prof.x.shape[1] == 2 else ""
    for ax, name, computed in ((axes[0], "opening", prof.opening), (axes[1], "slip", prof.slip)):
        ax.plot(s, computed, "o" + line, ms=2, label=f"{name} (computed)")
        if name == "opening" and np.any(prof.floor > 0.0):
            ax.plot(s, prof.floor, "k--", lw=1, label="proppant thickness")
        if name in ref:
            ax.plot(s, ref[name], "-", lw=1, label=f"{name} (closed form)")
        ax.set_ylabel(name)
        ax.legend(fontsize=8)
    ax = axes[2]
    ax.plot(s, prof.p, "o" + line, ms=2, label="contact pressure")
    ax.plot(s, prof.t, "s" + line, ms=2, label="tangential traction")
    for name, code in STATUS.items():
        sel = prof.status == code
        if np.any(sel) and code > 0:
            label = "closed / stick" if name == "stick" else name
            ax.plot(s[sel], np.zeros(sel.sum()), "|", ms=8, label=label)
    ax.set_ylabel("traction")
    ax.set_xlabel("s (along the interface)" if line else "s (interface coordinate)")
    ax.legend(fontsize=8)
    fig.suptitle(scene.name)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_front(front: dict[str, np.ndarray], scene: Scene, path: Path) -> None:
    """The stress intensities along a 3D crack front (every key K... of ``front`` with its
    K..._exact) against the front angle."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(7.0, 4.0))
    for name in (k for k in front if k != "angle" and not k.endswith("_exact")):
        (line,) = ax.plot(
            front["angle"], front[name], "o-", ms=3, label=f"{name} (displacement extrapolation)"
        )
        ax.plot(
            front["angle"],
            front[f"{name}_exact"],
            "-",
            lw=1,
            color=line.get_color(),
            label=f"{name} (closed form)",
        )
    ax.set_xlabel("front angle (degrees)")
    ax.set_ylabel("stress intensity")
    ax.legend(fontsize=8)
    fig.suptitle(f"{scene.name}: stress intensity along the crack front")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
