"""Seed 001's pendulum derived independently of the seed, as a planar two-link chain.

Write the angles of the two arms in the fixed frame, theta = S q with q = (phi1, phi2) and
S = [[1, 0], [1, 1]]. The COM of every part b is p_b = sum_k l_bk e(theta_k), e(t) = (cos t, sin t),
in the plane (x horizontal, y up): an arm-1 part at ``offset`` along arm 1 has l_b = (offset, 0); an
arm-2 part has l_b = (-r1, offset), since the outer axis is at -r1 on arm 1. With
L_kl = sum_b m_b l_bk l_bl, J_k = the sum of link k's parts' own inertias and G_k = g sum_b m_b l_bk,
the kinetic energy is (1/2) sum_kl (L_kl cos(theta_k - theta_l) + delta_kl J_k) theta_k' theta_l'
and the potential V = sum_k G_k sin(theta_k). Lagrange's equations in theta read

    M_th theta'' + c_th + grad V = Q_th,
    M_th = [[L11 + J1, L12 cos(theta1 - theta2)], [L12 cos(theta1 - theta2), L22 + J2]],
    c_th = L12 sin(theta1 - theta2) (theta2'^2, -theta1'^2),   grad V = (G1 cos theta1, G2 cos theta2),

and, S being constant, M = S^T M_th S and bias = S^T (c_th + grad V) in q. The seed's friction
F = k1 E1k + k2 E2k is (1/2) q'^T R q' with R = S^T (k1 M_th[arm 1] + k2 M_th[arm 2]) S, each M_th
built from one arm's parts; the friction torques are -R q'. The accelerations come from the 2x2
system in theta, regular wherever the pendulum is (J2 + L22 > 0).
"""

from __future__ import annotations

from dataclasses import dataclass
from math import cos, sin

import numpy as np

from .params import Params

S = np.array([[1.0, 0.0], [1.0, 1.0]])  # theta = S q


@dataclass(frozen=True)
class Link:
    """Lumped constants of a set of parts: L11, L12, L22, J1, J2 (kg m^2) and G1, G2 (N m)."""

    L11: float
    L12: float
    L22: float
    J1: float
    J2: float
    G1: float
    G2: float

    @classmethod
    def of(cls, p: Params, arms: tuple[int, ...]) -> Link:
        L, J, G = np.zeros((2, 2)), np.zeros(2), np.zeros(2)
        for b in p.bodies():
            if b.arm in arms:
                lever = np.array([b.offset, 0.0]) if b.arm == 1 else np.array([-p.r1, b.offset])
                L += b.mass * np.outer(lever, lever)
                J[b.arm - 1] += b.inertia
                G += p.g * b.mass * lever
        return cls(L[0, 0], L[0, 1], L[1, 1], J[0], J[1], G[0], G[1])

    def inertia(self, t1: float, t2: float) -> tuple[float, float, float]:
        """(M_th11, M_th12, M_th22) at absolute angles (t1, t2) (kg m^2)."""
        return self.L11 + self.J1, self.L12 * cos(t1 - t2), self.L22 + self.J2


def _to_q(m11: float, m12: float, m22: float) -> np.ndarray:
    """S^T [[m11, m12], [m12, m22]] S."""
    return np.array([[m11 + 2 * m12 + m22, m12 + m22], [m12 + m22, m22]])


@dataclass(frozen=True)
class Chain:
    """The whole pendulum (``link``), each arm's parts alone, and the friction coefficients (1/s)."""

    link: Link
    arm1: Link
    arm2: Link
    k1: float
    k2: float

    @classmethod
    def from_params(cls, p: Params) -> Chain:
        return cls(Link.of(p, (1, 2)), Link.of(p, (1,)), Link.of(p, (2,)), p.k1, p.k2)

    def _friction_th(self, t1: float, t2: float) -> tuple[float, float, float]:
        a, b = self.arm1.inertia(t1, t2), self.arm2.inertia(t1, t2)
        return tuple(self.k1 * x + self.k2 * y for x, y in zip(a, b))

    def _forces_th(self, t1: float, t2: float, w1: float, w2: float) -> tuple[float, float]:
        """c_th + grad V (N m)."""
        s = self.link.L12 * sin(t1 - t2)
        return s * w2**2 + self.link.G1 * cos(t1), -s * w1**2 + self.link.G2 * cos(t2)

    def mass_matrix(self, q: np.ndarray) -> np.ndarray:
        """M(q) (kg m^2)."""
        return _to_q(*self.link.inertia(q[0], q[0] + q[1]))

    def bias(self, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
        """Coriolis, centripetal and gravity torques (N m): MuJoCo's ``qfrc_bias``."""
        h1, h2 = self._forces_th(q[0], q[0] + q[1], qd[0], qd[0] + qd[1])
        return np.array([h1 + h2, h2])

    def friction_matrix(self, q: np.ndarray) -> np.ndarray:
        """R(q) (kg m^2/s): F = q'^T R q' / 2, friction torques -R q'."""
        return _to_q(*self._friction_th(q[0], q[0] + q[1]))

    def accel(self, p1: float, p2: float, w1: float, w2: float) -> tuple[float, float]:
        """(phi1'', phi2'') (rad/s^2)."""
        t1, t2, o1, o2 = p1, p1 + p2, w1, w1 + w2
        m11, m12, m22 = self.link.inertia(t1, t2)
        r11, r12, r22 = self._friction_th(t1, t2)
        h1, h2 = self._forces_th(t1, t2, o1, o2)
        b1, b2 = -h1 - r11 * o1 - r12 * o2, -h2 - r12 * o1 - r22 * o2
        det = m11 * m22 - m12 * m12
        a1, a2 = (m22 * b1 - m12 * b2) / det, (m11 * b2 - m12 * b1) / det
        return a1, a2 - a1

    def energy(self, q: np.ndarray, qd: np.ndarray) -> float:
        """Kinetic plus potential energy (J), zero potential with both arms horizontal."""
        return 0.5 * qd @ self.mass_matrix(q) @ qd + self.link.G1 * sin(q[0]) + self.link.G2 * sin(q[0] + q[1])

    def dissipation(self, q: np.ndarray, qd: np.ndarray) -> float:
        """F (W); the energy decreases at 2F."""
        return 0.5 * qd @ self.friction_matrix(q) @ qd
