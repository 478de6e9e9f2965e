"""``python -m validate identify``: a moment of inertia from measured periods or records, with its uncertainty.

    python -m validate identify RIG.toml --axis x|y|z (--period T [--amplitude A] | --signal FILE ...)
        [--column NAME] [--kind angle|rate|proportional] [--time-column NAME] [--fps F]
        [--time-unit s|ms] [--angle-unit rad|deg] [--from S] [--to S] [--law-sigma F]
        [--amplitude-scale K | --max-amplitude A]
        [--tare FIXTURE.toml (--tare-period T | --tare-signal FILE ...)]
        [--samples N] [--max-seconds S] [--json] [--png FILE.png] [--html FILE.html]

The rig file gives the geometry, the mass and the other inertia entries; the moment being identified
may be ``nan`` there (or any positive start value): the file's value is not checked, the identified
tensor is (positive definite, triangle inequality). ``[uncertainty]`` gives the standard deviations
propagated (docs/identification.md); without it nothing of the rig is propagated, and the output says so.

* ``--period T`` (s) timed at peak rotation ``--amplitude A`` (rad; default 0); its sigma is
  ``[uncertainty].period``.
* ``--signal FILE`` (repeatable: trials of one rig): records taken through
  :func:`bifilar.identification.records.pipeline.identify_records` (read, fit cycle by cycle with the
  rig's amplitude law and its excess learned from the record, swing checked, inverted, halves fitted,
  pooled); each trial is reported, and the pooled period goes through the propagation with the rig's
  sigmas (common to every trial) once.
* A hinge rig (``[pivot]`` or ``[torsion]``: a compound or torsion pendulum) is identified by
  :func:`bifilar.identification.hinge_measurement.measure_hinge`: ``--axis`` must be the body axis
  parallel to the hinge, a timed period is taken to zero amplitude by the exact law, and the records
  go through the same loop with the rig's own law (docs/identification.md, section 9).
* ``--tare FIXTURE.toml``: the fixture alone (same body frame as RIG.toml, its own period or
  records); the object's own moment about the axis through its own COM follows by difference and
  the parallel-axis theorem.

A dense record is fitted in bins (a note says so; :mod:`bifilar.identification.records.bounds`), and the
records' fits stop with exit 4 once ``--max-seconds`` of wall time are spent, as ``simulate``'s run does.

Exit status 2 with one line for bad input; implausible results are flagged (text and JSON ``flags``).
JSON fields: docs/identification.md. With an ``[air]`` table the moment is the apparent one (body and
air) and ``inertia_without_air``, ``inertia_without_air_std`` and ``air_share`` are added
(:mod:`bifilar.identification.air`, docs/air.md).
"""

from __future__ import annotations

import json
import math
from typing import TYPE_CHECKING

import numpy as np

from bifilar.rig import RigError, load_rig

from bifilar.identification.records.bounds import SAMPLES_PER_CYCLE, WorkSpent
from bifilar.identification.records.law import EXCESS_PRIOR

from ..argtypes import UsageError, bounded_float, positive_float, whole_number
from ..statuses import RunFailed

if TYPE_CHECKING:
    from bifilar.identification.measurement import Measurement, ObjectMoment


