"""Interference fits (``[[contact]] interference = "ramp"``): two concentric rings shrunk one
onto the other, against Lame's closed form, for every two-body method."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from mpi4py import MPI

from contactfx import _compat
from contactfx.scenes.problem_file import FileTwoBodyScene, load_problem

#: the rings: inner a < b, outer b - DELTA < c (radial interference DELTA), E, nu
A, B, C, DELTA, E, NU = 1.0, 1.5, 2.0, 0.005, 1000.0, 0.3

RINGS_GEO = """
a = 1.0; b = 1.5; c = 2.0; d = DELTA; hi = HI; ho = HO;
Point(1) = {0, 0, 0};
Point(2) = {a, 0, 0, hi}; Point(3) = {b, 0, 0, hi}; Point(4) = {0, b, 0, hi};
Point(5) = {0, a, 0, hi};
Line(1) = {2, 3}; Circle(2) = {3, 1, 4}; Line(3) = {4, 5}; Circle(4) = {5, 1, 2};
Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};
Point(12) = {b - d, 0, 0, ho}; Point(13) = {c, 0, 0, ho}; Point(14) = {0, c, 0, ho};
Point(15) = {0, b - d, 0, ho};
Line(11) = {12, 13}; Circle(12) = {13, 1, 14}; Line(13) = {14, 15}; Circle(14) = {15, 1, 12};
Curve Loop(2) = {11, 12, 13, 14}; Plane Surface(2) = {2};
Physical Surface("inner") = {1};
Physical Surface("outer") = {2};
Physical Curve("inner_out") = {2};
Physical Curve("outer_in") = {14};
Physical Curve("sym_x") = {3, 13};
Physical Curve("sym_y") = {1, 11};
"""

RINGS_TOML = """
title = "shrink-fit"
[mesh]
file = "rings.geo"
[[bodies]]
group = "inner"
E = 1000.0
nu = 0.3
[[bodies]]
group = "outer"
E = 1000.0
nu = 0.3
[[boundary]]
group = "sym_x"
fix = ["x"]
[[boundary]]
group = "sym_y"
fix = ["y"]
[[contact]]
slave = "outer_in"
master = "inner_out"
interference = "ramp"
[numerics]
method = "mortar"
steps = 2
"""


def lame_pressure(E: float, nu: float, a: float, b: float, c: float, delta: float) -> float:
    """The contact pressure of a shrink fit in plane strain (equal E, nu).

    Each ring carries u_r = A r + B / r (the radial Navier equation d/dr (d(r u)/dr / r) = 0).
    Plane strain: sigma_r = (lambda + 2 mu) u' + lambda u / r = 2 (lambda + mu) A - 2 mu B / r^2
    = C1 - C2 / r^2 with C1 = 2 (lambda + mu) A, C2 = 2 mu B, and

        2 (lambda + mu) = E / ((1 + nu) (1 - 2 nu)),   2 mu = E / (1 + nu).

    Inner ring, sigma_r(a) = 0, sigma_r(b) = -p: C2 = -p a^2 b^2 / (b^2 - a^2), C1 = C2 / a^2,
    so u_i(b) = C1 b / (2 (lambda + mu)) + C2 / (2 mu b)
             = -p b (1 + nu) ((1 - 2 nu) b^2 + a^2) / (E (b^2 - a^2)).
    Outer ring, sigma_r(b) = -p, sigma_r(c) = 0: C2 = p b^2 c^2 / (c^2 - b^2), C1 = C2 / c^2,
    so u_o(b) = p b (1 + nu) ((1 - 2 nu) b^2 + c^2) / (E (c^2 - b^2)).
    The fit closes the interference, u_o(b) - u_i(b) = delta; over the common denominator
    (c^2 - b^2)(b^2 - a^2) the numerator is
    ((1 - 2 nu) b^2 + c^2)(b^2 - a^2) + ((1 - 2 nu) b^2 + a^2)(c^2 - b^2)
    = (1 - 2 nu) b^2 (c^2 - a^2) + b^2 (c^2 - a^2) = 2 (1 - nu) b^2 (c^2 - a^2), so

        p = E delta (c^2 - b^2)(b^2 - a^2) / (2 (1 - nu^2) b^3 (c^2 - a^2)),

    the plane-stress formula with E / (1 - nu^2) for E (the same steps with the plane-stress
    2 (lambda* + mu) = E / (1 - nu) give 2 b^2 (c^2 - a^2) for the numerator)."""
    return E * delta * (c**2 - b**2) * (b**2 - a**2) / (2 * (1 - nu**2) * b**3 * (c**2 - a**2))


def lame_rings(
    E: float, nu: float, a: float, b_in: float, b_out: float, c: float, delta: float
) -> tuple[float, float]:
    """(the pressure on the outer ring's bore, on the inner ring's surface) from the four
    boundary and interface conditions on u_r = A r + B / r of each ring, solved as a linear
    system with the plane-strain Hooke law (no closed form used): sigma_r(a) = 0,
    sigma_r(c) = 0, the interference closed, u_o(b_out) - u_i(b_in) = delta, and the radial
    force balance b_out sigma_o(b_out) = b_in sigma_i(b_in). With b_in = b_out = b it checks
    :func:`lame_pressure`; with the meshed radii b_in = b, b_out = b - delta it is the small-
    strain solution of the meshed geometry (what the finite elements converge to)."""
    lam = E * nu / ((1 + nu) * (1 - 2 * nu))
    mu = E / (2 * (1 + nu))

    def sigma(r: float) -> list[float]:
        return [2 * (lam + mu), -2 * mu / r**2]

    def u(r: float) -> list[float]:
        return [r, 1 / r]

    M = np.array(
        [
            sigma(a) + [0.0, 0.0],
            [0.0, 0.0] + sigma(c),
            [-x for x in u(b_in)] + u(b_out),
            [-b_in * x for x in sigma(b_in)] + [b_out * x for x in sigma(b_out)],
        ]
    )
    coef = np.linalg.solve(M, [0.0, 0.0, delta, 0.0])
    return -float(np.dot(sigma(b_out), coef[2:])), -float(np.dot(sigma(b_in), coef[:2]))


def test_lame_pressure_checked_independently():
    """The closed form against the linear solve of the rings' conditions (:func:`lame_rings`)
    and, in plane stress (lambda* = 2 lambda mu / (lambda + 2 mu)), the textbook formula
    p = E delta / b (c^2 - b^2)(b^2 - a^2) / (2 b^2 (c^2 - a^2))."""
    p = lame_pressure(E, NU, A, B, C, DELTA)
    assert lame_rings(E, NU, A, B, B, C, DELTA) == pytest.approx((p, p), rel=1e-12)
    # plane stress is plane strain with E' = E (1 + 2 nu) / (1 + nu)^2, nu' = nu / (1 + nu)
    Es, nus = E * (1 + 2 * NU) / (1 + NU) ** 2, NU / (1 + NU)
    stress = E * DELTA / B * (C * C - B * B) * (B * B - A * A) / (2 * B * B * (C * C - A * A))
    assert lame_rings(Es, nus, A, B, B, C, DELTA)[0] == pytest.approx(stress, rel=1e-12)


class Rings(FileTwoBodyScene):
    """Records the slave nodes' pressures and weights of the last step (all ranks, by the
    nodes' angle)."""

    def on_step(self, problem, solver, load, quantities) -> None:
        super().on_step(problem, solver, load, quantities)
        nodes, D, p, _ = problem.coupling().nodal()
        comm, lay = problem.mesh.comm, problem.layout
        x = lay.X.getArray().reshape(-1, lay.gdim)[(nodes - lay.start).astype(np.int64)]
        # ordered by the angle (the same on every partition)
        order = np.argsort(np.concatenate(comm.allgather(np.arctan2(x[:, 1], x[:, 0]))))
        self.D = np.concatenate(comm.allgather(D))[order]
        self.pressure = np.concatenate(comm.allgather(p))[order]

    @property
    def mean_pressure(self) -> float:
        """The nodal pressure's weighted mean, sum D_j p_j / sum D_j."""
        return float(np.sum(self.D * self.pressure) / np.sum(self.D))


