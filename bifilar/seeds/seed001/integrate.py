"""Integrators for y = (phi1, phi2, phi1', phi2'): the seed's fixed-step RK4 and scipy's DOP853.

Both sample the solution on a uniform grid t_i = i * dt_out (s) from 0 to the duration, so that runs
from different engines can be compared sample by sample.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import NamedTuple

import numpy as np
from scipy.integrate import solve_ivp

from . import seed
from .chain import Chain

Rhs = Callable[[np.ndarray], np.ndarray]
Accel = Callable[[seed.Constants, float, float, float, float], float]


class Solution(NamedTuple):
    """Samples y (n, 4) at t (s) and the number of right-hand-side evaluations spent."""

    t: np.ndarray
    y: np.ndarray
    nfev: int


def seed_rhs(c: seed.Constants, f: Accel = seed.f, g: Accel = seed.g) -> Rhs:
    """y' = (y3, y4, f, g) as the seed writes it, with the printed f and g unless others are given
    (:func:`seed.g_fixed`, or :func:`seed.special_f` and :func:`seed.special_g`)."""

    def rhs(y: np.ndarray) -> np.ndarray:
        p1, p2, w1, w2 = y.tolist()
        return np.array([w1, w2, f(c, p1, p2, w1, w2), g(c, p1, p2, w1, w2)])

    return rhs


def chain_rhs(chain: Chain) -> Rhs:
    """y' from the independently derived chain equations."""

    def rhs(y: np.ndarray) -> np.ndarray:
        p1, p2, w1, w2 = y.tolist()
        return np.array([w1, w2, *chain.accel(p1, p2, w1, w2)])

    return rhs


def grid(duration: float, dt_out: float) -> np.ndarray:
    """0, dt_out, ..., duration (s); ``duration`` must be a whole number of output steps."""
    n = round(duration / dt_out)
    if n < 1 or abs(n * dt_out - duration) > 1e-9 * dt_out:
        raise ValueError(f"duration {duration} s is not a whole number of output steps {dt_out} s")
    return np.arange(n + 1) * dt_out


def steps_per_sample(dt: float, dt_out: float) -> int:
    """dt_out / dt (both s), which must be a whole number."""
    every = round(dt_out / dt)
    if every < 1 or abs(every * dt - dt_out) > 1e-9 * dt:
        raise ValueError(f"output step {dt_out} s is not a whole number of steps {dt} s")
    return every


def rk4(rhs: Rhs, y0: np.ndarray, duration: float, dt: float, dt_out: float) -> Solution:
    """The seed's scheme: classical RK4 with step ``dt`` (s). Its k_j1, k_j2 are the rates y3, y4 at
    stage j and k_j3, k_j4 the accelerations f, g there, which is the classical tableau applied to
    y' = rhs(y). ``dt_out`` must be a whole number of steps."""
    every = steps_per_sample(dt, dt_out)
    t = grid(duration, dt_out)
    out = np.empty((len(t), len(y0)))
    y = np.array(y0, dtype=float)
    out[0] = y
    for i in range(1, len(t)):
        for _ in range(every):
            k1 = rhs(y)
            k2 = rhs(y + 0.5 * dt * k1)
            k3 = rhs(y + 0.5 * dt * k2)
            k4 = rhs(y + dt * k3)
            y = y + dt / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
        out[i] = y
    return Solution(t, out, 4 * every * (len(t) - 1))


def dop853(rhs: Rhs, y0: np.ndarray, duration: float, dt_out: float, rtol: float = 1e-12) -> Solution:
    """scipy's 8th-order DOP853 at relative tolerance ``rtol`` (absolute tolerance ``rtol`` in rad
    and rad/s), sampled from its dense output."""
    t = grid(duration, dt_out)
    sol = solve_ivp(lambda _t, y: rhs(y), (0.0, t[-1]), np.asarray(y0, dtype=float), method="DOP853",
                    t_eval=t, rtol=rtol, atol=rtol)
    if not sol.success:
        raise RuntimeError(f"DOP853 failed: {sol.message}")
    return Solution(t, sol.y.T, sol.nfev)
