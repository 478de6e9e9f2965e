"""Speed of the record fit's steps on a generated record: the whole fit, its damping correction and its
periodograms, each against what it replaced where that is still a library call.

Run: python benchmarks/record_fit.py   (numbers vary with machine load: compare within one run)

Printed on this shared 2-core machine (OPENBLAS_NUM_THREADS=1, as ``validate`` sets it; issue 34), with
another user's load on it:

    synthetic gyro record (20 cycles, 250 Hz) generated in 0.55 s
    fit_oscillation, the whole record fit: 0.31 s
    damping_shift (compiled RK4, 16 amplitudes): 0.19 ms
    periodogram, 1024 samples x 1020 frequencies: 34 ms; scipy's lombscargle (floating mean): 65 ms

    12 gyro trials: 4.12 s; 6 video records of 100 cycles: 2.02 s

The last line (stop 49) against stop 48's code, alternately in one session (``cd`` a checkout of it,
``PYTHONPATH=. python <this file>``): 3.62 and 4.03 s, 1.85 and 1.89 s then; 4.27 and 4.23 s, 2.06 and
2.03 s now, 5-18 % more (the envelope degree's refits and the jackknife's leverage ratio). The numpy RK4 that damping_shift replaced took ~28 ms a call. The two record cases of ``validate all``,
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
    batch(law)
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


def batch(law: AmplitudeLaw) -> None:
    """The record cases' two kinds in bulk, less noisy than one fit: 12 gyro trials (25 cycles at 250 Hz,
    identify-record-trials' traits) and 6 video records of 100 cycles with AR(1) tracking noise
    (tests/test_record_sigma.py's)."""
    rng = np.random.default_rng(1819)
    gyros = [Y.record(ROD, rng, Y.gyro(rng, rate=250.0, cycles=25.0)) for _ in range(12)]
    video = Y.Traits(amplitude=0.8, cycles=100.0, white=0.0035, coloured=0.0066, colour_time=0.12, zeta=1.2e-3,
                     excess=0.25, shape=0.1)
    videos = [Y.record(ROD, np.random.default_rng(seed), video) for seed in range(6)]
    g = best_of(lambda: [fit_oscillation(r.t, r.y, "rate", law) for r in gyros], repeat=2)
    v = best_of(lambda: [fit_oscillation(r.t, r.y, "angle", law) for r in videos], repeat=2)
    print(f"12 gyro trials: {g:.2f} s; 6 video records of 100 cycles: {v:.2f} s")


if __name__ == "__main__":
    main()
