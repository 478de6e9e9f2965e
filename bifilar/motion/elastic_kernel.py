"""Compiled Newton-Euler equations of a rigid body on N elastic wires: the wires are force elements.

State y (13) as in :mod:`bifilar.motion.nwire_kernel`: COM c (world, m), unit quaternion q (body ->
world, scalar first), COM velocity v (world, m/s), angular velocity omega (world, rad/s). Per wire i:
arm s_i = R r_i, span d_i = a_i - c - s_i, distance rho_i = |d_i|, direction u_i = d_i / rho_i, and

    t_i = k_i max(0, rho_i - L_i),   k_i = EA_i / L_i   (a wire never pushes),

    m v'       = -m g e_z + sum t_i u_i,
    I_w omega' = -omega x I_w omega + sum s_i x t_i u_i,      I_w = R I_b R^T

(docs/elastic-wires.md). No constraint, no multiplier: the tensions follow from the pose alone. With
``[air]`` the fluid's added mass joins the mass matrix and its drag the applied wrench, exactly as in
the inextensible kernel. The energy adds each wire's strain energy (k_i / 2) max(0, rho_i - L_i)^2.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from bifilar.motion.kane_kernel import P_AIR as AIR_FLAG
from bifilar.motion.kane_kernel import air_terms
from bifilar.motion.nwire_kernel import STATE_SIZE, quat_matrix, state_rate
from bifilar.smallmat import cross as _cross
from bifilar.smallmat import mm as _mm
from bifilar.smallmat import mv as _mv
from bifilar.smallmat import add, add2, put, put2


@njit(cache=True)
def _dot(a, b):
    """a . b with a loop: numba sends a 1-D ``@`` to BLAS, a call (and a compile) dearer than the sum."""
    acc = 0.0
    for k in range(a.shape[0]):
        acc += a[k] * b[k]
    return acc


@njit(cache=True)
def dynamics(y, arms, anchors, lengths, springs, inertia_body, mass, gravity, air):
    """(nu', tensions, stretch): accelerations (v', omega'), tensions (N) and rho_i - L_i (m) at y."""
    n = arms.shape[0]
    c, v, om = y[0:3], y[7:10], y[10:13]
    rot = quat_matrix(y[3:7])
    iw = _mm(_mm(rot, inertia_body), rot.T.copy())
    f = np.zeros(6)
    f[2] = -mass * gravity
    put(f, 3, -_cross(om, _mv(iw, om)))
    tension = np.empty(n)
    stretch = np.empty(n)
    for i in range(n):
        s = _mv(rot, arms[i])
        d = anchors[i] - c - s
        rho = np.sqrt(_dot(d, d))
        stretch[i] = rho - lengths[i]
        tension[i] = springs[i] * stretch[i] if stretch[i] > 0.0 else 0.0
        pull = tension[i] * d / rho
        add(f, 0, pull)
        add(f, 3, _cross(s, pull))
    if air[AIR_FLAG] != 0.0:
        maw, bias, drag = air_terms(rot, v, om, air)
        m6 = maw.copy()
        for k in range(3):
            m6[k, k] += mass
        add2(m6, 3, 3, iw)
        acc = np.linalg.solve(m6, f + drag - bias)
    else:
        acc = np.empty(6)
        put(acc, 0, f[:3] / mass)
        put(acc, 3, np.linalg.solve(iw, f[3:]))
    return acc, tension, stretch


@njit(cache=True)
def rhs(y, arms, anchors, lengths, springs, inertia_body, mass, gravity, air):
    """y'; q' = (1/2) (0, omega) * q (world omega)."""
    return state_rate(y, dynamics(y, arms, anchors, lengths, springs, inertia_body, mass, gravity, air)[0])


@njit(cache=True)
def observe(Y, arms, anchors, lengths, springs, inertia_body, mass, gravity, air):
    """Per sample: rotation matrix, tensions (N), stretch rho - L (m) and energy (J: kinetic, gravity
    with zero at z = 0, strain; with air the fluid's kinetic energy)."""
    n_s, n = Y.shape[0], arms.shape[0]
    frames = np.empty((n_s, 3, 3))
    ten = np.empty((n_s, n))
    stretch = np.empty((n_s, n))
    energy = np.empty(n_s)
    for k in range(n_s):
        y = Y[k]
        rot = quat_matrix(y[3:7])
        put2(frames[k], 0, 0, rot)
        _, ten_k, stretch_k = dynamics(y, arms, anchors, lengths, springs, inertia_body, mass, gravity, air)
        put(ten[k], 0, ten_k)
        put(stretch[k], 0, stretch_k)
        om, v = y[10:13], y[7:10]
        iw = _mm(_mm(rot, inertia_body), rot.T.copy())
        energy[k] = 0.5 * mass * _dot(v, v) + 0.5 * _dot(om, _mv(iw, om)) + mass * gravity * y[2]
        for i in range(n):
            if stretch[k, i] > 0.0:
                energy[k] += 0.5 * springs[i] * stretch[k, i] ** 2
        if air[AIR_FLAG] != 0.0:
            x = np.concatenate((v, om))
            energy[k] += 0.5 * _dot(x, _mv(air_terms(rot, v, om, air)[0], x))
    return frames, ten, stretch, energy
