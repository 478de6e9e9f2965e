"""``python -m validate``: run the validation suite, and the rig tools it is built on.

Exit status: 0 success, 1 a validation check failed, 2 bad input (one line on stderr naming the
file, the field and the problem), 3 the Kane model's taut-wire assumption failed during a run.
"""

from __future__ import annotations

import argparse
import json
import sys

from bifilar.rig import RigError, load_rig

from .commands import boat as boat_cli
from .commands import identify as identify_cli
from .argtypes import OneLineParser, UsageError, positive_float, whole_number


def build_parser() -> argparse.ArgumentParser:
    parser = OneLineParser(prog="python -m validate", description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True, parser_class=OneLineParser)

    p = sub.add_parser("all", help="run every registered validation case")
    p.add_argument("--json", metavar="REPORT.json", help="also write the report as JSON")
    p.add_argument("--slow", action="store_true", help="include cases tagged slow")
    p.add_argument("--jobs", type=whole_number("--jobs", 1), default=2, help="cases run in parallel (default 2)")
    p.add_argument("--rerun", metavar="DIR", help="also write one rerun recording per case, DIR/<case>.rrd")

    sub.add_parser("list", help="list the registered cases")

    p = sub.add_parser("case", help="run one case")
    p.add_argument("name")
    p.add_argument("--json", metavar="REPORT.json", help="also write the report as JSON")
    p.add_argument("--rerun", metavar="FILE.rrd", help="also write a rerun recording of the case (open: rerun FILE.rrd)")

    p = sub.add_parser("modes", help="rest pose, static tensions and small-oscillation periods")
    p.add_argument("rig")
    p.add_argument("--json", action="store_true", help="print one JSON object")

    p = sub.add_parser("simulate", help="simulate a rig and write the trajectory CSV")
    p.add_argument("rig")
    p.add_argument("--engine", default="kane")
    p.add_argument("--duration", type=positive_float("--duration"), required=True)
    p.add_argument("--dt-out", type=positive_float("--dt-out"), default=0.01)
    p.add_argument("--rtol", type=positive_float("--rtol"), default=1e-10)
    p.add_argument("--out", required=True, metavar="FILE.csv")
    p.add_argument("--rerun", metavar="FILE.rrd", help="also write a rerun recording of the run (open: rerun FILE.rrd)")

    identify_cli.add_parser(sub)
    boat_cli.add_parser(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    try:
        args = build_parser().parse_args(argv)
        return _COMMANDS[args.command](args)
    except (RigError, UsageError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except OSError as exc:  # an output that cannot be written (inputs are read as RigError)
        print(f"error: {exc.filename}: cannot write ({exc.strerror})", file=sys.stderr)
        return 2


def _cmd_modes(args) -> int:
    from bifilar.motion.modes import linearize

    rig = load_rig(args.rig)
    lin = linearize(rig)
    rest = lin.rest
    report = {
        "rig": rig.name,
        "model": "pose-coordinate linearisation (bifilar.motion.modes)",
        "equilibrium": {
            "com": rest.com.tolist(),
            "rotation": rest.rotation.tolist(),
            "tensions": rest.tensions.tolist(),
        },
        "modes": [
            {"motion": m.motion, "period": m.period, "frequency": m.frequency, "omega2": m.omega2,
             "com_shape": m.com.tolist(), "rotation_shape": m.rotation.tolist()}
            for m in lin.modes
        ],
    }
    if args.json:
        print(json.dumps(report))
        return 0
    print(f"rig {rig.name}: rest COM {_fmt(rest.com)} m, tensions {_fmt(rest.tensions)} N")
    for i, m in enumerate(lin.modes, start=1):
        period = "neutral" if m.period is None else f"{m.period:.9g} s ({m.frequency:.6g} Hz)"
        print(f"  mode {i} ({m.motion}): period {period}; COM shape {_fmt(m.com)} m, "
              f"rotation shape {_fmt(m.rotation)} rad")
    return 0


def _cmd_simulate(args) -> int:
    from bifilar.motion.simulate import IntegrationError, output_grid

    from .engines import EngineInputError, engines
    from .trajectory import NonFiniteTrajectory, write_rig_csv

    available = engines()
    if args.engine not in available:
        raise UsageError(f"--engine: unknown engine {args.engine!r} (choose from {', '.join(available)})")
    try:
        output_grid(args.duration, args.dt_out)
    except ValueError as exc:
        raise UsageError(f"--dt-out: {exc}") from None
    rig = load_rig(args.rig)
    try:
        traj = available[args.engine](rig, args.duration, args.dt_out, args.rtol)
        write_rig_csv(traj, args.out)
    except EngineInputError as exc:
        raise UsageError(f"--dt-out: {exc}") from None
    except (IntegrationError, NonFiniteTrajectory) as exc:
        raise RigError(args.rig, "initial", f"the {args.engine} run failed ({exc}): the motion is too violent") from None
    if args.rerun:
        from .recording import record_trajectory

        record_trajectory(traj, args.rerun)
    failure = traj.meta.get("taut_failure")
    if failure:
        wire, t = failure
        print(
            f"error: {args.rig}: wire[{wire}]: went slack at t = {t:.6g} s; the {args.engine} model assumes taut "
            f"wires, so {args.out} ends there",
            file=sys.stderr,
        )
        return 3
    return 0


def _cmd_list(args) -> int:
    from .suite import registered

    for c in registered(slow=True):
        tags = ",".join(sorted(c.tags))
        print(f"{c.name:40s} [{tags}] {c.source}: {c.description.splitlines()[0] if c.description else ''}")
    return 0


def _cmd_all(args) -> int:
    from .suite import registered, run_cases

    return run_cases(registered(slow=args.slow), jobs=args.jobs, json_path=args.json,
                     on_result=_recorder(args.rerun, folder=True))


def _cmd_case(args) -> int:
    from .suite import find, run_cases

    return run_cases([find(args.name)], jobs=1, json_path=args.json, on_result=_recorder(args.rerun, folder=False))


def _recorder(dest: str | None, folder: bool):
    """None without ``--rerun``; else a function writing a case result's recording to ``dest`` (a
    file), or to ``dest/<case>.rrd`` with ``folder``."""
    if not dest:
        return None
    from pathlib import Path

    from .recording import record_case

    return lambda result: record_case(result, Path(dest) / f"{result.name}.rrd" if folder else dest)


def _fmt(values) -> str:
    return "[" + ", ".join(f"{v:.9g}" for v in values) + "]"


_COMMANDS = {
    "all": _cmd_all,
    "list": _cmd_list,
    "case": _cmd_case,
    "modes": _cmd_modes,
    "simulate": _cmd_simulate,
    "identify": identify_cli.run,
    "boat": boat_cli.run,
}
