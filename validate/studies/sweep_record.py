"""``sweep --rerun``: the sweep table and the MuJoCo check in one rerun recording, ``DIR/sweep.rrd``.

The table, on a ``configuration`` timeline (the row index, grid order, as in ``sweep.csv``):
``sweep/series/objective`` and ``sweep/series/sigma_<axis>`` (relative, feasible rows only),
``sweep/series/tension_peak`` (N), ``sweep/series/period_<k>`` (s, the k-th longest mode, rows that
have it), ``sweep/series/feasible`` (1 or 0, every row) and ``sweep/series/axes/<axis>`` (the varied
values, m); and, static, ``sweep/map``: every configuration as
a point at its values of the (up to) three most varied axes (world x, y, z = those axes, m), coloured by
the objective (viridis from 0 to the largest feasible objective; red: infeasible), labelled with its
values, sigmas and, if infeasible, the reason (up to :data:`LABELLED` rows; a larger grid's points are
unlabelled); ``sweep/map/best`` marks the best (labelled always). The runs of the
MuJoCo check (each measured mode of each checked configuration, named ``rank<n>_<axis>``) are drawn and
plotted by :func:`validate.recording.record`, which also writes the file whole or not at all.

The table is built as the sweep's rows pass (:class:`Columns`), never from the rows held: it holds a few
floats per row, ~100 B (and the map's labels, ~150 B per row, only up to :data:`LABELLED` rows).

The viewer opens on the ``configuration`` timeline, with tabs before the check's runs: the map in 3D,
the sigmas, periods and peak tension per configuration, and the table (every series, one row per
configuration).
"""

from __future__ import annotations

import math
from functools import partial
from pathlib import Path

import numpy as np
import rerun as rr
import rerun.blueprint as rrb

from bifilar.sweep.space import Space

from ..recording import Extra, record, tension_colors
from ..trajectory import Trajectory
from .sweep_check import Checked

TIMELINE = "configuration"
MODES = 4  # a row's periods: sweep.csv's period_1 .. period_4 (None for a neutral or absent mode)
LABELLED = 10**5  # rows: the map's points are labelled up to this many (~15 MB of labels)
SIGMAS = ("x", "y", "z")


class Columns:
    """The recording's table, filled as the rows pass (no row kept): one float per row and series
    (the objective, the measured sigmas, the peak tension, the four periods, feasible and each axis's
    value: ~100 B per row for three axes and three sigmas, NaN where a row has none), and the map's
    labels (strings of ~150 B) only for a grid of at most :data:`LABELLED` rows; beyond, the map's
    points are unlabelled, so that the recording stays ~100 B per row."""

    def __init__(self, space: Space, size: int):
        self.space, self.n = space, 0
        names = (["objective"] + [f"sigma_{a}" for a in space.measure] + ["tension_peak"]
                 + [f"period_{k}" for k in range(1, MODES + 1)] + ["feasible"] + [f"axes/{a}" for a in space.axes])
        self.series = {name: np.empty(size) for name in names}  # sweep/series/<name>
        self.labels: list[str] | None = [] if size <= LABELLED else None

    def add(self, row: dict, score: float) -> None:
        """Take the next row in grid order and its objective (inf if infeasible)."""
        space = self.space
        values = ([score] + [row["sigma"][a] for a in space.measure] + [row["tension_peak"]] + list(row["periods"][:MODES])
                  + [1.0 if row["feasible"] else 0.0] + [row["values"][a] for a in space.axes])
        for column, value in zip(self.series.values(), values):
            column[self.n] = math.nan if value is None else value
        if self.labels is not None:
            self.labels.append(_label(space, row, score))
        self.n += 1


