"""The TMT (frame-matrix) method for a serial chain of rigid bodies, as seed 002 sets it out.

A chain is a sequence of relative frames, each ``E^{i,i-1} = [[R_a(angle), s], [0, 1]]``: the new
frame's origin sits at ``s`` (parent axes, m) and its axes are the parent's turned by ``angle`` about
the unit ``axis`` (components in the parent axes, which equal the new axes). The angle is either a
generalized coordinate ``q[k]`` (rad) or a constant. A frame that carries a :class:`Body` is that
body's centre-of-mass frame. The first frame is relative to the inertial frame.

The quantities are the seed's:

* ``E^i = E^{i-1} E^{i,i-1}`` with rotation ``R^i`` (frame axes -> inertial) and origin ``x^i``
  (inertial frame, m);
* ``Omega^i = (E^i)^-1 dE^i/dt = [[w~^i, (R^i)^T xdot^i], [0, 0]]`` from the seed's recursion
  ``Omega^i = (E^{i,i-1})^-1 Omega^{i-1} E^{i,i-1} + Omega^{i,i-1}``; ``w~^i`` is the skew matrix of
  the angular velocity in body axes;
* ``B``, the partial velocities: per body six rows, ``xdot^i`` (inertial frame) then ``w^i`` (body
  axes), and one column per coordinate, so that ``[xdot; w] = B qdot``;
* ``M = blockdiag(m^i I_3, J^i)`` and ``D = blockdiag(0, w~^i)``, with ``J^i`` about the COM in body
  axes;
* ``M* = B^T M B``, ``N* = B^T (M Bdot + D M B)`` (a matrix that multiplies qdot) and ``F* = B^T f``,
  ``f = [m^i g, 0]`` (gravity in the inertial frame, no applied moments);
* the reduced equations ``M* qddot = F* - N* qdot``.

Since ``Omega^i`` is linear in qdot, the recursion is run on its partial derivatives
``Omega^i_k = dOmega^i/dqdot_k`` (one 4x4 matrix per coordinate), which give the columns of ``B``.
Their time derivatives, which give ``Bdot``, follow from differentiating the recursion:
``d/dt (E^-1 X E) = E^-1 Xdot E + [E^-1 X E, Omega^{i,i-1}]`` with ``[A, C] = A C - C A``.

The recursion is compiled with numba (``cache=True``): the first call on a machine compiles it (about
20 s of CPU), later processes load the cache. The reduced equations are numpy on (6 nb)-square
matrices, nb the number of bodies.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numba import njit
from scipy.integrate import solve_ivp

from bifilar.jit import announce_compile
from bifilar.smallmat import mm as _mm
from bifilar.smallmat import mv as _mv
from bifilar.smallmat import add2, put, put2, put_col


@dataclass(frozen=True)
class Body:
    """A rigid body: mass (kg) and inertia tensor about its COM in its own axes (kg m^2)."""

    name: str
    mass: float
    inertia: np.ndarray


@dataclass(frozen=True)
class Frame:
    """One relative frame ``[[R_axis(angle), s], [0, 1]]``; see the module docstring."""

    s: tuple[float, float, float] = (0.0, 0.0, 0.0)
    axis: tuple[float, float, float] = (1.0, 0.0, 0.0)
    coordinate: int | None = None  # index into q, or None for the constant ``angle``
    angle: float = 0.0  # rad, used when ``coordinate`` is None
    body: Body | None = None

    def matrix(self, angle: float) -> np.ndarray:
        """The 4x4 relative frame matrix at the given rotation angle (rad)."""
        axis = np.asarray(self.axis, dtype=float)
        return _frame_matrix(axis / np.linalg.norm(axis), float(angle), np.asarray(self.s, dtype=float))


@dataclass(frozen=True)
class Kinematics:
    """Poses and partial velocities of every body at one state (see the module docstring)."""

    R: np.ndarray  # (nb, 3, 3), body axes -> inertial
    x: np.ndarray  # (nb, 3), COM, inertial frame, m
    omega: np.ndarray  # (nb, 3), angular velocity, body axes, rad/s
    B: np.ndarray  # (6 nb, n)
    Bdot: np.ndarray  # (6 nb, n)


@dataclass(frozen=True)
class EoM:
    """The reduced equations ``Mstar qddot + Nstar qdot = Fstar`` at one state."""

    Mstar: np.ndarray  # (n, n), kg m^2 for rotational coordinates
    Nstar: np.ndarray  # (n, n)
    Fstar: np.ndarray  # (n,), N m for rotational coordinates


class Chain:
    """A serial chain of relative frames with bodies attached; gravity in the inertial frame (m/s^2)."""

    def __init__(self, frames: Sequence[Frame], gravity: Sequence[float]):
        self.frames = tuple(frames)
        self.gravity = np.asarray(gravity, dtype=float)
        self.bodies = tuple(f.body for f in self.frames if f.body is not None)
        coords = [f.coordinate for f in self.frames if f.coordinate is not None]
        self.n = len(coords)
        if sorted(coords) != list(range(self.n)):
            raise ValueError(f"coordinates must be 0..n-1, each driving one rotation; got {coords}")
        last_body = max((i for i, f in enumerate(self.frames) if f.body is not None), default=-1)
        for i, f in enumerate(self.frames):
            if f.coordinate is not None and i > last_body:
                raise ValueError(f"coordinate {f.coordinate} moves no body")
            if np.linalg.norm(f.axis) == 0.0:
                raise ValueError(f"frame {i}: rotation axis is zero")
        for b in self.bodies:
            _check_body(b)
        # The chain as arrays for the compiled kernel.
        body_index = np.cumsum([f.body is not None for f in self.frames]) - 1
        self._s = np.array([f.s for f in self.frames], dtype=float)
        self._axis = np.array([np.asarray(f.axis) / np.linalg.norm(f.axis) for f in self.frames], dtype=float)
        self._coord = np.array([-1 if f.coordinate is None else f.coordinate for f in self.frames], dtype=np.int64)
        self._angle = np.array([f.angle for f in self.frames], dtype=float)
        self._body = np.where([f.body is not None for f in self.frames], body_index, -1).astype(np.int64)
        self._mass = _block_diag([np.diag([b.mass] * 3) for b in self.bodies], [b.inertia for b in self.bodies])
        self._f = np.concatenate([np.concatenate([b.mass * self.gravity, np.zeros(3)]) for b in self.bodies])
        announce_compile("the TMT kernels", _kinematics)

    def kinematics(self, q, qd) -> Kinematics:
        """Poses and partial velocities at the state (q rad, qd rad/s)."""
        return Kinematics(*_kinematics(*self._args(q, qd)))

    def eom(self, q, qd) -> EoM:
        """``M* = B^T M B``, ``N* = B^T (M Bdot + D M B)`` and ``F* = B^T f`` at the state (q rad,
        qd rad/s)."""
        kin = self.kinematics(q, qd)
        M, B = self._mass, kin.B
        Mstar = B.T @ M @ B
        Nstar = B.T @ (M @ kin.Bdot + _gyro(kin.omega) @ M @ B)
        return EoM(0.5 * (Mstar + Mstar.T), Nstar, B.T @ self._f)

    def accelerations(self, q, qd) -> np.ndarray:
        """qddot (rad/s^2) from the reduced equations."""
        eom = self.eom(q, qd)
        return np.linalg.solve(eom.Mstar, eom.Fstar - eom.Nstar @ np.asarray(qd, dtype=float))

    def energy(self, q, qd) -> float:
        """Kinetic plus gravitational potential energy (J), zero potential at the inertial origin."""
        kin = self.kinematics(q, qd)
        v = kin.B @ np.asarray(qd, dtype=float)
        masses = np.array([b.mass for b in self.bodies])
        return float(0.5 * v @ self._mass @ v - masses @ (kin.x @ self.gravity))

    def body_loads(self, q, qd, qdd) -> tuple[np.ndarray, np.ndarray]:
        """The seed's per-body resultants: net force ``m^i xddot^i`` (inertial frame, N) and net moment
        about the COM ``J^i wdot^i + w^i x J^i w^i`` (body axes, N m), from ``M (B qdd + Bdot qd) +
        D M B qd``; shapes (nb, 3) each. The net force includes gravity and the joint reactions."""
        qd, qdd = np.asarray(qd, dtype=float), np.asarray(qdd, dtype=float)
        kin = self.kinematics(q, qd)
        D = _gyro(kin.omega)
        loads = self._mass @ (kin.B @ qdd + kin.Bdot @ qd) + D @ self._mass @ kin.B @ qd
        loads = loads.reshape(-1, 6)
        return loads[:, :3], loads[:, 3:]

    def _args(self, q, qd):
        q, qd = np.asarray(q, dtype=float), np.asarray(qd, dtype=float)
        return q, qd, self._s, self._axis, self._coord, self._angle, self._body, len(self.bodies)


@dataclass(frozen=True)
class Solution:
    """A sampled TMT trajectory: times (s), q (rad), qd (rad/s), energy (J)."""

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    energy: np.ndarray
    nfev: int


def simulate(chain: Chain, q0, qd0, duration: float, dt_out: float, rtol: float = 1e-11) -> Solution:
    """Integrate ``M* qddot = F* - N* qdot`` with DOP853 (8th order), sampled every ``dt_out`` s from
    the dense output; ``atol`` is ``rtol`` times 1e-2 rad (or rad/s)."""
    n = chain.n
    grid = np.arange(int(np.floor(duration / dt_out + 1e-9)) + 1) * dt_out

    def rhs(t, y):
        return np.concatenate([y[n:], chain.accelerations(y[:n], y[n:])])

    y0 = np.concatenate([np.asarray(q0, dtype=float), np.asarray(qd0, dtype=float)])
    sol = solve_ivp(rhs, (0.0, grid[-1]), y0, method="DOP853", t_eval=grid, rtol=rtol, atol=1e-2 * rtol)
    if sol.status != 0:
        raise RuntimeError(f"TMT integration failed: {sol.message}")
    q, qd = sol.y[:n].T, sol.y[n:].T
    energy = np.array([chain.energy(a, b) for a, b in zip(q, qd)])
    return Solution(sol.t, q, qd, energy, sol.nfev)


@njit(cache=True)
def _kinematics(q, qd, S, axes, coord, angle, body, nb):
    """The Omega recursion along the chain; returns R, x, omega, B, Bdot (see :class:`Kinematics`)."""
    n = q.size
    E = np.eye(4)
    Om = np.zeros((n, 4, 4))  # dOmega^i/dqdot_k
    Omd = np.zeros((n, 4, 4))  # its time derivative
    R, x, omega = np.empty((nb, 3, 3)), np.empty((nb, 3)), np.empty((nb, 3))
    B, Bdot = np.empty((6 * nb, n)), np.empty((6 * nb, n))
    for f in range(S.shape[0]):
        k = coord[f]
        Erel = _frame_matrix(axes[f], angle[f] if k < 0 else q[k], S[f])
        Einv = _inverse(Erel)
        for j in range(n):
            put2(Om[j], 0, 0, _mm(_mm(Einv, Om[j]), Erel))
            put2(Omd[j], 0, 0, _mm(_mm(Einv, Omd[j]), Erel))
        if k >= 0:
            G = np.zeros((4, 4))
            put2(G, 0, 0, _skew(axes[f]))
            add2(Om[k], 0, 0, G)
            Omega_rel = G * qd[k]
            for j in range(n):
                add2(Omd[j], 0, 0, _mm(Om[j], Omega_rel) - _mm(Omega_rel, Om[j]))
        E = _mm(E, Erel)
        i = body[f]
        if i < 0:
            continue
        Ri = np.ascontiguousarray(E[:3, :3])
        W = np.zeros((3, 3))  # w~^i, body axes
        for j in range(n):
            W += qd[j] * Om[j, :3, :3]
        for j in range(n):
            u = np.ascontiguousarray(Om[j, :3, 3])  # column j of (R^i)^T xdot^i
            udot = np.ascontiguousarray(Omd[j, :3, 3])
            put_col(B, 6 * i, j, _mv(Ri, u))
            put_col(B, 6 * i + 3, j, _unskew(Om[j, :3, :3]))
            put_col(Bdot, 6 * i, j, _mv(Ri, _mv(W, u) + udot))
            put_col(Bdot, 6 * i + 3, j, _unskew(Omd[j, :3, :3]))
        put2(R[i], 0, 0, Ri)
        put(x[i], 0, E[:3, 3])
        put(omega[i], 0, _unskew(W))
    return R, x, omega, B, Bdot


@njit(cache=True)
def _frame_matrix(axis, angle, s):
    """The seed's relative frame matrix [[R_axis(angle), s], [0, 1]] (unit axis)."""
    E = np.eye(4)
    put2(E, 0, 0, _rotation(axis, angle))
    put_col(E, 0, 3, s)
    return E


