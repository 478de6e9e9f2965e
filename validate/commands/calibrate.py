"""``python -m validate calibrate``: a torsion rod's stiffness from a body of known inertia, with its uncertainty.

    python -m validate calibrate ROD.toml (--period T [--amplitude A] | --signal FILE ...)
        [--column NAME] [--kind angle|rate|proportional] [--time-column NAME] [--fps F]
        [--time-unit s|ms] [--angle-unit rad|deg] [--from S] [--to S] [--law-sigma F]
        [--amplitude-scale K | --max-amplitude A] [--max-seconds S] [--json]

ROD.toml is a torsion rig (``[torsion]``, docs/rig-file.md) whose body's moment about the rod is known:
its ``inertia`` or a ``cylinder`` (the rod's shape and mass). k = 4 pi^2 J / T0^2
(:func:`bifilar.identification.hinge_measurement.calibrate_rod`); its sigma is propagated from the
period's (``[uncertainty].period`` for a timed period, the records' fits for records) and the mass's
(``[uncertainty].mass``: the body's moment scales with its mass at a fixed shape). The record options
are ``identify``'s; several ``--signal`` files are trials of the same rod, pooled.

A ``torsion.stiffness`` in the file is not used (it is what is calibrated): the output notes how far
it is from the one found, so that a rod's nominal stiffness (from a handbook shear modulus) can be
checked against it. A pivot rig, or a body whose moment about the rod is unknown (``nan``), is refused
in one line (exit 2). JSON: ``stiffness``, ``stiffness_std``, ``interval95``, ``moment``, ``period``,
``period_std``, ``budget``, ``trials``, ``flags`` (docs/identification.md).
"""

from __future__ import annotations

import json

from bifilar.identification.records.bounds import WorkSpent
from bifilar.rig import RigError, load_rig

from ..argtypes import UsageError, positive_float
from ..statuses import RunFailed
from .identify import clean, print_trial, say, add_record_arguments, check_record_options, record_options


def add_parser(subparsers) -> None:
    """Register the ``calibrate`` subcommand on the CLI's subparsers."""
    from ..statuses import epilog

    p = subparsers.add_parser("calibrate", help="a torsion rod's stiffness from a body of known inertia",
                              epilog=epilog("calibrate", (
                                  "python -m validate calibrate calibration_rod --period 1.2",
                                  "python -m validate calibrate calibration_rod --signal a.csv --signal b.csv "
                                  "--kind rate --json")))
    p.add_argument("rig", help="torsion rig file (TOML) whose body's moment about the rod is known")
    source = p.add_mutually_exclusive_group(required=True)
    source.add_argument("--period", type=positive_float("--period"), help="measured period, s")
    source.add_argument("--signal", metavar="FILE", action="append", help="a record (repeat for several trials)")
    p.add_argument("--amplitude", type=positive_float("--amplitude"), help="peak rotation while timed, rad (with --period)")
    add_record_arguments(p)
    p.add_argument("--max-seconds", type=positive_float("--max-seconds"), default=600.0,
                   help="wall-time budget of the records' fits, s; they stop with exit 4 when it is spent (default: 600)")
    p.add_argument("--json", action="store_true", help="print one JSON object")


def run(args) -> int:
    """Calibrate and print; returns the exit status (errors raised for cli.main)."""
    from bifilar.identification.hinge_measurement import calibrate_rod
    from bifilar.rig.hinge import HingeRig

    check_record_options(args, "calibrate", args.signal is not None)
    rig = load_rig(args.rig, hinge=True)
    if not isinstance(rig, HingeRig) or rig.kind != "torsion":
        table = "[pivot]" if isinstance(rig, HingeRig) else "[[wire]]"
        raise RigError(args.rig, table.strip("[]"), f"a {table} rig: calibrate takes a torsion rod ([torsion]) "
                       "carrying a body of known inertia")
    try:
        if args.signal is not None:
            result = calibrate_rod(rig, signals=args.signal, options=record_options(args))
        else:
            result = calibrate_rod(rig, period=args.period, amplitude=args.amplitude)
    except WorkSpent as exc:
        raise RunFailed(f"{exc} (--max-seconds {args.max_seconds:g}): give more, or a shorter record "
                        "(--from, --to)") from None
    except RigError as exc:
        if exc.field == "period" and args.signal is None:
            raise UsageError(f"calibrate: --period: {exc.problem}") from None
        raise
    if args.json:
        print(json.dumps(clean(result.as_dict()), allow_nan=False))
        return 0
    low, high = result.interval95
    say(f"rig {result.rig}: torsion stiffness k = {result.stiffness:.9g} +- {result.std:.3g} N m/rad "
         f"(95 %: {low:.9g} .. {high:.9g}; linear)", 0)
    say(f"from the body's known moment about the rod {result.moment:.9g} kg m^2")
    std = result.period_std
    say(f"period (zero amplitude) {result.period:.9g}" + (f" +- {std:.3g}" if std else "") +
         f" s ({result.period_std_source})")
    if result.std > 0.0:
        shares = sorted(result.budget.items(), key=lambda kv: -kv[1])
        say("variance budget: " + ", ".join(f"{g} {100.0 * s:.1f} %" for g, s in shares))
    for i, tr in enumerate(result.trial_dicts(), start=1):
        print_trial(i, tr, "stiffness", "k", "N m/rad")
    if len(result.trials) > 1:
        say(f"between trials: std {result.pooled.between_trial_std:.3g} N m/rad, chi^2/dof "
             f"{result.pooled.chi2_per_dof:.3g}")
    for flag in result.flags:
        say(f"warning: {flag}")
    return 0
