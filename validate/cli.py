"""``python -m validate``: run the validation suite, and the rig tools it is built on.

Every error is one line on stderr (``error: FILE: FIELD: problem``), never a traceback; warnings
raised during a command that then fails are dropped, so that the error stays one line. A numerical
failure inside the physics (a singular matrix, a solver that does not converge, a spent work budget)
is exit status 4 and names the field most likely responsible.
"""

from __future__ import annotations

import argparse
import json
import os
import shlex
import sys
import traceback
import warnings
from pathlib import Path

from bifilar.rig import RigError, load_rig

from .engines import NAMES as ENGINE_NAMES
from .argtypes import OneLineParser, UsageError, bounded_float, positive_float, whole_number
from .commands import boat as boat_cli
from .commands import identify as identify_cli
from .commands import plan as plan_cli
from .commands import sweep as sweep_cli
from .commands import tensor as tensor_cli
from .statuses import BAD_INPUT, BROKEN_PIPE, INTERRUPTED, OK, RUN_FAILED, WENT_SLACK, epilog
from .stdout import StdoutFailed
from .stdout import guarded as guarded_stdout

EPILOG = epilog(examples=(
    "python -m validate modes models/rigs/plate.toml",
    "python -m validate modes plate                      # a shipped rig by name (list --rigs)",
    "python -m validate simulate models/rigs/plate.toml --engine kane --duration 60 --out plate.csv",
    "python -m validate all -k torsion",
))

RIG_HELP = "rig file (TOML), or the name of a shipped rig, e.g. plate ('python -m validate list --rigs')"
MAX_DURATION = 1e5  # s: the longest simulation one command runs (27 hours of swinging)
RTOL_RANGE = (1e-13, 1e-4)  # below: DOP853 is at rounding; above: the energy drifts by percent per period


class RunFailed(Exception):
    """A run that failed (exit status 4): the message is the whole line after ``error: ``."""


