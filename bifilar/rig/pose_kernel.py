"""Compiled geometry of a rigid body on N inextensible wires, in pose coordinates.

A pose is the COM position c (world, m) and the rotation R (body -> world). Small displacements are
q = (x, theta): c = c0 + x and R = exp([theta]x) R0 (theta a rotation vector in the world frame), so
that at q = 0 the velocities are (c', omega) = q'. Wire i runs from the anchor a_i (world) to the
attachment p_i = c + R r_i (r_i: attachment minus COM, body frame); its arm is s_i = R r_i, its length
rho_i = |a_i - p_i| and its direction towards the anchor u_i = (a_i - p_i) / rho_i.

To first order dp_i = dx - [s_i]x dtheta, so the constraint g_i = rho_i - L_i has the gradient

    grad g_i = [-u_i^T, (u_i x s_i)^T],

and to second order, with the second-order term (1/2)[theta]x^2 s_i of the exponential map,

    hess g_i = P_i^T (I - u_i u_i^T) P_i / rho_i - blockdiag(0, (u_i s_i^T + s_i u_i^T) / 2 - (u_i . s_i) I),

P_i = [I, -[s_i]x]. A wire of tension t_i pulls the body with t_i u_i; the equilibrium of the weight
W = m g (along world -z) is the stationary point of the Lagrangian W c_z + sum t_i g_i, whose Hessian
restricted to the null space Z of the constraint gradients is the stiffness of small oscillations:
K = Z^T (sum t_i hess g_i) Z (the potential W c_z is linear in q). Nothing here passes through angles,
so no pose is a coordinate singularity. Everything is derived in ``docs/pose-coordinates.md``.
"""

from __future__ import annotations

import numba as nb
import numpy as np

from bifilar.smallmat import cross, mm, put, put2, put_col


@nb.njit(cache=True)
def cross_matrix(v):
    """[v]x, the matrix of v x (.)."""
    out = np.zeros((3, 3))
    out[0, 1], out[0, 2] = -v[2], v[1]
    out[1, 0], out[1, 2] = v[2], -v[0]
    out[2, 0], out[2, 1] = -v[1], v[0]
    return out


@nb.njit(cache=True)
def rotation_vector_matrix(theta):
    """exp([theta]x) by Rodrigues' formula (series near zero)."""
    angle = np.sqrt(theta[0] ** 2 + theta[1] ** 2 + theta[2] ** 2)
    k = cross_matrix(theta)
    if angle < 1e-8:
        a, b = 1.0, 0.5
    else:
        a, b = np.sin(angle) / angle, (1.0 - np.cos(angle)) / angle**2
    out = np.empty((3, 3))
    for r in range(3):
        for c in range(3):
            kk = k[r, 0] * k[0, c] + k[r, 1] * k[1, c] + k[r, 2] * k[2, c]
            out[r, c] = (1.0 if r == c else 0.0) + a * k[r, c] + b * kk
    return out


@nb.njit(cache=True)
def wire_geometry(com, rot, arms, anchors):
    """Per wire: arm s_i = R r_i (world), direction u_i to the anchor and distance rho_i (written out:
    these 3-vectors are too small for BLAS calls to pay)."""
    n = arms.shape[0]
    s = np.empty((n, 3))
    u = np.empty((n, 3))
    rho = np.empty(n)
    for i in range(n):
        for r in range(3):
            s[i, r] = rot[r, 0] * arms[i, 0] + rot[r, 1] * arms[i, 1] + rot[r, 2] * arms[i, 2]
            u[i, r] = anchors[i, r] - com[r] - s[i, r]
        rho[i] = np.sqrt(u[i, 0] ** 2 + u[i, 1] ** 2 + u[i, 2] ** 2)
        for r in range(3):
            u[i, r] /= rho[i]
    return s, u, rho


@nb.njit(cache=True)
def constraint_jacobian(s, u):
    """Rows grad g_i = [-u_i, u_i x s_i] (N x 6)."""
    n = s.shape[0]
    jac = np.empty((n, 6))
    for i in range(n):
        jac[i, 0], jac[i, 1], jac[i, 2] = -u[i, 0], -u[i, 1], -u[i, 2]
        jac[i, 3] = u[i, 1] * s[i, 2] - u[i, 2] * s[i, 1]
        jac[i, 4] = u[i, 2] * s[i, 0] - u[i, 0] * s[i, 2]
        jac[i, 5] = u[i, 0] * s[i, 1] - u[i, 1] * s[i, 0]
    return jac


