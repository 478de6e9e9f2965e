"""Hinge rigs (:class:`bifilar.rig.hinge.HingeRig`) as engine runs: where the body rests in the world, its
pose at a hinge angle, and the hand-derived 1-DOF engine ``kane`` (:func:`bifilar.motion.hinge.simulate`).

World frame: z up, gravity along -z, the hinge axis through the world origin. At rest

* a compound pendulum (``pivot``) has its axis along world x and its COM straight below the axis, at
  (0, 0, -d), d the arm: the body frame's perpendicular from the axis to the COM is turned onto -z;
* a torsion pendulum (``torsion``) has its rod axis along world z and its COM at the origin (the shortest
  rotation that takes the body-frame axis onto +z).

The hinge angle theta turns the body about that world axis from rest (right hand), as MuJoCo's hinge
joint does: R(theta) = Rot(a, theta) R0, a = R0 e. Every engine for hinge rigs (this one and
:mod:`validate.engines.mujoco_hinge`) returns a :class:`~validate.trajectory.Trajectory` with the
channels of :data:`validate.trajectory.HINGE_CHANNELS` (``com``, ``quat``, ``angle``, ``rate``) and
``energy`` (J, zero potential at z = 0), ``meta`` holding ``rig`` (name) and ``hinge`` (the rig).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.spatial.transform import Rotation

from bifilar.motion.hinge import moment_about_axis, restoring, simulate
from bifilar.rig import RigError
from bifilar.rig.hinge import HingeRig

from ..trajectory import Trajectory, rig_quaternions

__all__ = ["check_known", "rest_rotation", "hinge_origin", "channels", "run"]


def check_known(rig: HingeRig) -> None:
    """A :class:`RigError` unless the motion is fully given: the moment about the axis (not ``nan``) and,
    for a torsion rig, the rod's stiffness."""
    if math.isnan(moment_about_axis(rig)):
        raise RigError(rig.source, "body.inertia", "the moment about the hinge axis is unknown (nan): it is what "
                       "a timed period measures (python -m validate identify); give a value to simulate or model the rig")
    restoring(rig)  # raises on a torsion rod without a stiffness


def rest_rotation(rig: HingeRig) -> np.ndarray:
    """R0 (3x3, body -> world) of the rest pose (module docstring)."""
    e = rig.axis
    if rig.kind == "torsion":
        rot, _ = Rotation.align_vectors([[0.0, 0.0, 1.0]], [e])
        return rot.as_matrix()
    r = rig.com - rig.point
    down = r - (r @ e) * e  # body frame: from the axis to the COM, perpendicular to the axis; world -z at rest
    up = -down / np.linalg.norm(down)
    # Body-frame images of world x, y, z as rows: R0 maps e -> x, (up x e) -> y, up -> z.
    return np.array([e, np.cross(up, e), up])


def hinge_origin(rig: HingeRig) -> np.ndarray:
    """The body-frame point of the axis held at the world origin (m): the foot of the perpendicular from
    the COM on a pivot axis, the COM on a torsion rod."""
    if rig.kind == "torsion":
        return rig.com.copy()
    r = rig.com - rig.point
    return rig.point + (r @ rig.axis) * rig.axis


def channels(rig: HingeRig, angle: np.ndarray, rate: np.ndarray) -> dict[str, np.ndarray]:
    """The trajectory channels at hinge angles ``angle`` (rad) and rates ``rate`` (rad/s): COM (world, m),
    quaternion (wxyz, body -> world), the angle, the rate and the energy (J)."""
    angle = np.asarray(angle, dtype=float)
    r0 = rest_rotation(rig)
    world_axis = r0 @ rig.axis
    rot = Rotation.from_rotvec(angle[:, None] * world_axis) * Rotation.from_matrix(r0)
    com = rot.apply(rig.com - hinge_origin(rig))
    energy = 0.5 * moment_about_axis(rig) * rate**2 + rig.mass * rig.gravity * com[:, 2]
    if rig.kind == "torsion":
        energy = energy + 0.5 * rig.stiffness * angle**2
    return {"com": com, "quat": rig_quaternions(rot), "angle": angle, "rate": np.asarray(rate, dtype=float),
            "energy": energy}


def run(rig: HingeRig, amplitude: float, duration: float, dt_out: float = 0.01, rtol: float = 1e-10) -> Trajectory:
    """The ``kane`` engine for a hinge rig: the exact 1-DOF equation of motion from rest at ``amplitude``
    (rad), integrated by DOP853 at ``rtol`` (:func:`bifilar.motion.hinge.simulate`), every ``dt_out`` s."""
    check_known(rig)
    t, angle, rate = simulate(rig, amplitude, duration, dt_out, rtol=rtol)
    return Trajectory("kane", t, channels(rig, angle, rate), {"rig": rig.name, "hinge": rig, "rtol": rtol})
