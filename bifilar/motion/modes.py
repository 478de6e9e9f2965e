"""Small oscillations of a rig about its rest pose, in pose coordinates, for any number of wires.

The body's small displacement is q = (x, theta) (COM shift and rotation vector, world frame; see
:mod:`bifilar.rig.pose_kernel`). The wires allow q = Z dq, Z a basis of the null space of the wire
constraints' gradients (n = 6 - rank of them: 4 for two wires, 3 for three), and

    M dq'' + K dq = 0,   M = Z^T diag(m I, R I R^T) Z,   K = Z^T (sum_i t_i hess g_i) Z,

with t_i the static tensions; the body's ``[air]`` adds its added-mass tensor (about the COM, turned
to the world) to diag(m I, R I R^T). K is the Hessian of the potential on the constraint manifold, exact and
closed-form: no finite differences and no angles, so no rig is near a coordinate singularity (the
thesis's angles theta_1..5 have one where the attachment line turns steeply, which made the earlier
linearisation through them wrong there). On two-wire rigs it agrees with the exact linearisation of the
Kane-Tseng equations where their chart is regular (case ``kane-modes-spectrum``, tests/test_modes.py).

Elastic wires (``axial_stiffness``, :mod:`bifilar.rig.elastic`) leave the body all six directions:
Z = I and K = hess V = sum_taut k_i J_i^T J_i + sum_i t_i H_i, the wires' axial stiffness plus the
geometric stiffness of their tension (the second term is the inextensible K before the null-space
restriction). The six modes are three slow ones (``sway x``, ``sway y``, ``yaw``: the pendulum's, which
hardly stretch a wire) and three fast ones, which do: ``bounce`` (the COM's vertical motion), ``roll`` and
``pitch`` (turning about world x and y). :attr:`Mode.stretch_share` is the share of a mode's potential
energy that is wire stretch: ~1 for the fast modes, ~T / EA for the slow ones.

Each mode is named by the motion that holds most of its kinetic energy: ``sway x`` / ``sway y`` (COM
along world x / y), ``yaw`` (turning about world z) or ``tilt`` (turning about a horizontal axis, with
the COM's vertical motion). Modes of equal frequency (a symmetric trifilar's two sways) are resolved
deterministically, along world x, y, then the rotations, instead of eigh's arbitrary basis.
"""

from __future__ import annotations

from dataclasses import dataclass

import numba as nb
import numpy as np
from scipy.linalg import eigh

from bifilar.rig.air import added_mass
from bifilar.rig import Rig
from bifilar.rig import elastic, heavy
from bifilar.rig.heavy import has_wire_mass
from bifilar.rig.pose_loops import PK
from bifilar.rig.statics import NULL_RTOL, Rest, State, anchors, arms, rest_pose, rig_scale

# An omega^2 below this fraction of the pendulum's scale g / S (S: rig_scale) is neutral (or unstable), and
# two closer than it are one frequency; or below the eigen-solver's round-off, ROUNDOFF_RTOL of the
# largest |omega^2|, where that is larger (see resolution).
NEUTRAL_RTOL = 1e-9
DEGENERATE_RTOL = 1e-9
ROUNDOFF_RTOL = 1e-12
MOTIONS = ("sway x", "sway y", "yaw", "tilt")
ELASTIC_MOTIONS = ("sway x", "sway y", "yaw", "bounce", "roll", "pitch")  # elastic wires: six modes
# Pose directions (x, theta) tried in this order to resolve a degenerate eigenspace.
_PREFERRED = np.eye(6)[[0, 1, 5, 3, 4, 2]]


@dataclass(frozen=True)
class Mode:
    """One normal mode: period (s; None if neutral or unstable), omega^2 (rad^2/s^2), its shape as a
    COM displacement (world, m) and a small rotation vector (world, rad), scaled so that the largest
    of |rotation| and |com| / r_ref is 1, and the motion it is (one of :data:`MOTIONS`)."""

    period: float | None
    omega2: float
    com: np.ndarray
    rotation: np.ndarray
    motion: str
    stretch_share: float = 0.0  # of the potential energy of the mode's shape, the wires' stretch: 0 inextensible

    @property
    def frequency(self) -> float | None:
        """Hz."""
        return None if self.period is None else 1.0 / self.period


@dataclass(frozen=True)
class Modes:
    rest: Rest
    modes: tuple[Mode, ...]  # longest period first; neutral/unstable modes first of all
    mass: np.ndarray  # M (n x n)
    stiffness: np.ndarray  # K (n x n)
    basis: np.ndarray  # Z (6 x n): pose displacement (x, theta; world) per independent coordinate
    pendulum: float  # g / S (rad^2/s^2, S: rig_scale): the scale of the slow modes' omega^2 (see resolution)

    @property
    def partial_com(self) -> np.ndarray:
        """COM velocity (world, 3 x n) per independent speed."""
        return self.basis[:3]

    @property
    def partial_omega(self) -> np.ndarray:
        """Angular velocity (world, 3 x n) per independent speed."""
        return self.basis[3:]


