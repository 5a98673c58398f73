"""Problem files (contactfx solve): the demos of demos/problems solve and balance their
reactions against the contact force; 1 and 2 ranks agree; bad files fail with one error naming
the file and the key."""

from __future__ import annotations

import json
import re
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
import ufl
from mpi4py import MPI

from conftest import grad_error, psi
from contactfx.scenes import Numerics
from contactfx.scenes.problem_file import FileTwoBodyScene, load_problem

DEMOS = Path(__file__).resolve().parents[2] / "demos" / "problems"


def _solve(name: str, comm=MPI.COMM_WORLD, sets=()):
    scene, numerics, petsc = load_problem(DEMOS / name, list(sets))
    res = scene.run(numerics, comm=comm, petsc_options=petsc, verbose=False)
    return scene, res


@pytest.mark.parametrize(
    "name, radius",
    [("holed-pad.toml", 2.0), ("bored-block.toml", 1.0), ("rubber-pad.toml", 2.0)],
)
def test_obstacle_problem_reaction_balances_contact_force(name, radius):
    scene, res = _solve(name)
    d = "xyz"[scene.gdim - 1]
    reaction = scene.reaction_rows[-1][f"bottom_{d}"]
    assert res.force > 0.0
    # the support carries the whole contact force. The contact force is the integral of the
    # normal pressure, the reaction its vertical component: on the obstacle's surface the
    # normal tilts by at most a / R from the vertical, so they differ by at most
    # 1 - cos(a / R) <= (a / R)^2 / 2 (plus the solver tolerance)
    tol = 0.5 * (res.contact_size / radius) ** 2 + 1e-8
    assert abs(reaction - res.force) <= tol * res.force


def test_contact_pair_problem_reactions_balance():
    scene, res = _solve("block-on-plinth.toml")
    row = scene.reaction_rows[-1]
    bottom, top = row["plinth_bottom_y"], row["block_top_y"]
    # the two bodies' supports balance each other: every residual row vanishes to the solver
    # tolerance (snes_rtol 1e-10 of the initial residual)
    assert abs(bottom + top) <= 1e-8 * abs(top)
    # and carry the pair's force (the plinth's support pushes up): the mortar force sums the
    # nominal nodal pressures (reference surface), the reactions the current tractions; they
    # differ by the surface strain, at most the approach over the block height,
    # 0.004 / 0.4 = 1e-2 (measured 2e-6)
    assert abs(bottom - res.force) <= 1e-2 * res.force
    assert res.force > 0.0


@pytest.mark.skipif(MPI.COMM_WORLD.size == 1, reason="compares the run on all ranks with one rank")
@pytest.mark.parametrize(
    "name",
    [
        "holed-pad.toml",
        "block-on-plinth.toml",
        "pressurised-crack.toml",
        "bored-block.toml",
        "rubber-pad.toml",
        "o-ring.toml",
        "shrink-fit.toml",
    ],
)
def test_problem_file_ranks_agree(name):
    _, parallel = _solve(name)
    _, serial = _solve(name, comm=MPI.COMM_SELF)
    # the same discrete problem solved to snes_rtol 1e-10: forces agree to 1e-8
    assert parallel.force == pytest.approx(serial.force, rel=1e-8, abs=1e-12)
    assert parallel.contact_size == pytest.approx(serial.contact_size, rel=1e-8, abs=1e-12)
    if serial.interface is not None:
        for key, value in serial.interface.extra.items():
            assert parallel.interface.extra[key] == pytest.approx(value, rel=1e-8)


def test_set_overrides_a_key():
    scene, res = _solve(
        "holed-pad.toml", sets=["obstacle.motion=[0.0, -0.005]", "numerics.steps=1"]
    )
    _, full = _solve("holed-pad.toml", sets=["numerics.steps=1"])
    assert len(res.steps) == 1
    # half the indentation: a smaller force (Hertz-like growth, faster than linear)
    assert 0.2 * full.force < res.force < 0.5 * full.force


def test_axisymmetric_o_ring():
    scene, res = _solve("o-ring.toml")
    reaction = scene.reaction_rows[-1]["midplane_y"]
    # the flat plate presses along z only: the mid-plane's reaction carries the contact force
    # exactly (both totals over the circumference, 2 pi times the section's per-radian
    # integrals), to the solver's tolerance
    assert res.force > 0.0
    assert reaction == pytest.approx(res.force, rel=1e-8)
    # the reported size is the contact area (output.contact_size = "measure"): a band of the
    # ring's circumference 2 pi 10 and of a width below the section's diameter 3
    assert 0.0 < res.contact_size < 2.0 * np.pi * 11.5 * 3.0


@pytest.mark.serial_only
def test_axisymmetric_mesh_must_lie_in_r_positive(tmp_path):
    text = GOOD.replace("size = 1.0", "size = 1.0\naxisymmetric = true")
    path = _write(tmp_path, text)
    scene, _, _ = load_problem(path)
    with pytest.raises(ValueError, match=r"mesh.axisymmetric: .* needs x = r >= 0, got x = -1"):
        scene.build_mesh(MPI.COMM_SELF)


def test_hyperelastic_body():
    scene, numerics, _ = load_problem(DEMOS / "rubber-pad.toml")
    material = scene.material()
    # the file's mu = 1, kappa = 50: the neo-Hookean body with those small-strain moduli
    assert material.finite_strain and material.name == "neo-hookean"
    assert (material.mu, material.kappa) == pytest.approx((1.0, 50.0), rel=1e-14)
    assert numerics.formulation == "mixed-up"


RUBBER = (DEMOS / "rubber-pad.toml").read_text()


@pytest.mark.serial_only
@pytest.mark.parametrize(
    "edit, message",
    [
        (
            lambda t: t.replace('"neo-hookean"', '"rubber"'),
            "bodies.0.material: must be one of",
        ),
        (lambda t: t.replace("mu = 1.0", "mu = -1.0"), "bodies.0.mu: must be > 0"),
        (lambda t: t.replace("kappa = 50.0", "kappa = 0.0"), "bodies.0.kappa: must be > 0"),
        (lambda t: t.replace("mu = 1.0", "mu = 1.0\nE = 3.0"), "bodies.0.E: give E and nu"),
        (
            lambda t: t.replace("mu = 1.0", "mu = 1.0\nc10 = 3.0"),
            "bodies.0.c10: not a parameter of material neo-hookean",
        ),
        (
            lambda t: t.replace("mu = 1.0", "c10 = -1.0"),
            "bodies.0.c10: not a parameter of material neo-hookean",
        ),
        (
            lambda t: t.replace('"neo-hookean"', '"mooney-rivlin"').replace(
                "mu = 1.0", "c10 = -1.0"
            ),
            "bodies.0.c10: must be >= 0",
        ),
        (
            lambda t: t.replace('"neo-hookean"', '"svk"').replace(
                "mu = 1.0\nkappa = 50.0", "E = 1.0\nnu = 0.5"
            ),
            "bodies.0.nu: Poisson's ratio must be in (-1, 0.5)",
        ),
    ],
)
def test_bad_materials(tmp_path, edit, message):
    path = _write(tmp_path, edit(RUBBER))
    with pytest.raises((ValueError, OSError)) as err:
        load_problem(path)
    assert message in str(err.value)
    assert "\n" not in str(err.value)


