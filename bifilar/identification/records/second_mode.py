"""A second mode beating in: found in what the first mode leaves, fitted as a damped sinusoid.

Step 3 of the record fit (:mod:`.fit`). A sway or a pendulum mode of the rig adds a second sinusoid to
the record. Close to the torsion's frequency the cycles' own fits (:mod:`.cycles`) cannot tell it from
the first mode over one cycle, but the law's rigid phase (:mod:`.phase_law`) can: it stands out in the
periodogram of the record less the first mode, and nowhere else. :func:`second_mode_of` looks for it
there (:func:`peak_apart`: a peak well above the noise floor, away from the band the first mode sweeps
and its third harmonic) and fits it (:class:`Second`); it is subtracted and the cycles refitted. One
the cycles do not show is looked for again in the whole fit's residual (:mod:`.whole`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from .cycles import PERIODOGRAM_SAMPLES, Cycles, Samples, highest_harmonic, periodogram
from .phase_fit import PhaseFit
from .read import MIN_CYCLES

SECOND_MODE_POWER = 60.0  # peak / local median of the residual periodogram: noise peaks reach ~10-15
SECOND_DECAY_SPANS = 4.0  # the most a second mode may decay over the record, in e-folds


def peak_apart(tau: np.ndarray, rest: np.ndarray, swept: tuple[float, float]) -> float | None:
    """The angular frequency (rad/s) of a periodogram peak of ``rest`` (what the first mode leaves)
    that stands :data:`SECOND_MODE_POWER` times above the noise floor, within 0.25..4 times the first
    mode's highest frequency and apart from the band it sweeps (``swept``: its lowest and highest
    frequency over the record, at the largest and the smallest swing; and one resolution 2 pi / span)
    and from that band's third harmonic (what a slightly wrong waveform leaves there; a symmetric
    oscillator has no even harmonics, and a sway near twice the torsion's frequency is a real rig's);
    None if none does. The band is where the first mode was, not below the zero-swing frequency: a
    record that stays at 1.2 rad swings 9 % below it (the rod's law), and its own third harmonic, left
    outside a band placed there, passed for a second mode, was subtracted and took 1 % off the swing
    and 2.2e-3 off T0 (the rod undamped, 1e-4 rad of noise). The floor is
    the periodogram's median over an octave either side where the record is long enough to have one
    (coloured noise included), else white noise's E P = sigma^2 from the differences."""
    rest = rest - np.polyval(np.polyfit(tau, rest, 1), tau)
    span = tau[-1] - tau[0]
    resolution = 2.0 * math.pi / span
    stride = max(1, -(-len(tau) // PERIODOGRAM_SAMPLES))
    x, v = tau[::stride], rest[::stride]
    low, high = swept
    grid = np.arange(0.25 * high, min(4.0 * high, math.pi * (len(x) - 1) / (x[-1] - x[0])), 0.5 * resolution)
    if len(grid) < 8:
        return None
    near = ((grid > low - resolution) & (grid < high + resolution)) | (grid < 2.0 * resolution)
    near |= (grid > 3.0 * low - 4.0 * resolution) & (grid < 3.0 * high + 4.0 * resolution)
    power = np.where(near, 0.0, periodogram(x, v, grid))
    j = int(np.argmax(power))
    band = (grid > 0.5 * grid[j]) & (grid < 2.0 * grid[j]) & ~near & (np.abs(grid - grid[j]) > 3.0 * resolution)
    if band.sum() >= 8:
        floor = float(np.median(power[band]))
    else:
        floor = (1.4826 * float(np.median(np.abs(np.diff(v) - np.median(np.diff(v)))))) ** 2 / 2.0
    return float(grid[j]) if power[j] >= SECOND_MODE_POWER * floor and j > 0 else None


def outside(omega2: float, swept: tuple[float, float], span: float) -> bool:
    """Whether a fitted second mode's frequency (rad/s) is apart from the band the first mode swept
    (``swept``, and one resolution 2 pi / ``span`` either side), as :func:`peak_apart` asks of its peak.
    The least squares refining it can walk into the band: there it is the first mode's own misfit (its
    law's or its envelope's, ~1e-4 of the swing that a noiseless record's floor lets stand out), not
    a mode. A noiseless 100-cycle record from 0.8 rad had a peak 1.3 resolutions above the band fitted
    into it at 2.7e-4 of the swing: the first amplitude came out 3.7e-4 high and T0 1e-4 short."""
    resolution = 2.0 * math.pi / span
    return not swept[0] - resolution < omega2 < swept[1] + resolution


def swept_band(law_fit: PhaseFit, centres: np.ndarray) -> tuple[float, float]:
    """The lowest and highest frequency (rad/s) the first mode had at the cycles' ``centres`` (s)."""
    local = law_fit.local_omega(centres)
    return float(np.min(local)), float(np.max(local))


@dataclass(frozen=True)
class Second:
    """A damped sinusoid e^(-decay tau) (c cos + s sin)(omega tau) superposed on the record; ``near``: within
    the band the first mode sweeps (:func:`.near.near_mode_of`), found by the beat, not the periodogram."""

    omega: float
    decay: float
    c: float
    s: float
    near: bool = False
    held: bool = False  # its frequency the rig's (.near.near_held), not fitted

    def signal(self, tau):
        return np.exp(-self.decay * tau) * (self.c * np.cos(self.omega * tau) + self.s * np.sin(self.omega * tau))

    def phasor(self, tau):
        """The complex amplitude at ``tau`` whose real part times e^(i omega u) is the signal at tau + u
        (u small): (c - i s) e^((-decay + i omega) tau), what a window centred at tau fits as its fundamental."""
        return complex(self.c, -self.s) * np.exp((-self.decay + 1j * self.omega) * tau)


def _in_phase_harmonics(cyc: Cycles, good: np.ndarray) -> dict[int, np.ndarray]:
    """{n: the n-th odd harmonic's amplitude in each good cycle} (signal units), 1 the fundamental: each
    window's terms at the time its fundamental peaks (a symmetric oscillator's harmonics are in phase
    with it there, so the n-th is a_n cos(n Phi)); 0 where a window held fewer harmonics."""
    out = {}
    for j, n in enumerate(range(1, highest_harmonic(math.inf) + 1, 2)):
        out[n] = np.array([cyc.terms[k][1 + 2 * j] * math.cos(n * cyc.phase[k])
                           - cyc.terms[k][2 + 2 * j] * math.sin(n * cyc.phase[k])
                           if len(cyc.terms[k]) > 2 + 2 * j else 0.0 for k in good])
    return out


def second_mode_of(rec: Samples, cyc: Cycles, baseline: np.ndarray, law_fit: PhaseFit) -> Second | None:
    """:mod:`.fit`, step 3: a mode beating in, from the record minus the first mode as the law
    fitted it (its phase Phi(t), the cycles' fundamentals and odd harmonics between them: a swing that
    stays large has a third harmonic of ~1 % whose periodogram sidelobes, a few resolutions off it,
    stand far above a good record's noise) and the baseline: a
    periodogram peak :data:`SECOND_MODE_POWER` times its median over an octave either side, away from
    the first mode's harmonics, fitted as a damped sinusoid (omega2 and its decay by least squares, its
    two amplitudes linearly). A mode close to the first in frequency is absorbed by the cycles' own
    fits, which cannot tell them apart over one cycle, but not by the law's rigid phase: it stands out
    here and nowhere else. None if nothing stands out."""
    good = np.flatnonzero(cyc.good & np.isfinite(cyc.phase))
    if len(good) < MIN_CYCLES:
        return None
    idx = np.concatenate([cyc.index[k] for k in good])
    tau = rec.tau[idx]
    phase = law_fit.phase_at(tau)
    rest = rec.y[idx] - baseline[idx]
    for n, amplitude in _in_phase_harmonics(cyc, good).items():
        rest = rest - np.interp(tau, cyc.centre[good], amplitude) * np.cos(n * phase)
    rest = rest - np.polyval(np.polyfit(tau, rest, 1), tau)
    swept = swept_band(law_fit, cyc.centre[good])
    peak = peak_apart(tau, rest, swept)
    if peak is None:
        return None
    span = tau[-1] - tau[0]
    resolution = 2.0 * math.pi / span

    def fitted(p):
        """The damped sinusoid (omega2, decay2) fitted to the rest: residual and (cos, sin) amplitudes."""
        w2, a2 = p
        z = np.exp(-a2 * tau)[:, None] * np.column_stack([np.cos(w2 * tau), np.sin(w2 * tau)])
        beta = np.linalg.lstsq(z, rest, rcond=None)[0]
        return rest - z @ beta, beta

    # a mode beating in lasts the record (it decays by at most e^-SECOND_DECAY_SPANS over it: a fast
    # transient at the start fitted as one would take the first cycles' swing with it); that it is
    # smaller than the one released is asked of the whole fit (:func:`fit_whole`), once the law has settled
    sol = least_squares(lambda p: fitted(p)[0], [peak, 0.0], bounds=([0.0, 0.0], [np.inf, SECOND_DECAY_SPANS / span]),
                        x_scale=[resolution, 1.0 / span], xtol=1e-10)
    if not outside(float(sol.x[0]), swept, span):
        return None
    c2, s2 = fitted(sol.x)[1]
    return Second(float(sol.x[0]), float(sol.x[1]), float(c2), float(s2))
