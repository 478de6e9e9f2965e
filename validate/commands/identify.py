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

import numpy as np

from bifilar.rig import RigError, load_rig

from bifilar.identification.records.bounds import SAMPLES_PER_CYCLE, WorkSpent
from bifilar.identification.records.law import EXCESS_PRIOR

from ..argtypes import UsageError, bounded_float, positive_float, whole_number

AXIS_INDEX = {"x": 0, "y": 1, "z": 2}
WEAK_SENSITIVITY = 0.02  # d ln T / d ln I below this: the period barely depends on the moment


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


def run(args) -> int:
    """Identify, propagate, check and print; returns the exit status (errors raised for cli.main)."""
    _check_options(args)
    try:
        report, trials = _identify(args.rig, args, args.period, args.signal)
        if args.tare:
            fixture, tare_trials = _identify(args.tare, args, args.tare_period, args.tare_signal, amplitude=None)
            report["tare"] = fixture
            report["object"] = _transfer(args, report, fixture)
            trials = trials + tare_trials
    except WorkSpent as exc:
        from ..cli import RunFailed

        raise RunFailed(f"{exc} (--max-seconds {args.max_seconds:g}): give more, or a shorter record "
                        "(--from, --to)") from None
    if args.png and trials:
        from ..report.identify_png import draw

        draw(trials, args.png)
    if args.html:
        from ..report.identify_page import write_identify_html

        write_identify_html(args.html, report, trials, args)
    if args.json:
        print(json.dumps(_clean(report), allow_nan=False))
        return 0
    _print(report)
    if args.tare:
        _print(report["tare"], "fixture")
        _print_object(report["object"], args.axis)
    return 0


def _check_options(args) -> None:
    if args.signal is not None and args.amplitude is not None:
        raise UsageError("identify: --amplitude goes with --period; a --signal's amplitude is fitted")
    uses_signal = args.signal is not None or args.tare_signal is not None
    record_options = {"--law-sigma": args.law_sigma, "--column": args.column, "--time-column": args.time_column,
                      "--fps": args.fps, "--from": args.start, "--to": args.end, "--amplitude-scale": args.amplitude_scale,
                      "--max-amplitude": args.max_amplitude}
    record_options["--kind"] = None if args.kind == "angle" else args.kind
    record_options["--time-unit"] = None if args.time_unit == "s" else args.time_unit
    record_options["--angle-unit"] = None if args.angle_unit == "rad" else args.angle_unit
    if not uses_signal:
        given = [k for k, v in record_options.items() if v is not None]
        if given:
            raise UsageError(f"identify: {given[0]} goes with --signal")
    if (args.amplitude_scale or args.max_amplitude) and args.kind != "proportional":
        option = "--amplitude-scale" if args.amplitude_scale else "--max-amplitude"
        raise UsageError(f"identify: {option} goes with --kind proportional (an angle or a rate has its scale)")
    if args.fps is not None and args.time_unit != "s":
        raise UsageError("identify: --time-unit goes with a time column, not with --fps (frame numbers)")
    if args.start is not None and args.end is not None and args.end <= args.start:
        raise UsageError(f"identify: --to {args.end:g} must be after --from {args.start:g}")
    for name, value in (("--from", args.start), ("--to", args.end)):
        if value is not None and not math.isfinite(value):
            raise UsageError(f"identify: {name} must be finite, got {value!r}")
    if args.tare and args.tare_period is None and args.tare_signal is None:
        raise UsageError("identify: --tare needs --tare-period or --tare-signal")
    if not args.tare and (args.tare_period is not None or args.tare_signal is not None):
        raise UsageError("identify: --tare-period and --tare-signal go with --tare")


def _start_value(rig, axis: str):
    """The rig with a nan moment replaced by a start value (the mean of the other two diagonal
    entries: positive, and inside the triangle inequality of a diagonal tensor), and whether it was nan."""
    from bifilar.identification.identify import with_moment

    k = AXIS_INDEX[axis]
    if not math.isnan(rig.inertia[k, k]):
        return rig, False
    inertia = np.where(np.isnan(rig.inertia), 0.0, rig.inertia)
    others = [inertia[i, i] for i in range(3) if i != k]
    from dataclasses import replace

    return with_moment(replace(rig, inertia=inertia), axis, 0.5 * sum(others)), True


