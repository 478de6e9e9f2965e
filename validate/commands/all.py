"""``python -m validate all``: run every registered validation case (or those ``-k`` and ``--tag`` select)."""

from __future__ import annotations

from ..argtypes import whole_number
from ..statuses import epilog
from .shared import add_report_options, recorder, reports


def add_parser(subparsers) -> None:
    """Register the ``all`` subcommand on the CLI's subparsers."""
    p = subparsers.add_parser("all", help="run every registered validation case", epilog=epilog("all", (
        "python -m validate all --json report.json --rerun recordings/", "python -m validate all -k torsion")))
    p.add_argument("--json", metavar="REPORT.json", help="also write the report as JSON (default: none)")
    p.add_argument("--slow", action="store_true",
                   help="include cases tagged slow (default: fast cases only); with --html, also the stored result "
                        "of benchmarks/speed_accuracy.py")
    p.add_argument("-k", metavar="PATTERN", dest="pattern",
                   help="only cases whose name contains PATTERN (or matches it, with * ? [ ]; default: all)")
    p.add_argument("--tag", action="append", metavar="TAG",
                   help="only cases with this tag, e.g. fast, slow (repeat for any of several; default: all)")
    p.add_argument("--jobs", type=whole_number("--jobs", 1, 64), default=2,
                   help="cases run in parallel worker processes, 1-64 (default: 2)")
    p.add_argument("--rerun", metavar="DIR",
                   help="also write one rerun recording per case, DIR/<case>.rrd (default: none)")
    add_report_options(p)


def run(args) -> int:
    """Run the selected cases in ``--jobs`` processes; the exit status is the suite's verdict."""
    from ..suite import registered, run_cases, select

    cases = select(registered(slow=args.slow or bool(args.tag)), args.pattern, args.tag)
    return run_cases(cases, jobs=args.jobs, json_path=args.json, on_result=recorder(args.rerun, folder=True),
                     progress=True, reports=reports(args, cases), traces=bool(args.html))
