"""The scenes of a problem file: the mesh and its named groups, the supports and loads of
the file, the reactions and probes per step, and the three contact kinds (a rigid obstacle, a
pair of bodies, a straight fitted interface) on top of the built-in scenes' bases."""

from __future__ import annotations

import functools
import re
from dataclasses import dataclass

import dolfinx
import numpy as np
import ufl
from mpi4py import MPI

from contactfx import _compat
from contactfx.contact.obstacles import (
    Ball,
    FlatPunch,
    Floor,
    HalfSpace,
    Obstacle,
    Paraboloid,
    Sinusoid,
)
from contactfx.mechanics.axisymmetric import measure
from contactfx.mechanics.elasticity import Elastic
from contactfx.meshes import BUILDERS, build_file, build_grouped, builder_groups
from contactfx.params import Params, param
from contactfx.scenes._common import fix, fix_component, prescribe_component, reaction_forces
from contactfx.scenes.base import ObstacleScene
from contactfx.scenes.interface_base import InterfaceScene
from contactfx.scenes.problem_file.expressions import DistanceObstacle
from contactfx.scenes.problem_file.reader import ProblemError, Reader, amplitude_at
from contactfx.scenes.problem_file.specs import AXES, ProblemFile
from contactfx.scenes.two_body_base import TwoBodyScene

__all__ = ["FileParams", "FileObstacleScene", "FileTwoBodyScene", "FileInterfaceScene"]


@dataclass(frozen=True)
class FileParams(Params):
    """What run.json records of a problem-file run: the file and the mesh size factor."""

    problem: str = param("", "the problem file")
    size: float = param(1.0, "element size factor of a .geo mesh", positive=True)