def _identify(path: str, args, period, signals, amplitude="args"):
    """(report dict, trials) for one rig file (the rig, or a --tare fixture)."""
    from bifilar.identification.air import vacuum, without_air
    from bifilar.identification.identify import axis_vector, identify, pencil, with_moment
    from bifilar.identification.records.pipeline import identify_records

    axis = args.axis
    amplitude = args.amplitude if amplitude == "args" else amplitude
    rig_in_air, was_nan = _start_value(load_rig(path, free_moment=AXIS_INDEX[axis]), axis)
    rig = vacuum(rig_in_air)  # the moment identified is the apparent one, the air's included
    flags = []
    trials = []
    p = pencil(rig, axis)  # the rig's one rest-pose search: everything below is about this rest pose
    if signals is None:
        try:
            found = identify(rig, axis, period, amplitude or 0.0, p.lin.rest)
        except RigError as exc:
            if exc.field == "period":
                option = "--period" if path == args.rig else "--tare-period"
                raise UsageError(f"identify: {option}: {exc.problem}") from None
            raise
        ratio, small = found.amplitude_ratio, period / found.amplitude_ratio
        small_std = rig.uncertainty.period / ratio
        period_std_source = ("the rig file's [uncertainty].period" if small_std > 0.0 else
                             "none: the rig file states no [uncertainty].period")
        pooled = None
    else:
        trials, pooled = identify_records(rig, axis, signals, _record_options(args), p)
        small, small_std, ratio = pooled.period, pooled.period_std, 1.0
        period_std_source = "the records' fits"
        for tr in trials:
            flags.extend(tr.flags)
        if not pooled.consistent:
            flags.append(f"the {len(trials)} trials scatter more than their stated sigmas (chi^2 per degree of "
                         f"freedom {pooled.chi2_per_dof:.3g}): the pooled sigma is scaled by its square root")
    report = _propagate(rig, axis, small, small_std, args.samples, flags, p)
    report["period_std_source"] = period_std_source
    report["start_value"] = "nan in the rig file" if was_nan else "the rig file's value (a start only)"
    if pooled is None:
        report.update({key: None for key in _PER_RECORD}, trials=[], between_trial_std=None, chi2_per_dof=None)
        report["amplitude"] = [amplitude, amplitude] if amplitude else None
        if ratio != 1.0:
            report["timed_period"] = period
    else:
        report["trials"] = [_trial(tr, rig.mass) for tr in trials]
        one = report["trials"][0] if len(trials) == 1 else None
        for key in _PER_RECORD:  # one record: its own fields at the top as well
            report[key] = one[key] if one else None
        report["between_trial_std"] = pooled.between_trial_std
        report["chi2_per_dof"] = pooled.chi2_per_dof
    report["rig"] = rig.name
    if rig_in_air.air is not None:  # the body's own moment: the air's added moment subtracted
        own = without_air(rig_in_air, axis_vector(axis), report["inertia"], report["std"] or 0.0)
        report.update(inertia_without_air=own.inertia, inertia_without_air_std=own.std, air_share=own.air_share)
        # The air is no rigid body: the apparent tensor may break the triangle inequality; the body's must not.
        report["tensor_check_without_air"] = check = _tensor_check(with_moment(rig, axis, own.inertia).inertia)
        if check["positive_definite"] and check["triangle"]:
            report["flags"] = [f for f in report["flags"] if not f.startswith("the identified tensor")]
    return report, trials