@nb.njit(cache=True)
def constraint_hessian(s, u, rho, i):
    """hess g_i in q = (x, theta) at q = 0 (6 x 6, symmetric), written out in blocks:
    with A = (I - u u^T) / rho and S = [s]x, P^T A P = [[A, -A S], [S A, -S A S]]."""
    a = _projector(u, rho, i)
    sx = cross_matrix(s[i])
    a_s = np.zeros((3, 3))
    s_a_s = np.zeros((3, 3))
    for r in range(3):
        for c in range(3):
            for k in range(3):
                a_s[r, c] += a[r, k] * sx[k, c]
    for r in range(3):
        for c in range(3):
            for k in range(3):
                s_a_s[r, c] += sx[r, k] * a_s[k, c]
    us = u[i, 0] * s[i, 0] + u[i, 1] * s[i, 1] + u[i, 2] * s[i, 2]
    h = np.empty((6, 6))
    for r in range(3):
        for c in range(3):
            h[r, c] = a[r, c]
            h[r, 3 + c] = -a_s[r, c]
            h[3 + c, r] = -a_s[r, c]  # (S A)^T = -A S: S A = (-A S)^T
            h[3 + r, 3 + c] = -s_a_s[r, c] - 0.5 * (u[i, r] * s[i, c] + s[i, r] * u[i, c])
        h[3 + r, 3 + r] += us
    return h


@nb.njit(cache=True)
def equilibrium_balance(com, rot, tensions, arms, anchors, lengths, weight, scale):
    """The residual of :func:`equilibrium_residual` alone (6 + N), without its Jacobian."""
    s, u, rho = wire_geometry(com, rot, arms, anchors)
    return _balance(s, u, rho, tensions, lengths, weight, scale)


@nb.njit(cache=True)
def _balance(s, u, rho, tensions, lengths, weight, scale):
    """Force balance / W, moment balance / (W scale) and length errors / scale from the wire geometry."""
    n = s.shape[0]
    res = np.zeros(6 + n)
    res[2] = -1.0
    for i in range(n):
        t = tensions[i] / weight
        res[0] += t * u[i, 0]
        res[1] += t * u[i, 1]
        res[2] += t * u[i, 2]
        res[3] += t * (s[i, 1] * u[i, 2] - s[i, 2] * u[i, 1]) / scale
        res[4] += t * (s[i, 2] * u[i, 0] - s[i, 0] * u[i, 2]) / scale
        res[5] += t * (s[i, 0] * u[i, 1] - s[i, 1] * u[i, 0]) / scale
        res[6 + i] = (rho[i] - lengths[i]) / scale
    return res


@nb.njit(cache=True)
def _projector(u, rho, i):
    """(I - u_i u_i^T) / rho_i, written out (``np.eye`` and ``np.outer`` cost more to compile than the
    nine products; the same arithmetic)."""
    a = np.empty((3, 3))
    for r in range(3):
        for c in range(3):
            a[r, c] = ((1.0 if r == c else 0.0) - u[i, r] * u[i, c]) / rho[i]
    return a


@nb.njit(cache=True)
def equilibrium_residual(com, rot, tensions, arms, anchors, lengths, weight, scale):
    """Force balance / W, moment balance about the COM / (W scale) and length errors / scale
    (6 + N), and its Jacobian with respect to (x, theta, t / W)."""
    n = arms.shape[0]
    s, u, rho = wire_geometry(com, rot, arms, anchors)
    res = _balance(s, u, rho, tensions, lengths, weight, scale)
    jac = np.zeros((6 + n, 6 + n))
    for i in range(n):
        t = tensions[i] / weight
        # du = -(I - u u^T) / rho dp,  dp = dx - [s]x dtheta,  ds = dtheta x s = -[s]x dtheta
        proj = _projector(u, rho, i)
        sx = cross_matrix(s[i])
        du_dth = mm(proj, sx)
        # d(s x u) = ds x u + s x du = [u]x [s]x dtheta + [s]x du
        s_du_dx = mm(sx, -proj)
        turn = mm(cross_matrix(u[i]), sx) + mm(sx, du_dth)
        for r in range(3):
            for c in range(3):
                jac[r, c] += t * -proj[r, c]
                jac[r, 3 + c] += t * du_dth[r, c]
                jac[3 + r, c] += t * s_du_dx[r, c] / scale
                jac[3 + r, 3 + c] += t * turn[r, c] / scale
            jac[r, 6 + i] = u[i, r]
            jac[6 + i, r] = -u[i, r] / scale
        put_col(jac, 3, 6 + i, cross(s[i], u[i]) / scale)
        put(jac[6 + i], 3, cross(u[i], s[i]) / scale)
    return res, jac