def pendulum_scale(rig: Rig) -> float:
    """g / S (rad^2/s^2), S the rig's longest wire or anchor span: the scale of a pendulum's omega^2."""
    return rig.gravity / rig_scale(rig)


@nb.njit(cache=True)
def resolution(pendulum: float, big: float, rtol: float) -> float:
    """The omega^2 (rad^2/s^2) at or below which a mode is neutral, and the gap within which two are one
    frequency: ``rtol`` of the ``pendulum`` scale g / S, or the eigen-solver's round-off on the largest
    |omega^2| ``big`` (:data:`ROUNDOFF_RTOL`) if that is larger. Not a fraction of the largest alone: stiff
    elastic wires put the bounce's omega^2 (~EA / (m L)) 1e9 times above the sways' g / L at EA = 1e10
    (issue 35 item 4), where a fraction of it would call the sways and the yaw neutral (and one frequency).

    Compiled for the sweep kernel, which calls it; this module calls its Python function
    (``resolution.py_func``), so that one rig's modes still need no compiler (README)."""
    return max(rtol * pendulum, ROUNDOFF_RTOL * big, 1e-300)


def oscillating(w2: np.ndarray, pendulum: float) -> np.ndarray:
    """Which of the eigenvalues ``w2`` are oscillating modes (not neutral or unstable; :func:`resolution`)."""
    big = float(np.abs(w2).max()) if len(w2) else 0.0
    return w2 > resolution.py_func(pendulum, big, NEUTRAL_RTOL)


