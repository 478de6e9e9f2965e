"""The sweep's recommendation cross-validated by the independent engine: the best configurations run
in MuJoCo (tendon cables, the settings of ``models/README.md``), each measured mode excited alone.

Each measured mode (the one timed for a moment) starts at the rest pose with the velocity of its
linear shape at an amplitude of 1e-3 rad (the period's own amplitude shift is ~A^2/16 = 6e-8, below
1e-7), runs for five periods and its period is timed from the MuJoCo motion by refined crossings of
the coordinate that moves most. MuJoCo's own period error at the chosen settings is ~3e-10; the
threshold 1e-6 is the issue's. The mean tension over the run is compared with the static tension (the
motion adds ~A^2 of it: 1e-6).
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from bifilar.identification import identify as ident
from bifilar.motion.modes import excite, linearize
from bifilar.rig.statics import rest_pose
from bifilar.sweep.axes import configure
from bifilar.sweep.evaluate import measured_mode
from bifilar.sweep.space import Space

from ..engines import mujoco_rig
from ..engines.mjcf import CHOSEN
from ..metrics import period

AMPLITUDE = 1e-3  # rad
CYCLES = 5  # the run starts on a crossing (at rest), which the timing cannot use
TOLERANCE = 1e-6  # relative period and tension agreement that the command requires


def check(space: Space, values: dict) -> dict:
    """MuJoCo against the sweep's prediction for one configuration."""
    rig = configure(space.rig, values)
    rest = rest_pose(rig)
    lin = linearize(rig, rest)
    modes = []
    worst = 0.0
    for axis in space.measure:
        index = measured_mode(rig, lin, rest.rotation @ ident.axis_vector(axis))
        mode = lin.modes[index]
        step = CHOSEN.timestep
        dt_out = max(1, round(mode.period / 200 / step)) * step  # a whole number of MuJoCo steps
        traj = mujoco_rig.run(rig, CYCLES * mode.period, dt_out, state=excite(lin, index, AMPLITUDE))
        motion = np.column_stack([traj["com"] - rest.com, Rotation.from_quat(traj["quat"], scalar_first=True).as_rotvec()])
        measured = period(traj.t, motion[:, int(np.argmax(motion.std(axis=0)))]).value
        err = measured / mode.period - 1.0
        tension = float(np.max(np.abs(traj["tension"].mean(axis=0) / rest.tensions - 1.0)))
        worst = max(worst, abs(err), tension)
        modes.append({"axis": axis, "motion": mode.motion, "predicted": mode.period, "mujoco": measured,
                      "period_rel_error": err, "tension_rel_error": tension})
    return {"configuration": values, "modes": modes,
            "period_rel_error": max(abs(m["period_rel_error"]) for m in modes), "ok": worst <= TOLERANCE}
