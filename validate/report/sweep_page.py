"""The page of a sweep (``sweep ... --out DIR`` writes ``DIR/report.html``): what was swept and what
it found, the maps (the objective over the two most varied axes, and against the peak tension with the
Pareto front), the best configuration with its modes and sigmas, the grid-edge warnings, and the
MuJoCo check.

Built from ``DIR/summary.json`` and ``DIR/sweep.csv`` (docs/sweep.md), the CSV read row by row twice
and reduced as it goes, never held whole: the memory is that of the map's cells (at most
:data:`MAX_CELLS` along each axis, neighbouring values sharing a cell beyond), of a sample of at most
:data:`MAX_SCATTER` feasible rows (every k-th: :class:`Sample`, which ``sweep.png`` draws too) and of
the best row, whatever the number of rows.
"""

from __future__ import annotations

import bisect
import csv
import json
import math
from collections.abc import Iterator, Sequence
from pathlib import Path

import numpy as np

from bifilar.sweep.choose import objective

from .figures import png_bytes, pyplot
from .html import join, number, table, tag
from .page import Page, Section
from .sections import Facts, Table, Text, Warnings, figure

MAX_CELLS = 200  # along each drawn axis
MAX_SCATTER = 20_000  # feasible rows drawn against the peak tension at most
FIRST_RESULT = "period_1"  # the first column after the axis columns (docs/sweep.md)
_NOT_AXES = ("sigma", "objective", "tension_peak")  # the keys of a best or Pareto entry that are not axes


def _float(cell: str) -> float | None:
    return float(cell) if cell != "" else None


def read_rows(path: Path) -> tuple[list[str], Iterator[dict]]:
    """The axis names and a generator of rows (``values``, ``sigma``, ``feasible`` and every column,
    numbers as floats, empty cells as None), one at a time."""
    fh = open(path, newline="")
    reader = csv.reader(fh)
    header = next(reader)
    axes = header[: header.index(FIRST_RESULT)]

    def rows():
        with fh:
            for cells in reader:
                row = dict(zip(header, cells))
                yield {**row, "values": {a: float(row[a]) for a in axes},
                       "sigma": {a: _float(row[f"sigma_{a}"]) for a in "xyz"}, "feasible": row["feasible"] == "true"}

    return axes, rows()


class Sample:
    """At most :data:`MAX_SCATTER` of ``n`` points offered one at a time: every ``stride``-th, the
    stride fixed by ``n``, so the same points whoever draws them (this page and ``sweep.png``)."""

    def __init__(self, n: int):
        self.stride = max(1, math.ceil(n / MAX_SCATTER))
        self.points: list[tuple[float, float]] = []
        self._offered = 0

    def add(self, point: tuple[float, float]) -> None:
        if self._offered % self.stride == 0:
            self.points.append(point)
        self._offered += 1


def tension_panel(ax, sample: Sample, pareto: list[dict]) -> None:
    """The feasible rows' (peak tension, objective) sample, and the Pareto front (``summary.json``'s
    entries) in full, on a log objective axis (%)."""
    if sample.points:
        tension, score = np.array(sample.points, dtype=float).T
        ax.scatter(tension, 100.0 * score, s=6, color="grey",
                   label="feasible" + (f" (every {sample.stride}th)" if sample.stride > 1 else ""))
    ax.plot([p["tension_peak"] for p in pareto], [100.0 * p["objective"] for p in pareto], "o-",
            color="tab:orange", label="Pareto front")
    ax.set(xlabel="peak tension (N)", yscale="log")
    ax.legend(fontsize=8)


