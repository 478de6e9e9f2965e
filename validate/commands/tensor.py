"""``python -m validate tensor``: an object's full inertia tensor from its yaw periods in several hangings.

    python -m validate tensor HANGINGS.toml [--json] [--html FILE.html]

The hangings file (docs/identification.md, section 8) lists ``[[hanging]]`` tables: the rig as hung,
the object's orientation in it, and a period (s) or records; optionally a tare (the fixture alone).
A file whose rigs are hinge rigs (a torsion rod, a compound pendulum; section 9) is read and fitted by
:mod:`bifilar.identification.hinge_tensor` (linear in the six components, the rod's stiffness one
error shared by every torsion hanging) and reported the same way, with ``rod`` and ``known`` added.
:mod:`bifilar.identification.hangings` reads and measures them, :mod:`bifilar.identification.tensor`
fits the six components on the exact linearisation. The tensor is about the object's COM in the
object's axes (kg m^2); its covariance is over I_xx, I_yy, I_zz, I_xy, I_yz, I_xz.

Exit status 2 with one line for bad input (a missing field, too few hangings, orientations that leave
a component undetermined, a yaw that cannot be told from another mode, bodies that differ).
"""

from __future__ import annotations

import json

import numpy as np
from scipy.stats import chi2 as chi2_dist

from bifilar.identification.tensor import COMPONENTS

from ..statuses import epilog

_CHI2_LEVEL = 0.99  # hangings scattering beyond this quantile of chi^2 are flagged