def build_parser() -> argparse.ArgumentParser:
    parser = OneLineParser(prog="python -m validate", description=__doc__.splitlines()[0].replace("``", ""),
                           epilog=EPILOG)
    sub = parser.add_subparsers(dest="command", required=True, parser_class=OneLineParser, metavar="COMMAND")

    p = sub.add_parser("all", help="run every registered validation case", epilog=epilog("all", (
        "python -m validate all --json report.json --rerun recordings/", "python -m validate all -k torsion")))
    p.add_argument("--json", metavar="REPORT.json", help="also write the report as JSON (default: none)")
    p.add_argument("--slow", action="store_true", help="include cases tagged slow (default: fast cases only); with "
                                                        "--html, also the stored result of benchmarks/speed_accuracy.py")
    p.add_argument("-k", metavar="PATTERN", dest="pattern",
                   help="only cases whose name contains PATTERN (or matches it, with * ? [ ]; default: all)")
    p.add_argument("--tag", action="append", metavar="TAG",
                   help="only cases with this tag, e.g. fast, slow (repeat for any of several; default: all)")
    p.add_argument("--jobs", type=whole_number("--jobs", 1, 64), default=2,
                   help="cases run in parallel worker processes, 1-64 (default: 2)")
    p.add_argument("--rerun", metavar="DIR", help="also write one rerun recording per case, DIR/<case>.rrd (default: none)")
    _report_options(p)

    p = sub.add_parser("list", help="list the registered cases with their whole descriptions (--rigs: the shipped "
                                    "rigs, sweeps and suspensions)",
                       epilog=epilog("list", ("python -m validate list", "python -m validate list --rigs")))
    p.add_argument("--rigs", action="store_true",
                   help="list the shipped rig, sweep and suspension files instead, each with its name (which every "
                        "command takes in place of the path) and a one-line description")

    p = sub.add_parser("case", help="run one case", epilog=epilog("case", (
        "python -m validate case rig-torsion-6.2 --rerun torsion.rrd",)))
    p.add_argument("name", help="a case name from 'python -m validate list'")
    p.add_argument("--json", metavar="REPORT.json", help="also write the report as JSON (default: none)")
    p.add_argument("--rerun", metavar="FILE.rrd",
                   help="also write a rerun recording of the case, open with: rerun FILE.rrd (default: none)")
    _report_options(p)

    p = sub.add_parser("modes", help="rest pose, static tensions and small-oscillation periods",
                       epilog=epilog("modes", ("python -m validate modes plate", "python -m validate modes my_rig.toml --json")))
    p.add_argument("rig", help=RIG_HELP)
    p.add_argument("--json", action="store_true",
                   help="print one JSON object (COM m, rotation, tensions N, periods s, frequencies Hz, omega^2 "
                        "rad^2/s^2, mode shapes m and rad; world frame) instead of text (default: text)")

    p = sub.add_parser("simulate", help="simulate a rig and write the trajectory CSV", epilog=epilog("simulate", (
        "python -m validate simulate plate --engine kane --duration 60 --out plate.csv",)))
    p.add_argument("rig", help=RIG_HELP + "; the run starts from its [initial] disturbance")
    p.add_argument("--engine", default="kane", choices=ENGINE_NAMES,
                   help="kane: the hand-derived model (Kane-Tseng for two wires, the N-wire model otherwise; "
                        "stops where a wire goes slack); nwire: the N-wire model on any rig; mujoco: tendon "
                        "cables that may go slack; mujoco-eq: equality cables; mujoco-cable: heavy wires (linear_density) "
                        "as chains of rigid segments with their mass (default: kane)")
    p.add_argument("--duration", type=bounded_float("--duration", 0.0, MAX_DURATION, "s", low_open=True),
                   required=True, help=f"simulated time, s, > 0 and at most {MAX_DURATION:g}")
    p.add_argument("--dt-out", type=bounded_float("--dt-out", 0.0, 100.0, "s", low_open=True), default=0.01,
                   help="output sample spacing, s, at most --duration; for mujoco a whole number of its "
                        "4e-5 s steps (default: 0.01)")
    p.add_argument("--rtol", type=bounded_float("--rtol", *RTOL_RANGE, ""), default=1e-10,
                   help=f"kane integrator's relative tolerance, {RTOL_RANGE[0]:g} .. {RTOL_RANGE[1]:g} "
                        "(default: 1e-10; mujoco ignores it)")
    p.add_argument("--max-seconds", type=positive_float("--max-seconds"), default=600.0,
                   help="wall-time budget of the run, s; the run stops with exit 4 when it is spent (default: 600)")
    p.add_argument("--out", required=True, metavar="FILE.csv", help="trajectory CSV to write (whole or not at all)")
    p.add_argument("--rerun", metavar="FILE.rrd", help="also write a rerun recording of the run (default: none)")

    p = sub.add_parser("mjcf", help="write MuJoCo models of rigs: DIR/<rig>/<rig>.xml and DIR/<rig>/scene.xml",
                       epilog=epilog("mjcf", ("python -m validate mjcf asymmetric plate --out out/",)))
    p.add_argument("rigs", nargs="+", metavar="RIG", help="rig files (TOML) or shipped rigs' names ('list --rigs'); "
                                                         "their names must differ")
    p.add_argument("--out", required=True, metavar="DIR", help="folder that receives one folder per rig name")

    identify_cli.add_parser(sub)
    boat_cli.add_parser(sub)
    tensor_cli.add_parser(sub)
    plan_cli.add_parser(sub)
    sweep_cli.add_parser(sub)
    sweep = sub.choices["sweep"]
    sweep.epilog = sweep.epilog or epilog("sweep", ("python -m validate sweep bench_plate --out sweep/ --png",))
    return parser


def _report_options(p) -> None:
    p.add_argument("--junit", metavar="FILE.xml", help="also write the results as JUnit XML, for CI servers (default: none)")
    p.add_argument("--html", metavar="FILE.html",
                   help="also write one self-contained HTML page: summary, every case's metrics and figures "
                        "(default: none)")