class _Reduction:
    """The sweep's rows reduced as they pass: the objective's least per map cell, a sample of the
    feasible rows' (peak tension, objective), and the best row's columns."""

    def __init__(self, path: Path, summary: dict, measure: Sequence[str], kind: str):
        self.measure, self.kind = list(measure), kind
        axes, rows = read_rows(path)
        distinct = {a: set() for a in axes}  # capped: beyond MAX_CELLS values, only the range matters
        low, high = {a: math.inf for a in axes}, {a: -math.inf for a in axes}
        best = summary.get("best")
        self.best_row = None
        self.sample = Sample(summary["n"])
        for row in rows:
            for a, v in row["values"].items():
                low[a], high[a] = min(low[a], v), max(high[a], v)
                if len(distinct[a]) <= MAX_CELLS:
                    distinct[a].add(v)
            score = objective(row, self.measure, kind)
            if math.isfinite(score):
                self.sample.add((_float(row["tension_peak"]), score))
            if best is not None and self.best_row is None and all(row["values"][a] == best[a] for a in axes):
                self.best_row = row
        self.shown = sorted(axes, key=lambda a: -len(distinct[a]))[:2]
        self.shown = [a for a in self.shown if len(distinct[a]) > 1]
        self.edges = []  # per shown axis: the cell boundaries (values, cell index by searchsorted)
        for a in self.shown:
            if len(distinct[a]) <= MAX_CELLS:
                values = np.array(sorted(distinct[a]))
                self.edges.append((values, np.concatenate([[-math.inf], 0.5 * (values[1:] + values[:-1])])))
            else:
                bounds = np.linspace(low[a], high[a], MAX_CELLS + 1)
                self.edges.append((0.5 * (bounds[1:] + bounds[:-1]), np.concatenate([[-math.inf], bounds[1:-1]])))
        self.least = np.full(tuple(len(c) for c, _ in reversed(self.edges)), math.inf)  # (y, x)
        bounds = [(a, b.tolist()) for a, (_, b) in reversed(list(zip(self.shown, self.edges)))]
        _, rows = read_rows(path)
        for row in rows:
            at = tuple(bisect.bisect_right(b, row["values"][a]) - 1 for a, b in bounds)
            self.least[at] = min(self.least[at], objective(row, self.measure, kind))

    def figure(self, summary: dict) -> bytes:
        plt = pyplot()
        from matplotlib.colors import LogNorm

        fig, (left, right) = plt.subplots(1, 2, figsize=(12, 4.6))
        best = summary.get("best")
        shown = np.where(np.isfinite(self.least), 100.0 * self.least, np.nan)
        positive = shown[np.isfinite(shown) & (shown > 0)]
        norm = LogNorm(positive.min(), positive.max()) if positive.size else None
        if len(self.shown) == 2:
            (xs, _), (ys, _) = self.edges
            mesh = left.pcolormesh(xs, ys, shown, shading="nearest", cmap="viridis", norm=norm)
            left.set_facecolor("0.75")  # no feasible configuration in the cell
            fig.colorbar(mesh, ax=left, label="objective (%)")
            if best:
                left.scatter([best[self.shown[0]]], [best[self.shown[1]]], marker="*", s=220, color="white",
                             edgecolor="black", label="best")
                left.legend(loc="upper right", fontsize=8)
            left.set(xlabel=f"{self.shown[0]} (m)", ylabel=f"{self.shown[1]} (m)",
                     title="least objective over the axes not drawn; grey: none feasible")
        elif len(self.shown) == 1:
            (xs, _), = self.edges
            left.plot(xs, shown, "o-", ms=3)
            left.set(xlabel=f"{self.shown[0]} (m)", ylabel="objective (%)", yscale="log", title="least objective")
        else:
            left.set_axis_off()
        tension_panel(right, self.sample, summary.get("pareto") or [])
        right.set(ylabel="objective (%)", title="objective against peak tension")
        return png_bytes(fig)


class MapsSection(Section):
    title = "Maps and the Pareto front"
    open = True

    def __init__(self, reduction: _Reduction, summary: dict):
        self.reduction, self.summary = reduction, summary

    def body(self) -> str:
        front = [(", ".join(f"{a} = {v:g}" for a, v in p.items() if a not in _NOT_AXES),
                  f"{100.0 * p['objective']:.4g} %", number(p["tension_peak"], 5, "N"),
                  ", ".join(f"{a} {100.0 * s:.4g} %" for a, s in p["sigma"].items()))
                 for p in self.summary.get("pareto") or []]
        return join([figure(self.reduction.figure(self.summary), "left: the objective over the two most varied "
                            "axes; right: the feasible configurations' objective against their peak tension, and "
                            "the Pareto front"),
                     tag("p", "The Pareto front: no other configuration beats these in both the objective and the "
                              "peak tension."),
                     table(("configuration", "objective", "peak tension", "sigmas"), front)])


