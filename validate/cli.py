"""``python -m validate``: run the validation suite, and the rig tools it is built on.

Every error is one line on stderr (``error: FILE: FIELD: problem``), never a traceback; warnings
raised during a command that then fails are dropped, so that the error stays one line. A numerical
failure inside the physics (a singular matrix, a solver that does not converge, a spent work budget)
is exit status 4 and names the field most likely responsible.
"""

from __future__ import annotations

import argparse
import os
import sys
import traceback
import warnings

from bifilar.rig import RigError

from .argtypes import OneLineParser, UsageError
from .commands import all as all_cmd
from .commands import boat, calibrate, case, identify, mjcf, modes, plan, simulate, sweep, tensor
from .commands import list as list_cmd
from .statuses import BAD_INPUT, BROKEN_PIPE, INTERRUPTED, RUN_FAILED, RunFailed, epilog
from .stdout import StdoutFailed
from .stdout import guarded as guarded_stdout

EPILOG = epilog(examples=(
    "python -m validate modes models/rigs/plate.toml",
    "python -m validate modes plate                      # a shipped rig by name (list --rigs)",
    "python -m validate simulate models/rigs/plate.toml --engine kane --duration 60 --out plate.csv",
    "python -m validate all -k torsion",
))

# Each command's module, in the order of the help: add_parser(subparsers) registers it, run(args) runs it.
_COMMANDS = {"all": all_cmd, "list": list_cmd, "case": case, "modes": modes, "simulate": simulate, "mjcf": mjcf,
             "identify": identify, "calibrate": calibrate, "boat": boat, "tensor": tensor, "plan": plan, "sweep": sweep}


def build_parser() -> argparse.ArgumentParser:
    parser = OneLineParser(prog="python -m validate", description=__doc__.splitlines()[0].replace("``", ""),
                           epilog=EPILOG)
    sub = parser.add_subparsers(dest="command", required=True, parser_class=OneLineParser, metavar="COMMAND")
    for module in _COMMANDS.values():
        module.add_parser(sub)
    return parser


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
                code = _COMMANDS[args.command].run(args)
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


# Where a numerical failure happened -> the rig field most likely responsible. Keys are modules' dotted
# names, or (module, function) for a finer guess; the innermost frame whose module matches wins. Keyed by
# module, not file name, so that a module moved or renamed cannot pick up or lose a field unnoticed:
# tests/test_cli_errors.py imports every module named here and finds every function.
_LIKELY_FIELD = {
    ("bifilar.rig.statics", "initial_state"): "initial",
    ("bifilar.rig.statics", "taut_shift"): "initial.rotation",
    "bifilar.rig.statics": "wire",  # rest pose: anchors, attachments and lengths
    ("bifilar.motion.kane", "from_rig"): "body.com",
    ("bifilar.motion.kane", "complete_theta5"): "wire",
    "bifilar.motion.modes": "wire",
    "bifilar.motion.simulate": "initial",
    "bifilar.motion.kane_kernel": "initial",
    "validate.engines.mjcf": "body",
    "validate.engines.mujoco_rig": "initial",
    "validate.engines.mujoco_hinge": "body.inertia",
    "validate.engines.hinge": "amplitude",
    "bifilar.identification.propagation": "uncertainty",
    "bifilar.identification.identify": "body.inertia",
    "bifilar.identification.measurement": "body.inertia",
    "validate.commands.identify": "body.inertia",
    "bifilar.identification.records.fit": "signal",  # a record the fit could not use
    "bifilar.identification.records.law": "signal",
}


def _likely_field(exc: BaseException) -> str:
    """The field :data:`_LIKELY_FIELD` names for the innermost frame of ``exc`` it knows, else ``rig``."""
    for frame, _ in reversed(list(traceback.walk_tb(exc.__traceback__))):
        module = frame.f_globals.get("__name__")
        field = _LIKELY_FIELD.get((module, frame.f_code.co_name)) or _LIKELY_FIELD.get(module)
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
