"""The zero-amplitude period of a measured record: the rig's own nonlinear oscillation fitted to it.

The record is an angle, an angular rate or a signal only proportional to the angle
(:mod:`bifilar.identification.records`), sampled at increasing, possibly uneven times, with noise
(white or coloured), an offset, a linear drift, isolated glitches and possibly a second, superposed
mode. Its model is one degree of freedom with linear and quadratic damping,

    theta'' = -omega^2 f(theta, theta'; omega) - omega^2 k_x theta^3 - 2 zeta omega theta' - c |theta'| theta',
    signal(t) = offset + drift (t - t0) + g (theta or theta')(t) [+ e^(-a2 t) (c2 cos w2 t + s2 sin w2 t)],

integrated by RK4 on a fixed grid and read at the sample times by cubic Hermite interpolation.

The amplitude law f (:class:`AmplitudeLaw`) is the rig's own, not a cubic stand-in:

* ``exact``: the exact 1-DOF torsion of :mod:`bifilar.motion.lagrange` (wires of any spacing, the
  vertical kinetic energy kept), (I + m z'^2) theta'' + m z' z'' theta'^2 + m g z' = 0, divided by I:
  with z' = (bD / 4H) u(theta), u = sin(theta) / r, r = sqrt(1 - rho sin^2(theta/2)), rho = bD / H^2,

      f = u (1 + lam v theta'^2) / (1 + lam omega^2 u^2),   v = cos(theta) / r + rho u^2 / (4 r),

  lam = bD / (4 H g): the ratio m z'^2 / I is lam omega^2 u^2, so the law needs the geometry only,
  not the mass or the moment. omega is exactly the small-amplitude undamped frequency.
* ``series``: f = theta (1 + kappa theta^2 + q theta^4), kappa = -8 s / 3 reproducing T(A) = T0 (1 + s
  A^2) of the Kane model (:func:`bifilar.identification.identify.amplitude_coefficient`), for modes
  that are not a symmetric torsion; the quintic q, matched to the Kane model's T(A) / T0 at the
  record's largest amplitude (:meth:`AmplitudeLaw.matched`), makes it right at both ends of the
  record's amplitude range, not only to O(A^2).
* ``linear``: f = theta.

Where the real rig's amplitude dependence differs from the ideal law (wire stretch, finite hooks),
for the exact law the excess cubic k_x = -8 ds / 3 is fitted, ds the excess period-amplitude coefficient, with a
Gaussian prior of standard deviation :data:`EXCESS_PRIOR` times the law's own s: a decaying record
determines ds itself, a record at one amplitude leaves it at the prior, whose width then enters the
period's standard deviation as model error. ``amplitude_coefficient`` = s + ds is reported. The
series law is not fitted (over a coupled mode the waveform's harmonics differ from a cubic's and
would set ds wrongly): the same relative uncertainty of its s enters the period's variance as
(omega EXCESS_PRIOR s <A^2>)^2, <A^2> the mean of the first and last cycle's squared amplitudes.

The fit, robust over 150 cycles:

1. start: a Lomb-Scargle peak and a closed-form damped sinusoid over the first :data:`FIRST_CYCLES`
   cycles, its frequency mapped to the zero-amplitude one through the law at the measured amplitude
   (:func:`AmplitudeLaw.ratio`), so that the start is right at any amplitude;
2. continuation: the window grows :data:`GROWTH`-fold until it holds the whole record, each fit starting from the
   last, so that the phase cannot slip by a cycle (a 1 % frequency error over 150 cycles would);
3. glitches: a soft-L1 loss while the window grows, then samples beyond :data:`OUTLIER_Z` robust
   standard deviations (1.4826 MAD) are rejected and reported, and the inliers refitted by ordinary
   least squares;
4. a second mode: if the residual periodogram has a peak :data:`SECOND_MODE_POWER` times its median
   over an octave either side (its own lobe, the first mode and its harmonics left out), a damped sinusoid is added and everything refitted.

Uncertainty: the sandwich covariance with residual scores summed over blocks of consecutive samples
(batch means), the block :data:`BLOCK_TAUS` integrated autocorrelation times of the residual long, so
that coloured noise (a smoothing tracker) and slow model error widen the interval as they should;
white noise gives blocks of one, the usual Jacobian covariance.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
from numba import njit
from scipy.optimize import least_squares
from scipy.signal import lombscargle

from bifilar.identification.periods import crossing_times
from bifilar.identification.records import KINDS, MIN_SAMPLES, Record

MIN_CYCLES = 2.0  # fewer cycles in the record and the periodogram cannot locate the peak
MIN_SNR = 3.0  # the fitted swing's RMS against the residual's; a noise-only fit reaches ~0.2-0.5
# the start's sinusoid against the rest of the first cycles: noise alone gives ~sqrt(2 / samples),
# a second mode as large as the first ~1
START_SNR = 0.7
START_SAMPLES = 100  # at least this many samples in the first window: noise alone then gives < 0.4
FIRST_CYCLES = 4.0  # first window: long enough for a periodogram, short enough that A barely decays
GROWTH = 3.0  # window growth per stage: a fit of N cycles predicts the phase over 3N to << 1 cycle
OUTLIER_Z = 6.0  # robust sigmas: a normal sample exceeds it with probability 2e-9 (none in 1e6 samples)
EXCESS_PRIOR = 0.5  # prior std of ds / s: a real rig's amplitude law may differ by tens of percent
SECOND_MODE_POWER = 60.0  # peak / local median of the residual periodogram: noise peaks reach ~10-15
BLOCK_TAUS = 4.0  # batch-means block, in integrated autocorrelation times of the residual
MIN_BLOCKS = 20  # fewer blocks and the block variance itself is too uncertain
# RK4 steps per period: relative frequency error (omega h)^4 / 120 = 5e-8, cubic Hermite reading
# of the same order: far below the statistical error of any real record.
_STEPS_PER_PERIOD = 128
_PERIODOGRAM_SAMPLES = 512  # at most this many samples in a periodogram (starting values only)
# Matching a series law's quintic to the Kane model's T(A) / T0: the ratio itself is integrated to
# ~1e-10 (4096 RK4 steps per period), the Kane ratio is timed to ~1e-9; 1e-9 and a few secant steps.
_MATCH_TOL = 1e-9
_MATCH_STEPS = 6


@dataclass(frozen=True)
class AmplitudeLaw:
    """The restoring law f of the module docstring: ``kind`` ``exact``, ``series`` or ``linear``.

    ``rho`` = bD / H^2 and ``lam`` = bD / (4 H g) (s^2) for ``exact``; ``s`` (1/rad^2) for ``series``.
    """

    kind: str = "linear"
    rho: float = 0.0
    lam: float = 0.0
    s: float = 0.0
    quintic: float = 0.0  # series law: the theta^5 coefficient of f (1/rad^4), see :meth:`matched`

    @classmethod
    def torsion(cls, torsion_rig) -> "AmplitudeLaw":
        """The exact law of a :class:`bifilar.motion.lagrange.TorsionRig`."""
        bd, h = torsion_rig.hook_span * torsion_rig.attach_span, torsion_rig.height
        return cls("exact", rho=bd / h**2, lam=bd / (4.0 * h * torsion_rig.gravity))

    def coefficient(self, omega: float) -> float:
        """s in T(A) = T0 (1 + s A^2 + O(A^4)) (1/rad^2) at zero-amplitude frequency ``omega``.

        Exact law: s = eps / 4 - 3 beta / 8 with eps = lam omega^2 and beta = -1/6 + rho / 8, the series
        of :func:`bifilar.motion.lagrange.period_amplitude_coefficient`."""
        if self.kind == "exact":
            return 0.25 * self.lam * omega**2 - 0.375 * (-1.0 / 6.0 + 0.125 * self.rho)
        return self.s

    def ratio(self, amplitude: float, omega: float) -> float:
        """T(A) / T0 of the undamped law, from a quarter cycle integrated from rest at ``amplitude``."""
        if self.kind == "linear" or amplitude == 0.0:
            return 1.0
        period = 2.0 * math.pi / omega
        h = period / 4096.0
        stretch = 1.0 + 4.0 * abs(self.coefficient(omega)) * amplitude**2 + 4.0 * abs(self.quintic) * amplitude**4
        tau = np.arange(0.0, 0.75 * period * stretch, h)
        p = np.array([omega, 0.0, 0.0, amplitude, 0.0, 0.0, 0.0])
        theta = _response(p, self.kind == "exact", self.rho, self.lam, self._kappa(0.0), self.quintic, tau, h, False)
        down = crossing_times(tau, theta, 0.0, rising=False)
        return float(4.0 * down[0] / period) if len(down) else 1.0

    def matched(self, amplitude: float, ratio: float, omega: float) -> "AmplitudeLaw":
        """This series law with the quintic coefficient that makes its T(A) / T0 at ``amplitude``
        equal ``ratio`` (the Kane model's, :func:`bifilar.identification.identify.amplitude_ratio`):
        right at O(A^2) by s and at the record's largest amplitude by the quintic. T(A) / T0 falls by
        ~(5 / 16) q A^4 as q grows, nearly linearly: secant steps from that estimate."""
        if self.kind != "series":
            raise ValueError("only a series law takes a quintic term")
        law = replace(self, quintic=0.0)
        step = 16.0 / (5.0 * amplitude**4)
        q0, r0 = 0.0, law.ratio(amplitude, omega)
        q1 = q0 + (r0 - ratio) * step
        for _ in range(_MATCH_STEPS):
            r1 = replace(law, quintic=q1).ratio(amplitude, omega)
            if abs(r1 - ratio) < _MATCH_TOL or r1 == r0:
                break
            q0, r0, q1 = q1, r1, q1 - (r1 - ratio) * (q1 - q0) / (r1 - r0)
        return replace(law, quintic=float(q1))

    def _kappa(self, excess: float) -> float:
        """The cubic coefficient of f: the series law's own and the fitted excess."""
        return (-8.0 / 3.0) * ((self.s if self.kind == "series" else 0.0) + excess)


LINEAR = AmplitudeLaw()


@dataclass(frozen=True)
class OscillationFit:
    """A fitted record (module docstring). Times in s, angles in rad (signal units for ``proportional``).

    ``period`` is 2 pi / omega, the undamped zero-amplitude period, and ``period_std`` its standard
    deviation from the block covariance (``period_std_white`` the white-noise one, for comparison);
    ``amplitude`` the model's peak rotation in its first and last cycle (None where the scale is
    unknown); ``outliers`` the times of rejected samples; ``second_mode`` (period s, amplitude,
    decay rate 1/s) or None; ``block`` the batch length in samples.
    """

    period: float
    period_std: float
    period_std_white: float
    zeta: float
    zeta_std: float
    quadratic: float
    quadratic_std: float
    amplitude_coefficient: float
    amplitude_coefficient_std: float
    law: str
    amplitude: tuple[float, float] | None
    offset: float
    drift: float
    rms: float
    outliers: np.ndarray
    second_mode: tuple[float, float, float] | None
    block: int
    names: tuple[str, ...]
    parameters: np.ndarray
    covariance: np.ndarray
    samples: int
    t: np.ndarray
    y: np.ndarray
    fitted: np.ndarray  # the model at every sample time, outliers included
    first_mode: np.ndarray  # its first-mode part alone (no offset, drift or second mode)
    kept: np.ndarray  # boolean mask of the inliers

    @property
    def std(self) -> dict[str, float]:
        return dict(zip(self.names, np.sqrt(np.diag(self.covariance))))


@dataclass
class _Spec:
    """What is being fitted: the parameter layout and the fixed quantities of the model."""

    kind: str
    law: AmplitudeLaw
    tau: np.ndarray
    y: np.ndarray
    step: float
    names: list
    prior_std: float = 0.0  # of the excess coefficient; 0: not fitted
    noise: float = 1.0  # residual scale for the prior row
    law_sigma: float = 0.0  # relative std of the law's coefficient (model error of a series law)

    def index(self, name: str) -> int:
        return self.names.index(name)

    def law_terms(self, p: np.ndarray) -> tuple[bool, float, float]:
        """(exact law?, cubic coefficient, quintic coefficient) at parameters ``p``. A proportional
        record runs in signal units x, theta = sqrt(gain) x: the law enters as its O(A^2) series, its
        cubic scaled by gain."""
        n = self.names
        if self.kind == "proportional":
            gain = p[n.index("gain")] if "gain" in n else 0.0
            return False, -8.0 / 3.0 * self.law.coefficient(p[0]) * gain, 0.0
        excess = p[n.index("excess")] if "excess" in n else 0.0
        return self.law.kind == "exact", self.law._kappa(excess), self.law.quintic

    def model(self, p: np.ndarray, tau: np.ndarray, first_only: bool = False, rate_out: bool | None = None) -> np.ndarray:
        """The model signal at ``tau``; ``first_only``: theta (or theta') alone, no offset, drift or
        second mode."""
        exact, kappa, kappa5 = self.law_terms(p)
        base = np.array(p[:7], dtype=float)
        if first_only:
            base[5] = base[6] = 0.0
        rate_out = self.kind == "rate" if rate_out is None else rate_out
        out = _response(base, exact, self.law.rho, self.law.lam, kappa, kappa5, tau, self.step, rate_out)
        if "omega2" in self.names and not first_only:
            j = self.names.index("omega2")
            w2, a2, c2, s2 = p[j : j + 4]
            out = out + np.exp(-a2 * tau) * (c2 * np.cos(w2 * tau) + s2 * np.sin(w2 * tau))
        return out


def fit_record(record: Record, law: AmplitudeLaw = LINEAR, second_mode: bool = True,
               excess_prior: float = EXCESS_PRIOR) -> OscillationFit:
    """:func:`fit_oscillation` of a :class:`~bifilar.identification.records.Record`."""
    return fit_oscillation(record.t, record.y, record.kind, law, second_mode, excess_prior)


def fit_oscillation(t, y, kind: str, law: AmplitudeLaw = LINEAR, second_mode: bool = True,
                    excess_prior: float = EXCESS_PRIOR) -> OscillationFit:
    """Fit the module's model to samples ``y`` at increasing times ``t`` (see the module docstring).

    ``excess_prior``: the prior std of ds / s (0: the law exactly, no excess fitted). A record whose
    amplitude hardly decays cannot tell T0 from the law: its period sigma then carries this prior.
    Raises ValueError naming what is wrong with a record that cannot be used.
    """
    if kind not in KINDS:
        raise ValueError(f"kind must be one of {KINDS}, got {kind!r}")
    t, y = np.asarray(t, dtype=float), np.asarray(y, dtype=float)
    if t.ndim != 1 or t.shape != y.shape or len(t) < MIN_SAMPLES:
        raise ValueError(f"need two 1-D arrays of equal length >= {MIN_SAMPLES}, got shapes {t.shape} and {y.shape}")
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(y)) and np.all(np.diff(t) > 0.0)):
        raise ValueError("times must increase and every sample be finite")
    tau = t - t[0]
    omega_mean = _periodogram_peak(tau, y)
    cycles = omega_mean * tau[-1] / (2.0 * math.pi)
    if cycles < MIN_CYCLES:
        raise ValueError(f"the record holds {cycles:.3g} cycles; at least {MIN_CYCLES:g} are needed")

    spec, p = _start(tau, y, kind, law, omega_mean, excess_prior)
    cycles = p[0] * tau[-1] / (2.0 * math.pi)
    if cycles < MIN_CYCLES:
        raise ValueError(f"the record holds {cycles:.3g} cycles; at least {MIN_CYCLES:g} are needed")
    # 2. continuation over a doubling window, robust loss
    end = FIRST_CYCLES * 2.0 * math.pi / omega_mean
    kept = np.ones(len(tau), dtype=bool)
    while True:
        window = tau <= end
        last = end >= tau[-1]
        p = _solve(spec, p, window, robust=True, tol=1e-8 if last else 1e-6)  # a stage is only a start
        if last:
            break
        end = min(GROWTH * end, tau[-1])
    # 3. outliers: reject, refit the inliers by least squares, until the set stops changing
    p, kept = _reject(spec, p)
    # 4. a second mode in the residual
    if second_mode:
        found = _second_mode(spec, p, kept)
        if found is not None:
            spec.names += ["omega2", "decay2", "cos2", "sin2"]
            p = _solve(spec, np.append(p, found), kept, robust=True)
            p, kept = _reject(spec, p)
    return _result(spec, p, kept, t, y)


