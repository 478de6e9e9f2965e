"""Compiled period sensitivities: d ln T / d x_i of a measured mode for every measured input of a rig.

This is the inner loop of :func:`bifilar.identification.propagation.linear_axes`, the one path by which
``identify`` and sweeps propagate a rig file's ``[uncertainty]``. For each input x_i (a wire length, an
anchor or attachment coordinate, the mass, a COM coordinate; the order of
:func:`bifilar.identification.propagation.inputs`) the rig is changed by a forward step h_i and

1. the rest pose is continued from the base one by two chord-Newton steps on the equilibrium
   equations (:func:`bifilar.rig.pose_kernel.equilibrium_residual`) with the base Jacobian factored
   once: the residual of the base pose in the changed rig is O(h), so two steps leave O(h^3), far
   below the O(h) truncation of the forward difference;
2. the changed mode's omega^2 is the Rayleigh quotient p^T K p / p^T M p of the base mode's pose shape
   q projected (p) onto the changed rig's tangent space (the null space of its constraint gradients), with
   K = sum t_i hess g_i and M = diag(m I, R I R^T) (+ the air's added mass) of the changed rest pose.
   The Rayleigh quotient is stationary at an eigenvector, so a trial vector O(h) off the changed
   eigenvector errs by O(h^2) in omega^2: again below the forward difference's own O(h). The base
   quotient is computed by the same arithmetic, so the difference carries no rounding offset.

The same steps with a fresh eigen-solution per input and a full Newton solve agree to ~1e-6 of the
slope (tests/test_propagation_slopes.py). Where the base equilibrium Jacobian is singular (a neutral tilt
about the line of two attachments) the continuation is not unique and the caller uses the general path.
"""

from __future__ import annotations

import numba as nb
import numpy as np

from bifilar.rig import pose_kernel
from bifilar.smallmat import inverse, mm, mv, put, put2

_SINGULAR = 1e-10  # smallest / largest singular value of the equilibrium Jacobian treated as singular
_CHORD_STEPS = 2
_CHORD_RESIDUAL = 1e-9  # max-norm residual (forces / weight, lengths / rig size) after the chord steps


@nb.njit(cache=True)
def unpack(x, n_wires):
    """Lengths, anchors (world), arms (attachment minus COM, body) and mass from an input vector."""
    lengths = np.empty(n_wires)
    anchors = np.empty((n_wires, 3))
    attach = np.empty((n_wires, 3))
    j = 0
    for i in range(n_wires):
        lengths[i] = x[j]
        put(anchors[i], 0, x[j + 1 : j + 4])
        put(attach[i], 0, x[j + 4 : j + 7])
        j += 7
    mass = x[j]
    arms = attach - x[j + 1 : j + 4]
    return lengths, anchors, arms, mass


@nb.njit(cache=True)
def tangent_matrices(com, rot, tensions, arms, anchors, mass):
    """(J, K6, M6 translation part): the constraint gradients (N x 6) and the Lagrangian's Hessian
    sum t_i hess g_i (6 x 6) at a pose."""
    s, u, rho = pose_kernel.wire_geometry(com, rot, arms, anchors)
    jac = pose_kernel.constraint_jacobian(s, u)
    k6 = np.zeros((6, 6))
    for i in range(arms.shape[0]):
        k6 += tensions[i] * pose_kernel.constraint_hessian(s, u, rho, i)
    return jac, k6


@nb.njit(cache=True)
def mass_matrix(rot, inertia, mass, air_body, air):
    """diag(m I, R I R^T), plus with ``air`` the air's added mass (body-frame 6 x 6 about the COM)
    turned to the world."""
    m6 = np.zeros((6, 6))
    for k in range(3):
        m6[k, k] = mass
    for r in range(3):
        for c in range(3):
            acc = 0.0
            for k in range(3):
                for l in range(3):
                    acc += rot[r, k] * inertia[k, l] * rot[c, l]
            m6[3 + r, 3 + c] = acc
    if air:
        rot6 = np.zeros((6, 6))
        put2(rot6, 0, 0, rot)
        put2(rot6, 3, 3, rot)
        m6 += mm(mm(rot6, air_body), rot6.T.copy())
    return m6


