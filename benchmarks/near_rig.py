"""Issue 37 item 1 with the rig file, the measurement: bench_plate with I_zz drawn (0.23-0.38 kg m^2)
where its yaw lies within 10 % of the frequency of one of its two sways (2.828 and 2.857 s), a 250 Hz
gyro record of 25 cycles with the identify-record-trials traits whose sway is that mode of the rig
(2-10 % of the swing; ``clean``: the same records without it), identified as a lab would, with the
rig file (I_zz 0.15 there; :func:`validate.cases.records.near_rig_records`): z of the moment, its
relative sigma, the beats the sway makes over the record, the mode fitted beside the torsion (its
period over T0), what fitting the rig's mode at its frequency moved T0 (``shift``, s: in the sigma,
:func:`bifilar.identification.records.pipeline._with_rig_mode`) and whether a near-mode flag of the
rig fired; last, the rms of z and of the relative error of the moment.

    PYTHONPATH=. python benchmarks/near_rig.py SEED COUNT [clean]

Stop 53's code (where the record shows no mode near the torsion and the rig has one beating under 1.5
times, the record refitted with a mode at the rig's frequency and the move of T0 put in the sigma):
seed 3711, 32 records: "inside 30 of 32 rms z 1.010 rms error 2.80e-03"; its misses z +2.00 (0.82
beats) and -3.79 (2.55 beats, its sway found by the record: a record whose traits miss without the
sway as well, six draws without it: rms z 1.65). Seed 4242, 24 records: "inside 24 of 24 rms z 0.697
rms error 6.46e-03". ``clean``, seed 3711: "inside 30 of 32 rms z 1.031 rms error 1.45e-03" (the
estimates are those of stop 52's code, "inside 29 of 32 rms z 1.165 rms error 1.45e-03"; of the 16
sigmas that grew, the median by 1.3x, the largest 6.2x). Taking the fit with the mode as the estimate
instead (its own sigma): "inside 31 of 32 rms z 0.975 rms error 4.19e-03", clean "inside 29 of 32 rms
z 1.095 rms error 2.16e-03": the phantom mode a record without the sway is given moves T0 more than
the sway it stands for.

Stop 52's code, which only flagged such records: seed 3711 "inside 28 of 32 rms z 1.728", the three
misses under 1.5 beats flagged (z +3.73, +3.59, -5.75; now +1.25, +2.00, -1.01); seed 4242 "inside 21
of 24 rms z 1.351". With the first mode's envelope beside a near mode a quadratic in time (stop 50):
"inside 27 of 32 rms z 2.065", a sway 1.23 beats off under strong quadratic and dry damping fitted
0.47 % off its frequency and left unflagged (z +6.92); a cubic: "inside 27 of 32 rms z 1.774".
"""

import math
import sys

import numpy as np

from bifilar.identification.records import Record, identify_records
from validate.assets import rig
from validate.cases.records import near_rig_records


def main(seed: int, count: int, with_sway: bool) -> None:
    plate = rig("bench_plate")
    zs, errors = [], []
    for i, (moment, sway, period, rec) in enumerate(near_rig_records(np.random.default_rng(seed), count, with_sway)):
        (trial,), _ = identify_records(plate, "z", [Record("log.csv", "gyro_z", "rate", rec.t, rec.y)])
        z = (trial.moment - moment) / trial.moment_std
        zs.append(z)
        errors.append(trial.moment / moment - 1.0)
        flagged = any("the rig has" in flag for flag in trial.flags)
        beats = abs(1.0 / sway - 1.0 / period) * (rec.t[-1] - rec.t[0])
        second = trial.fit.second_mode
        print(f"{i:2d} I {moment:.3f} sway/T0 {sway / period:.4f} beats {beats:.2f} share {rec.traits.second[1]:.3f} "
              f"z {z:+.2f} sigma {trial.moment_std / moment:.1e} "
              f"fitted {None if second is None else round(second[0] / trial.fit.period, 4)} "
              f"{f'shift {trial.fit.rig_mode_shift:+.1e} ' if trial.fit.rig_mode_shift else ''}"
              f"flagged {flagged}", flush=True)
    zs = np.array(zs)
    print("inside", int(np.sum(np.abs(zs) <= 1.96)), "of", count, "rms z %.3f" % math.sqrt(float(np.mean(zs**2))),
          "rms error %.2e" % math.sqrt(float(np.mean(np.square(errors)))))


if __name__ == "__main__":
    main(int(sys.argv[1]), int(sys.argv[2]), sys.argv[3:] != ["clean"])
