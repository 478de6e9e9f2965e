"""The MuJoCo counterpart of a TMT chain (:mod:`bifilar.seeds.tmt`): the model, and the quantities to compare.

:func:`chain_spec` turns a chain into an :class:`mujoco.MjSpec` with one MuJoCo body per TMT body,
its frame at the body's COM with the TMT body axes (so that ``xpos``/``xmat`` are the seed's ``x^i``
and ``R^i``), and one hinge per coordinate, so that ``qpos`` is the TMT's ``q``. A body's relative
frames between its parent body and itself, ``A R_a(q) C`` with ``A`` and ``C`` constant, are
``(A C) (C^-1 R_a(q) C)``: the body sits at ``A C`` for q = 0, and ``C^-1 R_a(q) C`` is a rotation
by q about the axis ``R_C^T a`` through the point ``-R_C^T t_C``, both in the body's own frame, which
is how MuJoCo places a hinge. Several hinges in one body compose the same way, in chain order.

The per-body loads: MuJoCo works in reduced coordinates, so a hinge's reaction is neither an
``efc_force`` (there are no constraint rows) nor a ``qfrc_constraint``. It appears in
``cfrc_int`` after :func:`mujoco.mj_rnePostConstraint`: ``cfrc_int[b]`` is the spatial force
(torque, force) that body b's parent exerts on b's subtree, world axes, torque about the COM of b's
whole kinematic tree ``subtree_com[body_rootid[b]]``, and it equals the subtree's sum of
``I (a - g) + v x* I v``. So ``cfrc_int[b] - sum over children c of cfrc_int[c]`` is body b's own
``m (a - g)`` and its rate of angular momentum, referred to that point; :func:`body_loads` moves the
torque to b's COM, adds gravity back and rotates the moment into body axes, which gives the seed's
per-body resultants of :meth:`bifilar.seeds.tmt.Chain.body_loads`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import mujoco
import numpy as np

from bifilar.seeds.tmt import Chain


def chain_spec(chain: Chain, joint_names: Sequence[str] | None = None, model_name: str = "chain") -> mujoco.MjSpec:
    """An MjSpec of the chain: bodies named as the TMT bodies, hinges named ``joint_names`` (default
    ``q0, q1, ...``), gravity from the chain, energy computation on; no geoms, no damping, no armature."""
    names = list(joint_names) if joint_names is not None else [f"q{k}" for k in range(chain.n)]
    order = [f.coordinate for f in chain.frames if f.coordinate is not None]
    if order != list(range(chain.n)):
        raise ValueError(f"MuJoCo numbers dofs in chain order; the coordinates run {order}")
    spec = mujoco.MjSpec()
    spec.modelname = model_name
    spec.compiler.degree = False
    spec.option.gravity = chain.gravity
    spec.option.enableflags |= mujoco.mjtEnableBit.mjENBL_ENERGY  # fills data.energy
    parent = spec.worldbody
    T = np.eye(4)  # parent body frame -> current frame, at q = 0
    hinges = []  # [coordinate, axis in the rotating frame, frames from there to here at q = 0]
    for frame in chain.frames:
        E0 = frame.matrix(frame.angle if frame.coordinate is None else 0.0)
        T = T @ E0
        for h in hinges:
            h[2] = h[2] @ E0
        if frame.coordinate is not None:
            axis = np.asarray(frame.axis, dtype=float)
            hinges.append([frame.coordinate, axis / np.linalg.norm(axis), np.eye(4)])
        if frame.body is None:
            continue
        quat = np.empty(4)
        mujoco.mju_mat2Quat(quat, T[:3, :3].ravel())
        body = parent.add_body(name=frame.body.name, pos=T[:3, 3], quat=quat)
        J = np.asarray(frame.body.inertia, dtype=float)
        body.mass = frame.body.mass
        body.ipos = [0.0, 0.0, 0.0]
        body.fullinertia = [J[0, 0], J[1, 1], J[2, 2], J[0, 1], J[0, 2], J[1, 2]]
        body.explicitinertial = True
        for k, axis, C in hinges:
            Rc_t = C[:3, :3].T
            body.add_joint(name=names[k], type=mujoco.mjtJoint.mjJNT_HINGE, axis=Rc_t @ axis, pos=-Rc_t @ C[:3, 3])
        parent, T, hinges = body, np.eye(4), []
    return spec


def set_state(model: mujoco.MjModel, data: mujoco.MjData, q, qd) -> None:
    """Set qpos, qvel and run the forward dynamics (qacc from MuJoCo's own equations)."""
    data.qpos[:] = q
    data.qvel[:] = qd
    mujoco.mj_forward(model, data)


def mass_and_bias(model: mujoco.MjModel, data: mujoco.MjData, q, qd) -> tuple[np.ndarray, np.ndarray]:
    """MuJoCo's joint-space mass matrix (``mj_fullM``) and ``qfrc_bias`` (Coriolis, centrifugal and
    gravity, so that ``M qacc + qfrc_bias = 0`` in free motion) at the state."""
    set_state(model, data, q, qd)
    M = np.zeros((model.nv, model.nv))
    mujoco.mj_fullM(model, data, M)
    return M, data.qfrc_bias.copy()


def body_loads(
    model: mujoco.MjModel, data: mujoco.MjData, q, qd, names: Sequence[str]
) -> tuple[np.ndarray, np.ndarray]:
    """Per named body, at MuJoCo's own acceleration for the state: the net force (world frame, N,
    gravity included) and the net moment about the body's COM (body axes, N m); see the module
    docstring. Shapes (len(names), 3)."""
    set_state(model, data, q, qd)
    mujoco.mj_rnePostConstraint(model, data)
    forces, moments = np.empty((len(names), 3)), np.empty((len(names), 3))
    for i, name in enumerate(names):
        b = model.body(name).id
        children = np.flatnonzero(model.body_parentid == b)
        children = children[children != b]
        own = data.cfrc_int[b] - data.cfrc_int[children].sum(axis=0)  # (torque about P, m (a - g))
        ref = data.subtree_com[model.body_rootid[b]]
        torque_com = own[:3] + np.cross(ref - data.xipos[b], own[3:])
        forces[i] = own[3:] + model.body_mass[b] * model.opt.gravity
        moments[i] = data.xmat[b].reshape(3, 3).T @ torque_com
    return forces, moments


@dataclass(frozen=True)
class Run:
    """A sampled MuJoCo run: times (s), qpos (rad), qvel (rad/s), energy (J, MuJoCo's potential +
    kinetic, zero potential at the world origin)."""

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    energy: np.ndarray


def simulate(model: mujoco.MjModel, q0, qd0, duration: float, dt_out: float) -> Run:
    """Step the model from (q0, qd0) with its own integrator and timestep, sampling every ``dt_out``
    seconds (a whole number of steps); raise if MuJoCo reports any warning."""
    steps_per_sample = round(dt_out / model.opt.timestep)
    if abs(steps_per_sample * model.opt.timestep - dt_out) > 1e-12 * dt_out:
        raise ValueError(f"dt_out = {dt_out} s is not a whole number of timesteps ({model.opt.timestep} s)")
    n_out = int(np.floor(duration / dt_out + 1e-9)) + 1
    if not model.opt.enableflags & mujoco.mjtEnableBit.mjENBL_ENERGY:
        raise ValueError("the model must enable the energy flag")
    data = mujoco.MjData(model)
    q, qd, energy = np.empty((n_out, model.nq)), np.empty((n_out, model.nv)), np.empty(n_out)
    set_state(model, data, q0, qd0)
    for i in range(n_out):
        if i:
            for _ in range(steps_per_sample):
                mujoco.mj_step(model, data)
            mujoco.mj_forward(model, data)  # energy of the sampled state, not of the last step's start
        q[i], qd[i], energy[i] = data.qpos, data.qvel, data.energy.sum()
    warnings = [w.number for w in data.warning]
    if any(warnings):
        raise RuntimeError(f"MuJoCo warnings during the run: {warnings}")
    return Run(np.arange(n_out) * dt_out, q, qd, energy)