def _write(tmp_path: Path, text: str) -> Path:
    (tmp_path / "holed-pad.geo").write_text((DEMOS / "holed-pad.geo").read_text())
    path = tmp_path / "p.toml"
    path.write_text(text)
    return path


GOOD = (DEMOS / "holed-pad.toml").read_text()


@pytest.mark.serial_only
@pytest.mark.parametrize(
    "edit, message",
    [
        (lambda t: t + "\n[solver]\nx = 1\n", "solver: unknown section"),
        (lambda t: t.replace("nu = 0.3", "nu = 0.5"), "bodies.0.nu: Poisson's ratio"),
        (lambda t: t.replace("E = 1000.0", "E = -1.0"), "bodies.0.E: must be > 0"),
        (lambda t: t.replace("E = 1000.0", 'E = "soft"'), "bodies.0.E: expected a number"),
        (lambda t: t.replace('fix = ["x", "y"]', 'fix = ["x", "w"]'), "boundary.0.fix"),
        (
            lambda t: t.replace("radius = 2.0", "radius = 2.0\ncolour = 1"),
            "obstacle.colour: unknown",
        ),
        (lambda t: t.replace('method = "nitsche"', 'method = "magic"'), "numerics.method"),
        (lambda t: t.replace("steps = 2", "steps = 2\nspeed = 1"), "numerics.speed: unknown"),
        (lambda t: t.replace("holed-pad.geo", "nowhere.geo"), "nowhere.geo' not found"),
        (
            lambda t: t.replace('shape = "cylinder"', 'shape = "cone"'),
            "obstacle.shape: must be one",
        ),
        (lambda t: t.replace("[obstacle]", "[nothing]"), "nothing: unknown section"),
        (
            lambda t: t.replace('fix = ["x", "y"]', "traction = [0.0, -1.0]"),
            "boundary: the body has no support",
        ),
    ],
)
def test_bad_problem_files(tmp_path, edit, message):
    path = _write(tmp_path, edit(GOOD))
    with pytest.raises((ValueError, OSError)) as err:
        scene, _, _ = load_problem(path)
        scene.build_mesh(MPI.COMM_SELF)
    assert message in str(err.value)
    assert "\n" not in str(err.value)


@pytest.mark.serial_only
@pytest.mark.parametrize(
    "edit, message",
    [
        (
            lambda t: t.replace('group = "bottom"', 'group = "base"'),
            "boundary.0.group: no physical group 'base' in holed-pad.geo (it has: bottom (1D), top",
        ),
        (
            lambda t: t.replace('group = "bottom"', 'group = "pad"'),
            "boundary.0.group: group 'pad' has dimension 2, expected 1",
        ),
        (
            lambda t: t.replace('group = "pad"', 'group = "top"'),
            "bodies.0.group: group 'top' has dimension 1, expected 2",
        ),
        (
            lambda t: t.replace('contact = "top"', 'contact = "hull"'),
            "obstacle.contact: no physical",
        ),
        (
            lambda t: t.replace('contact = "top"', 'contact = "bottom"'),
            "boundary.0.group: 'bottom' is a contact surface",
        ),
    ],
)
def test_problem_file_groups_checked_against_the_mesh(tmp_path, edit, message):
    scene, _, _ = load_problem(_write(tmp_path, edit(GOOD)))
    with pytest.raises(ValueError) as err:
        scene.build_mesh(MPI.COMM_SELF)
    assert message in str(err.value)


PAIR = (DEMOS / "block-on-plinth.toml").read_text()


def _write_pair(tmp_path: Path, text: str) -> Path:
    geo = (DEMOS / "block-on-plinth.geo").read_text() + '\nPhysical Curve("both") = {12, 2};\n'
    (tmp_path / "block-on-plinth.geo").write_text(geo)
    path = tmp_path / "pair.toml"
    path.write_text(text)
    return path


def _pair_key(line: str):
    return lambda t: t.replace('master = "plinth_top"', f'master = "plinth_top"\n{line}')


@pytest.mark.serial_only
@pytest.mark.parametrize(
    "edit, message",
    [
        (_pair_key("h = -0.1"), "contact.0.h: must be > 0"),
        (_pair_key('h = "fine"'), "contact.0.h: expected a number"),
        (
            _pair_key('force_on = "pad"'),
            "contact.0.force_on: must be one of plinth, block, got 'pad'",
        ),
        (_pair_key('edge = "ellipse"'), "contact.0.edge: must be one of x-max, x-band, radial"),
        (_pair_key('edge = "radial"'), "contact.0.edge_ring: missing"),
        (_pair_key('edge = "radial"\nedge_ring = 0.0'), "contact.0.edge_ring: must be > 0"),
        (_pair_key("edge_ring = 0.01"), "contact.0.edge_ring: the ring width of edge = 'radial'"),
        (
            _pair_key('interference = "press"'),
            "contact.0.interference: must be one of ramp, got 'press'",
        ),
        (_pair_key("colour = 1"), "contact.0.colour: unknown key"),
        (
            lambda t: t.replace('slave = "block_bottom"', 'slave = "both"'),
            "contact.0.slave: the surface must bound one body, it bounds ['block', 'plinth']",
        ),
    ],
)
def test_bad_contact_pair_keys(tmp_path, edit, message):
    path = _write_pair(tmp_path, edit(PAIR))
    with pytest.raises(ValueError) as err:
        scene, _, _ = load_problem(path)
        scene.build_mesh(MPI.COMM_SELF)
    assert message in str(err.value)
    assert str(path) in str(err.value) and "\n" not in str(err.value)


