"""``contactfx plot RUN [--field NAME] [--step N] [--scale S] [--out PNG]``: the deformed body of
a run coloured by one of its fields, with matplotlib (for those without ParaView).

RUN is a run's output folder or its run.json. The body is read from the run's ParaView files
(:mod:`contactfx.io.vtk`): in 2D the mesh, displaced by ``displacement`` times the scale,
coloured by a point field (interpolated) or a cell field (per cell); in 3D the boundary faces;
on a bar the field against x. Vector fields are coloured by their magnitude.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from contactfx.io.vtk import read_pvd, read_vtu
from contactfx.io.xdmf import read_xdmf

__all__ = ["cmd_plot", "plot_run"]

#: the field coloured when none is asked for: the first the run has
DEFAULT_FIELDS = ("contact_pressure", "aperture", "von_mises")


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="contactfx plot", description=__doc__.split("\n\n")[0])
    p.add_argument("run", type=Path, help="a run's output folder (--out) or its run.json")
    first = ", ".join(DEFAULT_FIELDS)
    p.add_argument("--field", default=None, help=f"colour by (default: the first of {first})")
    p.add_argument("--step", type=int, default=-1, help="load step, 1-based (default: the last)")
    p.add_argument(
        "--scale",
        type=float,
        default=None,
        help="displacement magnification (default: the largest displacement drawn "
        "as 5%% of the body's size; 0: undeformed)",
    )
    p.add_argument(
        "--out", type=Path, default=None, help="the PNG (default: <field>.png next to run.json)"
    )
    return p


def cmd_plot(argv: list[str], comm) -> int:
    ns = _parser().parse_args(argv)
    if comm.rank != 0:
        return 0
    png, field, scale = plot_run(ns.run, ns.field, ns.step, ns.scale, ns.out)
    print(f"contactfx: {field} (displacement x {scale:.4g}) -> {png}")
    return 0


def series_of(run: Path) -> Path:
    """The body's series (XDMF or PVD) of a run folder or run.json (next to run.json if the
    recorded path, possibly relative to where the run was started, does not exist)."""
    run_json = run / "run.json" if run.is_dir() else run
    if not run_json.exists():
        raise ValueError(f"no run.json at {run_json}")
    data = json.loads(run_json.read_text())
    if data.get("status") != "completed":
        raise ValueError(f"{run_json}: the run did not complete ({data.get('error', '?')})")
    recorded = data.get("paraview")
    candidates = [Path(recorded)] if recorded else []
    candidates += [run_json.parent / f"{data['scene']}{s}" for s in (".xdmf", ".pvd")]
    for c in candidates:
        if c.exists():
            return c
    raise ValueError(f"{run_json}: no ParaView files ({candidates[-1]} missing)")


def plot_run(
    run: Path,
    field: str | None = None,
    step: int = -1,
    scale: float | None = None,
    out: Path | None = None,
) -> tuple[Path, str, float]:
    """Render the run's body at ``step`` coloured by ``field``; returns (PNG, field, scale)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    series = series_of(Path(run))
    t, grid = read_step(series, step)
    pdata, cdata = grid["point_data"], grid["cell_data"]
    names = [*pdata, *cdata]
    if field is None:
        field = next((f for f in DEFAULT_FIELDS if f in names), names[0])
    if field not in names:
        raise ValueError(f"no field '{field}' in {series.name}; fields: {', '.join(names)}")
    on_points = field in pdata
    values = pdata[field] if on_points else cdata[field]
    label = field
    if values.ndim == 2:
        values, label = np.linalg.norm(values, axis=1), f"|{field}|"

    x = grid["points"]
    u = pdata.get("displacement", np.zeros_like(x))
    if u.ndim == 1:  # a bar's scalar displacement: along x
        u = np.column_stack([u, np.zeros((len(u), 2))])
    size = float(np.linalg.norm(x.max(axis=0) - x.min(axis=0))) or 1.0
    umax = float(np.max(np.linalg.norm(u, axis=1), initial=0.0))
    if scale is None:
        scale = 0.05 * size / umax if umax > 0 else 0.0
    y = x + scale * u
    cells, vtk_type = grid["cells"], grid["type"]

    fig = plt.figure(figsize=(7, 5.5))
    if vtk_type == 3:  # a bar: the field against x
        ax = fig.add_subplot()
        order = np.argsort(x[:, 0])
        xs = x[order, 0] if on_points else x[cells].mean(axis=1)[:, 0]
        ax.plot(xs, values[order] if on_points else values, "o-")
        ax.set_xlabel("x")
        ax.set_ylabel(label)
    elif vtk_type in (5, 9):  # 2D: triangles (quads split in two)
        tri = cells if vtk_type == 5 else np.vstack([cells[:, [0, 1, 2]], cells[:, [0, 2, 3]]])
        ax = fig.add_subplot()
        if on_points:
            art = ax.tripcolor(y[:, 0], y[:, 1], tri, values, shading="gouraud", cmap="viridis")
        else:
            colours = values if vtk_type == 5 else np.concatenate([values, values])
            art = ax.tripcolor(y[:, 0], y[:, 1], tri, facecolors=colours, cmap="viridis")
        ax.set_aspect("equal")
        ax.set_xlabel("x")
        ax.set_ylabel("y")
        fig.colorbar(art, ax=ax, label=label)
    else:  # 3D: the boundary faces, coloured by the mean of their nodes (or their cell)
        from mpl_toolkits.mplot3d.art3d import Poly3DCollection

        faces, owner = _boundary_faces(cells, vtk_type)
        face_values = values[faces].mean(axis=1) if on_points else values[owner]
        ax = fig.add_subplot(projection="3d")
        norm = matplotlib.colors.Normalize(face_values.min(), face_values.max())
        cmap = matplotlib.colormaps["viridis"]
        ax.add_collection3d(
            Poly3DCollection(
                y[faces], facecolors=cmap(norm(face_values)), edgecolors="k", linewidths=0.1
            )
        )
        lo, hi = y.min(axis=0), y.max(axis=0)
        ax.set_xlim(lo[0], hi[0])
        ax.set_ylim(lo[1], hi[1])
        ax.set_zlim(lo[2], hi[2])
        ax.set_box_aspect(np.maximum(hi - lo, 1e-12 * size))
        fig.colorbar(matplotlib.cm.ScalarMappable(norm, cmap), ax=ax, label=label, shrink=0.7)
    ax.set_title(f"{series.stem}: {label}, load {t:g}, displacement x {scale:.3g}")
    out = Path(out) if out is not None else series.parent / f"{field}.png"
    fig.savefig(out, dpi=150, bbox_inches="tight")
    plt.close(fig)
    return out, field, scale