def _rings(folder: Path, h: float, toml: str = RINGS_TOML) -> Path:
    """The quarter rings (rollers on both symmetry planes), the bore's side (the slave) of
    element size h, the inner ring's 0.7 h."""
    path = folder / "rings.toml"
    if MPI.COMM_WORLD.rank == 0:
        geo = RINGS_GEO.replace("DELTA", repr(DELTA)).replace("HI", repr(0.7 * h))
        (folder / "rings.geo").write_text(geo.replace("HO", repr(h)))
        path.write_text(toml)
    MPI.COMM_WORLD.barrier()
    return path


#: mortar's gap between the smoothed surfaces (``contact.smoothing``), and between the facets
SMOOTH = ["contact.0.smoothing=normals"]
FACETS = ["contact.0.smoothing=none"]


def _solve(path: Path, sets=(), comm=MPI.COMM_WORLD):
    loaded, numerics, petsc = load_problem(path, list(sets))
    scene = Rings(loaded.spec)
    res = scene.run(numerics, comm=comm, petsc_options=petsc, verbose=False)
    return scene, res


@pytest.fixture
def shared_tmp(tmp_path):
    """One temporary folder for all ranks (rank 0's)."""
    return Path(MPI.COMM_WORLD.bcast(str(tmp_path), root=0))


