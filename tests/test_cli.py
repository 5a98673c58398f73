"""The command line as a user runs it (subprocesses, serial and mpirun -n 2)."""

import json
import subprocess
import tomllib
from pathlib import Path

import pytest

from conftest import clean_env, contactfx_cmd, run_cli, run_cli_batch
from contactfx.cli.args import Parser
from contactfx.io.xdmf import read_xdmf

pytestmark = pytest.mark.serial_only

FAST = ["--h-contact", "0.01", "--h-far", "0.2"]  # a coarse hertz2d for CLI plumbing


def test_list():
    res = run_cli("list")
    assert res.returncode == 0
    for scene in ("hertz2d", "hertz3d", "westergaard", "punch2d", "punch3d", "bar1d"):
        assert scene in res.stdout
    assert "--profile" in res.stdout and "--gamma0" in res.stdout


def test_scene_help():
    res = run_cli("run", "hertz3d", "--help")
    assert res.returncode == 0
    assert "--radius" in res.stdout and "--refine-radius" in res.stdout


def test_method_choices_in_help_and_list():
    """Every option with choices lists them (params.option_help), --method first of all."""
    from contactfx.contact.registry import METHODS

    methods = "one of " + ", ".join(METHODS)
    res = run_cli("run", "hertz2d", "--help")
    assert res.returncode == 0
    assert methods in " ".join(res.stdout.split())  # argparse wraps the help
    assert "one of lu, gamg" in " ".join(res.stdout.split())
    listed = run_cli("list")
    method_rows = [line for line in listed.stdout.splitlines() if "--method " in line]
    assert method_rows and all(methods in line for line in method_rows)


@pytest.mark.parametrize("args", [["check", "demos/problems/holed-pad.toml"], ["list"]])
def test_closed_pipe_ends_quietly(args):
    """`contactfx check FILE | head` after head has gone: the reader's end of the pipe closed
    before the first write (PETSc's SIGPIPE handler aborted MPI with a "Broken Pipe" banner)."""
    root = Path(__file__).parents[1]
    proc = subprocess.Popen(
        contactfx_cmd(*args),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        env=clean_env(),
        cwd=root,
    )
    proc.stdout.close()  # type: ignore[union-attr]
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 0, err.decode()
    assert not err.strip(), err.decode()


@pytest.mark.parametrize(
    "method, largest",
    [("penalty", 1e-10), ("nitsche --theta 0", 1e-10), ("nitsche", 1e-2), ("mortar", 1e-10)],
)
def test_tangential_nodal_force_of_every_two_body_method(tmp_path, method, largest):
    """Frictionless contact on patch-test's flat interface transmits no tangential nodal force
    (the closed form: zero, to the solver's tolerance), whatever the method; Nitsche theta = 1
    only through its consistency term's sigma_n(v) (was nan for Nitsche and penalty)."""
    res = run_cli("run", "patch-test", "--method", *method.split(), "--out", str(tmp_path))
    assert res.returncode == 0, res.stderr
    assert "nan" not in res.stdout
    value = json.loads((tmp_path / "run.json").read_text())["scores"]["tangential_nodal_force"]
    assert 0.0 <= value < largest
    if method == "nitsche":
        assert value > 1e-4  # the theta term, not round-off: theta = 0 above is


def test_locking_hint_names_the_cause_and_the_fix():
    """nu = 0.4999999 in P1 displacements: a failed solve (cut short by -snes_max_it 2, cheap)
    names locking and the options that cure it; not for P2 or nu <= 0.49."""
    from contactfx.mechanics.elasticity import locking_hint

    res = run_cli("run", "hertz2d", *FAST, "--nu", "0.4999999", "--", "-snes_max_it", "2")
    assert res.returncode != 0
    assert "DIVERGED_MAX_IT" in res.stderr and "locks" in res.stderr
    assert "--formulation mixed-up --degree 2" in res.stderr
    assert locking_hint(0.4999999, 2, "displacement") == ""
    assert locking_hint(0.49, 1, "displacement") == ""
    assert locking_hint(0.4999, 2, "mixed-up") == ""
    assert locking_hint(None, 1, "displacement") == ""


def test_quiet_prints_one_line(tmp_path):
    res = run_cli("run", "hertz2d", *FAST, "--quiet", "--out", str(tmp_path))
    assert res.returncode == 0, res.stderr
    lines = res.stdout.splitlines()
    assert len(lines) == 1, res.stdout
    data = json.loads((tmp_path / "run.json").read_text())
    assert lines[0].startswith("hertz2d, nitsche P1: force ")
    assert f"force {data['force']:.6g}," in lines[0] and f"run.json in {tmp_path}" in lines[0]


