"""The zero-amplitude period of a measured record, cycle by cycle: each cycle's phase, one law for all.

The record is an angle, an angular rate or a signal only proportional to the angle (:mod:`.read`),
sampled at increasing, possibly uneven times with gaps, with noise (white or correlated over many
frames), a drifting offset, glitches, stuck values, a tracker locking on, and possibly a second mode
beating in. The fit never models the damping, the drift or the tracker: it measures each cycle on its
own and asks one thing of all of them together, the rig's amplitude law.

1. Cycles (:func:`_cycles`): the record is cut into windows one local period long; in each, least
   squares gives the offset and the odd harmonics 1, 3, .. 7 (as many as the window's samples hold)
   of the phase w u + c u^2 / 2 under the envelope e^(lam u) (u the time from the window's centre; w,
   c and lam the local frequency, its drift and the decay the last pass's law gives), the frequency
   itself refined in the window (:func:`_window_fit`): the fundamental's phase at the centre with its
   variance, and its amplitude. Over a whole cycle these are orthogonal, so the offset, its drift and
   the waveform's harmonics take nothing from the phase. A slow baseline (the offsets, smoothed across
   cycles) is subtracted before the last pass, so that no window sees a slope.
2. Left out (:mod:`.clean`): stuck values, single-sample glitches beyond 6 robust sigmas of the
   record's and the neighbourhood's second differences within a window, and whole cycles that are not
   the rig's (a residual far above the record's and its neighbours': the tracker locking on; too few
   samples: frames lost; an amplitude that jumps away from its neighbours'; a phase more than 6 sigmas
   and 0.02 rad off the law: the tracker jumped).
3. A second mode: a peak of the periodogram of the record less the law's first mode, away from the
   first mode's harmonics, is fitted as a damped sinusoid, subtracted and the cycles refitted; one the
   cycles do not show is looked for again in the whole fit's residual (step 6).
4. The law (:mod:`.law`): the phases follow Phi(t) = phi0 + omega0 int dt / (R(A(t)) E(A(t)) D(t)), A(t)
   the peak amplitude (the cycles' amplitudes through the law's waveform, ln A a Chebyshev series of
   the degree an F test allows: :class:`_Envelope`), R the ideal law, E = 1 + ds A^2 + dq A^4 + d6 A^6
   the real rig's excess with Gaussian priors, D the damping's shift of the frequency. Weighted least
   squares gives omega0 = 2 pi / T0, the zero-amplitude period, and the excess.
5. Uncertainty: the sandwich covariance with the phase residuals' scores summed over blocks of
   :data:`BLOCK_TAUS` integrated autocorrelation times (tracker noise correlated over many frames, a
   wandering offset, a left-over beat all make neighbouring cycles err together), never below the
   white-noise covariance, plus what the envelope's own uncertainty adds (Murphy-Topel); the prior
   rows add the law's doubt, reported apart (``period_std_law``), with the learned law's own doubts
   (:meth:`_Model.check_law`: its extrapolation to zero swing, a law no rig has). A delete-a-group
   jackknife of the law's fit over 20 groups of cycles checks it (:meth:`_Model.jackknife`): where its
   variance is above the covariance's at 95 %, the jackknife's (Student-t scaled) is the statistical
   variance.
   Tracking noise correlated over a fraction of a cycle moves a cycle's phase, amplitude and waveform
   together; on such video records the covariance alone covered the truth in 77 % of 95 % intervals.
6. The whole record (:func:`_whole`): every kept sample fitted at once with the law's shape held, for
   the efficiency of a plain damped-sine fit; its sandwich over cycles (scaled to the Student-t
   interval of its few blocks: :func:`_few_blocks`) plus what the law's uncertainty adds is the
   statistical sigma of T0.

A proportional record (pixels) has no known scale: with ``scale`` (signal units per rad) it is an
angle record; with ``max_amplitude`` (rad, the largest swing it can have had) the scale kappa is fitted
with a prior uniform on [0, max_amplitude / first amplitude]; with neither the law cannot be applied
(a small swing is assumed, the period is the one at the record's amplitudes) and the fit says so.
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import least_squares
from scipy.ndimage import median_filter
from scipy.signal import lombscargle
from scipy.stats import chi2, norm
from scipy.stats import t as student_t

from .bounds import Deadline, binned, window_centres
from .clean import OUTLIER_Z, Rejected, spans, stuck
from .law import EXCESS_PRIOR, LINEAR, AmplitudeLaw, Table
from .read import KINDS, MIN_SAMPLES

MIN_CYCLES = 3  # cycles measured on their own: fewer, and no phase slope can be told from the law
MIN_SNR = 3.0  # the fundamental's RMS against the residual's: a noise-only fit reaches ~0.2-0.5
SECOND_MODE_POWER = 60.0  # peak / local median of the residual periodogram: noise peaks reach ~10-15
JACKKNIFE_GROUPS = 20  # groups of cycles of the jackknife (_Model.jackknife): its variance has ~19 dof
BLOCK_TAUS = 4.0  # batch-means block, in integrated autocorrelation times of the phase residuals
_WINDOW_SAMPLES = 12  # a window's terms (up to 9 with many samples a cycle) need residual degrees of freedom
_WINDOW_GAP = 0.35  # largest gap inside a window, in windows: more and its terms are not orthogonal
_BAD_RMS = 3.0  # a cycle's residual RMS above this times the record's median: not the rig's motion
# ... and above this share of its own amplitude: a tracker that has not locked on writes values tens of
# per cent off the swing, where what a window's model leaves of a clean large swing is below 1 %
_LOCK_FLOOR = 0.02
_SECOND_DECAY_SPANS = 4.0  # the most a second mode may decay over the record, in e-folds
_SECOND_SHARE = 0.5  # the largest second mode, relative to the first mode's largest swing
_FREQUENCY_STEPS = 3  # Gauss-Newton steps on a window's frequency
_FREQUENCY_RANGE = 0.05  # the largest relative step (a window's swing is within 5 % of the model's)
_GLITCH_NEIGHBOURHOOD = 31  # samples (about half a cycle of a 60 fps video at 1 s): a glitch's scale
_JUMP = math.log(1.5)  # a cycle's amplitude this far (in ln) from its neighbours' median: a jump
_PHASE_Z = 6.0  # a cycle's phase this many robust sigmas off the law: a slip (left out)
# ... and this far in rad: a tracker's jump moves a window's phase by a good part of a radian, where
# what the law's few terms leave at the largest swings of a clean record is ~1e-3 rad
_SLIP_FLOOR = 0.02
# At most this many samples in a periodogram (starting values only). The record's own frequency is taken
# from as many bin means of a longer record, not a stride: a stride kept the full rate's noise, whose
# derivative (1e-3 rad at 2500 Hz: 2.5 rad/s) drowned a 0.3 rad swing's (0.9 rad/s), and a 400-cycle
# record came out at 2.4 rad/s for 3.13 (its second half at 6.8).
_PERIODOGRAM_SAMPLES = 1024
_GRID_PER_CYCLE = 8  # integration points of the law's phase integral per cycle (trapezoid, smooth)
_PASSES = 3  # cycles refitted with the law's local frequency and the baseline removed
_BASELINE_CYCLES = 3.0  # the baseline: the offsets smoothed over this many cycles either side
_ENVELOPE_DEGREE = 8  # at most: ln A of a decay to a third of the start over the record needs ~5
_ENVELOPE_F = 9.0  # one more term of the envelope must lower chi^2 by this times the residual variance
# The real law's excess E = 1 + ds A^2 + dq A^4 + d6 A^6: a stronger cubic restoring term alone already
# gives all three (over 0.4..1.25 rad, A^2 and A^4 alone leave 2e-4 of it, enough to bias T0 by 1e-4).
EXCESS_TERMS = ("ds", "dq", "d6")
# A record whose T(A) asks for an excess this many prior sigmas from the ideal law at some amplitude it
# swung through follows no rig's law (real ones differ by up to 30-40 %, about one prior sigma): a mode
# close to the torsion's frequency beating in (its slow phase wobble reads as a chirp), or a rig file
# whose law is wrong. Either T0, the one learned or the one under the ideal law, may then be the right
# one: their difference enters T0's sigma (:meth:`_Model.check_law`) and the fit says so (``Law.conflict``).
# Learned alone from a gyro record with a mode 3 % from the torsion's, T0 came out 1.4 % off at 5 sigma.
LAW_CONFLICT = 3.0
_HELD = 1e-6  # a held excess's prior sd, relative to the prior's own: the data cannot move it


@dataclass(frozen=True)
class Law:
    """What the fit says of the amplitude law: the ideal law's kind and coefficient s (1/rad^2, at
    the fitted omega0), the excess ds, dq (and their sigmas), the coefficient used, s + ds, and its
    sigma; ``learned``: how far the record itself determined ds (1: wholly, 0: left at the prior)."""

    kind: str
    ideal: float | None
    excess: float
    excess_std: float
    quartic: float
    quartic_std: float
    learned: float
    note: str = ""
    conflict: float | None = None  # past LAW_CONFLICT: the excess the record asked for, in prior sigmas

    @property
    def coefficient(self) -> float | None:
        return None if self.ideal is None else self.ideal + self.excess

    def as_dict(self) -> dict:
        return {"kind": self.kind, "ideal": self.ideal, "coefficient": self.coefficient, "excess": self.excess,
                "excess_std": self.excess_std, "excess_quartic": self.quartic, "excess_quartic_std": self.quartic_std,
                "learned": self.learned, "note": self.note, "conflict": self.conflict}


@dataclass(frozen=True)
class OscillationFit:
    """A fitted record (module docstring). Times in s, angles in rad (signal units where the scale of a
    proportional record is unknown).

    ``period`` is T0 = 2 pi / omega0; ``period_std`` its whole standard deviation, the root-sum-square
    of ``period_std_statistical`` (the record's noise, block sandwich) and ``period_std_law`` (the
    amplitude law's doubt, from the priors); ``period_std_white`` is the white-noise sigma, for
    comparison. ``prior_gain`` maps the law's prior errors (in prior sigmas) to T0 (s per sigma):
    records of one rig share that error (pooling). ``amplitude``: peak rotation in the first and last
    cycle (None where the scale is unknown). ``cycle_*``: the measured cycles. ``jackknife``: the groups
    of cycles of the jackknife that set the statistical sigma (0: the covariance held;
    :meth:`_Model.jackknife`).
    """

    period: float
    period_std: float
    period_std_statistical: float
    period_std_law: float
    period_std_white: float
    prior_gain: np.ndarray
    law: Law
    amplitude: tuple[float, float] | None
    damping: dict
    offset: float
    drift: float
    rms: float
    outliers: np.ndarray
    rejected: Rejected
    second_mode: tuple[float, float, float] | None
    block: int
    jackknife: int
    samples: int
    cycles: int
    cycle_time: np.ndarray  # s, centre of each cycle used
    cycle_period: np.ndarray  # s, between neighbouring cycles (nan where not neighbours)
    cycle_amplitude: np.ndarray  # rad (or signal units), peak, at each cycle
    law_curve: tuple[np.ndarray, np.ndarray, np.ndarray]  # amplitude, T(A) fitted, T(A) ideal
    t: np.ndarray
    y: np.ndarray
    fitted: np.ndarray  # the model at every sample time (nan where no cycle covers it)
    kept: np.ndarray  # boolean mask of the samples used
    binned: int = 1  # a dense record's samples a bin (:func:`.bounds.binned`): t, y and samples are the bins'


@dataclass
class _Record:
    """The samples being fitted and what is known of them."""

    tau: np.ndarray  # s from the first sample
    y: np.ndarray
    kind: str
    usable: np.ndarray  # not stuck, not a glitch
    step: float  # median sample spacing, s
    omega: float = math.nan  # the record's own frequency, rad/s (:func:`_rough_frequency`)
    binned: int = 1  # samples a bin of a dense record (:func:`.bounds.binned`)
    deadline: Deadline = field(default_factory=Deadline)


@dataclass
class _Cycles:
    """Local fits of one pass: per window, its centre (s), local frequency (rad/s) and decay rate, phase of the
    fundamental at the centre (rad, wrapped), its variance, the fundamental's amplitude and the
    offset (signal units), the residual RMS, the sample indices and the terms (for the model)."""

    centre: np.ndarray
    omega: np.ndarray
    decay: np.ndarray  # d ln(amplitude) / dt at the centre, 1/s
    phase: np.ndarray
    phase_var: np.ndarray
    fundamental: np.ndarray
    offset: np.ndarray
    rms: np.ndarray
    index: list
    terms: list
    good: np.ndarray = field(default=None)
    reason: list = field(default=None)
    chirp: np.ndarray = field(default=None)  # d omega / dt at the centre, rad/s^2
    fitted_omega: np.ndarray = field(default=None)  # the window's own frequency (:func:`_window_fit`)


def fit_oscillation(t, y, kind: str, law: AmplitudeLaw = LINEAR, *, excess_prior: float = EXCESS_PRIOR,
                    scale: float | None = None, max_amplitude: float | None = None,
                    second_mode: bool = True, deadline: Deadline | None = None) -> OscillationFit:
    """Fit the module's model to samples ``y`` at increasing times ``t`` (s).

    ``excess_prior``: the prior std of ds / s and dq / s (0: the ideal law exactly). ``scale`` and
    ``max_amplitude``: what is known of a proportional record's scale (module docstring). A dense record
    is fitted in bins (:func:`.bounds.binned`). Raises ValueError naming what is wrong with a record that
    cannot be used, :class:`.bounds.WorkSpent` once ``deadline`` is spent.
    """
    if kind not in KINDS:
        raise ValueError(f"kind must be one of {KINDS}, got {kind!r}")
    t, y = np.asarray(t, dtype=float), np.asarray(y, dtype=float)
    if t.ndim != 1 or t.shape != y.shape or len(t) < MIN_SAMPLES:
        raise ValueError(f"need two 1-D arrays of equal length >= {MIN_SAMPLES}, got shapes {t.shape} and {y.shape}")
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(y)) and np.all(np.diff(t) > 0.0)):
        raise ValueError("times must increase and every sample be finite")
    if kind == "proportional" and scale is not None:
        y, kind = y / scale, "angle"
    tau = t - t[0]
    rec = _Record(tau, y, kind, ~stuck(y), float(np.median(np.diff(tau))), deadline=deadline or Deadline())
    rejected = Rejected(stuck=int((~rec.usable).sum()))
    rec.omega = omega = _rough_frequency(rec)
    tau, y, rec.binned = binned(tau, y, rec.usable, omega, rec.step)  # a dense record: its bins (.bounds)
    if rec.binned > 1:
        t = t[0] + tau
        rec.tau, rec.y, rec.usable, rec.step = tau, y, np.ones(len(y), dtype=bool), rec.binned * rec.step
    if omega * tau[-1] / (2.0 * math.pi) < MIN_CYCLES:
        raise ValueError(f"the record holds {omega * tau[-1] / (2.0 * math.pi):.3g} cycles; at least {MIN_CYCLES} "
                         "are needed")
    uses_law = law.kind != "linear" and (kind != "proportional" or max_amplitude is not None)
    model = _Model(law if uses_law else LINEAR, kind, excess_prior if uses_law else 0.0, max_amplitude)
    baseline = np.zeros(len(y))
    second = None
    cyc = _pass(rec, baseline, lambda c: (np.full(len(c), omega), np.zeros(len(c))), second)
    _check_swing(cyc, law, kind)
    model.fit(cyc)
    for _ in range(_PASSES):
        if second_mode:  # (re-)estimated on the record as it is, under the latest first mode
            second = _second_mode(rec, cyc, baseline, model)
        cyc = _pass(rec, baseline, model.local, second)
        model.fit(cyc)
        baseline = baseline + _baseline(rec.tau, cyc)  # the offsets left under the last baseline
    cyc = _pass(rec, baseline, model.local, second)
    model.fit(cyc, slips=True)
    model.check_law(cyc)
    whole = _whole(rec, cyc, model, baseline, second)
    return _result(rec, t, cyc, model, baseline, whole, rejected)


class SwingError(ValueError):
    """A record whose swing (rad, ``swing``) is past what the rig's law can hold (``limit``)."""

    def __init__(self, swing: float, limit: float):
        super().__init__(f"a swing of {swing:.4g} rad, past the law's {limit:.4g} rad")
        self.swing, self.limit = swing, limit


def _check_swing(cyc: _Cycles, law: AmplitudeLaw, kind: str) -> None:
    """Raise :class:`SwingError` if the largest fitted cycle swings past the law's limit: an angle in
    degrees read as rad, a rate in deg/s, the wrong column (the pipeline names which)."""
    if law.kind == "linear" or kind == "proportional":
        return
    fitted = np.isfinite(cyc.fundamental)
    if not fitted.any():
        return
    swing = cyc.fundamental[fitted] / (cyc.omega[fitted] if kind == "rate" else 1.0)
    largest = float(np.median(np.sort(swing)[-3:]))  # a glitched cycle alone does not refuse a record
    if largest > law.limit:
        raise SwingError(largest, law.limit)


def _rough_frequency(rec: _Record) -> float:
    """Angular frequency (rad/s) of the strongest oscillation: the Lomb-Scargle peak of the signal's
    derivative (of the signal itself for a rate), so that an offset, a slow drift or a tracker's
    lock-on jumps do not make the peak; differences across gaps and beyond 6 robust sigmas are left out. A
    record longer than :data:`_PERIODOGRAM_SAMPLES` is taken in as many bin means."""
    keep = rec.usable
    tau, y = rec.tau[keep], rec.y[keep]
    group = -(-len(tau) // _PERIODOGRAM_SAMPLES)
    if group > 1:  # bin means of a long record (their noise falls as the bins grow)
        m = len(tau) // group * group
        tau, y = tau[:m].reshape(-1, group).mean(axis=1), y[:m].reshape(-1, group).mean(axis=1)
    step = rec.step * group
    if rec.kind == "rate":
        x, v = tau, y - np.median(y)
    else:
        dt = np.diff(tau)
        ok = dt <= 1.5 * step
        x, v = 0.5 * (tau[1:] + tau[:-1])[ok], (np.diff(y) / dt)[ok]
    if len(x) < MIN_SAMPLES:
        raise ValueError(f"{len(x)} usable samples; at least {MIN_SAMPLES} are needed")
    # a step (the tracker locking on) is a spike of the derivative, clipped here; the derivative weighs a
    # mode by its frequency squared, which a second mode beating in (a few percent of the swing, at most a
    # few times its frequency) does not make up for, while the tracker's red noise and drift fall away
    dev = np.abs(v - np.median(v))
    mad = 1.4826 * float(np.median(dev)) or float(dev.max()) or 1.0
    x, v = x[dev <= OUTLIER_Z * mad], v[dev <= OUTLIER_Z * mad]
    span = rec.tau[-1]
    resolution = 2.0 * math.pi / span
    nyquist = math.pi * (len(x) - 1) / (x[-1] - x[0])
    grid = np.arange(MIN_CYCLES * resolution, nyquist, 0.5 * resolution)
    if len(grid) < 3:
        raise ValueError(f"the record is too short or too sparse to hold {MIN_CYCLES} cycles")
    power = lombscargle(x, v, grid, floating_mean=True)
    k = int(np.argmax(power))
    if k == 0 or k == len(grid) - 1:
        raise ValueError(f"no oscillation peak inside {grid[0]:.4g}..{grid[-1]:.4g} rad/s: fewer than "
                         f"{MIN_CYCLES} cycles, or undersampled")
    fine = grid[k] + np.linspace(-0.5, 0.5, 21) * resolution
    fpower = lombscargle(x, v, fine, floating_mean=True)
    return float(fine[int(np.argmax(fpower))])


def _pass(rec: _Record, baseline: np.ndarray, local, second) -> _Cycles:
    """One pass over the record: windows one local period long, centred a local period apart from the
    first sample (:func:`.bounds.window_centres`: never more than the record's band allows), fitted
    (:func:`_cycles`) with the local frequency and decay rate ``local(times)``
    gives, glitches rejected and refitted, bad cycles marked."""
    rec.deadline.check()
    y = rec.y - baseline - (second.signal(rec.tau) if second is not None else 0.0)
    centres = window_centres(float(rec.tau[-1]), rec.omega, local)
    omegas, decays = local(centres)
    step = 0.25 * float(np.min(2.0 * math.pi / omegas))
    chirps = (local(centres + step)[0] - local(centres - step)[0]) / (2.0 * step)
    usable = rec.usable.copy()
    for _ in range(4):
        cyc = _cycles(rec.tau, y, usable, centres, omegas, decays, chirps, rec.kind == "rate")
        glitch = _glitches(rec.tau, y, cyc, len(y))
        if not glitch.any():
            break
        usable &= ~glitch
    cyc.usable = usable
    _mark(cyc)
    return cyc


def _glitches(tau: np.ndarray, y: np.ndarray, cyc: _Cycles, n: int) -> np.ndarray:
    """Single-sample glitches among the ``n`` samples: a window's residual stepping out of line with its
    neighbours in the same window, d_i = r_i - (r_prev + r_next) / 2 (at a window's ends, where the
    next window's fit takes over, r_i - 2 r_next + r_next_next), beyond :data:`OUTLIER_Z` robust sigmas of d, over the
    record and over its neighbourhood, and the largest of its neighbours'. A glitch is a spike; what a
    model leaves of a clean record (a harmonic it does not hold, at a large swing) is smooth, and
    stays however small the noise."""
    glitch = np.zeros(n, dtype=bool)
    parts = []
    for c, w, lam, chirp, idx, coef in zip(cyc.centre, cyc.fitted_omega, cyc.decay, cyc.chirp, cyc.index,
                                           cyc.terms):
        if idx is None or len(idx) < 3:
            continue
        x = y[idx] - _basis(tau[idx] - c, w, lam, len(coef) - 2, chirp) @ coef
        d = np.empty(len(x))
        d[1:-1] = x[1:-1] - 0.5 * (x[:-2] + x[2:])
        d[0], d[-1] = x[0] - 2.0 * x[1] + x[2], x[-1] - 2.0 * x[-2] + x[-3]
        parts.append((idx, d))
    if not parts:
        return glitch
    idx = np.concatenate([p[0] for p in parts])
    d = np.abs(np.concatenate([p[1] for p in parts]))
    if len(d) < 5:
        return glitch
    sigma = 1.4826 * float(np.median(d))
    # against its neighbourhood's too: where the noise is tiny, what the model leaves at the largest
    # swings (smooth, but far above the noise) has second differences above the record's sigma
    local = 1.4826 * median_filter(d, size=_GLITCH_NEIGHBOURHOOD, mode="nearest")
    big = d > OUTLIER_Z * np.maximum(np.maximum(local, sigma), 1e-300)
    peak = d >= np.maximum(np.roll(d, 1), np.roll(d, -1))
    glitch[idx[big & peak]] = True
    return glitch


def _cycles(tau, y, usable, centres, omegas, decays, chirps, rate: bool) -> _Cycles:
    """Least squares in every window (module docstring, step 1); windows without the samples to
    determine their terms are returned marked, with nan phase."""
    n = len(centres)
    out = _Cycles(centres, omegas, decays, np.full(n, np.nan), np.full(n, np.nan), np.full(n, np.nan),
                  np.full(n, np.nan), np.full(n, np.nan), [None] * n, [None] * n)
    out.reason = [None] * n
    out.chirp = chirps
    out.fitted_omega = np.array(omegas, dtype=float)
    out.peak_ratio = np.full(n, np.nan)
    out.amplitude_var = np.full(n, np.nan)
    for k, (c, w, lam, chirp) in enumerate(zip(centres, omegas, decays, chirps)):
        half = math.pi / w
        lo, hi = np.searchsorted(tau, [c - half, c + half])
        idx = np.arange(lo, hi)[usable[lo:hi]]
        if len(idx) < _WINDOW_SAMPLES:
            out.reason[k] = "too few samples"
            continue
        u = tau[idx] - c
        edges = np.concatenate([[-half], u, [half]])
        if np.max(np.diff(edges)) > _WINDOW_GAP * 2.0 * half:
            out.reason[k] = "frames lost"
            continue
        wf, x, coef = _window_fit(u, y[idx], w, lam, _harmonics(len(idx)), chirp)
        out.fitted_omega[k] = wf
        r = y[idx] - x @ coef
        dof = len(idx) - x.shape[1] - 1
        var = float(r @ r) / dof
        cov = var * np.linalg.inv(x.T @ x)
        a1, b1 = coef[1], coef[2]
        amp2 = a1 * a1 + b1 * b1
        g = np.array([b1, -a1]) / max(amp2, 1e-300)  # d phase / d (a1, b1), phase = atan2(-b1, a1)
        phase = math.atan2(-b1, a1)
        out.phase[k] = phase
        # the waveform's peak over its fundamental: a symmetric oscillator's odd harmonics all peak at
        # the turning point, a_n = alpha_n cos(n phi) - beta_n sin(n phi) (for a rate, its n-th harmonic is
        # n omega a_n)
        peak = 0.0
        for j, n in enumerate(range(1, (len(coef) - 1), 2)):
            an = coef[1 + 2 * j] * math.cos(n * phase) - coef[2 + 2 * j] * math.sin(n * phase)
            peak += an / (n if rate else 1.0)
        out.peak_ratio[k] = peak / math.sqrt(amp2)
        out.phase_var[k] = float(g @ cov[1:3, 1:3] @ g)
        out.fundamental[k] = math.sqrt(amp2)
        radial = np.array([a1, b1]) / math.sqrt(max(amp2, 1e-300))
        out.amplitude_var[k] = float(radial @ cov[1:3, 1:3] @ radial)
        out.offset[k] = coef[0]
        out.rms[k] = math.sqrt(var)
        out.index[k] = idx
        out.terms[k] = coef
    return out


def _window_fit(u: np.ndarray, y: np.ndarray, w: float, lam: float, harmonics: int, chirp: float):
    """(frequency, design, terms) of one window's least squares with its frequency refined from ``w``
    by Gauss-Newton (:data:`_FREQUENCY_STEPS` steps on the terms' joint linearisation, each kept only
    where it lowers the residual, within :data:`_FREQUENCY_RANGE` of ``w``): a window whose swing is
    far from the model's (the first pass's single frequency, a cycle the model held from its
    neighbours) would otherwise leave a residual that grows as its phase runs off the window's, and be
    taken for a tracker that has not locked on. The phase at the centre, u = 0, does not depend on the
    frequency to first order (a symmetric window), so refining it moves the residual, not the phase."""
    def solve(wf):
        x = _basis(u, wf, lam, harmonics, chirp)
        coef, *_ = np.linalg.lstsq(x, y, rcond=None)
        r = y - x @ coef
        return x, coef, float(r @ r)

    x, coef, best = solve(w)
    wf = w
    for _ in range(_FREQUENCY_STEPS):
        phase = wf * u + 0.5 * chirp * u * u
        slope = np.zeros(len(u))
        for j, n in enumerate(range(1, harmonics + 1, 2)):  # d (x @ coef) / d w
            a, b = coef[1 + 2 * j], coef[2 + 2 * j]
            slope += n * (b * np.cos(n * phase) - a * np.sin(n * phase))
        slope *= u * np.exp(lam * u)
        step = np.linalg.lstsq(np.column_stack([x, slope]), y - x @ coef, rcond=None)[0][-1]
        w_new = float(np.clip(wf + step, w * (1.0 - _FREQUENCY_RANGE), w * (1.0 + _FREQUENCY_RANGE)))
        trial = solve(w_new)
        if trial[2] >= best:
            break
        wf = w_new
        x, coef, best = trial
    return wf, x, coef


def _basis(u: np.ndarray, w: float, lam: float, harmonics: int, chirp: float = 0.0) -> np.ndarray:
    """Offset, then the odd harmonics 1, 3, .. up to ``harmonics`` (cos, sin pairs) of the phase
    w u + chirp u^2 / 2 (the frequency drifting at ``chirp`` rad/s^2 as the amplitude law slows the
    swing down), under the envelope e^(lam u) of the amplitude's own decay: a decaying swing fitted
    with a constant one would shift the centre's phase by ~lam / w, and that shift changes as the decay
    slows; a chirp left out leaves a residual ~chirp T^2 / 8 times the amplitude, far above a good
    tracker's noise at a large swing."""
    env = np.exp(lam * u)
    phase = w * u + 0.5 * chirp * u * u
    cols = [np.ones_like(u)]
    for n in range(1, harmonics + 1, 2):
        cols += [env * np.cos(n * phase), env * np.sin(n * phase)]
    return np.column_stack(cols)


def _harmonics(samples_per_cycle: float) -> int:
    """The highest odd harmonic a window can hold: the seventh where a cycle has 24 samples or more,
    the fifth from 16 (a symmetric oscillator's waveform at 1 rad holds ~1e-2 of third, ~1e-4 of fifth,
    ~1e-6 of seventh), the third from 8, the fundamental alone below."""
    return 7 if samples_per_cycle >= 24 else 5 if samples_per_cycle >= 16 else 3 if samples_per_cycle >= 8 else 1


def _mark(cyc: _Cycles) -> None:
    """``good``: the windows fitted whose residual and amplitude look like the rest (module docstring,
    step 2); ``reason`` says why the others are left out."""
    fitted = np.isfinite(cyc.phase)
    good = fitted.copy()
    if fitted.sum() >= MIN_CYCLES:
        index = np.flatnonzero(fitted)
        median_rms = float(np.median(cyc.rms[fitted]))
        for j, k in enumerate(index):
            # against the record's and its neighbours' (a residual that grows smoothly with the swing, where
            # a clean record leaves what its harmonics do not hold, is not a tracker's)
            near = np.delete(cyc.rms[index[max(0, j - 5):j + 6]], min(j, 5))
            if (cyc.rms[k] > _BAD_RMS * max(median_rms, float(np.median(near)) if len(near) else 0.0)
                    and cyc.rms[k] > _LOCK_FLOOR * cyc.fundamental[k]):
                good[k] = False
                cyc.reason[k] = "residual far above the record's (tracker not locked on)"
        amp = np.log(np.where(good, cyc.fundamental, np.nan))
        for k in np.flatnonzero(good):
            near = amp[max(0, k - 3):k + 4]
            near = near[np.isfinite(near)]
            if len(near) >= 3 and abs(amp[k] - np.median(near)) > _JUMP:
                good[k] = False
                cyc.reason[k] = "amplitude jumps away from its neighbours'"
    cyc.good = good


def _baseline(tau: np.ndarray, cyc: _Cycles) -> np.ndarray:
    """The slow offset under the oscillation at every sample: the good cycles' offsets smoothed over
    :data:`_BASELINE_CYCLES` cycles either side (:func:`smooth`), held beyond the ends."""
    g = cyc.good
    x = cyc.centre[g]
    if len(x) < 2:
        return np.full(len(tau), float(np.median(cyc.offset[g])) if g.any() else 0.0)
    width = _BASELINE_CYCLES * float(np.median(np.diff(x)))
    at = np.linspace(x[0], x[-1], max(2, 4 * len(x)))
    return np.interp(tau, at, smooth(x, cyc.offset[g], at, width))


def smooth(x: np.ndarray, y: np.ndarray, at: np.ndarray, width: float, degree: int = 1) -> np.ndarray:
    """Local polynomial regression (``degree`` 1 or 2) of ``y`` on ``x`` at the points ``at`` with
    tricube weights over +- ``width``: a running straight line (exact for a linear trend) or parabola
    (its bias a fourth-order term in width: a decaying amplitude's curvature does not bias it), where
    too few points are in reach the lower degree."""
    d = x[None, :] - at[:, None]
    u = np.abs(d) / width
    w = np.where(u < 1.0, (1.0 - u**3) ** 3, 0.0)
    out = np.empty(len(at))
    for i in range(len(at)):
        keep = w[i] > 0.0
        k = min(degree, int(keep.sum()) - 1)
        if k < 0:
            out[i] = float(np.interp(at[i], x, y))
            continue
        basis = np.vander(d[i, keep] / width, k + 1, increasing=True)
        sw = np.sqrt(w[i, keep])
        out[i] = np.linalg.lstsq(basis * sw[:, None], y[keep] * sw, rcond=None)[0][0]
    return out


class _Model:
    """The phases' law (module docstring, step 4) fitted to the good cycles of a pass.

    The amplitude the law is evaluated at is measured with noise too: it is a smooth envelope fitted to
    the cycles' amplitudes alone (:class:`_Envelope`), and what its uncertainty does to T0 is added to
    the covariance (:meth:`_covariance`).
    """

    def __init__(self, law: AmplitudeLaw, kind: str, prior: float, max_amplitude: float | None):
        self.law, self.kind, self.prior, self.max_amplitude = law, kind, prior, max_amplitude
        self.omega0 = None
        self.table: Table | None = None
        self.parent: _Model | None = None  # a jackknife refit's: its damping shift and start are the parent's
        self.held = False  # the excess held at the ideal law (:meth:`check_law`'s fit)
        self.terms = len(EXCESS_TERMS)  # the excess terms free: the rest held at zero (:meth:`check_law`)
        self.order_shift = 0.0  # omega0 learned less omega0 with one excess term fewer (rad/s)
        self.conflict = 0.0  # the largest excess of the last fit, in prior sigmas
        self.held_shift = 0.0  # omega0 learned less omega0 under the ideal law (rad/s), past LAW_CONFLICT

    def _table(self, omega: float, largest: float) -> Table:
        """The law's table at ``omega`` up to ``largest`` rad, recomputed when omega moves by over 1e-6
        of itself: the exact law's R depends on it through lam omega^2 (d R / d ln omega = eps A^2 / 2
        < 0.1 for any rig's eps and A < 1.4 rad), so R stays right to 1e-7."""
        key = getattr(self, "_key", None)
        if key is None or abs(key[0] / omega - 1.0) > 1e-6 or key[1] < largest:
            self._key, self._cached = (omega, largest), self.law.table(omega, largest)
        return self._cached

    def fit(self, cyc: _Cycles, slips: bool = False) -> None:
        """Fit the good cycles; with ``slips``, cycles whose phase is far off the law are left out
        (the tracker jumped) and the rest refitted."""
        good = cyc.good & np.isfinite(cyc.phase)
        for _ in range(3):
            if good.sum() < MIN_CYCLES:
                raise ValueError(f"{int(good.sum())} cycles could be measured on their own; at least "
                                 f"{MIN_CYCLES} are needed")
            self._solve(cyc, good)
            if not slips:
                break
            z = self.residual / np.sqrt(self.var)
            robust = 1.4826 * float(np.median(np.abs(z))) or 1.0
            slip = (np.abs(z) > _PHASE_Z * max(robust, 1.0)) & (np.abs(self.residual) > _SLIP_FLOOR)
            if not slip.any():
                break
            for k in np.flatnonzero(good)[slip]:
                cyc.good[k] = False
                cyc.reason[k] = "phase slips off the law (the tracker jumped)"
            good = cyc.good & np.isfinite(cyc.phase)

    def _solve(self, cyc: _Cycles, good: np.ndarray) -> None:
        centre, var = cyc.centre[good], cyc.phase_var[good]
        n = len(centre)
        # the cycles' peak amplitudes (signal units; of the angle for a rate) and their ln variances
        a1 = cyc.fundamental[good] / (cyc.omega[good] if self.kind == "rate" else 1.0)
        shape = _waveform(a1, cyc.peak_ratio[good])
        peak_data = a1 * (1.0 + shape[0] * a1**2 + shape[1] * a1**4)
        log_sd = np.sqrt(cyc.amplitude_var[good]) / cyc.fundamental[good]
        grid = _phase_grid(centre)
        envelope = _Envelope(centre, np.log(peak_data), log_sd)
        b_grid = envelope.basis(grid)
        amp_grid = np.exp(b_grid @ envelope.beta)
        omega = float(np.median(cyc.omega[good])) if self.omega0 is None else self.omega0
        largest = float(amp_grid.max())
        law_on = self.law.kind != "linear"
        kappa_max = None
        if self.kind == "proportional":
            kappa_max = self.max_amplitude / largest if self.max_amplitude is not None else None
            largest_rad = self.max_amplitude or 0.0
        else:
            largest_rad = largest
        s = self.law.coefficient(omega)
        if law_on:
            self.table = self._table(omega, 1.05 * largest_rad)
        phase = self._unwrap(cyc, good, grid)
        names = ["phi", "omega"]
        start = [0.0, omega]
        priors = []  # (index, centre, sd)
        if law_on and self.prior > 0.0:
            names += list(EXCESS_TERMS)
            start += [0.0] * len(EXCESS_TERMS)
            priors += [(2 + j, 0.0, (_HELD if self.held or j >= self.terms else 1.0) * self.prior * abs(s))
                       for j in range(len(EXCESS_TERMS))]
        if law_on and kappa_max is not None:
            names.append("kappa")
            start.append(0.5 * kappa_max)
            priors.append((len(names) - 1, 0.5 * kappa_max, kappa_max / math.sqrt(12.0)))
        ref = float(np.average(centre, weights=1.0 / var))
        at = np.searchsorted(grid, centre)
        at_ref = float(np.interp(ref, grid, np.arange(len(grid))))
        weights = 1.0 / np.sqrt(var)
        # the damping's own lengthening of the period, second order in it (:func:`damping_shift`)
        if self.parent is None:
            damping = damping_of(grid, amp_grid, omega)
            shift = damping_shift(damping, amp_grid)
        else:  # a ~1e-5 effect that leaving out a group of cycles moves by a few % of itself
            damping = self.parent.damping
            shift = np.interp(amp_grid, *self.parent.shift_curve)
        order = np.argsort(amp_grid)
        self.shift_curve = (amp_grid[order], shift[order])
        slow = 1.0 / (1.0 + shift)

        def terms(p):
            """(amplitude A(t) in rad on the grid, 1 / (R E D), d(1 / (R E D)) / d ln a, and its
            derivatives in the law's parameters)."""
            amp = amp_grid
            if not law_on:
                return amp, slow, np.zeros_like(amp), []
            kappa = p[names.index("kappa")] if "kappa" in names else 1.0
            a = np.minimum(kappa * amp, self.table.largest)
            a2 = a * a
            d = p[2:2 + len(EXCESS_TERMS)] if "ds" in names else np.zeros(len(EXCESS_TERMS))
            powers = [a2 ** (j + 1) for j in range(len(EXCESS_TERMS))]
            excess = 1.0 + sum(dj * pw for dj, pw in zip(d, powers))
            growth = sum(2.0 * (j + 1) * dj * a2**j for j, dj in enumerate(d))  # dE/da / a
            ratio = self.table.ratio_at(a)
            g = slow / (ratio * excess)
            dg_da = -g * (self.table.ratio_slope(a) / ratio + growth * a / excess)
            dg_dlna = a * dg_da
            slopes = [-g * pw / excess for pw in powers] if "ds" in names else []
            if "kappa" in names:  # d g / d kappa = A d g / d a: finite at kappa = 0, where a is 0
                slopes.append(amp * dg_da)
            return a, g, dg_dlna, slopes

        def integral(f):
            cum = np.concatenate([np.zeros((1,) + f.shape[1:]),
                                  np.cumsum(0.5 * (f[1:] + f[:-1]) * np.diff(grid).reshape((-1,) + (1,) * (f.ndim - 1)),
                                           axis=0)])
            return cum[at] - _interp_rows(at_ref, cum)

        def evaluate(p):
            _, g, dg, slopes = terms(p)
            big = integral(g)
            r_phase = (phase - p[0] - p[1] * big) * weights
            cols = [-np.ones(n), -big] + [-p[1] * integral(d) for d in slopes]
            j_phase = np.column_stack(cols) * weights[:, None]
            j_envelope = -p[1] * integral(dg[:, None] * b_grid) * weights[:, None]
            rp = np.array([(p[i] - c) / sd for i, c, sd in priors])
            jp = np.zeros((len(priors), len(p)))
            for row, (i, _, sd) in enumerate(priors):
                jp[row, i] = 1.0 / sd
            return r_phase, j_phase, j_envelope, rp, jp

        # Gauss-Newton with the analytic Jacobian: phi0 and omega0 enter linearly, the rest nearly so; a
        # record at one amplitude leaves a direction to the priors alone, which finite differences of a
        # residual weighted by 1 / sigma_phase would drown in rounding.
        p = np.array(start, dtype=float)
        if self.parent is not None:
            p = self.parent.params.copy()
        p[0] = float(np.average(phase - p[1] * integral(terms(p)[1]), weights=weights**2))
        for _ in range(40):
            r_phase, j_phase, _, rp, jp = evaluate(p)
            jac = np.vstack([j_phase, jp])
            res = np.concatenate([r_phase, rp])
            col = np.maximum(np.linalg.norm(jac, axis=0), 1e-300)
            step = -np.linalg.lstsq(jac / col, res, rcond=None)[0] / col
            new = p + step
            new[1] = min(max(new[1], 0.5 * omega), 2.0 * omega)
            if "kappa" in names:
                new[names.index("kappa")] = max(new[names.index("kappa")], 0.0)
            done = abs(new[1] - p[1]) <= 1e-14 * p[1] and np.all(np.abs(step[2:]) <= 1e-12 * (1.0 + np.abs(p[2:])))
            p = new
            if done:
                break
        r_phase, j_phase, j_envelope, rp, jp = evaluate(p)
        a_fit, g_fit, _, _ = terms(p)
        self.names, self.params, self.omega0 = names, p, float(p[1])
        if "ds" in names and not self.held:  # the excess at each amplitude swung through, in prior sigmas
            powers = np.array([(a_fit * a_fit) ** (j + 1) for j in range(len(EXCESS_TERMS))])
            sd = self.prior * abs(s) * np.sqrt(np.sum(powers**2, axis=0))
            self.conflict = float(np.max(np.abs(p[2:2 + len(EXCESS_TERMS)] @ powers) / np.maximum(sd, 1e-300)))
        self.residual, self.var = r_phase / weights, var
        self.ideal = s if law_on else None
        self.damping = damping
        self.scale_known = self.kind != "proportional" or "kappa" in names
        amp_signal = amp_grid
        slope = envelope.basis(grid, derivative=1) @ envelope.beta
        self.fund_at = lambda tt: np.interp(tt, grid, amp_signal)
        self.peak_at = (lambda tt: np.interp(tt, grid, a_fit)) if law_on else (lambda tt: None)
        self.rate_at = lambda tt: np.interp(tt, grid, g_fit)
        self.decay_at = lambda tt: np.interp(tt, grid, slope)
        cum = np.concatenate([[0.0], np.cumsum(0.5 * (g_fit[1:] + g_fit[:-1]) * np.diff(grid))])
        cum = cum - float(np.interp(at_ref, np.arange(len(grid)), cum))
        self._phase = (grid, cum, float(p[0]), float(p[1]), float(g_fit[0]), float(g_fit[-1]))
        self._covariance(j_phase, jp, r_phase, j_envelope, envelope.cov)

    def _unwrap(self, cyc: _Cycles, good: np.ndarray, grid: np.ndarray) -> np.ndarray:
        """The good cycles' phases made continuous: each one within pi of its predecessor advanced by
        the local frequency over the time between them."""
        centre, phase, omega = cyc.centre[good], cyc.phase[good], cyc.omega[good]
        out = np.empty(len(phase))
        out[0] = phase[0]
        for k in range(1, len(phase)):
            advance = 0.5 * (omega[k] + omega[k - 1]) * (centre[k] - centre[k - 1])
            predicted = out[k - 1] + advance
            out[k] = phase[k] + 2.0 * math.pi * round((predicted - phase[k]) / (2.0 * math.pi))
        return out

    def _covariance(self, jd, jp, r, j_envelope, cov_envelope) -> None:
        """Module docstring, step 5: white, block sandwich (at least the white one), the priors', and
        what the envelope's own uncertainty adds (a two-step estimate's correction, Murphy and Topel:
        H^-1 (J^T J_A) V_A (J_A^T J) H^-1, J_A the phases' response to the envelope's coefficients)."""
        hessian = jd.T @ jd + jp.T @ jp
        # equilibrated before the inverse: the columns differ by ~1e3 in scale (phase, omega0 times the
        # record's span, the excess times A^2), and at a nearly constant swing the direction only the
        # priors fix has ~1e-10 of the largest curvature, which pinv's cut would otherwise round away
        scale = 1.0 / np.sqrt(np.maximum(np.diag(hessian), 1e-300))
        bread_inv = scale[:, None] * np.linalg.pinv(scale[:, None] * hessian * scale[None, :]) * scale[None, :]
        stat_white, stat_sand, block = _white_and_blocks(jd, r, bread_inv)
        cross = jd.T @ j_envelope
        envelope = bread_inv @ cross @ cov_envelope @ cross.T @ bread_inv
        self.block = block
        self.cov_white = bread_inv @ (jd.T @ jd) @ bread_inv
        self.cov_stat = (stat_sand if stat_sand[1, 1] > stat_white[1, 1] else stat_white) + envelope
        self.cov_law = bread_inv @ (jp.T @ jp) @ bread_inv
        # T0's response to the law's prior being off by one sigma in each of its excess terms (their rows
        # come first): records of one rig share that error, while a proportional record's scale is its own
        law_rows = len(EXCESS_TERMS) if "ds" in self.names else 0
        self.prior_gain = (bread_inv @ jp.T)[1, :law_rows]

    def check_law(self, cyc: _Cycles) -> None:
        """Two doubts of the learned law that T0's sigma carries (:func:`_result`: the first where it
        is more than the sigma already holds), each the same cycles refitted: :attr:`order_shift`,
        omega0 as fitted less omega0 with the excess's last term held at zero, and past :data:`LAW_CONFLICT` :attr:`held_shift`, omega0 less omega0 with the whole excess
        held at the ideal law.

        The first is the extrapolation's: a record whose swing spans a narrow range (a lightly damped
        rig from 1.2 rad to 1.05) gives the law's value, slope and curvature there so precisely that
        the three terms seem determined, and their extrapolation to zero swing turns a 1e-5 misfit of
        the law's shape into 1.5e-3 of T0 (6-8 sigma of the covariance's, which only counts the
        noise); with one term fewer, where the record does determine the law, the two agree to a
        fraction of their sigma."""
        self.held_shift = self.order_shift = 0.0
        if "ds" in self.names and not self.held:
            fewer = copy.copy(self)  # _solve rebinds its results: the shallow copy keeps this fit's
            fewer.terms = len(EXCESS_TERMS) - 1
            fewer._solve(cyc, cyc.good & np.isfinite(cyc.phase))
            self.order_shift = self.omega0 - fewer.omega0
        if self.conflict <= LAW_CONFLICT:
            return
        held = copy.copy(self)
        held.held = True
        held._solve(cyc, cyc.good & np.isfinite(cyc.phase))
        self.held_shift = self.omega0 - held.omega0

    def integral_at(self, tt: np.ndarray) -> np.ndarray:
        """int dt / (R E D) from the reference time to ``tt`` (s), carried on at the end rates beyond the
        first and last cycle: the phase is phi0 + omega0 times this."""
        grid, cum, _, _, g0, g1 = self._phase
        inside = np.interp(tt, grid, cum)
        inside = np.where(tt < grid[0], cum[0] + g0 * (tt - grid[0]), inside)
        return np.where(tt > grid[-1], cum[-1] + g1 * (tt - grid[-1]), inside)

    def phase_at(self, tt: np.ndarray) -> np.ndarray:
        """The fitted law's phase Phi at times ``tt`` (the cycles' fundamental is A cos Phi)."""
        _, _, phi, omega, _, _ = self._phase
        return phi + omega * self.integral_at(tt)

    def law_induced_variance(self) -> float:
        """The variance of omega0 that the law's parameters carry (their own uncertainty, the record's and
        the priors'): Sigma_wL Sigma_LL^-1 Sigma_Lw of the whole covariance, the part a fit holding the
        law at its estimate does not see."""
        law = [i for i, n in enumerate(self.names) if n in EXCESS_TERMS or n == "kappa"]
        if not law:
            return 0.0
        cov = self.cov_stat + self.cov_law
        cross = cov[1, law]
        return float(cross @ np.linalg.pinv(cov[np.ix_(law, law)]) @ cross)

    def jackknife(self, cyc: _Cycles) -> tuple[float, int]:
        """(variance of omega0, groups): the delete-a-group jackknife of this fit over up to
        :data:`JACKKNIFE_GROUPS` contiguous groups of the good cycles, each refitted whole (waveform,
        envelope and phases). It sees every path by which a record's noise reaches omega0, those the
        covariance models (the phases, the envelope) and those it does not (noise correlated within
        a cycle, which moves phase, amplitude and waveform together; the law's shape misfit), which
        on records with tracking noise correlated over a fraction of a cycle leaves the covariance
        ~2x short (tests/test_record_sigma.py)."""
        good = np.flatnonzero(cyc.good & np.isfinite(cyc.phase))
        groups = min(JACKKNIFE_GROUPS, len(good))
        if groups < 5:
            return 0.0, 0
        omegas = []
        if self.law.kind != "linear":  # the refits' table: at their starting omega0, and room for
            self._table(self.omega0, 1.2 * self._key[1])  # an envelope a little higher without a group
        for part in np.array_split(good, groups):
            keep = cyc.good & np.isfinite(cyc.phase)
            keep[part] = False
            refit = copy.copy(self)  # _solve rebinds its results: the shallow copy keeps this fit's
            refit.parent = self
            refit._solve(cyc, keep)
            omegas.append(refit.omega0)
        omegas = np.array(omegas)
        return float((groups - 1) / groups * np.sum((omegas - omegas.mean()) ** 2)), groups

    def local_omega(self, tt: np.ndarray) -> np.ndarray:
        """The instantaneous frequency (rad/s) the fitted law gives at times ``tt``."""
        return self.omega0 * self.rate_at(tt)

    def local(self, tt: np.ndarray):
        """(instantaneous frequency, d ln(amplitude) / dt) at times ``tt``: what the next pass's windows
        are fitted with."""
        return self.local_omega(tt), self.decay_at(tt)


class _Envelope:
    """ln A(t) of the cycles' amplitudes as a Chebyshev series in the time scaled to [-1, 1], of the
    lowest degree past which one more term does not lower chi^2 by :data:`_ENVELOPE_F` times the
    residual variance (an F test at ~3 sigma), at most :data:`_ENVELOPE_DEGREE`: as smooth as the decay
    the record shows and no smoother. Fitted to the amplitudes alone: let the phases move it and their
    noise would pass for a law through it (an error in the regressor attenuates what it regresses).
    ``cov``: the coefficients' covariance, scaled by chi^2 per degree of freedom where that is above 1."""

    def __init__(self, t: np.ndarray, log_a: np.ndarray, sd: np.ndarray):
        self.t0, self.t1 = float(t[0]), float(t[-1])
        n = len(t)
        best = None
        for degree in range(0, min(_ENVELOPE_DEGREE, n - 2) + 1):
            x = self.basis(t, degree=degree) / sd[:, None]
            beta, *_ = np.linalg.lstsq(x, log_a / sd, rcond=None)
            r = log_a / sd - x @ beta
            chi = float(r @ r)
            dof = max(n - degree - 1, 1)
            if best is not None and best[2] - chi < _ENVELOPE_F * chi / dof:
                break
            best = (degree, beta, chi, dof, x)
        self.degree, self.beta, chi, dof, x = best
        self.cov = _sandwich(x, log_a / sd - x @ self.beta)

    def basis(self, t: np.ndarray, derivative: int = 0, degree: int | None = None) -> np.ndarray:
        from numpy.polynomial import chebyshev as C

        degree = self.degree if degree is None else degree
        half = max(0.5 * (self.t1 - self.t0), 1e-300)
        u = np.clip((np.asarray(t) - 0.5 * (self.t0 + self.t1)) / half, -1.0, 1.0)
        cols = []
        for k in range(degree + 1):
            c = np.zeros(k + 1)
            c[k] = 1.0
            cols.append(C.chebval(u, C.chebder(c, derivative) if derivative else c) / half**derivative)
        return np.column_stack(cols)


def _waveform(a1: np.ndarray, peak_ratio: np.ndarray) -> np.ndarray:
    """(c1, c2) of peak / fundamental = 1 + c1 a1^2 + c2 a1^4, least squares over the cycles: the real
    rig's waveform, measured on the record (its harmonics are its law's, not the ideal law's: at 1.2 rad
    they differ by ~excess x 1 %, which moves A by 1e-4 and T0 with it)."""
    if len(a1) < 3:
        return np.zeros(2)
    return np.linalg.lstsq(np.column_stack([a1**2, a1**4]), peak_ratio - 1.0, rcond=None)[0]


def _interp_rows(at: float, cum: np.ndarray):
    """``cum`` (rows on a grid index) interpolated at fractional row ``at``."""
    i = min(int(at), len(cum) - 2)
    f = at - i
    return (1.0 - f) * cum[i] + f * cum[i + 1]


def _phase_grid(centre: np.ndarray) -> np.ndarray:
    """The cycles' centres with :data:`_GRID_PER_CYCLE` - 1 points between neighbours."""
    parts = [np.linspace(a, b, _GRID_PER_CYCLE, endpoint=False) for a, b in zip(centre[:-1], centre[1:])]
    return np.concatenate(parts + [centre[-1:]])


def _white_and_blocks(x: np.ndarray, r: np.ndarray, bread_inv: np.ndarray):
    """(white, block sandwich, block length) covariances of least-squares coefficients of weighted
    design ``x`` with residuals ``r`` (``bread_inv`` the inverse normal matrix, priors included): the
    white one scaled by chi^2 per degree of freedom where that is above 1, the sandwich's scores summed
    over blocks of :func:`_block_length` neighbours (errors correlated over several cycles)."""
    n, k = x.shape
    white = bread_inv @ (x.T @ x) @ bread_inv * max(1.0, float(r @ r) / max(n - k, 1))
    block = _block_length(r)
    blocks = np.add.reduceat(x * r[:, None], np.arange(0, n, block), axis=0)
    nb = len(blocks)
    sand = bread_inv @ (blocks.T @ blocks) @ bread_inv * (nb / max(nb - 1, 1)) * (n / max(n - k, 1))
    return white, sand, block


def _sandwich(x: np.ndarray, r: np.ndarray) -> np.ndarray:
    """The covariance of plain weighted least squares (design ``x``, residuals ``r``): the block
    sandwich of :func:`_white_and_blocks` where it is the larger in total (``tr(W^-1 S) > k``), never
    below the white one."""
    bread_inv = np.linalg.pinv(x.T @ x)
    white, sand, _ = _white_and_blocks(x, r, bread_inv)
    return sand if float(np.trace(np.linalg.pinv(white) @ sand)) > x.shape[1] else white


def _few_blocks(nb: int) -> float:
    """The variance factor that makes a normal 95 % interval from a sandwich over ``nb`` blocks the
    Student-t interval it is ((t_0.975(nb - 1) / z_0.975)^2): such a variance is itself estimated from
    nb - 1 degrees of freedom, and a short record (a 6-cycle laser record: 6 blocks, a factor 1.56)
    would otherwise state intervals that hold the truth in ~85 % of records, not 95 %."""
    return (float(student_t.ppf(0.975, max(nb - 1, 1))) / float(norm.ppf(0.975))) ** 2


def _block_length(r: np.ndarray) -> int:
    """:data:`BLOCK_TAUS` integrated autocorrelation times of ``r`` (initial positive sequence), at most
    a fifth of the cycles (fewer blocks and their variance is itself too uncertain)."""
    n = len(r)
    if n < 10:
        return 1
    x = r - r.mean()
    f = np.fft.rfft(x, 2 * n)
    acf = np.fft.irfft(f * np.conj(f))[:n]
    acf = acf / acf[0]
    below = np.flatnonzero(acf < 0.0)
    stop = int(below[0]) if len(below) else n
    tau_int = 1.0 + 2.0 * float(acf[1:stop].sum())
    return int(min(max(1, math.ceil(BLOCK_TAUS * tau_int)) if tau_int > 1.5 else 1, max(1, n // 5)))


def _peak_apart(tau: np.ndarray, rest: np.ndarray, swept: tuple[float, float]) -> float | None:
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
    stride = max(1, -(-len(tau) // _PERIODOGRAM_SAMPLES))
    x, v = tau[::stride], rest[::stride]
    low, high = swept
    grid = np.arange(0.25 * high, min(4.0 * high, math.pi * (len(x) - 1) / (x[-1] - x[0])), 0.5 * resolution)
    if len(grid) < 8:
        return None
    near = ((grid > low - resolution) & (grid < high + resolution)) | (grid < 2.0 * resolution)
    near |= (grid > 3.0 * low - 4.0 * resolution) & (grid < 3.0 * high + 4.0 * resolution)
    power = np.where(near, 0.0, lombscargle(x, v, grid, floating_mean=True))
    j = int(np.argmax(power))
    band = (grid > 0.5 * grid[j]) & (grid < 2.0 * grid[j]) & ~near & (np.abs(grid - grid[j]) > 3.0 * resolution)
    if band.sum() >= 8:
        floor = float(np.median(power[band]))
    else:
        floor = (1.4826 * float(np.median(np.abs(np.diff(v) - np.median(np.diff(v)))))) ** 2 / 2.0
    return float(grid[j]) if power[j] >= SECOND_MODE_POWER * floor and j > 0 else None


def _swept(model: _Model, centres: np.ndarray) -> tuple[float, float]:
    """The lowest and highest frequency (rad/s) the first mode had at the cycles' ``centres`` (s)."""
    local = model.local_omega(centres)
    return float(np.min(local)), float(np.max(local))


@dataclass(frozen=True)
class _Second:
    """A damped sinusoid e^(-decay tau) (c cos + s sin)(omega tau) superposed on the record."""

    omega: float
    decay: float
    c: float
    s: float

    def signal(self, tau):
        return np.exp(-self.decay * tau) * (self.c * np.cos(self.omega * tau) + self.s * np.sin(self.omega * tau))


def _in_phase_harmonics(cyc: _Cycles, good: np.ndarray) -> dict[int, np.ndarray]:
    """{n: the n-th odd harmonic's amplitude in each good cycle} (signal units), 1 the fundamental: each
    window's terms at the time its fundamental peaks (a symmetric oscillator's harmonics are in phase
    with it there, so the n-th is a_n cos(n Phi)); 0 where a window held fewer harmonics."""
    out = {}
    for j, n in enumerate(range(1, _harmonics(math.inf) + 1, 2)):
        out[n] = np.array([cyc.terms[k][1 + 2 * j] * math.cos(n * cyc.phase[k])
                           - cyc.terms[k][2 + 2 * j] * math.sin(n * cyc.phase[k])
                           if len(cyc.terms[k]) > 2 + 2 * j else 0.0 for k in good])
    return out


def _second_mode(rec: _Record, cyc: _Cycles, baseline: np.ndarray, model: _Model) -> _Second | None:
    """Module docstring, step 3: a mode beating in, from the record minus the first mode as the law
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
    phase = model.phase_at(tau)
    rest = rec.y[idx] - baseline[idx]
    for n, amplitude in _in_phase_harmonics(cyc, good).items():
        rest = rest - np.interp(tau, cyc.centre[good], amplitude) * np.cos(n * phase)
    rest = rest - np.polyval(np.polyfit(tau, rest, 1), tau)
    peak = _peak_apart(tau, rest, _swept(model, cyc.centre[good]))
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
    # smaller than the one released is asked of the whole fit (:func:`_whole`), once the law has settled
    sol = least_squares(lambda p: fitted(p)[0], [peak, 0.0], bounds=([0.0, 0.0], [np.inf, _SECOND_DECAY_SPANS / span]),
                        x_scale=[resolution, 1.0 / span], xtol=1e-10)
    c2, s2 = fitted(sol.x)[1]
    return _Second(float(sol.x[0]), float(sol.x[1]), float(c2), float(s2))


@dataclass
class _Whole:
    """The whole record fitted at once, the law held (:func:`_whole`): omega0 (rad/s) and its
    statistical variance, the batch block (cycles), the refined second mode, the model at the samples
    used and their indices."""

    omega0: float
    variance: float
    variance_white: float
    block: int
    second: _Second | None
    fitted: np.ndarray
    index: np.ndarray


def _whole(rec: _Record, cyc: _Cycles, model: _Model, baseline: np.ndarray, second: _Second | None) -> _Whole:
    """Every sample of the good cycles fitted at once, with the law's shape held as the cycles gave it:

        y - baseline = c0 + c1 u + E(t) [cos Phi + sum_{n=3,5} (E / E_mean)^(n-1) (a_n cos n Phi + b_n sin n Phi)]
                       + e^(-a2 tau) (c2 cos w2 tau + s2 sin w2 tau),
        Phi = phi0 + omega0 int dt / (R E D),   E(t) = e^(e0 + e1 u) A_cycles(t),

    u the time from the middle over the span, A_cycles the amplitude the cycles measured (times the
    local frequency for a rate). A cycle measured alone spends some of its information on its own
    offset, envelope and harmonics, and a record of a few cycles gives only a few phases; here one
    phase law, one envelope and one second mode take all of it, the efficiency of a plain damped-sine
    least squares, while the law's chirp (from the cycles) keeps it right at large amplitude. The
    phase law's parameters other than phi0 and omega0 stay as the cycles fitted them; what their
    uncertainty does to omega0 is added after (:meth:`_Model.law_induced_variance`).

    Its uncertainty: the sandwich with the scores summed over each cycle, then over blocks of
    :data:`BLOCK_TAUS` integrated autocorrelation times of the omega0 score's cycle series, never
    below the white-noise covariance (residual variance times (J^T J)^-1).

    The samples: those of the good cycles, and the record's usable tail past the last of them (too
    short a cycle to measure alone, not too short to hold phase). A second mode the cycles did not
    show is looked for in this fit's own residual (:func:`_peak_apart`), and the fit repeated with it."""
    good = np.flatnonzero(cyc.good & np.isfinite(cyc.phase))
    idx = np.unique(np.concatenate([cyc.index[k] for k in good]))
    tail = np.flatnonzero(cyc.usable & (rec.tau > rec.tau[idx[-1]]))
    idx = np.concatenate([idx, tail])
    tau = rec.tau[idx]
    y = rec.y[idx] - baseline[idx]
    span = max(tau[-1] - tau[0], 1e-300)
    u = (tau - 0.5 * (tau[0] + tau[-1])) / span
    integral = model.integral_at(tau)
    envelope = model.fund_at(tau) * (model.local_omega(tau) if rec.kind == "rate" else 1.0)
    level = float(np.exp(np.mean(np.log(envelope))))
    harmonics = _harmonics(float(np.median([len(cyc.index[k]) for k in good])))
    _, _, phi0, omega0, _, _ = model._phase
    first = [phi0, omega0, math.log(float(np.median(cyc.fundamental[good])) / level), 0.0]
    largest = _SECOND_SHARE * float(np.max(envelope))

    def plausible(f) -> bool:
        """Its second mode at most _SECOND_SHARE of the first: a law misfit near the first mode's
        frequency would pass for one of comparable size."""
        return math.hypot(*f[3][-2:]) * math.exp(-f[0][5] * tau[0]) <= largest

    fit = _whole_fit(tau, y, u, integral, envelope, level, harmonics, first, second)
    if second is not None and not plausible(fit):
        second = None
        fit = _whole_fit(tau, y, u, integral, envelope, level, harmonics, first, None)
    if second is None:
        low, high = _swept(model, cyc.centre[good])
        peak = _peak_apart(tau, fit[2], (low * fit[0][1] / model.omega0, high * fit[0][1] / model.omega0))
        if peak is not None:
            with_second = _whole_fit(tau, y, u, integral, envelope, level, harmonics, list(fit[0][:4]),
                                     _Second(peak, 0.0, 0.0, 0.0))
            if plausible(with_second):
                fit, second = with_second, _Second(peak, 0.0, 0.0, 0.0)
    q, jac, r, beta, model_y = fit
    n, k = jac.shape
    bread = np.linalg.pinv(jac.T @ jac)
    white = bread * float(r @ r) / max(n - k, 1)
    cycle = np.floor((q[1] * (integral - integral[0])) / (2.0 * math.pi)).astype(int)
    scores = np.zeros((cycle.max() + 1, k))
    np.add.at(scores, cycle, jac * r[:, None])
    block = _block_length(scores[:, 1]) if len(scores) >= 10 else 1
    blocks = np.add.reduceat(scores, np.arange(0, len(scores), block), axis=0)
    nb = len(blocks)
    sandwich = bread @ (blocks.T @ blocks) @ bread * (nb / max(nb - 1, 1)) * (n / max(n - k, 1))
    sandwich *= _few_blocks(nb)
    refined = None
    if second is not None:
        c2, s2 = beta[-2:]
        refined = _Second(float(q[4]), float(q[5]), float(c2), float(s2))
    return _Whole(float(q[1]), float(max(white[1, 1], sandwich[1, 1])), float(white[1, 1]), int(block), refined,
                  model_y + baseline[idx], idx)


def _whole_fit(tau, y, u, integral, envelope, level, harmonics, first, second):
    """The least squares of :func:`_whole` from ``first`` (phi0, omega0, e0, e1) and a second mode's
    (omega2, decay2) start if any: (parameters, Jacobian of the residual with the linear terms last,
    residual, linear terms, model)."""
    start = list(first)
    omega0 = start[1]
    if second is not None:
        start += [second.omega, second.decay]

    def design(q):
        phase = q[0] + q[1] * integral
        env = np.exp(q[2] + q[3] * u) * envelope
        cols = [np.ones_like(u), u]
        for n in range(3, harmonics + 1, 2):
            rel = env * (env / level) ** (n - 1)
            cols += [rel * np.cos(n * phase), rel * np.sin(n * phase)]
        if second is not None:
            decay = np.exp(-q[5] * tau)
            cols += [decay * np.cos(q[4] * tau), decay * np.sin(q[4] * tau)]
        return env * np.cos(phase), np.column_stack(cols)

    def residual(q):
        fixed, x = design(q)
        beta = np.linalg.lstsq(x, y - fixed, rcond=None)[0]
        return y - fixed - x @ beta

    lo = np.full(len(start), -np.inf)
    hi = np.full(len(start), np.inf)
    lo[1], hi[1] = 0.9 * omega0, 1.1 * omega0
    if second is not None:  # a mode beating in lasts the record (:func:`_second_mode`)
        lo[5], hi[5] = 0.0, _SECOND_DECAY_SPANS / max(tau[-1] - tau[0], 1e-300)
    start = np.clip(np.array(start, dtype=float), lo, hi)
    sol = least_squares(residual, start, bounds=(lo, hi), x_scale="jac", xtol=1e-12, ftol=1e-12, gtol=1e-12)
    q = sol.x
    fixed, x = design(q)
    beta = np.linalg.lstsq(x, y - fixed, rcond=None)[0]
    model_y = fixed + x @ beta
    return q, np.column_stack([sol.jac, -x]), y - model_y, beta, model_y


def _result(rec: _Record, t: np.ndarray, cyc: _Cycles, model: _Model, baseline: np.ndarray, whole: _Whole,
            rejected: Rejected) -> OscillationFit:
    good = cyc.good & np.isfinite(cyc.phase)
    omega0 = whole.omega0
    period = 2.0 * math.pi / omega0
    to_period = 2.0 * math.pi / omega0**2
    # the whole record's statistical variance, and what the law's parameters add to it; the law's prior
    # part of that is reported apart (and is what records of one rig share)
    # the learned law's own doubts (:meth:`_Model.check_law`): its extrapolation to zero swing (one
    # excess term fewer), and past LAW_CONFLICT the ideal law's T0 (the record's beat or the rig file's
    # law is wrong); the interval holds both T0s of each (the record's doubt, not the prior's that the
    # trials share)
    base = whole.variance + model.law_induced_variance() + model.held_shift**2
    # the extrapolation's doubt where it is more than the sigma already holds: the sigma is at least the
    # difference of the two extrapolations (where the record determines the law it is well inside it)
    order = max(0.0, model.order_shift**2 - base)
    held = model.held_shift**2 + order
    std_law = to_period * math.sqrt(model.cov_law[1, 1] + held)
    std_all = to_period * math.sqrt(base + order)
    std_stat = math.sqrt(max(std_all**2 - std_law**2, to_period**2 * whole.variance))
    jack, groups = model.jackknife(cyc)
    if not (groups and jack > (std_stat / to_period) ** 2 * chi2.ppf(0.95, groups - 1) / (groups - 1)):
        groups = 0  # the covariance holds (the jackknife, a variance of groups - 1 dof, is not above it at 95 %)
    else:  # the covariance is short: the jackknife's, scaled to its Student-t interval as the blocks are
        std_stat = max(std_stat, to_period * math.sqrt(jack * _few_blocks(groups)))
    std_white = to_period * math.sqrt(whole.variance_white)
    second = whole.second
    fitted = np.full(len(t), np.nan)
    kept = np.zeros(len(t), dtype=bool)
    fitted[whole.index] = whole.fitted
    kept[whole.index] = True
    swing = np.sqrt(0.5) * np.median(cyc.fundamental[good])
    r = (rec.y - fitted)[kept]
    rms = math.sqrt(float(np.mean(r**2)))
    if swing / max(rms, 1e-300) < MIN_SNR:
        raise ValueError(f"no oscillation stands out of the noise (fundamental RMS / residual RMS = "
                         f"{swing / max(rms, 1e-300):.2g} < {MIN_SNR:g})")
    # what was left out
    in_window = np.zeros(len(t), dtype=bool)
    bad_cycles = []
    for k in range(len(cyc.centre)):
        half = math.pi / cyc.omega[k]
        lo, hi = np.searchsorted(rec.tau, [cyc.centre[k] - half, cyc.centre[k] + half])
        if good[k]:
            in_window[lo:hi] = True
        else:
            bad_cycles.append((k, lo, hi))
    glitch = in_window & rec.usable & ~cyc.usable
    rejected.glitches = int(glitch.sum())
    out_cycles = np.zeros(len(t), dtype=bool)
    for k, lo, hi in bad_cycles:
        seg = np.arange(lo, hi)
        seg = seg[~in_window[seg] & rec.usable[seg]]
        out_cycles[seg] = True
        if len(seg) and cyc.reason[k]:
            rejected.reasons.append(f"{t[seg[0]]:.6g}..{t[seg[-1]]:.6g} s: {cyc.reason[k]}")
    # samples past the last whole window are not a cycle: they are not counted as left out
    rejected.cycles = int(out_cycles.sum())
    rejected.spans = spans(t, out_cycles | glitch | ~rec.usable, 3.0 * rec.step)
    # the cycles, for plots and the law's report
    centre = cyc.centre[good]
    fund = model.fund_at(centre)
    amplitude_rad = model.peak_at(centre) if model.law.kind != "linear" else None
    if model.kind in ("angle", "rate") and model.law.kind == "linear":
        amplitude_rad = fund  # a linear law: the fundamental is the peak
    unwrapped = model._unwrap(cyc, good, centre)
    neighbours = np.diff(np.flatnonzero(good)) == 1
    per_cycle = np.where(neighbours, 2.0 * math.pi * np.diff(centre) / np.maximum(np.diff(unwrapped), 1e-300), np.nan)
    cycle_amp = amplitude_rad if amplitude_rad is not None else fund
    names = model.names
    std = np.sqrt(np.diag(model.cov_stat + model.cov_law))
    excess = model.params[names.index("ds")] if "ds" in names else 0.0
    quartic = model.params[names.index("dq")] if "dq" in names else 0.0
    learned = 0.0
    if "ds" in names:
        i = names.index("ds")
        prior_sd = model.prior * abs(model.ideal)
        learned = max(0.0, 1.0 - std[i] ** 2 / prior_sd**2) if prior_sd > 0 else 0.0
    note = ""
    if model.kind == "proportional" and "kappa" not in names:
        note = ("scale unknown: the ideal law cannot be applied; T0 is the period at the record's amplitudes "
                "(a small swing assumed)")
    law = Law(model.law.kind if model.law.kind != "linear" or model.kind != "proportional" else "none (scale unknown)",
              model.ideal, float(excess), float(std[names.index("ds")]) if "ds" in names else 0.0,
              float(quartic), float(std[names.index("dq")]) if "dq" in names else 0.0, float(learned), note,
              model.conflict if model.conflict > LAW_CONFLICT else None)
    curve = _law_curve(model, period, cycle_amp)
    level = cyc.offset[good] + np.interp(centre, rec.tau, baseline)  # the offset under each cycle
    amplitude = None
    if model.scale_known and amplitude_rad is not None:
        amplitude = (float(amplitude_rad[0]), float(amplitude_rad[-1]))
    return OscillationFit(
        period=period, period_std=math.hypot(std_stat, std_law), period_std_statistical=std_stat,
        period_std_law=std_law, period_std_white=std_white, prior_gain=to_period * model.prior_gain, law=law,
        amplitude=amplitude, damping=model.damping, offset=float(np.median(cyc.offset[good])),
        drift=float(np.polyfit(centre, cyc.offset[good] + np.interp(centre, rec.tau, baseline), 1)[0])
        if len(centre) > 1 else 0.0,
        rms=rms, outliers=t[glitch], rejected=rejected,
        second_mode=None if second is None else (2.0 * math.pi / second.omega, math.hypot(second.c, second.s),
                                                 second.decay),
        block=whole.block, jackknife=groups, samples=int(kept.sum()), cycles=int(good.sum()), cycle_time=t[0] + centre,
        cycle_period=per_cycle, cycle_amplitude=cycle_amp, law_curve=curve, t=t, y=rec.y, fitted=fitted, kept=kept,
        binned=rec.binned)


def _law_curve(model: _Model, period: float, amplitude: np.ndarray):
    """(A, T(A) fitted, T(A) ideal) over the record's amplitude range, for plots."""
    a = np.linspace(0.0, float(np.max(amplitude)) * 1.05, 60)
    if model.law.kind == "linear" or model.table is None or not model.scale_known:
        flat = np.full(len(a), period)
        return a, flat, flat
    names, p = model.names, model.params
    kappa = p[names.index("kappa")] if "kappa" in names else 1.0
    a_rad = a * kappa if model.kind == "proportional" else a
    ideal = period * model.table.ratio_at(np.minimum(a_rad, model.table.largest))
    excess = 1.0
    if "ds" in names:
        excess = 1.0 + sum(p[names.index(n)] * a_rad ** (2 * (j + 1)) for j, n in enumerate(EXCESS_TERMS))
    return a, ideal * excess, ideal


def damping_of(time: np.ndarray, amplitude: np.ndarray, omega: float) -> dict:
    """The decay of the amplitude described by linear, quadratic and dry damping, dA/dt = -zeta omega A
    - (4 / 3 pi) c omega A^2 - (2 / pi) mu / omega (first-order averaging of theta'' + omega^2 theta =
    -2 zeta omega theta' - c |theta'| theta' - mu sign theta'), non-negative least squares on A(t) at
    ``time``: the description the period's damping correction needs (:func:`damping_shift`)."""
    from scipy.optimize import nnls

    if len(time) < 4:
        return {"linear": 0.0, "quadratic": 0.0, "dry": 0.0}
    a = np.asarray(amplitude, dtype=float)
    slope = np.gradient(a, time)
    x = np.column_stack([omega * a, 4.0 / (3.0 * math.pi) * omega * a * a, 2.0 / (math.pi * omega) * np.ones_like(a)])
    coef, _ = nnls(x, -slope)
    return {"linear": float(coef[0]), "quadratic": float(coef[1]), "dry": float(coef[2] / omega**2)}


def damping_shift(damping: dict, amplitude: np.ndarray) -> np.ndarray:
    """T_damped / T_undamped - 1 of a cycle at each ``amplitude``, for the damping of
    :func:`damping_of` (``dry`` there is mu / omega^2, in the amplitude's unit).

    Damping lengthens the period at second order in itself, by a form that depends on the damping's
    kind: zeta^2 / 2 for linear damping, ~0.15 zeta_eff^2 for quadratic, ~1.5 zeta_eff^2 for dry
    friction (zeta_eff the decrement per radian), ~1e-5 of the period for a hardly damped video record
    released at 1 rad, as large as its statistical sigma. So it is measured: one and a half cycles of
    theta'' + theta = -2 zeta theta' - c |theta'| theta' - m tanh(theta' / eps) from each amplitude (a
    grid, RK4 at 256 steps per cycle: the shift to ~1e-3 of itself, for at most three cycles: a swing
    that dry friction stops has no second crossing), the period from descending crossing to descending
    crossing, and the amplitude half way (the trough) it belongs to."""
    zeta, quad, dry = damping["linear"], damping["quadratic"], damping["dry"]
    amplitude = np.asarray(amplitude, dtype=float)
    if zeta == quad == dry == 0.0 or not len(amplitude):
        return np.zeros_like(amplitude)
    top = float(amplitude.max())
    a = np.linspace(0.5 * float(amplitude.min()), 1.05 * top, 16)
    eps = 1e-4 * top

    def acc(th, v):
        return -th - 2.0 * zeta * v - quad * np.abs(v) * v - dry * np.tanh(v / eps)

    h = 2.0 * math.pi / 256
    th, v = a.copy(), np.zeros_like(a)
    crossings = [np.full(len(a), np.nan), np.full(len(a), np.nan)]
    trough = np.zeros(len(a))
    for n in range(int(3.0 * 256)):
        k1v, k1x = acc(th, v), v
        k2v, k2x = acc(th + 0.5 * h * k1x, v + 0.5 * h * k1v), v + 0.5 * h * k1v
        k3v, k3x = acc(th + 0.5 * h * k2x, v + 0.5 * h * k2v), v + 0.5 * h * k2v
        k4v, k4x = acc(th + h * k3x, v + h * k3v), v + h * k3v
        new = th + h / 6.0 * (k1x + 2 * k2x + 2 * k3x + k4x)
        new_v = v + h / 6.0 * (k1v + 2 * k2v + 2 * k3v + k4v)
        down = (th > 0.0) & (new <= 0.0)
        at = n * h + h * th / np.where(down, th - new, 1.0)
        first = np.isnan(crossings[0])
        crossings[1] = np.where(down & ~first & np.isnan(crossings[1]), at, crossings[1])
        crossings[0] = np.where(down & first, at, crossings[0])
        trough = np.maximum(trough, np.where(np.isnan(crossings[1]) & ~first, -new, 0.0))
        th, v = new, new_v
        if not np.isnan(crossings[1]).any():  # every cycle measured (the rest would change nothing)
            break
    shift = (crossings[1] - crossings[0]) / (2.0 * math.pi) - 1.0
    ok = np.isfinite(shift) & (trough > 0.0)
    if ok.sum() < 2:
        return np.zeros_like(amplitude)
    order = np.argsort(trough[ok])
    return np.interp(amplitude, trough[ok][order], shift[ok][order])
