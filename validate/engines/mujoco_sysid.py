"""One moment of inertia of the MuJoCo rig fitted by MuJoCo's own system identification (``mujoco.sysid``)
to a gyro record: the cross-check of our identification by one we did not write (issue 13, item 9).

The record (:func:`kane_gyro_record`): the Kane model released along the mode of a body axis
(:func:`bifilar.identification.identify.released`), sampled as a rate gyro strapped to the body reads
it: the angular velocity in body axes (rad/s), white noise of a stated sigma on each axis, fixed seed.

The fit (:func:`fit_moment`), mujoco.sysid used as its own tests use it: the rig's MJCF from
:func:`validate.engines.mjcf.build_spec` with its ``gyro`` sensor, the release as the initial state
(``create_initial_state``), one :class:`~mujoco.sysid.Parameter` (the moment about the axis, written
into the body's ``fullinertia`` by :func:`~bifilar.identification.identify.with_moment`, the rest of the
tensor held), ``ModelSequences`` + ``build_residual_fn`` + ``optimize`` (MuJoCo's Levenberg-Marquardt)
and ``calculate_intervals`` for the sigma. Two choices are ours, both through sysid's own hooks:

* the residual (``modify_residual``) is the gyro's (measured - predicted) / sigma. sysid's default
  divides each column by that column's own RMS, which gives the two axes that only carry noise
  (pure torsion turns about z alone) the weight of the signal and makes the pooled variance that
  ``calculate_intervals`` scales by meaningless; divided by the noise sigma the residuals are
  N(0, 1) when the model is right, so that variance should be 1 and is reported.
* ``mujoco.rollout`` labels each sensor reading with the time after its step, while MuJoCo computes
  sensors in the forward pass before the step: the prediction labelled t is the gyro at t - h
  (measured against the Kane record: RMS 2.6e-6 rad/s at lag h, 1e-3 at lag h/2 or 3h/2, h = 1e-3 s).
  Unremoved, that lag of one step biases the moment by 3 h / (record length) (least squares takes
  part of a time shift d as a frequency change 1.5 d / length, and d ln I = 2 d ln T): predicted
  and measured 7.5e-4 at h = 2e-3 s over 8 s, ten times the noise's sigma; so the prediction is read
  at t + h. (Started from v(0) with no half-step stagger, the leapfrog's
  velocity ``qvel`` at step k is v(t_k): the lag is exactly one step.)

Windows: least squares on an oscillation has a basin of about a quarter cycle of phase. A moment
wrong by a fraction e moves the period by s e (s = d ln T / d ln I, about 1/2), so n cycles are safe
while n s e < 1/4: 2.5 cycles for e = 0.2. The fit therefore runs on the first :data:`FIRST_WINDOW`
cycles, then on the whole record from there.
"""

from __future__ import annotations

import io
from dataclasses import dataclass, replace

import numpy as np
from mujoco import sysid

from bifilar.identification import identify as ident
from bifilar.motion.simulate import simulate
from bifilar.rig import Rig, RigError
from bifilar.rig.statics import State

from . import mjcf

FIRST_WINDOW = 1.0  # cycles of the guess's linear period (module docstring: safe below 2.5)
# MuJoCo refuses a body whose principal moments break I1 + I2 >= I3; the bounds stay this far inside.
_BOUND_MARGIN = 1e-6  # relative
_RTOL = 1e-10  # Kane integrator: its period error (~1e-10) is far below the fit's sigma (~1e-4)


@dataclass(frozen=True)
class GyroRecord:
    """What a rate gyro on the body recorded after the release."""

    t: np.ndarray  # s, from the release
    rate: np.ndarray  # rad/s, (n, 3), body axes
    noise: float  # rad/s, the white noise's sigma on each axis (the fit's weight)
    state: State  # the release (t = 0), world frame

    def noisy(self, rng: np.random.Generator) -> GyroRecord:
        """The record with white noise of sigma ``noise`` drawn from ``rng`` added to every axis."""
        return replace(self, rate=self.rate + self.noise * rng.standard_normal(self.rate.shape))


def kane_gyro_record(rig: Rig, axis, amplitude: float, cycles: float, rate_hz: float, noise: float) -> GyroRecord:
    """``cycles`` linear periods of the Kane model released at ``amplitude`` (rad) about the body
    ``axis``, sampled at ``rate_hz`` as body-axis angular velocity: the clean record, whose stated
    sigma is ``noise`` (rad/s; :meth:`GyroRecord.noisy` adds it)."""
    start = ident.released(rig, axis, amplitude)
    dt = 1.0 / rate_hz
    run = simulate(start.model, start.state, round(cycles * start.period / dt) * dt, dt_out=dt, rtol=_RTOL)
    if run.slack is not None:
        wire, t = run.slack
        raise RigError(rig.source, "amplitude", f"{amplitude:g} rad: wire[{wire}] goes slack at t = {t:.4g} s")
    body_rate = np.einsum("nji,nj->ni", run.rotation, run.omega)  # R^T omega: world -> body axes
    return GyroRecord(run.t, body_rate, noise, start.state)