def reduced(rig: Rig, rest: Rest) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(Z, M, K) about ``rest`` (see the module docstring); with ``[air]``, M gains Z^T M_A,w Z."""
    if rig.elastic:
        z = np.eye(6)
        mr = np.zeros((6, 6))
        mr[:3, :3] = rig.mass * np.eye(3)
        mr[3:, 3:] = rest.rotation @ rig.inertia @ rest.rotation.T
        kr = elastic.stiffness(rig, rest.com, rest.rotation, arms(rig), anchors(rig))
    else:
        z, mr, kr, _ = PK.reduced_matrices(
            rest.com, rest.rotation, rest.tensions, arms(rig), anchors(rig), rig.inertia, rig.mass,
            rig_scale(rig), NULL_RTOL,
        )
    if rig.air is not None:
        mr = mr + z.T @ air_mass_world(rig, rest) @ z
    return z, mr, kr


def air_mass_world(rig: Rig, rest: Rest) -> np.ndarray:
    """The air's added-mass tensor (6x6, about the COM, world axes at rest) on the pose speeds
    (COM velocity, angular velocity); zero without ``[air]``."""
    if rig.air is None:
        return np.zeros((6, 6))
    rot6 = np.kron(np.eye(2), rest.rotation)
    return rot6 @ added_mass(rig.air, rig.com) @ rot6.T


def motion_of(rig: Rig, rest: Rest, com: np.ndarray, rotation: np.ndarray) -> str:
    """The motion holding most of the kinetic energy of a shape (COM and rotation, world)."""
    inertia = rest.rotation @ rig.inertia @ rest.rotation.T
    horizontal = np.array([rotation[0], rotation[1], 0.0])
    if rig.elastic:
        energy = {
            "sway x": rig.mass * com[0] ** 2,
            "sway y": rig.mass * com[1] ** 2,
            "yaw": inertia[2, 2] * rotation[2] ** 2,
            "bounce": rig.mass * com[2] ** 2,
            "roll": inertia[0, 0] * rotation[0] ** 2,
            "pitch": inertia[1, 1] * rotation[1] ** 2,
        }
        return max(ELASTIC_MOTIONS, key=energy.__getitem__)
    energy = {
        "sway x": rig.mass * com[0] ** 2,
        "sway y": rig.mass * com[1] ** 2,
        "yaw": inertia[2, 2] * rotation[2] ** 2,
        "tilt": horizontal @ inertia @ horizontal + rig.mass * com[2] ** 2,
    }
    return max(MOTIONS, key=energy.__getitem__)


def degenerate_sets(w2: np.ndarray, pendulum: float) -> list[tuple[int, int]]:
    """(start, stop) of each run of two or more ascending eigenvalues ``w2`` that are one frequency:
    within :func:`resolution` (``pendulum``: g / S) of each other."""
    gap = resolution.py_func(pendulum, float(np.abs(w2).max()) if len(w2) else 0.0, DEGENERATE_RTOL)
    sets, k = [], 0
    while k < len(w2):
        j = k + 1
        while j < len(w2) and w2[j] - w2[k] <= gap:
            j += 1
        if j - k > 1:
            sets.append((k, j))
        k = j
    return sets


def _resolve_degenerate(w2: np.ndarray, vecs: np.ndarray, z: np.ndarray, m6: np.ndarray, pendulum: float) -> np.ndarray:
    """Eigenvectors with every degenerate eigenspace spanned along :data:`_PREFERRED` directions
    (M-orthonormal, by Gram-Schmidt), each with its largest pose component positive."""
    vecs = vecs.copy()
    for k, j in degenerate_sets(w2, pendulum):
        space = vecs[:, k:j]
        chosen = []
        for direction in _PREFERRED:
            v = space @ (space.T @ (z.T @ m6 @ direction))  # M-projection onto the eigenspace
            for c in chosen:
                v = v - c * (c @ (z.T @ m6 @ z) @ v)
            norm = np.sqrt(v @ (z.T @ m6 @ z) @ v)
            if norm > 1e-6 * np.sqrt(np.abs(m6).max()):
                chosen.append(v / norm)
            if len(chosen) == j - k:
                break
        vecs[:, k:j] = np.array(chosen).T
    for col in range(vecs.shape[1]):
        shape = z @ vecs[:, col]
        if shape[np.argmax(np.abs(shape))] < 0.0:
            vecs[:, col] = -vecs[:, col]
    return vecs


def linearize(rig: Rig, rest: Rest | None = None) -> Modes:
    """Mass and stiffness matrices about the rest pose and the normal modes. Heavy wires
    (``linear_density``) enter to first order in their mass (:func:`bifilar.rig.heavy.system`; ``rest``
    is then recomputed, the rest tensions are the pull at the body end)."""
    if has_wire_mass(rig):
        rest, z, m6, kr = heavy.system(rig)
        m6 = m6 + air_mass_world(rig, rest)
        mr = 0.5 * (z.T @ m6 @ z + (z.T @ m6 @ z).T)
    else:
        rest = rest_pose(rig) if rest is None else rest
        z, mr, kr = reduced(rig, rest)
        m6 = np.zeros((6, 6))
        m6[:3, :3] = rig.mass * np.eye(3)
        m6[3:, 3:] = rest.rotation @ rig.inertia @ rest.rotation.T
        m6 += air_mass_world(rig, rest)
    pendulum = pendulum_scale(rig)
    if z.shape[1] == 0:
        return Modes(rest, (), mr, kr, z, pendulum)
    w2, vecs = eigh(kr, mr)
    vecs = _resolve_degenerate(w2, vecs, z, m6, pendulum)
    moving = oscillating(w2, pendulum)
    scale = max(np.linalg.norm(arms(rig), axis=1).max(), 1e-3)
    modes = []
    for k in range(len(w2)):
        shape = z @ vecs[:, k]
        com, rot = shape[:3], shape[3:]
        norm = max(np.linalg.norm(rot), np.linalg.norm(com) / scale)
        period = float(2.0 * np.pi / np.sqrt(w2[k])) if moving[k] else None
        modes.append(Mode(period, float(w2[k]), com / norm, rot / norm, motion_of(rig, rest, com, rot),
                          _stretch_share(rig, rest, shape)))
    modes.sort(key=lambda m: (m.period is not None, -(m.period or 0.0)))
    return Modes(rest, tuple(modes), mr, kr, z, pendulum)


def _stretch_share(rig: Rig, rest: Rest, shape: np.ndarray) -> float:
    """(sum k_i (J_i q)^2) / (q^T K q) for the pose shape q: the share of the mode's potential energy
    stored in stretching the wires (0 for inextensible wires)."""
    if not rig.elastic:
        return 0.0
    s, u, rho = PK.wire_geometry(rest.com, rest.rotation, arms(rig), anchors(rig))
    rates = PK.constraint_jacobian(s, u) @ shape
    taut = rest.tensions > 0.0
    axial = float(elastic.springs(rig)[taut] @ rates[taut] ** 2)
    total = float(shape @ elastic.stiffness(rig, rest.com, rest.rotation, arms(rig), anchors(rig)) @ shape)
    return axial / total if total > 0.0 else 0.0


def excite(lin: Modes, index: int, amplitude: float) -> State:
    """A state at the rest pose moving along mode ``index`` with angle amplitude ~``amplitude`` (rad):
    the velocity is omega_k times the mode shape, which is tangent to the wire constraints."""
    mode = lin.modes[index]
    if mode.period is None:
        raise ValueError(f"mode {index} is neutral or unstable; it cannot be excited into oscillation")
    rate = amplitude * 2.0 * np.pi / mode.period
    return State(lin.rest.com, lin.rest.rotation, rate * mode.com, rate * mode.rotation)