BAD = [
    (["run", "nosuch"], "unknown scene 'nosuch'"),
    (["run", "hertz2d", "--method", "magic"], "--method must be one of"),
    (["run", "hertz2d", "--bogus", "1"], "unrecognized arguments: --bogus"),
    (["run", "hertz2d", "--E", "-1"], "--E must be > 0"),
    (["run", "hertz2d", "--nu", "0.5"], "Poisson's ratio nu must lie in (-1, 0.5)"),
    (["run", "hertz2d", "--nu", "-1.2"], "Poisson's ratio nu must lie in (-1, 0.5)"),
    (["run", "hertz2d", "--theta", "2"], "--theta must be one of 1, 0, -1"),
    (["run", "hertz2d", "--gamma0", "0"], "--gamma0 must be > 0"),
    (["run", "hertz2d", "--h-contact", "-0.1"], "--h-contact must be > 0"),
    (["run", "hertz2d", "--degree", "3"], "--degree must be one of 1, 2"),
    (["run", "hertz2d", "--out", "/proc/contactfx"], "is not writable"),
    (["frobnicate"], "unknown command 'frobnicate'"),
    (["run", "sliding-block", "--mu", "-0.1"], "--mu must be >= 0"),
    (
        ["run", "sliding-block", "--friction", "tresca", "--mu", "0", "--threshold", "-1"],
        "--threshold must be >= 0",
    ),
    (
        ["run", "hertz2d", "--method", "vi", "--friction", "coulomb", "--mu", "0.3"],
        "friction law 'coulomb' is not supported by method 'vi'",
    ),
    (["run", "hertz2d", "--mu", "0.3"], "--mu needs --friction coulomb"),
    (["run", "sliding-block", "--method", "vi"], "not supported by method 'vi'"),
    # the press-then-drag scenes' press_fraction, checked once (contactfx/scenes/two_body_2d.py)
    (["run", "shallow-ironing", "--press-fraction", "1"], "--press-fraction must be < 1"),
    (["run", "cattaneo-cylinders", "--press-fraction", "1.5"], "--press-fraction must be < 1"),
    (["run", "hertz2d", "--method", "al-ssn", "--solver", "gamg"], "use --solver lu"),
    (["run", "hertz2d", "--method", "al-ssn", "--ncp", "newton"], "--ncp must be one of"),
    (["run", "hertz2d", "--quadrature", "nodal", "--degree", "2"], "--quadrature nodal needs"),
    # a method's own options come from its parameters (contactfx/contact/compliance.py)
    (["run", "hertz2d", "--method", "compliance", "--exponent", "0"], "--exponent must be > 0"),
    (
        ["run", "hertz2d", "--method", "compliance", "--friction", "coulomb", "--mu", "0.3"],
        "friction law 'coulomb' is not supported by method 'compliance'",
    ),
    (["bench", "--scene", "nosuch"], "unknown bench case 'nosuch'"),
    (["bench", "--method", "magic"], "unknown method 'magic'"),
    (["bench", "--method", "penalty@x"], "'x' is not a number"),
    (["bench", "--levels", "0"], "--levels must be >= 1"),
    (["bench", "--repeat", "0"], "--repeat must be >= 1"),
    (["bench", "--degree", "3"], "--degree must list 1 and/or 2"),
    (["stress", "--axis", "nosuch"], "unknown axis 'nosuch'"),
    (["stress", "--time-limit", "-1"], "--time-limit must be > 0"),
    (["run", "crack-sneddon", "--method", "vi"], "method vi is not offered on fitted interfaces"),
    (["run", "crack-sneddon", "--h-tip", "0.1"], "element sizes must satisfy --h-tip"),
    (["run", "crack-sneddon", "--crack-half-length", "12"], "must be < plate-width / 2"),
    (["run", "crack-inclined", "--nu", "0.5"], "Poisson's ratio nu must lie in (-1, 0.5)"),
    (["run", "crack-inclined", "--boundary", "free"], "--boundary must be one of"),
    (["run", "propped-fracture", "--proppant-thickness=-1e-4"], "--proppant-thickness must be > 0"),
    # negative numbers in scientific notation are values, without '=' (Python 3.11 too)
    (
        ["run", "propped-fracture", "--proppant-thickness", "-1e-4"],
        "--proppant-thickness must be > 0",
    ),
    (["run", "hertz2d", "--E", "-2.1E+11"], "--E must be > 0"),
    (["run", "hertz2d", "--gap0", "-x"], "argument --gap0: expected one argument"),
    (["stress", "--time-limit", "-1e2"], "--time-limit must be > 0"),
    (
        ["run", "propped-fracture", "--proppant-half-length", "1.5"],
        "--proppant-half-length (1.5) must be < --crack-half-length",
    ),
    (["run", "joint-column", "--Vm", "2e-3"], "--Vm (0.002) must be <= --aperture"),
    # the fluid pushes harder than the load: no equilibrium, refused before any solve (a
    # diverging solve: test_diverging_solve_is_reported_and_marked_failed)
    (
        ["run", "joint-column", "--fluid-pressure", "40e6"],
        "--fluid-pressure (4e+07) exceeds --closure-stress (3e+07)",
    ),
    (["init", "nosuch", "--out", "x"], "unknown scene 'nosuch'"),
    (["init", "hertz2d"], "give the output folder with --out DIR"),
    (["init", "hertz2d", "--nu", "0.5", "--out", "x"], "Poisson's ratio nu must lie in"),
    # dynamics (docs/verification.md section 18)
    (["run", "bar-impact", "--dt", "0"], "--dynamic needs a time step --dt > 0"),
    (["run", "bar-impact", "--t-end", "0.001"], "must be at least one time step"),
    (["run", "bar-impact", "--rho-inf", "1.5"], "--rho-inf must lie in [0, 1]"),
    (["run", "bar-impact", "--scheme", "hht", "--rho-inf", "0.3"], "needs --rho-inf in [0.5, 1]"),
    (["run", "hertz2d", "--dynamic", "--dt", "0.1", "--t-end", "1"], "needs the body's density"),
    (["run", "patch-test", "--dynamic", "--dt", "0.1", "--t-end", "1"], "needs the body's density"),
    (["run", "crack-sneddon", "--dynamic", "--dt", "0.1", "--t-end", "1"], "offered static only"),
    (["run", "two-bars", "--method", "mortar"], "--method mortar needs --mass redistributed"),
    (["run", "bar-impact", "--method", "vi"], "needs --mass redistributed"),
    (["run", "bar-impact", "--method", "al-ssn"], "needs --mass redistributed"),
    (
        ["run", "disc-drop", "--formulation", "mixed-up", "--degree", "2"],
        "the mixed u-p formulation is not offered in time yet",
    ),
    (["run", "bar-impact", "--al-coupling", "dual"], "--al-coupling must be one of"),
    (["run", "bar-impact", "--mass", "lumped", "--degree", "2"], "is a P1 lumping"),
    # the adaptive time step (contactfx/solvers/dynamics.py)
    (["run", "hertz2d", "--time-tolerance", "1e-3"], "an adaptive time step needs --dynamic"),
    (["run", "bar-impact", "--time-tolerance", "-1"], "--time-tolerance must be >= 0"),
    # the penalty's contact dashpot (contactfx/contact/penalty.py)
    (["run", "bar-impact", "--method", "penalty", "--dashpot", "-1"], "--dashpot must be >= 0"),
    (["run", "hertz2d", "--method", "penalty", "--dashpot", "1"], "use it with --dynamic"),
    (["run", "bar-impact", "--dashpot", "1"], "use --method penalty (got --method nitsche)"),
    (
        ["run", "two-bars", "--method", "penalty", "--dashpot", "1"],
        "the contact dashpot is offered against a rigid obstacle only",
    ),
]


