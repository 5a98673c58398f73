"""Scenes with a fitted interface inside one body (cracks, fractures, joints) and their driver.

The unknown is the vector field U = (u, a) of 2 d components (d the dimension): the
displacement is w = u + H a, with the enrichment a nonzero only at the interface's dofs and zero
at the crack tips (see :mod:`contactfx.contact.interface`). Contact, friction, proppant floor,
fluid pressure and joint closure are interior-facet integrals; the methods are the ones of the
rigid-obstacle scenes (Nitsche, penalty, augmented Lagrangian), written against
:class:`contactfx.contact.interface.InterfaceSurface`.

Outputs: along the interface the aperture, slip, normal and tangential traction and the status
(0 open, 1 closed / stick, 2 slip, 3 propped) as P1 fields in the XDMF file (zero away from the
interface), as a PNG line plot (``interface.png``) against the interface coordinate s and as
CSV (``interface.csv``); the continuous part u (``displacement``) and the enrichment a
(``enrichment``): the faces are at u + a and u - a (XDMF stores no discontinuous fields on
dolfinx >= 0.8).
"""

from __future__ import annotations

import dataclasses
import time
from pathlib import Path
from typing import Any, ClassVar

import dolfinx
import dolfinx.fem.petsc
import numpy as np
import ufl
from mpi4py import MPI
from petsc4py import PETSc

from contactfx import _compat
from contactfx.contact.interface import BartonBandis, InterfaceSurface, oriented_jump
from contactfx.contact.laws import active, positive_part
from contactfx.io.provenance import versions, write_json
from contactfx.io.xdmf import ResultsWriter
from contactfx.scenes.base import (
    RunResult,
    Scene,
    _boundary_mask,
    _prepare_output,
    _say,
    _timed_load_program,
    _vertex_rule,
    _write_timed,
)
from contactfx.solvers.loadstep import StepRecord
from contactfx.solvers.snes import GAMG_OPTIONS, ContactSNES
from contactfx.solvers.uzawa import Uzawa

__all__ = ["InterfaceScene", "Profile", "STATUS"]

#: interface status codes of the ``interface_status`` field
STATUS = {"open": 0, "stick": 1, "slip": 2, "propped": 3}
#: methods offered on fitted interfaces (vi bounds dofs, not jumps)
INTERFACE_METHODS = ("nitsche", "penalty", "al-uzawa", "al-ssn")