@dataclass(frozen=True)
class SysidMoment:
    """MuJoCo sysid's estimate of one moment and the uncertainty it states."""

    moment: float  # kg m^2
    std: float  # kg m^2: sqrt of calculate_intervals' covariance
    interval95: float  # kg m^2: its half-width (Student t)
    residual_variance: float  # of the whitened residuals: 1 when the noise sigma and the model are right
    samples: int  # residuals (gyro samples x 3 axes)


def physical_range(rig: Rig, axis) -> tuple[float, float]:
    """The moments J about ``axis`` (the rest of the tensor held) that make a body MuJoCo accepts:
    positive definite, principal moments obeying the triangle inequality. Physical inertia tensors are
    a convex set and :func:`with_moment` moves along a line, so it is one interval; found by bisection
    from the rig's own moment, then shrunk by :data:`_BOUND_MARGIN`."""

    def physical(value: float) -> bool:
        m = np.linalg.eigvalsh(ident.with_moment(rig, axis, value).inertia)
        return m[0] > 0.0 and m[0] + m[1] >= m[2]

    j0 = ident.moment(rig, axis)
    if not physical(j0):
        raise RigError(rig.source, "body.inertia", "is not a body MuJoCo accepts (triangle inequality)")
    ends = []
    for outside in (0.0, 2.0 * j0 + np.trace(rig.inertia)):  # J = 0 is not positive definite; this breaks the triangle
        inside = j0
        for _ in range(60):
            mid = 0.5 * (inside + outside)
            inside, outside = (mid, outside) if physical(mid) else (inside, mid)
        ends.append(inside)
    span = ends[1] - ends[0]
    return ends[0] + _BOUND_MARGIN * span, ends[1] - _BOUND_MARGIN * span


def fit_moment(rig: Rig, axis, record: GyroRecord, guess: float, timestep: float) -> SysidMoment:
    """Fit the moment about the body ``axis`` of ``rig``'s MuJoCo model (step ``timestep``) to
    ``record`` with mujoco.sysid, starting from ``guess`` (kg m^2); see the module docstring."""
    if rig.air is not None:
        raise RigError(rig.source, "air", "mujoco.sysid recompiles the MJCF, which cannot hold the air's added mass")
    spec = mjcf.build_spec(rig, numerics=mjcf.CHOSEN.with_(timestep=timestep), gyro=True)
    model = spec.compile()
    qpos, qvel = mjcf.state_qpos_qvel(rig, record.state)
    initial = sysid.create_initial_state(model, qpos, qvel)
    low, high = physical_range(rig, axis)
    if not low < guess < high:
        raise RigError(rig.source, "guess", f"{guess:g} kg m^2 is not a body MuJoCo accepts ({low:.6g} to {high:.6g})")

    def write(s, p):
        i = ident.with_moment(rig, axis, float(p.value[0])).inertia
        s.body("body").fullinertia = [i[0, 0], i[1, 1], i[2, 2], i[0, 1], i[0, 2], i[1, 2]]

    def whitened(params, predicted, measured, model, return_pred_all, **_):
        h = model.opt.timestep  # the rollout's one-step sensor lag (module docstring)
        measured = sysid.signal_modifier.apply_time_window(measured, predicted.times[0] - h, predicted.times[-1] - h)
        at = predicted.resample(measured.times + h)
        # sysid compares the two mappings by identity of their arrays: hand back the measured one
        at = sysid.TimeSeries(measured.times, at.data, measured.signal_mapping)
        return (measured.data - at.data) / record.noise, at, measured

    params = sysid.ParameterDict()
    params.add(sysid.Parameter("moment", nominal=guess, min_value=low, max_value=high, modifier=write))
    first = ident.linear_period(ident.with_moment(rig, axis, guess), axis) * FIRST_WINDOW
    for end in (first, record.t[-1]):
        keep = record.t <= end + 1e-9  # s: the last sample's time is a sum of steps, rounded
        t = record.t[keep]
        sequences = sysid.ModelSequences(rig.name, spec, "gyro", initial, sysid.TimeSeries(t, np.zeros((len(t), 0))),
                                         sysid.TimeSeries.from_names(t, record.rate[keep], model))
        residual = sysid.build_residual_fn(models_sequences=[sequences], modify_residual=whitened)
        # The optimizer's own verbosity stays at its default (full): only then does its last log hold
        # the Jacobian at the end point, which calculate_intervals needs; its printout goes to a buffer.
        # mu_factor: at the optimum the Armijo test fails on rounding and the regulariser climbs from
        # 1e-6 to its 1e8 ceiling, one rollout a rung: 14 rungs at 10, 140 at the default 10^0.1.
        params, result = sysid.optimize(params, residual, optimizer="mujoco", verbose=False, output=io.StringIO(),
                                        mu_factor=10.0)
    r_star, _, _ = residual(result.x, params)
    covariance, interval = sysid.calculate_intervals(r_star, result.jac)
    r = np.concatenate(r_star)
    return SysidMoment(float(params["moment"].value[0]), float(np.sqrt(covariance[0, 0])), float(interval[0]),
                       float(r @ r / (r.size - 1)), int(r.size))
