"""``python -m validate sweep SPACE.toml --out DIR``: a parameter sweep of suspension configurations.

Writes, whole or not at all, ``DIR/sweep.csv`` (one row per configuration; columns: the varied axes,
``period_1..period_4`` (s, longest first, empty for a neutral mode), ``tension_1,tension_2`` (N at rest),
``tension_peak`` (N), ``sigma_x,sigma_y,sigma_z`` (relative standard deviation of the identified moment;
empty where not measured or not identifiable), ``clearance`` (m above the floor), ``feasible``, then
``motion_1..motion_4``, ``dominant_x..z`` (the uncertainty group with the largest share), ``separation``
(smallest relative gap between two mode periods), ``reason`` (why a row is infeasible) and
``air_share_x..z`` (for a rig with ``[air]``: the air's share of each measured period, 1 - (T_vacuum/T)^2)), and
``DIR/summary.json`` (n, feasible, objective, best, pareto, seconds, mujoco_check) and ``DIR/report.html``
(one self-contained page of them: :mod:`validate.report.sweep_page`). ``--check-mujoco K``
runs the K best configurations in MuJoCo (:mod:`validate.studies.sweep_check`) and fails (exit 1) on a
disagreement over 1e-6. ``--png`` adds ``DIR/sweep.png``:
the objective over the two most varied axes (the best over the others), infeasible points marked, and the
Pareto front; ``--rerun`` adds ``DIR/sweep.rrd``, the table and the check's motions
(:mod:`validate.studies.sweep_record`). The evaluation is :mod:`bifilar.sweep`. ``DIR/.lock`` is held
for the whole run: a second sweep into ``DIR`` meanwhile is refused (exit 2).
"""

from __future__ import annotations

import csv
import io
import json
import math
import sys
import time
from pathlib import Path

from ..argtypes import UsageError, whole_number

COLUMNS_AFTER_AXES = (
    ["period_1", "period_2", "period_3", "period_4", "tension_1", "tension_2", "tension_peak",
     "sigma_x", "sigma_y", "sigma_z", "clearance", "feasible"]
    + [f"motion_{k}" for k in range(1, 5)] + ["dominant_x", "dominant_y", "dominant_z", "separation", "reason"]
    + ["air_share_x", "air_share_y", "air_share_z"]
)


def add_parser(subparsers):
    p = subparsers.add_parser("sweep", help="sweep suspension configurations: periods, sigma, tensions, the best rig")
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
    return p


def _cell(x) -> str:
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return ""
    if isinstance(x, bool):
        return "true" if x else "false"
    return repr(float(x)) if isinstance(x, (int, float)) else str(x)


def csv_text(axes: list[str], rows: list[dict]) -> str:
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(axes + COLUMNS_AFTER_AXES)
    for r in rows:
        w.writerow([_cell(r["values"][a]) for a in axes] + [_cell(p) for p in r["periods"]]
                   + [_cell(t) for t in r["tensions"]] + [_cell(r["tension_peak"])]
                   + [_cell(r["sigma"][a]) for a in ("x", "y", "z")] + [_cell(r["clearance"]), _cell(r["feasible"])]
                   + list(r["motions"]) + [r["dominant"][a] or "" for a in ("x", "y", "z")]
                   + [_cell(r["separation"]), r["reason"]] + [_cell(r["air_share"][a]) for a in ("x", "y", "z")])
    return buf.getvalue()


def _wrap(text: str) -> str:
    """A report line wrapped at 100 columns (continuations indented; paths and words kept whole)."""
    import textwrap

    return textwrap.fill(text, width=100, subsequent_indent="  ", break_on_hyphens=False, break_long_words=False)


def summary(space, rows: list[dict], seconds: float) -> dict:
    from bifilar.sweep.choose import best, edges, objective, pareto

    def point(r):
        return {**r["values"], "sigma": {a: r["sigma"][a] for a in space.measure},
                "objective": objective(r, space.measure, space.objective), "tension_peak": r["tension_peak"]}

    top = best(rows, space.measure, space.objective)
    return {
        "n": len(rows),
        "feasible": sum(r["feasible"] for r in rows),
        "objective": f"{space.objective} relative sigma over {list(space.measure)}, feasible rows only",
        "best": point(top) if top else None,
        "pareto": [point(r) for r in pareto(rows, space.measure, space.objective)],
        "edges": edges(space.axes, top, space.explicit),
        "seconds": seconds,
        "mujoco_check": [],
    }