@dataclasses.dataclass
class Profile:
    """Nodal values along the interface (rank 0 holds all, sorted by s; other ranks empty):
    coordinate s, position x (n, 2), opening (normal jump), slip (tangential jump, along the
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


class InterfaceScene(Scene):
    """Base of the fitted-interface scenes. Subclasses give the mesh, the interface (tag, sides,
    tips, frame), the supports and loads, and the closed-form references."""

    interface_tag: ClassVar[int]

    #: component supports: (facet tag, component) pairs with zero displacement; they hold for
    #: the total displacement, so for u and a alike
    def supports(self) -> list[tuple[int, int]]:
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

    def frame(self) -> tuple[np.ndarray, np.ndarray]:
        """(origin, unit direction) of the interface coordinate s = (x - origin) . direction."""
        raise NotImplementedError

    def floor(self, s):
        """Proppant thickness along the interface (UFL in the coordinate s), or None."""
        return None

    def joint(self) -> BartonBandis | None:
        return None

    def fluid_pressure(self) -> float | None:
        """Fluid pressure on the faces at load factor 1, or None (no fluid)."""
        return None

    def exact_opening(self, s) -> Any:
        """Closed-form normal opening (UFL in s), or None."""
        return None

    def exact_slip(self, s) -> Any:
        return None

    def exact_pressure_interface(self, s) -> Any:
        """Closed-form contact pressure on the interface (UFL in s), or None."""
        return None

    def length_scale(self) -> float:
        """A typical length of the body (tolerances of point location)."""
        raise NotImplementedError

    def reference_profile(self, s: np.ndarray) -> dict[str, np.ndarray]:
        """Closed-form 'opening' / 'slip' at the coordinates s (numpy) for the plots."""
        return {}

    def interface_reference(self, prof: Profile, summary: dict) -> dict[str, float]:
        """Closed-form comparisons from the gathered profile (rank 0)."""
        return {}

    def extra_quantities(self, mesh, w, ds) -> dict[str, Any]:
        """Named UFL functionals (integrals, summed over ranks) the scene reports."""
        return {}

    @classmethod
    def default_numerics(cls, **overrides):
        num = super().default_numerics(**overrides)
        if num.method not in INTERFACE_METHODS:
            raise ValueError(
                f"method {num.method} is not offered on fitted interfaces (it bounds dofs, not "
                "displacement jumps); use " + ", ".join(INTERFACE_METHODS)
            )
        return num

    def run(self, numerics, *, comm=MPI.COMM_WORLD, out=None, petsc_options=None,
            verbose=True) -> RunResult:  # fmt: skip
        return _InterfaceRun(self, numerics, comm, out, petsc_options or {}, verbose).execute()


def _components(U, H, gdim: int):
    """w = u + H a from U = (u, a)."""
    return ufl.as_vector([U[i] + H * U[gdim + i] for i in range(gdim)])


def _tangent(n):
    """The interface direction in 2D: n_I rotated by -90 degrees."""
    return ufl.as_vector([n[1], -n[0]])


def _free_mask(Q, fdim: int, facets: np.ndarray, tips: list, scale: float) -> np.ndarray:
    """Per local dof block of the collapsed space Q: on the interface and not at a tip."""
    on = _boundary_mask(Q, fdim, facets)
    if tips:
        tol = 1e-9 * scale

        def at_tip(x):
            hit = np.zeros(x.shape[1], dtype=bool)
            for tip in tips:
                hit |= np.linalg.norm(x[: len(tip)].T - tip, axis=1) < tol
            return hit

        on[dolfinx.fem.locate_dofs_geometrical(Q, at_tip)] = False
    return on


def _fix_outside(Vsub, fdim, facets, tips, scale) -> list:
    """Dirichlet conditions a = 0 (or multiplier = 0) away from the free interface dofs."""
    Q, q_to_w = Vsub.collapse()
    free = _free_mask(Q, fdim, facets, tips, scale)
    bs = Q.dofmap.index_map_bs
    q_to_w = np.asarray(q_to_w).reshape(-1, bs)
    if bs == 1:
        return [_compat.dirichletbc(np.float64(0.0), q_to_w[~free, 0].astype(np.int32), Vsub)]
    return [
        _compat.dirichletbc(np.float64(0.0), q_to_w[~free, i].astype(np.int32), Vsub.sub(i))
        for i in range(bs)
    ]


def _pin(Vsub, point: np.ndarray, scale: float):
    Q, q_to_w = Vsub.collapse()

    def at(x):
        return np.linalg.norm(x[: len(point)].T - point, axis=1) < 1e-9 * scale

    dofs = dolfinx.fem.locate_dofs_geometrical(Q, at)
    parent = np.asarray(q_to_w)[dofs].astype(np.int32)
    return _compat.dirichletbc(np.float64(0.0), parent, Vsub)


class _InterfaceRun:
    def __init__(self, scene: InterfaceScene, numerics, comm, out, petsc_options, verbose):
        self.scene, self.num, self.comm = scene, numerics, comm
        self.out = None if out is None else Path(out)
        self.petsc_options = petsc_options
        self.verbose = verbose
        self.timings: dict[str, float] = {}

    def _check(self) -> None:
        num = self.num
        if num.method not in INTERFACE_METHODS:
            raise ValueError(
                f"method {num.method} is not offered on fitted interfaces (it bounds dofs, not "
                "displacement jumps); use " + ", ".join(INTERFACE_METHODS)
            )
        if num.formulation != "displacement":
            raise ValueError("fitted interfaces use --formulation displacement")

    def execute(self) -> RunResult:  # noqa: C901 (one linear story: spaces, forms, solve, post)
        scene, num, comm = self.scene, self.num, self.comm
        self._check()
        material = scene.material()
        method = num.method_object()
        friction = num.friction_law()
        joint = scene.joint()
        if self.out is not None:
            _prepare_output(self.out, comm)

        t0 = time.perf_counter()
        mesh, facet_tags = scene.build_mesh(comm)
        self.timings["mesh"] = time.perf_counter() - t0
        gdim = mesh.geometry.dim
        if gdim != 2:
            raise ValueError("fitted interfaces are implemented in 2D (plane strain)")
        fdim = mesh.topology.dim - 1
        facets = facet_tags.indices[facet_tags.values == scene.interface_tag]
        scale = scene.length_scale()

        # the side sign H: +1 / -1 from the cell midpoints
        DG0 = _compat.function_space(mesh, "DG", 0)
        H = dolfinx.fem.Function(DG0, name="side")
        H.interpolate(lambda x: np.where(scene.side(x) >= 0.0, 1.0, -1.0))

        mixed = method.mixed
        mult_shape = (gdim,) if friction is not None else ()
        lam = lam_test = None
        if mixed:
            W = _compat.mixed_space(mesh, num.degree, 2 * gdim, mult_shape)
            V = W.sub(0)
            state = dolfinx.fem.Function(W, name="state")
            trial, test = ufl.TrialFunction(W), ufl.TestFunction(W)
            U, lam = ufl.split(state)
            dU, _ = ufl.split(trial)
            Vt, lam_test = ufl.split(test)
        else:
            W = V = _compat.function_space(mesh, "Lagrange", num.degree, (2 * gdim,))
            state = U = dolfinx.fem.Function(V, name="state")
            trial, test = ufl.TrialFunction(V), ufl.TestFunction(V)
            dU, Vt = trial, test
        w, dw, vt = (_components(X, H, gdim) for X in (U, dU, Vt))

        bcs = []
        for tag, comp in scene.supports():
            for c in (comp, gdim + comp):
                sub = V.sub(c)
                dofs = _compat.locate_dofs_topological(
                    sub, fdim, facet_tags.indices[facet_tags.values == tag]
                )
                bcs.append(_compat.dirichletbc(np.float64(0.0), dofs, sub))
        for point, comp in scene.pinned():
            bcs.append(_pin(V.sub(comp), np.asarray(point, dtype=float), scale))
        tips = [np.asarray(t, dtype=float) for t in scene.tips()]
        for i in range(gdim):
            bcs += _fix_outside(V.sub(gdim + i), fdim, facets, tips, scale)
        if mixed:
            bcs += _fix_outside(W.sub(1), fdim, facets, tips, scale)

        qdeg = 2 * num.degree + 2
        dS = ufl.Measure("dS", domain=mesh, subdomain_data=facet_tags)
        rule = _vertex_rule(fdim) if num.quadrature == "nodal" else {"quadrature_degree": qdeg}
        dSc = dS(scene.interface_tag, metadata=rule)
        dS_fine = dS(scene.interface_tag, metadata={"quadrature_degree": 12})
        dS_nodal = dS(scene.interface_tag, metadata=_vertex_rule(fdim))
        ds = ufl.Measure("ds", domain=mesh, subdomain_data=facet_tags)
        x = ufl.SpatialCoordinate(mesh)
        origin, direction = (np.asarray(v, dtype=float) for v in scene.frame())
        s_coord = (x[0] - origin[0]) * direction[0] + (x[1] - origin[1]) * direction[1]
        tload = dolfinx.fem.Constant(mesh, 0.0)
        fluid_value = scene.fluid_pressure()
        fluid = None
        if fluid_value is not None:
            fluid = dolfinx.fem.Constant(mesh, 0.0)
        floor = scene.floor(s_coord)

        prev = None
        if friction is not None:
            prev = dolfinx.fem.Function(state.function_space)
        multiplier = None
        if method.name == "al-uzawa":
            multiplier = dolfinx.fem.Function(
                _compat.function_space(mesh, "Lagrange", 1, mult_shape if mult_shape else None),
                name="multiplier",
            )
            lam = multiplier
        w_prev = None
        if prev is not None:
            w_prev = _components(ufl.split(prev)[0] if mixed else prev, H, gdim)
        h = _compat.cell_diameter(mesh)
        surface = InterfaceSurface(
            w, vt, H, dSc, material.sigma(w), material.sigma(vt), scene.contact_modulus(), h,
            floor=floor, fluid=fluid, joint=joint, friction=friction, u_prev=w_prev,
            ds_nodal=dS_nodal if mixed else None,
            multiplier=None if lam is None else lam("+"),
            multiplier_test=None if lam_test is None else lam_test("+"),
        )  # fmt: skip

        t0 = time.perf_counter()
        zero = dolfinx.fem.Constant(mesh, 0.0)
        a_ufl = ufl.inner(material.sigma(dw), ufl.sym(ufl.grad(vt))) * ufl.dx
        # zero couplings that give the matrix the pattern of the interface terms (dofs of the
        # two cells of an interface facet; every component of a mixed unknown)
        n_comp = ufl.shape(trial)[0]
        s_trial = sum(trial[i] for i in range(n_comp))
        s_test = sum(test[i] for i in range(n_comp))
        a_ufl += zero * ufl.jump(s_trial) * ufl.jump(s_test) * dS(scene.interface_tag)
        a_ufl += zero * ufl.avg(s_trial) * ufl.avg(s_test) * dS(scene.interface_tag)
        if mixed:
            a_ufl += zero * s_trial * s_test * ufl.dx
        a_form = dolfinx.fem.form(a_ufl)
        L = scene.load(vt, ds, tload)
        if L is None:
            L = ufl.inner(dolfinx.fem.Constant(mesh, np.zeros(gdim)), vt) * ufl.dx
        if fluid is not None:  # the fluid pushes both faces apart
            L = L + fluid * ufl.dot(surface.v, surface.interface_normal()) * dSc
        L_form = dolfinx.fem.form(L)
        Fc_ufl = method.residual(surface)
        F_c = dolfinx.fem.form(Fc_ufl)
        J_c = dolfinx.fem.form(ufl.derivative(Fc_ufl, state, trial))
        post = _InterfacePost(mesh, scene, num, surface, method, dS_nodal, dS_fine, s_coord,
                              material, H, ds, facet_tags, U)  # fmt: skip
        update = None
        if multiplier is not None:
            update = _NodalUpdate(method.update(surface), multiplier, dS_nodal)
        self.timings["compile"] = time.perf_counter() - t0

        options = dict(GAMG_OPTIONS) if num.solver == "gamg" else {}
        prefix = f"contactfx_{scene.name.replace('-', '_')}_"
        solver = ContactSNES(
            state, stiffness=a_form, load=L_form, contact_residual=F_c, contact_jacobian=J_c,
            bcs=bcs, prefix=prefix, options=options, user_options=self.petsc_options,
        )  # fmt: skip
        if multiplier is not None:
            mask = _free_mask(multiplier.function_space, fdim, facets, tips, scale)
            solver = Uzawa(solver, multiplier, update, mask, tol=num.al_tol, max_it=num.al_max_it)

        def apply_load(t: float) -> None:
            tload.value = t
            if fluid is not None:
                fluid.value = t * fluid_value

        apply_load(1.0 / num.steps)
        t0 = time.perf_counter()
        spring = None
        if joint is not None:  # the joint's initial normal stiffness, tangentially bonded
            n_I = surface.interface_normal()
            t_I = _tangent(n_I)
            jd, jv = oriented_jump(dw, H), surface.v
            k_t = scene.contact_modulus() / surface.h
            spring = dolfinx.fem.form(
                (joint.Kni * ufl.dot(jd, n_I) * ufl.dot(jv, n_I)
                 + k_t * ufl.dot(jd, t_I) * ufl.dot(jv, t_I)) * dSc
            )  # fmt: skip
        _initial_guess(solver.inner if multiplier is not None else solver, V, gdim, spring)
        if lam is not None:  # multipliers start at the traction of that state
            n = surface.normal()
            if mult_shape:
                start = ufl.dot(surface.stress, n)
            else:
                start = positive_part(surface.effective_pressure())
            if multiplier is not None:
                _NodalUpdate(start, multiplier, dS_nodal)(multiplier)
                bs = multiplier.function_space.dofmap.index_map_bs
                multiplier.x.array[~np.repeat(mask, bs)] = 0.0
            else:
                Q, q_to_w = W.sub(1).collapse()
                lam0 = dolfinx.fem.Function(Q)
                _NodalUpdate(start, lam0, dS_nodal)(lam0)
                state.x.array[np.asarray(q_to_w)] = lam0.x.array
                state.x.scatter_forward()
        self.timings["initial_guess"] = time.perf_counter() - t0
        inner = solver.inner if multiplier is not None else solver
        user = set(self.petsc_options)
        if not {"snes_atol", prefix + "snes_atol"} & user:
            # absolute tolerance a little above the round-off of the loads: the start (bonded,
            # or the load-step predictor) can already be the solution, e.g. of a uniformly
            # compressed joint, and rtol then cannot be met
            inner.snes.setTolerances(atol=1e-11 * inner.b.norm())
        if not mixed and not {"snes_stol", prefix + "snes_stol"} & user:
            # and a Newton step below 1e-12 of the displacement is converged too (the
            # residual's round-off floor grows with the conditioning, e.g. P2 on graded tips);
            # not for al-ssn, whose unknown mixes displacements and multipliers
            inner.snes.setTolerances(stol=1e-12)

        steps_log: list[dict] = []
        last: dict[str, Any] = {}
        writer = None
        xdmf_path = None if self.out is None else self.out / f"{scene.name}.xdmf"

        def on_step(rec: StepRecord) -> None:
            summary = post.evaluate()
            last.clear()
            last.update(summary)
            steps_log.append({
                "step": rec.step, "load": rec.load, "newton": rec.stats.newton,
                "ksp": rec.stats.ksp, "outer": rec.stats.outer, "cutbacks": rec.cutbacks,
                "reason": rec.stats.reason, "normal_force": summary["normal_force"],
                "tangential_force": summary["tangential_force"],
            })  # fmt: skip
            if writer is not None:
                _write_timed(writer, rec.load, post.fields(state), self.timings)
            if prev is not None:
                prev.x.array[:] = state.x.array
            outer = f"  outer {rec.stats.outer:3d}" if multiplier is not None else ""
            _say(
                comm, self.verbose,
                f"  step {rec.step:3d}  load {rec.load:6.3f}  newton {rec.stats.newton:3d}{outer}"
                f"  normal force {summary['normal_force']:.6g}"
                f"  tangential force {summary['tangential_force']:.6g}",
            )  # fmt: skip

        try:
            if xdmf_path is not None:
                writer = ResultsWriter(xdmf_path, mesh).__enter__()
            records = _timed_load_program(solver, apply_load, num.steps, on_step, self.timings)
        finally:
            if writer is not None:
                writer.__exit__(None, None, None)

        prof = post.profile()
        reference: dict[str, float] = {}
        if comm.rank == 0:
            reference = scene.interface_reference(prof, last)
        reference = comm.bcast(reference, root=0)
        png = None
        if self.out is not None:
            png = self.out / "interface.png"
            if comm.rank == 0:
                _plot_profile(prof, scene, png)
                _write_profile(prof, self.out / "interface.csv")
        dofs_total = state.function_space.dofmap.index_map.size_global * (
            state.function_space.dofmap.index_map_bs
        )
        n_fixed = comm.allreduce(
            sum(int(np.sum(np.asarray(_compat.bc_dofs(bc)) < _owned(state))) for bc in bcs),
            op=MPI.SUM,
        )
        data: dict[str, Any] = {
            "status": "completed",
            "scene": scene.name,
            "parameters": dataclasses.asdict(scene.p),
            "numerics": dataclasses.asdict(num),
            "petsc_options": {k: str(v) for k, v in self.petsc_options.items()},
            "petsc_prefix": prefix,
            "versions": versions(),
            "ranks": comm.size,
            "dofs": dofs_total - n_fixed,
            "cells": mesh.topology.index_map(mesh.topology.dim).size_global,
            "h_contact": scene.h_contact(),
            "newton_iterations": sum(r.stats.newton for r in records),
            "ksp_iterations": sum(r.stats.ksp for r in records),
            "outer_iterations": sum(r.stats.outer for r in records),
            "steps": steps_log,
            "timings": dict(self.timings),
            "xdmf": None if xdmf_path is None else str(xdmf_path),
            "plot": None if png is None else str(png),
            **last,
            # the names the rigid-obstacle scenes use, for tools reading any run.json
            "force": last["normal_force"],
            "peak_pressure": last["max_pressure"],
            "reference": reference,
            "errors": post.field_errors(),
        }
        solver.destroy()
        if self.out is not None:
            write_json(self.out / "run.json", data, comm)
        return RunResult(data)


def _initial_guess(solver: ContactSNES, V, gdim: int, spring=None) -> None:
    """Start from the interface held together under the first load step's loads: a linear
    solve with the jump fixed to zero (``spring`` None: the bonded body) or held by the linear
    springs of the compiled bilinear form ``spring`` (a joint's initial stiffness). Where the
    interface is then in compression the contact law is active at the first Newton iterate and
    the body stays supported (from the unloaded, touching state the semi-smooth derivative of
    [x]_+ at x = 0 would leave a part split off by the interface unsupported); where it is in
    tension the faces open in the next iterations. Multiplier unknowns start at zero."""
    state = solver.u
    n_owned = _owned(state)
    keep = np.zeros(n_owned, dtype=bool)
    for i in range(gdim if spring is None else 2 * gdim):
        _, parent = V.sub(i).collapse()
        parent = np.asarray(parent)
        keep[parent[parent < n_owned]] = True
    keep[solver._bc_rows] = False
    rows = np.flatnonzero(~keep).astype(np.int32)
    solver.assemble_load()
    A = solver.K.copy()
    if spring is not None:
        S = _compat.assemble_matrix(_compat.create_matrix(spring), spring)
        A.axpy(1.0, S, structure=PETSc.Mat.Structure.SUBSET_NONZERO_PATTERN)
        S.destroy()
    A.zeroRowsColumnsLocal(rows, diag=1.0)
    b = solver.b.copy()
    b.getArray()[rows] = 0.0
    x = _compat.petsc_vec(state)
    ksp = PETSc.KSP().create(state.function_space.mesh.comm)
    ksp.setOperators(A)
    ksp.setType("preonly")
    ksp.getPC().setType("lu")
    ksp.getPC().setFactorSolverType("mumps")
    ksp.solve(b, x)
    x.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)
    for obj in (ksp, A, b):
        obj.destroy()


def _owned(f) -> int:
    im = f.function_space.dofmap.index_map
    return im.size_local * f.function_space.dofmap.index_map_bs


class _NodalUpdate:
    """The Uzawa update on an interface: the multiplier's next value at the interface nodes,
    (int f q dS) / (int q dS) with the vertex rule (exact nodal values of f; interior-facet
    quantities cannot be interpolated cellwise)."""

    def __init__(self, expr, multiplier, dS_nodal) -> None:
        Q = multiplier.function_space
        q = ufl.TestFunction(Q)
        self.b_form = dolfinx.fem.form(ufl.inner(expr, q("+")) * dS_nodal)
        shape = multiplier.ufl_shape
        ones = ufl.as_vector([1.0] * shape[0]) if shape else 1.0
        self.mass = _assemble(dolfinx.fem.form(ufl.inner(ones, q("+")) * dS_nodal))

    def __call__(self, target) -> None:
        _lumped_into(self.b_form, target, self.mass)


def _assemble(form) -> np.ndarray:
    b = _compat.assemble_vector(_compat.create_vector(form), form)
    b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    arr = b.getArray().copy()
    b.destroy()
    return arr


def _lumped_into(form, target, mass: np.ndarray) -> None:
    """target = assembled form / mass at the nodes where mass > 0, else 0 (owned dofs, then
    a forward scatter)."""
    b = _assemble(form)
    vec = _compat.petsc_vec(target)
    arr = vec.getArray()
    on = mass > 0.0
    arr[:] = 0.0
    arr[on] = b[on] / mass[on]
    vec.ghostUpdate(addv=PETSc.InsertMode.INSERT, mode=PETSc.ScatterMode.FORWARD)


class _InterfacePost:
    """Nodal interface fields, forces, errors against the closed forms, the gathered profile."""

    def __init__(self, mesh, scene, num, surface: InterfaceSurface, method, dS_nodal, dS_fine,
                 s_coord, material, H, ds, facet_tags, U) -> None:  # fmt: skip
        self.mesh, self.scene, self.num, self.surface = mesh, scene, num, surface
        self.comm = mesh.comm
        gdim = mesh.geometry.dim
        self.gdim = gdim
        Q1 = _compat.function_space(mesh, "Lagrange", 1)
        self.Q1 = Q1
        q = ufl.TestFunction(Q1)
        self.mass = _assemble(dolfinx.fem.form(q("+") * dS_nodal))
        n_I = surface.interface_normal()
        t_I = _tangent(n_I)
        p = method.pressure(surface)
        closed = getattr(method, "contact_indicator", method.pressure)(surface)
        friction = surface.friction
        joint = surface.joint
        w0 = 0.0 if joint is None else joint.w0
        quantities = {
            "aperture": surface.opening() + w0,
            "slip": ufl.dot(surface.u, t_I),
            "normal_traction": p,
            "gap": surface.gap(),
        }
        if friction is not None:
            quantities["tangential_traction"] = ufl.dot(method.tangential_traction(surface), t_I)
            quantities["slipping"] = method.slip_indicator(surface)
        if surface.floor is not None:
            quantities["proppant"] = surface.floor
        self.fields_nodal = {
            name: dolfinx.fem.Function(Q1, name=name) for name in quantities if name != "slipping"
        }
        self._slipping = dolfinx.fem.Function(Q1)
        self.forms = {
            name: dolfinx.fem.form(expr * q("+") * dS_nodal) for name, expr in quantities.items()
        }
        self.status = dolfinx.fem.Function(Q1, name="interface_status")
        self.force_form = dolfinx.fem.form(p * dS_fine)
        self.closed_form = dolfinx.fem.form(active(closed) * dS_fine)
        self.tforce_form = None
        if friction is not None:
            self.tforce_form = dolfinx.fem.form(quantities["tangential_traction"] * dS_fine)
        self.propped_form = None
        if surface.floor is not None:
            self.propped_form = dolfinx.fem.form(p * active(surface.floor) * dS_fine)
        # errors against the closed forms, integrated with a degree-12 rule
        self.err_forms: dict[str, tuple] = {}
        for name, computed, exact in (
            ("opening", surface.opening(), scene.exact_opening(s_coord)),
            ("slip", ufl.dot(surface.u, t_I), scene.exact_slip(s_coord)),
            ("pressure", p, scene.exact_pressure_interface(s_coord)),
        ):
            if exact is None:
                continue
            self.err_forms[name] = (
                dolfinx.fem.form((computed - exact) ** 2 * dS_fine),
                dolfinx.fem.form(exact**2 * dS_fine),
            )
        self.extra = {
            k: dolfinx.fem.form(v) for k, v in scene.extra_quantities(mesh, surface.w, ds).items()
        }
        # the continuous part u ("displacement": the displacement everywhere but in the cells
        # touching the interface, where w = u + H a) and the enrichment a ("enrichment": the
        # faces are at u + a and u - a, the jump is 2 a); XDMF on dolfinx >= 0.8 stores no
        # discontinuous fields
        DG0 = _compat.function_space(mesh, "DG", 0)
        self.vm_expr = _compat.expression(material.von_mises(surface.w), DG0)
        self.vm = dolfinx.fem.Function(DG0, name="von_mises")
        V1 = _compat.function_space(mesh, "Lagrange", 1, (gdim,))
        self.u_out = dolfinx.fem.Function(V1, name="displacement")
        self.a_out = dolfinx.fem.Function(V1, name="enrichment")
        self.u_expr = _compat.expression(ufl.as_vector([U[i] for i in range(gdim)]), V1)
        self.a_expr = _compat.expression(ufl.as_vector([U[gdim + i] for i in range(gdim)]), V1)
        self.x_nodes = _compat.dof_coordinates(Q1)

    def _sum(self, form) -> float:
        return self.comm.allreduce(dolfinx.fem.assemble_scalar(form), op=MPI.SUM)

    def evaluate(self) -> dict[str, Any]:
        for name, f in self.fields_nodal.items():
            _lumped_into(self.forms[name], f, self.mass)
        on = self.mass > 0.0
        n = len(self.mass)
        st = self.status.x.array
        st[:] = 0.0
        p = self.fields_nodal["normal_traction"].x.array
        p_max = self.comm.allreduce(float(np.max(p[:n][on], initial=0.0)), op=MPI.MAX)
        closed = p > 1e-10 * max(p_max, 1e-300)
        st[closed] = STATUS["stick"]
        if "slipping" in self.forms:
            _lumped_into(self.forms["slipping"], self._slipping, self.mass)
            st[closed & (self._slipping.x.array > 0.5)] = STATUS["slip"]
        if "proppant" in self.fields_nodal:
            st[closed & (self.fields_nodal["proppant"].x.array > 0.0)] = STATUS["propped"]
        gap = self.fields_nodal["gap"].x.array[:n][on]
        complementarity = self.comm.allreduce(
            float(np.max(np.abs(gap * p[:n][on]), initial=0.0)), op=MPI.MAX
        )
        out: dict[str, Any] = {
            "normal_force": self._sum(self.force_form),
            "tangential_force": 0.0 if self.tforce_form is None else self._sum(self.tforce_form),
            "closed_length": self._sum(self.closed_form),
            "max_penetration": self.comm.allreduce(
                float(max(-gap.min(initial=0.0), 0.0)), op=MPI.MAX
            ),
            "max_pressure": p_max,
            "complementarity": complementarity,
        }
        if self.propped_form is not None:
            out["proppant_force"] = self._sum(self.propped_form)
            ap = self.fields_nodal["aperture"].x.array[:n]
            propped = on & (self.fields_nodal["proppant"].x.array[:n] > 0.0)
            out["min_aperture_propped"] = self.comm.allreduce(
                float(np.min(ap[propped], initial=np.inf)), op=MPI.MIN
            )
        for k, form in self.extra.items():
            out[k] = self._sum(form)
        return out

    def field_errors(self) -> dict[str, float]:
        out = {}
        for name, (err, norm) in self.err_forms.items():
            e, nrm = np.sqrt(self._sum(err)), np.sqrt(self._sum(norm))
            out[f"{name}_L2"] = e
            out[f"{name}_L2_rel"] = e / nrm if nrm > 0.0 else e
        return out

    def profile(self) -> Profile:
        """Gather the owned interface nodes' values on rank 0, sorted by s."""
        im = self.Q1.dofmap.index_map
        owned = np.zeros(len(self.mass), dtype=bool)
        owned[: im.size_local] = True
        sel = owned & (self.mass > 0.0)
        origin, direction = (np.asarray(v, dtype=float) for v in self.scene.frame())
        xs = self.x_nodes[: len(self.mass)][sel][:, :2]
        s = (xs - origin) @ direction

        def col(name):
            f = self.fields_nodal.get(name)
            return np.zeros(len(s)) if f is None else f.x.array[: len(self.mass)][sel]

        local = np.column_stack([
            s, xs, col("aperture"), col("slip"), col("normal_traction"),
            col("tangential_traction"), self.status.x.array[: len(self.mass)][sel],
            col("proppant"),
        ])  # fmt: skip
        parts = self.comm.gather(local, root=0)
        if self.comm.rank != 0:
            return Profile(*(np.zeros(0) for _ in range(8)))
        a = np.vstack(parts)
        a = a[np.argsort(a[:, 0])]
        w0 = 0.0 if self.surface.joint is None else self.surface.joint.w0
        return Profile(a[:, 0], a[:, 1:3], a[:, 3] - w0, a[:, 4], a[:, 5], a[:, 6], a[:, 7],
                       a[:, 8])  # fmt: skip

    def fields(self, state) -> list:
        self.u_out.interpolate(self.u_expr)
        self.a_out.interpolate(self.a_expr)
        self.vm.interpolate(self.vm_expr)
        return [self.u_out, self.a_out, self.vm, *self.fields_nodal.values(), self.status]


def _write_profile(prof: Profile, path: Path) -> None:
    """The interface profile as CSV (one row per interface node, sorted by s)."""
    cols = np.column_stack([prof.s, prof.x, prof.opening, prof.slip, prof.p, prof.t,
                            prof.status, prof.floor])  # fmt: skip
    np.savetxt(
        path,
        cols,
        delimiter=",",
        comments="",
        header="s,x,y,opening,slip,normal_traction,tangential_traction,status,proppant",
    )


def _plot_profile(prof: Profile, scene: InterfaceScene, path: Path) -> None:
    """Line plots along the interface: aperture and slip (with the closed forms where the
    scene has them), normal and tangential traction, status."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(3, 1, figsize=(7.0, 8.0), sharex=True)
    s = prof.s
    ref = scene.reference_profile(s)
    for ax, name, computed in ((axes[0], "opening", prof.opening), (axes[1], "slip", prof.slip)):
        ax.plot(s, computed, "o-", ms=2, label=f"{name} (computed)")
        if name == "opening" and np.any(prof.floor > 0.0):
            ax.plot(s, prof.floor, "k--", lw=1, label="proppant thickness")
        if name in ref:
            ax.plot(s, ref[name], "-", lw=1, label=f"{name} (closed form)")
        ax.set_ylabel(name)
        ax.legend(fontsize=8)
    ax = axes[2]
    ax.plot(s, prof.p, "o-", ms=2, label="contact pressure")
    ax.plot(s, prof.t, "s-", ms=2, label="tangential traction")
    for name, code in STATUS.items():
        sel = prof.status == code
        if np.any(sel) and code > 0:
            label = "closed / stick" if name == "stick" else name
            ax.plot(s[sel], np.zeros(sel.sum()), "|", ms=8, label=label)
    ax.set_ylabel("traction")
    ax.set_xlabel("s (along the interface)")
    ax.legend(fontsize=8)
    fig.suptitle(scene.name)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