def _start(tau, y, kind, law, omega_mean, excess_prior):
    """The parameter layout and the amplitude-aware start from the first cycles (step 1)."""
    first = tau <= FIRST_CYCLES * 2.0 * math.pi / omega_mean
    if first.sum() < START_SAMPLES:
        first = np.arange(len(tau)) < START_SAMPLES
    omega_d, alpha, c, s, offset, drift = _damped_sinusoid(tau[first], y[first], omega_mean)
    omega_d = abs(omega_d)
    swing = np.exp(-alpha * tau[first]) * (c * np.cos(omega_d * tau[first]) + s * np.sin(omega_d * tau[first]))
    rest = y[first] - offset - drift * tau[first] - swing
    snr = math.sqrt(float(np.mean(swing**2))) / max(1.4826 * float(np.median(np.abs(rest))), 1e-300)
    if snr < START_SNR:  # refused before the costly stages
        raise ValueError(f"no oscillation stands out of the noise in the first {FIRST_CYCLES:g} cycles (sinusoid "
                         f"/ residual RMS = {snr:.2g} < {START_SNR:g})")
    rate_out = kind == "rate"
    amplitude = math.hypot(c, s) / (omega_d if rate_out else 1.0)
    omega = math.hypot(omega_d, alpha)
    if kind != "proportional":
        omega *= law.ratio(min(amplitude, 0.95 * math.pi), omega)  # T(A) > T0 for a softening law
    if rate_out:  # theta' = e^(-alpha tau)(c cos + s sin): theta(0) from theta''(0) = -omega^2 theta(0)
        theta0, rate0 = -(-alpha * c + omega_d * s) / omega**2, c
    else:
        theta0, rate0 = c, -alpha * c + omega_d * s
    names = ["omega", "zeta", "quadratic", "theta0", "rate0", "offset", "drift"]
    p = [omega, alpha / omega, 0.0, theta0, rate0, offset, drift]
    prior = 0.0
    if kind == "proportional" and law.kind != "linear":
        names.append("gain")  # rad^2 per signal unit^2: the square of the unknown scale
        p.append(0.0)
    elif law.kind == "exact":
        prior = excess_prior * abs(law.coefficient(omega))
        if prior > 0.0:
            names.append("excess")
            p.append(0.0)
    step = 2.0 * math.pi / (omega * _STEPS_PER_PERIOD)
    noise = 1.4826 * float(np.median(np.abs(y[first] - np.median(y[first])))) or 1.0
    return _Spec(kind, law, tau, y, step, names, prior, noise, excess_prior), np.array(p)