def add_parser(subparsers) -> None:
    """Register the ``identify`` subcommand on the CLI's subparsers."""

    from ..statuses import epilog

    p = subparsers.add_parser("identify", help="a moment of inertia from measured periods or records, with its uncertainty",
                              epilog=epilog("identify", (
                                  "python -m validate identify bench_plate --axis z --period 1.5 --json",
                                  "python -m validate identify bench_plate --axis z --signal video.csv --fps 60")))
    p.add_argument("rig", help="rig file (TOML) holding the body as hung; the unknown moment may be nan there")
    p.add_argument("--axis", required=True, choices=("x", "y", "z"), help="body axis of the unknown moment")
    source = p.add_mutually_exclusive_group(required=True)
    source.add_argument("--period", type=positive_float("--period"), help="measured period, s")
    source.add_argument("--signal", metavar="FILE", action="append", help="a record (repeat for several trials)")
    p.add_argument("--amplitude", type=positive_float("--amplitude"), help="peak rotation while timed, rad (with --period)")
    add_record_arguments(p)
    p.add_argument("--tare", metavar="FIXTURE.toml", help="the fixture alone, to subtract")
    tare = p.add_mutually_exclusive_group()
    tare.add_argument("--tare-period", type=positive_float("--tare-period"), help="the fixture's period, s")
    tare.add_argument("--tare-signal", metavar="FILE", action="append", help="a record of the fixture alone")
    p.add_argument("--samples", type=whole_number("--samples", 100),
                   help="Monte Carlo draws instead of linear propagation, at least 100 (default: none, linear propagation)")
    p.add_argument("--max-seconds", type=positive_float("--max-seconds"), default=600.0,
                   help="wall-time budget of the records' fits, s; they stop with exit 4 when it is spent "
                        "(default: 600). A dense record is fitted in bins leaving at least 200 samples a cycle "
                        "(a note says so): its time grows with the rows read, not faster")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument("--png", metavar="FILE.png", help="draw each record, its fit, residuals and period against amplitude")
    p.add_argument("--html", metavar="FILE.html", help="write one self-contained page: the result, the fits, the "
                                                       "variance budget, the tensor check and the inputs")


def add_record_arguments(p) -> None:
    """The record options (``--column`` .. ``--max-amplitude``), shared by ``identify`` and ``calibrate``."""
    p.add_argument("--column", help="record column (default: the --kind's name, else the only non-time column)")
    p.add_argument("--kind", choices=("angle", "rate", "proportional"), default="angle",
                   help="what the column holds (default angle; proportional: any unit, e.g. pixels, its scale "
                        "unknown: give --amplitude-scale or --max-amplitude for the amplitude correction)")
    p.add_argument("--time-column", help="time column (default: t, time or timestamp; with --fps: frame first)")
    p.add_argument("--fps", type=positive_float("--fps"), help="frames per second: the time column holds frame numbers")
    p.add_argument("--time-unit", choices=("s", "ms"), default="s", help="unit of the time column (default s)")
    p.add_argument("--angle-unit", choices=("rad", "deg"), default="rad", help="angle (or rate) unit (default rad)")
    p.add_argument("--from", dest="start", type=float, metavar="S", help="use the record from this time, s")
    p.add_argument("--to", dest="end", type=float, metavar="S", help="use the record up to this time, s")
    p.add_argument("--law-sigma", type=bounded_float("--law-sigma", 0.0, 10.0, ""), default=None, metavar="F",
                   help="prior std of the real rig's amplitude-law excess, relative to the ideal coefficient "
                        f"(default {EXCESS_PRIOR:g}; 0: the ideal law exactly)")
    scale = p.add_mutually_exclusive_group()
    scale.add_argument("--amplitude-scale", type=positive_float("--amplitude-scale"), metavar="K",
                       help="a proportional record's units per rad (e.g. pixels per rad): it is then an angle record")
    scale.add_argument("--max-amplitude", type=bounded_float("--max-amplitude", 0.0, math.pi, "rad", low_open=True),
                       metavar="A", help="the largest swing a proportional record can have had, rad: its scale is "
                                         "fitted within [0, A / first amplitude] and the rest of the doubt is in the sigma")


def run(args) -> int:
    """Identify, propagate, check and print; returns the exit status (errors raised for cli.main)."""
    from bifilar.identification.measurement import subtract_tare

    _check_options(args)
    try:
        result = _measure(args.rig, args, args.period, args.signal, args.amplitude)
        if args.tare:
            result = subtract_tare(result, _measure(args.tare, args, args.tare_period, args.tare_signal, None))
    except WorkSpent as exc:
        raise RunFailed(f"{exc} (--max-seconds {args.max_seconds:g}): give more, or a shorter record "
                        "(--from, --to)") from None
    trials = result.trials + (result.tare.trials if result.tare else ())
    if args.png and trials:
        from ..report.identify_png import draw

        draw(trials, args.png)
    if args.html:
        from ..report.identify_page import write_identify_html

        write_identify_html(args.html, result, args)
    if args.json:
        print(json.dumps(clean(result.as_dict()), allow_nan=False))
        return 0
    _print(result)
    if args.tare:
        _print(result.tare, "fixture")
        _print_object(result.object_part, args.axis)
    return 0