#: the mean nodal pressure's error from the closed form at h = 0.05 and 0.025, measured
#: (mortar, nitsche, penalty): 1.02 / 0.98 %, 2.76 / 1.38 %, 2.71 / 1.35 % (Nitsche and penalty
#: 1.06 %, 1.05 % at h = 0.0125); the meshed geometry's own solution (the bore at b - delta) is
#: 0.97 % above the closed form, and the errors from it fall by 4.0 to 4.9 per halving
#: (O(h^2)). Mortar with the gap between the smoothed surfaces (``smoothing = "normals"``,
#: :mod:`contactfx.contact.smoothing`): 0.055 % and 0.013 % from the meshed geometry's
#: solution (2.50 / 1.34 % from the closed form with the facets' gap, ``smoothing = "none"``; the
#: default, ``auto``, smooths this conforming pair)
MEASURED = {"mortar": (0.0102, 0.0098), "nitsche": (0.0276, 0.0138), "penalty": (0.0271, 0.0135)}


@pytest.mark.parametrize("method", ["mortar", "nitsche", "penalty"])
def test_shrink_fit_rings_against_lame(shared_tmp, method):
    """Two concentric rings with a radial interference delta = 0.005 (b = 1.5: the overlap is
    10 times the tolerance at the start), the overlap ramped out over two load steps: the
    mean nodal pressure of each two-body method against Lame's closed form at two meshes
    (h = 0.05, 0.025 on the bore; MEASURED), and against the small-strain solution of the
    meshed geometry (the bore at b - delta, 0.97 % above the closed form): its error falls as
    h^2 (by 4.2, 4.4 and 4.6 from h = 0.05 to 0.025, measured). Mortar's mean within 2 % at
    the finer mesh (the issue's target) and every node's within 2 % (measured +0.5 % to
    +1.4 % of p: the meshed geometry's +0.97 % and +-0.5 % about it)."""
    p = lame_pressure(E, NU, A, B, C, DELTA)
    meshed = lame_rings(E, NU, A, B, B - DELTA, C, DELTA)[0]
    errors, to_meshed = [], []
    # mortar's gap between the smoothed surfaces (test_mortar_pressure_smooth_whichever_side)
    sets = [f"numerics.method={method}"] + SMOOTH * (method == "mortar")
    for h in (0.05, 0.025):
        scene, res = _solve(_rings(shared_tmp, h), sets)
        errors.append(scene.mean_pressure / p - 1.0)
        to_meshed.append(abs(scene.mean_pressure / meshed - 1.0))
        # the quarter's force on the bore: p b_out pi / 2 within the same errors
        assert res.force == pytest.approx(scene.mean_pressure * (B - DELTA) * np.pi / 2, rel=2e-3)
    coarse, fine = MEASURED[method]
    assert errors[0] == pytest.approx(coarse, abs=2e-3)
    assert errors[1] == pytest.approx(fine, abs=1e-3)
    assert abs(errors[1]) < 0.02
    assert to_meshed[1] < 0.005 and to_meshed[0] / to_meshed[1] > 3.5
    if method == "mortar":
        assert np.all(np.abs(scene.pressure / p - 1.0) < 0.02)