def _residual(spec: _Spec, p: np.ndarray, mask: np.ndarray) -> np.ndarray:
    r = spec.model(p, spec.tau[mask]) - spec.y[mask]
    if spec.prior_std > 0.0:
        r = np.append(r, spec.noise * p[spec.index("excess")] / spec.prior_std)
    return r


def _bounds(spec: _Spec, p: np.ndarray):
    lo = np.full(len(p), -np.inf)
    hi = np.full(len(p), np.inf)
    lo[0] = 0.2 * p[0]
    hi[0] = 5.0 * p[0]
    # A free oscillation loses energy: both damping coefficients are >= 0. Unbounded, a short window at
    # nearly constant amplitude cannot tell them apart and lets them cancel (zeta < 0 < quadratic),
    # which the next, longer window extrapolates into a wrong minimum.
    lo[1] = lo[2] = 0.0
    if "gain" in spec.names:
        lo[spec.index("gain")] = 0.0
    if "omega2" in spec.names:
        lo[spec.index("omega2")] = 0.0
    return lo, hi


def _solve(spec: _Spec, p: np.ndarray, mask: np.ndarray, robust: bool, tol: float = 1e-10):
    """Least squares on the samples in ``mask`` to relative ``tol``; soft-L1 at 3 robust sigmas when
    ``robust``."""
    r = _residual(spec, p, mask)[: int(mask.sum())]
    spec.noise = max(1.4826 * float(np.median(np.abs(r - np.median(r)))), 1e-300)
    lo, hi = _bounds(spec, p)
    p = np.where(p <= lo, lo + 1e-9 * np.abs(p[0]) * (lo == 0.0), p)  # a bound reached by the last fit
    kw = dict(loss="soft_l1", f_scale=3.0 * spec.noise) if robust else {}
    sol = least_squares(lambda q: _residual(spec, q, mask), p, bounds=(lo, hi), x_scale="jac", method="trf",
                        xtol=tol, ftol=tol, gtol=tol, **kw)
    return sol.x


