"""Seed 001's pendulum run in MuJoCo, with the seed's friction added as generalized forces.

Why not MuJoCo's joint damping: damping is the Rayleigh function (1/2) sum_i b_i q_i'^2, a constant
diagonal matrix acting on each joint's own relative rate. The seed's F = k1 E1k + k2 E2k is a drag
-k v on every mass element, v its absolute velocity: its matrix R(q) = k1 M_arm1 + k2 M_arm2(q)
depends on phi2 and couples the joints (R12 = k2 (2C - B cos phi2)); arm2 is dragged when only phi1
turns. No choice of b_i reproduces that. :class:`Friction` builds the drag from MuJoCo's own mass
matrix and body Jacobians, independently of the seed's algebra.

Where it enters: ``qfrc_applied`` is an input that MuJoCo holds fixed over a step, all four RK4
stages included, so setting it once per step is a first-order hold whose error is O(k dt): 7e-4 rad
after 1 s with dt = 1 ms (docs/seed001.md), larger than everything else we compare. The friction is
therefore added to ``qfrc_passive`` by MuJoCo's passive-force callback, which MuJoCo calls at every
RK4 stage with that stage's state; :func:`simulate` installs it for the run only and restores the
previous one. ``per_step=True`` keeps the held ``qfrc_applied`` to measure that hold.
"""

from __future__ import annotations

from contextlib import contextmanager
from dataclasses import dataclass

import mujoco
import numpy as np

from bifilar.seeds.seed001.integrate import grid, steps_per_sample
from bifilar.seeds.seed001.params import Params


class Friction:
    """The seed's friction torques -dF/dq' = -(k1 M_arm1 + k2 M_arm2) q' (N m) on MuJoCo's state.

    M_arm2 = M - M_arm1 with M MuJoCo's mass matrix (current once the position stage has run), and
    M_arm1 = sum over arm 1's bodies of Jp^T m Jp + Jr^T I Jr at their COMs, built once: arm 1's
    parts move with phi1 alone, so their share of M does not depend on the state.
    """

    def __init__(self, model: mujoco.MjModel, p: Params):
        self.k1, self.k2 = p.k1, p.k2
        data = mujoco.MjData(model)
        mujoco.mj_forward(model, data)
        jacp, jacr = np.zeros((3, model.nv)), np.zeros((3, model.nv))
        self._m_arm1 = np.zeros((model.nv, model.nv))
        for part in p.bodies():
            if part.arm == 1:
                body = model.body(part.name).id
                mujoco.mj_jacBodyCom(model, data, jacp, jacr, body)
                rot = data.ximat[body].reshape(3, 3)
                inertia = rot @ np.diag(model.body_inertia[body]) @ rot.T  # world frame, about the COM
                self._m_arm1 += model.body_mass[body] * jacp.T @ jacp + jacr.T @ inertia @ jacr
        self._mqd = np.zeros(model.nv)

    @property
    def active(self) -> bool:
        return self.k1 != 0.0 or self.k2 != 0.0

    def __call__(self, model: mujoco.MjModel, data: mujoco.MjData) -> np.ndarray:
        mujoco.mj_mulM(model, data, self._mqd, data.qvel)
        return -self.k2 * self._mqd - (self.k1 - self.k2) * (self._m_arm1 @ data.qvel)


@contextmanager
def _passive_callback(callback):
    previous = mujoco.get_mjcb_passive()
    mujoco.set_mjcb_passive(callback)
    try:
        yield
    finally:
        mujoco.set_mjcb_passive(previous)


@dataclass(frozen=True)
class MujocoRun:
    """Samples at t (s): q (rad, (n, 2)), qd (rad/s, (n, 2)), energy (J, MuJoCo's kinetic plus
    potential, zero potential at the inner axis's height) and power (W, the friction's, <= 0)."""

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    energy: np.ndarray
    power: np.ndarray


def simulate(model: mujoco.MjModel, p: Params, duration: float, dt_out: float, per_step: bool = False) -> MujocoRun:
    """Step ``model`` (its own integrator and step) from ``p``'s initial state with ``p``'s friction,
    sampling every ``dt_out`` (s, a whole number of steps). ``per_step`` holds the friction over
    each step in ``qfrc_applied`` instead of evaluating it at every stage."""
    every = steps_per_sample(model.opt.timestep, dt_out)
    t = grid(duration, dt_out)
    n = len(t) - 1
    data = mujoco.MjData(model)
    data.qpos[:], data.qvel[:] = p.q0, p.qd0
    friction = Friction(model, p)

    def add_friction(m: mujoco.MjModel, d: mujoco.MjData) -> None:
        d.qfrc_passive[:] += friction(m, d)

    q, qd = np.empty((n + 1, model.nv)), np.empty((n + 1, model.nv))
    energy, power = np.empty(n + 1), np.empty(n + 1)
    with _passive_callback(add_friction if friction.active and not per_step else None):
        for i in range(n + 1):
            for _ in range(every if i else 0):
                if per_step and friction.active:
                    mujoco.mj_forward(model, data)  # the mass matrix of the current state
                    data.qfrc_applied[:] = friction(model, data)
                mujoco.mj_step(model, data)
            mujoco.mj_forward(model, data)
            q[i], qd[i] = data.qpos, data.qvel
            energy[i], power[i] = data.energy.sum(), friction(model, data) @ data.qvel
    return MujocoRun(t, q, qd, energy, power)


@dataclass(frozen=True)
class Probe:
    """MuJoCo's dynamics at one state: mass matrix (mj_fullM, kg m^2), bias forces (qfrc_bias, N m),
    the seed's friction torques (N m), the accelerations they all give (qacc, rad/s^2) and the
    potential energy (J, zero at the inner axis's height)."""

    mass: np.ndarray
    bias: np.ndarray
    friction: np.ndarray
    qacc: np.ndarray
    potential: float


class Prober:
    """Evaluates :class:`Probe` at given states of ``model`` with ``p``'s friction coefficients."""

    def __init__(self, model: mujoco.MjModel, p: Params):
        self.model, self.data, self.friction = model, mujoco.MjData(model), Friction(model, p)

    def __call__(self, q: np.ndarray, qd: np.ndarray) -> Probe:
        model, data = self.model, self.data
        data.qpos[:], data.qvel[:], data.qfrc_applied[:] = q, qd, 0.0
        mujoco.mj_forward(model, data)
        data.qfrc_applied[:] = self.friction(model, data)
        mujoco.mj_forward(model, data)
        mass = np.zeros((model.nv, model.nv))
        mujoco.mj_fullM(model, data, mass)
        return Probe(mass, data.qfrc_bias.copy(), data.qfrc_applied.copy(), data.qacc.copy(), float(data.energy[0]))
