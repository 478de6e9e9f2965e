"""What several subcommands share: the rig argument and its loading (``modes``, ``simulate``, ``mjcf``, which
also take hinge rigs),
and the report options of the suite's commands (``all``, ``case``)."""

from __future__ import annotations

import shlex
from pathlib import Path

RIG_HELP = "rig file (TOML), or the name of a shipped rig, e.g. plate ('python -m validate list --rigs')"


def load(path: str, hinge: bool = False):
    """The rig file and its rest pose, with every wire hanging down from its anchor; with ``hinge`` a
    hinge rig file (``[pivot]`` or ``[torsion]``) is taken too and gives ``(HingeRig, None)``, else it is
    refused in one line."""
    from bifilar.rig import load_rig
    from bifilar.rig.file import check_hanging
    from bifilar.rig.hinge import HingeRig
    from bifilar.rig.statics import rest_pose

    rig = load_rig(path, hinge=hinge)
    if isinstance(rig, HingeRig):
        return rig, None
    rest = rest_pose(rig)
    check_hanging(rig, rest)
    return rig, rest


def add_report_options(p) -> None:
    """``--junit`` and ``--html`` of ``all`` and ``case``."""
    p.add_argument("--junit", metavar="FILE.xml",
                   help="also write the results as JUnit XML, for CI servers (default: none)")
    p.add_argument("--html", metavar="FILE.html",
                   help="also write one self-contained HTML page: summary, every case's metrics and figures "
                        "(default: none)")


def reports(args, cases) -> list:
    """The writers of ``--junit`` and ``--html``, each called with the results and the wall time."""
    out = []
    if args.junit:
        from ..report.junit import write_junit

        out.append(lambda results, seconds: write_junit(args.junit, results, seconds))
    if args.html:
        from ..report.suite_page import write_suite_html

        descriptions = {c.name: c.description for c in cases}
        extra = []
        if getattr(args, "slow", False):  # the stored speed-accuracy result: benchmarks/speed_accuracy.py
            from ..report.speed_accuracy import SpeedAccuracySection, load

            extra.append(SpeedAccuracySection(load()))
        command = "python -m validate " + shlex.join(args.argv)
        out.append(lambda results, seconds: write_suite_html(args.html, results, seconds, descriptions, extra, command))
    return out


def recorder(dest: str | None, folder: bool):
    """None without ``--rerun``; else a function writing a case result's recording to ``dest`` (a
    file), or to ``dest/<case>.rrd`` with ``folder``."""
    if not dest:
        return None
    from ..recording import record_case

    return lambda result: record_case(result, Path(dest) / f"{result.name}.rrd" if folder else dest)