def _propagate(rig, axis: str, period: float, period_std: float, samples, flags: list, p) -> dict:
    """The propagated moment and everything derived from it (per mass, checks, flags); ``p`` is the
    rig's pencil about ``axis`` (its rest pose and linearisation)."""
    from bifilar.identification.identify import invert_period, with_moment
    from bifilar.identification.propagation import budget, linear_axes, monte_carlo

    found = invert_period(rig, axis, period, p.lin.rest, p)
    geometry = [g for g in ("length", "anchor", "attach", "mass", "com") if getattr(rig.uncertainty, g) > 0.0]
    if samples and (geometry or period_std > 0.0):
        result = monte_carlo(rig, axis, period, period_std, samples, np.random.default_rng(0))
    else:
        result = linear_axes(rig, {axis: period}, period_std, p.lin.rest, {axis: found}, p.lin)[axis]
    j, m = result.moment, found.rig.mass
    inp = result.inputs
    parts = (result.gradient * inp.std) ** 2
    groups = np.array(inp.groups)
    rep_var, rig_var = float(parts[groups == "period"].sum()), float(parts[groups != "period"].sum())
    # J / m: the same inputs; the mass enters as d(J/m)/dm = (dJ/dm)/m - J/m^2
    per_mass_gradient = result.gradient / m
    per_mass_gradient[groups == "mass"] -= j / m**2
    std_pm = float(np.sqrt(np.sum((per_mass_gradient * inp.std) ** 2)))
    propagated = bool(np.any(inp.std > 0.0))
    if not geometry:
        flags.append("the rig file has no [uncertainty] for geometry or mass: nothing of the rig was propagated"
                     + ("" if period_std > 0.0 else ", nor of the period: no uncertainty is stated"))
    floor = p.floor
    if propagated and result.low <= max(floor, 0.0):
        flags.append(f"the 95 % interval reaches {result.low:.6g} kg m^2, a moment no body has (the tensor is "
                     f"positive definite only above {max(floor, 0.0):.6g}): this rig cannot determine it")
    check = _tensor_check(with_moment(rig, axis, j).inertia)
    if not check["positive_definite"] or not check["triangle"]:
        flags.append(f"the identified tensor (principal moments {', '.join(f'{x:.6g}' for x in check['principal'])}) "
                     f"{'is not positive definite' if not check['positive_definite'] else 'breaks the triangle inequality'}: "
                     "no body has it (a wrong period, mode or rig file)")
    if found.sensitivity < WEAK_SENSITIVITY:
        flags.append(f"the period hardly depends on this moment (d ln T / d ln I = {found.sensitivity:.3g}): "
                     "its uncertainty is amplified 1/(2 x that) times")
    per_mass = j / m
    k = math.sqrt(per_mass) if per_mass > 0.0 else None
    return {
        "axis": axis,
        "inertia": j,
        "std": result.std if propagated else None,
        "interval95": [result.low, result.high] if propagated else None,
        "std_repeatability": math.sqrt(rep_var) if period_std > 0.0 else None,
        "std_rig": math.sqrt(rig_var) if geometry else None,
        "period": period,
        "period_std": period_std if period_std > 0.0 else None,
        "sensitivity": found.sensitivity,
        "inertia_per_mass": per_mass,
        "std_per_mass": std_pm if propagated else None,
        "radius_of_gyration": k,
        "radius_of_gyration_std": std_pm / (2.0 * k) if propagated and k else None,
        "method": result.method,
        "budget": result.budget if propagated else None,
        "budget_per_mass": budget(inp, per_mass_gradient) if propagated else None,
        "tensor_check": check,
        "flags": flags,
    }


def _tensor_check(inertia: np.ndarray) -> dict:
    """Positive definite, and the triangle inequality of the principal moments (to rounding)."""
    principal = np.linalg.eigvalsh(inertia)
    return {"principal": principal.tolist(), "positive_definite": bool(principal[0] > 0.0),
            "triangle": bool(principal[0] + principal[1] >= principal[2] * (1.0 - 1e-9))}


_PER_RECORD = ("amplitude", "damping", "law", "halves", "rejected", "residual_rms", "outliers")


def _record_options(args):
    """identify's record options as the pipeline takes them."""
    from bifilar.identification.records.pipeline import RecordOptions

    return RecordOptions(args.column, args.kind, args.time_column, args.fps, args.time_unit, args.angle_unit,
                         args.start, args.end, EXCESS_PRIOR if args.law_sigma is None else args.law_sigma,
                         args.amplitude_scale, args.max_amplitude, args.max_seconds)


def _trial(tr, mass: float) -> dict:
    """The JSON object of one trial: its fit and the moment from it alone (repeatability sigma)."""
    fit = tr.fit
    z = 1.959963984540054
    halves = None
    if tr.halves is not None:
        h = tr.halves
        halves = {"first": {"period": h.first[0], "period_std": h.first[1]},
                  "second": {"period": h.second[0], "period_std": h.second[1]}, "split": h.split, "z": h.z}
    return {
        "source": tr.record.source,
        "period": fit.period,
        "period_std": fit.period_std,
        "period_std_statistical": fit.period_std_statistical,
        "period_std_law": fit.period_std_law,
        "period_std_white": fit.period_std_white,
        "inertia": tr.moment,
        "std": tr.moment_std,
        "interval95": [tr.moment - z * tr.moment_std, tr.moment + z * tr.moment_std],
        "inertia_per_mass": tr.moment / mass,
        "std_per_mass": tr.moment_std / mass,
        "amplitude": list(fit.amplitude) if fit.amplitude is not None else None,
        "damping": fit.damping,
        "law": fit.law.as_dict(),
        "halves": halves,
        "rejected": fit.rejected.as_dict(),
        "residual_rms": fit.rms,
        "outliers": fit.outliers.tolist(),
        "second_mode": None if fit.second_mode is None else dict(zip(("period", "amplitude", "decay"), fit.second_mode)),
        "samples": fit.samples,
        "binned": fit.binned,
        "cycles": fit.cycles,
        "dropped": tr.record.dropped,
        "unfolded": tr.record.unfolded,
        "block": fit.block,
        "jackknife": fit.jackknife,
        "flags": list(tr.flags),
    }


