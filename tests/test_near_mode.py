"""The near-band search for a second mode (bifilar.identification.records.near) on a plain sinusoid's fit."""

import math

import numpy as np
from scipy.optimize import least_squares

from bifilar.identification.records.near import degenerate, scan


def _fitted(t, y, omega):
    """A sinusoid's least squares (phi0, omega0, amplitude, offset): its parameters, Jacobian, residual."""
    def residual(q):
        return y - q[2] * np.cos(q[0] + q[1] * t) - q[3]

    sol = least_squares(residual, [0.0, omega, 1.0, 0.0], x_scale="jac")
    return sol.x, sol.jac, sol.fun


def _record(rng, ratio, share, cycles=20.0, rate=40.0, noise=0.01):
    t = np.arange(0.0, cycles * 2.0 * math.pi, 2.0 * math.pi / rate)
    y = np.cos(t) + share * np.cos(ratio * t + 1.0) + noise * rng.standard_normal(len(t))
    return t, y


def test_a_resolved_near_mode_is_found_at_its_frequency():
    # a sway at 1.06 omega0, 5 % of the swing, 20 cycles (1.2 beats): far above the white-noise
    # threshold (the fall is ~ share^2 n / (2 sigma^2) ~ 1e4 noise variances against ~13)
    rng = np.random.default_rng(37)
    t, y = _record(rng, 1.06, 0.05)
    q, jac, r = _fitted(t, y, 1.0)
    found = scan(t, jac, r, q[1])
    assert found.significant
    resolution = 2.0 * math.pi / (t[-1] - t[0])
    assert abs(found.omega - 1.06) < resolution
    assert not degenerate(found, q[1], t[-1] - t[0])


def test_no_mode_on_a_clean_sinusoid():
    # white noise alone: the look-elsewhere threshold holds false alarms to NEAR_ALPHA = 1 %
    rng = np.random.default_rng(38)
    t, y = _record(rng, 1.06, 0.0)
    q, jac, r = _fitted(t, y, 1.0)
    assert not scan(t, jac, r, q[1]).significant