def _reject(spec: _Spec, p: np.ndarray):
    """Step 3: inliers within :data:`OUTLIER_Z` robust sigmas, refitted until the set is stable."""
    kept = None
    for _ in range(4):
        r = spec.model(p, spec.tau) - spec.y
        inl = r if kept is None else r[kept]
        sigma = 1.4826 * float(np.median(np.abs(inl - np.median(inl))))
        new = np.abs(r - np.median(inl)) <= OUTLIER_Z * sigma
        if kept is not None and np.array_equal(new, kept):
            break
        kept = new
        p = _solve(spec, p, kept, robust=False)
    return p, kept


def _second_mode(spec: _Spec, p: np.ndarray, kept: np.ndarray):
    """Step 4: (omega2, decay2, cos2, sin2) of a residual peak that stands out, else None."""
    tau = spec.tau[kept]
    r = spec.y[kept] - spec.model(p, tau)
    grid, power = _periodogram(tau, r)
    if grid is None:
        return None
    resolution = 2.0 * math.pi / tau[-1]
    near = np.zeros(len(grid), dtype=bool)
    for k in (1, 2, 3):  # the first mode, and what a slightly wrong law leaves at its harmonics
        near |= np.abs(grid - k * p[0]) < 4.0 * resolution
    power = np.where(near, 0.0, power)
    j = int(np.argmax(power))
    # the local noise floor: an octave either side, without the peak's own lobe and the first mode's
    band = (grid > 0.5 * grid[j]) & (grid < 2.0 * grid[j]) & ~near & (np.abs(grid - grid[j]) > 3.0 * resolution)
    if not band.any() or power[j] < SECOND_MODE_POWER * float(np.median(power[band])):
        return None
    w2, a2, c2, s2, _, _ = _damped_sinusoid(tau, r, grid[j])
    return np.array([abs(w2), a2, c2, s2 * np.sign(w2)])


