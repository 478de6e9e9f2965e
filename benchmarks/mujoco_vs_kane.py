"""Speed and accuracy, side by side: the Kane engine (rtol 1e-10) and MuJoCo (chosen numerics).

For the thesis plate (models/rigs/plate.toml, 10 deg torsion) and the parallel-wire rig
(models/rigs/parallel.toml, 0.1 rad torsion), each engine simulates the same seconds from the same
initial state; the table gives simulated seconds per wall-clock second (and per CPU second of this
process, steadier on a shared machine) and the relative error of the torsion period against the
exact period of the 1-DOF torsion model (bifilar.motion.lagrange, by quadrature; exact for these symmetric
rigs, and independent of both engines). Both engines are run once on a short span first, so that compilation is not timed.

    python benchmarks/mujoco_vs_kane.py [--duration 10]
"""

from __future__ import annotations

import argparse
import time
from functools import partial

from bifilar.motion import lagrange
from bifilar.rig import load_rig
from validate.engines import kane, mujoco_rig
from validate.metrics import period

RIGS = ("models/rigs/plate.toml", "models/rigs/parallel.toml")
ENGINES = {
    "kane rtol 1e-10": partial(kane.run, rtol=1e-10),
    "mujoco (tendon)": partial(mujoco_rig.run, cables="tendon"),
    "mujoco-eq (equality)": partial(mujoco_rig.run, cables="equality"),
}


def timed(fn, *args):
    wall, cpu = time.perf_counter(), time.process_time()
    out = fn(*args)
    return out, time.perf_counter() - wall, time.process_time() - cpu


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--duration", type=float, default=10.0, help="simulated seconds per run")
    args = parser.parse_args()
    print(f"{args.duration:g} s of torsion per run; period error against the exact 1-DOF torsion period "
          "(energy quadrature, bifilar.motion.lagrange), a formulation independent of both engines")
    print("| rig | engine | sim s / wall s | sim s / CPU s | period rel. err |")
    print("|---|---|---|---|---|")
    for path in RIGS:
        rig = load_rig(path)
        for run in ENGINES.values():
            run(rig, 0.05)  # compile / warm up
        p_ref = lagrange.period(lagrange.from_rig(rig), float(rig.initial_rotation[2]))
        for label, run in ENGINES.items():
            traj, wall, cpu = timed(run, rig, args.duration)
            err = period(traj.t, traj["quat"][:, 3]).value / p_ref - 1.0
            print(f"| {rig.name} | {label} | {args.duration / wall:.1f} | {args.duration / cpu:.1f} | {err:+.1e} |")


if __name__ == "__main__":
    main()
