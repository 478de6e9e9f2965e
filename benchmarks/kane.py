"""Speed of the Kane-Tseng model: right-hand-side evaluations per second, and simulated seconds per
wall-clock second at rtol 1e-10, for a splayed rig (plate) and a parallel-wire rig.

Run: python benchmarks/kane.py   (numbers vary with machine load: compare ratios within one run)
"""

from __future__ import annotations

import numpy as np
from timing import best_of

from bifilar.motion import kane_kernel as K
from bifilar.motion.kane import KaneModel
from bifilar.motion.simulate import preferred_chart, simulate, state_to_chart
from bifilar.rig.statics import initial_state
from validate.assets import rig


def main() -> None:
    print(f"{'rig':10s} {'rhs evals/s':>12s} {'sim s / wall s':>15s} {'rhs evals':>10s}")
    for name in ("plate", "parallel"):
        r = rig(name)
        model = KaneModel.from_rig(r)
        state = initial_state(r)
        chart = preferred_chart(model, state)
        y = state_to_chart(model, state, chart)
        K.rhs(y, model.p, chart)  # compile or load from cache outside the timing
        n = 20000

        def loop():
            for _ in range(n):
                K.rhs(y, model.p, chart)

        rhs_rate = n / best_of(loop)
        duration = 60.0
        run = simulate(model, state, duration)
        wall = best_of(lambda: simulate(model, state, duration), repeat=3)
        print(f"{name:10s} {rhs_rate:12.3g} {duration / wall:15.3g} {run.nfev:10d}")


if __name__ == "__main__":
    np.set_printoptions(precision=4)
    main()
