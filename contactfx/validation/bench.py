"""``contactfx bench``: error against run time over mesh refinement, every method variant.

For each benchmark case (a scene with a closed-form reference, see ``CASES``), each method
variant (``nitsche`` = theta 1, 0, -1; ``penalty`` = three penalty parameters; ``al-uzawa``,
``al-ssn``, ``vi``), each Lagrange degree and each refinement level (every mesh size of the
scene halves per level) one run records dofs, Newton / KSP iterations, the wall time split into
mesh, compile, assembly and solve, and the errors against the closed form: force, contact
half-width a, peak pressure p0, the pressure in L2 on the contact boundary, the displacement in
L2 and H1 where an exact field exists, the flat punch's normalised pressure on |x| <= 0.8 a, and
the sliding block's gross-slip force Q = mu P.

Outputs (``--out``): ``bench.csv``, ``bench.md`` (tables and observed rates) and PNG plots per
case and error measure: error against solve wall time (assembly + solve: the just-in-time
compilation is cached between runs, so it is reported but not plotted) and error against h
with the least-squares rate. Runs under mpirun; rank 0 writes.

Optional yardsticks (issue-2 targets): ``--linear`` times one linear-elastic solve on the same
mesh; ``--speedup`` reruns every case on rank 0 alone under mpirun.
"""

from __future__ import annotations

import dataclasses
import math
import time

import numpy as np
import ufl
from mpi4py import MPI

from contactfx.contact.registry import METHODS, method_class
from contactfx.numerics import Numerics
from contactfx.params import option_name
from contactfx.results import MEASURES, measure
from contactfx.scenes.base import resized
from contactfx.solvers.dynamics import Scheme

__all__ = [
    "CASES",
    "MEASURES",
    "run_bench",
    "expand_methods",
    "method_label",
    "linear_elastic_time",
    "observed_rates",
    "parallel_ceiling",
]


@dataclasses.dataclass(frozen=True)
class BenchCase:
    """A scene with a reference, its parameter overrides, and the coarsening of level 0
    relative to the scene's default mesh (level k has mesh sizes default * coarsen / 2^k)."""

    scene: str
    params: dict
    coarsen: float
    summary: str
    #: at most this many levels with P2 (3D P2 grows fast)
    p2_levels: int = 99
    #: at most this many levels with P1 (two meshed bodies: the search and the Gauss-point
    #: coupling run in Python, a level costs about 8x the one before in 3D)
    levels: int = 99
    #: numerics overrides of the case (e.g. its friction law), under the method variant's
    numerics: dict = dataclasses.field(default_factory=dict)
    #: a case plotted with this one in common figures (error against time and h) when both ran
    beside: str | None = None


