"""The zero-amplitude period of a measured record, cycle by cycle: each cycle's phase, one law for all.

The record is an angle, an angular rate or a signal only proportional to the angle (:mod:`.read`),
sampled at increasing, possibly uneven times with gaps, with noise (white or correlated over many
frames), a drifting offset, glitches, stuck values, a tracker locking on, and possibly a second mode
beating in. The fit never models the damping, the drift or the tracker: it measures each cycle on its
own and asks one thing of all of them together, the rig's amplitude law. This module runs the steps
and assembles the result; each step is a module of its own.

1. Cycles (:mod:`.cycles`, a pass: :func:`.cycles.measure`): the record is cut into windows one local
   period long; in each, least squares gives the offset and the odd harmonics 1, 3, .. 7 (as many as the
   window's samples hold) of the phase w u + c u^2 / 2 under the envelope e^(lam u) (u the time from the
   window's centre; w, c and lam the local frequency, its drift and the decay the last pass's law
   gives), the frequency itself refined in the window (:func:`.cycles._window_fit`): the fundamental's
   phase at the centre with its variance, and its amplitude. Over a whole cycle these are orthogonal, so
   the offset, its drift and the waveform's harmonics take nothing from the phase. A slow baseline (the
   offsets, smoothed across cycles) is subtracted before the last pass, so that no window sees a slope.
2. Left out (:mod:`.clean`): stuck values, single-sample glitches beyond 6 robust sigmas of the record's
   and the neighbourhood's second differences within a window, and whole cycles that are not the rig's
   (a residual far above the record's and its neighbours': the tracker locking on; too few samples:
   frames lost; an amplitude that jumps away from its neighbours'; a phase more than 6 sigmas and 0.02
   rad off the law: the tracker jumped).
3. A second mode (:mod:`.second_mode`): a peak of the periodogram of the record less the law's first
   mode, away from the first mode's harmonics, is fitted as a damped sinusoid, subtracted and the cycles
   refitted; one the cycles do not show is looked for again in the whole fit's residual (step 6). One
   within 15 % of the torsion's frequency, where the periodogram cannot look or where the law took part
   of its beat, is found by the beat itself (:mod:`.near`: the cycles' phase and envelope wobbling
   together), fitted beside the first mode, subtracted and the law refitted; what its trade with the
   law does to omega0 is added to the sigma (:func:`.near.near_doubt`).
4. The law (:mod:`.phase_law`, the ideal law: :mod:`.law`): the phases follow Phi(t) = phi0 + omega0 int
   dt / (R(A(t)) E(A(t)) D(t)), A(t) the peak amplitude (the cycles' amplitudes through the law's
   waveform, ln A a Chebyshev series of the degree Akaike's criterion allows: :class:`.phase_law._Envelope`), R
   the ideal law, E = 1 + ds A^2 + dq A^4 + d6 A^6 the real rig's excess with Gaussian priors, D the
   damping's shift of the frequency (:mod:`.damping`). Weighted least squares gives omega0 = 2 pi / T0,
   the zero-amplitude period, and the excess.
5. Uncertainty (:mod:`.spread`): the long-run covariance of the phase residuals' scores (summed over
   blocks of :data:`.spread.BLOCK_TAUS` integrated autocorrelation times where neighbouring cycles err
   together: tracker noise correlated over many frames, a wandering offset; Newey-West over two
   neighbours where they err in turn: a sway beating every few cycles), never below the white-noise
   covariance, plus what the envelope's own uncertainty adds (Murphy-Topel) and what choosing its
   degree adds (:meth:`.phase_law.Model.envelope_doubt`: Akaike's weights over the degrees, on video
   records with noise correlated within a cycle a spread of T0 as large as the rest); the prior rows
   add the law's doubt, reported apart (``period_std_law``), with the learned law's own doubts
   (:meth:`.phase_law.Model.check_law`: its extrapolation to zero swing, a law no rig has or an
   envelope that rises again or decays as no damping law does, a mode near the torsion's frequency
   beating in: :mod:`.near`). A
   delete-a-group jackknife of the law's fit over 20 groups of cycles, the envelope's degree held,
   checks it (:meth:`.phase_law.Model.jackknife`): where its variance is above what it gives an honest
   covariance at 95 % (the groups at the ends move omega0 more than their share:
   :func:`.spread.jackknife_inflation`), the jackknife's over that ratio (Student-t scaled) is the
   statistical variance.
6. The whole record (:mod:`.whole`): every kept sample fitted at once with the law's shape held, for the
   efficiency of a plain damped-sine fit; its sandwich over cycles (scaled to the Student-t interval of
   its few blocks: :func:`.spread.few_blocks`) plus what the law's uncertainty adds is the statistical
   sigma of T0. Beside it, the Cramér-Rao bound of T0 (:mod:`.bound`) for that model with the law's
   parameters free under their priors, and the noise its residual shows (white, or coloured: an
   autoregressive spectrum): how far the sigma is from the smallest any unbiased fit could state.

A proportional record (pixels) has no known scale: with ``scale`` (signal units per rad) it is an
angle record; with ``max_amplitude`` (rad, the largest swing it can have had) the scale kappa is fitted
with a prior uniform on [0, max_amplitude / first amplitude]; with neither the law cannot be applied
(a small swing is assumed, the period is the one at the record's amplitudes) and the fit says so.
A compound pendulum's (:func:`.phase_law.pendulum`) is the exception: its scale is read from each
cycle's third harmonic (:func:`.phase_law.harmonic_scale`) and fitted with the law under that prior.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.stats import chi2

from .bounds import Deadline, binned
from .clean import Rejected, spans, stuck
from .cycles import Cycles, Samples, baseline_of, measure, rough_frequency
from .law import EXCESS_PRIOR, LINEAR, AmplitudeLaw
from .near import NEAR_BAND, near_doubt, near_held, near_mode_of, near_refit
from .phase_fit import EXCESS_TERMS, PhaseFit
from .phase_law import LAW_CONFLICT, Model, pendulum, swing_of, unwrap
from .read import KINDS, MIN_CYCLES, MIN_SAMPLES
from .second_mode import second_mode_of
from .spread import few_blocks
from .whole import Whole, fit_whole

MIN_SNR = 3.0  # the fundamental's RMS against the residual's: a noise-only fit reaches ~0.2-0.5
_PASSES = 3  # cycles refitted with the law's local frequency and the baseline removed


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
    beat: bool = False  # the envelope is not one mode's decay (.near): the ideal law's T0 is in the sigma
    ideal_gap: float = 0.0  # s, T0 under the ideal law (the excess held at zero) less T0 learned

    @property
    def coefficient(self) -> float | None:
        return None if self.ideal is None else self.ideal + self.excess

    def as_dict(self) -> dict:
        return {"kind": self.kind, "ideal": self.ideal, "coefficient": self.coefficient, "excess": self.excess,
                "excess_std": self.excess_std, "excess_quartic": self.quartic, "excess_quartic_std": self.quartic_std,
                "learned": self.learned, "note": self.note, "conflict": self.conflict, "beat": self.beat}


@dataclass(frozen=True)
class OscillationFit:
    """A fitted record (module docstring). Times in s, angles in rad (signal units where the scale of a
    proportional record is unknown).

    ``period`` is T0 = 2 pi / omega0; ``period_std`` its whole standard deviation, the root-sum-square
    of ``period_std_statistical`` (the record's noise: step 5's covariance and its checks) and
    ``period_std_law`` (the amplitude law's doubt, from the priors); ``period_std_white`` is the
    white-noise sigma, for comparison. ``prior_gain`` maps the law's prior errors (in prior sigmas) to
    T0 (s per sigma): records of one rig share that error (pooling). ``amplitude``: peak rotation in the
    first and last cycle (None where the scale is unknown). ``cycle_*``: the measured cycles.
    ``jackknife``: the groups of cycles of the jackknife that set the statistical sigma (0: the
    covariance held; :meth:`.phase_law.Model.jackknife`). ``crb``: the Cramér-Rao bound's sigma of T0 (s) for the whole
    fit's model with the law's parameters free under their priors (the record's part) and the noise its
    residual shows, judged ``crb_noise`` ('white'
    or 'coloured'; :mod:`.bound`): ``period_std_statistical / crb`` is how far the fit is from efficient.
    ``period_std_parts`` says why: the standard deviations (s) whose root-sum-square is
    ``period_std_statistical``, each what one doubt adds (absent where it adds nothing): ``noise``, the
    whole record's sandwich with the law held; ``law``, what the law's excess (and a proportional record's
    scale) carries into T0 as the record's noise moves it; ``jackknife``, where the jackknife found the
    covariance short; ``envelope``, choosing the envelope's degree; ``near_mode``, a mode near the
    torsion's frequency trading with the law; ``rig_mode``, what the rig's near mode the record does not
    show moves T0 when fitted at its frequency (``rig_mode_shift``, added by
    :func:`.pipeline.identify_records`). ``near_held``: the second mode is one of ``near_periods``
    fitted at its given frequency (:func:`.near.near_held`), not one the record showed.
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
    crb: float = math.nan  # s, the Cramér-Rao bound's sigma of T0 (:mod:`.bound`)
    crb_noise: str = ""  # the noise the bound assumed: 'white' or 'coloured'
    period_std_parts: dict = field(default_factory=dict)  # s, what makes period_std_statistical (its docstring)
    near_held: bool = False  # the second mode is the rig's near mode at its frequency (near_periods), not found
    rig_mode_shift: float = 0.0  # s, T0 moved by the rig's near mode fitted at its frequency, in period_std


def fit_oscillation(t, y, kind: str, law: AmplitudeLaw = LINEAR, *, excess_prior: float = EXCESS_PRIOR,
                    scale: float | None = None, max_amplitude: float | None = None,
                    second_mode: bool = True, near_periods: tuple[float, ...] = (),
                    deadline: Deadline | None = None) -> OscillationFit:
    """Fit the module's model to samples ``y`` at increasing times ``t`` (s).

    ``excess_prior``: the prior std of ds / s and dq / s (0: the ideal law exactly). ``scale`` and
    ``max_amplitude``: what is known of a proportional record's scale (module docstring). ``near_periods``
    (s): the rig's modes near the torsion's frequency that the record may not show by their beat; where
    the record shows none, a mode at the nearest-fitting of them is fitted beside the torsion at that
    frequency whatever its size, and its doubt carried into the sigma (:func:`.near.near_held`). A dense record
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
    rec = Samples(tau, y, kind, ~stuck(y), float(np.median(np.diff(tau))), deadline=deadline or Deadline())
    rejected = Rejected(stuck=int((~rec.usable).sum()))
    rec.omega = omega = rough_frequency(rec)
    tau, y, rec.binned = binned(tau, y, rec.usable, omega, rec.step)  # a dense record: its bins (.bounds)
    if rec.binned > 1:
        t = t[0] + tau
        rec.tau, rec.y, rec.usable, rec.step = tau, y, np.ones(len(y), dtype=bool), rec.binned * rec.step
    if omega * tau[-1] / (2.0 * math.pi) < MIN_CYCLES:
        raise ValueError(f"the record holds {omega * tau[-1] / (2.0 * math.pi):.3g} cycles; at least {MIN_CYCLES} "
                         "are needed")
    # a proportional record of a compound pendulum: its scale from its own third harmonic (.phase_law)
    uses_law = law.kind != "linear" and (kind != "proportional" or max_amplitude is not None or pendulum(law))
    model = Model(law if uses_law else LINEAR, kind, excess_prior if uses_law else 0.0, max_amplitude)
    baseline = np.zeros(len(y))
    second = None
    cyc = measure(rec, baseline, lambda c: (np.full(len(c), omega), np.zeros(len(c))), second)
    _check_swing(cyc, law, kind)
    phase = model.fit(cyc)
    for _ in range(_PASSES):
        if second_mode:  # (re-)estimated on the record as it is, under the latest first mode
            second = second_mode_of(rec, cyc, baseline, phase)
        cyc = measure(rec, baseline, phase.local, second)
        phase = model.fit(cyc, phase)
        baseline = baseline + baseline_of(rec.tau, cyc)  # the offsets left under the last baseline
    cyc = measure(rec, baseline, phase.local, second)
    phase = model.check_law(model.fit(cyc, phase, slips=True), cyc)
    near = None
    if second_mode and second is None:
        near = near_mode_of(cyc, phase, rec.kind == "rate", model.prior)
        if near is None and near_periods:
            near = near_held(cyc, phase, rec.kind == "rate", model.prior,
                             tuple(2.0 * math.pi / p for p in near_periods))
    elif second is not None and abs(second.omega / phase.omega0 - 1.0) <= NEAR_BAND:
        near = near_refit(cyc, phase, rec.kind == "rate", model.prior, second)
    if near is not None:  # a mode near the torsion's frequency, found by its beat: subtracted, the law refitted
        second = near
        for _ in range(2):
            cyc = measure(rec, baseline, phase.local, second)
            phase = model.fit(cyc, phase)
        phase = model.check_law(model.fit(cyc, phase, slips=True), cyc)
    whole = fit_whole(rec, cyc, phase, baseline, second)
    doubt = 0.0
    if whole.second is not None:  # what a mode near the torsion's frequency trades with the law (.near)
        doubt = near_doubt(cyc, phase, rec.kind == "rate", model.prior, whole.second, second)
    return _result(rec, t, cyc, model, phase, baseline, whole, rejected, law.kind, doubt)


class SwingError(ValueError):
    """A record whose swing (rad, ``swing``) is past what the rig's law can hold (``limit``)."""

    def __init__(self, swing: float, limit: float):
        super().__init__(f"a swing of {swing:.4g} rad, past the law's {limit:.4g} rad")
        self.swing, self.limit = swing, limit


def _check_swing(cyc: Cycles, law: AmplitudeLaw, kind: str) -> None:
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


def _result(rec: Samples, t: np.ndarray, cyc: Cycles, model: Model, phase: PhaseFit, baseline: np.ndarray,
            whole: Whole, rejected: Rejected, ideal_kind: str = "linear", near_variance: float = 0.0) -> OscillationFit:
    good = cyc.good & np.isfinite(cyc.phase)
    omega0 = whole.omega0
    period = 2.0 * math.pi / omega0
    to_period = 2.0 * math.pi / omega0**2
    # the whole record's statistical variance, and what the law's parameters add to it; the law's prior
    # part of that is reported apart (and is what records of one rig share)
    # the learned law's own doubts (:meth:`.phase_law.Model.check_law`): its extrapolation to zero swing (one
    # excess term fewer), and past LAW_CONFLICT the ideal law's T0 (the record's beat or the rig file's
    # law is wrong); the interval holds both T0s of each (the record's doubt, not the prior's that the
    # trials share)
    base = whole.variance + phase.law_induced_variance() + phase.held_shift**2
    # the extrapolation's doubt where it is more than the sigma already holds: the sigma is at least the
    # difference of the two extrapolations (where the record determines the law it is well inside it)
    order = max(0.0, phase.order_shift**2 - base)
    held = phase.held_shift**2 + order
    std_law = to_period * math.sqrt(phase.cov_law[1, 1] + held)
    std_all = to_period * math.sqrt(base + order)
    std_stat = math.sqrt(max(std_all**2 - std_law**2, to_period**2 * whole.variance))
    parts = {"noise": to_period**2 * whole.variance}  # what each doubt adds to std_stat^2 (s^2)
    parts["law"] = std_stat**2 - parts["noise"]
    jack, groups, ratio, dof = model.jackknife(phase, cyc)
    if not (groups and jack > (std_stat / to_period) ** 2 * ratio * chi2.ppf(0.95, dof) / dof):
        groups = 0  # the covariance holds: the jackknife is not above what it gives an honest one at 95 %
    else:  # the covariance is short: the jackknife's over its leverage, to its Student-t interval
        wider = max(std_stat, to_period * math.sqrt(jack / ratio * few_blocks(groups)))
        parts["jackknife"], std_stat = wider**2 - std_stat**2, wider
    # what choosing the envelope's degree adds, which neither holds (the jackknife keeps the degree), and
    # what a mode near the torsion's frequency adds by trading with the law (.near.near_doubt)
    for name, variance in (("envelope", model.envelope_doubt(phase, cyc)), ("near_mode", near_variance)):
        std = to_period * math.sqrt(variance)
        parts[name], std_stat = std**2, math.hypot(std_stat, std)
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
    fund = phase.fund_at(centre)
    amplitude_rad = phase.peak_at(centre) if model.law.kind != "linear" else None
    if model.kind in ("angle", "rate") and model.law.kind == "linear":
        amplitude_rad = fund  # a linear law: the fundamental is the peak
    unwrapped = unwrap(cyc, good)
    neighbours = np.diff(np.flatnonzero(good)) == 1
    per_cycle = np.where(neighbours, 2.0 * math.pi * np.diff(centre) / np.maximum(np.diff(unwrapped), 1e-300), np.nan)
    cycle_amp = amplitude_rad if amplitude_rad is not None else fund
    names = phase.names
    std = np.sqrt(np.diag(phase.cov_stat + phase.cov_law))
    excess = phase.params[names.index("ds")] if "ds" in names else 0.0
    quartic = phase.params[names.index("dq")] if "dq" in names else 0.0
    learned = 0.0
    if "ds" in names:
        i = names.index("ds")
        prior_sd = model.prior * abs(phase.ideal)
        learned = max(0.0, 1.0 - std[i] ** 2 / prior_sd**2) if prior_sd > 0 else 0.0
    note = ""
    if model.kind == "proportional" and "kappa" not in names and "q" not in names and ideal_kind != "linear":  # linear: no law to apply
        note = ("scale unknown: the ideal law cannot be applied; T0 is the period at the record's amplitudes "
                "(a small swing assumed)")
    law = Law("none (scale unknown)" if note else model.law.kind,
              phase.ideal, float(excess), float(std[names.index("ds")]) if "ds" in names else 0.0,
              float(quartic), float(std[names.index("dq")]) if "dq" in names else 0.0, float(learned), note,
              phase.conflict if phase.conflict > LAW_CONFLICT else None, phase.rises, to_period * phase.ideal_shift)
    curve = _law_curve(model, phase, period, cycle_amp)
    level = cyc.offset[good] + np.interp(centre, rec.tau, baseline)  # the offset under each cycle
    amplitude = None
    if phase.scale_known and amplitude_rad is not None:
        amplitude = (float(amplitude_rad[0]), float(amplitude_rad[-1]))
    return OscillationFit(
        period=period, period_std=math.hypot(std_stat, std_law), period_std_statistical=std_stat,
        period_std_law=std_law, period_std_white=std_white, prior_gain=to_period * phase.prior_gain, law=law,
        amplitude=amplitude, damping=phase.damping, offset=float(np.median(cyc.offset[good])),
        drift=float(np.polyfit(centre, cyc.offset[good] + np.interp(centre, rec.tau, baseline), 1)[0])
        if len(centre) > 1 else 0.0,
        rms=rms, outliers=t[glitch], rejected=rejected,
        second_mode=None if second is None else (2.0 * math.pi / second.omega, math.hypot(second.c, second.s),
                                                 second.decay),
        block=whole.block, jackknife=groups, samples=int(kept.sum()), cycles=int(good.sum()), cycle_time=t[0] + centre,
        cycle_period=per_cycle, cycle_amplitude=cycle_amp, law_curve=curve, t=t, y=rec.y, fitted=fitted, kept=kept,
        binned=rec.binned, crb=to_period * math.sqrt(whole.bound.variance), crb_noise=whole.bound.noise,
        period_std_parts={k: math.sqrt(v) for k, v in parts.items() if v > 1e-9 * std_stat**2},  # not rounding
        near_held=second is not None and second.held)


def _law_curve(model: Model, phase: PhaseFit, period: float, amplitude: np.ndarray):
    """(A, T(A) fitted, T(A) ideal) over the record's amplitude range, for plots."""
    a = np.linspace(0.0, float(np.max(amplitude)) * 1.05, 60)
    if model.law.kind == "linear" or phase.table is None or not phase.scale_known:
        flat = np.full(len(a), period)
        return a, flat, flat
    names, p = phase.names, phase.params
    kappa = p[names.index("kappa")] if "kappa" in names else 1.0
    a_rad = a * kappa if model.kind == "proportional" else a
    if "q" in names:
        a_rad = swing_of(math.sqrt(p[names.index("q")]) * a, phase.harmonic[2])
    ideal = period * phase.table.ratio_at(np.minimum(a_rad, phase.table.largest))
    excess = 1.0
    if "ds" in names:
        excess = 1.0 + sum(p[names.index(n)] * a_rad ** (2 * (j + 1)) for j, n in enumerate(EXCESS_TERMS))
    return a, ideal * excess, ideal
