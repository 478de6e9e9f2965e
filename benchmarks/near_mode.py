"""Issue 37 item 1 (near modes), the measurement: rate records of the rod (validate.cases.records.ROD)
from 0.3 rad, the ideal law, white noise only, 25 cycles at 250 Hz, a sway at 0.93-1.07 T0 of 2-10 %
of the swing, no decay: z = (T0 - truth) / sigma, the relative error and sigma, the white-noise sigma,
the learned law's excess ds (against its prior, EXCESS_PRIOR times the ideal s) and the second mode
found (its period, size, decay; None: none, or refused inside the band the first mode swept).

    PYTHONPATH=. python benchmarks/near_mode.py SEED COUNT
    PYTHONPATH=. python benchmarks/near_mode.py SEED COUNT damped

``damped``: gyro records of the rod (the identify-record-near-mode traits: 25 cycles at 250 Hz) from
0.5-0.8 rad under strong quadratic (0.025-0.04) and dry (1-3e-3) damping, a sway 4-10 % off the
torsion's frequency (1-2.5 beats over the record) of 5-10 % of the swing. Seed 53, 24 records: "inside
21 of 24 rms z 1.157" with the near-mode fit's first-mode envelope a quadratic in time, "inside 23 of
24 rms z 1.055" with a cubic, "inside 22 of 24 rms z 1.257" choosing between the two by an F test at 1 %,
"inside 24 of 24 rms z 0.822" with the damping law's decay
(:data:`bifilar.identification.records.near._ENVELOPE_TWO`, stop 52).

Measured (seed 7, 30 records, before issue 37 item 1's change): rms z 2.41; every |z| > 2.5 had its
sway at 0.96-0.99 omega0 (under 1 beat over the record, inside the swept band) with sigma ~3e-4 and
an error of 1-3e-3; many others a sigma of ~1e-2 (the white-noise one ~5e-6), the law having taken
the beat for an amplitude-dependent frequency (a 0.96 omega0 sway asked for ds = 0.20, 2.8 s, 8 prior sigmas:
the law conflict, whose sigma holds the T0s of both laws). With the envelope's rise held against the
learned law (:func:`bifilar.identification.records.near.envelope_rises`, :meth:`...phase_law.Model.check_law`):
rms z 1.43; left with |z| > 2.5, 4 records whose sway at 0.97-0.99 omega0 makes half a beat or less (z -2.7
to -3.8): there the envelope only falls faster, and the law learns the beat within its prior.
Stop 49's code (the decay test, the long-run covariance) printed "rms z 1.1376161472353525"; stop 50's
(near modes found by their beat and refitted beside the first mode: :mod:`...records.near`) prints
"rms z 1.1470669697276947": 17 of the 30 have a second mode fitted, 15 within 6e-3 of the sway's
frequency; one record (a sway at 0.987 omega0, under half a beat) is 3.8 sigma off, and the 0.3 rad
records whose law conflicts (e.g. #11, a 9 % sway 1.15 beats off) keep their flag, the two-mode fit of
their cycles no better than one mode's.
"""

import math
import sys
from dataclasses import replace

import numpy as np

from bifilar.identification.records import synthetic as Y
from bifilar.identification.records.fit import fit_oscillation
from bifilar.identification.records.law import AmplitudeLaw
from validate.cases.records import ROD


def damped(seed: int, count: int) -> None:
    """The ``damped`` records (module docstring): z and the fitted sway's frequency over the true one's."""
    law = AmplitudeLaw.torsion(ROD)
    rng = np.random.default_rng(seed)
    zs = []
    for i in range(count):
        traits = Y.gyro(rng, rate=250.0, cycles=25.0)
        off = rng.uniform(0.04, 0.10) * rng.choice([-1, 1])  # the sway's frequency over the torsion's, less 1
        traits = replace(traits, second=(1.0 / (1.0 + off), rng.uniform(0.05, 0.1), traits.second[2]))
        traits = replace(traits, quadratic=rng.uniform(0.025, 0.04), dry=rng.uniform(1e-3, 3e-3),
                         amplitude=rng.uniform(0.5, 0.8))
        rec = Y.record(ROD, rng, traits)
        fit = fit_oscillation(rec.t, rec.y, "rate", law)
        z = (fit.period - rec.period) / fit.period_std
        zs.append(z)
        found = None if fit.second_mode is None else round(fit.second_mode[0] / rec.period * (1.0 + off), 4)
        print(f"{i} off {off:+.3f} z {z:+.2f} second {found}", flush=True)
    zs = np.array(zs)
    print("inside", int(np.sum(np.abs(zs) <= 1.96)), "of", count, "rms z %.3f" % math.sqrt(float(np.mean(zs**2))))


def main(seed: int, count: int) -> None:
    law = AmplitudeLaw.torsion(ROD)
    rng = np.random.default_rng(seed)
    zs = []
    for i in range(count):
        ratio, share = rng.uniform(0.93, 1.07), rng.uniform(0.02, 0.1)
        traits = Y.Traits(kind="rate", rate=250.0, amplitude=0.3, cycles=25.0, zeta=5e-4, white=0.02,
                          second=(ratio, share, 0.0))
        rec = Y.record(ROD, rng, traits)
        fit = fit_oscillation(rec.t, rec.y, "rate", law)
        z = (fit.period - rec.period) / fit.period_std
        zs.append(z)
        print(f"{i:3d} w2/w0 {1 / ratio:.4f} share {share:.3f} z {z:+7.2f} rel {fit.period / rec.period - 1:+.2e} "
              f"sig {fit.period_std / rec.period:.2e} white {fit.period_std_white / rec.period:.2e} "
              f"ds {fit.law.excess:+.3g}+-{fit.law.excess_std:.2g} (s {fit.law.ideal:.3g}) second {fit.second_mode}",
              flush=True)
    print("rms z", math.sqrt(float(np.mean(np.square(zs)))))


if __name__ == "__main__":
    (damped if sys.argv[3:] == ["damped"] else main)(int(sys.argv[1]), int(sys.argv[2]))
