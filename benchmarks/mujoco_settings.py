"""Measure MuJoCo's agreement with the Kane model for several numerics on the thesis plate (torsion).

For each setting: relative period error against Kane (rtol 1e-12), largest wire stretch (m), largest
tension error relative to the static tension (t >= dt_out; the first sample is reported apart because
a soft constraint at zero stretch carries only about d times the load), energy excursion (J) and
speed (simulated seconds per CPU second of this process: wall time on a shared machine is noisier). The table in models/README.md is this script's output:

    python benchmarks/mujoco_settings.py [--duration 10]
"""

from __future__ import annotations

import argparse
import time

import mujoco
import numpy as np

from bifilar.rig import load_rig
from bifilar.rig.statics import rest_pose
from validate.engines import kane, mujoco_rig
from validate.engines.mjcf import CHOSEN, Numerics
from validate.metrics import energy_drift, period

PLATE = "models/rigs/plate.toml"
ASYMMETRIC = "models/rigs/asymmetric.toml"
MUJOCO_DEFAULT = Numerics(timestep=2e-3, integrator="Euler", timeconst=0.02, dampratio=1.0,
                          solimp=(0.9, 0.95, 0.001, 0.5, 2.0), tolerance=1e-8)
STIFF = (0.9999, 0.9999, 0.0001, 0.5, 2.0)  # impedance at MuJoCo's ceiling
ISSUE = CHOSEN.with_(timestep=1e-4, dampratio=1.0, solimp=STIFF)  # timeconst 2h, implicitfast

SETTINGS: list[tuple[str, str, Numerics]] = [
    ("MuJoCo defaults: h 2e-3 Euler, solref 0.02 1, solimp 0.9 0.95", "tendon", MUJOCO_DEFAULT),
    ("default solref/solimp, h 1e-4 implicitfast", "tendon", MUJOCO_DEFAULT.with_(timestep=1e-4, integrator="implicitfast")),
    ("timeconst 2h, dampratio 1, d 0.9999: h 1e-3", "tendon", ISSUE.with_(timestep=1e-3)),
    ("same, h 1e-4", "tendon", ISSUE),
    ("same, h 1e-4, qvel read as v(t)", "tendon", ISSUE.with_(staggered=False)),
    ("same, h 1e-4, Euler", "tendon", ISSUE.with_(integrator="Euler")),
    ("same, h 1e-4, discrete", "tendon", ISSUE.with_(integrator="discrete")),
    ("same, h 1e-4, discrete, refsafe off, timeconst h/10", "tendon",
     ISSUE.with_(integrator="discrete", refsafe=False, timeconst=1e-5)),
    ("same, h 1e-3, RK4", "tendon", ISSUE.with_(timestep=1e-3, integrator="RK4")),
    ("same, h 1e-4, RK4", "tendon", ISSUE.with_(integrator="RK4")),
    ("same, h 1e-4, RK4, solver tolerance 1e-8 (MuJoCo's default)", "tendon",
     ISSUE.with_(integrator="RK4", tolerance=1e-8)),
    ("same, h 2.5e-5", "tendon", ISSUE.with_(timestep=2.5e-5)),
    ("dampratio 0.5, d 0.9999: h 1e-4", "tendon", CHOSEN.with_(timestep=1e-4, solimp=STIFF)),
    ("dampratio 0.5, d 0.9999: h 5e-5", "tendon", CHOSEN.with_(timestep=5e-5, solimp=STIFF)),
    ("dampratio 0.5, d 0.9999: h 4e-5", "tendon", CHOSEN.with_(solimp=STIFF)),
    ("dampratio 0.5, d 0.999: h 4e-5", "tendon", CHOSEN.with_(solimp=(0.999, 0.999, 0.001, 0.5, 2.0))),
    ("dampratio 0.5, d 0.99: h 4e-5 (chosen)", "tendon", CHOSEN),
    ("dampratio 0.5, d 0.98: h 4e-5", "tendon", CHOSEN.with_(solimp=(0.98, 0.98, 0.001, 0.5, 2.0))),
    ("dampratio 0.5, d 0.99: h 1e-4", "tendon", CHOSEN.with_(timestep=1e-4)),
    ("dampratio 0.5, refsafe off, timeconst 1.5h: h 1e-4", "tendon",
     CHOSEN.with_(timestep=1e-4, refsafe=False, timeconst=1.5e-4)),
    ("chosen", "equality", CHOSEN),
    ("dampratio 0.5, d 0.9999: h 4e-5", "equality", CHOSEN.with_(solimp=STIFF)),
    ("timeconst 2h, dampratio 1, d 0.9999: h 1e-4", "equality", ISSUE),
]
# False slack: tendon cables on the asymmetric rig, whose wires Kane finds taut throughout (tension
# >= 33 N), from its [initial] disturbance scaled by these factors.
CHATTER_SCALES = (1.0, 3.0)
CHATTER_IMPEDANCES = (0.9999, 0.999, 0.99, 0.98)


