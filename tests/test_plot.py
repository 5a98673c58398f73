"""``contactfx plot``: a run's deformed body as a PNG with matplotlib (no ParaView needed)."""

import numpy as np
import pytest

from conftest import run_cli
from contactfx.cli import plot

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


def test_plot_reads_xdmf_and_vtu_alike(tmp_path):
    """The same run written in each format: ``plot`` reads the same steps, cells and values
    from both (serial runs: the same bits; the XDMF nodes in global order, the VTU's in
    first-use order, so both sorted by their coordinates)."""
    args = ("run", "hertz2d", "--h-contact", "0.02", "--h-far", "0.2", "--steps", "2", "--quiet")
    grids = {}
    for fmt in ("xdmf", "vtu"):
        res = run_cli(*args, "--format", fmt, "--out", str(tmp_path / fmt))
        assert res.returncode == 0, res.stderr
        series = plot.series_of(tmp_path / fmt)
        assert series.suffix == {"xdmf": ".xdmf", "vtu": ".pvd"}[fmt]
        grids[fmt] = [plot.read_step(series, step) for step in (1, -1)]
        with pytest.raises(ValueError, match="the run has steps 1..2"):
            plot.read_step(series, 3)
    for (t, a), (s, b) in zip(grids["xdmf"], grids["vtu"], strict=True):
        assert t == s and a["type"] == b["type"] == 5
        order = [np.lexsort(np.round(g["points"], 12).T[::-1]) for g in (a, b)]
        assert np.allclose(a["points"][order[0]], b["points"][order[1]], rtol=0, atol=1e-15)
        for name, v in b["point_data"].items():
            assert np.array_equal(a["point_data"][name][order[0]], v[order[1]]), name
        # the cells: the same node triples (by coordinates) in the same order (owned cells)
        assert np.array_equal(
            np.round(a["points"][a["cells"]], 12), np.round(b["points"][b["cells"]], 12)
        )
        for name, v in b["cell_data"].items():
            assert np.array_equal(a["cell_data"][name], v), name