@pytest.mark.serial_only
def test_contact_pair_keys(tmp_path):
    """h, force_on and the slave body's material reach the scene; the edge rules find the
    edge of a Hertz-like pressure p = sqrt(1 - (x / a)^2) (p^2 linear in x near the edge)."""
    from contactfx.scenes.two_body_base import contact_edge

    path = _write_pair(tmp_path, _pair_key('h = 0.05\nforce_on = "plinth"')(PAIR))
    scene, _, _ = load_problem(path)
    scene.build_mesh(MPI.COMM_SELF)
    assert scene.h_contact() == 0.05
    assert scene.material().E == 10000.0  # the slave (block) body's, the stiffer here
    assert not scene.slave_is_upper  # the force reported on the master (plinth) body
    swap = ["contact.0.slave=plinth_top", "contact.0.master=block_bottom"]
    scene, _, _ = load_problem(path, swap)
    scene.build_mesh(MPI.COMM_SELF)
    assert scene.material().E == 1000.0 and scene.slave_is_upper
    assert scene.h_contact() == 0.05

    a = 0.3
    x = np.linspace(-a, a, 61)[1:-1]
    p = np.sqrt(1.0 - (x / a) ** 2)
    pts = np.column_stack([x + 0.01, np.zeros_like(x)])
    # p^2 is linear in x near the edge only to O(h / a): the line through the two last nodes
    assert contact_edge("x-max", pts, p) == pytest.approx(a + 0.01, rel=1e-2)
    assert contact_edge("x-band", pts, p) == pytest.approx(a, rel=1e-2)
    assert contact_edge(None, pts, p) is None
    r = np.linspace(0.0, a, 300, endpoint=False)
    ring = np.column_stack([r * np.cos(r * 50), r * np.sin(r * 50)])
    assert contact_edge("radial", ring, np.sqrt(1.0 - (r / a) ** 2), 0.01) == pytest.approx(
        a, rel=2e-2
    )


def test_bad_set():
    with pytest.raises(ValueError, match="--set expects key=value"):
        load_problem(DEMOS / "holed-pad.toml", ["numerics.steps"])
    with pytest.raises(ValueError, match="numerics.steps must be > 0"):
        load_problem(DEMOS / "holed-pad.toml", ["numerics.steps=0"])


