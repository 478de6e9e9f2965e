"""A plausible swing in the wrong unit (issue 35, item 15): a 0.02 rad swing logged in deg/s and read as
rad/s is a 1.15 rad swing the rig can make; how its period changes as it decays says which it was
(bifilar.identification.records.units)."""

import json
import math

import numpy as np
import pytest

from bifilar.identification.records import Record, identify_records
from bifilar.identification.records import synthetic as Y
from bifilar.identification.records.units import BAYES_FACTOR, degrees_evidence
from bifilar.motion import lagrange as L
from validate import cli
from validate.assets import RIGS, rig

PLATE = rig("bench_plate")
BENCH = L.from_rig(PLATE)
TO_DEG = 180.0 / math.pi
FLAG = "likely unit mistake"


def _trial(amplitude: float, white: float, scale: float, seed: int = 1, zeta: float = 2e-3):
    """A 30-cycle 200 Hz gyro record of the bench plate (white noise ``white`` rad/s) written times
    ``scale`` and read as rad/s: its trial and the evidence for degrees (2 ln B, chi^2 rad, chi^2 deg)."""
    rec = Y.record(BENCH, np.random.default_rng(seed), Y.Traits(kind="rate", rate=200.0, amplitude=amplitude,
                                                                cycles=30, white=white, zeta=zeta))
    (trial,), _ = identify_records(PLATE, "z", [Record("log.csv", "gyro_z", "rate", rec.t, scale * rec.y)])
    return trial, degrees_evidence(trial.fit, 0.35)


def test_deg_per_second_read_as_rad_per_second_is_flagged():
    """0.02 rad decaying to 0.014 rad in deg/s read as rad/s: 1.14 rad as the file says, whose law would
    lengthen the period by ~4 % over the decay; the record's is flat. Its excess sits at -s (chi^2 8.7
    as a real rig's, 0.4 as degrees): Bayes factor ~370 for degrees, flagged naming the unit."""
    trial, (evidence, rad, deg) = _trial(0.02, 3e-4, TO_DEG)
    assert trial.fit.amplitude[0] == pytest.approx(0.02 * TO_DEG, rel=0.01)
    assert evidence > 2.0 * math.log(BAYES_FACTOR) and rad > 5.0 and deg < 2.0
    (flag,) = [f for f in trial.flags if FLAG in f]
    assert "deg/s (--angle-unit deg)" in flag and "as a 0.0199 rad swing's" in flag


def test_a_true_large_swing_in_rad_per_second_is_not_flagged():
    """A true 1.15 rad swing at a gyro's noise (0.03 rad/s): its excess is a real rig's (chi^2 ~0),
    degrees would need it at -s (chi^2 ~8): no flag."""
    trial, (evidence, rad, deg) = _trial(1.15, 0.03, 1.0, zeta=5e-4)
    assert evidence < 0.0 and rad < 1.0 and deg > 4.0
    assert not any(FLAG in f for f in trial.flags)


@pytest.mark.parametrize("amplitude, white, scale", [(0.02, 0.01, TO_DEG), (0.03, 0.01, 1.0)])
def test_a_record_that_cannot_tell_says_nothing(amplitude, white, scale):
    """A 0.02 rad swing in deg/s read as rad/s at a gyro's noise (0.01 rad/s, a sixth of the swing's
    rate): its excess is known to ~0.05, not well under s = 0.068, so the odds stay under 100. A true
    0.03 rad swing: neither scale's law lengthens its period measurably. Neither is flagged."""
    trial, found = _trial(amplitude, white, scale, zeta=5e-4)
    assert found is None or found[0] < 2.0 * math.log(BAYES_FACTOR)
    assert not any(FLAG in f for f in trial.flags)


@pytest.mark.slow
def test_cli_flags_a_flight_log_read_without_its_unit(tmp_path, capsys):
    """A flight log (ms, deg/s) given without --angle-unit deg: identify's JSON ``flags`` say so."""
    rec = Y.record(BENCH, np.random.default_rng(1), Y.Traits(kind="rate", rate=200.0, amplitude=0.02, cycles=30,
                                                             white=3e-4, zeta=2e-3))
    path = tmp_path / "gyro.csv"
    Y.write_gyro_csv(path, rec)
    args = [str(RIGS / "bench_plate.toml"), "--axis", "z", "--signal", str(path), "--column", "gyro_z",
            "--kind", "rate", "--time-unit", "ms", "--samples", "100", "--json"]
    assert cli.main(["identify", *args]) == 0
    out = json.loads(capsys.readouterr().out)
    assert any(FLAG in f and "deg/s" in f for f in out["flags"])
