"""``python -m validate plan``: which hangings to make for an object's full tensor.

    python -m validate plan CANDIDATES.toml --count K [--criterion worst|det] [--json]

The candidates file (docs/identification.md, section 8):

* ``rig`` (path relative to the file): the rig, its ``[body]`` the object in its own axes (mass, com,
  and the expected ``inertia``: a finite tensor, the plan's linearisation point); a wire rig or a
  torsion rod (``[torsion]`` with its ``stiffness``: each candidate turns the part about the rod,
  :func:`bifilar.identification.hinge_tensor.hinge_candidates`);
* ``fixture`` (optional): a platform the object is mounted on, its COM on the fixture's COM;
* ``period_std`` (s; default the rig's ``[uncertainty].period``): every period's sigma;
* ``generate = N`` (optional, 1 .. 5000, seconds): N orientations with vertical object axes spread over a hemisphere;
* ``[[candidate]]`` tables (optional, with or instead of ``generate``): ``orientation`` (object axes ->
  rig body axes, a rotation vector in rad or a 3x3 matrix) and an optional ``name``.

Prints the chosen K (:mod:`bifilar.identification.plan`), their predicted component sigmas, and those
of the six textbook hangings (three axes, three diagonals between them) for comparison.
Exit status 2 with one line for bad input.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from bifilar.identification.tensor import COMPONENTS

from ..argtypes import whole_number
from ..statuses import epilog

# orientations; more adds nothing a few hundred do not. 5000 take ~3 s (~8 s with the object's COM off its
# origin): bifilar.identification.plan shares the rest poses and batches the designs
MAX_GENERATED = 5000


def add_parser(subparsers) -> None:
    """Register the ``plan`` subcommand on the CLI's subparsers."""
    from bifilar.identification.plan import CRITERIA

    p = subparsers.add_parser("plan", help="choose the hangings that determine an object's tensor best",
                              epilog=epilog("plan", ("python -m validate plan candidates.toml --count 7",)))
    p.add_argument("candidates", help=f"candidates file (TOML): rig, period_std, generate (at most {MAX_GENERATED}: "
                                      "seconds) and/or [[candidate]] tables (docs/identification.md section 8)")
    p.add_argument("--count", required=True, type=whole_number("--count", 6, 100), metavar="K",
                   help="hangings to choose, 6-100")
    p.add_argument("--criterion", choices=CRITERIA, default="worst",
                   help="worst: the largest component sigma over the largest moment (default); det: ln det of "
                        "the covariance")
    p.add_argument("--json", action="store_true", help="print one JSON object")


def run(args) -> int:
    from bifilar.identification import plan as planning
    from bifilar.identification.hinge_tensor import hinge_candidates
    from bifilar.rig import RigError
    from bifilar.rig.hinge import HingeRig

    rig, fixture, sigma, orientations = read_candidates(args.candidates)
    if isinstance(rig, HingeRig):  # a torsion rod or a knife edge: the period's moment is linear in the tensor
        pool, skipped = hinge_candidates(rig, rig.inertia, sigma, orientations)
        book, book_skipped = hinge_candidates(rig, rig.inertia, sigma, planning.TEXTBOOK)
    else:
        pool, skipped = planning.candidates(rig, rig.inertia, sigma, orientations, fixture)
        book, book_skipped = planning.candidates(rig, rig.inertia, sigma, planning.TEXTBOOK, fixture)
    scale = float(np.linalg.eigvalsh(rig.inertia).max())
    if len(pool) < args.count:
        raise RigError(args.candidates, "candidate", f"{len(pool)} usable candidates for --count {args.count}"
                       + (f" ({len(skipped)} skipped: {skipped[0][0]}: {skipped[0][1]})" if skipped else ""))
    textbook = planning.design(book, scale) if len(book) == 6 else None
    try:
        best = planning.plan(pool, args.count, args.criterion, scale, starts=(book,) if len(book) == args.count else ())
    except np.linalg.LinAlgError:
        raise RigError(args.candidates, "candidate", "the candidates cannot determine all six components "
                                                     "(give more distinct vertical axes)") from None
    report = {"criterion": args.criterion, "count": args.count, "candidates": len(pool),
              "skipped": [{"name": n, "why": w} for n, w in skipped], "chosen": _design(best),
              "textbook": None if textbook is None else _design(textbook),
              "textbook_skipped": [{"name": n, "why": w} for n, w in book_skipped]}
    if args.json:
        print(json.dumps(report, allow_nan=False))
    else:
        print(_text(report))
    return 0