#: the rings with the inner ring's surface (the finer, convex side) as mortar's slave
SWAPPED = RINGS_TOML.replace(
    'slave = "outer_in"\nmaster = "inner_out"', 'slave = "inner_out"\nmaster = "outer_in"'
)


@pytest.mark.parametrize("slave", ["bore", "inner"])
def test_mortar_pressure_smooth_whichever_side_is_slave(shared_tmp, slave):
    """Mortar's nodal pressure on the curved non-matching interface with either side as the
    slave (the bore: the coarser, concave side; the inner ring: the finer, convex side, 0.7 h),
    against the meshed geometry's solution (:func:`lame_rings`: the pressure on the slave's
    own radius, b - delta for the bore, b for the inner ring; 0.97 % and 0.63 % above Lame's
    closed form).

    The cause of the side's effect (:mod:`contactfx.contact.smoothing`): both surfaces are
    polygons of the circles, whose chords cut them by up to L^2 / (8 R); the finer side's
    nodes sink into the coarser side's chords by a gap oscillating with its element length,
    and the pressure that closes an oscillation of wavelength L is stiffer than the fit's by
    about (R / L) pi: here 1 % of delta in the gap swings the pressure by its own size. The
    gap between the smoothed surfaces (``smoothing = "normals"``) removes it: every nodal
    pressure within 2 % of the meshed geometry's at h = 0.05 (measured -1.1 % .. +0.9 % with
    the bore as slave, -1.5 % .. +1.3 % with the inner ring; -0.4 % .. +0.4 % and -0.7 % ..
    +0.5 % at h = 0.025; the mean 0.055 % and 0.057 % from it, 0.013 % at h = 0.025), and with
    the facets' gap (``smoothing = "none"``) the finer slave's nodal pressure swings from 0 to
    3.25 times p with 36 of 69 nodes open (0.07 to 2.6 p at h = 0.025), the coarser slave's
    within -3.6 % .. +7.7 % (its nodes do not resolve the finer master's kinks)."""
    h = 0.05
    toml = RINGS_TOML if slave == "bore" else SWAPPED
    on_bore, on_inner = lame_rings(E, NU, A, B, B - DELTA, C, DELTA)
    meshed = on_bore if slave == "bore" else on_inner
    scene, smooth = _solve(_rings(shared_tmp, h, toml), SMOOTH)
    assert smooth.warnings == []
    # the default, smoothing = "auto", finds the pair conforming (mean curvatures 1 / b and
    # -1 / (b - delta) cancel to delta / b): the same run to the solver's tolerance (bit for
    # bit on one rank; two meshings of the same file may partition differently), and a note
    auto, noted = _solve(_rings(shared_tmp, h, toml))
    assert np.allclose(auto.pressure, scene.pressure, rtol=0.0, atol=1e-9 * meshed)
    (note,) = noted.warnings
    assert "smoothing = auto: a conforming pair" in note
    deviation = scene.pressure / meshed - 1.0
    assert np.all(np.abs(deviation) < 0.02)
    # the mean: the meshed geometry's to O(h^2) (measured 5.5e-4, 5.7e-4)
    assert scene.mean_pressure == pytest.approx(meshed, rel=1.5e-3)
    facets, res = _solve(_rings(shared_tmp, h, toml), FACETS)
    p = facets.pressure / meshed
    if slave == "inner":
        # the finer side's nodes on the coarser side's chords: a third or more open, and
        # the others carry the fit (measured 36 of 69 open, the largest 3.2 p); run.json
        # warns of the oscillation (the closed set in 21 pieces) and names the key
        assert np.mean(p <= 1e-9) > 0.3 and np.max(p) > 2.5
        (line,) = res.warnings
        assert "pieces along the slave surface" in line and 'smoothing = "normals"' in line
    else:
        # the coarser slave averages the finer master's kinks: no node opens, a swing of
        # about 10 % (measured -3.6 % .. +7.7 % of the meshed geometry's)
        assert np.min(p) > 0.9 and np.max(p) < 1.12