class _FileMesh:
    """What both file scenes share: the mesh and its named groups, the boundary conditions
    and loads of the file, the reactions per group."""

    symmetry = 1.0
    Params = FileParams

    def coarsened(self, factor: float):
        """None: the file's mesh has one size (nested iteration needs a generated mesh)."""
        return None

    def __init__(self, problem: ProblemFile) -> None:
        self.spec = problem
        self.p = FileParams(problem=str(problem.path), size=problem.mesh.size)
        # the name makes the output files and the PETSc options prefix
        self.name = re.sub(r"[^A-Za-z0-9_-]", "_", problem.title)
        self.summary = f"problem file {problem.path.name}"
        self.reaction_rows: list[dict] = []
        self._constants: list[tuple[dolfinx.fem.Constant, list, np.ndarray]] = []
        self.axisymmetric = problem.mesh.axisymmetric
        # a body of revolution: forces and areas 2 pi times the section's (weighted) integrals;
        # the radial forces cancel over the revolution, the axial ones add; the components
        # normal to a mirror plane cancel (Scene.force_symmetry)
        turn = 2.0 * np.pi if self.axisymmetric else 1.0
        self.symmetry = problem.output.symmetry * turn
        self.symmetry_planes = problem.output.symmetry_planes

    def _fail(self, key: str, message: str):
        raise ProblemError(f"{self.spec.path}: {key}: {message}")

    def read_mesh(self, comm):
        mesh = self.spec.mesh
        if mesh.builder is None:
            data, groups = build_file(comm, mesh.file, mesh.size, self.name)
        else:
            name, params = mesh.builder
            function, _ = BUILDERS[name]
            builder, groups = builder_groups(functools.partial(function, **params), name)
            try:
                data, groups = build_grouped(comm, builder, groups, self.name)
            except (ValueError, TypeError) as err:  # the builder's own checks, unknown names
                self._fail("mesh.parameters", f"{name}: {err}")
        self.groups = {g.name: g for g in groups}
        self._mesh = data.mesh
        self.gdim = max(g.dim for g in groups)
        self.cell_tags = data.cell_tags
        self._facet_tags = data.facet_tags
        self._check_groups()
        for k in self.symmetry_planes:
            if k >= self.gdim:
                self._fail(
                    "output.symmetry_planes",
                    f"'{AXES[k]}' is no axis of a {self.gdim}D mesh (the axes normal to the "
                    "mirror planes)",
                )
        if self.axisymmetric:
            self._check_axisymmetric(data.mesh)
        return data.mesh, data.facet_tags

    def _check_axisymmetric(self, mesh) -> None:
        """An axisymmetric mesh is 2D and lies in r = x >= 0 (collective)."""
        if self.gdim != 2:
            self._fail("mesh.axisymmetric", f"needs a 2D mesh (r, z), got {self.gdim}D")
        x = mesh.geometry.x[:, 0]
        lowest = mesh.comm.allreduce(float(x.min(initial=np.inf)), op=MPI.MIN)
        extent = mesh.comm.allreduce(float(np.abs(x).max(initial=0.0)), op=MPI.MAX)
        if lowest < -1e-10 * max(extent, 1.0):
            self._fail(
                "mesh.axisymmetric",
                f"the mesh is the (r, z) section: it needs x = r >= 0, got x = {lowest:.6g}",
            )

    def group_list(self) -> str:
        return ", ".join(f"{g.name} ({g.dim}D)" for g in self.groups.values())

    def tag(self, key: str, name: str, dim: int) -> int:
        g = self.groups.get(name)
        if g is None:
            self._fail(
                key,
                f"no physical group '{name}' in {self.spec.mesh.label} (it "
                f"has: {self.group_list()})",
            )
        if g.dim != dim:
            what = "cells (a body)" if dim == self.gdim else "facets (a boundary)"
            self._fail(key, f"group '{name}' has dimension {g.dim}, expected {dim}: {what}")
        if g.elements == 0:
            self._fail(key, f"group '{name}' has no element")
        return g.tag

    def _check_groups(self) -> None:
        pb, fdim = self.spec, self.gdim - 1
        self.body_tags = [
            self.tag(f"bodies.{i}.group", b.group, self.gdim) for i, b in enumerate(pb.bodies)
        ]
        for i, b in enumerate(pb.boundary):
            self.tag(f"boundary.{i}.group", b.group, fdim)
            comps = [*b.fix, *b.displacement]
            if any(c >= self.gdim for c in comps):
                self._fail(f"boundary.{i}", f"component z in a {self.gdim}D problem")
            if b.traction is not None and len(b.traction) != self.gdim:
                self._fail(f"boundary.{i}.traction", f"expected {self.gdim} numbers")
            if b.stress is not None and len(b.stress) != self.gdim:
                self._fail(f"boundary.{i}.stress", f"expected {self.gdim} rows of {self.gdim}")
        for i, pin in enumerate(pb.pins):
            if len(pin.point) != self.gdim:
                self._fail(f"pins.{i}.point", f"expected {self.gdim} coordinates")
            if any(c >= self.gdim for c in pin.fix):
                self._fail(f"pins.{i}.fix", f"component z in a {self.gdim}D problem")
        for name, (group, _) in pb.output.mean_displacement.items():
            self.tag(f"output.mean_displacement.{name}", group, fdim)
        self._check_dynamics()
        touching = set() if pb.pair is None else {pb.pair.slave, pb.pair.master}
        if pb.obstacle is not None:
            touching.add(pb.obstacle.contact)
        for i, b in enumerate(pb.boundary):
            if b.group in touching:
                self._fail(
                    f"boundary.{i}.group",
                    f"'{b.group}' is a contact surface: the "
                    "contact law there assumes no other condition or load (Nitsche "
                    "would be inconsistent); give it its own physical group",
                )
        if (
            pb.pair is None
            and pb.dynamics is None  # in time, its mass holds it
            and not pb.pins
            and not any(b.fix or b.displacement for b in pb.boundary)
        ):
            self._fail(
                "boundary",
                "the body has no support (fix or displacement on a group): "
                "frictionless contact alone leaves it free to slide, the solve would be "
                "singular (a free body needs [dynamics]: its mass holds it)",
            )
        for i, g in enumerate(pb.output.reactions):
            self.tag(f"output.reactions.{i}", g, fdim)
        for i, q in enumerate(pb.output.probes):
            if len(q) != self.gdim:
                self._fail(f"output.probes.{i}", f"expected {self.gdim} coordinates, got {list(q)}")

    def _check_dynamics(self) -> None:
        """The [dynamics] vectors against the mesh's dimension."""
        dyn = self.spec.dynamics
        if dyn is None:
            return
        vectors = {f"initial_velocity.{g}": v for g, v in dyn.velocity.items()}
        if dyn.gravity is not None:
            vectors["gravity"] = dyn.gravity
        if dyn.velocity_field is not None:
            vectors["initial_velocity"] = dyn.velocity_field
        for key, value in vectors.items():
            if len(value) != self.gdim:
                self._fail(
                    f"dynamics.{key}",
                    f"expected {self.gdim} components (a {self.gdim}D mesh), got {len(value)}",
                )

    # -- supports and loads -----------------------------------------------------------------
    def dirichlet(self, V, facet_tags) -> list:
        bcs = []
        for i, b in enumerate(self.spec.boundary):
            tag = self.groups[b.group].tag
            if V.num_sub_spaces == 0:  # one component (1D on dolfinx 0.9): no sub-spaces
                if b.displacement:
                    self._fail(
                        f"boundary.{i}.displacement",
                        "prescribed displacements are not offered in 1D (fix is)",
                    )
                bcs += fix(V, facet_tags, tag) if b.fix else []
                continue
            bcs += [fix_component(V, facet_tags, tag, c) for c in b.fix]
            for c, value in b.displacement.items():
                const = dolfinx.fem.Constant(V.mesh, 0.0)
                self._constants.append((const, b.amplitude, np.array(value)))
                bcs.append(prescribe_component(V, facet_tags, tag, c, const))
        return bcs

    def load(self, v, ds, t):
        L = self._gravity(v)
        # weighted by r on an axisymmetric section, as the bulk's and the mass's integrals;
        # a body's cells by its indicator, not a subdomain of dx: every volume integral of a
        # form shares one subdomain data on dolfinx 0.9 (the mass's has none)
        dx = measure("dx", self._mesh, self.axisymmetric)
        for i, body in enumerate(self.spec.bodies):
            if body.force is None:
                continue
            if len(body.force) != self.gdim:
                self._fail(f"bodies.{i}.body_force", f"expected {self.gdim} numbers")
            amp = dolfinx.fem.Constant(self._mesh, 0.0)
            self._constants.append((amp, body.amplitude, np.array(1.0)))
            force = ufl.as_vector(body.force.tolist())
            inside = self._per_body(self._mesh, [float(j == i) for j in range(len(self.body_tags))])
            form = amp * ufl.dot(force, v) * inside * dx
            L = form if L is None else L + form
        for b in self.spec.boundary:
            if b.traction is None and b.pressure is None and b.stress is None:
                continue
            amp = dolfinx.fem.Constant(self._mesh, 0.0)
            self._constants.append((amp, b.amplitude, np.array(1.0)))
            term = 0
            if b.traction is not None:
                term = ufl.dot(ufl.as_vector(b.traction.tolist()), v)
            if b.pressure is not None:  # a pressure pushes into the body: -p n
                term = term - b.pressure * ufl.dot(ufl.FacetNormal(self._mesh), v)
            if b.stress is not None:  # the traction sigma n of a stress field
                x = ufl.SpatialCoordinate(self._mesh)
                y = ufl.as_vector([x[i] for i in range(self.gdim)])
                sigma = ufl.as_matrix(
                    [[e(y) if callable(e) else e for e in row] for row in b.stress]
                )
                term = term + ufl.dot(ufl.dot(sigma, ufl.FacetNormal(self._mesh)), v)
            rule = (
                None if b.quadrature_degree is None else {"quadrature_degree": b.quadrature_degree}
            )
            form = amp * term * ds(self.groups[b.group].tag, metadata=rule)
            L = form if L is None else L + form
        return L

    def _gravity(self, v):
        """rho g . v over each body: ``dynamics.gravity``, constant in time (None without)."""
        dyn = self.spec.dynamics
        if dyn is None or dyn.gravity is None:
            return None
        dx = measure("dx", self._mesh, self.axisymmetric)
        rho = self._per_body(self._mesh, [b.material.density for b in self.spec.bodies])
        return rho * ufl.dot(ufl.as_vector(dyn.gravity.tolist()), v) * dx

    def set_load(self, t: float) -> None:
        for const, table, value in self._constants:
            const.value = value * amplitude_at(table, t)

    def h_contact(self) -> float:
        return self._h

    def contact_size(self, measure: float) -> float:
        """From the measure of the contact set (times the symmetry): by default the contact
        half-width (2D) or the radius of the disc of the same area (3D); ``output.contact_size``
        chooses half-measure, measure or disc-radius."""
        rule = self.spec.output.contact_size or (
            "disc-radius" if self.gdim == 3 or self.axisymmetric else "half-measure"
        )
        if rule == "measure":
            return measure
        return 0.5 * measure if rule == "half-measure" else float(np.sqrt(measure / np.pi))

    def initial_guess(self, u, t: float) -> None:
        """The file's ``initial.displacement`` (expressions in x, y, z), else zero."""
        if self.spec.initial is not None:
            self._interpolate(u, self.spec.initial, "initial.displacement")

    def _interpolate(self, u, exprs, key: str) -> None:
        """``u`` = the expressions in x, y, z (one per component)."""
        if len(exprs) != self.gdim:
            self._fail(key, f"expected {self.gdim} expressions, got {len(exprs)}")
        x = ufl.SpatialCoordinate(self._mesh)
        y = ufl.as_vector([x[i] for i in range(self.gdim)])
        # a zero Constant on the mesh: UFL folds 0 * x away, and an expression of constants
        # alone (a uniform field) would have no domain to interpolate on
        zero = dolfinx.fem.Constant(self._mesh, 0.0)
        values = [e(y) + zero * x[0] for e in exprs]
        u.interpolate(_compat.expression(ufl.as_vector(values), u.function_space))

    def density_field(self, mesh):
        """Each body's density as a DG0 field when they differ (None: one density)."""
        if len({b.material.density for b in self.spec.bodies}) < 2:
            return None
        return self._per_body(mesh, [b.material.density for b in self.spec.bodies])

    def initial_velocity(self, v) -> None:
        """``dynamics.initial_velocity``: per body, its vector on the body's cells (a node
        shared by two bodies takes the later body's), or a field of expressions in x, y, z."""
        dyn = self.spec.dynamics
        if dyn is None:
            return
        if dyn.velocity_field is not None:
            self._interpolate(v, dyn.velocity_field, "dynamics.initial_velocity")
            return
        tags = dict(zip((b.group for b in self.spec.bodies), self.body_tags, strict=True))
        for group, value in dyn.velocity.items():
            cells = self.cell_tags.indices[self.cell_tags.values == tags[group]]
            v.interpolate(_constant(value), cells)
        v.x.scatter_forward()

    def _per_body(self, mesh, values: list[float]):
        """A DG0 field with each body's value on its cells."""
        DG0 = _compat.function_space(mesh, "DG", 0)
        f = dolfinx.fem.Function(DG0)
        for tag, value in zip(self.body_tags, values, strict=True):
            cells = self.cell_tags.indices[self.cell_tags.values == tag]
            f.x.array[[DG0.dofmap.cell_dofs(c)[0] for c in cells]] = value
        f.x.scatter_forward()
        return f

    def _facet_points(self, mesh, facets: np.ndarray) -> np.ndarray:
        """(m, vertices per facet, gdim) vertex coordinates of this rank's ``facets``."""
        tdim, fdim = mesh.topology.dim, mesh.topology.dim - 1
        for a, b in ((fdim, 0), (fdim, tdim), (tdim, 0)):
            mesh.topology.create_connectivity(a, b)
        f2v = mesh.topology.connectivity(fdim, 0)
        f2c = mesh.topology.connectivity(fdim, tdim)
        c2v = mesh.topology.connectivity(tdim, 0)
        V = _compat.function_space(mesh, "Lagrange", 1)
        X = _compat.dof_coordinates(V)[:, : self.gdim]
        out = []
        for f in facets:
            c = f2c.links(f)[0]
            dofs, verts = V.dofmap.cell_dofs(c), c2v.links(c)
            out.append(X[[dofs[np.flatnonzero(verts == v)[0]] for v in f2v.links(f)]])
        return np.array(out).reshape(-1, fdim + 1, self.gdim)

    def _facet_size(self, mesh, facet_tags, tags: list[int]) -> float:
        """The longest edge of the facets of the groups ``tags`` (all ranks)."""
        pts = self._facet_points(mesh, facet_tags.indices[np.isin(facet_tags.values, tags)])
        n = pts.shape[1]
        edges = [np.linalg.norm(pts[:, i] - pts[:, j], axis=1) for i in range(n) for j in range(i)]
        h = float(np.max(edges, initial=0.0)) if edges else 0.0
        return mesh.comm.allreduce(h, op=MPI.MAX)

    def _bodies_touching(self, mesh, facet_tags, tag: int) -> list[str]:
        """The bodies (group names, file order) whose cells the facet group ``tag`` bounds,
        on any rank."""
        tdim = mesh.topology.dim
        mesh.topology.create_connectivity(tdim - 1, tdim)
        f2c = mesh.topology.connectivity(tdim - 1, tdim)
        cell_body = dict(zip(self.cell_tags.indices, self.cell_tags.values, strict=True))
        facets = facet_tags.indices[facet_tags.values == tag]
        local = {int(cell_body.get(int(c), -1)) for f in facets for c in f2c.links(f)}
        found = set().union(*mesh.comm.allgather(local))
        return [
            b.group for b, t in zip(self.spec.bodies, self.body_tags, strict=True) if t in found
        ]

    # -- reactions -----------------------------------------------------------------------
    def on_step(self, problem, solver, load: float, quantities) -> None:
        """The step's contact force, the probes, and the reaction force of each group of
        ``output.reactions``: the force the supports exert on the body there, per component,
        the full model's like the contact force (``Scene.force_symmetry``: ``symmetry`` times
        the model's, 0 along the normal of a mirror plane and, axisymmetric, along r).
        At a solution f_int(u) - f_ext + F_c(u) = R, nonzero on the supported dofs only
        (ContactSNES.reactions); R is summed over the group's owned dofs. (The condensed
        mortar rewrites the rows of the slave nodes: a support sharing nodes with a mortar
        slave surface would not be reported right.)"""
        row = {"load": load, "contact_force": quantities.force}
        self._probe(problem, row)
        if not self.spec.output.reactions:
            self.reaction_rows.append(row)
            return
        r = solver.reactions()
        # the full model's force vector: axisymmetric, the residual is per radian and the
        # axial total over the circumference 2 pi times it, while the radial forces all
        # around sum to zero (not Abaqus's CAX convention, the sum of their magnitudes)
        tags = {g: self.groups[g].tag for g in self.spec.output.reactions}
        full = self.force_symmetry(self.gdim)
        forces = reaction_forces(problem.V, self._facet_tags, tags, r, full)
        for g, force in forces.items():
            for c in range(self.gdim):
                row[f"{g}_{AXES[c]}"] = float(force[c])
        r.destroy()
        self.reaction_rows.append(row)

    def _probe(self, problem, row: dict) -> None:
        """The displacement at the probe points (NaN outside the mesh), interpolated into a
        discontinuous space of the displacement's degree, so that near an interface it is
        the total displacement u + H a of the side whose cell holds the point."""
        if not self.spec.output.probes:
            return
        if not hasattr(self, "_probe_fn"):
            space = _compat.function_space(problem.mesh, "DG", problem.num.degree, (self.gdim,))
            self._probe_fn = dolfinx.fem.Function(space)
            disp = getattr(problem, "w", None)
            if disp is None:
                disp = problem.U
            self._probe_expr = _compat.expression(
                ufl.as_vector([disp[i] for i in range(self.gdim)]), space
            )
        self._probe_fn.interpolate(self._probe_expr)
        values = _compat.point_values(self._probe_fn, np.asarray(self.spec.output.probes, float))
        for i, v in enumerate(values):
            for c in range(self.gdim):
                row[f"probe{i}_u{AXES[c]}"] = float(v[c])