#: XDMF topology type -> VTK cell type (the writers order the vertices alike)
_XDMF_VTK = {"Polyline": 3, "Triangle": 5, "Quadrilateral": 9, "Tetrahedron": 10, "Hexahedron": 12}


def read_step(series: Path, step: int) -> tuple[float, dict]:
    """(load factor, grid as :func:`read_vtu` gives it) of a step (1-based, or from the
    end when negative) of an XDMF or PVD series."""
    if series.suffix == ".xdmf":
        times = read_xdmf(series)["times"]
    else:
        steps = read_pvd(series)
        times = [t for t, _ in steps]
    if not (-len(times) <= step <= len(times)) or step == 0:
        raise ValueError(f"--step {step}: the run has steps 1..{len(times)}")
    k = step - 1 if step > 0 else step
    if series.suffix != ".xdmf":
        return times[k], read_vtu(steps[k][1])
    grid = read_xdmf(series, k)
    return times[k], {**grid, "type": _XDMF_VTK[grid["type"]]}


#: the faces of a tetrahedron and a hexahedron (VTK vertex order)
_FACES = {
    10: [[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]],
    12: [[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]],
}


def _boundary_faces(cells: np.ndarray, vtk_type: int) -> tuple[np.ndarray, np.ndarray]:
    """The faces (k, vertices) that belong to one cell only, and that cell."""
    local = np.array(_FACES[vtk_type])
    faces = cells[:, local].reshape(-1, local.shape[1])
    owner = np.repeat(np.arange(len(cells)), len(local))
    _, index, count = np.unique(
        np.sort(faces, axis=1), axis=0, return_index=True, return_counts=True
    )
    keep = index[count == 1]
    return faces[keep], owner[keep]