def main(argv: list[str] | None = None) -> int:
    """Run one command; returns its exit status (see :data:`EPILOG`)."""
    args = None
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            with guarded_stdout():
                args = build_parser().parse_args(argv)
                args.argv = list(sys.argv[1:] if argv is None else argv)  # the command line, for the reports
                _resolve_inputs(args)
                _check_outputs(args)
                code = _COMMANDS[args.command](args)
                sys.stdout.flush()
        except BaseException as exc:  # every way out becomes one line and an exit status
            return _failure(exc, args)
    _print_warnings(caught)
    return code


def _failure(exc: BaseException, args) -> int:
    """The one error line for ``exc`` on stderr, and the exit status."""
    if isinstance(exc, SystemExit):  # --help, --version
        return exc.code if isinstance(exc.code, int) else 0
    if isinstance(exc, BrokenPipeError) or (isinstance(exc, OSError) and exc.errno == 32 and exc.filename is None):
        _silence_stdout()
        return BROKEN_PIPE
    if isinstance(exc, StdoutFailed):  # an output that cannot be written, as a file's below
        _silence_stdout()
        _error(f"stdout: cannot write ({exc})")
        return BAD_INPUT
    if isinstance(exc, KeyboardInterrupt) or _caused_by_interrupt(exc):
        _error("interrupted")
        return INTERRUPTED
    if isinstance(exc, (RigError, UsageError)):
        _error(str(exc))
        return BAD_INPUT
    if isinstance(exc, RunFailed):
        _error(str(exc))
        return RUN_FAILED
    if isinstance(exc, OSError) and exc.filename is not None:  # an output that cannot be written
        _error(f"{exc.filename}: cannot write ({exc.strerror or exc})")
        return BAD_INPUT
    if isinstance(exc, Exception):
        _error(_run_failed_line(exc, args))
        return RUN_FAILED
    raise exc


def _error(line: str) -> None:
    print(f"error: {line}", file=sys.stderr, flush=True)


def _print_warnings(caught) -> None:
    """Warnings of a command that succeeded, one line each, each once."""
    seen = set()
    for w in caught:
        line = f"warning: {w.category.__name__}: {str(w.message).splitlines()[0] if str(w.message) else ''}"
        if line not in seen:
            seen.add(line)
            print(line, file=sys.stderr)


