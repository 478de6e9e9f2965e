"""The hand-derived N-wire model as an engine (:mod:`bifilar.motion.nwire`): any number of wires."""

from __future__ import annotations

from scipy.spatial.transform import Rotation

from bifilar.motion.nwire import NWireModel, simulate
from bifilar.motion.simulate import Budget
from bifilar.rig import Rig
from bifilar.rig.statics import State, initial_state

from ..trajectory import Trajectory, rig_quaternions


def run(rig: Rig, duration: float, dt_out: float = 0.01, rtol: float = 1e-10, state: State | None = None,
        engine: str = "nwire", *, max_seconds: float | None = None) -> Trajectory:
    """Integrate from ``state`` (default: the rig's initial state) within the default work budget and
    ``max_seconds`` of wall time; see :func:`bifilar.motion.nwire.simulate`."""
    start = initial_state(rig) if state is None else state
    nr = simulate(NWireModel.from_rig(rig), start, duration, dt_out=dt_out, rtol=rtol, budget=Budget(seconds=max_seconds))
    channels = {
        "com": nr.com,
        "quat": rig_quaternions(Rotation.from_matrix(nr.rotation)),
        "tension": nr.tension,
        "length_error": nr.length_error,
        "velocity": nr.velocity,
        "omega": nr.omega,
        "energy": nr.energy,
    }
    # taut_failure: (wire, time) where a wire went slack and the taut-wire model stopped, else None.
    meta = {"rig": rig.name, "rig_spec": rig, "rtol": rtol, "nfev": nr.nfev, "taut_failure": nr.slack,
            "model": "nwire"}
    return Trajectory(engine, nr.t, channels, meta)
