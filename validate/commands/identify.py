"""``python -m validate identify``: a moment of inertia from a measured period, with its uncertainty.

    python -m validate identify RIG.toml --axis x|y|z (--period T [--amplitude A]
        | --signal FILE.csv [--column NAME] [--kind angle|rate]) [--samples N] [--json]

The rig file gives the geometry, the mass and a starting value of the unknown moment about the body
axis (its other inertia entries are held); its ``[uncertainty]`` table gives the standard deviations
that are propagated (docs/identification.md).

* ``--period T`` (s): a period timed with the body turning about the axis at peak rotation ``A``
  (rad; default 0, small); its standard deviation is ``[uncertainty].period``.
* ``--signal FILE.csv``: the recorded angle (or, with ``--kind rate``, angular rate) about the axis
  in column ``NAME`` (default: the kind's name) against column ``t``, fitted by
  :func:`bifilar.signals.fit_csv` with the Kane model's period-amplitude coefficient; the fit's
  standard error is the period's standard deviation.
* ``--samples N``: Monte Carlo with N draws (seed 0) instead of linear propagation.

JSON: ``{"axis", "inertia", "std", "period", "period_std", "method", "budget"}`` with the moment and
its standard deviation in kg m^2, the period used and its standard deviation in s, the propagation
method (``linear`` or ``monte-carlo (N)``) and each uncertainty group's share of the variance.
With an ``[air]`` table, ``inertia`` is the apparent moment (body and air) and ``inertia_without_air``,
``inertia_without_air_std`` and ``air_share`` are added (:mod:`bifilar.identification.air`).
"""

from __future__ import annotations

import json

import numpy as np

from bifilar.rig import RigError, load_rig

from ..argtypes import positive_float, whole_number


def add_parser(subparsers) -> None:
    """Register the ``identify`` subcommand on the CLI's subparsers."""

    p = subparsers.add_parser("identify", help="a moment of inertia from a measured period, with its uncertainty")
    p.add_argument("rig")
    p.add_argument("--axis", required=True, choices=("x", "y", "z"), help="body axis of the unknown moment")
    source = p.add_mutually_exclusive_group(required=True)
    source.add_argument("--period", type=positive_float("--period"), help="measured period, s")
    source.add_argument("--signal", metavar="FILE.csv", help="recorded angle or rate about the axis")
    p.add_argument("--amplitude", type=positive_float("--amplitude"), help="peak rotation while timed, rad")
    p.add_argument("--column", help="signal column (default: the --kind)")
    p.add_argument("--kind", choices=("angle", "rate"), default="angle", help="what the signal column holds")
    p.add_argument("--samples", type=whole_number("--samples", 100), help="Monte Carlo draws instead of linear propagation")
    p.add_argument("--json", action="store_true", help="print one JSON object")


def run(args) -> int:
    """Identify, propagate and print; returns the exit status (errors are raised for cli.main)."""
    from bifilar.identification.air import vacuum, without_air
    from bifilar.identification.identify import axis_vector, identify
    from bifilar.identification.propagation import linear, monte_carlo

    from ..argtypes import UsageError

    if args.signal is not None and args.amplitude is not None:
        raise UsageError("identify: --amplitude goes with --period; a --signal's amplitude is fitted")
    if args.signal is None and (args.column is not None or args.kind != "angle"):
        raise UsageError("identify: --column and --kind go with --signal")
    rig_in_air = load_rig(args.rig)
    rig = vacuum(rig_in_air)  # the moment identified is the apparent one, the air's included
    if args.signal is None:
        period, period_std = args.period, rig.uncertainty.period
        ratio = identify(rig, args.axis, period, args.amplitude or 0.0).amplitude_ratio
    else:
        period, period_std = _signal_period(rig, args)
        ratio = 1.0
    # The uncertainty goes through the small-amplitude inversion with the amplitude ratio held: an
    # input error moves the ratio by (ratio - 1) times its relative effect, O(A^2) smaller.
    small, small_std = period / ratio, period_std / ratio
    if args.samples:
        result = monte_carlo(rig, args.axis, small, small_std, args.samples, np.random.default_rng(0))
    else:
        result = linear(rig, args.axis, small, small_std)
    report = {
        "axis": args.axis,
        "inertia": result.moment,
        "std": result.std,
        "period": period,
        "period_std": period_std,
        "method": result.method,
        "budget": result.budget,
    }
    if rig_in_air.air is not None:  # the body's own moment: the air's added moment subtracted
        own = without_air(rig_in_air, axis_vector(args.axis), result.moment, result.std)
        report.update(inertia_without_air=own.inertia, inertia_without_air_std=own.std, air_share=own.air_share)
    if args.json:
        print(json.dumps(report))
        return 0
    unit = "kg m^2"
    print(f"rig {rig.name}: I_{args.axis}{args.axis} = {result.moment:.9g} +- {result.std:.3g} {unit} "
          f"(95 %: {result.low:.9g} .. {result.high:.9g}; {result.method})")
    amplitude = f" at {args.amplitude:g} rad, small-amplitude {small:.9g} s" if ratio != 1.0 else ""
    print(f"  period {period:.9g} +- {period_std:.3g} s{amplitude}")
    shares = sorted(result.budget.items(), key=lambda kv: -kv[1])
    print("  variance budget: " + ", ".join(f"{name} {100.0 * share:.1f} %" for name, share in shares))
    if "air_share" in report:
        print(f"  without the air: {report['inertia_without_air']:.9g} +- {report['inertia_without_air_std']:.3g} "
              f"{unit} (the air is {100.0 * report['air_share']:.1f} % of the measured moment)")
    return 0


def _signal_period(rig, args) -> tuple[float, float]:
    """Small-amplitude period and its standard error from the recorded signal.

    The fit needs the period-amplitude coefficient c of the mode, which depends (weakly) on the
    moment being sought: a first fit with c = 0 gives the moment at which c is then computed.
    """
    from bifilar.identification.identify import amplitude_coefficient, invert_period
    from bifilar.identification.signals import fit_csv

    column = args.column or args.kind
    try:
        first = fit_csv(args.signal, column, args.kind)
        rough = invert_period(rig, args.axis, first.period).rig
        fit = fit_csv(args.signal, column, args.kind, amplitude_coefficient=amplitude_coefficient(rough, args.axis))
    except RigError:
        raise
    except ValueError as exc:  # a record the fit cannot use (too short, no oscillation)
        raise RigError(args.signal, column, str(exc)) from None
    return fit.period, fit.period_std
