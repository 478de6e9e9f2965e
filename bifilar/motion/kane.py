"""The Kane-Tseng model of a rig: thesis parameters, angles <-> pose, and the equations of motion.

:class:`KaneModel` maps a :class:`~bifilar.rig.Rig` to the thesis's parameters (seed 000, ch. 5.1):
b, b', l, l', r, lambda, the principal inertias and the constant rotation between the thesis's body
frame n~ and the principal axes b (5.1.6), plus the generalised anchor offset AB. The equations
themselves live in :mod:`bifilar.motion.kane_kernel` (compiled); this module is the Python face of them.

Charts: angles are ``theta`` in the thesis's POLAR chart unless a ``chart`` argument says TILT (the
remedy for a vertical wire 1; see :mod:`bifilar.motion.kane_kernel`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from bifilar.rig.air import added_mass, drag_parameters
from bifilar.motion import kane_kernel as K
from bifilar.rig import Rig, RigError
from bifilar.rig.statics import State
from bifilar.smallmat import solve

POLAR, TILT = K.POLAR, K.TILT


@dataclass(frozen=True)
class KaneModel:
    """The thesis's parameters of a two-wire rig and the compiled parameter vector ``p``."""

    b: float  # |AB|, distance between the ceiling anchors, m
    b_prime: float  # |CD|, distance between the body attachments, m
    l: float  # wire 1 (BC), m
    l_prime: float  # wire 2 (DA), m
    r: float  # |C R*|, m
    lam: float  # angle from DC to C R*, rad (5.1.14)
    mass: float
    gravity: float
    ab: np.ndarray  # B - A, world frame (the thesis: -b n2)
    principal_moments: np.ndarray  # I1 <= I2 <= I3, kg m^2
    principal_axes: np.ndarray  # N_n~^b of (5.1.6): row i is b_i in n~ coordinates
    frame_in_body: np.ndarray  # columns n~1, n~2, n~3 in the rig's body coordinates
    rig: Rig
    p: np.ndarray

    @classmethod
    def from_rig(cls, rig: Rig) -> "KaneModel":
        if len(rig.wires) != 2:
            raise RigError(rig.source, "wire", f"the kane engine represents exactly two wires, found {len(rig.wires)}")
        K.announce()
        w1, w2 = rig.wires
        c_b, d_b = w1.attach, w2.attach
        b_prime = float(np.linalg.norm(c_b - d_b))
        n3 = (c_b - d_b) / b_prime
        arm = rig.com - c_b
        along = float(arm @ n3)  # = -r cos(lam)
        perp = arm - along * n3
        r = float(np.linalg.norm(arm))
        if np.linalg.norm(perp) > 1e-12 * max(r, 1.0):
            n1 = perp / np.linalg.norm(perp)
        else:
            # COM on the line CD: theta1 is neutral; fix n~1 as the direction normal to CD nearest
            # the body's -z axis (or -x if CD is along z).
            down = np.array([0.0, 0.0, -1.0]) if abs(n3[2]) < 0.9 else np.array([-1.0, 0.0, 0.0])
            n1 = down - (down @ n3) * n3
            n1 /= np.linalg.norm(n1)
        n2 = np.cross(n3, n1)
        frame = np.column_stack([n1, n2, n3])
        lam = float(np.arctan2(np.linalg.norm(perp), -along))
        inertia_n = frame.T @ rig.inertia @ frame
        moments, axes = np.linalg.eigh(inertia_n)
        ab = w1.anchor - w2.anchor
        p = np.zeros(K.P_SIZE)
        p[K.P_L], p[K.P_LP], p[K.P_BP] = w1.length, w2.length, b_prime
        p[K.P_R], p[K.P_SLAM], p[K.P_CLAM] = r, np.sin(lam), np.cos(lam)
        p[K.P_M], p[K.P_G] = rig.mass, rig.gravity
        p[8:11] = ab
        p[11:20] = inertia_n.ravel()
        p[20:23] = w1.anchor
        if rig.air is not None:
            _air_parameters(p, rig, frame)
        return cls(
            b=float(np.linalg.norm(ab)),
            b_prime=b_prime,
            l=w1.length,
            l_prime=w2.length,
            r=r,
            lam=lam,
            mass=rig.mass,
            gravity=rig.gravity,
            ab=ab,
            principal_moments=moments,
            principal_axes=axes.T,
            frame_in_body=frame,
            rig=rig,
            p=p,
        )

    # --- equations of motion -------------------------------------------------------------------
    def eom(self, theta, dtheta, chart=POLAR):
        """(M5, N5) of (5.1.30) at angles ``theta`` and rates ``dtheta``."""
        return K.eom(_vec(theta), _vec(dtheta), self.p, chart)

    def accelerations(self, theta, dtheta, chart=POLAR) -> np.ndarray:
        """theta'' from M5 theta'' = N5, solved as the compiled rhs solves it."""
        return solve(*self.eom(theta, dtheta, chart))

    def constraint(self, theta, chart=POLAR) -> float:
        """g(theta) - a of (5.1.2): |AD|^2 - l'^2, m^2."""
        d = K.kinematics(_vec(theta), np.zeros(5), self.p, chart)[7]
        return float(d @ d - self.l_prime**2)

    def tensions(self, theta, dtheta, chart=POLAR) -> np.ndarray:
        """Tensions (N) of wire 1 (BC) and wire 2 (DA); negative means the wire would have to push."""
        return K.loads(_vec(theta), _vec(dtheta), self.p, chart)[0]

    # --- angles <-> pose -----------------------------------------------------------------------
    def pose(self, theta, chart=POLAR) -> tuple[np.ndarray, np.ndarray]:
        """COM (world, m) and body->world rotation for angles ``theta``."""
        com, frame = K.pose(_vec(theta), self.p, chart)
        return com, frame @ self.frame_in_body.T

    def velocity(self, theta, dtheta, chart=POLAR) -> tuple[np.ndarray, np.ndarray]:
        """COM velocity and angular velocity (world frame) for angles and rates."""
        kin = K.kinematics(_vec(theta), _vec(dtheta), self.p, chart)
        V, G = kin[3], kin[4]
        return V @ dtheta, G @ dtheta

    def state(self, theta, dtheta, chart=POLAR) -> State:
        """The rigid-body state (world frame) of angles and rates."""
        com, rotation = self.pose(theta, chart)
        velocity, omega = self.velocity(theta, dtheta, chart)
        return State(com=com, rotation=rotation, velocity=velocity, omega=omega)

    def angles(self, com, rotation, chart=POLAR) -> np.ndarray:
        """The five angles of a pose (the pose must hold both wires at their lengths)."""
        w1 = self.rig.wires[0]
        c = com + rotation @ (w1.attach - self.rig.com)
        u = (c - w1.anchor) / np.linalg.norm(c - w1.anchor)
        frame = rotation @ self.frame_in_body
        n1, n3 = frame[:, 0], frame[:, 2]
        th5 = np.arcsin(np.clip(-n3[2], -1.0, 1.0))
        th4 = np.arctan2(-n3[0], -n3[1])
        s4, c4, s5, c5 = np.sin(th4), np.cos(th4), np.sin(th5), np.cos(th5)
        th1 = np.arctan2(n1 @ [c4, -s4, 0.0], n1 @ [s4 * s5, c4 * s5, -c5])
        q2, q3 = wire_angles(u, chart)
        return np.array([th1, q2, q3, th4, th5])

    def rates(self, theta, velocity, omega, chart=POLAR) -> np.ndarray:
        """theta' from the COM velocity and angular velocity (world frame), by least squares on
        [V; G] theta' = [v; omega] (exact when the velocity keeps both wires at length)."""
        kin = K.kinematics(_vec(theta), np.zeros(5), self.p, chart)
        A = np.vstack([kin[3], kin[4]])
        return np.linalg.lstsq(A, np.concatenate([velocity, omega]), rcond=None)[0]

    def complete_theta5(self, theta14, dtheta14, guess: float = 0.0):
        """theta5 with g(theta) = a (Newton from ``guess``) and theta5' = gamma . theta'_{1..4} (5.1.4)."""
        th = np.append(np.asarray(theta14, dtype=float), guess)
        for _ in range(50):
            kin = K.kinematics(th, np.zeros(5), self.p, POLAR)
            d, J = kin[7], kin[8]
            f = d @ d - self.l_prime**2
            beta5 = 2.0 * (J[:, 4] @ d)
            step = f / beta5
            th[4] -= step
            if abs(step) < 1e-15:
                break
        else:
            raise RuntimeError("theta5 did not converge: no closed loop near the guess")
        kin = K.kinematics(th, np.zeros(5), self.p, POLAR)
        beta = 2.0 * (kin[8].T @ kin[7])
        gamma = -beta[:4] / beta[4]
        return th[4], float(gamma @ np.asarray(dtheta14, dtype=float))


