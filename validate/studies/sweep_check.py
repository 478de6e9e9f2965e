"""The sweep's recommendation cross-validated by the independent engine: the best configurations run
in MuJoCo (tendon cables, the settings of ``models/README.md``), each measured mode excited alone.

Each measured mode (the one timed for a moment) starts at the rest pose with the velocity of its
linear shape at an amplitude of 1e-3 rad (the period's own amplitude shift is ~A^2/16 = 6e-8, below
1e-7), runs for five periods and its period is timed from the MuJoCo motion by refined crossings of
the coordinate that moves most. MuJoCo's own period error at the chosen settings is ~3e-10; the
threshold 1e-6 is the issue's. The mean tension over the run is compared with the static tension (the
motion adds ~A^2 of it: 1e-6).

All the runs of all the configurations are stepped together by ``mujoco.rollout`` on every core
(:func:`validate.engines.mujoco_rig.run_batch`); ``batched=False`` runs them one by one with
:func:`validate.engines.mujoco_rig.run`, the reference the batched runs are tested against.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from bifilar.identification import identify as ident
from bifilar.motion.modes import Mode, excite, linearize
from bifilar.rig.statics import Rest, rest_pose
from bifilar.sweep.axes import configure
from bifilar.sweep.evaluate import measured_mode
from bifilar.sweep.space import Space

from ..engines import mujoco_rig
from ..engines.mjcf import CHOSEN
from ..metrics import period
from ..trajectory import Trajectory

AMPLITUDE = 1e-3  # rad
CYCLES = 5  # the run starts on a crossing (at rest), which the timing cannot use
TOLERANCE = 1e-6  # relative period and tension agreement that the command requires


@dataclass(frozen=True)
class Checked:
    """One configuration checked: its ``summary.json`` entry and the MuJoCo run of each measured axis."""

    entry: dict
    runs: dict[str, Trajectory]  # measured axis -> the MuJoCo motion of its mode


@dataclass(frozen=True)
class _Planned:
    axis: str
    mode: Mode
    rest: Rest
    run: mujoco_rig.BatchRun


def check(space: Space, configurations: list[dict], *, batched: bool = True) -> list[Checked]:
    """MuJoCo against the sweep's prediction for each configuration (axis values) of ``configurations``."""
    plans = [_plan(space, values) for values in configurations]
    todo = [p.run for plan in plans for p in plan]
    runs = mujoco_rig.run_batch(todo) if batched else [mujoco_rig.run(r.rig, r.duration, r.dt_out, state=r.state)
                                                        for r in todo]
    out, start = [], 0
    for values, plan in zip(configurations, plans):
        trajs = runs[start : start + len(plan)]
        start += len(plan)
        out.append(_compare(values, plan, trajs))
    return out


def _plan(space: Space, values: dict) -> list[_Planned]:
    """The run of each measured mode of one configuration."""
    rig = configure(space.rig, values)
    rest = rest_pose(rig)
    lin = linearize(rig, rest)
    plan = []
    for axis in space.measure:
        index = measured_mode(rig, lin, rest.rotation @ ident.axis_vector(axis))
        mode = lin.modes[index]
        step = CHOSEN.timestep
        dt_out = max(1, round(mode.period / 200 / step)) * step  # a whole number of MuJoCo steps
        run = mujoco_rig.BatchRun(rig, CYCLES * mode.period, dt_out, excite(lin, index, AMPLITUDE))
        plan.append(_Planned(axis, mode, rest, run))
    return plan


def _compare(values: dict, plan: list[_Planned], trajs: list[Trajectory]) -> Checked:
    modes = []
    worst = 0.0
    for p, traj in zip(plan, trajs):
        motion = np.column_stack([traj["com"] - p.rest.com,
                                  Rotation.from_quat(traj["quat"], scalar_first=True).as_rotvec()])
        measured = period(traj.t, motion[:, int(np.argmax(motion.std(axis=0)))]).value
        err = measured / p.mode.period - 1.0
        tension = float(np.max(np.abs(traj["tension"].mean(axis=0) / p.rest.tensions - 1.0)))
        worst = max(worst, abs(err), tension)
        modes.append({"axis": p.axis, "motion": p.mode.motion, "predicted": p.mode.period, "mujoco": measured,
                      "period_rel_error": err, "tension_rel_error": tension})
    entry = {"configuration": values, "modes": modes,
             "period_rel_error": max(abs(m["period_rel_error"]) for m in modes), "ok": worst <= TOLERANCE}
    return Checked(entry, {p.axis: traj for p, traj in zip(plan, trajs)})