@nb.njit(cache=True)
def projector(jac):
    """I - J^T (J J^T)^-1 J: the projection (6 x 6) onto the null space of the constraint gradients.
    The products are :mod:`bifilar.smallmat`'s loops: numba's ``@`` compiles a BLAS path per operand
    layout, and J^T is another layout than J; (J J^T)^-1 too (a LAPACK solve with a matrix right-hand side
    compiles its own wrapper: see :mod:`bifilar.smallmat`)."""
    jac_t = jac.T.copy()
    out = -mm(jac_t, mm(inverse(mm(jac, jac_t)), jac))
    for k in range(6):
        out[k, k] += 1.0
    return out


@nb.njit(cache=True)
def rayleigh(proj, k6, m6, q):
    """p^T K p / p^T M p with p = ``proj`` q, the shape q moved onto the tangent space."""
    p = mv(proj, q)
    num = 0.0
    den = 0.0
    for r in range(6):
        for c in range(6):
            num += p[r] * k6[r, c] * p[c]
            den += p[r] * m6[r, c] * p[c]
    return num / den


@nb.njit(cache=True)
def period_slopes(x, h, n_wires, gravity, scale, com0, rot0, t0, inertias, shapes, air_base, air_com):
    """d ln T / d x_i (axes x inputs) of the modes with pose shapes ``shapes`` (one per axis, world
    (x, theta)), each with the rig's inertia ``inertias[a]`` (body, about the COM), for forward steps
    ``h`` (0: input not varied, slope 0). ``air_base``: the body-frame added mass about the COM (zeros
    in a vacuum); ``air_com[k]``: the same with COM coordinate k stepped. Returns (slopes, ok); ok is
    False where the base equilibrium Jacobian is singular or a chord continuation did not converge."""
    n_axes = shapes.shape[0]
    n_in = x.shape[0]
    has_air = np.abs(air_base).max() > 0.0
    out = np.zeros((n_axes, n_in))
    lengths, anchors, arms, mass = unpack(x, n_wires)
    weight = mass * gravity
    _, jac_eq = pose_kernel.equilibrium_residual(com0, rot0, t0, arms, anchors, lengths, weight, scale)
    sv = np.linalg.svd(jac_eq)[1]
    if not sv[-1] > _SINGULAR * sv[0]:
        return out, False
    inv_eq = inverse(jac_eq)  # a loop inverse (bifilar.smallmat): numba's inv compiles another LAPACK wrapper
    jac, k6 = tangent_matrices(com0, rot0, t0, arms, anchors, mass)
    proj = projector(jac)
    base = np.empty(n_axes)
    for a in range(n_axes):
        base[a] = rayleigh(proj, k6, mass_matrix(rot0, inertias[a], mass, air_base, has_air), shapes[a])
    com_at = 7 * n_wires + 1  # index of the first COM coordinate in x
    for i in range(n_in):
        if h[i] == 0.0:
            continue
        xi = x.copy()
        xi[i] += h[i]
        lengths, anchors, arms, mass = unpack(xi, n_wires)
        weight = mass * gravity
        com, rot, tn = com0.copy(), rot0.copy(), t0 / weight
        for _ in range(_CHORD_STEPS):
            res = pose_kernel.equilibrium_balance(com, rot, tn * weight, arms, anchors, lengths, weight, scale)
            step = -mv(inv_eq, res)
            com += step[:3]
            rot = mm(pose_kernel.rotation_vector_matrix(step[3:6]), rot)
            tn += step[6:]
        res = pose_kernel.equilibrium_balance(com, rot, tn * weight, arms, anchors, lengths, weight, scale)
        if not np.abs(res).max() < _CHORD_RESIDUAL:
            return out, False
        jac, k6 = tangent_matrices(com, rot, tn * weight, arms, anchors, mass)
        proj = projector(jac)
        air = air_com[i - com_at] if com_at <= i < com_at + 3 else air_base
        for a in range(n_axes):
            w2 = rayleigh(proj, k6, mass_matrix(rot, inertias[a], mass, air, has_air), shapes[a])
            out[a, i] = -0.5 * (np.log(w2) - np.log(base[a])) / h[i]
    return out, True
