"""Speed of the record fit's steps on a generated record: the whole fit, its damping correction and its
periodograms, each against what it replaced where that is still a library call.

Run: python benchmarks/record_fit.py   (numbers vary with machine load: compare within one run)

Printed on this shared 2-core machine (OPENBLAS_NUM_THREADS=1, as ``validate`` sets it; issue 34), with
another user's load on it:

    synthetic gyro record (20 cycles, 250 Hz) generated in 0.55 s
    fit_oscillation, the whole record fit: 0.31 s
    damping_shift (compiled RK4, 16 amplitudes): 0.19 ms
    periodogram, 1024 samples x 1020 frequencies: 34 ms; scipy's lombscargle (floating mean): 65 ms

The numpy RK4 that damping_shift replaced took ~28 ms a call. The two record cases of ``validate all``,
before and after (one worker each, warm, side by side in one run, two repeats): identify-record-efficiency
4.65 / 4.60 s -> 2.57 / 2.58 s, identify-records 4.08 / 3.98 s -> 2.97 / 3.03 s, every metric the same to
the last bit.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.signal import lombscargle
from timing import best_of

from bifilar.identification.records import AmplitudeLaw, fit_oscillation
from bifilar.identification.records import synthetic as Y
from bifilar.identification.records.cycles import periodogram
from bifilar.identification.records.damping import damping_shift
from bifilar.motion import lagrange as L

ROD = L.TorsionRig.parallel(0.5, 0.0016, 0.8, 0.196)  # the rod of the records cases (T0 = 1.036 s)


def main() -> None:
    traits = Y.gyro(np.random.default_rng(1), rate=250.0, amplitude=0.4, cycles=20.0)
    made = []
    seconds = best_of(lambda: made.append(Y.record(ROD, np.random.default_rng(2), traits)), repeat=1)
    rec = made[0]
    print(f"synthetic gyro record (20 cycles, 250 Hz) generated in {seconds:.2f} s")
    law = AmplitudeLaw.torsion(ROD)
    fit_oscillation(rec.t, rec.y, "rate", law)  # compiles or loads the damping kernel outside the timing
    print(f"fit_oscillation, the whole record fit: {best_of(lambda: fit_oscillation(rec.t, rec.y, 'rate', law)):.2f} s")
    damping = {"linear": 1e-4, "quadratic": 1e-3, "dry": 1e-6}
    amplitude = np.linspace(0.2, 0.4, 40)
    shift = best_of(lambda: damping_shift(damping, amplitude), repeat=20)
    print(f"damping_shift (compiled RK4, 16 amplitudes): {1e3 * shift:.2f} ms")
    rng = np.random.default_rng(3)
    x = np.sort(rng.uniform(0.0, 60.0, 1024))
    y = np.cos(6.1 * x) * np.exp(-0.01 * x) + 0.05 * rng.standard_normal(len(x))
    grid = np.arange(0.2, math.pi * (len(x) - 1) / 60.0, math.pi / 60.0)
    ours = best_of(lambda: periodogram(x, y, grid), repeat=5)
    scipys = best_of(lambda: lombscargle(x, y, grid, floating_mean=True), repeat=5)
    print(f"periodogram, {len(x)} samples x {len(grid)} frequencies: {1e3 * ours:.0f} ms; "
          f"scipy's lombscargle (floating mean): {1e3 * scipys:.0f} ms")


if __name__ == "__main__":
    main()
