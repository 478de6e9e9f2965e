"""Engines: each turns a rig into an engine-neutral :class:`~validate.trajectory.Trajectory`.

Every engine starts from :func:`bifilar.rig.statics.initial_state` (the rig file's ``[initial]``
semantics) and returns the rig channels of :data:`validate.trajectory.RIG_CHANNELS` plus
``velocity`` and ``omega`` (world frame) and ``energy`` (J, zero potential at z = 0). ``meta`` holds
``rig`` (name) and ``rig_spec`` (the :class:`~bifilar.rig.Rig`, for drawing); an engine whose model
cannot continue past a slack wire sets ``taut_failure = (wire, time)``.
An engine is ``run(rig, duration, dt_out, rtol, state=None, *, max_seconds=None) -> Trajectory``;
``rtol`` is the integrator's relative tolerance where the engine has one and is ignored otherwise;
``state`` (a :class:`bifilar.rig.statics.State`) replaces the rig's initial state when a case needs
another one; ``max_seconds`` bounds the wall time (every engine also has a work budget of its own),
and a spent budget raises :class:`bifilar.motion.simulate.BudgetSpent`.
"""

from __future__ import annotations

from typing import Callable

from bifilar.rig import Rig

from ..trajectory import Trajectory
from .errors import EngineInputError

__all__ = ["NAMES", "EngineInputError", "EngineRun", "engines"]

EngineRun = Callable[[Rig, float, float, float], Trajectory]

NAMES = ("kane", "nwire", "mujoco", "mujoco-eq", "mujoco-cable")  # the keys of engines(), known without importing them


def engines() -> dict[str, EngineRun]:
    """Engine name -> run function (imported lazily so that one engine's import cost is paid only
    when it is used)."""
    from . import kane, mujoco_cable, mujoco_rig, nwire

    return {"kane": kane.run, "nwire": nwire.run, **mujoco_rig.ENGINES, "mujoco-cable": mujoco_cable.run}
