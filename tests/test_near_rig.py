"""A rig whose own modes lie near the one timed (issue 37 item 1: a sway near the torsion flagged where
a record cannot show it). bench_plate's yaw is tuned by its moment: at I_zz = 0.29 kg m^2 it swings
at 2.789 s, beside the bifilar's two sways at 2.828 and 2.857 s (1.4 and 2.4 % off in frequency).
A sway that beats less than about once over a record is taken by the amplitude law (records.near), so
identify refits the record with a mode at the rig's frequency beside the torsion, whatever its size
(records.near.near_held), carries how far that moves T0 into the sigma and says so; a record long enough
to beat more is not flagged.
The rig's own motion (the Kane model) shows such a pair beating in a gyro's record where the COM is off
the wires' plane and mixes them."""

import json
import math
from dataclasses import replace

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from bifilar.identification import identify as ident
from bifilar.identification.measurement import measure, trial_dict
from bifilar.identification.records import AmplitudeLaw, Record, fit_oscillation, identify_records
from bifilar.identification.records import pipeline
from bifilar.identification.records import synthetic as Y
from bifilar.identification.records.near import NEAR_BAND
from bifilar.identification.records.pipeline import NEAR_BEATS, near_modes
from bifilar.motion import lagrange as L
from bifilar.motion.kane import KaneModel
from bifilar.motion.simulate import simulate
from bifilar.rig import RigError
from bifilar.rig.statics import State, rest_pose, taut_shift
from validate import cli
from validate.assets import rig
from validate.cases.records import near_rig_records

PLATE = rig("bench_plate")
TUNED = 0.29  # kg m^2: the yaw 1.4 % from one sway, 2.4 % from the other
FLAG = "the rig has modes at"


def _trial(cycles: float, rate: float):
    """A gyro record of the tuned plate (0.3 rad, white noise 0.01 rad/s, no sway in it), identified
    with the bench plate's rig file (I_zz 0.15 there: the moment is found, and the modes there)."""
    truth = L.from_rig(ident.with_moment(PLATE, "z", TUNED))
    rec = Y.record(truth, np.random.default_rng(3), Y.Traits(kind="rate", rate=rate, amplitude=0.3, cycles=cycles,
                                                             white=0.01, zeta=1e-3))
    (trial,), _ = identify_records(PLATE, "z", [Record("log.csv", "gyro_z", "rate", rec.t, rec.y)])
    return trial


def test_near_modes_are_the_rigs_other_modes_within_the_band():
    p = ident.pencil(PLATE, "z")
    for value in (0.15, TUNED, 0.31):
        k, w2, _ = p.associated(value)
        periods = 2.0 * math.pi / np.sqrt(w2)
        expected = sorted(periods[j] for j in range(len(w2)) if j != k and abs(periods[k] / periods[j] - 1.0) <= NEAR_BAND)
        assert sorted(near_modes(p, value)) == pytest.approx(expected, rel=1e-12)
    assert near_modes(p, 0.15) == ()  # the plate's own yaw, 2.006 s: its sways 29-30 % slower
    # tuned: the two sways; past them (0.31) the yaw is the slowest mode, the sways still within the band
    assert sorted(near_modes(p, TUNED)) == pytest.approx([2.8281, 2.8574], abs=1e-4)
    assert len(near_modes(p, 0.31)) == 2


def test_a_record_a_sway_could_hide_in_is_flagged():
    """30 cycles of 2.789 s: the sways beat 84 s x |1/T2 - 1/T0| = 0.43 and 0.74 times, under a beat."""
    trial = _trial(30.0, 200.0)
    assert trial.moment == pytest.approx(TUNED, rel=1e-3)  # the record itself is fine (sigma 3e-4 relative)
    (flag,) = [f for f in trial.flags if FLAG in f]
    assert "2.828 s (1.4 %" in flag and "2.857 s (2.4 %" in flag and "0.43 beats" in flag
    near = trial_dict(trial, 4.0)["near_modes"]
    span = trial.record.t[-1] - trial.record.t[0]
    for mode in near:
        assert mode["beats"] == pytest.approx(span * abs(1.0 / mode["period"] - 1.0 / trial.fit.period), rel=1e-12)
    assert sorted(m["beats"] for m in near) == pytest.approx([0.43, 0.74], abs=0.01)


