"""Compiled core of one sweep configuration, continued from its neighbour's rest pose.

A sweep steps through neighbouring configurations, so each rest pose is a few Newton steps from the
previous one. :func:`continued_modes` does those steps (:func:`bifilar.rig.pose_kernel.newton_equilibrium`,
the Newton of :func:`bifilar.rig.statics.rest_pose`), checks the pose as ``rest_pose`` does (every wire
pulls, residual at machine precision, stable) and solves the small-oscillation problem of
:mod:`bifilar.motion.modes` (the same reduced M and K, eigen-solved as L^-1 K L^-T with M = L L^T), in
one compiled call. It hands back a status instead of raising: a configuration it cannot settle
cleanly -- Newton not converging from the neighbour, an unstable or neutral pose (a neutral tilt needs
the representative that ``rest_pose`` picks), or two modes of equal frequency (``linearize``
resolves their basis deterministically) -- is evaluated by the general path instead
(:func:`bifilar.sweep.evaluate.evaluate`), which is also the reference the tests hold this one to.

:func:`peak_tension` is the largest wire tension over the three states of each measured mode that
:mod:`bifilar.sweep.evaluate` describes, with the tensions of the N-wire model's kernel.
"""

from __future__ import annotations

import numba as nb
import numpy as np

from bifilar.motion import nwire_kernel as NK
from bifilar.motion.modes import resolution  # the neutral and degenerate tests of linearize
from bifilar.rig import pose_kernel
from bifilar.rig.statics import NEWTON_ITERATIONS, RESIDUAL  # the same Newton as rest_pose
from bifilar.smallmat import mm, mv  # loops: numba's `@` compiles a BLAS path per operand layout
from bifilar.smallmat import put

OK, NO_NEWTON, SLACK, NO_MODES, UNSTABLE, NEUTRAL, DEGENERATE = range(7)


@nb.njit(cache=True)
def continued_modes(arms, anchors, lengths, mass, gravity, inertia, scale, com, rot, tensions,
                    null_rtol, neutral_rtol, degenerate_rtol, slack_rtol):
    """(status, com, rotation, tensions, omega^2 ascending, shapes 6 x n): the rest pose found by Newton
    from (com, rot, tensions) and its modes, each shape the pose displacement (x, theta; world) of an
    M-normalised eigenvector. ``status`` is :data:`OK` or why the general path must take over."""
    empty = np.zeros(0)
    weight = mass * gravity
    # np.int64: a bare module-level int would be typed Literal[int] and compile newton_equilibrium
    # a second time, beside the int64 signature rest_pose already compiled.
    com, rot, tensions, residual, _ = pose_kernel.newton_equilibrium(
        com, rot, tensions, arms, anchors, lengths, weight, scale, np.int64(NEWTON_ITERATIONS))
    if not residual <= RESIDUAL:
        return NO_NEWTON, com, rot, tensions, empty, np.zeros((6, 0))
    if tensions.min() <= 0.0:
        return SLACK, com, rot, tensions, empty, np.zeros((6, 0))
    z, mr, kr, _ = pose_kernel.reduced_matrices(com, rot, tensions, arms, anchors, inertia, mass, scale, null_rtol)
    n = z.shape[1]
    if n == 0:
        return NO_MODES, com, rot, tensions, empty, np.zeros((6, 0))
    chol_inv = np.linalg.inv(np.linalg.cholesky(mr))
    a = mm(mm(chol_inv, kr), chol_inv.T.copy())
    w2, y = np.linalg.eigh(0.5 * (a + a.T))
    big = max(np.abs(w2).max(), 1e-300)
    if w2[0] < -slack_rtol * big:
        return UNSTABLE, com, rot, tensions, w2, np.zeros((6, 0))
    if w2[0] <= resolution(gravity / scale, big, neutral_rtol):
        return NEUTRAL, com, rot, tensions, w2, np.zeros((6, 0))
    gap = resolution(gravity / scale, big, degenerate_rtol)
    for k in range(n - 1):
        if w2[k + 1] - w2[k] <= gap:
            return DEGENERATE, com, rot, tensions, w2, np.zeros((6, 0))
    return OK, com, rot, tensions, w2, mm(z, mm(chol_inv.T, y))


@nb.njit(cache=True)
def peak_tension(com, rot, shapes, omegas, springs, base, arms, anchors, inertia, mass, gravity, air):
    """Largest tension (N) over the modes ``shapes[k]`` (x, theta; world) of angular frequency
    ``omegas[k]`` (rad/s) and over their states: at rest with velocity omega * shape, and at rest
    displaced by +-shape without velocity.

    Elastic wires (``springs``, N/m; empty: inextensible; ``base``: the rest tensions, N): at the displaced
    states the elastic law to first order, base +- K J shape (exact for the fast modes, whose tension is
    their stretch, and the slow ones alike); at the moving state
    :func:`~bifilar.motion.nwire_kernel.compatible_tensions` (the centripetal part). The inextensible
    tensions are singular on four parallel wires (statically indeterminate; issue 35 item 5)."""
    y = np.zeros(NK.STATE_SIZE)
    peak = -np.inf
    for k in range(shapes.shape[0]):
        put(y, 0, com)
        put(y, 3, NK.matrix_quat(rot))
        put(y, 7, omegas[k] * shapes[k])
        if springs.size:
            peak = max(peak, NK.compatible_tensions(y, arms, anchors, inertia, mass, gravity, air, springs, base).max())
            stretch = springs * np.abs(mv(NK.dynamics_jacobian(y, arms, anchors), shapes[k]))
            peak = max(peak, (base + stretch).max())
            continue
        peak = max(peak, NK.dynamics(y, arms, anchors, inertia, mass, gravity, air)[1].max())
        for sign in (1.0, -1.0):
            put(y, 0, com + sign * shapes[k, :3])
            put(y, 3, NK.matrix_quat(mm(pose_kernel.rotation_vector_matrix(sign * shapes[k, 3:]), rot)))
            for j in range(7, 13):
                y[j] = 0.0
            peak = max(peak, NK.dynamics(y, arms, anchors, inertia, mass, gravity, air)[1].max())
    return peak