CASES: dict[str, BenchCase] = {
    "hertz2d": BenchCase("hertz2d", {}, 2.0, "Hertz cylinder, plane strain"),
    # partial slip: the stick half-width c (c / a column) converges under refinement; level 0
    # is the scene's default mesh, where c spans two elements
    "hertz2d-shift": BenchCase(
        "hertz2d",
        {"shift": 5e-4},
        1.0,
        "Hertz cylinder pressed, then sheared to Q = 0.72 mu P: partial slip, Coulomb mu 0.3 "
        "(a and p0 against frictionless Hertz: approximate, Dundurs beta = 0.29)",
        p2_levels=2,
        numerics={"friction": "coulomb", "mu": 0.3, "steps": 8},
    ),
    # level 0 has about 2e3 dofs and level 4 about 9e5 (P1)
    "hertz3d": BenchCase("hertz3d", {}, 1.4, "Hertz sphere, quarter model", p2_levels=2),
    # the sphere on its axisymmetric section (r, z): level 0 has about 700 dofs
    "hertz-axi": BenchCase("hertz-axi", {}, 2.0, "Hertz sphere, axisymmetric (r, z) section"),
    # finite strain (neo-Hookean) at a / R = 0.13 (2D) and 0.2 (3D): the errors are against
    # small-strain Hertz, which the nonlinearity leaves by about 0.1 a / R (docs/verification.md
    # section 15); the columns to read are the Newton counts and the times
    "hertz2d-finite": BenchCase(
        "hertz2d",
        {"profile": "circle", "depth": 0.024, "refine_half_width": 0.15},
        2.0,
        "Hertz cylinder, neo-Hookean, a / R = 0.13 (against small-strain Hertz)",
        numerics={"material": "neo-hookean", "steps": 2},
    ),
    "hertz3d-finite": BenchCase(
        "hertz3d",
        {"profile": "circle", "depth": 0.04, "refine_radius": 0.3},
        1.4,
        "Hertz sphere, neo-Hookean, a / R = 0.2 (against small-strain Hertz)",
        p2_levels=1,
        numerics={"material": "neo-hookean", "steps": 2},
    ),
    "westergaard-partial": BenchCase(
        "westergaard", {"mean_pressure_ratio": 0.5}, 2.0, "Westergaard, partial contact p_m = p*/2"
    ),
    "westergaard-full": BenchCase(
        "westergaard",
        {"mean_pressure_ratio": 1.5, "h_contact": 1 / 8, "h_far": 1 / 8},
        1.0,
        "Westergaard, full contact p_m = 1.5 p*, uniform mesh, exact displacement",
    ),
    "punch2d": BenchCase("punch2d", {}, 2.0, "flat rigid punch, plane strain"),
    "sliding-block": BenchCase("sliding-block", {}, 2.0, "Coulomb block dragged to gross slip"),
    "crack-sneddon": BenchCase("crack-sneddon", {}, 2.0, "pressurised crack, Sneddon opening"),
    "crack-inclined": BenchCase(
        "crack-inclined", {"beta": 45.0}, 2.0, "inclined crack, compression, Coulomb mu 0.3"
    ),
    # tau / sigma_n = tan(beta) = 5: a driving shear of 4.7 sigma_n, the tips' largest pollution
    "crack-inclined-steep": BenchCase(
        "crack-inclined",
        {"beta": math.degrees(math.atan(5.0))},
        2.0,
        "inclined crack, tau / sigma_n = 5, Coulomb mu 0.3",
    ),
    "propped-fracture": BenchCase(
        "propped-fracture",
        {"net_pressure": 1e6},
        2.0,
        "propped fracture, open branch p_net > p* (Sneddon)",
    ),
    # the same cracks on a mesh that ignores them (P1 and nitsche only; the rest: n/a), beside
    # the fitted rows above
    "crack-sneddon-unfitted": BenchCase(
        "crack-sneddon",
        {"crack": "unfitted"},
        2.0,
        "pressurised crack, unfitted, Sneddon",
        beside="crack-sneddon",
    ),
    "crack-inclined-unfitted": BenchCase(
        "crack-inclined",
        {"beta": 45.0, "crack": "unfitted"},
        2.0,
        "inclined crack, unfitted, compression, Coulomb mu 0.3",
        beside="crack-inclined",
    ),
    "crack-set": BenchCase(
        "crack-set", {}, 2.0, "three unfitted cracks under compression and shear, Coulomb"
    ),
    # level 2 is the scene's default mesh (68012 dofs with P2)
    "penny-crack": BenchCase(
        "penny-crack", {}, 4.0, "pressurised penny-shaped crack in 3D, Sneddon", p2_levels=3
    ),
    # level 2 is the default mesh (132410 dofs with P2; the bench's P2 stops at level 1)
    "fault-block": BenchCase(
        "fault-block",
        {"overpressure": 3e6},
        4.0,
        "circular fault, remote stress, fluid overpressure, Coulomb (3D)",
        p2_levels=2,
    ),
    "joint-column": BenchCase("joint-column", {}, 1.0, "Barton-Bandis joint column (exact)"),
    "patch-test": BenchCase("patch-test", {}, 1.0, "two blocks, non-matching meshes (exact)"),
    "hertz-cylinders": BenchCase("hertz-cylinders", {}, 2.0, "two elastic cylinders, Hertz"),
    # (3D P2 between two bodies: level 0 only; level 1 is ~2e5 dofs per method and degree)
    "hertz-spheres": BenchCase(
        "hertz-spheres", {}, 2.0, "two elastic spheres, quarter model", p2_levels=1, levels=2
    ),
    "cattaneo-cylinders": BenchCase(
        "cattaneo-cylinders", {}, 2.0, "identical cylinders sheared, Cattaneo-Mindlin, mu 0.3"
    ),
    # level 0 is the scene's default mesh; penalty only (two finite-strain bodies)
    "shallow-ironing": BenchCase(
        "shallow-ironing",
        {},
        1.0,
        "neo-Hookean die ironing a block, frictionless (force plateau against Yang et al. 2005)",
        p2_levels=0,
    ),
    "shallow-ironing-coulomb": BenchCase(
        "shallow-ironing",
        {},
        1.0,
        "neo-Hookean die ironing a block, Coulomb mu 0.3 (plateaus P, Q against Yang et al.)",
        p2_levels=0,
        numerics={"friction": "coulomb", "mu": 0.3},
        beside="shallow-ironing",
    ),
    # the published 3D slab: level 0 is the scene's default mesh (h_contact 0.2, 6822 dofs),
    # level 1 (24747 dofs) takes about an hour on one core
    "shallow-ironing-3d": BenchCase(
        "shallow-ironing-3d",
        {},
        1.0,
        "neo-Hookean die ironing a block, the published 3D slab, frictionless (force plateau "
        "against Yang et al. 2005)",
        p2_levels=0,
        levels=2,
    ),
    # 3D, two finite-strain bodies, Coulomb friction: no closed form; the columns to read are
    # the load steps, Newton iterations, times, memory and the equilibrium of the reactions
    # with the contact force. Level 1 is the scene's default mesh (penalty only); level 3
    # (about 100k dofs) is for --solver gamg on 2 ranks (--levels 4)
    # implicit dynamics (no closed form at the levels: the columns to read are the time and
    # Newton iterations per time step and the energy balance's largest remainder)
    "disc-drop": BenchCase(
        "disc-drop", {}, 1.0, "disc dropped on a plane, Nitsche, Newmark, t in [0, 40]"
    ),
    "sliding-stop": BenchCase(
        "sliding-stop", {}, 1.0, "block stopped by Coulomb friction (v0^2 / (2 mu g))"
    ),
    # finite strain in time: dt c / h from 0.18 to 0.7 over the levels (at 1 and more an
    # element at the contact inverts, docs/verification.md section 18)
    "disc-drop-finite": BenchCase(
        "disc-drop",
        {},
        2.0,
        "neo-Hookean disc dropped on a plane, Nitsche, Newmark, t in [0, 30]",
        numerics={"material": "neo-hookean", "dt": 0.05, "t_end": 30.0},
    ),
    # 3D in time: the quarter ball, level 2 the scene's default mesh (a level 3, h_contact
    # 0.005 and h_far 0.125, ran over 20 minutes at 4.4 GB and was stopped)
    "hertz-impact": BenchCase(
        "hertz-impact", {}, 4.0, "elastic sphere striking a rigid plane (3D), Nitsche, Newmark"
    ),
    "sphere-slide": BenchCase(
        "sphere-slide",
        {},
        2.0,
        "neo-Hookean sphere pressed 0.3 R into a block and slid 1 R, Coulomb mu 0.3 (3D)",
        p2_levels=0,
        levels=4,
    ),
}

