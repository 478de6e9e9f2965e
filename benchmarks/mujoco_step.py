"""Cost of one MuJoCo step of a rig model (us), as compiled by validate.engines.mjcf, and what each of
MuJoCo's per-step features that a one-body rig does not need would cost turned back on; the
trajectory after 1e5 steps is compared bitwise with the chosen model's.

    python benchmarks/mujoco_step.py [--steps 100000]

Rounds alternate the variants, and each figure is the best of its rounds (the least disturbed by other
load); compare the ratios within one run.
"""

from __future__ import annotations

import argparse
import time

import mujoco
import numpy as np

from bifilar.rig.statics import initial_state
from validate.assets import rig
from validate.engines.mjcf import compile_model, state_qpos_qvel

# What the chosen options disable, and what turning each back on would cost.
VARIANTS = {"chosen": 0, "island discovery on": int(mujoco.mjtDisableBit.mjDSBL_ISLAND)}


def step_cost(name: str, cables: str, enabled: int, steps: int) -> tuple[float, np.ndarray]:
    """us per step of rig ``name`` with ``enabled`` disable bits cleared, and the final qpos."""
    r = rig(name)
    model = compile_model(r, cables)
    model.opt.disableflags &= ~int(enabled)
    data = mujoco.MjData(model)
    data.qpos[:], data.qvel[:] = state_qpos_qvel(r, initial_state(r))
    mujoco.mj_forward(model, data)
    start = time.perf_counter()
    mujoco.mj_step(model, data, steps)
    return (time.perf_counter() - start) / steps * 1e6, data.qpos.copy()


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=100_000)
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args(argv)
    print(f"{'rig':10s} {'cables':9s} {'variant':22s} {'us/step':>8s} {'vs chosen':>9s}  trajectory")
    for name in ("plate", "asymmetric"):
        for cables in ("tendon", "equality"):
            best, final = {}, {}
            for _ in range(args.rounds):
                for variant, bits in VARIANTS.items():
                    us, final[variant] = step_cost(name, cables, bits, args.steps)
                    best[variant] = min(best.get(variant, np.inf), us)
            for variant in VARIANTS:
                same = "bitwise same" if np.array_equal(final[variant], final["chosen"]) else "DIFFERS"
                print(f"{name:10s} {cables:9s} {variant:22s} {best[variant]:8.2f} {best[variant] / best['chosen']:9.3f}  {same}")


if __name__ == "__main__":
    main()
