"""``python -m validate sweep SPACE.toml --out DIR``: a parameter sweep of suspension configurations.

Writes, whole or not at all, ``DIR/sweep.csv`` (one row per configuration; columns: the varied axes,
``period_1..period_4`` (s, longest first, empty for a neutral mode), ``tension_1,tension_2`` (N at rest),
``tension_peak`` (N), ``sigma_x,sigma_y,sigma_z`` (relative standard deviation of the identified moment;
empty where not measured or not identifiable), ``clearance`` (m above the floor), ``feasible``, then
``motion_1..motion_4``, ``dominant_x..z`` (the uncertainty group with the largest share), ``separation``
(smallest relative gap between two mode periods), ``reason`` (why a row is infeasible) and
``air_share_x..z`` (for a rig with ``[air]``: the air's share of each measured period, 1 - (T_vacuum/T)^2),
``near_x..z`` (each measured mode's relative gap in frequency to the nearest other mode: under ~1.5
beats over a record a sway of it hides in the amplitude law; ``limits.separation`` sets a least one)), and
``DIR/summary.json`` (n, feasible, objective, best, pareto, seconds, mujoco_check) and ``DIR/report.html``
(one self-contained page of them: :mod:`validate.report.sweep_page`). ``--check-mujoco K``
runs the K best configurations in MuJoCo (:mod:`validate.studies.sweep_check`) and fails (exit 1) on a
disagreement over 1e-6. ``--png`` adds ``DIR/sweep.png``:
the objective over the two most varied axes (the best over the others), infeasible points marked, and the
Pareto front; ``--rerun`` adds ``DIR/sweep.rrd``, the table and the check's motions
(:mod:`validate.studies.sweep_record`). The evaluation is :mod:`bifilar.sweep`. ``DIR/.lock`` is held
for the whole run: a second sweep into ``DIR`` meanwhile is refused (exit 2).

The rows are never held: one pass over the chunk files (:class:`bifilar.sweep.run.Chunks`) writes the
CSV and folds each row into the summary's choice, the figure's cells and sample and the recording's
columns, so the memory does not grow with the grid (but for ``--rerun``'s ~100 B per row;
``benchmarks/sweep_memory.py`` measures it).
"""

from __future__ import annotations

import csv
import json
import math
import sys
import time
from pathlib import Path

from ..argtypes import UsageError, whole_number
from ..statuses import epilog

COLUMNS_AFTER_AXES = (
    ["period_1", "period_2", "period_3", "period_4", "tension_1", "tension_2", "tension_peak",
     "sigma_x", "sigma_y", "sigma_z", "clearance", "feasible"]
    + [f"motion_{k}" for k in range(1, 5)] + ["dominant_x", "dominant_y", "dominant_z", "separation", "reason"]
    + ["air_share_x", "air_share_y", "air_share_z", "near_x", "near_y", "near_z"]
)


def add_parser(subparsers) -> None:
    """Register the ``sweep`` subcommand on the CLI's subparsers."""
    p = subparsers.add_parser("sweep", help="sweep suspension configurations: periods, sigma, tensions, the best rig",
                              epilog=epilog("sweep", ("python -m validate sweep bench_plate --out sweep/ --png",)))
    p.add_argument("space", metavar="SPACE.toml", help="the sweep file (format: bifilar/sweep/space.py)")
    p.add_argument("--out", required=True, metavar="DIR", help="folder for sweep.csv, summary.json (and sweep.png)")
    p.add_argument("--jobs", type=whole_number("--jobs", 1, 256), default=None, metavar="N",
                   help="local processes (default: every core)")
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="run on a Dask distributed cluster at ADDRESS (e.g. tcp://127.0.0.1:8786) instead")
    p.add_argument("--png", action="store_true", help="also draw DIR/sweep.png (objective map, Pareto front)")
    p.add_argument("--check-mujoco", type=whole_number("--check-mujoco", 0, 100), default=0, metavar="K",
                   help="run the K best configurations in MuJoCo and compare periods and tensions "
                        "(exit 1 if any differs by more than 1e-6; default 0: no check)")
    p.add_argument("--rerun", action="store_true",
                   help="also write DIR/sweep.rrd: the table and the MuJoCo check's motions "
                        "(open: rerun DIR/sweep.rrd)")


def _cell(x) -> str:
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return ""
    if isinstance(x, bool):
        return "true" if x else "false"
    return repr(float(x)) if isinstance(x, (int, float)) else str(x)


def csv_row(axes: list[str], r: dict) -> list[str]:
    """The cells of row ``r`` in ``sweep.csv``: the axes' values, then :data:`COLUMNS_AFTER_AXES`."""
    return ([_cell(r["values"][a]) for a in axes] + [_cell(p) for p in r["periods"]]
            + [_cell(t) for t in r["tensions"]] + [_cell(r["tension_peak"])]
            + [_cell(r["sigma"][a]) for a in ("x", "y", "z")] + [_cell(r["clearance"]), _cell(r["feasible"])]
            + list(r["motions"]) + [r["dominant"][a] or "" for a in ("x", "y", "z")]
            + [_cell(r["separation"]), r["reason"]] + [_cell(r["air_share"][a]) for a in ("x", "y", "z")]
            + [_cell(r["near"][a]) for a in ("x", "y", "z")])