def _measure(path: str, args, period, signals, amplitude) -> Measurement:
    """:func:`bifilar.identification.measurement.measure` of one rig file (the rig, or a --tare fixture)."""
    from bifilar.identification.hinge_measurement import measure_hinge
    from bifilar.identification.measurement import measure
    from bifilar.rig.hinge import HingeRig

    rig = load_rig(path, free_moment="xyz".index(args.axis), hinge=True)
    if isinstance(rig, HingeRig):
        if args.samples:
            raise UsageError("identify: --samples: a hinge rig's moment is an explicit function of its inputs, "
                             "propagated linearly; leave --samples out")
        how, kwargs = measure_hinge, {}
    else:
        how, kwargs = measure, {"samples": args.samples}
    if signals is not None:
        return how(rig, args.axis, signals=signals, options=record_options(args), **kwargs)
    try:
        return how(rig, args.axis, period=period, amplitude=amplitude, **kwargs)
    except RigError as exc:
        if exc.field == "period":
            option = "--period" if path == args.rig else "--tare-period"
            raise UsageError(f"identify: {option}: {exc.problem}") from None
        raise


def _check_options(args) -> None:
    check_record_options(args, "identify", args.signal is not None or args.tare_signal is not None)
    if args.tare and args.tare_period is None and args.tare_signal is None:
        raise UsageError("identify: --tare needs --tare-period or --tare-signal")
    if not args.tare and (args.tare_period is not None or args.tare_signal is not None):
        raise UsageError("identify: --tare-period and --tare-signal go with --tare")


def check_record_options(args, verb: str, uses_signal: bool) -> None:
    """The record options' one-line refusals (``verb``: the command named in them): given without a
    record, or with each other where they do not go."""
    if args.signal is not None and args.amplitude is not None:
        raise UsageError(f"{verb}: --amplitude goes with --period; a --signal's amplitude is fitted")
    record_options = {"--law-sigma": args.law_sigma, "--column": args.column, "--time-column": args.time_column,
                      "--fps": args.fps, "--from": args.start, "--to": args.end, "--amplitude-scale": args.amplitude_scale,
                      "--max-amplitude": args.max_amplitude}
    record_options["--kind"] = None if args.kind == "angle" else args.kind
    record_options["--time-unit"] = None if args.time_unit == "s" else args.time_unit
    record_options["--angle-unit"] = None if args.angle_unit == "rad" else args.angle_unit
    if not uses_signal:
        given = [k for k, v in record_options.items() if v is not None]
        if given:
            raise UsageError(f"{verb}: {given[0]} goes with --signal")
    if (args.amplitude_scale or args.max_amplitude) and args.kind != "proportional":
        option = "--amplitude-scale" if args.amplitude_scale else "--max-amplitude"
        raise UsageError(f"{verb}: {option} goes with --kind proportional (an angle or a rate has its scale)")
    if args.fps is not None and args.time_unit != "s":
        raise UsageError(f"{verb}: --time-unit goes with a time column, not with --fps (frame numbers)")
    if args.start is not None and args.end is not None and args.end <= args.start:
        raise UsageError(f"{verb}: --to {args.end:g} must be after --from {args.start:g}")
    for name, value in (("--from", args.start), ("--to", args.end)):
        if value is not None and not math.isfinite(value):
            raise UsageError(f"{verb}: {name} must be finite, got {value!r}")


def record_options(args):
    """identify's record options as the pipeline takes them."""
    from bifilar.identification.records.pipeline import RecordOptions

    return RecordOptions(args.column, args.kind, args.time_column, args.fps, args.time_unit, args.angle_unit,
                         args.start, args.end, EXCESS_PRIOR if args.law_sigma is None else args.law_sigma,
                         args.amplitude_scale, args.max_amplitude, args.max_seconds)


