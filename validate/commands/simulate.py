"""``python -m validate simulate RIG --duration S --out FILE.csv``: simulate a rig from its ``[initial]``
disturbance on one engine (:mod:`validate.engines`) and write the trajectory CSV, whole or not at all.

A taut-wire model stops where a wire goes slack: the CSV ends there and the exit status is 3.

A hinge rig (``[pivot]`` or ``[torsion]``) runs on ``kane`` (the exact 1-DOF equation,
:func:`validate.engines.hinge.run`) or ``mujoco`` (:mod:`validate.engines.mujoco_hinge`) from rest at
``--amplitude``; its CSV has the COM and quaternion columns of a wire rig's, then ``angle`` and ``rate``
(:func:`validate.trajectory.write_hinge_csv`); ``--rerun`` draws its axis, body and trail. The wire engines are
refused for it.
"""

from __future__ import annotations

import sys

from bifilar.rig import RigError

from ..argtypes import UsageError, bounded_float, positive_float
from ..engines import NAMES as ENGINE_NAMES
from ..statuses import OK, WENT_SLACK, RunFailed, epilog
from .shared import RIG_HELP, load

MAX_DURATION = 1e5  # s: the longest simulation one command runs (27 hours of swinging)
MAX_TWIST = 100.0  # rad: the largest --amplitude (16 turns of a torsion rod; a compound pendulum stays below pi)
HINGE_ENGINES = ("kane", "mujoco")  # the engines with a model of a hinge rig
RTOL_RANGE = (1e-13, 1e-4)  # below: DOP853 is at rounding; above: the energy drifts by percent per period


def add_parser(subparsers) -> None:
    """Register the ``simulate`` subcommand on the CLI's subparsers."""
    p = subparsers.add_parser("simulate", help="simulate a rig and write the trajectory CSV", epilog=epilog(
        "simulate", ("python -m validate simulate plate --engine kane --duration 60 --out plate.csv",)))
    p.add_argument("rig", help=RIG_HELP + "; the run starts from its [initial] disturbance")
    p.add_argument("--engine", default="kane", choices=ENGINE_NAMES,
                   help="kane: the hand-derived model (Kane-Tseng for two wires, the N-wire model otherwise; "
                        "stops where a wire goes slack); nwire: the N-wire model on any rig; mujoco: tendon "
                        "cables that may go slack; mujoco-eq: equality cables; mujoco-cable: heavy wires "
                        "(linear_density) as chains of rigid segments with their mass; a hinge rig runs on kane "
                        "(its exact 1-DOF equation) or mujoco (a hinge joint) (default: kane)")
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
    p.add_argument("--amplitude", type=bounded_float("--amplitude", -MAX_TWIST, MAX_TWIST, "rad"),
                   help="hinge rigs only (which have no [initial]): the angle about the hinge axis the body is "
                        "released from, at rest, rad; below pi for a compound pendulum (required for them)")
    p.add_argument("--out", required=True, metavar="FILE.csv", help="trajectory CSV to write (whole or not at all)")
    p.add_argument("--rerun", metavar="FILE.rrd", help="also write a rerun recording of the run (default: none)")


def run(args) -> int:
    """Check the sampling, run the engine, write the CSV (and recording) and print one summary line."""
    from bifilar.motion.simulate import MAX_SAMPLES, BudgetSpent, IntegrationError

    from ..engines import EngineInputError, engines
    from ..trajectory import NonFiniteTrajectory, write_rig_csv

    if args.dt_out > args.duration:
        raise UsageError(f"--duration: {args.duration:g} s is shorter than --dt-out {args.dt_out:g} s: "
                         "the CSV would hold t = 0 only")
    n_samples = int(args.duration / args.dt_out + 1e-9) + 1
    if n_samples > MAX_SAMPLES:
        raise UsageError(f"--duration: {args.duration:g} s every --dt-out {args.dt_out:g} s is {n_samples} samples, "
                         f"more than {MAX_SAMPLES}: shorten --duration or lengthen --dt-out")
    rig, rest = load(args.rig, hinge=True)
    if rest is None:
        return _run_hinge(args, rig)
    if args.amplitude is not None:
        raise UsageError(f"--amplitude: {args.rig} is a wire rig, which starts from its [initial] table; "
                         "--amplitude is for hinge rigs")
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
        raise RigError(args.rig, "initial",
                       f"the {args.engine} run failed ({exc}): the motion is too violent") from None
    if args.rerun:
        from ..recording import record_trajectory

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


def _run_hinge(args, rig) -> int:
    """Simulate a hinge rig from rest at ``--amplitude`` on ``kane`` or ``mujoco`` and write its CSV."""
    import numpy as np

    from bifilar.motion.hinge import period_at
    from bifilar.motion.simulate import BudgetSpent

    from ..engines import EngineInputError
    from ..engines import hinge, mujoco_hinge
    from ..trajectory import NonFiniteTrajectory, write_hinge_csv

    if args.engine not in HINGE_ENGINES:
        raise UsageError(f"--engine: {args.engine} models wires; a hinge rig runs on {' or '.join(HINGE_ENGINES)}")
    if args.amplitude is None:
        raise UsageError(f"--amplitude: {args.rig} is a hinge rig, which has no [initial]: give the release angle, rad")
    exact = period_at(rig, args.amplitude)  # refuses a compound pendulum over the top, and nothing is known
    hinge.check_known(rig)
    try:
        if args.engine == "kane":
            traj = hinge.run(rig, args.amplitude, args.duration, args.dt_out, args.rtol)
        else:
            traj = mujoco_hinge.run(rig, args.amplitude, args.duration, args.dt_out, max_seconds=args.max_seconds)
        write_hinge_csv(traj, args.out)
    except EngineInputError as exc:
        raise UsageError(f"{exc.option}: {exc}") from None
    except BudgetSpent as exc:
        raise RunFailed(f"{args.rig}: amplitude: {exc} (--max-seconds {args.max_seconds:g}); nothing written") from None
    except NonFiniteTrajectory as exc:
        raise RigError(args.rig, "amplitude", f"the {args.engine} run failed ({exc})") from None
    if args.rerun:
        from ..recording import record_trajectory

        record_trajectory(traj, args.rerun)
    angle = np.asarray(traj["angle"])
    print(f"{traj.engine} on {rig.name}: t = 0 .. {traj.t[-1]:.6g} s, {len(traj.t)} samples every {args.dt_out:g} s; "
          f"angle {angle.min():.6g} .. {angle.max():.6g} rad; exact period {exact:.9g} s; wrote {args.out}")
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