def _wrap(text: str) -> str:
    """A report line wrapped at 100 columns (continuations indented; paths and words kept whole)."""
    import textwrap

    return textwrap.fill(text, width=100, subsequent_indent="  ", break_on_hyphens=False, break_long_words=False)


def summary(space, choice, seconds: float) -> dict:
    """``summary.json``'s entries from the rows' :class:`~bifilar.sweep.choose.Choice`."""
    from bifilar.sweep.choose import edges, objective

    def point(r):
        return {**r["values"], "sigma": {a: r["sigma"][a] for a in space.measure},
                "objective": objective(r, space.measure, space.objective), "tension_peak": r["tension_peak"]}

    top = choice.best[1] if choice.best else None
    return {
        "n": choice.n,
        "feasible": choice.feasible,
        "objective": f"{space.objective} relative sigma over {list(space.measure)}, feasible rows only",
        "best": point(top) if top else None,
        "pareto": [point(r) for r in choice.front.rows],
        "edges": edges(space.axes, top, space.explicit),
        "seconds": seconds,
        "mujoco_check": [],
    }


class Drawing:
    """What ``sweep.png`` draws, folded in as the rows pass, in memory independent of their number:
    the least objective per cell of the two most varied axes' grid, and a sample of the feasible rows'
    (peak tension, objective) (:class:`validate.report.sweep_page.Sample`)."""

    def __init__(self, space):
        import numpy as np

        from ..report.sweep_page import Sample

        self.axes = sorted(space.axes, key=lambda a: -len(space.axes[a]))[:2]  # x, y
        self.values = [space.axes[a] for a in self.axes]
        self.least = np.full((len(self.values[1]), len(self.values[0])), math.inf) if len(self.axes) == 2 else None
        self.sample = Sample(space.size)

    def add(self, row: dict, score: float) -> None:
        import numpy as np

        if self.least is not None:
            (x, y), (xs, ys) = (row["values"][a] for a in self.axes), self.values
            at = int(np.argmin(abs(ys - y))), int(np.argmin(abs(xs - x)))
            self.least[at] = min(self.least[at], score)
        if math.isfinite(score):
            self.sample.add((row["tension_peak"], score))


def figure(space, drawing: Drawing, data: dict, path: Path) -> None:
    """Objective over the two most varied axes (least over the others) and, against the peak tension,
    the feasible rows (a sample of at most :data:`~validate.report.sweep_page.MAX_SCATTER`) and the
    Pareto front; ``data`` is ``summary.json``'s."""
    import numpy as np

    from ..report.figures import png_bytes, pyplot
    from ..report.sweep_page import tension_panel
    from ..trajectory import atomic_write_bytes

    plt = pyplot()
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.5))
    if drawing.least is not None:
        axes, (xs, ys), grid, top = drawing.axes, drawing.values, drawing.least, data["best"]
        shown = np.where(np.isfinite(grid), grid, np.nan)
        mesh = left.pcolormesh(xs, ys, 100 * shown, shading="nearest", cmap="viridis")
        fig.colorbar(mesh, ax=left, label=f"{space.objective} sigma (%)")
        bad = ~np.isfinite(grid)
        gx, gy = np.meshgrid(xs, ys)
        left.scatter(gx[bad], gy[bad], marker="x", color="red", s=12, label="infeasible")
        if top:
            left.scatter([top[axes[0]]], [top[axes[1]]], marker="*", s=200, color="white",
                         edgecolor="black", label="best")
        hidden = [a for a in space.axes if a not in axes and len(space.axes[a]) > 1]
        left.set_title("least over " + ", ".join(hidden) + " in each cell" if hidden else "every configuration",
                       fontsize=9)
        for k, edge in enumerate(data["edges"]):
            left.annotate(f"best on the {edge['side']} edge of {edge['axis']}: widen {edge['widen']}",
                          xy=(0.01, 0.01 + 0.05 * k), xycoords="axes fraction", fontsize=7, color="red")
        left.set_xlabel(f"{axes[0]} (m)")
        left.set_ylabel(f"{axes[1]} (m)")
        left.legend(loc="upper right", fontsize=8)
    tension_panel(right, drawing.sample, data["pareto"])
    right.set_ylabel(f"{space.objective} sigma (%)")
    fig.suptitle(f"sweep of {Path(space.source).name}: {data['n']} configurations")
    atomic_write_bytes(path, png_bytes(fig, dpi=110))