def _silence_stdout() -> None:
    """Point stdout at /dev/null so that the interpreter's final flush does not fail again."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError):
        pass


def _caused_by_interrupt(exc: BaseException) -> bool:
    """A Ctrl-C inside a compiled kernel surfaces as a SystemError whose cause is the interrupt."""
    seen = 0
    while exc is not None and seen < 10:
        if isinstance(exc, KeyboardInterrupt):
            return True
        exc, seen = exc.__cause__ or exc.__context__, seen + 1
    return False


# Where a numerical failure happened -> the rig field most likely responsible. Keys are module file
# names, or (module file, function) for a finer guess; the innermost frame of ours that matches wins.
_LIKELY_FIELD = {
    ("statics.py", "initial_state"): "initial",
    ("statics.py", "taut_shift"): "initial.rotation",
    "statics.py": "wire",  # rest pose: anchors, attachments and lengths
    ("kane.py", "from_rig"): "body.com",
    ("kane.py", "complete_theta5"): "wire",
    "modes.py": "wire",
    "simulate.py": "initial",
    "kane_kernel.py": "initial",
    "mjcf.py": "body",
    "mujoco_rig.py": "initial",
    "propagation.py": "uncertainty",
    "identify.py": "body.inertia",
    "fit.py": "signal",  # bifilar/identification/records/fit.py: a record the fit could not use
    "law.py": "signal",
}


def _likely_field(exc: BaseException) -> str:
    frames = traceback.extract_tb(exc.__traceback__)
    for frame in reversed(frames):
        name = Path(frame.filename).name
        if "bifilar" not in frame.filename and "validate" not in frame.filename:
            continue
        field = _LIKELY_FIELD.get((name, frame.name)) or _LIKELY_FIELD.get(name)
        if field:
            return field
    return "rig"


def _run_failed_line(exc: Exception, args) -> str:
    source = getattr(args, "rig", None) or getattr(args, "suspension", None) or "python -m validate"
    if isinstance(source, list):
        source = source[0]
    what = f"{type(exc).__name__}: {str(exc).splitlines()[0] if str(exc) else 'no message'}"
    command = getattr(args, "command", "command")
    if os.environ.get("VALIDATE_TRACEBACK"):
        traceback.print_exception(exc)
    return (f"{source}: {_likely_field(exc)}: the {command} run failed ({what}); this field is the most likely "
            "cause (VALIDATE_TRACEBACK=1 shows where)")


# Input file arguments -> the kind of shipped file a bare name means (validate.assets.resolve).
_INPUTS = {"rig": "rig", "rigs": "rig", "tare": "rig", "space": "sweep", "suspension": "suspension"}


def _resolve_inputs(args) -> None:
    """Every input file argument through :func:`validate.assets.resolve`: a path that exists as given,
    else a shipped file by name (``modes plate``, ``sweep bench_plate``) from any folder."""
    from .assets import resolve

    for name, kind in _INPUTS.items():
        value = getattr(args, name, None)
        if isinstance(value, str):
            setattr(args, name, resolve(value, kind))
        elif isinstance(value, list):
            setattr(args, name, [resolve(v, kind) for v in value])


def _check_outputs(args) -> None:
    """Every output path is checked before the work starts: no two options name the same path (one
    would overwrite the other), each file writable, each folder a folder (:mod:`validate.outputs`)."""
    from .outputs import check_folder, check_writable, distinct_outputs

    given = {name: value for name in ("out", "json", "rerun", "png", "junit", "html")
             if isinstance(value := getattr(args, name, None), str)}
    clash = distinct_outputs(given)
    if clash:
        first, second = clash
        raise UsageError(f"--{second}: {given[second]} is also the --{first} output: one would overwrite the other; "
                         "give each output its own path (nothing written)")
    for name, value in given.items():
        folder = (name == "rerun" and args.command == "all") or (name == "out" and args.command in ("mjcf", "sweep"))
        (check_folder if folder else check_writable)(value)


def _load(path: str):
    """The rig file and its rest pose, with every wire hanging down from its anchor."""
    from bifilar.rig.file import check_hanging
    from bifilar.rig.statics import rest_pose

    rig = load_rig(path)
    rest = rest_pose(rig)
    check_hanging(rig, rest)
    return rig, rest


def _cmd_modes(args) -> int:
    from bifilar.motion.modes import linearize

    rig, rest = _load(args.rig)
    lin = linearize(rig, rest)
    rest = lin.rest
    light = _massless_modes(rig)
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
             **({"kind": _mode_kind(m), "stretch_share": m.stretch_share} if rig.elastic else {}),
             "com_shape": m.com.tolist(), "rotation_shape": m.rotation.tolist(),
             **({} if light is None else {"massless_period": light.modes[k].period})}
            for k, m in enumerate(lin.modes)
        ],
    }
    if light is not None:
        report["model"] += ", heavy wires to first order in their mass (docs/heavy-wires.md); tensions at the body end"
    if args.json:
        print(json.dumps(report, allow_nan=False))
        return 0
    print(f"rig {rig.name}: rest COM {_fmt(rest.com)} m, tensions {_fmt(rest.tensions)} N")
    for i, m in enumerate(lin.modes, start=1):
        period = "neutral" if m.period is None else f"{m.period:.9g} s ({m.frequency:.6g} Hz)"
        kind = f", {_mode_kind(m)}: {m.stretch_share:.3g} of its energy in wire stretch" if rig.elastic else ""
        heavy = "" if light is None or light.modes[i - 1].period is None else \
            f" [massless wires: {light.modes[i - 1].period:.9g} s]"
        print(f"  mode {i} ({m.motion}{kind}): period {period}{heavy}; COM shape {_fmt(m.com)} m, "
              f"rotation shape {_fmt(m.rotation)} rad")
    return 0


def _mode_kind(mode) -> str:
    """``fast`` for a mode held by the wires' stretch (bounce, roll, pitch), ``slow`` for a pendulum mode."""
    return "fast" if mode.stretch_share > 0.5 else "slow"