@pytest.mark.serial_only
def test_cli_check_solve_and_bad_file(tmp_path, capsys):
    from contactfx.cli import main

    assert main(["check", str(DEMOS / "holed-pad.toml")]) == 0
    out = capsys.readouterr().out
    assert "valid" in out and "boundary   bottom: fixed x,y" in out
    assert (
        main(
            [
                "solve",
                str(DEMOS / "holed-pad.toml"),
                "--set",
                "numerics.steps=1",
                "--out",
                str(tmp_path / "res"),
            ]
        )
        == 0
    )
    out = capsys.readouterr().out
    assert "reaction on bottom" in out
    rows = (tmp_path / "res" / "history.csv").read_text().splitlines()
    assert rows[0] == "load,contact_force,bottom_x,bottom_y" and len(rows) == 2
    assert (tmp_path / "res" / "history.png").is_file()
    assert (tmp_path / "res" / "run.json").is_file()
    bad = _write(tmp_path, GOOD.replace('group = "bottom"', 'group = "base"'))
    assert main(["solve", str(bad), "--out", str(tmp_path / "bad")]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "no physical group 'base'" in err[0]
    # the groups are checked when the mesh is read: the run failed at that stage, and says so
    data = json.loads((tmp_path / "bad" / "run.json").read_text())
    assert data["status"] == "failed" and data["stage"] == "mesh"
    assert "no physical group 'base'" in data["error"]


@pytest.mark.parametrize(
    "load, per_length", [("traction = [0.0, -2.0]", 2.0), ("pressure = 3.0", 3.0)]
)
def test_loads_and_amplitude_reach_the_support(tmp_path, load, per_length):
    """No contact (the obstacle stays 1 above the pad): the bottom carries the load on the top
    (length 2) scaled by the amplitude table at each step, exactly (to solver tolerance)."""
    # (the obstacle's surface is the sides: the top carries the load)
    text = (
        GOOD.replace("position = [0.0, 1.0]", "position = [0.0, 2.0]")
        .replace('contact = "top"', 'contact = "sides"')
        .replace(
            "[obstacle]",
            f'[[boundary]]\ngroup = "top"\n{load}\namplitude = [[0.0, 0.0], [0.5, 1.0], [1.0, 0.5]]'
            "\n\n[obstacle]",
        )
    )
    path = _write(tmp_path, text)  # (each rank has its own tmp_path)
    scene, numerics, petsc = load_problem(path)
    res = scene.run(numerics, petsc_options=petsc, verbose=False)
    assert res.force == 0.0
    ys = [row["bottom_y"] for row in scene.reaction_rows]
    xs = [row["bottom_x"] for row in scene.reaction_rows]
    # amplitude 1 at load 0.5, 0.5 at load 1; the reaction pushes up (+y)
    assert ys == pytest.approx([2.0 * per_length, 1.0 * per_length], rel=1e-9)
    assert np.max(np.abs(xs)) <= 1e-9 * per_length


@pytest.mark.serial_only
def test_msh_file_gives_the_geo_result(tmp_path):
    """The .geo meshed by gmsh and written as .msh: the same mesh, the same solution."""
    import gmsh

    _write(tmp_path, GOOD)
    gmsh.initialize(readConfigFiles=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.merge(str(tmp_path / "holed-pad.geo"))
        gmsh.model.mesh.generate(2)
        gmsh.write(str(tmp_path / "pad.msh"))
    finally:
        gmsh.finalize()
    msh = tmp_path / "msh.toml"
    msh.write_text(GOOD.replace('file = "holed-pad.geo"', 'file = "pad.msh"'))
    scene, numerics, petsc = load_problem(msh, ["numerics.steps=1"])
    res = scene.run(numerics, comm=MPI.COMM_SELF, petsc_options=petsc, verbose=False)
    scene, numerics, petsc = load_problem(tmp_path / "p.toml", ["numerics.steps=1"])
    ref = scene.run(numerics, comm=MPI.COMM_SELF, petsc_options=petsc, verbose=False)
    assert res.dofs == ref.dofs
    assert res.force == pytest.approx(ref.force, rel=1e-10)


def test_interface_problem_crack_volume_sneddon():
    """A fluid-pressurised crack in a user's mesh: the crack volume against Sneddon's
    infinite-plate 2 pi (1 - nu^2) p a^2 / E (docs/verification.md). The plate's half-width is
    10 a (a finite plate changes the volume by O((a / W)^2), about 1 %) and the P1 opening
    misses part of the sqrt profile in the last elements (h_tip / a = 0.004): 2 %; measured
    -0.7 %."""
    scene, res = _solve("pressurised-crack.toml")
    assert len(scene.tips()) == 2 and scene.interface_tag > 0
    E, nu, p, a = 10e9, 0.25, 1e6, 1.0
    exact = 2.0 * np.pi * (1.0 - nu**2) * p * a**2 / E
    assert res.interface.extra["crack_volume"] == pytest.approx(exact, rel=2e-2)


def test_distance_expression_obstacle_matches_the_cylinder():
    """The cylinder written as a signed distance expression (the same circle: centre (0, 2)
    in the obstacle's frame, radius 2) gives the cylinder's run to round-off."""
    sets = ["numerics.steps=1"]
    _, ref = _solve("holed-pad.toml", sets=sets)
    _, res = _solve(
        "holed-pad.toml",
        sets=[*sets, "obstacle.shape=distance", 'obstacle.distance="sqrt(x**2 + (y - 2)**2) - 2"'],
    )
    assert res.force == pytest.approx(ref.force, rel=1e-9)
    assert res.peak_pressure == pytest.approx(ref.peak_pressure, rel=1e-9)


@pytest.mark.serial_only
@pytest.mark.parametrize(
    "text, message",
    [
        ("__import__('os').getcwd()", "is not allowed"),
        ("sqrt(x**2 + w**2)", "'w' is not allowed"),
        ("x +", "not an expression"),
        ("r = sqrt(x**2 + y**2)", "not an expression"),
        ("x = 1; x", "'x' cannot be redefined"),
        ("r = 1; q", "'q' is not allowed"),
    ],
)
def test_distance_expression_refused(text, message):
    with pytest.raises(ValueError, match=message):
        load_problem(
            DEMOS / "holed-pad.toml", ["obstacle.shape=distance", f'obstacle.distance="{text}"']
        )


def test_expression_definitions():
    """Definitions name their repeated parts: the same UFL value as the expression written
    out."""
    from contactfx.scenes.problem_file import parse_expression

    y = ufl.as_vector([3.0, 4.0])
    plain = parse_expression("sqrt(x**2 + y**2) * (1 + sqrt(x**2 + y**2))")(y)
    named = parse_expression("r = sqrt(x**2 + y**2)\n  q = 1 + r; r * q")(y)
    assert float(named) == pytest.approx(float(plain)) == 30.0


CRACK = (DEMOS / "pressurised-crack.toml").read_text()
_EDGE = '[[boundary]]\ngroup = "top"\n'


@pytest.mark.serial_only
@pytest.mark.parametrize(
    "edit, message",
    [
        (
            lambda t: t.replace("[interface]", _EDGE + "stress = [[1.0, 0.0]]\n[interface]"),
            "boundary.2.stress: expected a square table",
        ),
        (
            lambda t: t.replace(
                "[interface]", _EDGE + 'stress = [["sqrt(w)", 0], [0, 0]]\n[interface]'
            ),
            "boundary.2.stress: 'w' is not allowed",
        ),
        (
            lambda t: t.replace(
                "[interface]", _EDGE + "stress = [[1, 0, 0], [0, 1, 0], [0, 0, 1]]\n[interface]"
            ),
            "boundary.2.stress: expected 2 rows of 2",
        ),
        (
            lambda t: t.replace(
                "[interface]",
                _EDGE + "stress = [[1, 0], [0, 1]]\nquadrature_degree = 0\n[interface]",
            ),
            "boundary.2.quadrature_degree: expected an integer",
        ),
        (
            lambda t: t + '\n[[pins]]\npoint = [0.123, 0.456]\nfix = ["x"]\n',
            "pins.0.point: [0.123, 0.456] is not a vertex of the mesh",
        ),
        (lambda t: t + '\n[[pins]]\npoint = [-10.0, -10.0]\nfix = ["w"]\n', "pins.0.fix: expected"),
        (lambda t: t + '\n[[pins]]\npoint = "corner"\nfix = ["x"]\n', "pins.0.point: expected"),
        (
            lambda t: t + '\n[[pins]]\npoint = [-10.0, -10.0, 0.0]\nfix = ["x"]\n',
            "pins.0.point: expected 2 coordinates",
        ),
        (
            lambda t: t.replace("fluid_pressure = 1e6", "fluid_pressure = 1e6\nh = -1.0"),
            "interface.h: must be > 0",
        ),
        (
            lambda t: t.replace("fluid_pressure = 1e6", "fluid_pressure = 1e6\ndirection = [0, 0]"),
            "interface.direction: expected a nonzero vector",
        ),
        (
            lambda t: t.replace("fluid_pressure = 1e6", "fluid_pressure = 1e6\ndirection = [0, 1]"),
            "interface.direction: the group 'crack' is 1 off the line",
        ),
        (
            lambda t: t.replace("fluid_pressure = 1e6", "fluid_pressure = 1e6\norigin = [0, 0.5]"),
            "interface.origin: the group 'crack' is 0.5 off the line",
        ),
        (
            lambda t: t.replace("fluid_pressure = 1e6", "fluid_pressure = 1e6\norigin = 0"),
            "interface.origin: expected 2 numbers",
        ),
        (
            lambda t: t.replace("fluid_pressure = 1e6", "proppant_zone = [-0.5, 0.5]"),
            "interface.proppant_zone: a zone of the proppant layer: give its proppant_thickness",
        ),
        (
            lambda t: t.replace(
                "fluid_pressure = 1e6", "proppant_thickness = 1e-4\nproppant_zone = [0.5, -0.5]"
            ),
            "interface.proppant_zone: expected [s0, s1] with s0 < s1",
        ),
        (
            lambda t: t + '\n[output]\nmean_displacement = { u = ["top", "w"] }\n',
            "output.mean_displacement: expected a table name = [group, component]",
        ),
        (
            lambda t: t + '\n[output]\nmean_displacement = { u = ["nowhere", "y"] }\n',
            "output.mean_displacement.u: no physical group 'nowhere'",
        ),
    ],
)
def test_bad_interface_problem_files(tmp_path, edit, message):
    """The keys of the interface problems (boundary stress, pins, the interface's h, frame
    and proppant zone, mean displacements): a bad value is one error naming the file and
    the key."""
    (tmp_path / "pressurised-crack.geo").write_text((DEMOS / "pressurised-crack.geo").read_text())
    path = tmp_path / "p.toml"
    path.write_text(edit(CRACK))
    with pytest.raises(ValueError) as err:
        scene, _, _ = load_problem(path)
        scene.build_mesh(MPI.COMM_SELF)
    assert str(path) in str(err.value) and message in str(err.value)
    assert "\n" not in str(err.value)


@pytest.mark.serial_only
@pytest.mark.parametrize(
    "edit, message",
    [
        (
            lambda t: t + '\n[[pins]]\npoint = [0.0, 0.0]\nfix = ["x"]\n',
            "pins: pinned points are offered with an [interface]",
        ),
        (
            lambda t: t.replace("[output]", '[output]\nmean_displacement = { u = ["top", "y"] }'),
            "output.mean_displacement: reported with an [interface]",
        ),
    ],
)
def test_interface_keys_refused_elsewhere(tmp_path, edit, message):
    path = _write(tmp_path, edit(GOOD))
    with pytest.raises(ValueError, match=re.escape(message)):
        load_problem(path)


def test_interface_problem_proppant_holds_the_faces(tmp_path):
    """The crack of pressurised-crack.geo under a compression of 1 MPa (top edge) with a
    proppant layer of thickness t along it and no fluid: the faces rest on the layer, the
    opening is t on the whole crack but the last element at each tip (the tips do not open),
    so the crack volume is t (2 a - h_1 - h_2), h_i the tip elements (0.004): within 0.5 % of
    2 a t."""
    t = 1e-4
    text = (
        (DEMOS / "pressurised-crack.toml")
        .read_text()
        .replace("fluid_pressure = 1e6", f"proppant_thickness = {t}")
        .replace(
            "[interface]", '[[boundary]]\ngroup = "top"\ntraction = [0.0, -1e6]\n\n[interface]'
        )
    )
    (tmp_path / "pressurised-crack.geo").write_text((DEMOS / "pressurised-crack.geo").read_text())
    path = tmp_path / "p.toml"
    path.write_text(text)
    scene, numerics, petsc = load_problem(path)
    res = scene.run(numerics, petsc_options=petsc, verbose=False)
    assert res.interface.extra["crack_volume"] == pytest.approx(2.0 * t, rel=5e-3)
    assert res.interface.proppant_force > 0.0


def test_interface_problem_joint_closure(tmp_path):
    """A Barton-Bandis joint across a column (two blocks of height 1 and width 1 with lateral
    rollers) under a top compression s: the joint closes uniformly by the closed form
    v = s Vm / (Kni Vm + s) (references.joint_column), so the crack volume is -v times the
    width; the closure is uniform and the P1 fields represent it exactly: to the solver's
    tolerance (1e-6 relative, Newton on the hyperbolic law). Probes in both blocks."""
    from contactfx.references import joint_column

    geo = """
Point(1) = {0, 0, 0, 0.1}; Point(2) = {1, 0, 0, 0.1}; Point(3) = {1, 1, 0, 0.1};
Point(4) = {0, 1, 0, 0.1}; Point(5) = {1, 2, 0, 0.1}; Point(6) = {0, 2, 0, 0.1};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Line(5) = {3, 5}; Line(6) = {5, 6}; Line(7) = {6, 4};
Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};
Curve Loop(2) = {-3, 5, 6, 7}; Plane Surface(2) = {2};
Physical Surface("column") = {1, 2};
Physical Curve("bottom") = {1}; Physical Curve("top") = {6};
Physical Curve("sides") = {2, 4, 5, 7}; Physical Curve("joint") = {3};
"""
    (tmp_path / "column.geo").write_text(geo)
    s, Kni, Vm, w0, E, nu = 2e6, 5e9, 1e-3, 2e-3, 10e9, 0.25
    text = f"""
[mesh]
file = "column.geo"
[[bodies]]
group = "column"
E = {E}
nu = {nu}
[[boundary]]
group = "bottom"
fix = ["y"]
[[boundary]]
group = "sides"
fix = ["x"]
[[boundary]]
group = "top"
pressure = {s}
[interface]
group = "joint"
joint = {{ Kni = {Kni}, Vm = {Vm}, w0 = {w0} }}
[output]
probes = [[0.3, 0.5], [0.6, 1.5], [5.0, 5.0]]
"""
    path = tmp_path / "column.toml"
    path.write_text(text)
    scene, numerics, petsc = load_problem(path)
    res = scene.run(numerics, petsc_options=petsc, verbose=False)
    assert scene.tips() == []  # the joint crosses the column: both ends on the boundary
    ref = joint_column(s, 0.0, E, nu, 1.0, w0, Kni, Vm)
    v = ref["closure"]
    assert res.interface.extra["crack_volume"] == pytest.approx(-v, rel=1e-6)
    # probes: uniaxial strain in each block, u_y = -s y / M, the upper block moved down by
    # the closure as well (the total displacement u + H a of the probed cell's side)
    row = scene.reaction_rows[-1]
    assert row["probe0_uy"] == pytest.approx(-s * 0.5 / ref["M"], rel=1e-6)
    assert row["probe1_uy"] == pytest.approx(-s * 1.5 / ref["M"] - v, rel=1e-6)
    assert abs(row["probe0_ux"]) + abs(row["probe1_ux"]) <= 1e-9 * v
    assert np.isnan(row["probe2_uy"])  # outside the mesh


def test_petsc_table_reaches_the_solver():
    """[petsc] options apply: GMRES + Jacobi instead of LU takes many Krylov iterations per
    Newton step and, solved to 1e-12, gives the LU run's force (Newton stops at snes_rtol
    1e-10: 1e-8)."""
    _, lu = _solve("holed-pad.toml", sets=["numerics.steps=1"])
    _, it = _solve(
        "holed-pad.toml",
        sets=[
            "numerics.steps=1",
            "petsc.ksp_type=gmres",
            "petsc.pc_type=jacobi",
            "petsc.ksp_rtol=1e-12",
            "petsc.ksp_max_it=20000",
        ],
    )
    assert lu.ksp_iterations == lu.newton_iterations
    assert it.ksp_iterations > 10 * it.newton_iterations
    assert it.force == pytest.approx(lu.force, rel=1e-8)


# -- two bodies of their own materials (finite strain) -----------------------------------------

#: two stacked blocks [0, 1] x [-0.5, 0] (Mooney-Rivlin) and [0, 1] x [0, 0.5] (neo-Hookean),
#: non-matching along y = 0, rollers on every lateral face and at the bottom, a dead (nominal)
#: traction q = 150 on the top: uniaxial strain F = diag(1, l2) in each block, of its own l2
STACKED = """
title = "stacked-rubber"

[mesh]
builder = "stacked-blocks"
parameters = { width = 1.0, h_lower = 0.5, h_upper = 0.5, h1 = 0.1, ratio = 0.7, offset = 0.3 }

[[bodies]]
group = "lower"
material = "mooney-rivlin"
c10 = 150.0
c01 = 40.0
kappa = 1000.0

[[bodies]]
group = "upper"
material = "neo-hookean"
mu = 600.0
kappa = 2000.0

[[boundary]]
group = "lower_bottom"
fix = ["y"]

[[boundary]]
group = "lower_left"
fix = ["x"]

[[boundary]]
group = "lower_right"
fix = ["x"]

[[boundary]]
group = "upper_left"
fix = ["x"]

[[boundary]]
group = "upper_right"
fix = ["x"]

[[boundary]]
group = "upper_top"
traction = [0.0, -150.0]

[[contact]]
slave = "upper_bottom"
master = "lower_top"

[numerics]
method = "penalty"
penalty = 1000.0
steps = 2

[output]
reactions = ["lower_right", "upper_right", "lower_bottom"]
"""
Q_STACKED = 150.0


def uniaxial_strain(model: str, m, q: float) -> tuple[float, float]:
    """(l2, P11) of plane-strain uniaxial strain F = diag(1, l2, 1) with P22 = -q, P = d psi / d F
    of the NumPy energy (conftest.psi) by complex steps (Squire and Trapp 1998,
    doi:10.1137/S003614459631241X), Newton on l2 with a difference derivative."""

    def piola(l2: float, i: int) -> float:
        F = np.diag([1.0, l2, 1.0]).astype(complex)
        F[i, i] += 1e-30j
        return psi(model, m, F).imag / 1e-30

    l2 = 1.0
    for _ in range(30):
        r = piola(l2, 1) + q
        l2 -= r / ((piola(l2 + 1e-7, 1) + q - r) / 1e-7)
    # exact to round-off: the energy's terms are ~1e-16 of the moduli (1e3 here)
    assert abs(piola(l2, 1) + q) < 1e-10 * q
    return l2, piola(l2, 0)


#: the file's materials as the NumPy energies read them (from the file's numbers: lambda =
#: kappa - 2 mu / 3)
LOWER = SimpleNamespace(c10=150.0, c01=40.0, bulk=1000.0)
UPPER = SimpleNamespace(mu=600.0, lmbda=2000.0 - 2.0 * 600.0 / 3.0)


class RecordingPair(FileTwoBodyScene):
    """A problem file's pair that records, at the last step, the L2 error of grad u over each
    body against the homogeneous F - I = diag(0, l2 - 1) of ``exact`` (body: l2), relative to
    |l2 - 1| per unit area, and the pair's force on the slave body (collective)."""

    exact: dict[str, float] = {}

    def on_step(self, problem, solver, load, quantities) -> None:
        super().on_step(problem, solver, load, quantities)
        self.slave_force = problem.coupling().slave_force()
        dx = ufl.Measure("dx", domain=problem.mesh, subdomain_data=self.cell_tags)
        self.grad_errors = {
            body: grad_error(problem, dx(self.cells[body]), 1.0, l2) / np.sqrt(0.5) / abs(l2 - 1.0)
            for body, l2 in self.exact.items()
        }


def _solve_pair(path: Path, sets=(), exact=None, comm=MPI.COMM_WORLD):
    loaded, numerics, petsc = load_problem(path, list(sets))
    scene = RecordingPair(loaded.spec)
    scene.exact = exact or {}
    res = scene.run(numerics, comm=comm, petsc_options=petsc, verbose=False)
    return scene, res


def _stacked(tmp_path: Path, text: str = STACKED) -> Path:
    path = tmp_path / "stacked.toml"
    if MPI.COMM_WORLD.rank == 0:
        path.write_text(text)
    MPI.COMM_WORLD.barrier()
    return path


@pytest.fixture
def shared_tmp(tmp_path):
    """One temporary folder for all ranks (rank 0's)."""
    return Path(MPI.COMM_WORLD.bcast(str(tmp_path), root=0))


def test_two_hyperelastic_bodies_homogeneous_state(shared_tmp):
    """Each block takes the uniaxial strain of its own material: the lower (Mooney-Rivlin)
    shortens by 8.7 %, the upper (neo-Hookean) by 5.1 % under the same nominal stress; the
    lateral rollers carry each one's own P11 (-68.6 and -83.2). The penalty's error shrinks
    with the penalty."""
    l2 = {"lower": uniaxial_strain("mooney-rivlin", LOWER, Q_STACKED)}
    l2["upper"] = uniaxial_strain("neo-hookean", UPPER, Q_STACKED)
    assert 0.08 < 1.0 - l2["lower"][0] < 0.09 and 0.05 < 1.0 - l2["upper"][0] < 0.06
    # the reference at a small load (q / E ~ 1e-4): Hooke's uniaxial strain, eps22 = -q / M
    # and sigma11 = lambda eps22 (M = lambda + 2 mu), to O(q / E)
    for model, m, lam, mu in (
        ("mooney-rivlin", LOWER, 1000.0 - 2.0 * 380.0 / 3.0, 380.0),
        ("neo-hookean", UPPER, UPPER.lmbda, UPPER.mu),
    ):
        small, p11 = uniaxial_strain(model, m, 0.15)
        assert small - 1.0 == pytest.approx(-0.15 / (lam + 2.0 * mu), rel=1e-3)
        assert p11 == pytest.approx(-0.15 * lam / (lam + 2.0 * mu), rel=1e-3)
    # the two materials' states differ by far more than the tolerances below
    assert abs(l2["lower"][0] - l2["upper"][0]) > 0.03
    assert abs(l2["lower"][1] - l2["upper"][1]) > 0.1 * abs(l2["upper"][1])
    errors = {}
    for penalty, tol in ((10.0, 2e-2), (1000.0, 2e-3)):
        scene, res = _solve_pair(
            _stacked(shared_tmp),
            [f"numerics.penalty={penalty}"],
            exact={body: v[0] for body, v in l2.items()},
        )
        row = scene.reaction_rows[-1]
        # equilibrium: the bottom carries the dead load q * width (the rollers carry no
        # vertical force), and so does the pair on the upper block: to Newton's tolerance
        assert row["lower_bottom_y"] == pytest.approx(Q_STACKED, rel=1e-8)
        assert scene.slave_force[1] == pytest.approx(Q_STACKED, rel=1e-8)
        # grad u against each body's exact state. The penalty at the slave's Gauss points does
        # not pass the pressure patch test between non-matching meshes (test_two_body_finite_
        # strain.py: 5.8e-3 at penalty 10, 6.2e-4 at 1000 in one neo-Hookean material on this
        # mesh); measured 6.6e-3, 9.7e-3 (lower, upper) at penalty 10, 6.0e-4, 9.6e-4 at 1000
        # (and 1.2e-4 at 1e4): bounds 2e-2 and 2e-3
        for body in ("lower", "upper"):
            assert scene.grad_errors[body] < tol, body
            # the lateral support carries P11 (nominal) over the block height 0.5: its force
            # on the right face is P11 * 0.5 along +x (measured within 2.3e-4 and 1.4e-5)
            assert row[f"{body}_right_x"] == pytest.approx(0.5 * l2[body][1], rel=tol), body
        # the contact force is the nominal pressure over the slave's reference face: q * width
        # but for the tilt theta of the master normals, 1 - cos(theta) ~ (grad u error)^2 / 2
        # (measured 1.2e-6 and 9e-9)
        assert res.force == pytest.approx(Q_STACKED, rel=tol**2)
        errors[penalty] = max(scene.grad_errors.values())
    # the penalty's error shrinks with its stiffness (measured by 10 for 100 times the penalty)
    assert errors[1000.0] < 0.2 * errors[10.0]


def test_linear_body_among_hyperelastic_ones(shared_tmp):
    """A linear upper block in the same file keeps its small-strain stress (geometrically
    linear): uniaxial strain eps22 = -q / M (M = E (1 - nu) / ((1 + nu)(1 - 2 nu))), sigma11 =
    lambda eps22 exactly, while the lower block is the Mooney-Rivlin one of the file; the run
    reports the linear body's rotation (none here, to the penalty's error)."""
    E, nu = 2000.0, 0.3
    text = STACKED.replace(
        'material = "neo-hookean"\nmu = 600.0\nkappa = 2000.0', f"E = {E}\nnu = {nu}"
    )
    lam, mu = E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))
    eps = -Q_STACKED / (lam + 2 * mu)
    l2 = uniaxial_strain("mooney-rivlin", LOWER, Q_STACKED)
    scene, res = _solve_pair(_stacked(shared_tmp, text), exact={"lower": l2[0], "upper": 1.0 + eps})
    assert "small strain in the linear body upper" in scene.summary
    row = scene.reaction_rows[-1]
    assert res.force == pytest.approx(Q_STACKED, rel=1e-8)
    assert scene.grad_errors["lower"] < 2e-3 and scene.grad_errors["upper"] < 2e-3
    assert row["upper_right_x"] == pytest.approx(0.5 * lam * eps, rel=2e-3)
    assert row["lower_right_x"] == pytest.approx(0.5 * l2[1], rel=2e-3)
    # no rotation but the penalty's error (the grad u errors above; measured 1.0e-4, 0.18 % of
    # the strain, the largest over the cells)
    assert 0.0 <= res.scores["linear_body_rotation"] < 5e-3 * abs(eps)