#: relative errors below this are round-off (e.g. the force under force control): no rate
ROUNDOFF = 1e-10


def method_label(o: dict) -> str:
    """The label of a method variant given as Numerics overrides: the method with the value of
    the option that tells its variants apart (``sweep``), its other parameters given, and the
    nodal quadrature; bench and stress name their rows with it."""
    cls = method_class(o.get("method", "nitsche"))
    key, _ = cls.sweep
    label = cls.name + (f"({_short(o[key])})" if key in o else "")
    for f in dataclasses.fields(cls):
        name = option_name(f)
        if name in o and name != key:
            label += f" {name}={_short(o[name])}"
    label += " nodal" if o.get("quadrature") == "nodal" else ""
    return label + (f" nested{o['nested']}" if o.get("nested") else "")


def _short(value) -> str:
    return f"{value:g}" if isinstance(value, int | float) else str(value)


def expand_methods(spec: str) -> list[tuple[str, dict]]:
    """'nitsche,penalty@100,al-ssn' -> [(label, Numerics overrides), ...]. A method name
    expands to the values of its ``sweep`` (nitsche: theta = 1, 0, -1; penalty: three penalty
    factors; compliance: three exponents); ``name@value`` picks one value of that option (for
    the augmented Lagrangian, r0); a ``+nodal`` suffix integrates the contact terms at the
    nodes (``--quadrature nodal``); a ``+nestedN`` suffix starts every solve from N coarser
    meshes (``--nested N``)."""
    out: list[dict] = []
    for token in filter(None, (t.strip() for t in spec.split(","))):
        token, has_nested, nested = token.partition("+nested")
        token, nodal = token.removesuffix("+nodal"), token.endswith("+nodal")
        name, _, value = token.partition("@")
        if name not in METHODS:
            raise ValueError(f"unknown method '{name}' in --method (known: {', '.join(METHODS)})")
        try:
            number = float(value) if value else None
        except ValueError:
            raise ValueError(f"--method {token}: '{value}' is not a number") from None
        extra = {"quadrature": "nodal"} if nodal else {}
        if has_nested:
            if not nested.isdigit() or int(nested) < 1:
                raise ValueError(
                    f"--method {token}+nested{nested}: give the coarser levels, e.g. +nested2"
                )
            extra["nested"] = int(nested)
        key, defaults = method_class(name).sweep
        values = defaults if number is None else (number,)
        if key and values:
            kind = type(getattr(Numerics(), key))
            out += [{"method": name, key: kind(v), **extra} for v in values]
        else:
            out.append({"method": name, **extra})
    if not out:
        raise ValueError("--method: no method given")
    return [(method_label(o), o) for o in out]


