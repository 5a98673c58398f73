"""Symmetry bookkeeping (docs/architecture.md, "Symmetry"): every force of a model cut by
mirror planes is the full model's, the contact force, the pair's force vector
(pair_forces.csv), the friction's tangential force and the reactions alike: the multiplicity
times the model's along the planes, 0 normal to a plane (the mirror images cancel). A quarter
model cut by x = 0 and y = 0 reports (0, 0, 4 F_z)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from mpi4py import MPI

from contactfx.scenes.hertz import Hertz3D, Hertz3DParams, HertzAxi
from contactfx.scenes.problem_file import load_problem
from contactfx.scenes.sphere_slide import SphereSlide
from contactfx.scenes.two_body import HertzCylinders, HertzSpheres
from contactfx.scenes.two_body_2d import CattaneoCylinders

# a quarter block [0, 1]^2 x [-1, 0] on the mirror planes x = 0 and y = 0, clamped at the
# bottom, pressed by a rigid plane over its whole top
QUARTER = """\
title = "quarter"

[mesh]
builder = "box"
parameters = { x0 = 0.0, x1 = 1.0, y0 = 0.0, y1 = 1.0, z0 = -1.0, z1 = 0.0, \
refine_center = [0.0, 0.0], refine_radius = 0.3, h_contact = 0.2, h_far = 0.4 }

[[bodies]]
group = "domain"
E = 1000.0
nu = 0.3

[[boundary]]
group = "zmin"
fix = ["x", "y", "z"]

[[boundary]]
group = "xmin"
fix = ["x"]

[[boundary]]
group = "ymin"
fix = ["y"]

[obstacle]
shape = "plane"
contact = "zmax"
position = [0.0, 0.0, 0.0]
motion = [0.0, 0.0, -0.01]

[numerics]
method = "nitsche"
steps = 1

[output]
symmetry_planes = ["x", "y"]
reactions = ["zmin", "xmin", "ymin"]
"""

# the half model of two cylinders (hertz-cylinders' geometry, coarse) on the mirror plane x = 0
HALF = """\
title = "half-cylinders"

[mesh]
builder = "cylinders"
parameters = { radius_lower = 1.0, radius_upper = 1.0, h_contact = 0.02, h_far = 0.3, \
refine = 0.15, ratio = 1.0 }

[[bodies]]
group = "lower"
E = 1000.0
nu = 0.3

[[bodies]]
group = "upper"
E = 1000.0
nu = 0.3

[[boundary]]
group = "lower_bottom"
fix = ["y"]

[[boundary]]
group = "lower_symmetry"
fix = ["x"]

[[boundary]]
group = "upper_symmetry"
fix = ["x"]

[[boundary]]
group = "upper_top"
displacement = { y = -0.005 }

[[contact]]
slave = "upper_contact"
master = "lower_contact"
force_on = "upper"

[numerics]
method = "nitsche"
steps = 1