def clean(value):
    """JSON-safe: numpy scalars to Python, non-finite numbers to None (JSON has no NaN)."""
    if isinstance(value, dict):
        return {k: clean(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [clean(v) for v in value]
    if isinstance(value, (float, np.floating)):
        return float(value) if math.isfinite(value) else None
    if isinstance(value, np.integer):
        return int(value)
    return value


WIDTH = 100  # text reports are wrapped at this many columns


def say(text: str, indent: int = 2) -> None:
    """One item of the text report, wrapped at :data:`WIDTH` columns, continued further indented."""
    import textwrap

    print(textwrap.fill(text, WIDTH, initial_indent=" " * indent, subsequent_indent=" " * (indent + 4),
                        break_on_hyphens=False, break_long_words=False))


def _print(result: Measurement, label: str | None = None) -> None:
    a, unit = result.axis, "kg m^2"
    name = f"rig {result.rig}" + (f" ({label})" if label else "")
    if result.std is None:
        say(f"{name}: I_{a}{a} = {result.inertia:.9g} {unit} (no uncertainty propagated)", 0)
    else:
        low, high = result.interval95
        say(f"{name}: I_{a}{a} = {result.inertia:.9g} +- {result.std:.3g} {unit} "
             f"(95 %: {low:.9g} .. {high:.9g}; {result.method})", 0)
    parts = [f"{what} {std:.3g}" for std, what in ((result.std_repeatability, "repeatability"),
                                                  (result.std_rig, "rig geometry and mass")) if std]
    if parts:
        say("sigma: " + ", ".join(parts) + f" {unit}")
    spm = result.std_per_mass
    say(f"I/m = {result.inertia_per_mass:.9g}" + (f" +- {spm:.3g}" if spm is not None else "") + " m^2, radius of "
         f"gyration {result.radius_of_gyration:.6g} m")
    std = result.period_std
    say(f"period (zero amplitude) {result.period:.9g}" + (f" +- {std:.3g}" if std else "") +
         f" s ({result.period_std_source}); d ln T / d ln I = {result.sensitivity:.3g}")
    if result.air is not None:
        say(f"without the air: {result.air.inertia:.9g} +- {result.air.std:.3g} {unit} (the air is "
             f"{100.0 * result.air.share:.1f} % of the measured moment)")
    if result.budget:
        shares = sorted(result.budget.items(), key=lambda kv: -kv[1])
        say("variance budget: " + ", ".join(f"{g} {100.0 * s:.1f} %" for g, s in shares))
        shares = sorted(result.budget_per_mass.items(), key=lambda kv: -kv[1])
        say("variance budget of I/m: " + ", ".join(f"{g} {100.0 * s:.1f} %" for g, s in shares))
    for i, tr in enumerate(result.trial_dicts(), start=1):
        print_trial(i, tr)
    if len(result.trials) > 1:
        say(f"between trials: std {result.pooled.between_trial_std:.3g} {unit}, chi^2/dof "
             f"{result.pooled.chi2_per_dof:.3g}")
    # with air, the body's own tensor is the one that must be a body's (the apparent one need not be)
    check, whose = ((result.air.tensor_check, " (the body's, without the air)") if result.air is not None else
                    (result.tensor_check, ""))
    say(f"identified tensor{whose}: principal {', '.join(f'{x:.6g}' for x in check.principal)}; positive "
         f"definite {'yes' if check.positive_definite else 'NO'}, triangle inequality "
         f"{'yes' if check.triangle else 'NO'}")
    for flag in result.flags:
        say(f"warning: {flag}")


def sigma_parts(tr: dict) -> str:
    """What makes the record's T0 variance (:func:`bifilar.identification.measurement.sigma_shares`)."""
    from bifilar.identification.measurement import sigma_shares

    said = [f"{what} {100.0 * share:.0f} %" for what, share in sigma_shares(tr)]
    return f"; its variance: {', '.join(said)}" if said else ""


def print_trial(i: int, tr: dict, key: str = "inertia", symbol: str = "I", unit: str = "kg m^2") -> None:
    """A trial in one line each: its result (``tr[key]``, printed as ``symbol`` in ``unit``), swing and
    damping, amplitude law, halves, what was left out."""
    say(f"trial {i} {tr['source']}: T0 {tr['period']:.9g} +- {tr['period_std']:.3g} s (record "
        f"{tr['period_std_statistical']:.2g}, amplitude law {tr['period_std_law']:.2g}), {symbol} {tr[key]:.9g} "
        f"+- {tr['std']:.3g} {unit}")
    if tr["crb_ratio"] is not None:
        say(f"T0 sigma (record) {tr['period_std_statistical']:.2g} s = {tr['crb_ratio']:.2f}x the Cramér-Rao bound "
            f"{tr['crb']:.2g} s ({tr['crb_noise']} noise){sigma_parts(tr)}", 4)
    amp, d = tr["amplitude"], tr["damping"]
    swing = f"{amp[0]:.3g} -> {amp[1]:.3g} rad" if amp else "in rad unknown (proportional)"
    second = tr["second_mode"]
    say(f"swing {swing} over {tr['cycles']} cycles; damping {d['linear']:.2g} + {d['quadratic']:.2g} |w| + dry "
         f"{d['dry']:.2g}; rms {tr['residual_rms']:.3g}" + (f"; second mode {second['period']:.4g} s" if second else ""),
         4)
    law = tr["law"]
    if law["ideal"] is None:
        say(f"amplitude law: {law['kind']}" + (f" ({law['note']})" if law["note"] else ""), 4)
    elif law["conflict"] is not None:
        say(f"amplitude law: {law['kind']}, ideal {law['ideal']:.4g} A^2, the record's {law['coefficient']:.4g} "
             f"A^2, {law['conflict']:.2g} prior sigmas off: no real rig's law, T0's sigma holds the ideal law's "
             "T0 too (see the flags)", 4)
    elif law["excess_std"] == 0.0:
        say(f"amplitude law: {law['kind']}, T(A)/T0 - 1 = {law['ideal']:.4g} A^2 + ... (the ideal law, held)", 4)
    else:
        rel, rel_std = law["excess"] / law["ideal"], law["excess_std"] / abs(law["ideal"])
        say(f"amplitude law: {law['kind']}, ideal {law['ideal']:.4g} A^2, the record's {law['coefficient']:.4g} "
             f"A^2 (excess {100.0 * rel:+.1f} +- {100.0 * rel_std:.1f} %, {100.0 * law['learned']:.0f} % learned from "
             "the record, the rest prior)", 4)
    if tr["binned"] > 1:
        say(f"a dense record: fitted in bins of {tr['binned']} samples ({tr['samples']} bins, at least "
             f"{SAMPLES_PER_CYCLE} a cycle)", 4)
    h = tr["halves"]
    if h is not None:
        say(f"halves: T0 {h['first']['period']:.9g} +- {h['first']['period_std']:.2g} s and "
             f"{h['second']['period']:.9g} +- {h['second']['period_std']:.2g} s, z = {h['z']:+.2f}", 4)
    else:
        say("halves: a half holds too few cycles to fit alone", 4)
    r = tr["rejected"]
    if r["samples"]:
        spans = ", ".join(f"{a:.4g}..{b:.4g} s" for a, b in r["spans"][:6]) + (" ..." if len(r["spans"]) > 6 else "")
        say(f"left out: {r['samples']} samples ({r['cycles']} in whole cycles, {r['glitches']} glitches, "
             f"{r['stuck']} stuck values; {tr['dropped']} rows had no value): {spans}", 4)


def _print_object(obj: ObjectMoment, axis: str) -> None:
    std = f" +- {obj.std:.3g}" if obj.std is not None else " (no uncertainty propagated)"
    say(f"object (rig minus fixture, {obj.mass:.6g} kg at COM {', '.join(f'{x:.6g}' for x in obj.com)} m): "
         f"I_{axis}{axis} about its own COM = {obj.inertia:.9g}{std} kg m^2", 0)
    for flag in obj.flags:
        say(f"warning: {flag}")