def _massless_modes(rig):
    """The modes of ``rig`` on massless wires if its wires are heavy (shown beside the corrected
    ones), else None."""
    from bifilar.motion.modes import linearize
    from bifilar.rig.heavy import has_wire_mass, massless

    return linearize(massless(rig)) if has_wire_mass(rig) else None


def _cmd_simulate(args) -> int:
    from bifilar.motion.simulate import MAX_SAMPLES, BudgetSpent, IntegrationError

    from .engines import EngineInputError, engines
    from .trajectory import NonFiniteTrajectory, write_rig_csv

    if args.dt_out > args.duration:
        raise UsageError(f"--duration: {args.duration:g} s is shorter than --dt-out {args.dt_out:g} s: "
                         "the CSV would hold t = 0 only")
    n_samples = int(args.duration / args.dt_out + 1e-9) + 1
    if n_samples > MAX_SAMPLES:
        raise UsageError(f"--duration: {args.duration:g} s every --dt-out {args.dt_out:g} s is {n_samples} samples, "
                         f"more than {MAX_SAMPLES}: shorten --duration or lengthen --dt-out")
    rig, _ = _load(args.rig)
    heavy = [i for i, w in enumerate(rig.wires, start=1) if w.linear_density > 0.0]
    if heavy and args.engine != "mujoco-cable":
        raise RigError(args.rig, f"wire[{heavy[0]}].linear_density", f"the {args.engine} engine models massless "
                       "wires: simulate heavy wires with --engine mujoco-cable")
    try:
        traj = engines()[args.engine](rig, args.duration, args.dt_out, args.rtol, max_seconds=args.max_seconds)
        failure = traj.meta.get("taut_failure")
        if failure and failure[1] == 0.0:
            raise RigError(args.rig, "initial", _slack_at_once(traj, failure[0]))
        write_rig_csv(traj, args.out)
    except EngineInputError as exc:
        raise UsageError(f"{exc.option}: {exc}") from None
    except BudgetSpent as exc:
        raise RunFailed(f"{args.rig}: initial: {exc} (--max-seconds {args.max_seconds:g}); the motion is too "
                        "violent for this engine, or the run too long; nothing written") from None
    except (IntegrationError, NonFiniteTrajectory) as exc:
        raise RigError(args.rig, "initial", f"the {args.engine} run failed ({exc}): the motion is too violent") from None
    if args.rerun:
        from .recording import record_trajectory

        record_trajectory(traj, args.rerun)
    print(_summary(args, traj))
    if failure:
        wire, t = failure
        print(
            f"error: {args.rig}: wire[{wire}]: went slack at t = {t:.6g} s; the {args.engine} model assumes taut "
            f"wires, so {args.out} ends there",
            file=sys.stderr,
        )
        return WENT_SLACK
    return OK


def _slack_at_once(traj, wire: int) -> str:
    tension = float(traj["tension"][0, wire - 1])
    return (f"the disturbance is so violent that wire[{wire}] goes slack at once (a taut wire[{wire}] would have to "
            f"push with {-tension:.6g} N at t = 0); the taut-wire kane model cannot start: try --engine mujoco "
            "or a smaller [initial]; nothing written")


