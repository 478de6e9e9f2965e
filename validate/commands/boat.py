"""``python -m validate boat``: the Solar Boat study of the thesis's ch. 8 (:mod:`validate.studies.boat_study`).

Prints, per configuration, each moment identified from its timed motion against the thesis's
estimate and the truth with its predicted standard deviation, the wire tensions and deck loads, and
the depth under the hooks that the motions need; then the recommendation. ``--json`` prints one
JSON object instead; ``--png`` also draws the wire tensions of the three motions per configuration
(``python -m validate boat --png docs/boat_tensions.png`` makes the committed figure).
"""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from ..studies.boat_study import Study

FIGURE_SECONDS = 10.0  # s of each motion drawn: 2.4-5 periods
COLOURS = ((31, 119, 180), (255, 127, 14), (44, 160, 44), (148, 103, 189), (140, 86, 75))  # per configuration


def add_parser(subparsers) -> None:
    """Add the ``boat`` command to ``python -m validate``'s subparsers."""
    from ..statuses import epilog

    p = subparsers.add_parser("boat", help="the Solar Boat study (thesis ch. 8): moments, tensions, clearance",
                              epilog=epilog("boat", ("python -m validate boat --png docs/boat_tensions.png",)))
    p.add_argument("--suspension", metavar="FILE.toml",
                   help="hall, configurations and measurement errors: a file or a shipped suspension's name "
                        "('list --rigs') (default: models/solar_boat/suspension.toml)")
    p.add_argument("--json", action="store_true",
                   help="print one JSON object instead of the text tables (moments kg m^2, tensions N, depths m; "
                        "default: text)")
    p.add_argument("--png", metavar="FILE.png",
                   help=f"also draw the wire tensions (N) of every configuration over {FIGURE_SECONDS:g} s of each "
                        "motion (default: no figure)")


def run(args) -> int:
    """Run the study (about 10 s) and print it; the study's modules are imported only here, so that
    ``python -m validate`` starts fast."""
    from bifilar.bodies.boat import load_suspension

    from ..studies.boat_study import SUSPENSION, run_study, summary

    study = run_study(load_suspension(args.suspension or SUSPENSION))
    if args.png:
        path = tension_figure(study, args.png)
        print(f"wrote {path}", file=sys.stderr)
    print(json.dumps(summary(study)) if args.json else report(summary(study)))
    return 0


def report(data: dict) -> str:
    """The study's summary (:func:`validate.studies.boat_study.summary`) as text tables."""
    hall = data["hall"]
    lines = [
        f"Solar Boat: {data['mass']:.4g} kg, COM {data['com_below_deck']:.4f} m below the deck, pilot "
        f"{100 * data['pilot_fraction']:.1f} %; principal moments "
        + ", ".join(f"{n} {v:.3f}" for n, v in zip(data["axes"], data["principal_inertia"])) + " kg m^2",
        f"hall: hooks {hall['hooks']} m, wires {hall['wire_length']:g} m, hooks {hall['hook_height']:g} m above the floor",
        "",
        "moment  conf  truth     thesis (error)        identified (error)     sigma     d lnT/d lnI  largest error source",
    ]
    for c in data["configurations"]:
        for k, name in enumerate(data["axes"]):
            truth, found, thesis = c["truth"][k], c["estimates"][k], c["thesis"][k]
            budget = c["budget"][k]
            top = max(budget, key=budget.get)
            quoted = "-" if thesis is None else f"{thesis:8.3f} ({100 * (thesis / truth - 1):+6.2f} %)"
            lines.append(f"{name:7s} {c['name']:5s} {truth:8.3f}  {quoted:20s}  {found:8.3f} ({found / truth - 1:+.1e})  "
                         f"{100 * c['std'][k] / found:6.2f} %  {c['sensitivity'][k]:11.4f}  "
                         f"{top} {100 * budget[top]:.0f} %")
    lines += ["", "conf  attach x  tension at rest (N)  peak tension (N) torsion/swing/roll  "
                  "peak in-plane deck load (N)  depth at rest / in motion (m)  floor margin (m)"]
    for c in data["configurations"]:
        peaks = "/".join(f"{max(m['tension_max']):.0f}" for m in c["motions"])
        plane = max(c["in_plane_max"])
        lines.append(f"{c['name']:5s} {c['attach'][0][0]:7.3f}  {np.mean(c['tension_rest']):18.1f}  {peaks:>35s}  "
                     f"{plane:27.0f}  {c['clearance_rest']:14.3f} / {c['clearance']:.3f}  {c['floor_margin']:16.3f}")
    rec = data["recommendation"]
    chosen = ", ".join(f"{n}: {rec[n]}" for n in data["axes"])
    lines += ["", f"recommendation: configuration {rec['configuration']} (best per moment: {chosen})"]
    lines += [f"  {reason}" for reason in rec["reasons"]]
    return "\n".join(lines)


def tension_figure(study: Study, path: str | Path) -> Path:
    """One panel per motion: both wires' tensions in every configuration, rest tensions as thin lines."""
    from ..studies.boat_study import AXIS_NAME
    from ..lineplot import Panel, Series, save_png

    panels = []
    for k, motion in enumerate(study.configurations[0].loads):
        series, levels = [], []
        for c, rgb in zip(study.configurations, COLOURS):
            run = c.loads[k].run
            shown = run.t <= FIGURE_SECONDS
            series.append(Series(run.t[shown], run.tension[shown, 0], f"configuration {c.config.name}", rgb))
            series.append(Series(run.t[shown], run.tension[shown, 1], "", rgb, dashed=True))
            levels.append((float(c.rest.tensions.mean()), rgb))
        m = motion.motion
        axis = AXIS_NAME[m.axis]
        name = m.name if m.name == axis else f"{m.name} ({axis})"
        how = "wire 1 turned" if m.of_wire else "turned"
        panels.append(Panel(f"{name}: {how} pi/{np.pi / m.amplitude:.0f} at release; wire 1 solid, "
                            "wire 2 dashed, rest thin", "N", tuple(series), tuple(levels)))
    return save_png(path, panels, "time (s)")