@pytest.fixture(scope="module")
def one_rank_refusals():
    """Every BAD case on one rank, in one process (contactfx's main called per case)."""
    return dict(zip((" ".join(a) for a, _ in BAD), run_cli_batch([a for a, _ in BAD]), strict=True))


@pytest.mark.parametrize("ranks", [1, 2])
@pytest.mark.parametrize("args, message", BAD, ids=[" ".join(a) for a, _ in BAD])
def test_bad_input(args, message, ranks, request):
    if ranks == 1:  # main's status, and all it printed (Python's and PETSc's output)
        status, _, stderr = request.getfixturevalue("one_rank_refusals")[" ".join(args)]
    else:  # a process of its own: the exit status, no rank left waiting
        res = run_cli(*args, ranks=ranks, timeout=120)
        status, stderr = res.returncode, res.stderr
    assert status != 0
    errors = [line for line in stderr.splitlines() if line.startswith("contactfx: error:")]
    assert len(errors) == 1, stderr  # one line, from rank 0 only
    assert message in errors[0]
    assert "Traceback" not in stderr


@pytest.mark.parametrize("ranks", [1, 2])
def test_diverging_solve_is_reported_and_marked_failed(tmp_path, ranks):
    res = run_cli(
        "run", "hertz2d", *FAST, "--out", str(tmp_path), "--", "-snes_max_it", "1", ranks=ranks
    )
    assert res.returncode != 0
    assert "nonlinear solve diverged at load step 1" in res.stderr
    assert "DIVERGED_MAX_IT" in res.stderr
    data = json.loads((tmp_path / "run.json").read_text())
    assert data["status"] == "failed" and data["stage"] == "solve"