def _summary(args, traj) -> str:
    """One line: what ran, how far, the tension range, where it went."""
    import numpy as np

    t_end = float(traj.t[-1])
    tension = np.asarray(traj["tension"])
    lines = (f"{traj.engine} on {traj.meta.get('rig')}: t = 0 .. {t_end:.6g} s, {len(traj.t)} samples every "
             f"{args.dt_out:g} s; tensions {tension.min():.6g} .. {tension.max():.6g} N; wrote {args.out}")
    if traj.meta.get("first_slack"):
        wire, t = traj.meta["first_slack"]
        lines += f"; wire[{wire}] slack at t = {t:.6g} s"
    if not traj.meta.get("taut_failure") and t_end < args.duration * (1.0 - 1e-9):
        lines += (f"; ends at {t_end:.6g} s, the last multiple of --dt-out within --duration {args.duration:g} s "
                  f"(the last {args.duration - t_end:.3g} s are not sampled)")
    return lines


def _cmd_mjcf(args) -> int:
    from .engines.mjcf import write_model_files

    loaded = [_load(path)[0] for path in args.rigs]
    names: dict[str, str] = {}
    for path, rig in zip(args.rigs, loaded):
        if rig.name in names:
            raise RigError(path, "name", f"{rig.name!r} is also the name of {names[rig.name]}: each rig's model goes to "
                           f"{args.out}/<name>/, so the names must differ")
        names[rig.name] = path
    for rig in loaded:
        for written in write_model_files(rig, Path(args.out) / rig.name):
            print(written)
    return OK


def _cmd_list(args) -> int:
    import textwrap

    if args.rigs:
        return _list_shipped()
    from .suite import registered

    for c in registered(slow=True):
        tags = ",".join(sorted(c.tags))
        print(f"{c.name}  [{tags}]  {c.source}")
        text = " ".join(c.description.split())
        print(textwrap.fill(text, width=100, initial_indent="    ", subsequent_indent="    ",
                            break_on_hyphens=False) if text else "    -")
    return OK


def _list_shipped() -> int:
    """``list --rigs``: per kind, one line per shipped file: its name and description."""
    from .assets import KINDS, MODELS, description, shipped

    for kind in KINDS:
        files = shipped(kind)
        folders = ", ".join(str(MODELS / f) for f in KINDS[kind])
        print(f"{kind}s, in {folders}:")
        width = max(map(len, files))
        for name, path in files.items():
            print(f"  {name:<{width}}  {description(path, width=96 - width)}")
    return OK


def _cmd_all(args) -> int:
    from .suite import registered, run_cases, select

    cases = select(registered(slow=args.slow or bool(args.tag)), args.pattern, args.tag)
    return run_cases(cases, jobs=args.jobs, json_path=args.json, on_result=_recorder(args.rerun, folder=True),
                     progress=True, reports=_reports(args, cases), traces=bool(args.html))


def _cmd_case(args) -> int:
    from .suite import find, run_cases

    cases = [find(args.name)]
    return run_cases(cases, jobs=1, json_path=args.json, on_result=_recorder(args.rerun, folder=False),
                     reports=_reports(args, cases), traces=bool(args.html))


def _reports(args, cases) -> list:
    """The writers of ``--junit`` and ``--html``, each called with the results and the wall time."""
    out = []
    if args.junit:
        from .report.junit import write_junit

        out.append(lambda results, seconds: write_junit(args.junit, results, seconds))
    if args.html:
        from .report.suite_page import write_suite_html

        descriptions = {c.name: c.description for c in cases}
        extra = []
        if getattr(args, "slow", False):  # the stored speed-accuracy result: benchmarks/speed_accuracy.py
            from .report.speed_accuracy import SpeedAccuracySection, load

            extra.append(SpeedAccuracySection(load()))
        command = "python -m validate " + shlex.join(args.argv)
        out.append(lambda results, seconds: write_suite_html(args.html, results, seconds, descriptions, extra, command))
    return out


def _recorder(dest: str | None, folder: bool):
    """None without ``--rerun``; else a function writing a case result's recording to ``dest`` (a
    file), or to ``dest/<case>.rrd`` with ``folder``."""
    if not dest:
        return None
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
    "mjcf": _cmd_mjcf,
    "identify": identify_cli.run,
    "boat": boat_cli.run,
    "tensor": tensor_cli.run,
    "plan": plan_cli.run,
    "sweep": sweep_cli.run,
}
