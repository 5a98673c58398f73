"""Tables and plots of ``contactfx bench`` and ``contactfx stress`` (rank 0 only).

CSV for machines, Markdown for the results page, PNG for the eye. Plots use matplotlib's Agg
backend (no display needed).
"""

from __future__ import annotations

import csv
import math
import os
import platform
import time
from collections import defaultdict
from pathlib import Path

import numpy as np

__all__ = ["machine", "write_bench", "write_csv", "markdown_table", "method_guide"]


def machine(ranks: int) -> str:
    """One line naming the machine, the versions and the date."""
    from contactfx.io.provenance import versions

    cpu = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    v = versions()
    distro = ""
    try:
        for line in Path("/etc/os-release").read_text().splitlines():
            if line.startswith("PRETTY_NAME="):
                distro = line.split("=", 1)[1].strip('"')
    except OSError:
        pass
    return (
        f"{cpu}, {os.cpu_count()} cores, {ranks} MPI rank(s); {distro}; contactfx "
        f"{v['contactfx']}, dolfinx {v['dolfinx']}, PETSc {v['petsc']}, Python {v['python']}; "
        f"{time.strftime('%Y-%m-%d')}"
    )


def write_csv(rows: list[dict], path: Path) -> Path:
    fields: list[str] = []
    for r in rows:
        fields += [k for k in r if k not in fields]
    with open(path, "w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=fields, restval="")
        writer.writeheader()
        writer.writerows(rows)
    return path


def _cell(value) -> str:
    if isinstance(value, float):
        if not math.isfinite(value):
            return ""
        return f"{value:.3g}" if abs(value) >= 1e-3 or value == 0.0 else f"{value:.2e}"
    return str(value)


def _escape(text: str) -> str:
    """A table cell's text with its pipes escaped (|x| would split the cell)."""
    return text.replace("|", "\\|")


def markdown_table(rows: list[dict], columns: list[tuple[str, str]]) -> str:
    """Rows as a Markdown table with the (key, heading) columns."""
    lines = ["| " + " | ".join(_escape(h) for _, h in columns) + " |", "|" + "---|" * len(columns)]
    for r in rows:
        lines.append("| " + " | ".join(_escape(_cell(r.get(k, ""))) for k, _ in columns) + " |")
    return "\n".join(lines)


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _series(rows: list[dict]) -> dict[tuple[str, int], list[dict]]:
    out: dict[tuple[str, int], list[dict]] = defaultdict(list)
    for r in rows:
        if r["status"] == "ok":
            out[(r["method"], r["degree"])].append(r)
    return out


def _has(rows: list[dict], column: str, floor: float = 0.0) -> bool:
    """Some successful row has an error above ``floor`` in the column."""
    return any(
        r.get("status") == "ok" and math.isfinite(r.get(column, math.nan)) and r[column] > floor
        for r in rows
    )


#: optional bench columns that are values, not errors (shown where some row has them)
VALUE_COLUMNS = (
    ("Q_over_bound", "Q / (mu P)"),
    ("c_over_a_computed", "stick c / a"),
    ("Q_over_P_over_mu", "Q / (mu P) global"),
    ("equilibrium_top", "equilibrium top"),
    ("equilibrium_bottom", "equilibrium bottom"),
    ("t_contact", "t contact"),
    ("contact_over_bulk", "contact over bulk"),
    ("contact_over_linear", "contact over linear"),
    ("newton_over_linear", "Newton over linear"),
    ("speedup", "speedup"),
    ("t_per_step", "time per step"),
    ("newton_per_step", "Newton per step"),
    ("step_over_linear", "step over linear"),
    ("energy_remainder", "energy remainder"),
    ("stop_distance_error", "stop distance error"),
)


def write_bench(rows: list[dict], out: Path, ranks: int, total: float) -> list[Path]:
    """bench.csv, bench.md and the plots; returns the paths written."""
    from contactfx.validation.bench import CASES, MEASURES, ROUNDOFF, observed_rates

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    written = [write_csv(rows, out / "bench.csv")]
    plt = _plt()
    md = [
        "# contactfx bench: error against run time",
        "",
        f"Machine: {machine(ranks)}. {len(rows)} runs, {total:.0f} s in all.",
        "",
        "Errors are relative to the closed form at the computed force. Time is the wall time "
        "of assembly + solve (mesh generation and the cached form compilation are in "
        "bench.csv). Rates: least-squares slope of log(error) against log(h) over the levels "
        "(last pair in brackets).",
    ]
    md += [
        "",
        "## Which method for which problem",
        "",
        "From the tables below (generated): per case, the most accurate method at the finest "
        "level every method reached, the fastest one whose error is within twice that, the "
        "one with the fewest Newton iterations, and the runs that failed.",
        "",
    ]
    md += method_guide(rows)
    for case_name in dict.fromkeys(r["case"] for r in rows):
        case_rows = [r for r in rows if r["case"] == case_name]
        measures = [m for m in MEASURES if _has(case_rows, m)]
        # exact by construction (e.g. the force under force control): tabulated, not plotted
        plotted = [m for m in measures if _has(case_rows, m, ROUNDOFF)]
        md += ["", f"## {case_name}: {CASES[case_name].summary}", ""]
        cols = [
            ("method", "method"),
            ("degree", "P"),
            ("level", "level"),
            ("h", "h"),
            ("dofs", "dofs"),
            ("newton", "Newton"),
            ("ksp", "KSP"),
            ("t_mesh", "t mesh"),
            ("t_compile", "t compile"),
            ("t_assembly", "t assembly"),
            ("t_solve", "t solve"),
            ("memory_mib", "memory MiB"),
        ]
        cols += [(m, MEASURES[m][0]) for m in measures]
        cols += [(k, heading) for k, heading in VALUE_COLUMNS if any(k in r for r in case_rows)]
        cols.append(("status", "status"))
        md.append(markdown_table(case_rows, cols))
        bad = [r for r in case_rows if r["status"] != "ok"]
        if bad:
            md += [""] + [
                f"- {r['method']} P{r['degree']} level {r['level']}: {r['status']} ({r['reason']})"
                for r in bad
            ]
        series = _series(case_rows)
        if not measures:
            continue
        rate_rows = []
        for (label, degree), srs in series.items():
            rr = {"method": label, "degree": degree}
            for m in plotted:
                fit, last = observed_rates(srs, m)
                rr[m] = "" if math.isnan(fit) else f"{fit:.2f} ({last:.2f})"
            rate_rows.append(rr)
        if any(len(s) > 1 for s in series.values()):
            md += ["", "Observed rates:", ""]
            md.append(
                markdown_table(
                    rate_rows,
                    [("method", "method"), ("degree", "P")]
                    + [(m, MEASURES[m][0]) for m in plotted],
                )
            )
        for m in plotted:
            for kind in ("time", "h"):
                path = out / f"{case_name}_{m[4:]}_{kind}.png"
                _plot(plt, series, m, kind, f"{case_name}: {MEASURES[m][0]}", path)
                written.append(path)
            md += [
                "",
                f"![{case_name} {m} vs time]({case_name}_{m[4:]}_time.png)"
                f" ![{case_name} {m} vs h]({case_name}_{m[4:]}_h.png)",
            ]
        md += _beside(plt, rows, case_name, plotted, out, written)
    path = out / "bench.md"
    path.write_text("\n".join(md) + "\n")
    written.append(path)
    return written


def _beside(
    plt, rows: list[dict], case_name: str, plotted: list[str], out: Path, written: list[Path]
) -> list[str]:
    """The case with the one it is benched beside (``BenchCase.beside``, e.g. an unfitted
    crack beside the fitted one) in common figures: the measures both have, every series
    labelled with its case. Returns the Markdown lines."""
    from contactfx.validation.bench import CASES, MEASURES

    other = CASES[case_name].beside
    other_rows = [r for r in rows if r["case"] == other]
    if other is None or not other_rows:
        return []
    series = {}
    for name in (other, case_name):
        for (label, degree), srs in _series([r for r in rows if r["case"] == name]).items():
            series[(f"{name}: {label}", degree)] = srs
    md = ["", f"### {case_name} beside {other}"]
    for m in (m for m in plotted if _has(other_rows, m)):
        names = []
        for kind in ("time", "h"):
            path = out / f"{case_name}_beside_{m[4:]}_{kind}.png"
            _plot(plt, series, m, kind, f"{case_name} and {other}: {MEASURES[m][0]}", path)
            written.append(path)
            names.append(path.name)
        md += ["", f"![{m} vs time]({names[0]}) ![{m} vs h]({names[1]})"]
    return md


#: one colour per method variant (tab10 and eight more of distinct hue), in order of appearance
PALETTE = (
    "#1f77b4",
    "#ff7f0e",
    "#2ca02c",
    "#d62728",
    "#9467bd",
    "#8c564b",
    "#e377c2",
    "#7f7f7f",
    "#bcbd22",
    "#17becf",
    "#000000",
    "#aec7e8",
    "#ffbb78",
    "#98df8a",
    "#c5b0d5",
    "#c49c94",
    "#f7b6d2",
    "#dbdb8d",
)
#: one line style and marker per degree
DEGREE_STYLE = {1: ("-", "o"), 2: ("--", "s"), 3: (":", "^")}


def _plot(plt, series, column: str, kind: str, title: str, path: Path) -> None:
    """Error against time or h: a colour per method, a line style and marker per degree, the
    legend beside the axes (off the data)."""
    from contactfx.validation.bench import observed_rates

    colours = {
        label: PALETTE[i % len(PALETTE)]
        for i, label in enumerate(dict.fromkeys(label for label, _ in series))
    }
    fig, ax = plt.subplots(figsize=(8.4, 4.4))
    for (label, degree), srs in series.items():
        pts = [(r["t_run"] if kind == "time" else r["h"], r[column]) for r in srs]
        pts = [(x, e) for x, e in pts if math.isfinite(e) and e > 1e-10]
        if not pts:
            continue
        x, e = np.array(pts).T
        name = f"{label} P{degree}"
        if kind == "h" and len(pts) > 1:
            name += f" (rate {observed_rates(srs, column)[0]:.2f})"
        line, marker = DEGREE_STYLE.get(degree, ("-.", "v"))
        ax.loglog(
            x, e, linestyle=line, marker=marker, color=colours[label], label=name, markersize=4
        )
    ax.set_xlabel("wall time, assembly + solve [s]" if kind == "time" else "h (contact zone)")
    ax.set_ylabel("relative error")
    ax.set_title(title)
    ax.grid(True, which="both", alpha=0.3)
    if kind == "h":
        ax.invert_xaxis()
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def method_guide(rows: list[dict]) -> list[str]:
    """Markdown: for each case, from the bench rows, the most accurate method at the finest
    level it reached, the fastest method within twice that error (time of assembly + solve at
    that method's finest level), the one with the fewest Newton iterations there, and the
    methods that failed. The yardstick is the case's primary error (``PRIMARY``, most specific
    first) that is above round-off somewhere, else its first such measure."""
    from contactfx.results import PRIMARY
    from contactfx.validation.bench import MEASURES, ROUNDOFF

    lines = [
        "| case | yardstick | most accurate | fastest within 2x its error | "
        "fewest Newton | failed |",
        "|---|---|---|---|---|---|",
    ]
    for case in dict.fromkeys(r["case"] for r in rows):
        case_rows = [r for r in rows if r["case"] == case]
        measures = [m for m in MEASURES if _has(case_rows, m)]
        failed = sorted(
            {f"{r['method']} P{r['degree']}" for r in case_rows if r["status"] not in ("ok", "n/a")}
        )
        above = [m for m in measures if _has(case_rows, m, ROUNDOFF)]
        if not above:
            continue
        primary = [c for _, c in PRIMARY if c in above]
        m = primary[0] if primary else above[0]
        best: dict[tuple[str, int], dict] = {}
        for (label, degree), srs in _series(case_rows).items():
            ok = [r for r in srs if math.isfinite(r.get(m, math.nan))]
            if ok:
                best[(label, degree)] = max(ok, key=lambda r: r["level"])
        if not best:
            continue
        finest = max(r["level"] for r in best.values())
        top = {k: r for k, r in best.items() if r["level"] == finest}
        acc_key, acc = min(top.items(), key=lambda kv: kv[1][m])
        near = {k: r for k, r in top.items() if r[m] <= 2.0 * max(acc[m], ROUNDOFF_GUIDE)}
        fast_key, fast = min(near.items(), key=lambda kv: kv[1]["t_run"])
        few_key, few = min(top.items(), key=lambda kv: (kv[1]["newton"], kv[1]["t_run"]))

        def name(key):
            return f"{key[0]} P{key[1]}"

        lines.append(
            f"| {case} | {_escape(MEASURES[m][0])}, level {finest} "
            f"| {name(acc_key)} ({_cell(acc[m])}) "
            f"| {name(fast_key)} ({_cell(fast['t_run'])} s, {_cell(fast[m])}) "
            f"| {name(few_key)} ({few['newton']}) | {', '.join(failed) or 'none'} |"
        )
    return lines


#: errors below this are round-off: "within 2x" of it means at round-off too
ROUNDOFF_GUIDE = 1e-10


#: stress statuses that are not failures (a refusal is one only where the case expects it)
STRESS_SETTLED = ("converged", "n/a", "refused")


def write_stress(rows: list[dict], out: Path, ranks: int, total: float) -> list[Path]:
    """stress.csv, stress.md and gamma0.png; returns the paths written."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    written = [write_csv(rows, out / "stress.csv")]
    failed = [r for r in rows if r["status"] not in STRESS_SETTLED]
    md = [
        "# contactfx stress: robustness matrix",
        "",
        f"Machine: {machine(ranks)}. {len(rows)} cases, {len(failed)} not converged, "
        f"{total:.0f} s in all.",
        "",
        "penetration / h: largest nodal penetration over the contact element size; "
        "|g p| / (p0 h): nodal complementarity residual; error: against the closed form at "
        "the computed force (p L2: pressure in L2 on the contact boundary; punch p: "
        "pi sqrt(a^2 - x^2) p / P - 1 on |x| <= 0.8 a; Q = mu P: gross-slip force); energy "
        "balance error: a dynamic run's largest remainder of its energy balance over the "
        "largest energy (the scheme's dissipation and the balance's error).",
    ]
    cols = [
        ("case", "case"),
        ("method", "method"),
        ("status", "status"),
        ("newton", "Newton"),
        ("cutbacks", "cut-backs"),
        ("penetration_over_h", "penetration / h"),
        ("complementarity", "|g p| / (p0 h)"),
        ("error_measure", "error of"),
        ("error", "error"),
        ("p0_error", "p0 error"),
        ("energy_remainder", "energy balance error"),
        ("time", "time [s]"),
        ("reason", "reason"),
    ]
    for axis in dict.fromkeys(r["axis"] for r in rows):
        md += ["", f"## {axis}", "", markdown_table([r for r in rows if r["axis"] == axis], cols)]
    if any(r["axis"] == "gamma0" for r in rows):
        path = out / "gamma0.png"
        _plot_gamma0(rows, path)
        written.append(path)
        md += ["", "![error and Newton iterations against gamma0](gamma0.png)"]
    path = out / "stress.md"
    path.write_text("\n".join(md) + "\n")
    written.append(path)
    return written


def _plot_gamma0(rows: list[dict], path: Path) -> None:
    """The Nitsche robustness figure: error and Newton iterations against gamma0 per theta
    (failed solves are drawn as crosses at the top of the iterations panel)."""
    plt = _plt()
    fig, (ax_e, ax_n) = plt.subplots(1, 2, figsize=(10.0, 4.0))
    for theta, marker in ((1, "o"), (0, "s"), (-1, "^")):
        sel = [r for r in rows if r["axis"] == "gamma0" and f"theta={theta} " in r["case"]]
        _gamma0_lines(ax_e, ax_n, sel, marker, f"theta = {theta}")
    nodal = [r for r in rows if r["axis"] == "gamma0, nodal quadrature"]
    _gamma0_lines(ax_e, ax_n, nodal, "d", "theta = 1, nodal quadrature")
    ax_e.set_xlabel("gamma0")
    ax_e.set_ylabel("pressure error, L2 on contact (relative)")
    ax_n.set_xlabel("gamma0")
    ax_n.set_ylabel("Newton iterations (x: failed)")
    for ax in (ax_e, ax_n):
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle("Nitsche, Hertz 2D: robustness in gamma0")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _gamma0_lines(ax_e, ax_n, sel: list[dict], marker: str, label: str) -> None:
    g = [float(r["case"].split("g0=")[1].split()[0]) for r in sel]
    ok = [(gi, r) for gi, r in zip(g, sel, strict=True) if r["status"] == "converged"]
    bad = [gi for gi, r in zip(g, sel, strict=True) if r["status"] != "converged"]
    if ok:
        x = [gi for gi, _ in ok]
        ax_e.loglog(x, [r["error"] for _, r in ok], marker + "-", label=label)
        ax_n.semilogx(x, [r["newton"] for _, r in ok], marker + "-", label=label)
    if bad:
        ax_n.semilogx(bad, [50] * len(bad), "x", color="k", markersize=8)


def write_results_page(folder: Path, page: Path) -> Path:
    """The results page: the bench and stress Markdown of ``folder`` (bench/, stress/) under
    one heading, headings demoted one level and image links made relative to the page."""
    folder, page = Path(folder), Path(page)
    parts = [
        "# contactfx results",
        "",
        "Made by `make results` (`contactfx bench` and `contactfx stress`); the CSV files "
        "beside the plots hold every number.",
        "",
    ]
    for sub in ("bench", "stress"):
        md = folder / sub / f"{sub}.md"
        if not md.exists():
            raise OSError(f"{md} is missing: run contactfx {sub} --out {folder / sub} first")
        rel = os.path.relpath(folder / sub, page.parent)
        for line in md.read_text().splitlines():
            parts.append("#" + line if line.startswith("#") else line.replace("](", f"]({rel}/"))
        parts.append("")
    page.write_text("\n".join(parts))
    return page


if __name__ == "__main__":
    import sys

    print(f"wrote {write_results_page(Path(sys.argv[1]), Path(sys.argv[2]))}")