DEMOS = Path(__file__).parents[1] / "demos" / "problems"

#: block-on-plinth.geo broken as a user's geometry can be: (edit, stage, the error's words)
BROKEN = {
    # the block 0.02 into the plinth: refused at the start (the geometry checks of the set-up)
    "overlap": (
        lambda g: g.replace("{-0.3, 1, 0, hu}", "{-0.3, 0.98, 0, hu}").replace(
            "{0.3, 1, 0, hu}", "{0.3, 0.98, 0, hu}"
        ),
        "set-up",
        "the bodies overlap by 0.02 at the start",
    ),
    "syntax error": (
        lambda g: g.replace("Line(14) = {14, 11};", "Line(14) = {14, 11}"),
        "mesh",
        "bad.geo: gmsh failed: line 27: syntax error (Curve)",
    ),
    "open curve loop": (
        lambda g: g.replace("Curve Loop(2) = {11, 12, 13, 14};", "Curve Loop(2) = {11, 12, 13};"),
        "mesh",
        "bad.geo: gmsh failed: The 1D mesh seems not to be forming a closed loop",
    ),
    # the block's top corners swapped: a figure eight, which gmsh 4.8 meets by terminating and
    # gmsh 4.13 by meshing again without end (the count of intersections and curves differs)
    "self-intersecting loop": (
        lambda g: (
            g.replace("{0.3, 1.4, 0, hu * 2}", "{x, 1.4, 0, hu * 2}")
            .replace("{-0.3, 1.4, 0, hu * 2}", "{0.3, 1.4, 0, hu * 2}")
            .replace("{x, 1.4, 0, hu * 2}", "{-0.3, 1.4, 0, hu * 2}")
        ),
        "mesh",
        "intersections in the 1D mesh (curves ",
    ),
}


@pytest.mark.parametrize(
    "case, ranks",
    [(case, 1) for case in BROKEN] + [("self-intersecting loop", 2), ("overlap", 2)],
)
def test_failure_before_the_solve_is_one_line_and_marked_failed(tmp_path, case, ranks):
    """A geometry that gmsh cannot mesh (its error, or its crash in a child process) or that
    the set-up refuses: one line on rank 0, no traceback or backtrace, a non-zero exit on
    every rank (no hang), and run.json marked failed with the stage and the same line."""
    edit, stage, words = BROKEN[case]
    (tmp_path / "bad.geo").write_text(edit((DEMOS / "block-on-plinth.geo").read_text()))
    problem = (DEMOS / "block-on-plinth.toml").read_text()
    (tmp_path / "bad.toml").write_text(problem.replace("block-on-plinth.geo", "bad.geo"))
    out = tmp_path / "out"
    res = run_cli("solve", str(tmp_path / "bad.toml"), "--out", str(out), ranks=ranks, timeout=60)
    assert res.returncode != 0
    errors = [line for line in res.stderr.splitlines() if line.startswith("contactfx: error:")]
    assert len(errors) == 1, res.stderr
    assert words in errors[0]
    if stage == "mesh":  # the file named, gmsh's message after it
        assert "bad.geo: gmsh failed: " in errors[0]
    for noise in ("Traceback", "terminate called", "Signal:", "MPI_ABORT"):
        assert noise not in res.stderr, res.stderr
    data = json.loads((out / "run.json").read_text())
    assert data["status"] == "failed" and data["stage"] == stage and data["ranks"] == ranks
    assert data["error"] == errors[0].removeprefix("contactfx: error: ")
    assert data["scene"] == "block-on-plinth" and data["numerics"]["method"] == "mortar"
    assert sorted(p.name for p in out.iterdir()) == ["run.json"]


