"""A second mode near the first one's frequency, seen in the envelope: damping never lifts a swing.

A sway within ~10 % of the torsion's frequency beats into the record. In the frame turning at omega0
the analytic signal is A(t) + c2 e^(i dw t): the beat moves the complex amplitude round a circle, so
the envelope and the phase wobble together, of the same relative size, in quadrature. The periodogram
search of :mod:`.second_mode` refuses that band (the first mode sweeps it: its own law misfit stands
there). To first order in its size a beat is the same as an amplitude law whose frequency moves with
ln A at the beat frequency, and the law the record learns takes it within its prior where it makes
less than a beat over the record: the learned law's extrapolation to zero swing then carries the beat
into T0. What tells it apart is that damping only shrinks the swing: where the cycles' envelope rises
again (:func:`envelope_rises`), :meth:`.phase_law.Model.check_law` holds T0 under the ideal law in the
sigma as well, as it does for a law past its prior.

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
