"""``sweep --rerun``: the sweep table and the MuJoCo check in one rerun recording, ``DIR/sweep.rrd``.

The table, on a ``configuration`` timeline (the row index, grid order, as in ``sweep.csv``):
``sweep/series/objective`` and ``sweep/series/sigma_<axis>`` (relative, feasible rows only),
``sweep/series/tension_peak`` (N), ``sweep/series/period_<k>`` (s, the k-th longest mode, rows that
have it), ``sweep/series/feasible`` (1 or 0, every row) and ``sweep/series/axes/<axis>`` (the varied
values, m); and, static, ``sweep/map``: every configuration as
a point at its values of the (up to) three most varied axes (world x, y, z = those axes, m), coloured by
the objective (viridis from 0 to the largest feasible objective; red: infeasible), labelled with its
values, sigmas and, if infeasible, the reason; ``sweep/map/best`` marks the best. The runs of the
MuJoCo check (each measured mode of each checked configuration, named ``rank<n>_<axis>``) are drawn and
plotted by :func:`validate.recording.record`, which also writes the file whole or not at all.

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

from bifilar.sweep.choose import best, objective
from bifilar.sweep.space import Space

from ..recording import Extra, record, tension_colors
from ..trajectory import Trajectory
from .sweep_check import Checked

TIMELINE = "configuration"
MODES = 4  # a row's periods: sweep.csv's period_1 .. period_4 (None for a neutral or absent mode)
SIGMAS = ("x", "y", "z")


def record_sweep(path: str | Path, space: Space, rows: list[dict], checked: list[Checked]) -> Path:
    """Write ``path`` (see the module docstring); ``checked`` in rank order (may be empty)."""
    runs = [Trajectory(t.engine, t.t, t.channels, {**t.meta, "rig": f"rank{rank}_{axis}"})
            for rank, c in enumerate(checked, start=1) for axis, t in c.runs.items()]
    lines = [f"{len(rows)} configurations, {sum(r['feasible'] for r in rows)} feasible; objective: "
             f"{space.objective} relative sigma over {list(space.measure)}"]
    for rank, c in enumerate(checked, start=1):
        values = ", ".join(f"{a} = {v:g}" for a, v in c.entry["configuration"].items())
        lines.append(f"MuJoCo check rank{rank} ({values}): largest period difference "
                     f"{c.entry['period_rel_error']:.2e}, {'ok' if c.entry['ok'] else 'FAILED'}")
    return record(path, f"sweep of {Path(space.source).name}", runs, note="\n".join(lines),
                  extra=Extra(partial(_log_table, space=space, rows=rows), _views(space)), timeline=TIMELINE)


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


def _log_table(rec: rr.RecordingStream, space: Space, rows: list[dict]) -> None:
    index = np.arange(len(rows))
    score = np.array([objective(r, space.measure, space.objective) for r in rows])
    ok = np.isfinite(score)

    def series(name: str, values: np.ndarray, keep: np.ndarray) -> None:
        rec.log(f"sweep/series/{name}", rr.SeriesPoints(names=[name], marker_sizes=[2.0]), static=True)
        if keep.any():
            rec.send_columns(f"sweep/series/{name}", [rr.TimeColumn(TIMELINE, sequence=index[keep])],
                             rr.Scalars.columns(scalars=values[keep]))

    series("objective", score, ok)
    for a in space.measure:
        sigma = np.array([math.nan if r["sigma"][a] is None else r["sigma"][a] for r in rows])
        series(f"sigma_{a}", sigma, np.isfinite(sigma))
    peak = np.array([math.nan if r["tension_peak"] is None else r["tension_peak"] for r in rows], dtype=float)
    series("tension_peak", peak, np.isfinite(peak))
    for k in range(MODES):
        period = np.array([math.nan if r["periods"][k] is None else r["periods"][k] for r in rows], dtype=float)
        series(f"period_{k + 1}", period, np.isfinite(period))
    series("feasible", np.array([1.0 if r["feasible"] else 0.0 for r in rows]), np.ones(len(rows), dtype=bool))
    for a in space.axes:
        series(f"axes/{a}", np.array([r["values"][a] for r in rows]), np.ones(len(rows), dtype=bool))

    shown = sorted(space.axes, key=lambda a: -len(space.axes[a]))[:3]
    positions = np.zeros((len(rows), 3))
    for k, a in enumerate(shown):
        positions[:, k] = [r["values"][a] for r in rows]
    steps = [np.diff(space.axes[a]).min() for a in shown if len(space.axes[a]) > 1]
    radius = 0.2 * min(steps, default=0.05)  # a fifth of the finest grid step: neighbours stay apart
    top = float(score[ok].max()) if ok.any() else 1.0
    rec.log("sweep/map", rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
    rec.log("sweep/map", rr.Points3D(positions, radii=radius, colors=tension_colors(np.where(ok, score, -1.0), top),
                                     labels=[_label(space, r, s) for r, s in zip(rows, score)]), static=True)
    winner = best(rows, space.measure, space.objective)
    if winner is not None:
        i = rows.index(winner)
        rec.log("sweep/map/best", rr.Points3D(positions[i : i + 1], radii=2.5 * radius, colors=[(255, 255, 255)],
                                              labels=["best: " + _label(space, winner, score[i])]), static=True)


def _label(space: Space, row: dict, score: float) -> str:
    values = ", ".join(f"{a} = {row['values'][a]:g}" for a in space.axes)
    if not math.isfinite(score):
        return f"{values}: infeasible ({row['reason'] or 'an axis not identifiable'})"
    sigmas = ", ".join(f"sigma_{a} {100 * row['sigma'][a]:.3g} %" for a in space.measure)
    return f"{values}: {space.objective} {100 * score:.3g} % ({sigmas})"