@pytest.mark.parametrize(
    "args, fields",
    [
        (["run", "hertz2d", "--E", "-1"], {"scene": "hertz2d"}),
        (
            ["solve", str(DEMOS / "holed-pad.toml"), "--set", "bodies.0.nu=0.5"],
            {"problem": "holed-pad.toml"},
        ),
    ],
    ids=["run", "solve"],
)
def test_refused_input_is_marked_failed(tmp_path, args, fields):
    """A refused option or problem-file key with --out: run.json failed at stage input (no
    earlier run.json in the folder stays as this run's)."""
    (tmp_path / "run.json").write_text('{"status": "completed"}')
    res = run_cli(*args, "--out", str(tmp_path), timeout=60)
    assert res.returncode != 0
    data = json.loads((tmp_path / "run.json").read_text())
    assert data["status"] == "failed" and data["stage"] == "input"
    assert f"contactfx: error: {data['error']}" in res.stderr.splitlines()
    for key, value in fields.items():
        assert value in data[key]


def test_run_two_ranks_writes_results(tmp_path):
    res = run_cli("run", "hertz2d", *FAST, "--out", str(tmp_path), "--", "-snes_monitor", ranks=2)
    assert res.returncode == 0, res.stderr
    assert "SNES Function norm" in res.stdout  # command-line PETSc options reach PETSc
    assert "peak pressure p0" in res.stdout and "ParaView: " in res.stdout
    data = json.loads((tmp_path / "run.json").read_text())
    assert data["status"] == "completed" and data["ranks"] == 2
    assert "stage" not in data  # a failed run's key only
    assert data["petsc_options"] == {"snes_monitor": "None"}
    for key in ("mesh", "compile", "assembly", "solve"):
        assert data["timings"][key] >= 0.0
    assert data["steps"][0]["newton"] == data["newton_iterations"]
    # the printed path is the file to open: one dataset per step with every field, the
    # points gathered from both ranks
    assert f"ParaView: {tmp_path / 'hertz2d.xdmf'}" in res.stdout
    assert data["paraview"] == str(tmp_path / "hertz2d.xdmf")
    grid = read_xdmf(tmp_path / "hertz2d.xdmf")
    assert grid["times"] == [1.0] and grid["cells"].shape[0] == data["cells"]
    for name in ("displacement", "contact_pressure", "gap", "contact_status"):
        assert name in grid["point_data"], name
    assert "von_mises" in grid["cell_data"]
    p = grid["point_data"]["contact_pressure"]
    assert p.max() == pytest.approx(data["peak_pressure"], rel=1e-9)


def test_init_then_solve_two_ranks_reproduces_the_run(tmp_path):
    """The user's path: `contactfx init` writes the scene as a problem file, `contactfx solve`
    on it (2 ranks, as `contactfx run`) gives the run's numbers (the same discrete problem:
    round-off apart, tests/verification/test_init.py)."""
    run = run_cli(
        "run", "hertz2d", *FAST, "--steps", "2", "--out", str(tmp_path / "run"), "--quiet", ranks=2
    )
    assert run.returncode == 0, run.stderr
    init = run_cli("init", "hertz2d", *FAST, "--steps", "2", "--out", str(tmp_path / "p"), ranks=2)
    assert init.returncode == 0, init.stderr
    toml = tmp_path / "p" / "hertz2d.toml"
    assert f"wrote {toml}" in init.stdout and (tmp_path / "p" / "hertz2d.msh").is_file()
    solve = run_cli("solve", str(toml), "--out", str(tmp_path / "solved"), ranks=2)
    assert solve.returncode == 0, solve.stderr
    a = json.loads((tmp_path / "run" / "run.json").read_text())
    b = json.loads((tmp_path / "solved" / "run.json").read_text())
    assert b["status"] == "completed" and b["ranks"] == 2 and b["dofs"] == a["dofs"]
    assert b["newton_iterations"] == a["newton_iterations"]
    for key in ("force", "contact_half_width", "peak_pressure"):
        assert b[key] == pytest.approx(a[key], rel=1e-10), key
    assert [s["force"] for s in b["steps"]] == pytest.approx(
        [s["force"] for s in a["steps"]], rel=1e-10
    )


