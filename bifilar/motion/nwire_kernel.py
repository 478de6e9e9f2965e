"""Compiled Newton-Euler equations of a rigid body on N inextensible wires, tensions as multipliers.

State y (13): COM c (world, m), unit quaternion q of the body->world rotation (scalar first), COM
velocity v (world, m/s), angular velocity omega (world, rad/s). Per wire i: anchor a_i (world), arm
s_i = R r_i (r_i: attachment minus COM, body frame), span d_i = a_i - c - s_i, length rho_i = |d_i|,
direction u_i = d_i / rho_i and attachment velocity w_i = v + omega x s_i.

With nu = (v, omega) and M = diag(m I, I_w), I_w = R I_b R^T, the equations are (docs/nwire-model.md):

    M nu' = f - J^T t,     f = (-m g e_z, -omega x I_w omega),     J_i = [-u_i^T, (u_i x s_i)^T],
    J nu' = b,             b_i = u_i . (omega x (omega x s_i)) - (|w_i|^2 - (u_i . w_i)^2) / rho_i,

the second being rho_i'' = 0. Eliminating nu' gives the tensions from (J M^-1 J^T) t = J M^-1 f - b.
Nothing here is shared with the statics (bifilar.rig.pose_kernel): the geometry is recomputed from
its definition so the model is an independent check of the rest pose and the modes.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from bifilar.motion.kane_kernel import P_AIR as AIR_FLAG
from bifilar.motion.kane_kernel import air_terms
from bifilar.smallmat import cross as _cross
from bifilar.smallmat import add2, put, put2, put_col

STATE_SIZE = 13


@njit(cache=True)
def quat_matrix(q):
    """Rotation matrix of a quaternion (scalar first), normalised first."""
    n = np.sqrt(q @ q)
    w, x, y, z = q[0] / n, q[1] / n, q[2] / n, q[3] / n
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ])


@njit(cache=True)
def matrix_quat(rot):
    """The unit quaternion (scalar first, w >= 0) of a rotation matrix (Shepperd's method: the
    largest of the four squared components is taken first, so no division is by a small number)."""
    tr = rot[0, 0] + rot[1, 1] + rot[2, 2]
    q = np.empty(4)
    if tr >= max(rot[0, 0], rot[1, 1], rot[2, 2]):
        r = np.sqrt(1.0 + tr)
        q[0], q[1] = 0.5 * r, (rot[2, 1] - rot[1, 2]) / (2.0 * r)
        q[2], q[3] = (rot[0, 2] - rot[2, 0]) / (2.0 * r), (rot[1, 0] - rot[0, 1]) / (2.0 * r)
    else:
        i = 0 if rot[0, 0] >= max(rot[1, 1], rot[2, 2]) else (1 if rot[1, 1] >= rot[2, 2] else 2)
        j, k = (i + 1) % 3, (i + 2) % 3
        r = np.sqrt(1.0 + rot[i, i] - rot[j, j] - rot[k, k])
        q[1 + i] = 0.5 * r
        q[0] = (rot[k, j] - rot[j, k]) / (2.0 * r)
        q[1 + j] = (rot[j, i] + rot[i, j]) / (2.0 * r)
        q[1 + k] = (rot[k, i] + rot[i, k]) / (2.0 * r)
    if q[0] < 0.0:
        q = -q
    return q


@njit(cache=True)
def dynamics(y, arms, anchors, inertia_body, mass, gravity, air):
    """(nu', tensions, J, rho): accelerations (v', omega'), wire tensions (N, positive pulling),
    the constraint Jacobian (N x 6) and the anchor-attachment distances (m) at state y. Also the
    tensions' kernel for Python and the sweep (``dynamics(...)[1]``): one kernel fewer to compile.

    ``air``: the Kane kernel's parameter vector with its air entries filled in the rig's body frame
    (:func:`bifilar.motion.kane.air_vector`); with air the fluid's added mass M_A,w joins the mass
    matrix and its velocity terms and drag the applied wrench, exactly as in the Kane model
    (``kane_kernel.air_terms``); in a vacuum the block-diagonal path below runs unchanged."""
    minv_f, minv_jt, jac, b, rho = _system(y, arms, anchors, inertia_body, mass, gravity, air)
    tension = np.linalg.solve(jac @ minv_jt, jac @ minv_f - b)
    acc = minv_f - minv_jt @ tension
    return acc, tension, jac, rho


@njit(cache=True)
def compatible_tensions(y, arms, anchors, inertia_body, mass, gravity, air, springs, base):
    """Tensions (N) at state y of wires with spring constants ``springs`` (N/m) whose tensions at a
    nearby pose are ``base``: t = base + K J d, K = diag(springs), with the pose change d the least-squares
    solution of (J M^-1 J^T) K J d = J M^-1 f - b - (J M^-1 J^T) base, the equations :func:`dynamics`
    solves. Where J M^-1 J^T is invertible (two or three wires) this is :func:`dynamics`' tension exactly;
    where it is singular (four parallel wires: statically indeterminate) the increment is the one the
    wires' stretch allows, and the self-stress of ``base`` (the part no motion of the body changes to first
    order) is kept: what :func:`dynamics` cannot solve (issue 35 item 5)."""
    minv_f, minv_jt, jac, b, _ = _system(y, arms, anchors, inertia_body, mass, gravity, air)
    a = jac @ minv_jt
    stretch = jac * springs.reshape(-1, 1)  # K J
    d = np.linalg.lstsq(a @ stretch, jac @ minv_f - b - a @ base, 1e-10)[0]
    return base + stretch @ d


@njit(cache=True)
def _system(y, arms, anchors, inertia_body, mass, gravity, air):
    """(M^-1 f, M^-1 J^T, J, b, rho) at state y: the terms of J M^-1 J^T t = J M^-1 f - b, the wires'
    tensions t that keep every wire at its length (see :func:`dynamics`)."""
    n = arms.shape[0]
    c, v, om = y[0:3], y[7:10], y[10:13]
    rot = quat_matrix(y[3:7])
    iw = rot @ inertia_body @ rot.T
    iw_inv = rot @ np.linalg.inv(inertia_body) @ rot.T
    jac = np.empty((n, 6))
    b = np.empty(n)
    rho = np.empty(n)
    for i in range(n):
        s = rot @ arms[i]
        d = anchors[i] - c - s
        rho[i] = np.sqrt(d @ d)
        u = d / rho[i]
        w = v + _cross(om, s)
        uw = u @ w
        put(jac[i], 0, -u)
        put(jac[i], 3, _cross(u, s))
        b[i] = u @ _cross(om, _cross(om, s)) - (w @ w - uw * uw) / rho[i]
    f = np.zeros(6)
    f[2] = -mass * gravity
    put(f, 3, -_cross(om, iw @ om))
    minv_f = np.empty(6)
    minv_jt = np.empty((6, n))
    if air[AIR_FLAG] != 0.0:
        maw, bias, drag = air_terms(rot, v, om, air)
        m6 = maw.copy()
        for k in range(3):
            m6[k, k] += mass
        add2(m6, 3, 3, iw)
        f += drag - bias
        m6_inv = np.linalg.inv(m6)
        put(minv_f, 0, m6_inv @ f)
        put2(minv_jt, 0, 0, m6_inv @ jac.T)
    else:
        # M^-1 applied to f and to each row of J (as columns of M^-1 J^T).
        put(minv_f, 0, f[:3] / mass)
        put(minv_f, 3, iw_inv @ f[3:])
        for i in range(n):
            put_col(minv_jt, 0, i, jac[i, :3] / mass)
            put_col(minv_jt, 3, i, iw_inv @ jac[i, 3:])
    return minv_f, minv_jt, jac, b, rho


@njit(cache=True)
def dynamics_jacobian(y, arms, anchors):
    """The constraint Jacobian J (N x 6, rows [-u_i, u_i x s_i]) at state y."""
    n = arms.shape[0]
    rot = quat_matrix(y[3:7])
    jac = np.empty((n, 6))
    for i in range(n):
        s = rot @ arms[i]
        d = anchors[i] - y[0:3] - s
        u = d / np.sqrt(d @ d)
        put(jac[i], 0, -u)
        put(jac[i], 3, _cross(u, s))
    return jac


@njit(cache=True)
def rhs(y, arms, anchors, inertia_body, mass, gravity, air):
    """y' for the state layout of the module docstring; q' = (1/2) (0, omega) * q (world omega)."""
    return state_rate(y, dynamics(y, arms, anchors, inertia_body, mass, gravity, air)[0])


@njit(cache=True)
def state_rate(y, acc):
    """y' of a free rigid body (the module docstring's layout) whose COM and angular accelerations
    (world) are ``acc``: velocities, q' = (1/2) (0, omega) * q (world omega), accelerations."""
    q, om = y[3:7], y[10:13]
    dy = np.empty(STATE_SIZE)
    put(dy, 0, y[7:10])
    dy[3] = -0.5 * (om[0] * q[1] + om[1] * q[2] + om[2] * q[3])
    dy[4] = 0.5 * (om[0] * q[0] + om[1] * q[3] - om[2] * q[2])
    dy[5] = 0.5 * (-om[0] * q[3] + om[1] * q[0] + om[2] * q[1])
    dy[6] = 0.5 * (om[0] * q[2] - om[1] * q[1] + om[2] * q[0])
    put(dy, 7, acc)
    return dy


@njit(cache=True)
def observe(Y, arms, anchors, inertia_body, mass, gravity, air):
    """Per sample: the rotation matrix, the tensions (N) and the energy (J; potential zero at z = 0;
    with air, the fluid's kinetic energy included as in the Kane model)."""
    n_s, n = Y.shape[0], arms.shape[0]
    frames = np.empty((n_s, 3, 3))
    ten = np.empty((n_s, n))
    energy = np.empty(n_s)
    for k in range(n_s):
        y = Y[k]
        rot = quat_matrix(y[3:7])
        put2(frames[k], 0, 0, rot)
        put(ten[k], 0, dynamics(y, arms, anchors, inertia_body, mass, gravity, air)[1])
        om, v = y[10:13], y[7:10]
        iw = rot @ inertia_body @ rot.T
        energy[k] = 0.5 * mass * (v @ v) + 0.5 * (om @ (iw @ om)) + mass * gravity * y[2]
        if air[AIR_FLAG] != 0.0:
            x = np.concatenate((v, om))
            energy[k] += 0.5 * (x @ (air_terms(rot, v, om, air)[0] @ x))
    return frames, ten, energy