def figure(space, rows: list[dict], path: Path) -> None:
    """Objective over the two most varied axes (least over the others) and the Pareto front."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    from bifilar.sweep.choose import best, edges, objective, pareto

    axes = sorted(space.axes, key=lambda a: -len(space.axes[a]))[:2]
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.5))
    if len(axes) == 2:
        xs, ys = space.axes[axes[0]], space.axes[axes[1]]
        grid = np.full((len(ys), len(xs)), np.inf)
        for r in rows:
            i = int(np.argmin(abs(ys - r["values"][axes[1]])))
            j = int(np.argmin(abs(xs - r["values"][axes[0]])))
            grid[i, j] = min(grid[i, j], objective(r, space.measure, space.objective))
        shown = np.where(np.isfinite(grid), grid, np.nan)
        mesh = left.pcolormesh(xs, ys, 100 * shown, shading="nearest", cmap="viridis")
        fig.colorbar(mesh, ax=left, label=f"{space.objective} sigma (%)")
        bad = ~np.isfinite(grid)
        gx, gy = np.meshgrid(xs, ys)
        left.scatter(gx[bad], gy[bad], marker="x", color="red", s=12, label="infeasible")
        top = best(rows, space.measure, space.objective)
        if top:
            left.scatter([top["values"][axes[0]]], [top["values"][axes[1]]], marker="*", s=200, color="white",
                         edgecolor="black", label="best")
        hidden = [a for a in space.axes if a not in axes and len(space.axes[a]) > 1]
        left.set_title("least over " + ", ".join(hidden) + " in each cell" if hidden else "every configuration",
                       fontsize=9)
        for k, edge in enumerate(edges(space.axes, top, space.explicit)):
            left.annotate(f"best on the {edge['side']} edge of {edge['axis']}: widen {edge['widen']}",
                          xy=(0.01, 0.01 + 0.05 * k), xycoords="axes fraction", fontsize=7, color="red")
        left.set_xlabel(f"{axes[0]} (m)")
        left.set_ylabel(f"{axes[1]} (m)")
        left.legend(loc="upper right", fontsize=8)
    front = pareto(rows, space.measure, space.objective)
    ok = [r for r in rows if math.isfinite(objective(r, space.measure, space.objective))]
    right.scatter([r["tension_peak"] for r in ok], [100 * objective(r, space.measure, space.objective) for r in ok],
                  s=6, color="grey", label="feasible")
    right.plot([r["tension_peak"] for r in front], [100 * objective(r, space.measure, space.objective) for r in front],
               "o-", color="tab:orange", label="Pareto front")
    right.set_xlabel("peak tension (N)")
    right.set_ylabel(f"{space.objective} sigma (%)")
    right.set_yscale("log")
    right.legend(fontsize=8)
    fig.suptitle(f"sweep of {Path(space.source).name}: {len(rows)} configurations")
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110)
    plt.close(fig)
    from ..trajectory import atomic_write_bytes

    atomic_write_bytes(path, buf.getvalue())


def run(args) -> int:
    from bifilar.sweep.run import InUse, lock
    from bifilar.sweep.space import load_space

    from ..trajectory import check_writable

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

    from ..trajectory import atomic_write_text

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
        rows = run_sweep(args.space, space, out, jobs=jobs, scheduler=args.scheduler, progress=progress)
    except Unreachable as exc:
        raise UsageError(f"sweep: --scheduler {args.scheduler}: {exc}") from None
    finally:
        if bar is not None:
            bar.close()
    seconds = time.perf_counter() - start
    data = summary(space, rows, seconds)
    checked = []
    if args.check_mujoco:
        from bifilar.sweep.choose import objective

        from ..studies.sweep_check import check

        ranked = sorted((r for r in rows if math.isfinite(objective(r, space.measure, space.objective))),
                        key=lambda r: objective(r, space.measure, space.objective))
        checked = check(space, [r["values"] for r in ranked[: args.check_mujoco]])
        data["mujoco_check"] = [c.entry for c in checked]
    data["files"] = (["sweep.csv", "summary.json"] + (["sweep.png"] if args.png else []) + ["report.html"]
                     + (["sweep.rrd"] if args.rerun else []))
    atomic_write_text(out / "sweep.csv", csv_text(list(space.axes), rows))
    atomic_write_text(out / "summary.json", json.dumps(data, indent=1, allow_nan=False) + "\n")
    if args.png:
        figure(space, rows, out / "sweep.png")
    from ..report.sweep_page import write_sweep_html

    write_sweep_html(out, space.measure, space.objective, f"sweep of {Path(args.space).name}")
    if args.rerun:
        from ..studies.sweep_record import record_sweep

        record_sweep(out / "sweep.rrd", space, rows, checked)
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
