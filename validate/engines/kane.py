"""The hand-derived models as the ``kane`` engine: Kane-Tseng (:mod:`bifilar.motion.simulate`) for two
wires, the N-wire model (:mod:`bifilar.motion.nwire`) for three or more and for elastic wires."""

from __future__ import annotations

from scipy.spatial.transform import Rotation

from bifilar.motion.kane import KaneModel
from bifilar.rig import Rig
from bifilar.motion.simulate import Budget, KaneRun, simulate
from bifilar.rig.statics import State, initial_state

from ..trajectory import Trajectory, rig_quaternions
from . import nwire


def run(rig: Rig, duration: float, dt_out: float = 0.01, rtol: float = 1e-10, state: State | None = None, *,
        max_seconds: float | None = None) -> Trajectory:
    """Integrate from ``state`` (default: the rig's initial state) within the default work budget and
    ``max_seconds`` of wall time; see :func:`bifilar.motion.simulate.simulate` (two wires) and
    :func:`bifilar.motion.nwire.simulate` (more)."""
    if len(rig.wires) != 2 or rig.elastic:  # Kane-Tseng's five angles hold two inextensible wires
        return nwire.run(rig, duration, dt_out, rtol, state, engine="kane", max_seconds=max_seconds)
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