def test_linear_body_rotation_indicator(shared_tmp):
    """The rotation the run reports for the linear bodies: |skew grad u| of a rigid rotation
    by theta is sin(theta) on the linear body's cells, 0 on the hyperelastic one's."""
    import dolfinx

    from contactfx import _compat
    from contactfx.driver import setup

    text = STACKED.replace(
        'material = "neo-hookean"\nmu = 600.0\nkappa = 2000.0', "E = 1.0\nnu = 0.3"
    )
    scene, numerics, _ = load_problem(_stacked(shared_tmp, text))
    pb = setup(scene, numerics)
    theta = 0.3
    c, s = np.cos(theta), np.sin(theta)
    pb.U.interpolate(lambda x: np.stack([(c - 1) * x[0] - s * x[1], s * x[0] + (c - 1) * x[1]]))
    DG0 = _compat.function_space(pb.mesh, "DG", 0)
    rotation = dolfinx.fem.Function(DG0)
    rotation.interpolate(_compat.expression(pb.small_strain_rotation(), DG0))
    tags = scene.cell_tags
    for body, expected in (("upper", s), ("lower", 0.0)):
        cells = tags.indices[tags.values == scene.cells[body]]
        values = rotation.x.array[_compat.cell_dofs(DG0)[cells, 0]]
        assert np.allclose(values, expected, rtol=1e-12, atol=1e-14), body