@njit(cache=True)
def _rotation(axis, angle):
    """Rotation by ``angle`` (rad) about the unit ``axis``, Rodrigues' formula."""
    K = _skew(axis)
    return np.eye(3) + np.sin(angle) * K + (1.0 - np.cos(angle)) * _mm(K, K)


@njit(cache=True)
def _inverse(E):
    """The seed's inverse frame matrix [[R^T, -R^T s], [0, 1]]."""
    out = np.eye(4)
    Rt = np.ascontiguousarray(E[:3, :3].T)
    put2(out, 0, 0, Rt)
    put_col(out, 0, 3, -_mv(Rt, np.ascontiguousarray(E[:3, 3])))
    return out


def _gyro(omega: np.ndarray) -> np.ndarray:
    """D = blockdiag(0, w~^1, 0, w~^2, ...)."""
    return _block_diag([np.zeros((3, 3))] * len(omega), [_skew(w) for w in omega])


@njit(cache=True)
def _skew(w):
    return np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])


@njit(cache=True)
def _unskew(W):
    return np.array([W[2, 1], W[0, 2], W[1, 0]])


def _block_diag(first: list[np.ndarray], second: list[np.ndarray]) -> np.ndarray:
    """blockdiag(first[0], second[0], first[1], second[1], ...) of 3x3 blocks."""
    blocks = [blk for pair in zip(first, second) for blk in pair]
    out = np.zeros((3 * len(blocks), 3 * len(blocks)))
    for i, blk in enumerate(blocks):
        out[3 * i : 3 * i + 3, 3 * i : 3 * i + 3] = blk
    return out


def _check_body(b: Body) -> None:
    J = np.asarray(b.inertia, dtype=float)
    if not b.mass > 0.0:
        raise ValueError(f"body {b.name}: mass must be positive, got {b.mass}")
    if J.shape != (3, 3) or not np.allclose(J, J.T, rtol=0.0, atol=1e-15 + 1e-12 * np.abs(J).max()):
        raise ValueError(f"body {b.name}: inertia must be a symmetric 3x3 matrix")
    moments = np.linalg.eigvalsh(J)
    if moments[0] < -1e-15 or moments[0] + moments[1] < moments[2] * (1.0 - 1e-9):
        raise ValueError(f"body {b.name}: inertia is not that of a real body (principal moments {moments})")
