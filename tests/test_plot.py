"""``contactfx plot``: a run's deformed body as a PNG with matplotlib (no ParaView needed)."""

import pytest

from conftest import run_cli

pytestmark = pytest.mark.serial_only

PNG = b"\x89PNG\r\n\x1a\n"


def test_plot_a_run(tmp_path):
    res = run_cli(
        "run", "hertz2d", "--h-contact", "0.01", "--h-far", "0.2", "--quiet", "--out", str(tmp_path)
    )
    assert res.returncode == 0, res.stderr
    # the default field (contact_pressure), next to run.json
    res = run_cli("plot", str(tmp_path))
    assert res.returncode == 0, res.stderr
    assert (tmp_path / "contact_pressure.png").read_bytes()[:8] == PNG
    # a cell field, from run.json, to a chosen file, undeformed
    png = tmp_path / "vm.png"
    res = run_cli(
        "plot",
        str(tmp_path / "run.json"),
        "--field",
        "von_mises",
        "--scale",
        "0",
        "--out",
        str(png),
    )
    assert res.returncode == 0, res.stderr
    assert png.read_bytes()[:8] == PNG and "von_mises" in res.stdout
    # an unknown field: one line naming the fields there are
    res = run_cli("plot", str(tmp_path), "--field", "nope")
    assert res.returncode == 1
    assert "no field 'nope'" in res.stderr and "contact_pressure" in res.stderr
    res = run_cli("plot", str(tmp_path / "missing"))
    assert res.returncode == 1 and "no run.json" in res.stderr