def test_two_body_hyperelastic_demo_reactions_balance():
    """demos/problems/indenter-on-rubber.toml: the neo-Hookean half-cylinder 0.3 R into the
    Mooney-Rivlin block. Each body's supports balance the pair's force on it, to Newton's
    tolerance (every free residual row vanishes); the scalar contact force (the nominal
    pressure over the slave's reference face) exceeds the vertical reaction by the tilt of the
    current normals, 1 - cos(theta) <= (a / R)^2 / 2 with theta <= a / R on the indenter."""
    scene, res = _solve_pair(DEMOS / "indenter-on-rubber.toml")
    row = scene.reaction_rows[-1]
    bottom = np.array([row["block_bottom_x"], row["block_bottom_y"]])
    top = np.array([row["rounded_top_x"], row["rounded_top_y"]])
    f = scene.slave_force  # the pair's force on the slave (block) body
    scale = np.linalg.norm(f)
    assert f[1] < 0.0 and scale > 0.0  # the indenter pushes the block down
    assert np.linalg.norm(bottom + f) <= 1e-8 * scale
    assert np.linalg.norm(top - f) <= 1e-8 * scale
    a = res.contact_size
    assert 0.0 < res.force - bottom[1] <= 0.5 * a**2 * res.force
    assert "linear_body_rotation" not in res.scores  # both bodies hyperelastic