@nb.njit(cache=True)
def newton_equilibrium(com, rot, tensions, arms, anchors, lengths, weight, scale, max_iter):
    """Newton's method on :func:`equilibrium_residual` from a guess. Returns the pose, the tensions,
    the final max-norm residual and the number of iterations (max_iter + 1 if it did not converge)."""
    com = com.copy()
    rot = rot.copy()
    t = tensions / weight
    n = arms.shape[0]
    best = np.inf
    for it in range(max_iter):
        res, jac = equilibrium_residual(com, rot, t * weight, arms, anchors, lengths, weight, scale)
        err = np.abs(res).max()
        if err < 1e-14:
            return com, rot, t * weight, err, it
        if not np.isfinite(err) or err > 1e6 * min(best, 1.0) + 1.0:
            break
        best = min(best, err)
        # Least squares: the minimum-norm step where the Jacobian is singular (a neutral tilt
        # about the line of two attachments), Newton's step elsewhere.
        step = np.linalg.lstsq(jac, -res, 1e-13)[0]
        finite = True
        for v in step:
            finite = finite and np.isfinite(v)
        if not finite:
            break
        # Limit the turn and the shift per step: Newton far from the solution may jump to the
        # inverted equilibrium; a damped step keeps it in the basin it started in.
        shift = step[0] * step[0] + step[1] * step[1] + step[2] * step[2]
        turn = step[3] * step[3] + step[4] * step[4] + step[5] * step[5]
        shrink = max(1.0, np.sqrt(turn) / 0.2, np.sqrt(shift) / (0.2 * scale))
        step /= shrink
        com += step[:3]
        rot = mm(rotation_vector_matrix(step[3:6]), rot)
        t += step[6 : 6 + n]
    res, jac = equilibrium_residual(com, rot, t * weight, arms, anchors, lengths, weight, scale)
    return com, rot, t * weight, np.abs(res).max(), max_iter + 1


@nb.njit(cache=True)
def reduced_matrices(com, rot, tensions, arms, anchors, inertia_body, mass, scale, null_tol):
    """Small oscillations about an equilibrium pose: the null-space basis Z (6 x n) of the wire
    constraints, the mass matrix Z^T diag(m I, R I R^T) Z and the stiffness Z^T (sum t_i hess g_i) Z.

    Z comes from the SVD of the constraint Jacobian with its rotation columns multiplied by the rig
    size ``scale`` (m), so that both halves are lengths: directions whose singular value is below
    ``null_tol`` times the largest are free; ``rank`` is the number of independent constraints.
    """
    n = arms.shape[0]
    s, u, rho = wire_geometry(com, rot, arms, anchors)
    jac = constraint_jacobian(s, u)
    for r in range(jac.shape[0]):
        for c in range(3, 6):
            jac[r, c] /= scale
    _, sv, vt = np.linalg.svd(jac)
    rank = 0
    for k in range(sv.shape[0]):
        if sv[k] > null_tol * sv[0]:
            rank += 1
    z = np.ascontiguousarray(vt[rank:, :].T)
    for r in range(3, 6):
        for c in range(z.shape[1]):
            z[r, c] /= scale
    m6 = np.zeros((6, 6))
    for k in range(3):
        m6[k, k] = mass
    put2(m6, 3, 3, mm(mm(rot, inertia_body), rot.T.copy()))
    k6 = np.zeros((6, 6))
    for i in range(n):
        k6 += tensions[i] * constraint_hessian(s, u, rho, i)
    zt = z.T.copy()
    mr = mm(mm(zt, m6), z)
    kr = mm(mm(zt, k6), z)
    return z, 0.5 * (mr + mr.T), 0.5 * (kr + kr.T), rank