def _result(spec: _Spec, p: np.ndarray, kept: np.ndarray, t: np.ndarray, y: np.ndarray) -> OscillationFit:
    r_all = spec.model(p, spec.tau) - spec.y
    r = r_all[kept]
    swing = spec.model(p, spec.tau[kept]) - p[5] - p[6] * spec.tau[kept]
    rms = math.sqrt(float(np.mean(r**2)))
    snr = math.sqrt(float(np.mean(swing**2))) / max(rms, 1e-300)
    if snr < MIN_SNR:
        raise ValueError(f"no oscillation stands out of the noise (fitted swing / residual RMS = {snr:.2g} "
                         f"< {MIN_SNR:g})")
    cov, cov_white, block = _covariance(spec, p, kept, r)
    amplitude = _amplitudes(spec, p)
    if spec.law.kind == "series" and spec.kind != "proportional" and amplitude is not None:
        # model error: the series law is not fitted (over a coupled mode the waveform's harmonics would
        # set it wrongly); its coefficient's uncertainty moves omega by law_sigma s <A^2>
        mean_a2 = 0.5 * (amplitude[0] ** 2 + amplitude[1] ** 2)
        cov[0, 0] += (p[0] * spec.law_sigma * abs(spec.law.s) * mean_a2) ** 2
    std = np.sqrt(np.diag(cov))
    omega = p[0]
    n = spec.names
    excess, excess_std = (p[n.index("excess")], std[n.index("excess")]) if "excess" in n else (0.0, 0.0)
    second = None
    if "omega2" in n:
        j = n.index("omega2")
        second = (2.0 * math.pi / p[j], math.hypot(p[j + 2], p[j + 3]), p[j + 1])
    return OscillationFit(
        period=2.0 * math.pi / omega,
        period_std=2.0 * math.pi * std[0] / omega**2,
        period_std_white=2.0 * math.pi * math.sqrt(cov_white[0, 0]) / omega**2,
        zeta=p[1], zeta_std=std[1], quadratic=p[2], quadratic_std=std[2],
        amplitude_coefficient=spec.law.coefficient(omega) + excess, amplitude_coefficient_std=excess_std,
        law=spec.law.kind if spec.kind != "proportional" or spec.law.kind == "linear" else "series (scale fitted)",
        amplitude=amplitude,
        offset=p[5], drift=p[6], rms=rms,
        outliers=t[~kept], second_mode=second, block=block,
        names=tuple(n), parameters=p, covariance=cov, samples=int(kept.sum()),
        t=t, y=y, fitted=spec.model(p, spec.tau), first_mode=spec.model(p, spec.tau, first_only=True), kept=kept,
    )