@pytest.mark.skipif(MPI.COMM_WORLD.size == 1, reason="compares the run on all ranks with one rank")
def test_two_body_hyperelastic_ranks_agree(shared_tmp):
    path = _stacked(shared_tmp)
    exact = {"lower": 0.9, "upper": 0.95}
    p_scene, parallel = _solve_pair(path, exact=exact)
    s_scene, serial = _solve_pair(path, exact=exact, comm=MPI.COMM_SELF)
    assert parallel.force == pytest.approx(serial.force, rel=1e-8)
    for body in exact:
        assert p_scene.grad_errors[body] == pytest.approx(s_scene.grad_errors[body], rel=1e-6)
    for key, value in s_scene.reaction_rows[-1].items():
        assert p_scene.reaction_rows[-1][key] == pytest.approx(value, rel=1e-8, abs=1e-10)
    _, demo = _solve("indenter-on-rubber.toml")
    _, demo_serial = _solve("indenter-on-rubber.toml", comm=MPI.COMM_SELF)
    assert demo.force == pytest.approx(demo_serial.force, rel=1e-8)
    assert demo.contact_size == pytest.approx(demo_serial.contact_size, rel=1e-8)


@pytest.mark.serial_only
@pytest.mark.parametrize(
    "edit, sets, message",
    [
        (lambda t: t.replace("mu = 600.0", "mu = -1.0"), [], "bodies.1.mu: must be > 0"),
        (lambda t: t.replace("c10 = 150.0", "c10 = -1.0"), [], "bodies.0.c10: must be >= 0"),
        (
            lambda t: t.replace("kappa = 1000.0", "kappa = 1000.0\nnu = 0.3"),
            [],
            "bodies.0.nu: not a parameter of material mooney-rivlin",
        ),
        (
            lambda t: t,
            ["numerics.material=neo-hookean"],
            "numerics.material: 'neo-hookean' conflicts with bodies.0.material = 'mooney-rivlin'",
        ),
        (
            lambda t: t,
            ["numerics.material=linear:E=5"],
            "numerics.material: 'linear:E=5' conflicts with bodies.0.material",
        ),
        (
            lambda t: t,
            ["numerics.method=nitsche"],
            "numerics.method: nitsche between two finite-strain bodies evaluates the stress of "
            "linear, neo-hookean, svk bodies, not mooney-rivlin: use --method penalty or mortar",
        ),
    ],
)
def test_bad_two_body_materials(tmp_path, edit, sets, message):
    path = _stacked(tmp_path, edit(STACKED))
    with pytest.raises(ValueError) as err:
        load_problem(path, sets)
    assert message in str(err.value)
    assert str(path) in str(err.value) and "\n" not in str(err.value)