class FileObstacleScene(_FileMesh, ObstacleScene):
    """A problem file with a rigid obstacle."""

    def build_mesh(self, comm):
        mesh, facet_tags = self.read_mesh(comm)
        ob = self.spec.obstacle
        self.contact_tag = self.tag("obstacle.contact", ob.contact, self.gdim - 1)
        for shape, dim, other in (
            ("circle", 2, "sphere"),
            ("cylinder", 2, "sphere"),
            ("parabola", 2, "paraboloid"),
            ("sphere", 3, "circle"),
            ("paraboloid", 3, "parabola"),
        ):
            if ob.shape == shape and self.gdim != dim:
                self._fail(
                    "obstacle.shape", f"{shape} is a {dim}D obstacle (in {5 - dim}D: {other})"
                )
        if ob.shape in ("sinusoid", "punch") and self.gdim == 1:
            self._fail("obstacle.shape", f"{ob.shape} needs a 2D or 3D problem")
        r = Reader(self.spec.path)
        zero = [0.0] * self.gdim
        given = (zero if v is None else v for v in (ob.position, ob.motion))
        self.position, self.motion = (
            r.vector(v, f"obstacle.{k}", self.gdim)
            for v, k in zip(given, ("position", "motion"), strict=True)
        )
        if ob.path is not None and len(ob.path[0]) != self.gdim + 1:
            self._fail(
                "obstacle.path", f"expected rows [load factor, {self.gdim} offset components]"
            )
        self._h = ob.h or self._facet_size(mesh, facet_tags, [self.contact_tag])
        if not self._h > 0.0:
            self._fail(
                "obstacle.h",
                "the contact facets have no size (a 1D problem): give the element size h",
            )
        if len(self.spec.bodies) > 1 and len({b.material.nu for b in self.spec.bodies}) > 1:
            self._fail(
                "bodies",
                "bodies of different nu against an obstacle are not supported (one nu, E per body)",
            )
        # the modulus of the body at the contact surface (the largest, if several touch)
        moduli = self.spec.materials
        touching = self._bodies_touching(mesh, facet_tags, self.contact_tag) or list(moduli)
        self._contact_E = max(moduli[g].E for g in touching)
        return mesh, facet_tags

    def material(self) -> Elastic:
        return self.spec.bodies[0].material

    def modulus(self, mesh):
        if len(self.spec.bodies) == 1:
            return None
        return self._per_body(mesh, [b.material.E for b in self.spec.bodies])

    def contact_modulus(self) -> float:
        """The modulus of the body at the contact surface (the largest, if several touch)."""
        return self._contact_E

    def obstacle(self) -> Obstacle:
        ob = self.spec.obstacle
        if ob.shape == "plane":
            return HalfSpace(0.0)
        if ob.shape == "floor":  # the plane below its body, through position
            return Floor(0.0)
        if ob.shape == "distance":
            return DistanceObstacle(ob.distance)
        if ob.shape in ("parabola", "paraboloid"):
            return Paraboloid(ob.radius)
        if ob.shape == "sinusoid":
            return Sinusoid(ob.height, ob.wavelength)
        if ob.shape == "punch":
            return FlatPunch(ob.radius, ob.edge_radius)
        return Ball(ob.radius)

    def obstacle_offset(self, t: float, gdim: int) -> np.ndarray:
        ob = self.spec.obstacle
        if ob.path is not None:
            rows = np.asarray(ob.path)
            moved = np.array([np.interp(t, rows[:, 0], rows[:, 1 + i]) for i in range(gdim)])
            return self.position + moved
        return self.position + self.motion * amplitude_at(ob.amplitude, t)