def _transfer(args, report: dict, fixture: dict) -> dict:
    """The object's own moment: (rig - fixture, both about the axis through their own COM) by the
    parallel-axis theorem, with the two sigmas combined as independent (conservative: the shared
    geometry errors correlate and partly cancel)."""
    from bifilar.identification.identify import axis_vector

    rig, fix = load_rig(args.rig, AXIS_INDEX[args.axis]), load_rig(args.tare, AXIS_INDEX[args.axis])
    e = axis_vector(args.axis)
    m_obj = rig.mass - fix.mass
    if m_obj <= 0.0:
        raise RigError(args.tare, "body.mass", f"{fix.mass:g} kg: not less than the rig's {rig.mass:g} kg, so no "
                                               "object is left")
    c_obj = (rig.mass * rig.com - fix.mass * fix.com) / m_obj

    def perp2(point):
        d = point - rig.com
        return float(d @ d - (d @ e) ** 2)

    about_com = report["inertia"] - (fixture["inertia"] + fix.mass * perp2(fix.com))
    own = about_com - m_obj * perp2(c_obj)
    stds = [report["std"], fixture["std"]]
    std = math.sqrt(sum(s**2 for s in stds)) if all(s is not None for s in stds) else None
    return {"mass": m_obj, "com": c_obj.tolist(), "inertia": own, "std": std,
            "interval95": [own - 1.96 * std, own + 1.96 * std] if std is not None else None,
            "inertia_per_mass": own / m_obj, "flags": [] if own > 0 else ["the object's moment is not positive"]}


