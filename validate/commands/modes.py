"""``python -m validate modes RIG``: rest pose, static tensions and small-oscillation periods
(:mod:`bifilar.motion.modes`), as text or one JSON object; for heavy wires beside those on massless ones.
A hinge rig (``[pivot]`` or ``[torsion]``) has one mode, the turn about its axis (:mod:`bifilar.motion.hinge`):
its moment about the axis, restoring moment and small-amplitude period, the period as a formula in what
the rig file leaves unknown (the moment, or a calibration rod's stiffness)."""

from __future__ import annotations

import json

from ..statuses import epilog
from .shared import RIG_HELP, load


def add_parser(subparsers) -> None:
    """Register the ``modes`` subcommand on the CLI's subparsers."""
    p = subparsers.add_parser("modes", help="rest pose, static tensions and small-oscillation periods",
                              epilog=epilog("modes", ("python -m validate modes plate",
                                                      "python -m validate modes my_rig.toml --json")))
    p.add_argument("rig", help=RIG_HELP)
    p.add_argument("--json", action="store_true",
                   help="print one JSON object (COM m, rotation, tensions N, periods s, frequencies Hz, omega^2 "
                        "rad^2/s^2, mode shapes m and rad; world frame) instead of text (default: text)")


def run(args) -> int:
    """Linearise the rig about its rest pose and print each mode."""
    from bifilar.motion.modes import linearize

    rig, rest = load(args.rig, hinge=True)
    if rest is None:
        return _hinge_modes(rig, args.json)
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


def _hinge_modes(rig, as_json: bool) -> int:
    """The one mode of a hinge rig; ``None`` (JSON ``null``) for what the rig file leaves unknown."""
    import math

    from bifilar.motion.hinge import linear_period, moment_about_axis

    moment = moment_about_axis(rig)
    known = None if math.isnan(moment) else moment
    stiffness = rig.mass * rig.gravity * rig.arm if rig.kind == "pivot" else rig.stiffness  # N m/rad
    period = linear_period(rig) if known is not None and stiffness is not None else None
    motion = "swing about the pivot axis" if rig.kind == "pivot" else "twist about the rod"
    report = {
        "rig": rig.name,
        "model": "exact 1-DOF hinge (bifilar.motion.hinge); period at small amplitude",
        "kind": rig.kind, "axis": rig.axis.tolist(), "point": None if rig.point is None else rig.point.tolist(),
        "arm": rig.arm, "moment": known, "restoring": stiffness,
        "modes": [{"motion": motion, "period": period, "frequency": None if period is None else 1.0 / period,
                   "omega2": None if period is None else stiffness / known}],
    }
    if as_json:
        print(json.dumps(report, allow_nan=False))
        return 0
    where = (f"compound pendulum about the axis {_fmt(rig.axis)} through {_fmt(rig.point)} m (body frame), "
             f"arm {rig.arm:.9g} m" if rig.kind == "pivot" else f"torsion pendulum about the rod {_fmt(rig.axis)} "
             "(body frame) through the COM")
    j = "unknown (nan: what a timed period measures)" if known is None else f"{known:.9g} kg m^2"
    k = ("unknown (calibrate the rod)" if stiffness is None else
         f"{stiffness:.9g} N m/rad" + (" (m g d)" if rig.kind == "pivot" else ""))
    print(f"rig {rig.name}: {where}; moment about the axis {j}, restoring moment {k}")
    if period is not None:
        text = f"{period:.9g} s ({1.0 / period:.6g} Hz)"
    else:
        text = f"2 pi sqrt({'J' if known is None else f'{known:.9g} kg m^2'} / " \
               f"{'k' if stiffness is None else f'{stiffness:.9g} N m/rad'})"
    exact = "; at amplitude A x (2 / pi) K(sin^2(A / 2))" if rig.kind == "pivot" else "; at any amplitude"
    print(f"  mode 1 ({motion}): period {text}{exact}")
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


def _fmt(values) -> str:
    return "[" + ", ".join(f"{v:.9g}" for v in values) + "]"