def run_case(
    case_name: str,
    label: str,
    overrides: dict,
    degree: int,
    level: int,
    comm,
    petsc_options: dict | None = None,
    solver: str = "lu",
) -> tuple[dict, object, object]:
    """One bench row (and the scene and numerics it ran, for the yardsticks)."""
    from contactfx.scenes import SCENES
    from contactfx.solvers.snes import ConvergenceError

    case = CASES[case_name]
    scene_cls = SCENES[case.scene]
    params = resized(scene_cls.Params(**case.params), case.coarsen * 0.5**level)
    scene = scene_cls(params)
    row: dict = {
        "case": case_name,
        "method": label,
        "degree": degree,
        "level": level,
        "h": scene.h_contact(),
        "ranks": comm.size,
    }
    try:
        num = scene_cls.default_numerics(
            degree=degree, solver=solver, **{**case.numerics, **overrides}
        )
        scene.problem.check(scene, num, num.method_object())
    except ValueError as err:  # e.g. al-ssn or P2 between two bodies: not applicable, not failed
        row.update(status="n/a", reason=str(err))
        return row, scene, None
    try:
        res = scene.run(num, comm=comm, petsc_options=petsc_options, verbose=False)
    except (ConvergenceError, ValueError) as err:
        row.update(status="failed", reason=str(err))
        return row, scene, num
    t = res.timings
    row.update(
        status="ok",
        reason="",
        dofs=res.dofs,
        steps=len(res.steps),
        newton=res.newton_iterations,
        ksp=res.ksp_iterations,
        outer=res.outer_iterations,
        newton_coarse=sum(step.coarse_newton for step in res.steps),
        t_mesh=t["mesh"],
        t_compile=t["compile"],
        t_assembly=t["assembly"],
        t_solve=t["solve"],
        t_run=t["assembly"] + t["solve"],
        memory_mib=res.memory_mib,
    )
    if res.energy:  # a dynamic run: per time step, and its energy balance
        row["t_per_step"] = row["t_run"] / max(len(res.steps), 1)
        row["newton_per_step"] = res.newton_iterations / max(len(res.steps), 1)
        row["energy_remainder"] = float(res.energy["largest_remainder_relative"])
        if "stop_distance_rel_error" in res.reference:
            row["stop_distance_error"] = float(res.reference["stop_distance_rel_error"])
    if "contact" in t:  # two bodies: search + contact terms against bulk assembly + solve
        row["t_contact"] = t["contact"]
        row["contact_over_bulk"] = t["contact"] / max(row["t_run"] - t["contact"], 1e-12)
    for column in MEASURES:
        row[column] = measure(res, column)
    for key in ("Q_over_bound", "c_over_a_computed"):  # partial slip: values, not errors
        if key in res.reference:
            row[key] = float(res.reference[key])
    # force plateaus against published curves (shallow ironing): signed errors and values;
    # the sliding sphere's Q / (mu P) and equilibrium of the reactions with the contact force
    values = ("P_plateau_error", "Q_plateau_error", "Q_over_P", "P_jump", "Q_jump")
    values += ("Q_over_P_over_mu", "equilibrium_top", "equilibrium_bottom")
    for key in values:
        if key in res.scores:
            row[key] = float(res.scores[key])
    return row, scene, num


