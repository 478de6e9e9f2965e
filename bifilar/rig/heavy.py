"""Heavy wires to first order in their mass: what a wire of mass mu_i = rho_i L_i adds to the body.

A taut uniform wire of length L from the fixed anchor a to the attachment p stays straight to first
order in mu / m (its sag shortens the chord at order mu^2, and its own transverse modes, at
sqrt(t / rho) pi / L, are far above the body's), and it turns about the anchor: the point at arc
length s from the anchor moves with (s / L) p'. Hence (docs/heavy-wires.md, derived step by step):

* kinetic energy (1/2) (mu / 3) |p'|^2: a point mass mu / 3 at the attachment, moving with the body;
* potential energy mu g (a_z + p_z) / 2: a point weight mu g / 2 at the attachment;
* the force at the body end of the wire F = t u - (mu g / 2) z_hat (u towards the anchor, z_hat
  world up), t the tension of the same rig with the half weights lumped at the attachments: the
  wire's moment balance about its anchor.

The lumped rig (body plus every mu_i / 2 at its attachment, massless wires) therefore has the heavy
rig's rest pose and its potential; its stiffness is the massless machinery's
(:func:`bifilar.rig.pose_kernel.reduced_matrices`), and the mass matrix is the body's plus mu_i / 3 at
each attachment, in the pose coordinates of the body's own COM. With every density zero this is the
massless model exactly (tests/test_heavy.py).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from bifilar.rig import Rig
from bifilar.rig import pose_kernel
from bifilar.rig.statics import NULL_RTOL, Rest, anchors, arms, rest_pose, rig_scale

__all__ = ["wire_masses", "has_wire_mass", "massless", "lumped", "body_end_tensions", "system", "with_mass_ratio"]


def wire_masses(rig: Rig) -> np.ndarray:
    """mu_i = rho_i L_i (kg) of every wire."""
    return np.array([w.linear_density * w.length for w in rig.wires])


def has_wire_mass(rig: Rig) -> bool:
    """True if any wire has a ``linear_density``."""
    return any(w.linear_density > 0.0 for w in rig.wires)


def massless(rig: Rig) -> Rig:
    """The same rig on massless wires (today's model)."""
    return replace(rig, wires=tuple(replace(w, linear_density=0.0) for w in rig.wires))


def lumped(rig: Rig) -> Rig:
    """The massless-wire rig with half of each wire's weight carried at its attachment: mass
    m + sum mu_i / 2 and the COM of that assembly (body frame). It has the heavy rig's rest pose and
    potential (module docstring); its inertia is the body's (statics never use it)."""
    half = wire_masses(rig) / 2.0
    mass = rig.mass + half.sum()
    com = (rig.mass * rig.com + half @ np.array([w.attach for w in rig.wires])) / mass
    return replace(massless(rig), mass=float(mass), com=com)


def body_end_tensions(rig: Rig, com: np.ndarray, rotation: np.ndarray, lumped_tensions: np.ndarray) -> np.ndarray:
    """|t_i u_i - (mu_i g / 2) z_hat| (N): the pull of each wire on the body at rest, from the lumped
    rig's tensions ``lumped_tensions`` at the pose (``com`` of the body, world; ``rotation``)."""
    points = com + (rotation @ (np.array([w.attach for w in rig.wires]) - rig.com).T).T
    span = anchors(rig) - points
    u = span / np.linalg.norm(span, axis=1)[:, None]
    force = lumped_tensions[:, None] * u
    force[:, 2] -= wire_masses(rig) * rig.gravity / 2.0
    return np.linalg.norm(force, axis=1)


def kinetic_matrix(rig: Rig, rotation: np.ndarray) -> np.ndarray:
    """The 6x6 kinetic matrix on (COM velocity, angular velocity), world, of the body plus a point
    mass mu_i / 3 at every attachment: v_p = v - [s_i]x omega, s_i the attachment's arm from the COM."""
    m6 = np.zeros((6, 6))
    m6[:3, :3] = rig.mass * np.eye(3)
    m6[3:, 3:] = rotation @ rig.inertia @ rotation.T
    for w, third in zip(rig.wires, wire_masses(rig) / 3.0):
        p = np.hstack([np.eye(3), -pose_kernel.cross_matrix(rotation @ (w.attach - rig.com))])
        m6 += third * p.T @ p
    return m6


def system(rig: Rig, guess: Rest | None = None) -> tuple[Rest, np.ndarray, np.ndarray, np.ndarray]:
    """(rest, Z, M6, K) of the heavy rig about its rest pose, in the body-COM pose coordinates of
    :mod:`bifilar.motion.modes`: the rest pose (body COM, rotation, body-end tensions), the null-space
    basis Z (6 x n), the 6x6 kinetic matrix (M = Z^T M6 Z) and the reduced stiffness K (n x n).
    ``guess``: a rest pose of the lumped rig to continue from."""
    light = lumped(rig)
    rest = rest_pose(light, guess=guess)
    z, _, kr, _ = pose_kernel.reduced_matrices(
        rest.com, rest.rotation, rest.tensions, arms(light), anchors(light), light.inertia, light.mass,
        rig_scale(light), NULL_RTOL,
    )
    offset = rest.rotation @ (rig.com - light.com)  # body COM from the lumped COM, world
    body_com = rest.com + offset
    z = z.copy()
    z[:3] -= pose_kernel.cross_matrix(offset) @ z[3:]  # the body COM moves with x - [d]x theta
    tensions = body_end_tensions(rig, body_com, rest.rotation, rest.tensions)
    return Rest(body_com, rest.rotation, tensions), z, kinetic_matrix(rig, rest.rotation), kr


def with_mass_ratio(rig: Rig, ratio: float) -> Rig:
    """``rig`` with every wire of one linear density, chosen so that the wires together weigh
    ``ratio`` times the body: rho = ratio m / sum L_i (kg/m)."""
    density = ratio * rig.mass / sum(w.length for w in rig.wires)
    return replace(rig, wires=tuple(replace(w, linear_density=density) for w in rig.wires))