class FileTwoBodyScene(_FileMesh, TwoBodyScene):
    """A problem file with a contact pair between two bodies, each of its own material: the
    problem is finite strain when either is hyperelastic, and a linear body then keeps its
    small-strain stress (:mod:`contactfx.driver.two_body`), which the summary notes."""

    def __init__(self, problem: ProblemFile) -> None:
        super().__init__(problem)
        linear = [b.group for b in problem.bodies if not b.material.finite_strain]
        if linear and len(linear) < len(problem.bodies):
            self.summary += (
                f"; small strain in the linear body {', '.join(linear)} (exact for "
                "translations, not objective under large rotations: run.json's "
                "linear_body_rotation)"
            )

    def build_mesh(self, comm):
        mesh, facet_tags = self.read_mesh(comm)
        pair = self.spec.pair
        fdim = self.gdim - 1
        self._slave = self.tag("contact.0.slave", pair.slave, fdim)
        self._master = self.tag("contact.0.master", pair.master, fdim)
        self.cells = {b.group: t for b, t in zip(self.spec.bodies, self.body_tags, strict=True)}
        contact = [self._slave, self._master]
        self._h = pair.h or self._facet_size(mesh, facet_tags, contact)
        bodies = self._bodies_touching(mesh, facet_tags, self._slave)
        if len(bodies) != 1:
            self._fail(
                "contact.0.slave",
                f"the surface must bound one body, it bounds {sorted(bodies) or 'none'}",
            )
        self._slave_body = bodies[0]
        self._master_bodies = self._bodies_touching(mesh, facet_tags, self._master)
        return mesh, facet_tags

    # (before the mesh is read the tags are unknown; the file's names were checked distinct)
    @property
    def slave_tag(self) -> int:
        return getattr(self, "_slave", -1)

    @property
    def master_tag(self) -> int:
        return getattr(self, "_master", -2)

    @property
    def slave_is_upper(self) -> bool:
        """Whether the pair's force vector (the friction's tangential force, pair_forces.csv)
        is reported on the slave body: ``contact.force_on`` names that body (default the
        slave's)."""
        on = self.spec.pair.force_on
        return on is None or on == getattr(self, "_slave_body", on)

    def materials(self) -> dict[str, Elastic]:
        return self.spec.materials

    def material(self) -> Elastic:
        """The slave body's material: it scales the methods' parameters (gamma_N = gamma0 E /
        h, the penalty), as the surface whose traction the method discretises (the stiffest
        body's before the mesh is read)."""
        slave = getattr(self, "_slave_body", None)
        if slave is not None:
            return self.materials()[slave]
        return max((b.material for b in self.spec.bodies), key=lambda m: m.E)

    def interference(self) -> str | None:
        """``contact.interference``: how an initial overlap of the pair is taken."""
        return self.spec.pair.interference

    def smoothing(self) -> str:
        """``contact.smoothing``: the gap between the smoothed surfaces or the facets."""
        return self.spec.pair.smoothing

    def pair_modulus(self) -> float:
        """E* of the slave body and the master surface's body (the stiffest if it bounds
        several)."""
        m = self.materials()
        slave = m[self._slave_body]
        master = max((m[b] for b in self._master_bodies), key=lambda e: e.E, default=slave)
        return 1.0 / sum((1.0 - e.nu**2) / e.E for e in (slave, master))

    def contact_edge_rule(self) -> str | None:
        """The rule ``contact.edge`` (:func:`contact_edge`), else None (the measure rule of
        ``output.contact_size``)."""
        return self.spec.pair.edge

    def edge_ring(self) -> float | None:
        return self.spec.pair.edge_ring