def test_module_entry_point_westergaard():
    res = run_cli("run", "westergaard", "--mean-pressure-ratio", "0.5", "--quiet")
    assert res.returncode == 0, res.stderr
    assert "0.25" in res.stdout  # a / lambda = 0.25 (asserted precisely in verification)


def test_bench_command_line(tmp_path):
    """The bench entry point end to end (positional case, method list, the linear yardstick
    with repeated runs, CSV written)."""
    res = run_cli(
        "bench",
        "hertz2d",
        "--method",
        "nitsche@-1,penalty@100",
        "--levels",
        "1",
        "--linear",
        "--repeat",
        "2",
        "--out",
        str(tmp_path),
        timeout=300,
    )
    assert res.returncode == 0, res.stderr
    assert "nitsche(-1)" in res.stdout and "penalty(100)" in res.stdout
    assert res.stdout.count("contact/linear") == 2
    rows = (tmp_path / "bench.csv").read_text().splitlines()
    assert rows[0].startswith("case,method,degree,level,h") and len(rows) == 3


@pytest.mark.parametrize("ranks", [1, 2])
def test_first_run_prints_no_compiler_chatter(tmp_path, ranks):
    """An empty form cache (XDG_CACHE_HOME: dolfinx's JIT cache is $XDG_CACHE_HOME/fenics):
    every form is compiled, and the build's log (cffi, distutils) stays out of the output."""
    env = {**clean_env(), "XDG_CACHE_HOME": str(tmp_path / "cache")}
    cmd = contactfx_cmd("run", "bar1d", "--out", str(tmp_path / "out"), ranks=ranks)
    if ranks > 1:
        cmd[1:1] = ["-x", "XDG_CACHE_HOME"]  # mpirun passes the variable to every rank
    res = subprocess.run(cmd, capture_output=True, text=True, timeout=300, env=env)
    assert res.returncode == 0, res.stderr
    assert "contact force" in res.stdout  # our own output is all there
    output = res.stdout + res.stderr
    assert not [line for line in output.splitlines() if "INFO:" in line], output
    assert any((tmp_path / "cache" / "fenics").glob("*.so"))  # the forms were compiled, cached


def _number_parser() -> Parser:
    parser = Parser(prog="test")
    parser.add_argument("--gap0", type=float, default=0.0)
    parser.add_argument("--quiet", action="store_true")
    return parser


@pytest.mark.parametrize("text", ["-3e-3", "-1E+6", "-2.5e-1", "-1", "-.5", "-7.", "-1e6"])
def test_negative_numbers_are_option_values(text):
    assert _number_parser().parse_args(["--gap0", text]).gap0 == float(text)
    assert _number_parser().parse_args(["--gap0", text, "--quiet"]).gap0 == float(text)
    assert _number_parser().parse_args(["--gap", text]).gap0 == float(text)  # abbreviated


@pytest.mark.parametrize(
    "args, message",
    [
        (["-x"], "unrecognized arguments: -x"),
        (["--gap0", "1", "-x"], "unrecognized arguments: -x"),
        (["--gap0", "-x"], "argument --gap0: expected one argument"),
        (["--gap0", "-1e-3", "-2e-3"], "unrecognized arguments: -2e-3"),
        (["--quiet", "-1e-3"], "--quiet: ignored explicit argument '-1e-3'"),
    ],
)
def test_unknown_options_still_fail(args, message):
    with pytest.raises(ValueError, match=message):
        _number_parser().parse_args(args)


def test_negative_scientific_value_reaches_the_run(tmp_path):
    res = run_cli("run", "hertz2d", *FAST, "--gap0", "-3e-4", "--quiet", "--out", str(tmp_path))
    assert res.returncode == 0, res.stderr
    assert json.loads((tmp_path / "run.json").read_text())["parameters"]["gap0"] == -3e-4


def test_module_runs_from_another_directory(tmp_path):
    """``python -m contactfx`` of the installed package (here the test's interpreter, the venv),
    not of the source folder in the current directory."""
    res = run_cli("list", cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    assert "hertz2d" in res.stdout and "--gamma0" in res.stdout


ROOT = Path(__file__).resolve().parents[1]


def test_every_subpackage_is_installed():
    """A wheel (non-editable install) holds only the packages pyproject.toml lists."""
    listed = set(
        tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]["packages"]
    )
    found = {
        ".".join(init.parent.relative_to(ROOT).parts)
        for init in (ROOT / "contactfx").rglob("__init__.py")
    }
    assert found | {"contactfx.meshes"} == listed


