"""What the stiff bounce mode of elastic wires costs each engine: steps per simulated second against
the COM error, on the symmetric quadrifilar (models/rigs/quadrifilar.toml, bounce 58 Hz) released
from its rest pose 1e-5 m low.

With four equal vertical wires that stay taut (the stretch at rest is 7.4e-5 m) the bounce is exactly a
harmonic oscillator, z(t) = z_rest - A cos(omega t), omega^2 = 4 EA / (m L) (docs/elastic-wires.md): the
reference is exact. ``kane`` (the elastic N-wire model, DOP853) over rtol; ``mujoco`` (tendon springs,
semi-implicit Euler with staggered velocities) over its time step. A DOP853 step costs 12 right-hand
sides; steps per simulated second are nfev / 12 / duration for kane, 1 / h for MuJoCo.

Run: python benchmarks/elastic.py   (wall times vary with machine load)
"""

from __future__ import annotations

import time

import numpy as np

from bifilar.rig.statics import State, rest_pose
from validate.assets import rig
from validate.engines import engines, mujoco_rig
from validate.engines.mjcf import CHOSEN

AMPLITUDE = 1e-5  # m
DURATION = 1.0  # s, 58 bounce periods
DT_OUT = 1e-3  # s, a whole number of every MuJoCo step below


def main() -> None:
    r = rig("quadrifilar")
    rest = rest_pose(r)
    omega = np.sqrt(sum(w.axial_stiffness / w.length for w in r.wires) / r.mass)
    start = State(rest.com - [0.0, 0.0, AMPLITUDE], rest.rotation, np.zeros(3), np.zeros(3))

    def error(traj) -> float:
        exact = rest.com[2] - AMPLITUDE * np.cos(omega * traj.t)
        return float(max(np.abs(traj["com"][:, 2] - exact).max(), np.abs(traj["com"][:, :2]).max()))

    engines()["kane"](r, 0.01, 0.01, 1e-8, start)  # compile the kernels outside the timing
    print(f"bounce {2 * np.pi / omega * 1e3:.4f} ms, amplitude {AMPLITUDE:g} m, {DURATION:g} s simulated")
    print(f"{'engine':8s} {'setting':>14s} {'steps/sim s':>12s} {'COM error (m)':>14s} {'rel. to A':>10s} {'wall s':>8s}")
    for rtol in (1e-6, 1e-8, 1e-10, 1e-12):
        t0 = time.perf_counter()
        traj = engines()["kane"](r, DURATION, DT_OUT, rtol, start)
        wall = time.perf_counter() - t0
        err = error(traj)
        print(f"{'kane':8s} {f'rtol {rtol:g}':>14s} {traj.meta['nfev'] / 12 / DURATION:12.4g} {err:14.3g} "
              f"{err / AMPLITUDE:10.3g} {wall:8.3f}")
    for h in (1e-4, 5e-5, 2.5e-5, 1e-5):
        t0 = time.perf_counter()
        traj = mujoco_rig.run(r, DURATION, DT_OUT, state=start, numerics=CHOSEN.with_(timestep=h))
        wall = time.perf_counter() - t0
        err = error(traj)
        print(f"{'mujoco':8s} {f'h {h:g} s':>14s} {1.0 / h:12.4g} {err:14.3g} {err / AMPLITUDE:10.3g} {wall:8.3f}")


if __name__ == "__main__":
    main()
