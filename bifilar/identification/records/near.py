"""A second mode near the first one's frequency: found in the whole fit's residual, its doubt in omega0.

A sway within ~10 % of the torsion's frequency beats into the record. In the frame turning at omega0
the analytic signal is A(t) + c2 e^(i dw t): the beat moves the complex amplitude round a circle, so
the envelope and the phase wobble together, of the same relative size, in quadrature. An amplitude
law only ties the phase to |A| monotonically and damping only shrinks |A|, so neither explains it;
left in, it takes the law's excess and biases the mean frequency by up to ~c2 dw. The periodogram
search of :mod:`.second_mode` refuses that band (the first mode sweeps it: its own law misfit stands
there), so the whole fit (:mod:`.whole`) asks here instead, on its own Jacobian and residual:
:func:`scan` adds a sinusoid at each trial omega2 within :data:`NEAR_BAND` of omega0 (its two
amplitudes linear, the rest of the model linearised) and measures how much the residual's sum of
squares falls. The fall, in noise variances, is chi^2 with 2 degrees of freedom at each frequency when
there is no mode; over the band's ~2 NEAR_BAND omega0 span / 2 pi independent frequencies the
look-elsewhere threshold is 2 ln(M / :data:`NEAR_ALPHA`) (family-wise false alarms at NEAR_ALPHA). The
noise variance is the residual's, scaled by the scan's median fall away from omega0 where the noise
is coloured (a median of 2 ln 2 for white noise).

The omega2 where the sum of squares is within chi^2_1(95 %) noise variances of its least are the
plausible ones (a profile over omega2); omega0's linearised shift over them is a doubt the joint
Jacobian (at the best omega2 only) may not carry where the beat is not resolved (less than one beat
over the record: the sinusoid and the first mode's frequency trade off nonlinearly). :func:`profile_sigma`
gives it, as half that range over 1.96.

To first order in its size a beat is the same as an amplitude law whose frequency moves with ln A at
the beat frequency, and the law the record learns takes it within its prior where it makes less than
a beat over the record. What tells it apart is that damping only shrinks the swing: where the cycles'
envelope rises again (:func:`envelope_rises`), :meth:`.phase_law.Model.check_law` holds T0 under the
ideal law in the sigma as well, as it does for a law past its prior. (:func:`scan` is not yet used by
the record fit: searched on the whole fit's residual it finds the beat's mirror image, the law having
taken the beat; issue 37 item 1 is open.)
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.stats import chi2

NEAR_BAND = 0.12  # searched: omega2 / omega0 within 1 -+ this (the sways are within 0.93-1.07 T0)
NEAR_ALPHA = 0.01  # family-wise false-alarm probability of the near-band search
NEAR_FLOOR = 1e-3  # relative amplitude below which a near "mode" is the first mode's own law misfit
# (:func:`.second_mode.outside`: a noiseless record's misfit fitted as one at 2.7e-4 of the swing)
_STEP = 0.25  # grid step, in resolutions 2 pi / span
_FAR = (0.6, 0.8, 1.25, 1.5)  # the octave bands (relative to omega0) where the noise colour is read


@dataclass(frozen=True)
class Scan:
    """The near-band search (:func:`scan`): the best omega2 (rad/s), the sum of squares' fall there in
    noise variances (``gain``) against the look-elsewhere ``threshold``, the noise scale (the white
    variance's factor), and the plausible omega2 with omega0's linearised shift at each."""

    omega: float
    gain: float
    threshold: float
    colour: float
    plausible: np.ndarray
    shifts: np.ndarray

    @property
    def significant(self) -> bool:
        return self.gain > self.threshold


def _falls(tau, q_basis, row, r, grid):
    """For each omega2 of ``grid``: the sum of squares' fall and omega0's shift (the residual regressed
    on the model's linearised columns and the sinusoid's two)."""
    gains, shifts = np.empty(len(grid)), np.empty(len(grid))
    for j, w in enumerate(grid):
        c = np.column_stack([np.cos(w * tau), np.sin(w * tau)])
        proj = q_basis.T @ c
        cp = c - q_basis @ proj
        gram = cp.T @ cp
        if np.linalg.cond(gram) > 1e12:
            gains[j], shifts[j] = 0.0, 0.0
            continue
        gamma = np.linalg.solve(gram, cp.T @ r)
        gains[j] = float(r @ (cp @ gamma))
        shifts[j] = float(row @ (proj @ gamma))  # omega0's shift
    return gains, shifts


def scan(tau: np.ndarray, jac: np.ndarray, r: np.ndarray, omega0: float) -> Scan | None:
    """The near-band search on a fit's residual ``r`` and its Jacobian ``jac`` (of the residual, omega0
    its second column) at sample times ``tau`` (s) (module docstring). None if the record is too short
    to have a grid."""
    n, k = jac.shape
    span = float(tau[-1] - tau[0])
    if n <= k + 4 or span <= 0.0:
        return None
    resolution = 2.0 * math.pi / span
    q_basis, upper = np.linalg.qr(jac)
    keep = np.abs(np.diag(upper)) > 1e-12 * np.max(np.abs(np.diag(upper)))
    if not keep[1]:
        return None
    q_basis, upper = q_basis[:, keep], upper[np.ix_(keep, keep)]
    # a shift d of the residual's parameters moves the model by -jac d = -Q R d: the residual regressed
    # on [-jac, C] gives d = R^-1 Q^T C gamma (less a constant, Q^T r ~ 0 at the fit's optimum)
    row = np.linalg.inv(upper)[int(np.sum(keep[:1]))]
    variance = float(r @ r) / (n - k)
    grid = omega0 * np.arange(1.0 - NEAR_BAND, 1.0 + NEAR_BAND, _STEP * resolution / omega0)
    gains, shifts = _falls(tau, q_basis, row, r, grid)
    nyquist = math.pi * (n - 1) / span
    far = np.concatenate([omega0 * np.arange(_FAR[0], _FAR[1], resolution / omega0),
                          omega0 * np.arange(_FAR[2], _FAR[3], resolution / omega0)])
    far = far[far < nyquist]
    colour = 1.0
    if len(far) >= 8:
        colour = max(1.0, float(np.median(_falls(tau, q_basis, row, r, far)[0])) / variance / math.log(4.0))
    gains = gains / (variance * colour)
    independent = max(1.0, 2.0 * NEAR_BAND * omega0 / resolution)
    threshold = 2.0 * math.log(independent / NEAR_ALPHA)
    best = int(np.argmax(gains))
    within = gains >= gains[best] - chi2.ppf(0.95, 1)
    return Scan(float(grid[best]), float(gains[best]), threshold, colour, grid[within], shifts[within])


def profile_sigma(found: Scan) -> float:
    """omega0's doubt over the plausible omega2 (rad/s): half the range of its shifts over 1.96."""
    return 0.5 * float(np.ptp(found.shifts)) / 1.96 if len(found.shifts) > 1 else 0.0


def degenerate(found: Scan, omega0: float, span: float) -> bool:
    """Whether the plausible omega2 reach within one resolution of omega0: less than a beat over the
    record, the second mode cannot be told from the first's frequency and amplitude."""
    return bool(np.any(np.abs(found.plausible - omega0) < 2.0 * math.pi / span))


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