def _covariance(spec: _Spec, p: np.ndarray, kept: np.ndarray, r: np.ndarray):
    """(block sandwich covariance, white-noise covariance, block length): module docstring."""
    sol = least_squares(lambda q: _residual(spec, q, kept), p, x_scale="jac", max_nfev=1)
    jac = sol.jac
    n, k = len(r), len(p)
    u, sv, vt = np.linalg.svd(jac, full_matrices=False)
    keep = sv > sv[0] * 1e-12
    bread = (vt[keep].T / sv[keep] ** 2) @ vt[keep]
    variance = float(r @ r) / max(n - k, 1)
    white = bread * variance
    block = _block_length(r)
    scores = jac[:n] * r[:, None]
    blocks = np.add.reduceat(scores, np.arange(0, n, block), axis=0)
    meat = blocks.T @ blocks * (len(blocks) / max(len(blocks) - 1, 1)) * (n / max(n - k, 1))
    if spec.prior_std > 0.0:  # the prior row: its own variance, noise^2 by construction
        meat += np.outer(jac[n], jac[n]) * spec.noise**2
    return bread @ meat @ bread, white, block


def _block_length(r: np.ndarray) -> int:
    """:data:`BLOCK_TAUS` integrated autocorrelation times of ``r`` (initial positive sequence),
    at most n / :data:`MIN_BLOCKS` samples."""
    n = len(r)
    x = r - r.mean()
    f = np.fft.rfft(x, 2 * n)
    acf = np.fft.irfft(f * np.conj(f))[:n]
    acf = acf / acf[0]
    below = np.flatnonzero(acf < 0.0)
    stop = int(below[0]) if len(below) else n
    tau_int = 1.0 + 2.0 * float(acf[1:stop].sum())
    return int(min(max(1, math.ceil(BLOCK_TAUS * tau_int)) if tau_int > 1.5 else 1, max(1, n // MIN_BLOCKS)))


def _amplitudes(spec: _Spec, p: np.ndarray) -> tuple[float, float] | None:
    """Peak |theta| (rad) of the model in its first and last cycle; None where the scale is unknown."""
    scale = 1.0
    if spec.kind == "proportional":
        gain = p[spec.index("gain")] if "gain" in spec.names else 0.0
        if gain <= 0.0:
            return None
        scale = math.sqrt(gain)
    period = 2.0 * math.pi / p[0]
    tau = np.arange(0.0, spec.tau[-1] + spec.step, spec.step / 4.0)
    theta = spec.model(p, tau, first_only=True, rate_out=False)
    head, tail = tau <= period, tau >= tau[-1] - period
    return float(scale * np.abs(theta[head]).max()), float(scale * np.abs(theta[tail]).max())


def _detrended(tau: np.ndarray, y: np.ndarray) -> np.ndarray:
    """y minus its least-squares line, so that drift does not leak into the low frequencies."""
    return y - np.polyval(np.polyfit(tau, y, 1), tau)


def _periodogram(tau: np.ndarray, y: np.ndarray):
    """(grid, power) of the detrended signal on half the record's resolution, or (None, None)."""
    span = tau[-1]
    resolution = 2.0 * math.pi / span
    stride = max(1, -(-len(tau) // _PERIODOGRAM_SAMPLES))
    x, v = tau[::stride], _detrended(tau, y)[::stride]
    nyquist = math.pi * (len(x) - 1) / (x[-1] - x[0])
    grid = np.arange(MIN_CYCLES * resolution, nyquist, 0.5 * resolution)
    if len(grid) < 3:
        return None, None
    return grid, lombscargle(x, v, grid, floating_mean=True)


def _periodogram_peak(tau: np.ndarray, y: np.ndarray) -> float:
    """Angular frequency (rad/s) of the Lomb-Scargle peak of the detrended signal.

    The cost is samples x frequencies, so the search uses at most :data:`_PERIODOGRAM_SAMPLES`
    evenly strided samples on a grid of half the record's resolution 2 pi / span, fine enough to
    land in the peak's main lobe; a grid of 1/20 of the resolution across that lobe and a parabola
    through its top then locate the peak.
    """
    grid, power = _periodogram(tau, y)
    if grid is None:
        raise ValueError(f"the record is too short or too sparse to hold {MIN_CYCLES:g} cycles")
    k = int(np.argmax(power))
    if k == 0 or k == len(grid) - 1:
        raise ValueError(f"no oscillation peak inside {grid[0]:.4g}..{grid[-1]:.4g} rad/s: fewer than "
                         f"{MIN_CYCLES:g} cycles, or undersampled")
    resolution = 2.0 * math.pi / tau[-1]
    stride = max(1, -(-len(tau) // _PERIODOGRAM_SAMPLES))
    fine = grid[k] + np.linspace(-0.5, 0.5, 21) * resolution
    fpower = lombscargle(tau[::stride], _detrended(tau, y)[::stride], fine, floating_mean=True)
    j = min(max(int(np.argmax(fpower)), 1), len(fine) - 2)
    p0, p1, p2 = fpower[j - 1 : j + 2]
    denom = p0 - 2.0 * p1 + p2
    return float(fine[j] + (0.5 * (p0 - p2) / denom * (fine[1] - fine[0]) if denom != 0.0 else 0.0))


def _damped_sinusoid(tau: np.ndarray, y: np.ndarray, omega_d: float) -> np.ndarray:
    """(omega_d, alpha, c, s, offset, drift) of y = offset + drift tau + e^(-alpha tau)(c cos + s sin),
    soft-L1 so that a glitch cannot pull the start; from the linear fit at ``omega_d`` with alpha = 0."""
    basis = np.column_stack([np.cos(omega_d * tau), np.sin(omega_d * tau), np.ones_like(tau), tau])
    c, s, offset, drift = np.linalg.lstsq(basis, y, rcond=None)[0]
    r0 = basis @ np.array([c, s, offset, drift]) - y
    scale = 3.0 * max(1.4826 * float(np.median(np.abs(r0 - np.median(r0)))), 1e-12 * (np.ptp(y) or 1.0))

    def residual(p):
        w, a, cc, ss, off, dr = p
        return off + dr * tau + np.exp(-a * tau) * (cc * np.cos(w * tau) + ss * np.sin(w * tau)) - y

    return least_squares(residual, [omega_d, 0.0, c, s, offset, drift], x_scale="jac", loss="soft_l1",
                         f_scale=scale).x


@njit(cache=True)
def _acceleration(theta, rate, omega, zeta, quadratic, exact, rho, lam, kappa, kappa5):
    w2 = omega * omega
    damping = 2.0 * zeta * omega * rate + quadratic * abs(rate) * rate
    if exact:
        half, co = math.sin(0.5 * theta), math.cos(0.5 * theta)
        r = math.sqrt(max(1.0 - rho * half * half, 1e-12))
        u = 2.0 * half * co / r  # sin(theta) / r
        v = (1.0 - 2.0 * half * half) / r + 0.25 * rho * u * u / r  # cos(theta) / r + ...
        restoring = w2 * u * (1.0 + lam * v * rate * rate) / (1.0 + lam * w2 * u * u) + w2 * kappa * theta**3
    else:
        t2 = theta * theta
        restoring = w2 * theta * (1.0 + kappa * t2 + kappa5 * t2 * t2)
    return -damping - restoring


@njit(cache=True)
def _response(p, exact, rho, lam, kappa, kappa5, tau, h, rate_out):
    """The model signal offset + drift tau + theta (or theta') at the sample times ``tau`` (tau[0] = 0)
    with RK4 steps of ``h``; p = (omega, zeta, quadratic, theta0, rate0, offset, drift, ...)."""
    omega, zeta, quadratic, theta, rate, offset, drift = p[0], p[1], p[2], p[3], p[4], p[5], p[6]
    out = np.empty(tau.shape[0])
    acc = _acceleration(theta, rate, omega, zeta, quadratic, exact, rho, lam, kappa, kappa5)
    k, i = 0, 0
    while k < tau.shape[0]:
        r2 = rate + 0.5 * h * acc
        a2 = _acceleration(theta + 0.5 * h * rate, r2, omega, zeta, quadratic, exact, rho, lam, kappa, kappa5)
        r3 = rate + 0.5 * h * a2
        a3 = _acceleration(theta + 0.5 * h * r2, r3, omega, zeta, quadratic, exact, rho, lam, kappa, kappa5)
        r4 = rate + h * a3
        a4 = _acceleration(theta + h * r3, r4, omega, zeta, quadratic, exact, rho, lam, kappa, kappa5)
        theta1 = theta + h / 6.0 * (rate + 2.0 * r2 + 2.0 * r3 + r4)
        rate1 = rate + h / 6.0 * (acc + 2.0 * a2 + 2.0 * a3 + a4)
        acc1 = _acceleration(theta1, rate1, omega, zeta, quadratic, exact, rho, lam, kappa, kappa5)
        if not (abs(theta1) < 1e6 and abs(rate1) < 1e12):  # a diverging trial step: stop, flat
            while k < tau.shape[0]:
                out[k] = offset + drift * tau[k] + (rate if rate_out else theta)
                k += 1
            break
        t0 = i * h
        while k < tau.shape[0] and tau[k] <= t0 + h:
            u = (tau[k] - t0) / h
            h00, h10 = (1.0 + 2.0 * u) * (1.0 - u) ** 2, u * (1.0 - u) ** 2
            h01, h11 = u * u * (3.0 - 2.0 * u), u * u * (u - 1.0)
            if rate_out:
                x = h00 * rate + h10 * h * acc + h01 * rate1 + h11 * h * acc1
            else:
                x = h00 * theta + h10 * h * rate + h01 * theta1 + h11 * h * rate1
            out[k] = offset + drift * tau[k] + x
            k += 1
        theta, rate, acc = theta1, rate1, acc1
        i += 1
    return out


def cycles(fit: OscillationFit) -> tuple[np.ndarray, np.ndarray]:
    """(per-cycle period s, amplitude) of the record itself, for plots: rising crossings of the
    signal cleaned of the fitted offset, drift and second mode, and the peak |signal| in each cycle."""
    t = fit.t[fit.kept]
    clean = (fit.y - fit.fitted + fit.first_mode)[fit.kept]
    times = crossing_times(t, clean, 0.0)
    periods = np.diff(times)
    amps = np.array([np.abs(clean[(t >= a) & (t < b)]).max() for a, b in zip(times[:-1], times[1:])])
    return periods, amps
