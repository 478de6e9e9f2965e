"""Inertia from measured wire tensions (thesis 7.2, Euler's equations 7.2.1-7.2.2), by least squares.

Measured along a trajectory: the pose (COM in the world frame, rotation body -> world), the angular
velocity and angular acceleration (world frame) and each wire's tension (N, positive when pulling).
The wires' moment about the COM is M = sum_i (p_i - c) x T_i u_i, with p_i the attachment point and
u_i the unit vector from it to its anchor. In body axes Euler's equations

    I alpha_b + omega_b x (I omega_b) = M_b,   alpha_b = R^T alpha, omega_b = R^T omega, M_b = R^T M,

are linear in the six entries x = (I_xx, I_yy, I_zz, I_xy, I_xz, I_yz): A(alpha_b, omega_b) x = M_b,
three rows per sample, stacked over the trajectory and solved by least squares (or for the three
diagonal entries when the body axes are known to be principal, as the thesis assumes).

Conditioning. Every unknown is in kg m^2 and every row in N m, so the condition number of A itself
(no scaling) measures how well the motion separates the entries: the singular values are the
angular accelerations (gyroscopic terms included) that each combination of entries feels. A
rotation about one body axis only (the torsion of ch. 7.2) leaves the moments about the other two
axes in no row at all: the condition number is then limited only by the motion the torsion excites
elsewhere, and the thesis's observation that the dominant axis is found best is this, quantified.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from bifilar.rig import Rig
from bifilar.rig.statics import anchors

ENTRIES = ("xx", "yy", "zz", "xy", "xz", "yz")


def wire_moments(rig: Rig, com: np.ndarray, rotation: np.ndarray, tension: np.ndarray) -> np.ndarray:
    """Moment (N m, world frame) of the wire tensions about the COM, per sample: (n, 3)."""
    out = np.zeros((len(com), 3))
    for w, pull, hook in zip(rig.wires, tension.T, anchors(rig)):
        arm = rotation @ (w.attach - rig.com)  # COM -> attachment, world
        span = hook - (com + arm)
        out += np.cross(arm, span / np.linalg.norm(span, axis=1)[:, None] * pull[:, None])
    return out


def angular_acceleration(t: np.ndarray, omega: np.ndarray) -> np.ndarray:
    """d omega / dt at the interior samples 2 .. n-3 of a uniformly sampled record, by the fourth-order
    central difference (error h^4 omega^(5) / 30: ~1e-9 of alpha at 100 samples per period)."""
    h = float(t[1] - t[0])
    if not np.allclose(np.diff(t), h, rtol=1e-9, atol=0.0):
        raise ValueError("angular_acceleration needs uniformly sampled times")
    return (omega[:-4] - 8.0 * omega[1:-3] + 8.0 * omega[3:-1] - omega[4:]) / (12.0 * h)


def _entry_matrix(v: np.ndarray) -> np.ndarray:
    """L(v) with I v = L(v) x for x in :data:`ENTRIES` order: (n, 3, 6)."""
    out = np.zeros((len(v), 3, 6))
    a0, a1, a2 = v[:, 0], v[:, 1], v[:, 2]
    out[:, 0, 0], out[:, 0, 3], out[:, 0, 4] = a0, a1, a2
    out[:, 1, 1], out[:, 1, 3], out[:, 1, 5] = a1, a0, a2
    out[:, 2, 2], out[:, 2, 4], out[:, 2, 5] = a2, a0, a1
    return out


@dataclass(frozen=True)
class TensionFit:
    """Least-squares inertia (kg m^2, body axes about the COM) with the standard deviation of each
    fitted entry (from the residual variance), the condition number of the stacked system and the
    root-mean-square moment residual (N m)."""

    inertia: np.ndarray
    std: dict[str, float]
    condition: float
    rms: float


def fit_inertia(rig: Rig, com, rotation, omega, alpha, tension, principal: bool = False) -> TensionFit:
    """Inertia from Euler's equations along a trajectory (see the module docstring).

    Every argument but ``rig`` (its wires, attachments and COM) is per sample, world frame: ``com``
    (n, 3) m, ``rotation`` (n, 3, 3) body -> world, ``omega`` and ``alpha`` (n, 3) rad/s and rad/s^2,
    ``tension`` (n, wires) N. ``principal`` fits the diagonal only.
    """
    rotation = np.asarray(rotation, dtype=float)
    to_body = np.swapaxes(rotation, 1, 2)
    w_b = np.einsum("nij,nj->ni", to_body, omega)
    a_b = np.einsum("nij,nj->ni", to_body, alpha)
    m_b = np.einsum("nij,nj->ni", to_body, wire_moments(rig, np.asarray(com), rotation, np.asarray(tension)))
    Lw = _entry_matrix(w_b)
    rows = _entry_matrix(a_b) + np.cross(w_b[:, :, None], Lw, axis=1)
    columns = 3 if principal else 6
    A = rows[:, :, :columns].reshape(-1, columns)
    b = m_b.reshape(-1)
    x, _, _, sv = np.linalg.lstsq(A, b, rcond=None)
    residual = A @ x - b
    variance = float(residual @ residual) / max(len(b) - columns, 1)
    _, _, vt = np.linalg.svd(A, full_matrices=False)
    with np.errstate(divide="ignore"):  # an entry the motion never excites has infinite variance
        var_x = variance * np.sum(vt**2 / sv[:, None] ** 2, axis=0)
    full = np.zeros(6)
    full[:columns] = x
    xx, yy, zz, xy, xz, yz = full
    inertia = np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])
    condition = float(sv[0] / sv[-1]) if sv[-1] > 0.0 else float("inf")
    std = {f"I_{e}": float(np.sqrt(v)) for e, v in zip(ENTRIES, var_x)}
    return TensionFit(inertia, std, condition, float(np.sqrt(np.mean(residual**2))))
