"""Small oscillations of a rig about its rest pose, from the exact linearisation of the Kane equations.

With theta5 eliminated through the constraint, the four independent angles q = theta_{1..4} move as
theta = theta0 + T dq, T = [I4; gamma^T] (5.1.4). Linearising M4(theta) theta'' = N4(theta, theta')
about rest (where N4 = 0 and the velocity terms are quadratic) gives

    M dq'' + K dq = 0,   M = M4 T = m V_new^T V_new + G_new^T I G_new,   K = -(dN4/dtheta) T,

all four modes coupled, unlike the thesis's reduced 2x2 systems of ch. 7.1. M is symmetric positive
definite; K is the Hessian of the potential on the constraint manifold (symmetric to rounding, which
is checked). dN4/dtheta is a fourth-order central difference of the compiled N4, accurate to ~1e-11.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.linalg import eigh

from bifilar.motion import kane_kernel as K
from bifilar.motion.kane import KaneModel
from bifilar.motion.simulate import preferred_chart
from bifilar.rig.statics import Rest, State, rest_pose

NEUTRAL_RTOL = 1e-9  # an eigenvalue below this fraction of the largest is neutral (or unstable)


@dataclass(frozen=True)
class Mode:
    """One normal mode: period (s; None if neutral or unstable), omega^2 (rad^2/s^2), and its shape as
    a COM displacement (world, m) and a small rotation vector (world, rad), scaled so that the largest
    of |rotation| and |com|/r_ref is 1."""

    period: float | None
    omega2: float
    com: np.ndarray
    rotation: np.ndarray


@dataclass(frozen=True)
class Modes:
    rest: Rest
    modes: tuple[Mode, ...]  # longest period first; neutral/unstable modes first of all
    mass: np.ndarray  # M (4x4)
    stiffness: np.ndarray  # K (4x4)
    chart: int
    theta0: np.ndarray
    tangent: np.ndarray  # T (5x4)


def linearize(model: KaneModel, rest: Rest | None = None) -> Modes:
    """Mass and stiffness matrices about the rest pose and the normal modes."""
    rest = rest_pose(model.rig) if rest is None else rest
    at_rest = State(rest.com, rest.rotation, np.zeros(3), np.zeros(3))
    chart = preferred_chart(model, at_rest)
    theta0 = model.angles(rest.com, rest.rotation, chart)
    p = model.p
    zero = np.zeros(5)
    kin = K.kinematics(theta0, zero, p, chart)
    V, G, d, J = kin[3], kin[4], kin[7], kin[8]
    beta = 2.0 * (J.T @ d)
    T = np.vstack([np.eye(4), -beta[:4] / beta[4]])
    Vn, Gn = V @ T, G @ T
    Iw = K.inertia_world(kin[1], p)
    M = model.mass * (Vn.T @ Vn) + Gn.T @ Iw @ Gn
    dN = np.empty((4, 4))
    h = 1e-4
    for j in range(4):
        def n4(s):
            return K.eom(theta0 + s * T[:, j], zero, p, chart)[1][:4]
        dN[:, j] = (-n4(2 * h) + 8 * n4(h) - 8 * n4(-h) + n4(-2 * h)) / (12 * h)
    Kmat = -dN
    asym = np.abs(Kmat - Kmat.T).max() / max(np.abs(Kmat).max(), 1e-300)
    if asym > 1e-6:
        raise RuntimeError(f"stiffness matrix is not symmetric (relative asymmetry {asym:.1e}): not a rest pose")
    Kmat = 0.5 * (Kmat + Kmat.T)
    w2, vecs = eigh(Kmat, M)
    scale = max(model.b_prime, model.r, 1e-3)
    modes = []
    for k in range(4):
        dtheta = T @ vecs[:, k]
        com, rot = V @ dtheta, G @ dtheta
        norm = max(np.linalg.norm(rot), np.linalg.norm(com) / scale)
        neutral = w2[k] <= NEUTRAL_RTOL * max(abs(w2).max(), 1e-300)
        period = None if neutral else float(2.0 * np.pi / np.sqrt(w2[k]))
        modes.append(Mode(period, float(w2[k]), com / norm, rot / norm))
    modes.sort(key=lambda m: (m.period is not None, -(m.period or 0.0)))
    return Modes(rest, tuple(modes), M, Kmat, chart, theta0, T)


def excite(model: KaneModel, lin: Modes, index: int, amplitude: float) -> State:
    """A state at the rest pose moving along mode ``index`` with angle amplitude ~``amplitude`` (rad):
    the velocity is omega_k times the mode shape, which is tangent to the wire constraints."""
    mode = lin.modes[index]
    if mode.period is None:
        raise ValueError(f"mode {index} is neutral or unstable; it cannot be excited into oscillation")
    rate = amplitude * 2.0 * np.pi / mode.period
    return State(lin.rest.com, lin.rest.rotation, rate * mode.com, rate * mode.rotation)