def observed_rates(rows: list[dict], column: str) -> tuple[float, float]:
    """Least-squares slope of log(error) against log(h) over the rows, and the rate between
    the two finest levels (nan when undefined; round-off errors are left out)."""
    pts = [(r["h"], r[column]) for r in rows if r.get("status") == "ok"]
    pts = [(h, e) for h, e in pts if np.isfinite(e) and e > ROUNDOFF]
    if len(pts) < 2:
        return float("nan"), float("nan")
    h, e = np.log(np.array(pts)).T
    fit = float(np.polyfit(h, e, 1)[0])
    last = float((e[-2] - e[-1]) / (h[-2] - h[-1]))
    return fit, last


def linear_elastic_time(
    scene, degree: int, comm, solver: str = "lu", num: Numerics | None = None
) -> tuple[float, int]:
    """Wall time of assembling and solving the scene's linear-elastic problem by the contact
    solver's wrapper with the same linear solver (MUMPS LU or GMRES + GAMG) and no contact
    terms; and its dofs. An obstacle scene's contact boundary is loaded by a uniform pressure;
    two bodies (each held by its own supports) by a uniform body force, each body with its
    small-strain constants. A dynamic run's (``num.dynamic``): one step's linear system, K +
    c M with the mass factor c of its scheme and time step (a free body's too: the mass makes
    it regular), assembled and solved once."""
    import dolfinx

    from contactfx import _compat
    from contactfx.solvers.bulk import LinearBulk
    from contactfx.solvers.snes import GAMG_OPTIONS, ContactSNES, owned_size

    mesh, facet_tags = scene.build_mesh(comm)
    gdim = mesh.geometry.dim
    V = _compat.function_space(mesh, "Lagrange", degree, (gdim,))
    du, v = ufl.TrialFunction(V), ufl.TestFunction(V)
    ds = ufl.Measure("ds", domain=mesh, subdomain_data=facet_tags)
    if hasattr(scene, "contact_tag"):
        material = scene.material()
        L = dolfinx.fem.form(-1.0 * v[gdim - 1] * ds(scene.contact_tag))
    else:  # two bodies: their supports' constants (the driven ones at load 0), E per body
        scene.make_constants(mesh)
        material = scene.body_material(mesh)
        L = dolfinx.fem.form(-1.0 * v[gdim - 1] * ufl.dx)
    a = ufl.inner(material.sigma(du), ufl.sym(ufl.grad(v))) * ufl.dx
    if num is not None and num.dynamic:
        c = Scheme.named(num.scheme, num.rho_inf).mass_factor(num.dt)
        a = a + c * material.density * ufl.inner(du, v) * ufl.dx
    a = dolfinx.fem.form(a)
    bcs = scene.dirichlet(V, facet_tags)
    comm.barrier()
    t0 = time.perf_counter()
    linear = ContactSNES(
        dolfinx.fem.Function(V),
        bulk=LinearBulk(stiffness=a, load=L),
        bcs=bcs,
        prefix="contactfx_linear_",
        near_nullspace=solver == "gamg",
        options=GAMG_OPTIONS if solver == "gamg" else {},
    )
    linear.assemble_load()
    linear.solve_linear(np.ones(owned_size(V), dtype=bool))
    comm.barrier()
    elapsed = time.perf_counter() - t0
    linear.destroy()
    return elapsed, V.dofmap.index_map.size_global * V.dofmap.index_map_bs


def parallel_ceiling(comm, n: int = 3_000_000, repeats: int = 3) -> float:
    """Speed-up this machine's ranks give at all: the same NumPy work on rank 0 alone, then
    on every rank at once (each rank does the full work; ideal = 1 x time of one)."""

    def work() -> float:
        x = np.linspace(0.0, 1.0, n)
        t0 = time.perf_counter()
        for _ in range(repeats):
            np.sqrt(x * x + 1.0).sum()
        return time.perf_counter() - t0

    comm.barrier()
    alone = work() if comm.rank == 0 else 0.0
    comm.barrier()
    together = comm.allreduce(work(), op=MPI.MAX)
    alone = comm.bcast(alone, root=0)
    return comm.size * alone / together


