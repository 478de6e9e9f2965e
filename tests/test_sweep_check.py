"""The sweep's MuJoCo check stepped by ``mujoco.rollout`` (validate.engines.mujoco_rig.run_batch) gives
the numbers of the sequential runs it replaces (``mujoco_rig.run``, one by one): same model, start,
steps and samples, so the positions bit for bit; and a run that MuJoCo warns about fails the batch."""

import numpy as np
import pytest

from bifilar.motion.modes import excite, linearize
from bifilar.motion.simulate import IntegrationError
from bifilar.rig.statics import State, initial_state
from bifilar.sweep.space import load_space
from validate.assets import MODELS, rig
from validate.engines import mujoco_rig
from validate.engines.mjcf import CHOSEN
from validate.studies.sweep_check import check

POSITIONS = ("com", "quat", "length_error")  # functions of qpos alone


def _runs() -> list[mujoco_rig.BatchRun]:
    """Two models (different sizes and wires), different durations and sample steps, excited modes."""
    plate, bench = rig("plate"), rig("bench_plate")
    lin = linearize(bench)
    return [mujoco_rig.BatchRun(bench, 0.6, 0.0048, excite(lin, 0, 1e-3)),
            mujoco_rig.BatchRun(bench, 0.4, 0.002, excite(lin, 3, 1e-3)),
            mujoco_rig.BatchRun(plate.with_initial(rotation=(0.0, 0.0, 0.1)), 0.3, 0.01)]


def _sequential(runs):
    return [mujoco_rig.run(r.rig, r.duration, r.dt_out, state=r.state) for r in runs]


def test_batched_runs_are_the_sequential_runs():
    """Each run in one rollout call: the positions bit for bit. The tensions and velocities are read
    from a forward pass at each sample whose solver starts from another warm start (the previous
    sample's acceleration, not the previous step's); Newton lands on the same answer to its last
    bits (measured: 1e-15 of the tension, 3e-20 m/s)."""
    runs = _runs()
    for seq, bat in zip(_sequential(runs), mujoco_rig.run_batch(runs, nthread=2)):
        np.testing.assert_array_equal(bat.t, seq.t)
        for name in POSITIONS:
            np.testing.assert_array_equal(bat[name], seq[name])
        np.testing.assert_allclose(bat["tension"], seq["tension"], rtol=1e-13, atol=0)
        for name in ("velocity", "omega", "energy"):
            np.testing.assert_allclose(bat[name], seq[name], rtol=0, atol=1e-15)
        assert bat.meta["first_slack"] == seq.meta["first_slack"]


def test_runs_too_long_for_one_call_go_in_pieces_and_agree_to_rounding(monkeypatch):
    """With room for 2000 steps a call, every run is cut in pieces, each started from the latest
    sample's acceleration as warm start: the solver gives the same answer to rounding, so at most a
    few last bits of the state differ. The soft cable rows turn that into tension: a row pulls with
    m k r, k = 1 / (d timeconst dampratio)^2 = 6.4e8 / s^2 at the chosen settings, so a last bit of a
    wire's length (~1e-15 m at 5 m) is ~1e-4 N on the 100 kg plate (measured 5e-5 N)."""
    monkeypatch.setattr(mujoco_rig, "ROLLOUT_FLOATS", 2000 * 14)
    runs = _runs()
    d, (timeconst, dampratio) = CHOSEN.solimp[0], CHOSEN.solref
    k = 1.0 / (d * timeconst * dampratio) ** 2
    for r, seq, bat in zip(runs, _sequential(runs), mujoco_rig.run_batch(runs, nthread=2)):
        for name in ("com", "length_error"):
            np.testing.assert_allclose(bat[name], seq[name], rtol=0, atol=1e-14)
        last_bit = np.spacing(max(w.length for w in r.rig.wires))
        np.testing.assert_allclose(bat["tension"], seq["tension"], rtol=0, atol=4 * r.rig.mass * k * last_bit)


def test_a_warning_inside_rollout_fails_the_batch():
    """A spin of 2e10 rad/s is over MuJoCo's velocity limit (1e10): rollout stops that run at its first
    step (MuJoCo resets it), so its clock stops, which the batch reports; the other run is unharmed."""
    bench = rig("bench_plate")
    rest = initial_state(bench)
    bad = State(rest.com, rest.rotation, rest.velocity, np.array([0.0, 0.0, 2e10]))
    with pytest.raises(IntegrationError, match="a warning stopped the run of bench_plate"):
        mujoco_rig.run_batch([mujoco_rig.BatchRun(bench, 0.02, 0.01), mujoco_rig.BatchRun(bench, 0.02, 0.01, bad)])


@pytest.mark.slow
def test_the_batched_check_is_the_sequential_check():
    """The best configuration of the small bench-plate sweep (the case sweep-mujoco-check's) and one
    more, x, y and z each: every number of the check equal, to 1e-12 (measured: the periods bit for
    bit, the mean tensions to 4e-16)."""
    space = load_space(MODELS / "sweeps" / "bench_plate_small.toml")
    configurations = [{"wire_length": 0.75, "attach_span": 0.2}, {"wire_length": 1.0, "attach_span": 0.3}]
    batched = check(space, configurations)
    sequential = check(space, configurations, batched=False)
    for b, s in zip(batched, sequential):
        assert b.entry["configuration"] == s.entry["configuration"] and b.entry["ok"] == s.entry["ok"]
        for mb, ms in zip(b.entry["modes"], s.entry["modes"]):
            assert (mb["axis"], mb["motion"], mb["predicted"]) == (ms["axis"], ms["motion"], ms["predicted"])
            assert mb["mujoco"] == pytest.approx(ms["mujoco"], rel=1e-12, abs=0)
            assert mb["period_rel_error"] == pytest.approx(ms["period_rel_error"], rel=0, abs=1e-12)
            assert mb["tension_rel_error"] == pytest.approx(ms["tension_rel_error"], rel=0, abs=1e-12)
        assert b.runs.keys() == s.runs.keys() == set(space.measure)


def test_rigs_of_different_shapes_are_not_batched():
    """One MjData per thread serves every model of a batch: two wires and three cannot share it."""
    with pytest.raises(ValueError, match="differ in size"):
        mujoco_rig.run_batch([mujoco_rig.BatchRun(rig("bench_plate"), 0.02, 0.01),
                              mujoco_rig.BatchRun(rig("trifilar"), 0.02, 0.01)])
