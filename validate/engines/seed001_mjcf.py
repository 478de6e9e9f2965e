"""The MuJoCo model of seed 001's pendulum, built with MjSpec from ``models/seed001/seed001.xml`` and a
:class:`~bifilar.seeds.seed001.params.Params`.

The XML gives the structure (bodies, hinges, drawing); every physical number is set here from the
parameters, so one XML serves every variant (e.g. the special case r_m2 = 0). World frame: x is the
seed's x, z the seed's y (up), and the seed's counter-clockwise angles turn about -y.
"""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np

from bifilar.seeds.seed001.params import Params

PLATE_THICKNESS = 0.004  # m, drawing only


def plate_inertia(mass: float, length: float, width: float) -> np.ndarray:
    """Principal inertias (kg m^2) of a uniform plate in the world x-z plane, along the body x (the
    arm), y (the hinge axis) and z: m b^2/12, m (a^2 + b^2)/12, m a^2/12. The middle one is summed
    from the others so that MuJoCo's check A + B >= C holds despite rounding (a plate is the limit)."""
    along, across = mass * width**2 / 12.0, mass * length**2 / 12.0
    return np.array([along, along + across, across])


def build_spec(xml: str | Path, p: Params, timestep: float = 1e-3) -> mujoco.MjSpec:
    """The model of ``xml`` with the masses, inertias, positions, gravity, step (s) and initial
    keyframe of ``p``."""
    spec = mujoco.MjSpec.from_file(str(xml))
    spec.option.gravity = [0.0, 0.0, -p.g]
    spec.option.timestep = timestep
    axis_position = {"arm1": [0.0, 0.0, 0.0], "arm2": [-p.r1, -p.gap, 0.0]}
    for part in p.bodies():
        body = spec.body(part.name)
        body.mass = part.mass
        body.ipos = [0.0, 0.0, 0.0]
        if part.size:  # a plate centred on its axis
            body.pos = axis_position[part.name]
            body.inertia = plate_inertia(part.mass, *part.size)
            body.first_geom().size = [part.size[0] / 2, PLATE_THICKNESS / 2, part.size[1] / 2]
        else:  # a point mass at ``offset`` along its arm
            body.pos = [part.offset, 0.0, 0.0]
            body.inertia = [0.0, 0.0, 0.0]
    key = spec.key("initial")
    key.qpos = list(p.q0)
    key.qvel = list(p.qd0)
    return spec


def build_model(xml: str | Path, p: Params, timestep: float = 1e-3) -> mujoco.MjModel:
    """:func:`build_spec` compiled."""
    return build_spec(xml, p, timestep).compile()