def test_what_the_rig_s_hidden_mode_moves_t0_is_in_the_sigma():
    """The three records of benchmarks/near_rig.py's seed 3711 whose sway hid from the record's own
    search (0.21, 0.82 and 0.10 beats over it; stop 52 flagged them, z +3.73, +3.59 and -5.75). The
    record refitted with a mode at the rig's period (held to the digit: fit_oscillation's near_periods)
    moves T0, and that move is in the sigma beside the fit's own: each moment within 3 sigma of the truth
    (measured z +1.25, +2.00, -1.01), and the flag quotes the move and the sigma."""
    records = list(near_rig_records(np.random.default_rng(3711), 26))
    for i in (0, 23, 25):
        moment, _, _, rec = records[i]
        (trial,), _ = identify_records(PLATE, "z", [Record("log.csv", "gyro_z", "rate", rec.t, rec.y)])
        shift = trial.fit.rig_mode_shift
        assert shift != 0.0 and trial.fit.period_std_parts["rig_mode"] == abs(shift)
        assert trial.fit.period_std > abs(shift)
        law = AmplitudeLaw.torsion(L.from_rig(ident.with_moment(PLATE, "z", moment)))
        held = fit_oscillation(rec.t, rec.y, "rate", law, near_periods=trial.near)
        assert held.near_held and min(abs(held.second_mode[0] / t2 - 1.0) for t2 in trial.near) < 1e-12
        assert abs(trial.moment - moment) < 3.0 * trial.moment_std, i  # 0.3 % of honest sigmas fail
        (flag,) = [f for f in trial.flags if "at the rig's frequency" in f]
        assert flag.startswith("log.csv: the rig has mode") and f"moves T0 by {shift:+.2g} s" in flag
        assert f"({100.0 * trial.fit.period_std / trial.fit.period:.2g} % of T0)" in flag


def test_a_record_whose_refit_with_the_rig_s_mode_fails_keeps_its_fit_and_flag(monkeypatch):
    """The refit with the rig's mode is a second opinion: if it raises, the record keeps its own fit
    and the flag that its sigma may not hold the sway (none of the rig's mode's part in it)."""
    fit = pipeline._fit

    def failing(record, law, options, deadline=None, near=()):
        if near:
            raise RigError(record.source, record.column, "a refit that fails")
        return fit(record, law, options, deadline)

    monkeypatch.setattr(pipeline, "_fit", failing)
    rec = list(near_rig_records(np.random.default_rng(3711), 26))[25][3]
    (trial,), _ = identify_records(PLATE, "z", [Record("log.csv", "gyro_z", "rate", rec.t, rec.y)])
    assert trial.fit.rig_mode_shift == 0.0 and "rig_mode" not in trial.fit.period_std_parts
    assert any("T0's sigma may not hold it" in f for f in trial.flags)


@pytest.mark.slow
def test_identify_says_what_the_rig_s_hidden_mode_adds(capsys, tmp_path):
    """``identify --signal`` on the record of that seed whose sway hid 0.10 beats off (stop 52: z -5.75):
    the JSON's sigma parts hold ``rig_mode``, most of the record's variance, the flag quotes the move, and
    the text names the part in words."""
    moment, _, _, rec = list(near_rig_records(np.random.default_rng(3711), 26))[25]
    path = tmp_path / "log.csv"
    np.savetxt(path, np.column_stack([rec.t, rec.y]), delimiter=",", header="t,gyro_z", comments="")
    args = ["identify", "bench_plate", "--axis", "z", "--signal", str(path), "--column", "gyro_z", "--kind", "rate"]
    assert cli.main([*args, "--json"]) == 0
    (trial,) = json.loads(capsys.readouterr().out)["trials"]
    move = trial["period_std_parts"]["rig_mode"]
    assert move**2 > 0.5 * trial["period_std_statistical"] ** 2
    assert any(f"moves T0 by {move:+.2g} s" in f or f"moves T0 by {-move:+.2g} s" in f for f in trial["flags"])
    assert abs(trial["inertia"] - moment) < 3.0 * trial["std"]  # 0.3 % of honest sigmas fail
    assert cli.main(args) == 0
    assert "what the rig's near mode, fitted at its frequency, moves T0" in " ".join(capsys.readouterr().out.split())