def best_section(row: dict | None, summary: dict) -> Section:
    if row is None:
        return Text("Best configuration", ["No configuration is feasible."])
    best = summary["best"]
    modes = [(k, row[f"motion_{k}"], number(_float(row[f"period_{k}"]), 9, "s") if row[f"period_{k}"] else "neutral")
             for k in range(1, 5)]
    sigmas = [(a, f"{100.0 * float(row[f'sigma_{a}']):.4g} %" if row[f"sigma_{a}"] else "not measured",
               row[f"dominant_{a}"] or "-") for a in "xyz"]
    items = [("configuration", ", ".join(f"{a} = {v:g} m" for a, v in row["values"].items())),
             ("objective", f"{100.0 * best['objective']:.4g} % ({summary['objective']})"),
             ("peak tension", number(best["tension_peak"], 5, "N")),
             ("static tensions", f"{number(_float(row['tension_1']), 6)}, {number(_float(row['tension_2']), 6)} N"),
             ("clearance", number(_float(row["clearance"]), 4, "m")),
             ("period separation", number(_float(row["separation"]), 3))]
    return _BestSection(items, modes, sigmas)


class _BestSection(Section):
    title = "Best configuration"
    open = True

    def __init__(self, items, modes, sigmas):
        self.items, self.modes, self.sigmas = items, modes, sigmas

    def body(self) -> str:
        return join([Facts("", self.items).body(), table(("mode", "motion", "period"), self.modes),
                     table(("body axis", "relative sigma of the moment", "largest share of its variance"), self.sigmas)])


def mujoco_section(summary: dict) -> Section:
    checked = summary.get("mujoco_check") or []
    if not checked:
        return Text("MuJoCo check", ["Not run (sweep --check-mujoco K runs the K best configurations in MuJoCo)."])
    rows, classes = [], []
    for rank, c in enumerate(checked, start=1):
        where = ", ".join(f"{a} = {v:g}" for a, v in c["configuration"].items())
        for m in c["modes"]:
            rows.append((rank, where, m["axis"], m["motion"], number(m["predicted"], 9, "s"), number(m["mujoco"], 9, "s"),
                         number(m["period_rel_error"], 3), number(m["tension_rel_error"], 3), "ok" if c["ok"] else "FAILED"))
            classes.append(None if c["ok"] else "fail")
    return Table("MuJoCo check", ("rank", "configuration", "axis", "motion", "predicted period", "MuJoCo period",
                                  "period rel. difference", "tension rel. difference", ""), rows,
                 note="Each measured mode of the best configurations run in MuJoCo against the sweep's prediction: "
                      "ok within 1e-6.", row_classes=classes)


def sweep_page(folder: str | Path, measure: Sequence[str], kind: str, title: str = "") -> Page:
    """The page of the sweep whose outputs are in ``folder``; ``measure`` and ``kind`` define the
    objective (the sweep file's ``[measure]`` axes and ``objective``)."""
    folder = Path(folder)
    summary = json.loads((folder / "summary.json").read_text())
    reduction = _Reduction(folder / "sweep.csv", summary, measure, kind)
    page = Page(title or f"sweep: {summary['n']} configurations",
                f"{summary['feasible']} of {summary['n']} feasible; objective: {summary['objective']}")
    best = summary.get("best")
    page.add(Facts("Summary", [
        ("configurations", f"{summary['n']}, {summary['feasible']} feasible"),
        ("objective", summary["objective"]),
        ("best", "none feasible" if best is None else
         ", ".join(f"{a} = {v:g}" for a, v in best.items() if a not in _NOT_AXES) +
         f": {100.0 * best['objective']:.4g} %, peak tension {number(best['tension_peak'], 5, 'N')}"),
        ("evaluation time", f"{summary['seconds']:.1f} s"),
        ("outputs", ", ".join(summary.get("files") or ["sweep.csv", "summary.json"]))]))
    page.add(Warnings("Grid-edge warnings", [e["text"] for e in summary.get("edges") or []]),
             best_section(reduction.best_row, summary), MapsSection(reduction, summary), mujoco_section(summary))
    return page


def write_sweep_html(folder: str | Path, measure: Sequence[str], kind: str, title: str = "") -> Path:
    """Write ``folder/report.html`` (:func:`sweep_page`) whole or not at all; returns its path."""
    return sweep_page(folder, measure, kind, title).write(Path(folder) / "report.html")
