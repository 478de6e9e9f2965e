"""``python -m validate case NAME``: run one registered validation case."""

from __future__ import annotations

from ..statuses import epilog
from .shared import add_report_options, recorder, reports


def add_parser(subparsers) -> None:
    """Register the ``case`` subcommand on the CLI's subparsers."""
    p = subparsers.add_parser("case", help="run one case", epilog=epilog("case", (
        "python -m validate case rig-torsion-6.2 --rerun torsion.rrd",)))
    p.add_argument("name", help="a case name from 'python -m validate list'")
    p.add_argument("--json", metavar="REPORT.json", help="also write the report as JSON (default: none)")
    p.add_argument("--rerun", metavar="FILE.rrd",
                   help="also write a rerun recording of the case, open with: rerun FILE.rrd (default: none)")
    add_report_options(p)


def run(args) -> int:
    """Run the named case; the exit status is its verdict."""
    from ..suite import find, run_cases

    cases = [find(args.name)]
    return run_cases(cases, jobs=1, json_path=args.json, on_result=recorder(args.rerun, folder=False),
                     reports=reports(args, cases), traces=bool(args.html))
