"""A record measured cycle by cycle: windows one local period long, each fitted on its own.

Step 1 of the record fit (:mod:`.fit`). In each window, least squares gives the offset and the odd
harmonics of the phase under the decay's envelope, with the window's frequency refined
(:func:`_window_fit`): the fundamental's phase at the centre with its variance, and its amplitude.
Over a whole cycle these are orthogonal, so the offset, its drift and the waveform's harmonics take
nothing from the phase, and the fit never models the damping, the drift or the tracker. A pass
(:func:`measure`) fits every window with the local frequency and decay the last pass's law gives,
leaves out glitches and bad cycles (:mod:`.clean`) and refits; the slow offset under the swing
(:func:`baseline_of`) is subtracted before the next. The first pass's single frequency is the record's
own (:func:`rough_frequency`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .bounds import Deadline, window_centres
from .clean import OUTLIER_Z, glitches, mark
from .read import MIN_CYCLES, MIN_SAMPLES

_WINDOW_SAMPLES = 12  # a window's terms (up to 9 with many samples a cycle) need residual degrees of freedom
_WINDOW_GAP = 0.35  # largest gap inside a window, in windows: more and its terms are not orthogonal
_FREQUENCY_STEPS = 3  # Gauss-Newton steps on a window's frequency
_FREQUENCY_RANGE = 0.05  # the largest relative step (a window's swing is within 5 % of the model's)
# converged: a relative step this small leaves the next (quadratic convergence) at ~1e-9 of the frequency,
# lowering the residual by ~1e-13 of itself (measured on clean and gyro records: the third step's median
# 5e-9, its gain 3e-13); the phase at the centre does not depend on the frequency to first order
_FREQUENCY_CONVERGED = 1e-6
# At most this many samples in a periodogram (starting values only). The record's own frequency is taken
# from as many bin means of a longer record, not a stride: a stride kept the full rate's noise, whose
# derivative (1e-3 rad at 2500 Hz: 2.5 rad/s) drowned a 0.3 rad swing's (0.9 rad/s), and a 400-cycle
# record came out at 2.4 rad/s for 3.13 (its second half at 6.8).
PERIODOGRAM_SAMPLES = 1024
_BASELINE_CYCLES = 3.0  # the baseline: the offsets smoothed over this many cycles either side


@dataclass
class Samples:
    """The samples being fitted and what is known of them."""

    tau: np.ndarray  # s from the first sample
    y: np.ndarray
    kind: str
    usable: np.ndarray  # not stuck, not a glitch
    step: float  # median sample spacing, s
    omega: float = math.nan  # the record's own frequency, rad/s (:func:`rough_frequency`)
    binned: int = 1  # samples a bin of a dense record (:func:`.bounds.binned`)
    deadline: Deadline = field(default_factory=Deadline)


@dataclass
class Cycles:
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
    residual: list = field(default=None)  # each fitted window's least-squares residual (None: not fitted)


def rough_frequency(rec: Samples) -> float:
    """Angular frequency (rad/s) of the strongest oscillation: the Lomb-Scargle peak of the signal's
    derivative (of the signal itself for a rate), so that an offset, a slow drift or a tracker's
    lock-on jumps do not make the peak; differences across gaps and beyond 6 robust sigmas are left out. A
    record longer than :data:`PERIODOGRAM_SAMPLES` is taken in as many bin means."""
    keep = rec.usable
    tau, y = rec.tau[keep], rec.y[keep]
    group = -(-len(tau) // PERIODOGRAM_SAMPLES)
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
    # from one cycle a record below the least it may hold: a decaying swing of barely MIN_CYCLES has a broad
    # peak that leans below its frequency; a record found to hold fewer is refused by the fit after
    grid = np.arange((MIN_CYCLES - 1) * resolution, nyquist, 0.5 * resolution)
    if len(grid) < 3:
        raise ValueError(f"the record is too short or too sparse to hold {MIN_CYCLES} cycles")
    power = periodogram(x, v, grid)
    k = int(np.argmax(power))
    if k == 0 or k == len(grid) - 1:
        raise ValueError(f"no oscillation peak inside {grid[0]:.4g}..{grid[-1]:.4g} rad/s: fewer than "
                         f"{MIN_CYCLES} cycles, or undersampled")
    fine = grid[k] + np.linspace(-0.5, 0.5, 21) * resolution
    fpower = periodogram(x, v, fine)
    return float(fine[int(np.argmax(fpower))])


def periodogram(x: np.ndarray, y: np.ndarray, omega: np.ndarray) -> np.ndarray:
    """The floating-mean Lomb-Scargle power of ``y`` at ``x`` for each angular frequency ``omega``: scipy's
    ``lombscargle(x, y, omega, floating_mean=True)`` (Zechmeister and Kuerster's equations, equal weights),
    to rounding (~1e-13 of the peak). scipy evaluates the sines and cosines twice, at omega x and again
    shifted by each frequency's tau; the shifted sums follow from the unshifted ones by the angle-sum
    identities, the squares' sums from e^(2 i omega x), and on an evenly spaced ``omega`` (every grid
    here) e^(i omega x) itself from :func:`_phasors`: ~1/8 of the trigonometry's time, which was most of a
    record's ~100 periodograms of ~1000 frequencies."""
    x, y, omega = (np.asarray(a, dtype=float) for a in (x, y, omega))
    n = len(x)
    e = _phasors(x, omega)
    w = 1.0 / n
    mean_y = float(y.sum()) * w
    m1 = w * e.sum(axis=0)  # the means of cos(omega x) + i sin(omega x)
    m2 = w * np.einsum("ij,ij->j", e, e)  # of e^(2 i omega x): 2 cos^2 - 1 + 2 i cos sin
    yc_ys = (w * y) @ e
    mc, ms = m1.real, m1.imag
    cc0, cs0 = 0.5 * (1.0 + m2.real), 0.5 * m2.imag
    yc0, ys0 = yc_ys.real, yc_ys.imag
    cc, ss, cs = cc0 - mc * mc, (1.0 - cc0) - ms * ms, cs0 - mc * ms
    tau = 0.5 * np.arctan2(2.0 * cs, cc - ss)
    ct, st = np.cos(tau), np.sin(tau)
    c_tau, s_tau = ct * mc + st * ms, ct * ms - st * mc  # the means of cos(omega x - tau), sin(...)
    cc_tau = ct * ct * cc0 + 2.0 * ct * st * cs0 + st * st * (1.0 - cc0)
    yc = ct * yc0 + st * ys0 - mean_y * c_tau
    ys = ct * ys0 - st * yc0 - mean_y * s_tau
    eps = np.finfo(float).epsneg
    cc = np.maximum(cc_tau - c_tau * c_tau, eps)
    ss = np.maximum((1.0 - cc_tau) - s_tau * s_tau, eps)
    return 2.0 * (yc * yc / cc + ys * ys / ss) * (n / 4.0)