def _clean(value):
    """JSON-safe: numpy scalars to Python, non-finite numbers to None (JSON has no NaN)."""
    if isinstance(value, dict):
        return {k: _clean(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_clean(v) for v in value]
    if isinstance(value, (float, np.floating)):
        return float(value) if math.isfinite(value) else None
    if isinstance(value, np.integer):
        return int(value)
    return value


WIDTH = 100  # text reports are wrapped at this many columns


def _say(text: str, indent: int = 2) -> None:
    """One item of the text report, wrapped at :data:`WIDTH` columns, continued further indented."""
    import textwrap

    print(textwrap.fill(text, WIDTH, initial_indent=" " * indent, subsequent_indent=" " * (indent + 4),
                        break_on_hyphens=False, break_long_words=False))


def _print(report: dict, label: str | None = None) -> None:
    a, unit = report["axis"], "kg m^2"
    name = f"rig {report['rig']}" + (f" ({label})" if label else "")
    if report["std"] is None:
        _say(f"{name}: I_{a}{a} = {report['inertia']:.9g} {unit} (no uncertainty propagated)", 0)
    else:
        low, high = report["interval95"]
        _say(f"{name}: I_{a}{a} = {report['inertia']:.9g} +- {report['std']:.3g} {unit} "
             f"(95 %: {low:.9g} .. {high:.9g}; {report['method']})", 0)
    parts = [f"{label} {report[key]:.3g}" for key, label in (("std_repeatability", "repeatability"),
                                                             ("std_rig", "rig geometry and mass")) if report[key]]
    if parts:
        _say("sigma: " + ", ".join(parts) + f" {unit}")
    per = report["inertia_per_mass"]
    spm = report["std_per_mass"]
    _say(f"I/m = {per:.9g}" + (f" +- {spm:.3g}" if spm is not None else "") + " m^2, radius of gyration "
         f"{report['radius_of_gyration']:.6g} m")
    std = report["period_std"]
    _say(f"period (zero amplitude) {report['period']:.9g}" + (f" +- {std:.3g}" if std else "") +
         f" s ({report['period_std_source']}); d ln T / d ln I = {report['sensitivity']:.3g}")
    if "air_share" in report:
        _say(f"without the air: {report['inertia_without_air']:.9g} +- {report['inertia_without_air_std']:.3g} "
             f"{unit} (the air is {100.0 * report['air_share']:.1f} % of the measured moment)")
    if report["budget"]:
        shares = sorted(report["budget"].items(), key=lambda kv: -kv[1])
        _say("variance budget: " + ", ".join(f"{g} {100.0 * s:.1f} %" for g, s in shares))
        shares = sorted(report["budget_per_mass"].items(), key=lambda kv: -kv[1])
        _say("variance budget of I/m: " + ", ".join(f"{g} {100.0 * s:.1f} %" for g, s in shares))
    for i, tr in enumerate(report["trials"], start=1):
        _print_trial(i, tr)
    if len(report["trials"]) > 1:
        _say(f"between trials: std {report['between_trial_std']:.3g} {unit}, chi^2/dof {report['chi2_per_dof']:.3g}")
    # with air, the body's own tensor is the one that must be a body's (the apparent one need not be)
    check, whose = ((report["tensor_check_without_air"], " (the body's, without the air)")
                    if "tensor_check_without_air" in report else (report["tensor_check"], ""))
    _say(f"identified tensor{whose}: principal {', '.join(f'{x:.6g}' for x in check['principal'])}; positive "
         f"definite {'yes' if check['positive_definite'] else 'NO'}, triangle inequality "
         f"{'yes' if check['triangle'] else 'NO'}")
    for flag in report["flags"]:
        _say(f"warning: {flag}")


def _print_trial(i: int, tr: dict) -> None:
    """A trial in one line each: its result, swing and damping, amplitude law, halves, what was left out."""
    _say(f"trial {i} {tr['source']}: T0 {tr['period']:.9g} +- {tr['period_std']:.3g} s (record "
         f"{tr['period_std_statistical']:.2g}, amplitude law {tr['period_std_law']:.2g}), I {tr['inertia']:.9g} "
         f"+- {tr['std']:.3g} kg m^2")
    amp, d = tr["amplitude"], tr["damping"]
    swing = f"{amp[0]:.3g} -> {amp[1]:.3g} rad" if amp else "swing in rad unknown (proportional)"
    second = tr["second_mode"]
    _say(f"swing {swing} over {tr['cycles']} cycles; damping {d['linear']:.2g} + {d['quadratic']:.2g} |w| + dry "
         f"{d['dry']:.2g}; rms {tr['residual_rms']:.3g}" + (f"; second mode {second['period']:.4g} s" if second else ""),
         4)
    law = tr["law"]
    if law["ideal"] is None:
        _say(f"amplitude law: {law['kind']}" + (f" ({law['note']})" if law["note"] else ""), 4)
    elif law["conflict"] is not None:
        _say(f"amplitude law: {law['kind']}, ideal {law['ideal']:.4g} A^2, the record's {law['coefficient']:.4g} "
             f"A^2, {law['conflict']:.2g} prior sigmas off: no real rig's law, T0's sigma holds the ideal law's "
             "T0 too (see the flags)", 4)
    elif law["excess_std"] == 0.0:
        _say(f"amplitude law: {law['kind']}, T(A)/T0 - 1 = {law['ideal']:.4g} A^2 + ... (the ideal law, held)", 4)
    else:
        rel, rel_std = law["excess"] / law["ideal"], law["excess_std"] / abs(law["ideal"])
        _say(f"amplitude law: {law['kind']}, ideal {law['ideal']:.4g} A^2, the record's {law['coefficient']:.4g} "
             f"A^2 (excess {100.0 * rel:+.1f} +- {100.0 * rel_std:.1f} %, {100.0 * law['learned']:.0f} % learned from "
             "the record, the rest prior)", 4)
    if tr["binned"] > 1:
        _say(f"a dense record: fitted in bins of {tr['binned']} samples ({tr['samples']} bins, at least "
             f"{SAMPLES_PER_CYCLE} a cycle)", 4)
    h = tr["halves"]
    if h is not None:
        _say(f"halves: T0 {h['first']['period']:.9g} +- {h['first']['period_std']:.2g} s and "
             f"{h['second']['period']:.9g} +- {h['second']['period_std']:.2g} s, z = {h['z']:+.2f}", 4)
    else:
        _say("halves: a half holds too few cycles to fit alone", 4)
    r = tr["rejected"]
    if r["samples"]:
        spans = ", ".join(f"{a:.4g}..{b:.4g} s" for a, b in r["spans"][:6]) + (" ..." if len(r["spans"]) > 6 else "")
        _say(f"left out: {r['samples']} samples ({r['cycles']} in whole cycles, {r['glitches']} glitches, "
             f"{r['stuck']} stuck values; {tr['dropped']} rows had no value): {spans}", 4)


def _print_object(obj: dict, axis: str) -> None:
    std = f" +- {obj['std']:.3g}" if obj["std"] is not None else " (no uncertainty propagated)"
    _say(f"object (rig minus fixture, {obj['mass']:.6g} kg at COM {', '.join(f'{x:.6g}' for x in obj['com'])} m): "
         f"I_{axis}{axis} about its own COM = {obj['inertia']:.9g}{std} kg m^2", 0)
    for flag in obj["flags"]:
        _say(f"warning: {flag}")
