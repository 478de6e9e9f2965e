"""MuJoCo for hinge rigs (:class:`bifilar.rig.hinge.HingeRig`): one body on one ``hinge`` joint, its MJCF
and the ``mujoco`` engine for them.

The model (world z up, gravity along -z; the rest pose of :mod:`validate.engines.hinge`): the body is
placed so that the hinge axis passes through the world origin, along world x for a compound pendulum
(COM straight below it) and along world z for a torsion rod (COM on it, at the origin). The body carries
the rig's mass, COM and full inertia tensor about the COM in body axes; the joint sits at the body-frame
point :func:`~validate.engines.hinge.hinge_origin` with the body-frame axis ``e``. Gravity is on in both:
about a vertical axis through the COM it has no moment, so the torsion rod's only moment is the joint
spring (``stiffness`` = k, ``springref`` 0). MuJoCo forms the moment about the axis from the tensor and
the offset itself (composite inertia), independently of :func:`bifilar.motion.hinge.moment_about_axis`.

Numerics: RK4 at :data:`TIMESTEP`. The model has no constraints, so nothing is soft and the only error
is RK4's truncation: on a harmonic oscillator its frequency is off by (omega h)^4 / 120 relative (the
phase error of its amplification factor, (omega h)^5 / 120 a step), and the pendulum's nonlinearity
changes only the constant. For the shipped wheel (omega ~ 4 rad/s) omega h = 4e-4 at h = 1e-4 s, so
~1e-16: measured, the period at 2 rad agrees with the elliptic integral to 6e-13 at both 1e-3 s and
1e-4 s, the floor of the zero-crossing measurement (:mod:`validate.cases.hinge` checks it). A rig with
omega h above :data:`MAX_OMEGA_STEP` (a period below 2 pi h / 0.01 = 0.063 s) is refused rather than run
less accurately than that: 1e-10 relative at the bound.
"""

from __future__ import annotations

import math
import time
from pathlib import Path

import mujoco
import numpy as np
from scipy.spatial.transform import Rotation

from bifilar.motion.hinge import linear_period, moment_about_axis
from bifilar.motion.simulate import BudgetSpent, output_grid
from bifilar.rig import RigError
from bifilar.rig.hinge import HingeRig

from ..trajectory import Trajectory
from . import mjcf
from .errors import EngineInputError
from .hinge import channels, check_known, hinge_origin, rest_rotation

__all__ = ["TIMESTEP", "build_spec", "compile_model", "run", "write_model_files"]

TIMESTEP = 1e-4  # s
MAX_OMEGA_STEP = 0.01  # rad: RK4's relative frequency error (omega h)^4 / 120 is 1e-10 at this bound
_AXIS_RGBA = (0.45, 0.35, 0.3, 1.0)


def build_spec(rig: HingeRig, timestep: float = TIMESTEP, scene: bool = False) -> mujoco.MjSpec:
    """The rig as an :class:`mujoco.MjSpec` (not compiled), keyframe ``rest`` at angle 0; ``scene`` adds
    floor and light. An unknown moment or stiffness is a :class:`RigError` (:func:`check_known`)."""
    check_known(rig)
    omega_step = 2.0 * math.pi / linear_period(rig) * timestep
    if omega_step > MAX_OMEGA_STEP:
        raise RigError(rig.source, "body.inertia", f"the period {linear_period(rig):.3g} s is too short for MuJoCo's "
                       f"{timestep:g} s step (omega h = {omega_step:.3g} rad, at most {MAX_OMEGA_STEP:g})")
    spec = mujoco.MjSpec()
    spec.modelname = rig.name
    spec.comment = _header(rig, timestep)
    spec.compiler.degree = False
    spec.compiler.autolimits = True
    spec.compiler.savecompiled = False
    spec.compiler.savecanonical = False
    opt = spec.option
    opt.timestep = timestep
    opt.integrator = mujoco.mjtIntegrator.mjINT_RK4
    opt.gravity = [0.0, 0.0, -rig.gravity]
    opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONTACT | mujoco.mjtDisableBit.mjDSBL_ISLAND  # as validate.engines.mjcf

    r0 = rest_rotation(rig)
    origin = hinge_origin(rig)
    body = spec.worldbody.add_body(name="body", pos=-r0 @ origin,
                                   quat=Rotation.from_matrix(r0).as_quat(scalar_first=True))
    body.explicitinertial = True
    body.mass = rig.mass
    body.ipos = rig.com
    i = rig.inertia
    body.fullinertia = [i[0, 0], i[1, 1], i[2, 2], i[0, 1], i[0, 2], i[1, 2]]
    joint = body.add_joint(name="hinge", type=mujoco.mjtJoint.mjJNT_HINGE, pos=origin, axis=rig.axis)
    if rig.kind == "torsion":
        joint.stiffness[0] = rig.stiffness  # linear term of MuJoCo 4's polynomial spring
        joint.springref = 0.0
    size, box_quat = mjcf._inertia_box(rig)
    body.add_geom(name="body", type=mujoco.mjtGeom.mjGEOM_BOX, size=size, pos=rig.com, quat=box_quat,
                  contype=0, conaffinity=0, group=2, rgba=(0.3, 0.45, 0.7, 1.0))
    reach = _reach(rig)
    spec.worldbody.add_geom(name="axis", type=mujoco.mjtGeom.mjGEOM_CYLINDER, contype=0, conaffinity=0,
                            fromto=np.concatenate([-(r0 @ rig.axis), r0 @ rig.axis]) * 0.5 * reach,
                            size=[0.01 * reach, 0.0, 0.0], rgba=_AXIS_RGBA)
    spec.add_key(name="rest", qpos=[0.0], qvel=[0.0])
    if scene:
        _add_scene(spec, reach)
    return spec