@pytest.mark.skipif(MPI.COMM_WORLD.size == 1, reason="compares the run on all ranks with one rank")
def test_shrink_fit_ranks_agree(shared_tmp):
    """Serial and parallel runs of the interference fit agree to 1e-8 (mortar, also with the
    smoothed surfaces, whose nodal normals are summed on the nodes' owners, and Nitsche)."""
    path = _rings(shared_tmp, 0.05)
    for method, extra in (("mortar", []), ("mortar", SMOOTH), ("nitsche", [])):
        sets = [f"numerics.method={method}", *extra]
        parallel, res = _solve(path, sets)
        serial, ref = _solve(path, sets, comm=MPI.COMM_SELF)
        assert res.force == pytest.approx(ref.force, rel=1e-8)
        assert parallel.mean_pressure == pytest.approx(serial.mean_pressure, rel=1e-8)
        assert np.allclose(parallel.pressure, serial.pressure, rtol=0.0, atol=1e-8)


@pytest.mark.serial_only
def test_check_reports_and_refuses_the_overlap(shared_tmp, capsys):
    """``contactfx check`` reports the largest overlap of the pair; without
    ``interference`` an overlap above the tolerance is refused in one line naming the key
    (as is ``solve``'s set-up), and a bad value of the key is refused with its choices."""
    from contactfx.cli import main

    path = _rings(shared_tmp, 0.05)
    assert main(["check", str(path)]) == 0
    out = capsys.readouterr().out
    line = next(x for x in out.splitlines() if x.startswith("  overlap"))
    largest = float(line.split()[2])
    assert largest == pytest.approx(DELTA, rel=0.05)
    assert "interference = ramp: removed over the load program" in line
    bare = _rings(shared_tmp, 0.05, RINGS_TOML.replace('interference = "ramp"\n', ""))
    assert main(["check", str(bare)]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1
    assert "the bodies overlap by 0.005" in err[0] and 'interference = "ramp"' in err[0]
    with pytest.raises(ValueError, match='set interference = "ramp" on the'):
        _solve(bare)
    bad = _rings(shared_tmp, 0.05, RINGS_TOML.replace('"ramp"', '"press"'))
    with pytest.raises(ValueError, match="contact.0.interference: must be one of ramp, got "):
        load_problem(bad)


@pytest.mark.parametrize("method", ["mortar", "penalty"])
def test_shrink_fit_at_finite_strain(shared_tmp, method):
    """Finite strain (both rings neo-Hookean with the same small-strain E, nu) takes the
    interference the same way (the slave points' / nodes' initial overlaps, searched at every
    Newton iteration in the deformed configuration): at strains of 3e-3 the mean nodal
    pressure is the small-strain run's within 0.1 % (measured 0.035 % for both; Nitsche
    0.037 %)."""
    path = _rings(shared_tmp, 0.05)
    sets = [f"numerics.method={method}"]
    small, _ = _solve(path, sets)
    finite, _ = _solve(path, [*sets, "numerics.material=neo-hookean"])
    assert finite.mean_pressure == pytest.approx(small.mean_pressure, rel=1e-3)


def test_shrink_fit_demo():
    """demos/problems/shrink-fit.toml (the test's rings at h = 0.025, mortar with the gap
    between the smoothed surfaces): the quarter's contact force over the bore's length is
    Lame's pressure within 1.1 % (measured 0.98 %: the meshed geometry's 0.97 %), every nodal
    pressure within 1.5 % (measured +0.5 % .. +1.4 %)."""
    demo = Path(__file__).resolve().parents[2] / "demos" / "problems" / "shrink-fit.toml"
    scene, res = _solve(demo)
    p = lame_pressure(E, NU, A, B, C, DELTA)
    assert res.force / ((B - DELTA) * np.pi / 2) == pytest.approx(p, rel=0.011)
    assert scene.mean_pressure == pytest.approx(p, rel=0.011)
    assert np.all(np.abs(scene.pressure / p - 1.0) < 0.015)
    # run.json's score: the largest overlap at the start (mortar's weighted nodal gaps)
    assert res.scores["initial_overlap"] == pytest.approx(DELTA, rel=0.01)


class _FitPatch:
    """The patch test (:class:`contactfx.scenes.two_body.PatchTest`) with the upper block moved
    by ``lift`` (< 0: into the lower one) along the last axis and ``interference = "ramp"``."""

    @staticmethod
    def make(dim: int, lift: float):
        from contactfx.scenes.two_body import PatchTest

        class FitPatch(PatchTest):
            def build_mesh(self, comm):
                mesh, facet_tags = super().build_mesh(comm)
                upper = self.cell_tags.indices[self.cell_tags.values == self.cells["upper"]]
                nodes = np.unique(_compat.geometry_nodes(mesh)[upper])
                mesh.geometry.x[nodes, dim - 1] += lift
                return mesh, facet_tags

            def interference(self):
                return "ramp"

        return FitPatch(PatchTest.Params(dim=dim, h=0.1 if dim == 2 else 0.2))


@pytest.mark.parametrize(
    "method, dim",
    [("mortar", 2), ("mortar", 3), ("nitsche", 2), ("penalty", 2), ("nitsche", 3), ("penalty", 3)],
)
def test_interference_patch_test(method, dim):
    """The patch test's blocks overlapping by 0.05 (half a lower element in 2D, a quarter in
    3D) with the interference ramped out over two steps: the upper block, held by the contact
    alone in the vertical, is pushed out by the overlap and the state is the patch test's
    (force q width^(dim - 1) to the solver tolerance). Mortar reproduces the uniform pressure
    to round-off (measured 1.0e-12 and 9.5e-13); the Gauss-point methods the patch test's own
    deviation without the overlap (1.15 % and 1.27 % in 2D, 2.5 % and 4.5 % in 3D for
    Nitsche and penalty) to 2e-13: the hidden overlap shifts the gap, nothing else."""
    from contactfx.scenes import Numerics

    num = Numerics(method=method, steps=2)
    scene = _FitPatch.make(dim, -0.05)
    res = scene.run(num, verbose=False)
    q, width = scene.p.pressure, scene.p.width
    assert res.force == pytest.approx(q * width ** (dim - 1), rel=1e-9)
    assert res.scores["initial_overlap"] == pytest.approx(0.05, rel=1e-9)
    if method == "mortar":
        assert res.scores["pressure_deviation"] < 1e-10
    else:
        touching = _FitPatch.make(dim, 0.0).run(num, verbose=False)
        assert res.scores["pressure_deviation"] == pytest.approx(
            touching.scores["pressure_deviation"], abs=1e-9
        )


@pytest.mark.parametrize("method", ["nitsche", "penalty"])
def test_smoothing_is_mortars(shared_tmp, method):
    """``contact.smoothing = "normals"`` corrects mortar's weighted nodal gaps; the Gauss-point
    methods measure the gap between the facets, so the key is refused for them in one line
    naming the key and the way out (never recorded as applied when it is not)."""
    with pytest.raises(ValueError, match='contact.0.smoothing = "normals" is mortar') as err:
        _solve(_rings(shared_tmp, 0.05), [f"numerics.method={method}", *SMOOTH])
    assert "\n" not in str(err.value) and "--method mortar" in str(err.value)