[output]
symmetry_planes = ["x"]
reactions = ["lower_bottom", "upper_top", "lower_symmetry"]
"""


@pytest.fixture
def shared_tmp(tmp_path):
    """One temporary folder for all ranks (rank 0's)."""
    return Path(MPI.COMM_WORLD.bcast(str(tmp_path), root=0))


def _file(folder: Path, name: str, text: str) -> Path:
    path = folder / name
    if MPI.COMM_WORLD.rank == 0:
        path.write_text(text)
    MPI.COMM_WORLD.barrier()
    return path


def _solve(path: Path, comm=MPI.COMM_WORLD, out=None, sets=()):
    scene, numerics, petsc = load_problem(path, list(sets))
    res = scene.run(numerics, comm=comm, out=out, petsc_options=petsc, verbose=False)
    return scene, res


def test_quarter_model_reactions_are_the_full_models(shared_tmp):
    """The plane presses along z: the clamped bottom carries the whole contact force, both
    the full model's (4 times the quarter's), to the solver's tolerance (snes_rtol 1e-10;
    before, the reaction was the quarter's, 1/4 of the force); the components normal to a
    mirror plane, which the quarter's supports carry, are 0."""
    scene, res = _solve(_file(shared_tmp, "quarter.toml", QUARTER))
    assert list(scene.force_symmetry(3)) == [0.0, 0.0, 4.0]
    row = scene.reaction_rows[-1]
    assert res.force > 0.0
    assert row["zmin_z"] == pytest.approx(res.force, rel=1e-8)
    for key in ("zmin_x", "zmin_y", "xmin_x", "ymin_y"):
        assert row[key] == 0.0
    if MPI.COMM_WORLD.size > 1:  # the same numbers on one rank
        serial, _ = _solve(shared_tmp / "quarter.toml", comm=MPI.COMM_SELF)
        for key, value in serial.reaction_rows[-1].items():
            assert row[key] == pytest.approx(value, rel=1e-8, abs=1e-10)


def test_half_model_pair_force_and_reactions_are_the_full_models(shared_tmp):
    """Two cylinders on the mirror plane x = 0: pair_forces.csv is (0, 2 F_y) and the
    supports' reactions balance its y component to the solver's tolerance (before: 2 F_x in
    pair_forces.csv, the reactions the half's); the contact force (the integral of the
    normal pressure) differs from F_y by the normal's tilt over the contact, at most
    (a / R)^2 / 2."""
    out = shared_tmp / "out"
    scene, res = _solve(_file(shared_tmp, "half.toml", HALF), out=out)
    forces = np.loadtxt(out / "pair_forces.csv", delimiter=",", skiprows=1, ndmin=2)
    fx, fy = forces[-1, 1:]
    assert fx == 0.0
    assert fy > 0.0
    row = scene.reaction_rows[-1]
    assert row["lower_bottom_y"] == pytest.approx(fy, rel=1e-9)
    assert row["upper_top_y"] == pytest.approx(-fy, rel=1e-9)
    for key in ("lower_bottom_x", "upper_top_x", "lower_symmetry_x"):
        assert row[key] == 0.0
    assert abs(fy - res.force) <= 0.5 * res.contact_size**2 * res.force


def test_built_in_scenes_mirror_planes():
    """The factors of each built-in model with symmetry: the quarter models (0, 0, 4), the
    half models 2 along their plane, the body of revolution 2 pi along its axis."""
    assert list(Hertz3D(Hertz3DParams()).force_symmetry(3)) == [0.0, 0.0, 4.0]
    assert list(Hertz3D(Hertz3DParams(shift=0.01)).force_symmetry(3)) == [2.0, 0.0, 2.0]
    assert list(HertzSpheres(HertzSpheres.Params()).force_symmetry(3)) == [0.0, 0.0, 4.0]
    assert list(SphereSlide(SphereSlide.Params()).force_symmetry(3)) == [2.0, 0.0, 2.0]
    assert list(HertzCylinders(HertzCylinders.Params()).force_symmetry(2)) == [0.0, 2.0]
    assert list(CattaneoCylinders(CattaneoCylinders.Params()).force_symmetry(2)) == [1.0, 1.0]
    assert list(HertzAxi(HertzAxi.Params()).force_symmetry(2)) == [0.0, 2.0 * np.pi]


@pytest.mark.parametrize(
    "edit, message",
    [
        (
            lambda t: t.replace('symmetry_planes = ["x"]', "symmetry = 2.0"),
            "output.symmetry: 2 needs the mirror planes: symmetry_planes = [...]",
        ),
        (
            lambda t: t.replace('symmetry_planes = ["x"]', 'symmetry_planes = ["x"]\nsymmetry = 4'),
            "output.symmetry: 4 with 1 mirror plane(s) in symmetry_planes: each doubles the "
            "model, so 2",
        ),
        (
            lambda t: t.replace('symmetry_planes = ["x"]', 'symmetry_planes = ["x", "x"]'),
            "output.symmetry_planes: expected a list of distinct axes",
        ),
        (
            lambda t: t.replace('symmetry_planes = ["x"]', "tangential_symmetry = [2.0, 0.0]"),
            "output.tangential_symmetry: replaced by symmetry_planes",
        ),
        (
            lambda t: t.replace('symmetry_planes = ["x"]', 'symmetry_planes = ["z"]'),
            "output.symmetry_planes: 'z' is no axis of a 2D mesh",
        ),
        (  # the [output] table's other keys: the ParaView files' format
            lambda t: t.replace(
                'symmetry_planes = ["x"]', 'symmetry_planes = ["x"]\nformat = "csv"'
            ),
            "output.format: must be one of xdmf, vtu, got 'csv'",
        ),
    ],
)
def test_bad_symmetry_keys(tmp_path, edit, message):
    path = tmp_path / "half.toml"
    path.write_text(edit(HALF))
    with pytest.raises(ValueError) as err:
        scene, _, _ = load_problem(path)
        scene.build_mesh(MPI.COMM_SELF)
    assert message in str(err.value)
    assert "\n" not in str(err.value)


def test_check_names_the_convention(shared_tmp, capsys):
    from contactfx.cli import main

    assert main(["check", str(_file(shared_tmp, "half.toml", HALF))]) == 0
    if MPI.COMM_WORLD.rank == 0:
        assert (
            "symmetry   forces of the full model: 2 times the model's, 0 along x (normal to "
            "the mirror planes)" in capsys.readouterr().out
        )


def test_output_format_key(tmp_path):
    """``output.format``: xdmf by default, vtu when asked (what ``solve`` writes unless
    ``--format`` overrides it)."""
    path = tmp_path / "half.toml"
    path.write_text(HALF)
    assert load_problem(path)[0].spec.output.format == "xdmf"
    path.write_text(
        HALF.replace('symmetry_planes = ["x"]', 'symmetry_planes = ["x"]\nformat = "vtu"')
    )
    assert load_problem(path)[0].spec.output.format == "vtu"
