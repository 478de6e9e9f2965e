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



def _envelope(rng, share, ratio, cycles=25, zeta=5e-4, noise=2e-3):
    """Cycle centres and amplitudes of a decaying swing with a mode beating in (the analytic signal's
    modulus, A e^(-zeta t) |1 + share e^(i (ratio - 1) t)|), each amplitude with relative noise."""
    t = 2.0 * math.pi * (np.arange(cycles) + 0.5)
    beat = np.abs(1.0 + share * np.exp(1j * (ratio - 1.0) * t))
    return t, np.exp(-zeta * t) * beat * (1.0 + noise * rng.standard_normal(cycles))


def test_a_decaying_envelope_does_not_rise():
    # damping only shrinks the swing: 30 noisy decaying (or flat) envelopes of 25 cycles, none called a beat
    from bifilar.identification.records.near import envelope_rises

    rng = np.random.default_rng(40)
    assert not any(envelope_rises(*_envelope(rng, 0.0, 1.0, zeta=z)) for z in np.linspace(0.0, 3e-3, 30))


def test_a_beat_under_one_cycle_lifts_the_envelope():
    # a sway at 0.96 omega0, 5 % of the swing: one beat over 25 cycles, its envelope falls and rises by
    # ~10 % against a decay of 7.6 % (zeta 5e-4) and a noise of 0.2 % a cycle
    from bifilar.identification.records.near import envelope_rises

    rng = np.random.default_rng(41)
    assert envelope_rises(*_envelope(rng, 0.05, 0.96))