def air_vector(rig: Rig) -> np.ndarray:
    """A kernel parameter vector holding only the air entries, in the rig's own body axes (the
    N-wire model's frame); all zero (no air) for a body in a vacuum."""
    p = np.zeros(K.P_AIR_DRAG.stop)
    if rig.air is not None:
        _air_parameters(p, rig, np.eye(3))
    return p


def _air_parameters(p: np.ndarray, rig: Rig, frame: np.ndarray) -> None:
    """Fill the kernel's air entries: the added-mass tensor about the COM, the ellipsoid's centre
    and axes, all turned from the rig's body axes to the n~ frame (columns of ``frame``)."""
    air = rig.air
    rot6 = np.kron(np.eye(2), frame)
    p[K.P_AIR] = 1.0
    p[K.P_AIR_MASS] = (rot6.T @ added_mass(air, rig.com) @ rot6).ravel()
    p[K.P_AIR_CENTER] = frame.T @ (air.center - rig.com)
    p[K.P_AIR_AXES] = (frame.T @ air.axes).ravel()
    p[K.P_AIR_DRAG] = drag_parameters(air)


def wire_angles(u: np.ndarray, chart: int) -> tuple[float, float]:
    """Chart coordinates of the unit vector u of BC."""
    if chart == POLAR:
        return float(np.arccos(np.clip(-u[2], -1.0, 1.0))), float(np.arctan2(u[1], u[0]))
    return float(np.arctan2(-u[1], -u[2])), float(np.arcsin(np.clip(u[0], -1.0, 1.0)))


def _vec(x) -> np.ndarray:
    return np.ascontiguousarray(x, dtype=float)