@pytest.mark.serial_only
def test_finite_strain_material_per_body_refusals(tmp_path, capsys):
    """Several bodies against an obstacle stay linear; a file body's own model does not take
    --material through the Python API either; ``contactfx check`` accepts the demo and names
    each body's model, and refuses a conflicting --set in one line."""
    from contactfx.cli import main

    text = PAIR.replace('group = "block"', 'group = "block"\nmaterial = "svk"')
    text = text.split("[[contact]]")[0] + '[obstacle]\nshape = "plane"\ncontact = "block_top"\n'
    with pytest.raises(ValueError) as err:
        load_problem(_write_pair(tmp_path, text))
    assert "bodies.1.material: a finite-strain material is offered for one body against " in (
        str(err.value)
    )
    scene, _, _ = load_problem(_stacked(tmp_path))
    with pytest.raises(ValueError, match=r"^--material svk: the body's material is neo-hookean"):
        scene.run(Numerics(method="penalty", material="svk"), verbose=False)
    demo = str(DEMOS / "indenter-on-rubber.toml")
    assert main(["check", demo]) == 0
    out = capsys.readouterr().out
    assert "body       block: mooney-rivlin, c10 = 0.4, c01 = 0.1, kappa = 10 (E = 2.9" in out
    assert "body       rounded: neo-hookean, mu = 10, kappa = 30 (E = 27, nu = 0.35)" in out
    assert main(["check", demo, "--set", "numerics.material=svk"]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "numerics.material: 'svk' conflicts with bodies.0.material" in err[0]


DROP = (DEMOS / "rubber-ball-drop.toml").read_text()


@pytest.mark.serial_only
@pytest.mark.parametrize(
    "edit, message",
    [
        (lambda t: t.replace("density = 1.0\n", ""), "bodies.0.density: missing: a dynamic run"),
        (lambda t: t.replace("density = 1.0", "density = -1.0"), "bodies.0.density: must be > 0"),
        (lambda t: t.replace("dt = 0.0025", "dt = 0.0"), "dynamics.dt: must be > 0"),
        (lambda t: t.replace("dt = 0.0025", "dt = -0.1"), "dynamics.dt: must be > 0"),
        (
            lambda t: t.replace("t_end = 0.5", "t_end = 0.001"),
            "dynamics.t_end: must be at least one time step",
        ),
        (
            lambda t: t.replace("dt = 0.0025", 'dt = 0.0025\nscheme = "generalized-alpha"').replace(
                "t_end = 0.5", "t_end = 0.5\nrho_inf = 1.5"
            ),
            "dynamics.rho_inf: rho_inf must lie in [0, 1]",
        ),
        (
            lambda t: t.replace("dt = 0.0025", 'dt = 0.0025\nscheme = "hht"\nrho_inf = 0.2'),
            "dynamics.rho_inf: scheme hht needs rho_inf in [0.5, 1]",
        ),
        (
            lambda t: t.replace("dt = 0.0025", 'dt = 0.0025\nscheme = "euler"'),
            "dynamics.scheme: must be one of",
        ),
        (
            lambda t: t.replace("disc = [0.0, -1.0]", "ball = [0.0, -1.0]"),
            "dynamics.initial_velocity.ball: not a body (the bodies: disc)",
        ),
        (
            lambda t: t.replace("{ disc = [0.0, -1.0] }", "3.0"),
            "dynamics.initial_velocity: expected a table body = [components]",
        ),
        (
            lambda t: t.replace("disc = [0.0, -1.0]", "disc = [0.0, -1.0, 0.0]"),
            "dynamics.initial_velocity.disc: expected 2 components (a 2D mesh), got 3",
        ),
        (
            lambda t: t.replace("gravity = [0.0, -1.0]", "gravity = [-1.0]"),
            "dynamics.gravity: expected 2 components",
        ),
        (
            lambda t: t.replace("{ disc = [0.0, -1.0] }", '["0.0", "-y +"]'),
            "dynamics.initial_velocity:",
        ),
        (
            lambda t: t.replace("dt = 0.0025", "dt = 0.0025\ntime_tolerance = -1e-3"),
            "dynamics.time_tolerance: must be >= 0",
        ),
        (lambda t: t + "\n[numerics]\ndt = 0.1\n", "numerics.dt: given in [dynamics] too"),
        (lambda t: t.replace("gravity", "gravitation"), "dynamics.gravitation: unknown"),
    ],
)
def test_bad_dynamics(tmp_path, edit, message):
    path = tmp_path / "p.toml"
    path.write_text(edit(DROP))
    with pytest.raises(ValueError) as err:
        scene, _, _ = load_problem(path)
        scene.build_mesh(MPI.COMM_SELF)
    assert message in str(err.value)
    assert "\n" not in str(err.value)


@pytest.mark.serial_only
def test_dynamics_not_with_an_interface(tmp_path):
    path = tmp_path / "crack.toml"
    path.write_text(CRACK + "\n[dynamics]\ndt = 0.1\n")
    with pytest.raises(ValueError, match=r"dynamics: .* a problem with an \[interface\] is static"):
        load_problem(path)


@pytest.mark.serial_only
def test_dynamics_pair_needs_densities(tmp_path):
    path = _write_pair(tmp_path, PAIR + "\n[dynamics]\ndt = 0.1\n")
    with pytest.raises(ValueError, match=r"bodies.0.density: missing: a dynamic run"):
        load_problem(path)


#: two blocks of densities 1 and 3 (each 1 x 0.5) thrown sideways, falling under gravity
#: without reaching the floor: a rigid translation, which Newmark integrates exactly
TWO_DENSITIES = """
[mesh]
builder = "stacked-blocks"
parameters = { width = 1.0, h_lower = 0.5, h_upper = 0.5, h1 = 0.25, ratio = 1.0 }

[[bodies]]
group = "lower"
E = 100.0
nu = 0.3
density = 1.0

[[bodies]]
group = "upper"
E = 100.0
nu = 0.3
density = 3.0

[obstacle]
shape = "floor"
contact = "lower_bottom"
position = [0.0, -0.6]

[dynamics]
dt = 0.01
t_end = 0.05
gravity = [0.0, -2.0]
initial_velocity = VELOCITY
"""


@pytest.mark.parametrize(
    "velocity", ["{ lower = [1.0, 0.0], upper = [1.0, 0.0] }", '["1.0", "0.0 * x"]']
)
def test_dynamics_densities_gravity_and_velocity(tmp_path, velocity):
    comm = MPI.COMM_WORLD
    folder = Path(comm.bcast(str(tmp_path), root=0))
    path = folder / "drop.toml"
    if comm.rank == 0:
        path.write_text(TWO_DENSITIES.replace("VELOCITY", velocity))
    comm.barrier()
    scene, num, petsc = load_problem(path)
    assert num.dynamic and num.dt == 0.01
    res = scene.run(num, comm=comm, petsc_options=petsc, verbose=False).to_json()
    m, g, v0 = 1.0 * 0.5 + 3.0 * 0.5, 2.0, 1.0  # the mass, each body's density times area
    assert len(res["steps"]) == 5
    for step in res["steps"]:
        e = step["energy"]
        t = e["time"]
        # free fall from rest vertically: v = (v0, -g t), the work of gravity m g (g t^2 / 2);
        # exact in Newmark (a constant acceleration): round-off of the energy's size
        assert e["kinetic"] == pytest.approx(0.5 * m * (v0**2 + (g * t) ** 2), rel=1e-10)
        assert e["external_work"] == pytest.approx(m * g * g * t * t / 2, rel=1e-9)
        assert step["force"] == 0.0