def _phasors(x: np.ndarray, omega: np.ndarray) -> np.ndarray:
    """e^(i omega_k x_j) (samples x frequencies). On an evenly spaced ``omega`` (to 1e-9 of its step) each
    of ~sqrt(m) blocks of frequencies is its first frequency's phasor times the step's powers within a
    block, both evaluated directly: one complex product per entry (a rounding of ~1e-16) instead of a
    sine and a cosine."""
    m = len(omega)
    step = (omega[-1] - omega[0]) / (m - 1) if m > 2 else 0.0
    if m <= 2 or np.max(np.abs(np.diff(omega) - step)) > 1e-9 * abs(step):
        return np.exp(1j * np.multiply.outer(x, omega))
    size = max(1, int(math.sqrt(m)))
    blocks = -(-m // size)
    first = np.exp(1j * np.multiply.outer(x, omega[0] + step * size * np.arange(blocks)))
    within = np.exp(1j * np.multiply.outer(x, step * np.arange(size)))
    return (first[:, :, None] * within[:, None, :]).reshape(len(x), -1)[:, :m]


def measure(rec: Samples, baseline: np.ndarray, local, second) -> Cycles:
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
        glitch = glitches(_residuals(cyc), len(y))
        if not glitch.any():
            break
        usable &= ~glitch
    cyc.usable = usable
    mark(cyc)
    return cyc



def _residuals(cyc: Cycles) -> list:
    """Each fitted window's (sample indices, residual of its least squares): what :func:`.clean.glitches`
    looks for spikes in."""
    return [(idx, r) for idx, r in zip(cyc.index, cyc.residual) if idx is not None and len(idx) >= 3]


def _cycles(tau, y, usable, centres, omegas, decays, chirps, rate: bool) -> Cycles:
    """Least squares in every window (:mod:`.fit`, step 1); windows without the samples to
    determine their terms are returned marked, with nan phase."""
    n = len(centres)
    out = Cycles(centres, omegas, decays, np.full(n, np.nan), np.full(n, np.nan), np.full(n, np.nan),
                  np.full(n, np.nan), np.full(n, np.nan), [None] * n, [None] * n)
    out.reason = [None] * n
    out.chirp = chirps
    out.fitted_omega = np.array(omegas, dtype=float)
    out.residual = [None] * n
    out.peak_ratio = np.full(n, np.nan)
    out.amplitude_var = np.full(n, np.nan)
    out.third = np.full(n, np.nan)  # the third harmonic over the fundamental, in the fundamental's phase
    out.third_var = np.full(n, np.nan)
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
        wf, coef, r, gram = _window_fit(u, y[idx], w, lam, highest_harmonic(len(idx)), chirp)
        out.fitted_omega[k] = wf
        dof = len(idx) - len(coef) - 1
        var = float(r @ r) / dof
        cov = var * np.linalg.inv(gram)
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
        if len(coef) >= 5:  # the signal's own third harmonic (a rate's not divided by 3): scale-free
            c3, s3 = math.cos(3.0 * phase), math.sin(3.0 * phase)
            out.third[k] = (coef[3] * c3 - coef[4] * s3) / math.sqrt(amp2)
            g3 = np.array([c3, -s3])
            out.third_var[k] = float(g3 @ cov[3:5, 3:5] @ g3) / amp2
        out.phase_var[k] = float(g @ cov[1:3, 1:3] @ g)
        out.fundamental[k] = math.sqrt(amp2)
        radial = np.array([a1, b1]) / math.sqrt(max(amp2, 1e-300))
        out.amplitude_var[k] = float(radial @ cov[1:3, 1:3] @ radial)
        out.offset[k] = coef[0]
        out.rms[k] = math.sqrt(var)
        out.index[k] = idx
        out.terms[k] = coef
        out.residual[k] = r
    return out


def _window_fit(u: np.ndarray, y: np.ndarray, w: float, lam: float, harmonics: int, chirp: float):
    """(frequency, terms, residual, normal matrix) of one window's least squares with its frequency
    refined from ``w`` by Gauss-Newton (up to :data:`_FREQUENCY_STEPS` steps on the terms' joint
    linearisation, each kept only where it lowers the residual, within :data:`_FREQUENCY_RANGE` of ``w``,
    none after a converged one): a window whose swing is far from the model's (the first pass's single
    frequency, a cycle the model held from its neighbours) would otherwise leave a residual that grows as
    its phase runs off the window's, and be taken for a tracker that has not locked on. The phase at the
    centre, u = 0, does not depend on the frequency to first order (a symmetric window), so refining it
    moves the residual, not the phase.

    Solved by the normal equations: over a window one period long the offset and the harmonics'
    columns are nearly orthogonal (the normal matrix's condition ~10, ~1e3 where a gap takes a third
    of the window), and a window's ~100 small solves cost half what numpy's SVD least squares does."""
    orders = np.arange(1, harmonics + 1, 2)

    def solve(wf):
        x = _basis(u, wf, lam, harmonics, chirp)
        gram = x.T @ x
        coef = np.linalg.solve(gram, x.T @ y)
        r = y - x @ coef
        return x, gram, coef, r, float(r @ r)

    x, gram, coef, r, best = solve(w)
    wf = w
    for _ in range(_FREQUENCY_STEPS):
        # d (x @ coef) / d w: each harmonic's n u (b cos - a sin) under the envelope, from the basis's columns
        slope = u * (x[:, 1::2] @ (orders * coef[2::2]) - x[:, 2::2] @ (orders * coef[1::2]))
        # the frequency's Gauss-Newton step with the terms free: the slope's part the terms cannot take
        # (its projection off their columns) against the residual, which is orthogonal to them already
        xs = x.T @ slope
        free = float(slope @ slope - xs @ np.linalg.solve(gram, xs))
        step = float(slope @ r) / free if free > 0.0 else 0.0
        w_new = float(np.clip(wf + step, w * (1.0 - _FREQUENCY_RANGE), w * (1.0 + _FREQUENCY_RANGE)))
        trial = solve(w_new)
        if trial[4] >= best:
            break
        wf = w_new
        x, gram, coef, r, best = trial
        if abs(step) <= _FREQUENCY_CONVERGED * w:
            break
    return wf, coef, r, gram


def _basis(u: np.ndarray, w: float, lam: float, harmonics: int, chirp: float = 0.0) -> np.ndarray:
    """Offset, then the odd harmonics 1, 3, .. up to ``harmonics`` (cos, sin pairs) of the phase
    w u + chirp u^2 / 2 (the frequency drifting at ``chirp`` rad/s^2 as the amplitude law slows the
    swing down), under the envelope e^(lam u) of the amplitude's own decay: a decaying swing fitted
    with a constant one would shift the centre's phase by ~lam / w, and that shift changes as the decay
    slows; a chirp left out leaves a residual ~chirp T^2 / 8 times the amplitude, far above a good
    tracker's noise at a large swing."""
    env = np.exp(lam * u)[:, None]
    arg = (w * u + 0.5 * chirp * u * u)[:, None] * np.arange(1, harmonics + 1, 2)
    x = np.empty((len(u), 1 + arg.shape[1] * 2))
    x[:, 0] = 1.0
    x[:, 1::2] = env * np.cos(arg)
    x[:, 2::2] = env * np.sin(arg)
    return x


def highest_harmonic(samples_per_cycle: float) -> int:
    """The highest odd harmonic a window can hold: the seventh where a cycle has 24 samples or more,
    the fifth from 16 (a symmetric oscillator's waveform at 1 rad holds ~1e-2 of third, ~1e-4 of fifth,
    ~1e-6 of seventh), the third from 8, the fundamental alone below."""
    return 7 if samples_per_cycle >= 24 else 5 if samples_per_cycle >= 16 else 3 if samples_per_cycle >= 8 else 1


def baseline_of(tau: np.ndarray, cyc: Cycles) -> np.ndarray:
    """The slow offset under the oscillation at every sample: the good cycles' offsets smoothed over
    :data:`_BASELINE_CYCLES` cycles either side (:func:`smooth`), held beyond the ends."""
    g = cyc.good
    x = cyc.centre[g]
    if len(x) < 2:
        return np.full(len(tau), float(np.median(cyc.offset[g])) if g.any() else 0.0)
    width = _BASELINE_CYCLES * float(np.median(np.diff(x)))
    at = np.linspace(x[0], x[-1], max(2, 4 * len(x)))
    return np.interp(tau, at, smooth(x, cyc.offset[g], at, width))


def smooth(x: np.ndarray, y: np.ndarray, at: np.ndarray, width: float) -> np.ndarray:
    """Local linear regression of ``y`` on ``x`` at the points ``at`` with tricube weights over +-
    ``width``: a running straight line (exact for a linear trend), from its weighted sums at every point
    at once; where one point is in reach its value, where none the interpolation of ``y``."""
    d = (x[None, :] - at[:, None]) / width
    u = np.abs(d)
    w = np.where(u < 1.0, (1.0 - u**3) ** 3, 0.0)
    wd = w * d
    s0, s1, s2 = w.sum(axis=1), wd.sum(axis=1), (wd * d).sum(axis=1)
    t0, t1 = w @ y, wd @ y
    det = s0 * s2 - s1 * s1
    count = np.count_nonzero(w, axis=1)
    line = (s2 * t0 - s1 * t1) / np.where(count >= 2, det, 1.0)
    return np.where(count >= 2, line, np.where(count == 1, t0 / np.where(count == 1, s0, 1.0), np.interp(at, x, y)))