def read_candidates(path: str):
    """(rig, fixture or None, period sigma (s), [(name, Q)]) of a candidates file."""
    from bifilar.identification.hangings import orientation, period_sigma
    from bifilar.identification.plan import hemisphere
    from bifilar.rig import RigError, load_rig
    from bifilar.rig.checks import no_unknown, read_toml, required
    from bifilar.rig.hinge import HingeRig

    data = read_toml(path)
    folder = Path(path).parent
    no_unknown(data, {"rig", "fixture", "period_std", "generate", "candidate"}, path, "")
    name = required(data, "rig", path, "")
    if not isinstance(name, str):
        raise RigError(path, "rig", "must be a file name (relative to the candidates file)")
    rig = load_rig(folder / name, hinge=True)
    if isinstance(rig, HingeRig):
        if rig.kind != "torsion":
            raise RigError(path, "rig", f"{rig.source} is a compound pendulum: the plan proposes orientations on a "
                           "torsion rod (or wires); a knife edge supplies one moment, chosen by hand")
        if "fixture" in data:
            raise RigError(path, "fixture", "a part on a torsion rod is clamped alone: no fixture")
        if not np.isfinite(rig.inertia).all():
            raise RigError(str(rig.source), "body.inertia", "the plan needs the expected tensor (finite): nan given")
    fixture = None
    if "fixture" in data:
        if not isinstance(data["fixture"], str):
            raise RigError(path, "fixture", "must be a file name (relative to the candidates file)")
        fixture = load_rig(folder / data["fixture"])
    sigma = period_sigma(data["period_std"], path, "period_std") if "period_std" in data else rig.uncertainty.period
    if sigma <= 0.0:
        raise RigError(path, "period_std", f"missing, and {rig.source} states no [uncertainty].period: give the "
                                           "periods' sigma (s)")
    orientations = []
    if "generate" in data:
        count = data["generate"]
        if isinstance(count, bool) or not isinstance(count, int) or not 1 <= count <= MAX_GENERATED:
            raise RigError(path, "generate", f"must be a whole number 1 .. {MAX_GENERATED}, got {count!r}")
        orientations += hemisphere(count)
    raw = data.get("candidate", [])
    if not isinstance(raw, list) or not all(isinstance(c, dict) for c in raw):
        raise RigError(path, "candidate", "must be [[candidate]] tables")
    for i, c in enumerate(raw, start=1):
        no_unknown(c, {"orientation", "name"}, path, f"candidate[{i}].")
        q = orientation(required(c, "orientation", path, f"candidate[{i}]."), path, f"candidate[{i}].orientation")
        orientations.append((str(c.get("name", f"candidate[{i}]")), q))
    if not orientations:
        raise RigError(path, "candidate", "no candidates: give [[candidate]] tables or generate = N")
    return rig, fixture, sigma, orientations


def _design(d) -> dict:
    return {"hangings": [{"name": c.name, "orientation": Rotation.from_matrix(c.orientation).as_rotvec().tolist(),
                          "vertical_axis": c.orientation[2].tolist(), "period": c.period} for c in d.chosen],
            "std": dict(zip(COMPONENTS, d.std.tolist())), "worst_relative_std": d.worst, "log_det": d.log_det}


def _text(report: dict) -> str:
    lines = [f"{report['count']} hangings chosen from {report['candidates']} candidates by the {report['criterion']} "
             "criterion:"]
    for h in report["chosen"]["hangings"]:
        lines.append(f"  {h['name']}: rotation vector ({', '.join(f'{v:+.4f}' for v in h['orientation'])}) rad, "
                     f"period {h['period']:.6g} s")
    for label, d in (("chosen", report["chosen"]), ("textbook (axes and diagonals)", report["textbook"])):
        if d is None:
            lines.append(f"{label}: not every textbook hanging is usable on this rig")
            continue
        stds = ", ".join(f"{k} {v:.3g}" for k, v in d["std"].items())
        lines.append(f"{label}: sigma {stds} kg m^2; worst {d['worst_relative_std']:.3g} of the largest moment, "
                     f"ln det {d['log_det']:.4g}")
    if report["skipped"]:
        lines.append(f"skipped {len(report['skipped'])} candidates whose yaw cannot be told from another mode")
    return "\n".join(lines)
