"""Issue 37 item 1, how wide the sigma of ordinary gyro trials is: for some of the eight configurations
``identify-record-trials`` draws (validate.cases.records: seed 1819, 25 cycles at 250 Hz), COUNT
repeated trials each (the release within 5 %, new noise), the scatter of T0 against the stated
statistical sigma (1 for an honest sigma), the rms of (T0 - truth) / sigma, and how often the jackknife
set the sigma (a 95 % test: ~5 % where the covariance is honest).

    PYTHONPATH=. python benchmarks/trial_width.py COUNT [CONFIGURATIONS, default 0,2,5,7]

Measured on stop 47's code (30 trials each): configurations 0, 2, 5, 7: sd / sigma 0.69, 0.75, 0.63,
0.63; the jackknife set the sigma in 60 %, 3 %, 20 % and 47 % of the trials (docs/identification.md,
"What is left").
"""

import math
import sys
import time

import numpy as np

from bifilar.identification.records import synthetic as Y
from bifilar.identification.records.fit import fit_oscillation
from bifilar.identification.records.law import AmplitudeLaw
from validate.cases.records import ROD


def main(count: int, configurations: list[int]) -> None:
    law = AmplitudeLaw.torsion(ROD)
    rng = np.random.default_rng(1819)  # identify-record-trials' configurations
    drawn = [Y.gyro(rng, rate=250.0, cycles=25.0) for _ in range(8)]
    print("configuration  sd/sigma  rms z  jackknife  cpu s")
    for k in configurations:
        sub = np.random.default_rng(1000 + k)
        start = time.process_time()
        errors, stat, std, jackknife = [], [], [], []
        for _ in range(count):
            traits = Y.Traits(**{**drawn[k].__dict__, "amplitude": drawn[k].amplitude * sub.uniform(0.95, 1.05)})
            rec = Y.record(ROD, sub, traits)
            fit = fit_oscillation(rec.t, rec.y, "rate", law)
            errors.append(fit.period - rec.period)
            stat.append(fit.period_std_statistical)
            std.append(fit.period_std)
            jackknife.append(fit.jackknife > 0)
        errors = np.array(errors)
        width = errors.std(ddof=1) / math.sqrt(float(np.mean(np.square(stat))))
        rms_z = math.sqrt(float(np.mean((errors / np.array(std)) ** 2)))
        print(f"{k:<13} {width:8.2f} {rms_z:6.2f} {np.mean(jackknife):9.0%} {time.process_time() - start:6.0f}",
              flush=True)


if __name__ == "__main__":
    if len(sys.argv) not in (2, 3):
        sys.exit("usage: python benchmarks/trial_width.py COUNT [CONFIGURATIONS, e.g. 0,2,5,7]")
    main(int(sys.argv[1]), [int(c) for c in (sys.argv[2] if len(sys.argv) == 3 else "0,2,5,7").split(",")])