def run_bench(
    cases: list[str],
    variants: list[tuple[str, dict]],
    degrees: list[int],
    levels: int,
    comm,
    petsc_options: dict,
    *,
    solver: str = "lu",
    linear: bool = False,
    speedup: bool = False,
    repeat: int = 1,
) -> list[dict]:
    """Every case x variant x degree x level; one row each (printed on rank 0 as it ends).
    With ``repeat`` > 1 every timed run (and the linear yardstick) is repeated and its
    shortest time kept: the least disturbed by other work on the machine."""
    ceiling = parallel_ceiling(comm) if speedup and comm.size > 1 else 1.0
    rows: list[dict] = []
    for case_name in cases:
        case = CASES[case_name]
        for label, overrides in variants:
            for degree in degrees:
                n = min(levels, case.levels if degree == 1 else case.p2_levels)
                for level in range(n):
                    row, scene, num = run_case(
                        case_name, label, overrides, degree, level, comm, petsc_options, solver
                    )
                    for _ in range(repeat - 1 if row["status"] == "ok" else 0):
                        again = run_case(
                            case_name, label, overrides, degree, level, comm, petsc_options, solver
                        )[0]
                        if again["status"] == "ok" and again["t_run"] < row["t_run"]:
                            row = again
                    # the yardstick: obstacle scenes and two bodies (not the interfaces)
                    yardstick = hasattr(scene, "contact_tag") or hasattr(scene, "body_material")
                    if row["status"] == "ok" and linear and yardstick:
                        lin = min(
                            linear_elastic_time(scene, degree, comm, solver, num)[0]
                            for _ in range(repeat)
                        )
                        row["t_linear"] = lin
                        if "t_per_step" in row:  # in time: a step against one K + c M solve
                            row["step_over_linear"] = row["t_per_step"] / lin
                        else:
                            row["contact_over_linear"] = row["t_run"] / lin
                        # one Newton iteration (its assembly, contact terms and solve)
                        newton = max(int(row["newton"]), 1)
                        row["newton_over_linear"] = row["t_run"] / newton / lin
                    if row["status"] == "ok" and speedup and comm.size > 1:
                        _add_speedup(row, scene, num, comm, ceiling)
                    rows.append(row)
                    if comm.rank == 0:
                        print(_format_row(row), flush=True)
                    if row["status"] == "n/a":
                        break  # the same at every level
    if speedup and comm.size > 1 and comm.rank == 0:
        print(f"parallel ceiling of this machine with {comm.size} ranks: {ceiling:.2f}x")
    return rows


def _add_speedup(row: dict, scene, num, comm, ceiling: float) -> None:
    serial = None
    if comm.rank == 0:
        res = scene.run(num, comm=MPI.COMM_SELF, verbose=False)
        serial = (res.timings, res.newton_iterations)
    ts, newton = comm.bcast(serial, root=0)
    row["newton_serial"] = newton
    row["speedup"] = (ts["assembly"] + ts["solve"]) / row["t_run"]
    row["speedup_over_ceiling"] = row["speedup"] / ceiling


def _format_row(row: dict) -> str:
    head = f"{row['case']:>19s} {row['method']:>14s} P{row['degree']} L{row['level']}"
    if row["status"] != "ok":
        return f"{head}  {row['status'].upper()}: {row['reason']}"
    errors = "  ".join(f"{col[4:]} {row[col]:.2e}" for col in MEASURES if math.isfinite(row[col]))
    extra = ""
    if "contact_over_linear" in row:
        extra += f"  contact/linear {row['contact_over_linear']:.2f}"
    if "step_over_linear" in row:
        extra += f"  step/linear {row['step_over_linear']:.2f}"
    if "speedup" in row:
        extra += f"  speed-up {row['speedup']:.2f} ({row['speedup_over_ceiling']:.2f} of ceiling)"
    return (
        f"{head} dofs {row['dofs']:>7d} newton {row['newton']:>3d}"
        + (f" (+{row['newton_coarse']} coarse)" if row.get("newton_coarse") else "")
        + f" ksp {row['ksp']:>4d} "
        f"time {row['t_run']:7.2f} s  mem {row['memory_mib']:6.0f} MiB  {errors}{extra}"
    )
