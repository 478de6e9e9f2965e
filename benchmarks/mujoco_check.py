"""Wall seconds of the sweep's MuJoCo check (validate/studies/sweep_check.py), side by side in one
process: the runs one by one (``mujoco_rig.run``) and batched through ``mujoco.rollout`` on every core
(``mujoco_rig.run_batch``), for the K best configurations of a sweep (default: the 4 best of the bench
plate, models/sweeps/bench_plate.toml: 12 runs, every measured mode of each). Also prints the largest
differences between the two checks' numbers (the batched check must be the sequential one): the
MuJoCo periods (relative) and the mean-tension errors (themselves relative, so their difference).

    python benchmarks/mujoco_check.py [K] [SWEEP.toml]
"""

from __future__ import annotations

import os
import sys
import tempfile
import time
from pathlib import Path

from bifilar.sweep.choose import Choice
from bifilar.sweep.run import run as run_sweep
from bifilar.sweep.space import load_space
from validate.assets import MODELS
from validate.studies.sweep_check import check


def main(k: int, path: str) -> None:
    space = load_space(path)
    choice = Choice(space.measure, space.objective, keep=k)
    with tempfile.TemporaryDirectory() as out:
        for row in run_sweep(path, space, Path(out), jobs=os.cpu_count() or 1).rows():
            choice.add(row)
    configurations = [r["values"] for _, r in choice.ranking.ranked()[:k]]
    start = time.perf_counter()
    sequential = check(space, configurations, batched=False)
    t_seq = time.perf_counter() - start
    start = time.perf_counter()
    batched = check(space, configurations)
    t_bat = time.perf_counter() - start
    pairs = [(mb, ms) for b, s in zip(batched, sequential) for mb, ms in zip(b.entry["modes"], s.entry["modes"])]
    periods = max(abs(mb["mujoco"] / ms["mujoco"] - 1.0) for mb, ms in pairs)
    tensions = max(abs(mb["tension_rel_error"] - ms["tension_rel_error"]) for mb, ms in pairs)
    runs = sum(len(c.runs) for c in batched)
    simulated = sum(t.t[-1] for c in batched for t in c.runs.values())
    print(f"MuJoCo check of the {len(configurations)} best of {os.path.basename(path)} ({runs} runs, {simulated:.1f} s "
          f"simulated): sequential {t_seq:.2f} s, batched (mujoco.rollout, {os.cpu_count()} threads) {t_bat:.2f} s, "
          f"ratio {t_seq / t_bat:.2f}; batched - sequential: periods {periods:.1e} (relative), mean tension errors "
          f"{tensions:.1e}")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 4,
         sys.argv[2] if len(sys.argv) > 2 else str(MODELS / "sweeps" / "bench_plate.toml"))