SYSTEM_PYTHON = Path("/usr/bin/python3")


@pytest.mark.skipif(not SYSTEM_PYTHON.exists(), reason="no Debian /usr/bin/python3")
def test_module_in_checkout_without_install_says_which_interpreter():
    """In the source folder an interpreter without contactfx installed finds the folder's
    contactfx/ (without contactfx.meshes): one line saying to use the venv, no traceback."""
    installed = subprocess.run(
        [str(SYSTEM_PYTHON), "-c", "import contactfx.meshes"],
        cwd="/",
        capture_output=True,
        env=clean_env(),
    )
    if installed.returncode == 0:
        pytest.skip("contactfx is installed for /usr/bin/python3")
    res = subprocess.run(
        [str(SYSTEM_PYTHON), "-m", "contactfx", "list"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        env=clean_env(),
        timeout=60,
    )
    assert res.returncode == 1
    assert res.stderr.splitlines() == [
        "contactfx: error: contactfx is not installed for /usr/bin/python3: use the venv of "
        "scripts/install.sh (.venv/bin/python -m contactfx, or source .venv/bin/activate)"
    ]


def test_progress_on_a_terminal_is_one_line():
    """On a terminal the step lines rewrite one line in place (carriage return, erase to the
    end of the line), closed by a newline before the summary; each ends with the load
    program's wall time and an estimate of the time left. In a pipe and under mpirun: one
    line per step."""
    import os
    import pty

    master, slave = pty.openpty()
    proc = subprocess.Popen(
        contactfx_cmd("run", "hertz2d", *FAST, "--steps", "3"),
        stdout=slave,
        stderr=subprocess.PIPE,
        env=clean_env(),
    )
    os.close(slave)
    chunks = []
    while True:
        try:
            data = os.read(master, 4096)
        except OSError:  # the child closed the terminal
            break
        if not data:
            break
        chunks.append(data)
    proc.wait(timeout=300)
    os.close(master)
    assert proc.returncode == 0
    text = b"".join(chunks).decode().replace("\r\n", "\n")  # the terminal's newline
    steps = [s for s in text.split("\r") if s.startswith("step ")]
    assert [s.split()[1] for s in steps] == ["1", "2", "3"]
    assert all(s.endswith("\x1b[K") for s in steps[:-1])
    assert steps[-1].split("\n")[0].endswith("\x1b[K")
    assert "\n  scene " in steps[-1]  # the summary starts on a line of its own
    assert " left ~" in steps[0] and " time " in steps[0]
    # in a pipe, and under mpirun (whose ranks write to a pseudo-terminal of Open MPI's
    # whatever mpirun's output is): one line per step, no control characters
    for ranks in (1, 2):
        piped = run_cli("run", "hertz2d", *FAST, "--steps", "3", ranks=ranks)
        lines = [s for s in piped.stdout.splitlines() if s.lstrip().startswith("step ")]
        assert len(lines) == 3 and "\r" not in piped.stdout and "\x1b" not in piped.stdout


@pytest.mark.parametrize(
    "args, mu, threshold",
    [
        ([], 0.3, 0.0),  # the scene's defaults: Coulomb mu = 0.3
        (["--friction", "none"], 0.0, 0.0),  # the default mu gives way to no friction
        (["--friction", "tresca", "--threshold", "2"], 0.0, 2.0),
        (["--mu", "0.5"], 0.5, 0.0),
    ],
)
def test_scene_friction_default_gives_way_to_another_law(args, mu, threshold):
    # sliding-stop's defaults are Coulomb mu = 0.3: --friction none alone used to be refused
    # ("--mu needs --friction coulomb")
    from contactfx.cli.run import scene_numerics, scene_parser
    from contactfx.scenes import get_scene

    cls = get_scene("sliding-stop")
    num = scene_numerics(cls, vars(scene_parser(cls).parse_args(args)))
    assert (num.mu, num.threshold) == (mu, threshold)


def test_a_coefficient_given_with_another_law_is_still_refused():
    from contactfx.cli.run import scene_numerics, scene_parser
    from contactfx.scenes import get_scene

    cls = get_scene("sliding-stop")
    ns = vars(scene_parser(cls).parse_args(["--friction", "none", "--mu", "0.2"]))
    with pytest.raises(ValueError, match="--mu needs --friction coulomb"):
        scene_numerics(cls, ns)
