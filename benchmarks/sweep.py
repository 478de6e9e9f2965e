"""Configurations per second per core of a sweep (rest pose + modes + sigma of x, y, z + peak tension),
side by side in one process: the sweep's path (rest pose continued from the neighbour, perturbed rest
poses shared by the three axes) and the per-configuration path (a rest-pose search from scratch and one
propagation per axis, as `identify` does for a single rig). CPU time of this process, on the bench-plate
sweep (models/sweeps/bench_plate.toml), BLAS on one thread as in a sweep's workers.

    python benchmarks/sweep.py [N]     # N configurations of the sweep path, N / 5 of the other (default 300)

Each path runs in ROUNDS interleaved rounds and the fastest round of each is reported (on a shared
machine the slower rounds measure the other jobs).
"""

from __future__ import annotations

import sys
import time

from threadpoolctl import threadpool_limits

from bifilar.identification import identify as ident
from bifilar.identification.propagation import linear
from bifilar.motion.modes import linearize
from bifilar.sweep.axes import configure
from bifilar.sweep.evaluate import evaluate
from bifilar.sweep.space import load_space
from validate.assets import MODELS

ROUNDS = 3


def _sweep_path(space, points) -> float:
    start = time.process_time()
    guess = None
    for p in points:
        row = evaluate(space, p, guess)
        guess = row.rest or guess
    return len(points) / (time.process_time() - start)


def _single_path(space, points) -> float:
    start = time.process_time()
    for p in points:
        rig = configure(space.rig, p)
        lin = linearize(rig)
        for axis in space.measure:
            pencil = ident.pencil(rig, axis, lin=lin)
            if pencil.shares(pencil.moment0, pencil.modes(pencil.moment0)[1]).max() > 1e-12:
                linear(rig, axis, ident.linear_period(rig, axis, lin.rest), rig.uncertainty.period)
    return len(points) / (time.process_time() - start)


def main(n: int, rounds: int = ROUNDS) -> None:
    space = load_space(MODELS / "sweeps" / "bench_plate.toml")
    points = list(space.points())[:n]
    evaluate(space, points[1], evaluate(space, points[0]).rest)  # compile and warm up both paths
    sweep = single = 0.0
    for _ in range(rounds):  # interleaved, the best round of each: the machine is shared
        sweep = max(sweep, _sweep_path(space, points))
        single = max(single, _single_path(space, points[: max(2, n // 5)]))
    print(f"sweep path: {sweep:.3g} configurations/s/core; per-configuration path: {single:.3g} "
          f"configurations/s/core; ratio {sweep / single:.3g} (best of {rounds} interleaved rounds; "
          f"issue 10's target: 1000 configurations/s/core)")


if __name__ == "__main__":
    with threadpool_limits(1):
        main(int(sys.argv[1]) if len(sys.argv) > 1 else 300)