def measure(rig, reference, cables: str, numerics: Numerics, duration: float, static: float) -> dict:
    start = time.process_time()
    traj = mujoco_rig.run(rig, duration, cables=cables, numerics=numerics)
    cpu = time.process_time() - start
    p_mj = period(traj.t, traj["quat"][:, 3]).value
    p_ref = period(reference.t, reference["quat"][:, 3]).value
    dT = np.abs(traj["tension"] - reference["tension"]) / static
    return {
        "period": p_mj / p_ref - 1.0,
        "stretch": float(np.abs(traj["length_error"]).max()),
        "tension0": float(dT[0].max()),
        "tension": float(dT[1:].max()),
        "energy": energy_drift(traj),
        "speed": duration / cpu,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--duration", type=float, default=10.0, help="simulated seconds per run")
    args = parser.parse_args()
    # An unstable setting is reported from mjData.warning; keep MuJoCo from also printing it and
    # writing MUJOCO_LOG.TXT into the working directory.
    mujoco.set_mju_user_warning(lambda message: None)
    rig = load_rig(PLATE)
    static = float(rest_pose(rig).tensions.mean())
    reference = kane.run(rig, args.duration, rtol=1e-12)
    print(f"plate torsion, {args.duration:g} s; Kane rtol 1e-12 reference; static tension {static:.5f} N")
    print("| cables | setting | period rel. err | max stretch (m) | tension rel. err t=0 | tension rel. err t>0 "
          "| energy excursion (J) | sim s / CPU s |")
    print("|---|---|---|---|---|---|---|---|")
    for label, cables, numerics in SETTINGS:
        try:
            r = measure(rig, reference, cables, numerics, args.duration, static)
        except RuntimeError as exc:
            print(f"| {cables} | {label} | failed: {exc} |||||")
            continue
        print(f"| {cables} | {label} | {r['period']:+.1e} | {r['stretch']:.1e} | {r['tension0']:.1e} "
              f"| {r['tension']:.1e} | {r['energy']:.1e} | {r['speed']:.1f} |")
    false_slack(args.duration)


def false_slack(duration: float) -> None:
    """Samples at which a tendon cable reads slack while the Kane model keeps it taut."""
    base = load_rig(ASYMMETRIC)
    print(f"\nasymmetric rig, {duration:g} s, tendon cables, h 4e-5 dampratio 0.5: samples with a wire falsely slack")
    print("| disturbance | " + " | ".join(f"d {d:g}" for d in CHATTER_IMPEDANCES) + " |")
    print("|---|" + "---|" * len(CHATTER_IMPEDANCES))
    for scale in CHATTER_SCALES:
        rig = base.with_initial(base.initial_rotation * scale, base.initial_omega * scale)
        reference = kane.run(rig, duration, rtol=1e-10)
        taut = len(reference.t) if reference.meta["taut_failure"] is None else 0
        counts = []
        for d in CHATTER_IMPEDANCES:
            traj = mujoco_rig.run(rig, duration, numerics=CHOSEN.with_(solimp=(d, d, 0.001, 0.5, 2.0)))
            counts.append(int((traj["tension"][1:taut] == 0.0).any(axis=1).sum()))
        print(f"| {scale:g} x [initial] | " + " | ".join(str(c) for c in counts) + " |")


if __name__ == "__main__":
    main()
