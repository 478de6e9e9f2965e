"""Statics of a rigid body on elastic wires: the rest pose as the minimum of the potential energy.

A wire i with ``axial_stiffness`` EA_i and unstretched length L_i pulls with t_i = k_i (rho_i - L_i),
k_i = EA_i / L_i, while its anchor-attachment distance rho_i exceeds L_i, and with 0 when it does not.
The body is then free in all six directions and its potential (world z up, gravity -g e_z) is

    V(q) = W c_z + sum_i (k_i / 2) max(0, rho_i - L_i)^2,     W = m g.

In the pose coordinates q = (x, theta) of :mod:`bifilar.rig.pose_kernel` (c = c0 + x, R = exp([theta]x)
R0), rho_i has the gradient J_i = [-u_i^T, (u_i x s_i)^T] and the Hessian H_i (``constraint_hessian``),
so at q = 0

    grad V = W (e_z, 0) + sum_i t_i J_i^T,
    hess V = sum_taut k_i J_i^T J_i + sum_i t_i H_i,

the first term the wires' axial stiffness, the second the geometric stiffness of their tension (the
pendulum's restoring stiffness). The rest pose is the lowest minimum: a trust-region Newton iteration
(re-based at every step, so q = 0 always and both formulas are exact) from several starts, the
lowest stable result kept. Four parallel wires, statically indeterminate when inextensible, are
determined here by their stiffnesses. Derived in docs/elastic-wires.md.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from bifilar.rig import Rig, RigError
from bifilar.rig.pose_loops import PK  # the pose kernels, compiled only where they loop (bifilar.jit)

# Converged when every force and moment / S of the gradient is below GRADIENT_TOL W plus the rounding
# floor ROUNDING x (machine epsilon x S) x sum k_i: a distance rho ~ S is known to eps S, so a stiff wire's
# tension to k eps S (measured 1.2e-12 W on the quadrifilar, EA = 2e5 N: the floor, not the iteration).
GRADIENT_TOL = 1e-12
ROUNDING = 16.0
MAX_ITERATIONS = 300
# A stable rest pose: no eigenvalue of hess V below -this fraction of its largest.
STABLE_SLACK = 1e-12
# Wires stiffer than stretching by this fraction of the rig's size under the weight are settled by
# continuation in their stiffness, from wires this soft up by STIFFENING a step (see settle).
SOFT_STRETCH = 1e-3
STIFFENING = 100.0


def springs(rig: Rig) -> np.ndarray:
    """k_i = EA_i / L_i (N/m) per wire."""
    return np.array([w.axial_stiffness / w.length for w in rig.wires])


def wire_tensions(rig: Rig, rho: np.ndarray) -> np.ndarray:
    """Tensions (N) at anchor-attachment distances ``rho`` (m): k (rho - L) when stretched, else 0."""
    lengths = np.array([w.length for w in rig.wires])
    return springs(rig) * np.maximum(rho - lengths, 0.0)


def energy_terms(rig: Rig, com: np.ndarray, rotation: np.ndarray, arms: np.ndarray, anchors: np.ndarray):
    """(V, grad V, hess V, tensions) at the pose, in pose coordinates at q = 0 (module docstring)."""
    s, u, rho = PK.wire_geometry(np.asarray(com, float), np.asarray(rotation, float), arms, anchors)
    lengths = np.array([w.length for w in rig.wires])
    k = springs(rig)
    stretch = np.maximum(rho - lengths, 0.0)
    tension = k * stretch
    weight = rig.mass * rig.gravity
    jac = PK.constraint_jacobian(s, u)
    energy = weight * float(com[2]) + 0.5 * float(k @ stretch**2)
    grad = jac.T @ tension
    grad[2] += weight
    taut = stretch > 0.0
    hess = (jac[taut].T * k[taut]) @ jac[taut]
    for i in np.flatnonzero(taut):
        hess += tension[i] * PK.constraint_hessian(s, u, rho, i)
    return energy, grad, 0.5 * (hess + hess.T), tension


def stiffness(rig: Rig, com: np.ndarray, rotation: np.ndarray, arms: np.ndarray, anchors: np.ndarray) -> np.ndarray:
    """hess V (6 x 6, pose coordinates, world frame): the stiffness of small oscillations about a rest
    pose (the gradient vanishes there, so the chart's second-order terms do not enter)."""
    return energy_terms(rig, com, rotation, arms, anchors)[2]


def minimise(rig: Rig, com: np.ndarray, rotation: np.ndarray, arms: np.ndarray, anchors: np.ndarray, scale: float,
             fixed_rotation: bool = False):
    """Trust-region Newton on V from a pose; (com, rotation, tensions, converged). With
    ``fixed_rotation`` only the COM moves (the 3 x 3 block): the body held at its orientation."""
    weight = rig.mass * rig.gravity
    com, rotation = np.array(com, float), np.array(rotation, float)
    n = 3 if fixed_rotation else 6
    metric = np.array([1.0, 1.0, 1.0, scale, scale, scale])[:n]  # y = metric * q: both halves lengths
    radius = 0.1 * scale
    tol = GRADIENT_TOL * weight + ROUNDING * np.finfo(float).eps * scale * float(springs(rig).sum())
    energy, grad, hess, tension = energy_terms(rig, com, rotation, arms, anchors)
    for _ in range(MAX_ITERATIONS):
        g = grad[:n] / metric
        if np.abs(g).max() <= tol:
            return com, rotation, tension, True
        h = hess[:n, :n] / np.outer(metric, metric)
        step = _trust_step(g, h, radius)
        predicted = -(g @ step + 0.5 * step @ h @ step)
        q = step / metric
        trial_com = com + q[:3]
        trial_rot = rotation if fixed_rotation else PK.rotation_vector_matrix(q[3:6]) @ rotation
        trial = energy_terms(rig, trial_com, trial_rot, arms, anchors)
        actual = energy - trial[0]
        # Near the minimum the energy difference is rounding (|V| ~ W S): there a full Newton step on
        # a positive definite Hessian is taken on the gradient's word.
        rounding = predicted < 1e-13 * weight * scale
        ratio = actual / predicted if predicted > 0.0 else -1.0
        if ratio > 0.1 or (rounding and np.abs(trial[1][:n] / metric).max() < np.abs(g).max()):
            com, rotation = trial_com, trial_rot
            energy, grad, hess, tension = trial
            if ratio > 0.75 and np.linalg.norm(step) > 0.8 * radius:
                radius = min(2.0 * radius, scale)
        else:
            radius = 0.25 * np.linalg.norm(step)
            if radius < 1e-16 * scale:
                break
    return com, rotation, tension, False


def settle(rig: Rig, com: np.ndarray, rotation: np.ndarray, arms: np.ndarray, anchors: np.ndarray, scale: float,
           fixed_rotation: bool = False):
    """:func:`minimise` from a pose (``fixed_rotation``: the COM alone), continued in the wires' stiffness:
    (com, rotation, tensions, converged).

    Why: V's valley across the wires' directions is ~W / sum k wide, ~1e-9 m at E A = 1e10 N, and a wire
    slack on one side of it and taut on the other: from a start a visible distance away the trust region
    shrank onto that kink and stopped (a four-wire platform at E A = 1e10 N: "no stable rest pose", where
    1e6 N settled; issue 35 item 5). Wires stiffer than stretching by :data:`SOFT_STRETCH` of the rig's
    size are first settled that soft, then stiffened :data:`STIFFENING` times a step, each step's pose the
    next one's start (a stretch away from it), up to their own stiffness; softer wires go straight on."""
    weight = rig.mass * rig.gravity
    soft = weight / (float(springs(rig).sum()) * SOFT_STRETCH * scale)
    factors = []
    while soft < 1.0:
        factors.append(soft)
        soft *= STIFFENING
    for factor in factors:
        softer = replace(rig, wires=tuple(replace(w, axial_stiffness=w.axial_stiffness * factor) for w in rig.wires))
        com, rotation, _, ok = minimise(softer, com, rotation, arms, anchors, scale, fixed_rotation)
        if not ok:
            break
    return minimise(rig, com, rotation, arms, anchors, scale, fixed_rotation)


def _trust_step(g: np.ndarray, h: np.ndarray, radius: float) -> np.ndarray:
    """The minimiser of g.p + p.h.p / 2 with |p| <= radius (More-Sorensen by bisection on the shift)."""
    lam, vec = np.linalg.eigh(h)
    gv = vec.T @ g

    def step(shift):
        return -vec @ (gv / (lam + shift))

    if lam[0] > 0.0:
        newton = step(0.0)
        if np.linalg.norm(newton) <= radius:
            return newton
    low = max(0.0, -lam[0]) + 1e-300
    high = low + np.linalg.norm(g) / radius + abs(lam).max() + 1e-300
    for _ in range(200):
        mid = 0.5 * (low + high)
        if np.linalg.norm(step(mid)) > radius:
            low = mid
        else:
            high = mid
        if high - low <= 1e-12 * high:
            break
    return step(high)


def rest_pose(rig: Rig, starts, arms: np.ndarray, anchors: np.ndarray, scale: float):
    """The lowest stable minimum of V with every wire taut from the poses ``starts`` (com, rotation),
    else the lowest with a wire slack (the caller refuses it); (com, rotation, tensions), or a
    :class:`RigError` naming ``wire`` if no start converges to a stable minimum. A taut minimum above a
    slack one is a pose the body can hang in, as the inextensible search's constrained minima are."""
    found = []
    for com, rotation in starts:
        try:
            c, r, t, ok = settle(rig, com, rotation, arms, anchors, scale)
        except np.linalg.LinAlgError:
            continue
        if not ok or not np.all(np.isfinite(c)):
            continue
        energy, _, hess, _ = energy_terms(rig, c, r, arms, anchors)
        w = np.linalg.eigvalsh(hess / np.outer([1, 1, 1, scale, scale, scale], [1, 1, 1, scale, scale, scale]))
        if w.min() < -STABLE_SLACK * abs(w).max():
            continue
        found.append((energy, c, r, t))
    if not found:
        raise RigError(rig.source, "wire", "no stable rest pose found on the elastic wires (the minimum of the "
                       "potential did not converge from any start)")
    taut = [f for f in found if f[3].min() > 0.0]
    found = taut or found
    lowest = min(f[0] for f in found)
    _, c, r, t = next(f for f in found if f[0] <= lowest + 1e-12 * rig.mass * rig.gravity * scale)
    return c, r, t
