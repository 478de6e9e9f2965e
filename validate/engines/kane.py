"""The hand-derived Kane-Tseng model as an engine (:mod:`bifilar.simulate`)."""

from __future__ import annotations

from scipy.spatial.transform import Rotation

from bifilar.motion.kane import KaneModel
from bifilar.rig import Rig
from bifilar.motion.simulate import Budget, KaneRun, simulate
from bifilar.rig.statics import State, initial_state

from ..trajectory import Trajectory, rig_quaternions


def run(rig: Rig, duration: float, dt_out: float = 0.01, rtol: float = 1e-10, state: State | None = None, *,
        max_seconds: float | None = None) -> Trajectory:
    """Integrate from ``state`` (default: the rig's initial state) within the default work budget and
    ``max_seconds`` of wall time; see :func:`bifilar.motion.simulate.simulate`."""
    model = KaneModel.from_rig(rig)
    start = initial_state(rig) if state is None else state
    run = simulate(model, start, duration, dt_out=dt_out, rtol=rtol, budget=Budget(seconds=max_seconds))
    return to_trajectory(run, rig, rtol)


def to_trajectory(kr: KaneRun, rig: Rig, rtol: float) -> Trajectory:
    quat = rig_quaternions(Rotation.from_matrix(kr.rotation))
    channels = {
        "com": kr.com,
        "quat": quat,
        "tension": kr.tension,
        "length_error": kr.length_error,
        "velocity": kr.velocity,
        "omega": kr.omega,
        "energy": kr.energy,
        "theta": kr.theta,
    }
    # taut_failure: (wire, time) where a wire went slack and the taut-wire model stopped, else None.
    meta = {"rig": rig.name, "rig_spec": rig, "rtol": rtol, "nfev": kr.nfev, "taut_failure": kr.slack}
    return Trajectory("kane", kr.t, channels, meta)
