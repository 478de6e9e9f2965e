"""A mode beating in near the first one's frequency lifts the envelope (bifilar.identification.records.near): decaying envelopes do not."""

import math

import numpy as np

from bifilar.identification.records.near import envelope_rises


def _envelope(rng, share, ratio, cycles=25, zeta=5e-4, noise=2e-3):
    """Cycle centres and amplitudes of a decaying swing with a mode beating in (the analytic signal's
    modulus, A e^(-zeta t) |1 + share e^(i (ratio - 1) t)|), each amplitude with relative noise."""
    t = 2.0 * math.pi * (np.arange(cycles) + 0.5)
    beat = np.abs(1.0 + share * np.exp(1j * (ratio - 1.0) * t))
    return t, np.exp(-zeta * t) * beat * (1.0 + noise * rng.standard_normal(cycles))


def test_a_decaying_envelope_does_not_rise():
    # damping only shrinks the swing: 30 noisy decaying (or flat) envelopes of 25 cycles, none called a beat
    rng = np.random.default_rng(40)
    assert not any(envelope_rises(*_envelope(rng, 0.0, 1.0, zeta=z)) for z in np.linspace(0.0, 3e-3, 30))


def test_a_beat_under_one_cycle_lifts_the_envelope():
    # a sway at 0.96 omega0, 5 % of the swing: one beat over 25 cycles, its envelope falls and rises by
    # ~10 % against a decay of 7.6 % (zeta 5e-4) and a noise of 0.2 % a cycle
    rng = np.random.default_rng(41)
    assert envelope_rises(*_envelope(rng, 0.05, 0.96))