class FileInterfaceScene(_FileMesh, InterfaceScene):
    """A problem file with a straight fitted interface (a crack, a fracture with fluid
    pressure) on an interior facet group of one body, in 2D. The interface's line, its sides
    and its tips (the group's end points that are not on the body's boundary) are read from
    the mesh; ``crack_volume`` reports the integral of the opening along it.

    The frame of the interface coordinate s = (x - origin) . direction (the proppant zone, the
    profiles) and the side sign (the + side is the one the normal (-d_y, d_x) points to) are
    ``interface.origin`` and ``interface.direction`` when given, else the centre of the group's
    points and their principal direction (of arbitrary sign). ``interface.h``, when given, is
    the element size that scales the methods' parameters, else the longest interface edge.
    ``[[pins]]`` fix components at mesh vertices (removing the rigid motions of a plate held
    by tractions only)."""

    def build_mesh(self, comm):
        mesh, facet_tags = self.read_mesh(comm)
        if self.gdim != 2:
            self._fail("interface", "interfaces in problem files are 2D (plane strain) for now")
        self.interface_tag = self.tag("interface.group", self.spec.interface.group, 1)
        segments = self._segments(mesh, facet_tags, [self.interface_tag])
        pts = segments.reshape(-1, 2)
        lo, hi = mesh.geometry.x[:, :2].min(axis=0), mesh.geometry.x[:, :2].max(axis=0)
        lo = np.min(comm.allgather(lo), axis=0)
        hi = np.max(comm.allgather(hi), axis=0)
        self._length = float(np.linalg.norm(hi - lo))
        centre = pts.mean(axis=0)
        _, _, vt = np.linalg.svd(pts - centre)
        spec = self.spec.interface
        self._origin = centre if spec.origin is None else spec.origin
        self._dir = vt[0] if spec.direction is None else spec.direction
        self._normal = np.array([-self._dir[1], self._dir[0]])
        off = np.abs((pts - centre) @ np.array([-vt[0][1], vt[0][0]])).max()
        if off > 1e-8 * self._length:
            self._fail(
                "interface.group",
                f"the group '{spec.group}' is not "
                f"straight ({off:.3g} off its line): curved interfaces are not offered "
                "yet",
            )
        given = [k for k in ("origin", "direction") if getattr(spec, k) is not None]
        off = np.abs((pts - self._origin) @ self._normal).max()
        if given and off > 1e-8 * self._length:
            self._fail(
                f"interface.{given[-1]}",
                f"the group '{spec.group}' is {off:.3g} "
                "off the line through interface.origin along interface.direction",
            )
        tol = 1e-9 * self._length
        keys = np.round(pts / tol).astype(np.int64)
        uniq, count = np.unique(keys, axis=0, return_counts=True)
        ends = uniq[count == 1] * tol
        fdim = mesh.topology.dim - 1
        mesh.topology.create_connectivity(fdim, mesh.topology.dim)
        exterior = _compat_exterior(mesh)
        outer = self._segments(mesh, None, exterior).reshape(-1, 2)
        self._tips = [e for e in ends if not np.any(np.linalg.norm(outer - e, axis=1) < 1e3 * tol)]
        self._h = spec.h or self._facet_size(mesh, facet_tags, [self.interface_tag])
        self._check_pins(mesh, tol)
        return mesh, facet_tags

    def _check_pins(self, mesh, tol: float) -> None:
        """Every pin is a mesh vertex (of some rank)."""
        x = mesh.geometry.x[:, : self.gdim]
        for i, pin in enumerate(self.spec.pins):
            point = pin.point
            found = bool(len(x)) and float(np.min(np.linalg.norm(x - point, axis=1))) < tol
            if not mesh.comm.allreduce(found, op=MPI.LOR):
                self._fail(
                    f"pins.{i}.point",
                    f"{point.tolist()} is not a vertex of the mesh {self.spec.mesh.label}",
                )

    def _segments(self, mesh, facet_tags, selection) -> np.ndarray:
        """(m, 2, gdim) vertex coordinates of the facets (of the groups ``selection``, or the
        facet indices ``selection`` when facet_tags is None) of every rank."""
        facets = (
            selection
            if facet_tags is None
            else facet_tags.indices[np.isin(facet_tags.values, selection)]
        )
        local = self._facet_points(mesh, facets)
        # ghost facets appear on two ranks: keep each facet once
        every = np.concatenate(mesh.comm.allgather(local))
        keys = np.round(np.sort(every.reshape(len(every), -1), axis=1) * 1e9).astype(np.int64)
        _, first = np.unique(keys, axis=0, return_index=True)
        return every[np.sort(first)]

    def length_scale(self) -> float:
        return self._length

    def supports(self):
        return [(self.groups[b.group].tag, c) for b in self.spec.boundary for c in b.fix]

    def pinned(self):
        return [(pin.point, c) for pin in self.spec.pins for c in pin.fix]

    def side(self, x):
        return self._normal[0] * (x[0] - self._origin[0]) + self._normal[1] * (
            x[1] - self._origin[1]
        )

    def tips(self):
        return list(self._tips)

    def frame(self):
        return self._origin, self._dir

    def material(self) -> Elastic:
        return self.spec.bodies[0].material

    def fluid_pressure(self):
        return self.spec.interface.fluid_pressure

    def floor(self, s):
        """A proppant layer of uniform thickness along the whole interface, or on the zone
        s0 < s < s1 of ``interface.proppant_zone`` only: its end points are unpropped (the
        zone shrunk by 1e-9 of its half-length, so that nodes placed at the ends are out)."""
        t = self.spec.interface.proppant_thickness
        if t is None:
            return None
        zone = self.spec.interface.proppant_zone
        if zone is None:
            return t + 0.0 * s
        centre, half = 0.5 * (zone[0] + zone[1]), 0.5 * (zone[1] - zone[0])
        return ufl.conditional(ufl.lt(abs(s - centre), half * (1.0 - 1e-9)), t, 0.0)

    def joint(self):
        return self.spec.interface.joint

    def extra_quantities(self, mesh, w, ds):
        """crack_volume: the integral of the opening -[w] . n+ along the interface (the + cell's
        outward normal points to the other face, so the opening is independent of which cell
        is +)."""
        dS = ufl.Measure("dS", domain=mesh, subdomain_data=self._facet_tags)
        n = ufl.FacetNormal(mesh)
        out = {"crack_volume": -ufl.dot(ufl.jump(w), n("+")) * dS(self.interface_tag)}
        # output.mean_displacement: the mean of a displacement component over a facet group
        for name, (group, comp) in self.spec.output.mean_displacement.items():
            tag = self.groups[group].tag
            one = dolfinx.fem.Constant(mesh, 1.0)
            local = dolfinx.fem.assemble_scalar(dolfinx.fem.form(one * ds(tag)))
            measure = mesh.comm.allreduce(local, op=MPI.SUM)
            out[name] = w[AXES.index(comp)] / measure * ds(tag)
        return out


def _compat_exterior(mesh) -> np.ndarray:
    """The exterior facets of this rank (local indices)."""
    return np.asarray(dolfinx.mesh.exterior_facet_indices(mesh.topology), dtype=np.int32)


def _constant(value: np.ndarray):
    """The interpolation callable of a constant vector."""

    def f(x: np.ndarray) -> np.ndarray:
        return np.tile(np.asarray(value, dtype=np.float64)[:, None], (1, x.shape[1]))

    return f
