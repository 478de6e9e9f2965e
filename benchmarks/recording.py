"""Cost of a rerun recording next to the simulation it records: a 60 s Kane run at 100 Hz on the
plate rig (6001 samples), alone (``simulate --rerun``) and overlaid with a second copy (a case
comparing two engines, differences included).

Run: python benchmarks/recording.py   (numbers vary with machine load: compare within one run)
"""

from __future__ import annotations

import tempfile
from dataclasses import replace
from pathlib import Path

from timing import best_of

from validate.assets import rig
from validate.engines import kane
from validate.recording import record, record_trajectory

DURATION, DT_OUT = 60.0, 0.01


def main() -> None:
    r = rig("plate")
    kane.run(r, 1.0, DT_OUT)  # compile or load the kernel outside the timing
    traj = kane.run(r, DURATION, DT_OUT)
    twin = replace(traj, engine="copy")
    simulate = best_of(lambda: kane.run(r, DURATION, DT_OUT))
    with tempfile.TemporaryDirectory() as tmp:
        one = Path(tmp) / "one.rrd"
        two = Path(tmp) / "two.rrd"
        alone = best_of(lambda: record_trajectory(traj, one))
        pair = best_of(lambda: record(two, "two engines", [traj, twin]))
        sizes = one.stat().st_size / 1e6, two.stat().st_size / 1e6
    print(f"plate, {DURATION:g} s at {1 / DT_OUT:g} Hz ({len(traj.t)} samples)")
    print(f"{'':28s} {'wall s':>8s} {'vs simulate':>12s} {'file MB':>8s}")
    print(f"{'simulate (Kane, rtol 1e-10)':28s} {simulate:8.3f} {1.0:12.2f} {'':>8s}")
    print(f"{'record one run':28s} {alone:8.3f} {alone / simulate:12.2f} {sizes[0]:8.2f}")
    print(f"{'record two runs + diffs':28s} {pair:8.3f} {pair / simulate:12.2f} {sizes[1]:8.2f}")


if __name__ == "__main__":
    main()
