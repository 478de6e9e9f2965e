"""MuJoCo's own system identification (validate/engines/mujoco_sysid.py) on Kane-simulated gyro records of
models/rigs/bench_plate.toml: it recovers the rig file's I_zz within its stated sigma, it does not
recover it from a record of another body, and the two facts the glue rests on (the rollout's one-step
sensor lag, the physical range of the moment) hold."""

from __future__ import annotations

import mujoco
import mujoco.rollout
import numpy as np
import pytest
from mujoco import sysid

from bifilar.identification import identify as ident
from bifilar.rig import RigError
from validate.assets import rig
from validate.engines import mjcf
from validate.engines.mujoco_sysid import fit_moment, kane_gyro_record, physical_range

PLATE = rig("bench_plate")
TRUTH = ident.moment(PLATE, "z")
STEP = 2e-3  # s; the clean fit's error at this step is 2.8e-6 (validate case identify-sysid-kane-record)


@pytest.fixture(scope="module")
def record():
    """3 cycles from 0.3 rad at 100 Hz, stated noise 0.01 rad/s (clean)."""
    return kane_gyro_record(PLATE, "z", 0.3, 3.0, 100.0, 0.01)


def test_recovers_the_moment(record):
    fit = fit_moment(PLATE, "z", record.noisy(np.random.default_rng(1)), 0.8 * TRUTH, STEP)
    # 3 sigma: a correct sigma is exceeded with probability 0.003 (50 seeds: |z| std 0.98, coverage 96 %)
    assert abs(fit.moment - TRUTH) <= 3.0 * fit.std
    # 0.01 rad/s over 3 cycles states sigma ~1e-4 of I_zz; a sigma ten times too large would pass the
    # line above for anything: bound it from the noise (5e-4 is 3 sigma at 4 cycles' 1.2e-4, generous)
    assert fit.std / TRUTH < 5e-4
    assert abs(fit.residual_variance - 1.0) < 5.0 * np.sqrt(2.0 / fit.samples)  # whitened: N(0, 1) residuals


def test_clean_record_error_is_the_step_error(record):
    fit = fit_moment(PLATE, "z", record, 0.8 * TRUTH, STEP)
    # leapfrog period error (w h)^2 / 24 = 1.6e-6 at h = 2e-3 s, / (d ln T / d ln I = 0.5): 3.3e-6
    assert abs(fit.moment / TRUTH - 1.0) < 1e-5


def test_record_of_another_body_is_not_the_files_truth():
    """A plate 10 % lighter in I_zz (a heavier one is not a body: the plate is nearly flat): the fit
    finds that plate's moment, and the rig file's is far outside its sigma."""
    other = ident.with_moment(PLATE, "z", 0.9 * TRUTH)
    noisy = kane_gyro_record(other, "z", 0.3, 3.0, 100.0, 0.01).noisy(np.random.default_rng(2))
    fit = fit_moment(PLATE, "z", noisy, 0.8 * TRUTH, STEP)
    assert abs(fit.moment - TRUTH) > 100.0 * fit.std
    assert abs(fit.moment - 0.9 * TRUTH) <= 3.0 * fit.std


def test_rollout_gyro_lags_one_step(record):
    """mujoco.rollout labels a reading with the time after its step; MuJoCo computes it before: the
    gyro labelled t is the Kane rate at t - h (to the linear interpolation of the 100 Hz record) and
    clearly not at t (a lag of h costs h * alpha, RMS ~4e-3 rad/s here)."""
    model = mjcf.build_spec(PLATE, numerics=mjcf.CHOSEN.with_(timestep=STEP), gyro=True).compile()
    qpos, qvel = mjcf.state_qpos_qvel(PLATE, record.state)
    n = round(record.t[-1] / STEP)
    state, sensors = mujoco.rollout.rollout(model, mujoco.MjData(model), sysid.create_initial_state(model, qpos, qvel),
                                            np.zeros((n, 0)))
    t, gyro = state[0, :, 0], sensors[0, :, 2]
    inside = t <= record.t[-1]

    def rms(lag):
        return np.sqrt(np.mean((gyro[inside] - np.interp(t[inside] - lag, record.t, record.rate[:, 2])) ** 2))

    assert rms(STEP) < 1e-4  # linear interpolation of the 100 Hz record: h_rec^2 w^2 |rate| / 8 ~ 1e-4
    assert rms(0.0) > 10.0 * rms(STEP)


def test_physical_range_of_a_diagonal_tensor():
    """For principal axes the moments that keep a body are |I_xx - I_yy| <= J <= I_xx + I_yy."""
    low, high = physical_range(PLATE, "z")
    ixx, iyy = PLATE.inertia[0, 0], PLATE.inertia[1, 1]
    assert low == pytest.approx(abs(ixx - iyy), rel=1e-5)
    assert high == pytest.approx(ixx + iyy, rel=1e-5)


def test_guess_that_is_no_body_is_refused(record):
    with pytest.raises(RigError, match="guess"):
        fit_moment(PLATE, "z", record, 1.2 * TRUTH, STEP)
