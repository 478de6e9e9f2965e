"""Compiled kernel of the Kane-Tseng bifilar equations (seed 000, ch. 5.1 and appendix B).

Notation follows the thesis. World frame N (n3 up, gravity -g n3). Wire 1 runs from ceiling point B
to body point C (length l), wire 2 from body point D to ceiling point A (length l'); b' = |CD|.
The body frame n~ has n~3 along DC; the COM R* sits at r = r sin(lam) n~1 - r cos(lam) n~3 from C.
Five angles theta: theta1 tilts the body about CD, (theta2, theta3) give the direction of BC
(polar angle from the downward vertical, azimuth from n1), theta4 and theta5 give the direction of CD
(heading and elevation). The loop closure g(theta) = |AB + BC + CD|^2 = l'^2 ties theta5 to the others.

Generalisation (docs/kane-tseng.md): the thesis's AB = -b n2 becomes any vector AB = B - A, so the
hooks may be at different heights and in any direction.

Chart remedy: the polar chart of BC is singular at theta2 = 0 (a vertical wire, e.g. every
parallel-wire rig at rest). The TILT chart writes the same unit vector as
u = (sin q3, -sin q2 cos q3, -cos q2 cos q3), singular only for a horizontal wire along n1. Every
term below is built from u and its first and second partial derivatives, so the Kane equations are
the same code in either chart; :mod:`bifilar.motion.simulate` switches charts before either degenerates.

Instead of transcribing the appendix's entries, the kernel assembles the thesis's matrices from
their definitions: V = C + W (5.1.17) with W's columns G e_i x r, the velocity-product term
Vdot theta' as the acceleration of R* at zero theta'', and so on. tests/test_kane_kernel.py checks
each against finite differences of the kinematics and against the appendix where it is right;
docs/thesis-corrections.md lists where it is not.

Air (docs/air.md): with ``p[P_AIR]`` set, the fluid's impulse [P; L] = M_A,w [v; omega] (world frame,
L about R*, M_A,w the added-mass tensor of :mod:`bifilar.rig.air` turned to the world) and the drag
enter as a wrench on the body: force -dP/dt + F_drag, torque about R* -(dL/dt + v x P) + G_drag
(Lamb 1932 §124). Its acceleration part adds [Vn; Gn]^T M_A,w [V; G] to the generalised inertia, the
rest is an active force. Without air the code path is skipped and the equations are those above.

Parameter vector layout: see :data:`P_*` indices.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from bifilar.rig.air import drag_wrench
from bifilar.jit import announce_compile
from bifilar.smallmat import cross as _cross
from bifilar.smallmat import mm as _mm
from bifilar.smallmat import mv as _mv
from bifilar.smallmat import solve as _solve
from bifilar.smallmat import add, add2, add_col, put, put2, put_col

POLAR, TILT = 0, 1

P_L, P_LP, P_BP, P_R, P_SLAM, P_CLAM, P_M, P_G = range(8)
P_AB = slice(8, 11)  # B - A, world frame
P_INERTIA = slice(11, 20)  # inertia about R* in the n~ frame, row-major
P_B = slice(20, 23)  # anchor B of wire 1, world frame
P_AIR = 23  # 1.0 with air, 0.0 in a vacuum
P_AIR_MASS = slice(24, 60)  # 6x6 added-mass tensor about R* in the n~ frame, row-major
P_AIR_CENTER = slice(60, 63)  # the air's ellipsoid centre from R*, n~ frame
P_AIR_AXES = slice(63, 72)  # the ellipsoid's axes (columns) in the n~ frame, row-major
P_AIR_DRAG = slice(72, 80)  # bifilar.rig.air.drag_parameters
P_SIZE = 80


@njit(cache=True)
def wire_direction(q2, q3, chart):
    """Unit vector of BC and its partials: u, du/dq2, du/dq3, d2u/dq2^2, d2u/dq2dq3, d2u/dq3^2."""
    s2, c2, s3, c3 = np.sin(q2), np.cos(q2), np.sin(q3), np.cos(q3)
    if chart == POLAR:
        u = np.array([s2 * c3, s2 * s3, -c2])
        u2 = np.array([c2 * c3, c2 * s3, s2])
        u3 = np.array([-s2 * s3, s2 * c3, 0.0])
        u22 = -u
        u23 = np.array([-c2 * s3, c2 * c3, 0.0])
        u33 = np.array([-s2 * c3, -s2 * s3, 0.0])
    else:
        u = np.array([s3, -s2 * c3, -c2 * c3])
        u2 = np.array([0.0, -c2 * c3, s2 * c3])
        u3 = np.array([c3, s2 * s3, c2 * s3])
        u22 = np.array([0.0, s2 * c3, c2 * c3])
        u23 = np.array([0.0, c2 * s3, -s2 * s3])
        u33 = np.array([-s3, s2 * c3, c2 * c3])
    return u, u2, u3, u22, u23, u33


@njit(cache=True)
def body_frame(q1, q4, q5):
    """N_n^n~ of (5.1.5): columns are n~1, n~2, n~3 in world coordinates."""
    s1, c1, s4, c4, s5, c5 = np.sin(q1), np.cos(q1), np.sin(q4), np.cos(q4), np.sin(q5), np.cos(q5)
    out = np.empty((3, 3))
    out[0, 0] = s1 * c4 + c1 * s4 * s5
    out[1, 0] = -s1 * s4 + c1 * c4 * s5
    out[2, 0] = -c1 * c5
    out[0, 1] = c1 * c4 - s1 * s4 * s5
    out[1, 1] = -c1 * s4 - s1 * c4 * s5
    out[2, 1] = s1 * c5
    out[0, 2] = -s4 * c5
    out[1, 2] = -c4 * c5
    out[2, 2] = -s5
    return out


@njit(cache=True)
def kinematics(th, dth, p, chart):
    """Everything Kane's equations need at (theta, theta').

    Returns u (BC direction), R (n~ frame), r (C->R*, world), V (3x5, 5.1.17), G (3x5, 5.1.10),
    vbias = Vdot theta', wbias = Gdot theta', d = AD (world), J (3x5, dd/dtheta), dbias = Jdot theta'.
    """
    l, bp = p[P_L], p[P_BP]
    u, u2, u3, u22, u23, u33 = wire_direction(th[1], th[2], chart)
    R = body_frame(th[0], th[3], th[4])
    n3t = R[:, 2]
    rho = np.array([p[P_R] * p[P_SLAM], 0.0, -p[P_R] * p[P_CLAM]])
    r = _mv(R, rho)
    s4, c4, s5, c5 = np.sin(th[3]), np.cos(th[3]), np.sin(th[4]), np.cos(th[4])
    # Angular velocity omega = th1' n~3 - th4' n3 + th5' (c4 n1 - s4 n2): the basis Q of (5.1.8).
    G = np.zeros((3, 5))
    put_col(G, 0, 0, n3t)
    G[2, 3] = -1.0
    G[0, 4] = c4
    G[1, 4] = -s4
    omega = _mv(G, dth)
    # Partials of n~3 = -(s4 c5, c4 c5, s5) and of the th5 axis e5 = (c4, -s4, 0).
    n3t_4 = np.array([-c4 * c5, s4 * c5, 0.0])
    n3t_5 = np.array([s4 * s5, c4 * s5, -c5])
    e5_4 = np.array([-s4, -c4, 0.0])
    wbias = dth[0] * (n3t_4 * dth[3] + n3t_5 * dth[4]) + dth[4] * dth[3] * e5_4
    # V = C + W: velocity of C along the wire plus omega x r, column by column.
    V = np.zeros((3, 5))
    put_col(V, 0, 1, l * u2)
    put_col(V, 0, 2, l * u3)
    for i in range(5):
        add_col(V, 0, i, _cross(G[:, i], r))
    ubias = u22 * dth[1] ** 2 + 2.0 * u23 * dth[1] * dth[2] + u33 * dth[2] ** 2
    vbias = l * ubias + _cross(wbias, r) + _cross(omega, _cross(omega, r))
    # Loop closure: d = AD = AB + l u + CD, CD = -b' n~3.
    d = p[8:11] + l * u - bp * n3t
    J = np.zeros((3, 5))
    put_col(J, 0, 1, l * u2)
    put_col(J, 0, 2, l * u3)
    put_col(J, 0, 3, -bp * n3t_4)
    put_col(J, 0, 4, -bp * n3t_5)
    # d2(n~3)/dt2 at zero theta'': n~3 is body-fixed, so it is wbias x n~3 + omega x (omega x n~3).
    n3t_bias = _cross(wbias, n3t) + _cross(omega, _cross(omega, n3t))
    dbias = l * ubias - bp * n3t_bias
    return u, R, r, V, G, vbias, wbias, d, J, dbias


@njit(cache=True)
def inertia_world(R, p):
    """Inertia about R* in world axes (kg m^2)."""
    Ib = p[11:20].copy().reshape((3, 3))
    return _mm(_mm(R, Ib), R.T.copy())


@njit(cache=True)
def air_terms(R, v, omega, p):
    """The air's M_A,w (6x6, world, about R*), its velocity terms b (the fluid's wrench is
    -(M_A,w [acc; alpha] + b) plus the drag) and the drag wrench (F; G about R*, world)."""
    ma = p[24:60].copy().reshape((6, 6))
    rot6 = np.zeros((6, 6))
    put2(rot6, 0, 0, R)
    put2(rot6, 3, 3, R)
    maw = _mm(_mm(rot6, ma), rot6.T.copy())
    x = np.concatenate((v, omega))
    h = _mv(maw, x)  # [P; L]
    spin = np.zeros(6)
    put(spin, 0, _cross(omega, v))
    b = -_mv(maw, spin)  # d(M_A,w)/dt x = Omega M_A,w x - M_A,w Omega x
    add(b, 0, _cross(omega, h[:3]))
    add(b, 3, _cross(omega, h[3:]) + _cross(v, h[:3]))
    axes = _mm(R, p[63:72].copy().reshape((3, 3)))
    c = _mv(R, p[60:63].copy())
    f_e, g_e = drag_wrench(_mv(axes.T.copy(), v + _cross(omega, c)), _mv(axes.T.copy(), omega), p[72:80])
    drag = np.empty(6)
    put(drag, 0, _mv(axes, f_e))
    put(drag, 3, _mv(axes, g_e) + _cross(c, drag[:3]))
    return maw, b, drag


@njit(cache=True)
def eom(th, dth, p, chart):
    """M5 and N5 of (5.1.30): rows 1-4 are Kane's equations F_r + F_r* = 0, row 5 the loop closure
    differentiated twice (beta^T theta'' = -d2g/dt2 at zero theta'')."""
    u, R, r, V, G, vbias, wbias, d, J, dbias = kinematics(th, dth, p, chart)
    m, g = p[P_M], p[P_G]
    beta = 2.0 * _mv(J.T.copy(), d)  # (5.1.3)
    gamma = -beta[:4] / beta[4]  # (5.1.4)
    # Partial velocities with theta5' eliminated: V_new (5.1.21), G_new (5.1.19).
    Vn = V[:, :4].copy()
    Gn = G[:, :4].copy()
    for i in range(3):
        for j in range(4):
            Vn[i, j] += V[i, 4] * gamma[j]
            Gn[i, j] += G[i, 4] * gamma[j]
    Iw = inertia_world(R, p)
    omega = _mv(G, dth)
    M5 = np.empty((5, 5))
    N5 = np.empty(5)
    VnT, GnT = Vn.T.copy(), Gn.T.copy()
    put2(M5, 0, 0, m * _mm(VnT, V) + _mm(GnT, _mm(Iw, G)))
    weight = np.array([0.0, 0.0, m * g])
    Iw_omega = _mv(Iw, omega)
    put(N5, 0, -_mv(VnT, m * vbias + weight) - _mv(GnT, _mv(Iw, wbias) + _cross(omega, Iw_omega)))
    if p[P_AIR] != 0.0:
        maw, b, drag = air_terms(R, _mv(V, dth), omega, p)
        P6 = np.vstack((V, G))
        Pn6T = np.vstack((Vn, Gn)).T.copy()
        add2(M5, 0, 0, _mm(Pn6T, _mm(maw, P6)))
        add(N5, 0, _mv(Pn6T, drag - b - _mv(maw, np.concatenate((vbias, wbias)))))
    put(M5[4], 0, beta)
    ddot = _mv(J, dth)
    N5[4] = -2.0 * (ddot @ ddot + d @ dbias)
    return M5, N5


@njit(cache=True)
def rhs(y, p, chart):
    """First-order form y = (theta, theta') -> y', theta'' from M5 theta'' = N5 (:func:`eom`)."""
    M5, N5 = eom(y[:5], y[5:], p, chart)
    out = np.empty(10)
    put(out, 0, y[5:])
    put(out, 5, _solve(M5, N5))
    return out


@njit(cache=True)
def pose(th, p, chart):
    """COM position (world, m) and n~ frame for angles theta."""
    u, _, _, _, _, _ = wire_direction(th[1], th[2], chart)
    R = body_frame(th[0], th[3], th[4])
    rho = np.array([p[P_R] * p[P_SLAM], 0.0, -p[P_R] * p[P_CLAM]])
    c = p[20:23] + p[P_L] * u
    return c + _mv(R, rho), R


@njit(cache=True)
def loads(th, dth, p, chart):
    """Wire tensions T1 (BC), T2 (DA) in N, from Newton-Euler with the model's accelerations.

    The thesis (7.2) solves two of the three force equations; with parallel wires these cannot tell
    the wires apart, so all six Newton-Euler equations about R* are solved in the least-squares
    sense (moment rows divided by b' to share the force rows' units). Also returns the COM
    acceleration and angular acceleration (world frame) and the residual of the fit (N).
    """
    u, R, r, V, G, vbias, wbias, d, J, dbias = kinematics(th, dth, p, chart)
    M5, N5 = eom(th, dth, p, chart)
    dd = _solve(M5, N5)
    m, g, bp = p[P_M], p[P_G], p[P_BP]
    acc = _mv(V, dd) + vbias
    alpha = _mv(G, dd) + wbias
    omega = _mv(G, dth)
    Iw = inertia_world(R, p)
    e1 = -u  # from C towards B
    e2 = -d / np.sqrt(d @ d)  # from D towards A
    arm_c = -r  # R* -> C
    arm_d = -r - bp * R[:, 2]  # R* -> D = R* -> C + CD
    A = np.empty((6, 2))
    put_col(A, 0, 0, e1)
    put_col(A, 0, 1, e2)
    put_col(A, 3, 0, _cross(arm_c, e1) / bp)
    put_col(A, 3, 1, _cross(arm_d, e2) / bp)
    rhs_ = np.empty(6)
    put(rhs_, 0, m * acc + np.array([0.0, 0.0, m * g]))
    put(rhs_, 3, _mv(Iw, alpha) + _cross(omega, _mv(Iw, omega)))
    if p[P_AIR] != 0.0:  # the wires carry what the air does not: minus the fluid's wrench
        maw, b, drag = air_terms(R, _mv(V, dth), omega, p)
        rhs_ += _mv(maw, np.concatenate((acc, alpha))) + b - drag
    for k in range(3, 6):
        rhs_[k] /= bp
    At = A.T.copy()
    tension = _solve(_mm(At, A), _mv(At, rhs_))
    res = _mv(A, tension) - rhs_
    return tension, acc, alpha, np.sqrt(res @ res)


@njit(cache=True)
def observe(Y, p, chart):
    """Observables at each row of Y = (theta, theta'): COM, n~ frame, COM velocity, angular velocity
    (world frame), tensions (N), length error of wire 2 (m; wire 1 is exact by construction) and
    total energy (J, zero potential at z = 0; with air, the fluid's kinetic energy included)."""
    n = Y.shape[0]
    com = np.empty((n, 3))
    frames = np.empty((n, 3, 3))
    vel = np.empty((n, 3))
    omg = np.empty((n, 3))
    tension = np.empty((n, 2))
    err2 = np.empty(n)
    energy = np.empty(n)
    m, g = p[P_M], p[P_G]
    for i in range(n):
        th, dth = Y[i, :5].copy(), Y[i, 5:].copy()
        u, R, r, V, G, vbias, wbias, d, J, dbias = kinematics(th, dth, p, chart)
        c, _ = pose(th, p, chart)
        put(com[i], 0, c)
        put2(frames[i], 0, 0, R)
        put(vel[i], 0, _mv(V, dth))
        put(omg[i], 0, _mv(G, dth))
        put(tension[i], 0, loads(th, dth, p, chart)[0])
        err2[i] = np.sqrt(d @ d) - p[P_LP]
        Iw = inertia_world(R, p)
        energy[i] = 0.5 * m * (vel[i] @ vel[i]) + 0.5 * (omg[i] @ _mv(Iw, omg[i])) + m * g * c[2]
        if p[P_AIR] != 0.0:  # plus the fluid's kinetic energy 1/2 x^T M_A,w x
            x = np.concatenate((vel[i], omg[i]))
            energy[i] += 0.5 * (x @ _mv(air_terms(R, vel[i], omg[i], p)[0], x))
    return com, frames, vel, omg, tension, err2, energy


def announce() -> None:
    """Say in one line if the kernels are about to be compiled (:func:`bifilar.jit.announce_compile`)."""
    announce_compile("the Kane kernels", rhs, observe, loads, eom, pose)