def record_sweep(path: str | Path, space: Space, table: Columns, best: tuple[int, dict] | None,
                 checked: list[Checked]) -> Path:
    """Write ``path`` (see the module docstring): ``table`` filled with every row, ``best`` the best
    row's (grid index, row) or None, ``checked`` in rank order (may be empty)."""
    runs = [Trajectory(t.engine, t.t, t.channels, {**t.meta, "rig": f"rank{rank}_{axis}"})
            for rank, c in enumerate(checked, start=1) for axis, t in c.runs.items()]
    lines = [f"{table.n} configurations, {int(table.series['feasible'].sum())} feasible; objective: "
             f"{space.objective} relative sigma over {list(space.measure)}"]
    for rank, c in enumerate(checked, start=1):
        values = ", ".join(f"{a} = {v:g}" for a, v in c.entry["configuration"].items())
        lines.append(f"MuJoCo check rank{rank} ({values}): largest period difference "
                     f"{c.entry['period_rel_error']:.2e}, {'ok' if c.entry['ok'] else 'FAILED'}")
    return record(path, f"sweep of {Path(space.source).name}", runs, note="\n".join(lines),
                  extra=Extra(partial(_log_table, space=space, table=table, best=best), _views(space)),
                  timeline=TIMELINE)


def _views(space: Space) -> tuple:
    """The map; sigmas and objective, periods and peak tension over the configurations; the table."""

    def plot(name: str, entities: list[str]) -> rrb.TimeSeriesView:
        return rrb.TimeSeriesView(origin="sweep/series", name=name, contents=[f"+ $origin/{e}" for e in entities])

    per_configuration = rrb.Vertical(
        plot("relative sigma", ["objective"] + [f"sigma_{a}" for a in space.measure]),
        plot("periods (s)", [f"period_{k}" for k in range(1, MODES + 1)]),
        plot("peak tension (N)", ["tension_peak"]), name="per configuration")
    table = rrb.DataframeView(origin="sweep/series", name="table",
                              query=rrb.archetypes.DataframeQuery(timeline=TIMELINE))
    return (rrb.Spatial3DView(origin="sweep/map", name="configurations"), per_configuration, table)


def _log_table(rec: rr.RecordingStream, space: Space, table: Columns, best: tuple[int, dict] | None) -> None:
    index = np.arange(table.n)
    score = table.series["objective"]
    for name, values in table.series.items():  # each series where the rows have it
        keep = np.isfinite(values)
        rec.log(f"sweep/series/{name}", rr.SeriesPoints(names=[name], marker_sizes=[2.0]), static=True)
        if keep.any():
            rec.send_columns(f"sweep/series/{name}", [rr.TimeColumn(TIMELINE, sequence=index[keep])],
                             rr.Scalars.columns(scalars=values[keep]))

    shown = sorted(space.axes, key=lambda a: -len(space.axes[a]))[:3]
    positions = np.zeros((table.n, 3))
    for k, a in enumerate(shown):
        positions[:, k] = table.series[f"axes/{a}"]
    steps = [np.diff(space.axes[a]).min() for a in shown if len(space.axes[a]) > 1]
    radius = 0.2 * min(steps, default=0.05)  # a fifth of the finest grid step: neighbours stay apart
    ok = np.isfinite(score)
    top = float(score[ok].max()) if ok.any() else 1.0
    rec.log("sweep/map", rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
    rec.log("sweep/map", rr.Points3D(positions, radii=radius, colors=tension_colors(np.where(ok, score, -1.0), top),
                                     labels=table.labels), static=True)
    if best is not None:
        i, winner = best
        rec.log("sweep/map/best", rr.Points3D(positions[i : i + 1], radii=2.5 * radius, colors=[(255, 255, 255)],
                                              labels=["best: " + _label(space, winner, score[i])]), static=True)


def _label(space: Space, row: dict, score: float) -> str:
    values = ", ".join(f"{a} = {row['values'][a]:g}" for a in space.axes)
    if not math.isfinite(score):
        return f"{values}: infeasible ({row['reason'] or 'an axis not identifiable'})"
    sigmas = ", ".join(f"sigma_{a} {100 * row['sigma'][a]:.3g} %" for a in space.measure)
    return f"{values}: {space.objective} {100 * score:.3g} % ({sigmas})"