@pytest.mark.slow
def test_a_record_long_enough_to_beat_is_not_flagged():
    """120 cycles: the sways beat 1.7 and 2.9 times, past NEAR_BEATS: a sway of them would show in the
    record (a beat, fitted or flagged by the fit itself); the modes are still listed in the JSON."""
    trial = _trial(120.0, 50.0)
    assert not [f for f in trial.flags if FLAG in f or "the rig has a mode" in f]
    assert min(m["beats"] for m in trial_dict(trial, 4.0)["near_modes"]) > NEAR_BEATS


def test_a_rig_s_own_yaw_and_sway_beating_in_its_gyro_are_flagged():
    """Exact physics, no sway added: the plate's COM 1 cm off the wires' plane (y) mixes its yaw with its
    in-plane sway, and at I_zz = 0.32 kg m^2 the yaw (2.798 s) lies 1.1 % from that sway (2.830 s),
    whose share of the rotation about z is 0.085 (an avoided crossing: 0.0062 at 0.30, 0.33 at
    0.325). Let go by a pure 0.2 rad twist about z, the Kane model's body-z rate over 84 s (30 yaw
    cycles, 0.31 beats of that pair) with 0.01 rad/s of gyro noise holds both modes. Identified with the
    rig file: the near modes are flagged, and the moment is within its sigma (measured z -0.77, the
    fit's own beat test holding the ideal law's T0 too: sigma 0.7 %)."""
    truth = ident.with_moment(replace(PLATE, com=np.array([0.0, 0.01, 0.0])), "z", 0.32)
    rest = rest_pose(truth)
    p = ident.pencil(truth, "z", rest)
    k, w2, v = p.associated(0.32)
    shares = p.shares(0.32, v)
    assert 2.0 * math.pi / math.sqrt(w2[k]) == pytest.approx(2.7983, abs=1e-4) and shares[k] == pytest.approx(0.8585, abs=1e-4)
    twisted = Rotation.from_rotvec([0.0, 0.0, 0.2]).as_matrix() @ rest.rotation
    start = State(rest.com + taut_shift(truth, rest.com, twisted), twisted, np.zeros(3), np.zeros(3))
    run = simulate(KaneModel.from_rig(truth), start, 84.0, dt_out=0.01, rtol=1e-10)
    rate = np.einsum("nji,nj->ni", run.rotation, run.omega)[:, 2]  # the body-z gyro: R^T omega
    rate = rate + 0.01 * np.random.default_rng(1).standard_normal(len(rate))
    (trial,), _ = identify_records(truth, "z", [Record("coupled.csv", "gyro_z", "rate", run.t, rate)])
    (flag,) = [f for f in trial.flags if FLAG in f]
    # the mixed sway, at the moment identified (0.318: 2.8298 s; at 0.32, 2.8303 s: the crossing moves it)
    assert "2.83 s (" in flag and min(abs(t2 - 2.8303) for t2 in trial.near) < 1e-3
    assert abs(trial.moment - 0.32) < 3.0 * trial.moment_std  # 99.7 % for an honest sigma


def test_a_period_of_a_rig_with_modes_near_the_timed_one_says_how_long_to_time():
    """identify --period: a stopwatch period has no record to beat over, so the flag says how many cycles
    make NEAR_BEATS beats with each near mode (1.5 / gap: 1.5 / 0.0240 = 62.6 and 1.5 / 0.0139 = 108 for
    the tuned plate's 2.789 s yaw); the plate's own 2.006 s yaw, its sways 30 % off, gets none."""
    tuned = ident.linear_period(ident.with_moment(PLATE, "z", TUNED), "z")
    (flag,) = [f for f in measure(PLATE, "z", period=tuned).flags if "the rig has modes at" in f]
    for t2 in (2.8574, 2.8281):
        assert f"{NEAR_BEATS / abs(tuned / t2 - 1.0):.3g} cycles make 1.5 beats" in flag
    assert "62.6 cycles" in flag and "108 cycles" in flag
    assert not [f for f in measure(PLATE, "z", period=ident.linear_period(PLATE, "z")).flags if "the rig has" in f]