def add_parser(subparsers) -> None:
    """Register the ``tensor`` subcommand on the CLI's subparsers."""
    p = subparsers.add_parser("tensor", help="an object's full inertia tensor from several hangings",
                              epilog=epilog("tensor", ("python -m validate tensor hangings.toml --json",)))
    p.add_argument("hangings", help="hangings file (TOML): [[hanging]] tables with rig, orientation, period or "
                                    "signal, tare (docs/identification.md section 8)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument("--html", metavar="FILE.html", help="write one self-contained page of the result")


def run(args) -> int:
    """Read, fit, report; returns the exit status (errors raised for cli.main)."""
    from bifilar.identification.hangings import fit_hangings, read_hangings
    from bifilar.identification.hinge_tensor import fit_hinge_hangings, hinge_file, read_hinge_hangings

    if hinge_file(args.hangings):  # torsion and compound pendulums (section 9)
        setup = read_hinge_hangings(args.hangings)
        result = fit_hinge_hangings(setup, args.hangings)
    else:
        setup = read_hangings(args.hangings)
        result = fit_hangings(setup, args.hangings)
    report = build_report(setup, result)
    if args.html:
        from ..report.tensor_page import write_tensor_html

        write_tensor_html(args.html, report, args.hangings)
    if args.json:
        print(json.dumps(report, allow_nan=False))
    else:
        print(text(report))
    return 0


def _matrix(a) -> list | None:
    return None if a is None else np.asarray(a, float).tolist()


def build_report(setup, result) -> dict:
    """The JSON report (docs/identification.md section 8)."""
    moments, axes, moments_std = result.principal()
    flags = list(setup.flags)
    if result.covariance is None:
        flags.append("not every hanging states a period sigma (period_std, [uncertainty].period or records): "
                     "no covariance")
    dof = len(setup.hangings) - setup.unknowns  # a hinge file may hold entries known
    if result.chi2_per_dof is not None and result.chi2_per_dof > chi2_dist.ppf(_CHI2_LEVEL, dof) / dof:
        flags.append(f"the hangings scatter more than their sigmas (chi^2 per degree of freedom "
                     f"{result.chi2_per_dof:.3g}, above the {_CHI2_LEVEL:.0%} bound {chi2_dist.ppf(_CHI2_LEVEL, dof) / dof:.3g})")
    hangings = []
    for k, (h, m) in enumerate(zip(setup.hangings, setup.measured)):
        hangings.append({
            "name": h.label, "rig": h.rig.source, "period": m.period, "period_std": m.std, "period_source": m.source,
            "model_period": float(result.model[k]),
            "residual_sigmas": None if result.residual_sigmas is None else float(result.residual_sigmas[k]),
            "tare": h.tare})
    tares = [{"rig": f.rig.source, "axis": f.axis.tolist(), "moment": f.moment, "moment_std": f.std,
              "period": f.measured.period, "period_std": f.measured.std, "period_source": f.measured.source,
              "hangings": [h.label for h in setup.hangings if h.tare == k]} for k, f in enumerate(setup.fixtures)]
    return {
        "tensor": _matrix(result.inertia), "tensor_std": _matrix(result.std), "components": list(COMPONENTS),
        "covariance": _matrix(result.covariance),
        "principal": {"moments": moments.tolist(), "moments_std": _matrix(moments_std), "axes": axes.tolist()},
        "object": {"mass": setup.mass, "com": _matrix(setup.com)},
        "hangings": hangings, "tares": tares, "chi2_per_dof": result.chi2_per_dof, "flags": flags,
        **_hinge_part(setup),
    }


def _hinge_part(setup) -> dict:
    """A hinge hangings file's extra keys: ``rod`` (``stiffness``, ``stiffness_std``, ``source``: the one
    stiffness every torsion hanging shares) and ``known`` (component -> value held); none for wires."""
    from bifilar.identification.hinge_tensor import HingeSetup

    if not isinstance(setup, HingeSetup):
        return {}
    rod = None if setup.rod is None else {"stiffness": setup.rod.stiffness, "stiffness_std": setup.rod.std,
                                          "source": setup.rod.source}
    return {"rod": rod, "known": {COMPONENTS[i]: v for i, v in sorted(setup.known.items())}}


def _pm(value: float, std) -> str:
    return f"{value:.7g}" if std is None else f"{value:.7g} +- {std:.2g}"


def text(report: dict) -> str:
    """The readable report: tensor, principal moments and axes, each hanging, the tares, flags."""
    t, s = np.array(report["tensor"]), report["tensor_std"]
    lines = [f"object: {report['object']['mass']:.6g} kg; tensor about its COM, object axes (kg m^2):"]
    for i in range(3):
        lines.append("  " + "  ".join(f"{_pm(t[i, k], None if s is None else s[i][k]):>24}" for k in range(3)))
    p = report["principal"]
    for k in range(3):
        axis = ", ".join(f"{a:+.4f}" for a in np.array(p["axes"])[:, k])
        std = None if p["moments_std"] is None else p["moments_std"][k]
        lines.append(f"principal {k + 1}: {_pm(p['moments'][k], std)} kg m^2 about ({axis})")
    lines.append("hangings: period used (s), model (s), residual in sigmas:")
    for h in report["hangings"]:
        z = "" if h["residual_sigmas"] is None else f", {h['residual_sigmas']:+.2f} sigma"
        std = "" if not h["period_std"] else f" +- {h['period_std']:.2g}"
        lines.append(f"  {h['name']}: {h['period']:.9g}{std} ({h['period_source']}), model {h['model_period']:.9g}{z}")
    for k, f in enumerate(report["tares"]):
        lines.append(f"tare {k}: {f['rig']}: {_pm(f['moment'], f['moment_std'])} kg m^2 about its vertical, "
                     f"from {f['period']:.9g} s, held in {len(f['hangings'])} hanging(s)")
    if report.get("rod"):
        r = report["rod"]
        lines.append(f"rod: {_pm(r['stiffness'], r['stiffness_std'])} N m/rad ({r['source']}), one error shared by "
                     "every torsion hanging")
    if report.get("known"):
        lines.append("held known: " + ", ".join(f"{c} = {v:.7g}" for c, v in report["known"].items()))
    if report["chi2_per_dof"] is not None:
        lines.append(f"chi^2 per degree of freedom: {report['chi2_per_dof']:.3g}")
    lines += [f"flag: {f}" for f in report["flags"]]
    return "\n".join(lines)
