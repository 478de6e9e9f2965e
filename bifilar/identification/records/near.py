"""A second mode near the first one's frequency, seen in the envelope, which one mode's damping never lifts or bends so.

A sway within ~10 % of the torsion's frequency beats into the record. In the frame turning at omega0
the analytic signal is A(t) + c2 e^(i dw t): the beat moves the complex amplitude round a circle, so
the envelope and the phase wobble together, of the same relative size, in quadrature. The periodogram
search of :mod:`.second_mode` refuses that band (the first mode sweeps it: its own law misfit stands
there). To first order in its size a beat is the same as an amplitude law whose frequency moves with
ln A at the beat frequency, and the law the record learns takes it within its prior where it makes
less than a beat over the record: the learned law's extrapolation to zero swing then carries the beat
into T0. What tells it apart is that damping only shrinks the swing, and only as a damping law does:
where the cycles' envelope rises again (:func:`envelope_rises`) or decays as no one mode's does (two
modes decay as two exponentials of their own rates and wobble at their beat: :func:`decay_misfit`),
:meth:`.phase_law.Model.check_law` holds T0 under the ideal law in the sigma as well, as it does for a
law past its prior.

Searching the whole fit's residual for the near mode (a sinusoid at each trial omega2, the rest of the
model linearised, a look-elsewhere threshold) was tried and left out: with the learned law having taken
the beat, the residual showed the beat's mirror image (a sway at 0.963 omega0 turned up at 1.035) and
joint fits wandered (rms z 3.24 against 1.43 without it, ``benchmarks/near_mode.py``).

Half a beat or less over one record cannot be told from a law at all: while the beat's phase
dw t + phi sweeps less than pi, the envelope's share of it moves one way, and the frequency the beat
adds, d arg(1 + eps e^(i (dw t + phi))) / dt, is a single-valued function of it, to every order in
eps, so it is an amplitude law (in the beat's part of ln A; the damping moves ln A alone). What does tell it apart is
that a rig has one law: records of it, or a record's two halves, each learn the beat their own
sway's phase and size ask for. Where the excesses they learned disagree beyond their sigmas,
:func:`.pipeline._own_variances` measures their spread (the between-fits variance of the excess) and
carries it into each one's T0, in the halves' test and in pooled trials. One record alone stays open
(issue 37 item 1; docs/identification.md, "What is left").
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import least_squares
from scipy.stats import f as fisher

NEAR_FLOOR = 1e-3  # relative rise below which a "beat" is the first mode's own law misfit
# (:func:`.second_mode.outside`: a noiseless record's misfit fitted as a mode at 2.7e-4 of the swing)

RISE_SIGMAS = 12.0  # a rise of the smoothed envelope this many of its sigmas: a beat. Of 400 flat noisy
# envelopes of 8-100 cycles each, the largest rise reached 7.6 at the 99th percentile, 12 at the most


def envelope_rises(times: np.ndarray, amplitudes: np.ndarray) -> bool:
    """Whether the cycles' amplitudes (at their centre ``times``) rise over the record: damping only
    shrinks a free oscillation's swing, and an amplitude law only ties its phase to it, but a mode
    beating in moves the complex amplitude round a circle and lifts the envelope again. To first order
    in its size the beat is then the same as a law whose frequency moves with ln A at its beat
    frequency, so the law learned from such a record may be the beat's (:meth:`.phase_law.Model.check_law`
    then holds the ideal law's T0 in the sigma too). ln A is smoothed by a polynomial (degree up to 3,
    one per 6 cycles); its largest rise (a later value above an earlier one) is compared with
    :data:`RISE_SIGMAS` sigmas of the smoothed curve (the fit's residual sigma times
    sqrt((degree + 1) / N)) and with :data:`NEAR_FLOOR`. Half a beat or less over the record may only
    steepen the decay, and several beats are more than the polynomial follows: neither is seen here."""
    ok = np.isfinite(amplitudes) & (amplitudes > 0.0)
    t, a = times[ok], np.log(amplitudes[ok])
    n = len(a)
    degree = int(min(3, max(1, n // 6)))
    if n < degree + 4:
        return False
    x = (t - t.mean()) / max(float(np.ptp(t)), 1e-300)
    smooth = np.polyval(np.polyfit(x, a, degree), x)
    sigma = math.sqrt(float(np.sum((a - smooth) ** 2)) / (n - degree - 1) * (degree + 1) / n)
    rise = float(np.max(smooth - np.minimum.accumulate(smooth)))
    return rise > max(RISE_SIGMAS * sigma, NEAR_FLOOR)


DECAY_P = 1e-6  # a decay this unlikely under one mode's damping law: two modes (:func:`decay_misfit`)


def decay_misfit(times: np.ndarray, amplitudes: np.ndarray, sd: np.ndarray, degree: int) -> float:
    """The p-value of the cycles' amplitudes (at their centre ``times``, ``sd`` their sds) decaying as one
    mode's do: ln A fitted by d ln A / dt = -(a + b A + c / A), a, b, c >= 0 (linear, quadratic and dry
    damping), against the most flexible envelope the record fit allows (a Chebyshev series of
    ``degree``, :data:`.phase_law._ENVELOPE_DEGREE`), by the F ratio of the misfit that law adds over
    that envelope's residual variance. A second mode near the torsion's frequency adds to the swing a
    term of its own decay and phase: the sum's envelope wobbles at the beat, or, under half a beat,
    bends as no damping law bends it (two exponentials of different rates)."""
    ok = np.isfinite(amplitudes) & (amplitudes > 0.0) & np.isfinite(sd) & (sd > 0.0)
    t, log_a, w = times[ok] - times[ok][0], np.log(amplitudes[ok]), 1.0 / sd[ok]
    n = len(t)
    top = min(degree, n - 2)
    if top < 5:
        return 1.0
    u = 2.0 * t / max(float(t[-1]), 1e-300) - 1.0
    x = np.polynomial.chebyshev.chebvander(u, top) * w[:, None]
    flexible = log_a * w - x @ np.linalg.lstsq(x, log_a * w, rcond=None)[0]
    chi_top = float(flexible @ flexible)
    steps = np.diff(t)

    def residual(p):
        la0, a, b, c = p

        def rate(v):  # d ln A / dt (v clipped: a trial step of the search may send ln A far off)
            v = min(max(v, -700.0), 700.0)
            return -(a + b * math.exp(v) + c * math.exp(-v))

        out = np.empty(n)
        out[0] = la = la0
        for k, h in enumerate(steps):  # RK4 at the cycles' spacing: (rate h)^5 ~ 1e-10 of a slow decay
            k1 = rate(la)
            k2 = rate(la + 0.5 * h * k1)
            k3 = rate(la + 0.5 * h * k2)
            k4 = rate(la + h * k3)
            la = la + h * (k1 + 2.0 * k2 + 2.0 * k3 + k4) / 6.0
            out[k + 1] = la
        return (out - log_a) * w

    # started from the decay's mean rate taken as all linear, all quadratic or all dry, whichever fits
    # best: from it the search reached the best of all three's minima within 3e-7 of chi^2 on 65 decays
    # of one and of two modes (tests/test_near_mode.py's), at a third of the cost
    slope = max(-float(np.polyfit(t, log_a, 1)[0]), 1e-9)
    mean = math.exp(float(np.mean(log_a)))
    starts = [[log_a[0], slope, 0.0, 0.0], [log_a[0], 0.0, slope / mean, 0.0], [log_a[0], 0.0, 0.0, slope * mean]]
    start = min(starts, key=lambda p: float(np.sum(residual(np.array(p)) ** 2)))
    best = 2.0 * least_squares(residual, start, bounds=([-np.inf, 0.0, 0.0, 0.0], np.inf), x_scale="jac").cost
    dof = top + 1 - 4
    ratio = (best - chi_top) / dof / max(chi_top / (n - top - 1), 1e-300)
    return float(fisher.sf(max(ratio, 0.0), dof, n - top - 1))