def run(args) -> int:
    from bifilar.sweep.run import InUse, lock
    from bifilar.sweep.space import load_space

    from ..outputs import check_writable

    out = Path(args.out)
    if args.scheduler is not None and not args.scheduler.strip():  # not a quiet fall-back to local processes
        raise UsageError(f"sweep: --scheduler {args.scheduler!r}: empty; give the address, e.g. tcp://127.0.0.1:8786")
    if args.rerun:
        check_writable(out / "sweep.rrd")  # a bad path fails now, not after the sweep
    space = load_space(args.space)
    out.mkdir(parents=True, exist_ok=True)
    try:
        held = lock(out)
    except InUse as exc:
        raise UsageError(f"sweep: {out} is in use by another sweep (lock {exc})") from None
    with held:  # the whole sweep: chunks, outputs and their clean-up
        return _sweep(args, space, out)


def _sweep(args, space, out: Path) -> int:
    import os
    import shutil

    from bifilar.sweep.run import Unreachable, run as run_sweep

    from ..trajectory import atomic_file, atomic_write_text

    jobs = args.jobs or os.cpu_count() or 1
    start = time.perf_counter()
    bar = None
    if sys.stderr.isatty():
        from tqdm import tqdm

        bar = tqdm(total=space.size, unit="config", file=sys.stderr)

        def progress(n):
            bar.update(n - bar.n)
    else:
        progress = None
    try:
        chunks = run_sweep(args.space, space, out, jobs=jobs, scheduler=args.scheduler, progress=progress)
    except Unreachable as exc:
        raise UsageError(f"sweep: --scheduler {args.scheduler}: {exc}") from None
    finally:
        if bar is not None:
            bar.close()
    seconds = time.perf_counter() - start
    # sweep.csv is renamed into place after the check, as the other outputs are written: all or none
    with atomic_file(out / "sweep.csv") as fh:
        choice, drawing, table = _one_pass(space, chunks, fh, args)
        data = summary(space, choice, seconds)
        checked = []
        if args.check_mujoco:
            from ..studies.sweep_check import check

            checked = check(space, [row["values"] for _, row in choice.ranking.ranked()[: args.check_mujoco]])
            data["mujoco_check"] = [c.entry for c in checked]
    data["files"] = (["sweep.csv", "summary.json"] + (["sweep.png"] if args.png else []) + ["report.html"]
                     + (["sweep.rrd"] if args.rerun else []))
    atomic_write_text(out / "summary.json", json.dumps(data, indent=1, allow_nan=False) + "\n")
    if args.png:
        figure(space, drawing, data, out / "sweep.png")
    from ..report.sweep_page import write_sweep_html

    write_sweep_html(out, space.measure, space.objective, f"sweep of {Path(args.space).name}")
    if args.rerun:
        from ..studies.sweep_record import record_sweep

        record_sweep(out / "sweep.rrd", space, table, choice.best, checked)
    shutil.rmtree(out / ".chunks", ignore_errors=True)  # the sweep is whole: the resume files are spent
    failed = [c for c in data["mujoco_check"] if not c["ok"]]
    top = data["best"]
    best_text = ("no feasible configuration" if top is None else
                 "best " + ", ".join(f"{a} = {top[a]:g}" for a in space.axes) + f": {space.objective} sigma "
                 f"{100 * top['objective']:.3g} %, peak tension {top['tension_peak']:.4g} N")
    print(_wrap(f"sweep {Path(args.space).name}: {data['n']} configurations, {data['feasible']} feasible, "
          f"{seconds:.1f} s on {1 if args.scheduler is None and jobs == 1 else jobs} worker(s); {best_text}; "
          f"wrote {', '.join(str(out / f) for f in data['files'])}"))
    for edge in data["edges"]:
        print(_wrap(f"warning: {edge['text']}"))
    if data["mujoco_check"]:
        worst = max(c["period_rel_error"] for c in data["mujoco_check"])
        print(f"MuJoCo check of the {len(data['mujoco_check'])} best: largest period difference {worst:.2e}"
              + (f"; {len(failed)} over 1e-6" if failed else " (<= 1e-6)"))
    return 1 if failed else 0


def _one_pass(space, chunks, csv_file, args):
    """One pass over the rows in grid order, none kept: each written to ``csv_file`` (sweep.csv's
    text) and folded into the choice (count, best, Pareto front, the ``--check-mujoco K`` best), the
    figure's :class:`Drawing` (with ``--png``) and the recording's columns (with ``--rerun``); returns
    (choice, drawing or None, columns or None)."""
    from bifilar.sweep.choose import Choice

    axes = list(space.axes)
    choice = Choice(space.measure, space.objective, keep=args.check_mujoco)
    drawing = Drawing(space) if args.png else None
    table = None
    if args.rerun:
        from ..studies.sweep_record import Columns

        table = Columns(space, chunks.size)
    writer = csv.writer(csv_file, lineterminator="\n")
    writer.writerow(axes + COLUMNS_AFTER_AXES)
    for row in chunks.rows():
        writer.writerow(csv_row(axes, row))
        score = choice.add(row)
        for fold in (drawing, table):
            if fold is not None:
                fold.add(row, score)
    return choice, drawing, table