def compile_model(rig: HingeRig, timestep: float = TIMESTEP) -> mujoco.MjModel:
    """:func:`build_spec` compiled."""
    return build_spec(rig, timestep).compile()


def run(rig: HingeRig, amplitude: float, duration: float, dt_out: float = 0.01, rtol: float = 1e-10, *,
        timestep: float = TIMESTEP, max_seconds: float | None = None) -> Trajectory:
    """Released from rest at ``amplitude`` (rad), stepped by RK4 for ``duration`` s, sampled every ``dt_out``
    s (a whole number of steps) within ``max_seconds`` of wall time; ``rtol`` is ignored (a fixed step)."""
    model = compile_model(rig, timestep)
    nstep = round(dt_out / timestep)
    if nstep < 1 or abs(nstep * timestep - dt_out) > 1e-9 * dt_out:
        raise EngineInputError("--dt-out", f"{dt_out:g} s is not a whole number of MuJoCo time steps ({timestep:g} s)")
    times = output_grid(duration, dt_out)
    data = mujoco.MjData(model)
    data.qpos[0] = amplitude
    angle, rate = np.empty(len(times)), np.empty(len(times))
    started = time.monotonic()
    for k in range(len(times)):
        if k:
            mujoco.mj_step(model, data, nstep)
        angle[k], rate[k] = data.qpos[0], data.qvel[0]
        if max_seconds is not None and time.monotonic() - started > max_seconds:
            raise BudgetSpent(f"mujoco: wall-time budget of {max_seconds:g} s spent at t = {times[k]:.6g} s")
    meta = {"rig": rig.name, "hinge": rig, "timestep": timestep, "integrator": "RK4"}
    return Trajectory("mujoco", times, channels(rig, angle, rate), meta)


def joint_moment(rig: HingeRig, timestep: float = TIMESTEP) -> float:
    """The moment about the hinge axis (kg m^2) as MuJoCo computes it: its joint-space mass matrix."""
    model = compile_model(rig, timestep)
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    full = np.zeros((1, 1))
    mujoco.mj_fullM(model, data, full)
    return float(full[0, 0])


def write_model_files(rig: HingeRig, directory: str | Path) -> tuple[Path, Path]:
    """Write ``<rig.name>.xml`` and ``scene.xml`` (which includes it and adds floor and light), as
    :func:`validate.engines.mjcf.write_model_files` does for wire rigs."""
    return mjcf.write_xml_pair(build_spec(rig), f"{rig.name}.xml", lambda s: _add_scene(s, _reach(rig)), directory)


def _reach(rig: HingeRig) -> float:
    """How far the body's drawing box reaches from the hinge axis, at most (m): sizes the drawing."""
    size, _ = mjcf._inertia_box(rig)
    return float(np.linalg.norm(size)) + float(np.linalg.norm(rig.com - hinge_origin(rig)))


def _add_scene(spec: mujoco.MjSpec, reach: float) -> None:
    """A floor ``reach`` below the lowest point the body can reach, and a light: drawing only."""
    spec.worldbody.add_geom(name="floor", type=mujoco.mjtGeom.mjGEOM_PLANE, pos=[0.0, 0.0, -2.0 * reach],
                            size=[0.0, 0.0, 0.05], rgba=[0.2, 0.3, 0.4, 1.0])
    spec.worldbody.add_light(name="top", pos=[0.0, 0.0, 2.0 * reach], dir=[0.0, 0.0, -1.0],
                             type=mujoco.mjtLightType.mjLIGHT_DIRECTIONAL)
    spec.stat.center = [0.0, 0.0, -0.5 * reach]
    spec.stat.extent = 2.0 * reach


def _header(rig: HingeRig, timestep: float) -> str:
    """The file's opening comment: where every number comes from."""
    def vec(x) -> str:
        return "[" + ", ".join(repr(float(v)) for v in x) + "]"

    kind = ("compound pendulum: hinge axis along world x through the origin, COM straight below it at rest"
            if rig.kind == "pivot" else
            f"torsion pendulum: rod axis along world z through the COM, joint stiffness {rig.stiffness!r} N m/rad")
    lines = [
        f"Hinge rig '{rig.name}' from {rig.source}, written by validate/engines/mujoco_hinge.py.",
        f"Units SI, angles radian; world z up, gravity {rig.gravity:g} m/s^2 along -z.",
        f"{kind}.",
        f"body: {rig.mass:g} kg, COM {vec(rig.com)} m (body frame), fullinertia about the COM (body axes);",
        f"  joint 'hinge' at {vec(hinge_origin(rig))} m, axis {vec(rig.axis)} (body frame); moment about it "
        f"{moment_about_axis(rig)!r} kg m^2.",
        f"Numerics: RK4 at {timestep:g} s (no constraints: only RK4's truncation error, see the module).",
        "Body geom: the uniform box with the body's mass and inertia, for drawing only (no contact).",
    ]
    return "\n" + "\n".join("  " + line for line in lines) + "\n"
