"""The Cramér-Rao bound of omega0 for the whole-record fit (:mod:`.whole`) and the noise its residual shows.

No unbiased estimator of the whole fit's model can state a smaller variance of omega0 than the bound's,
the inverse of the Fisher information of the samples used. The stated sigma is compared with it
(``sigma / crb``): near 1, the fit spends the record's information as well as can be done; far above
it, the sigma is either honest about something the bound leaves out (the amplitude law's doubt, the
noise's model) or wastes information.

The Jacobian: every fitted parameter's column, nonlinear (phase, omega0, envelope, second mode) and
linear (offset, drift, harmonics, second mode's amplitudes). The whole fit's nonlinear columns are those
of its variable-projection residual; they span the same space as the model's own derivatives together
with the linear columns (they differ by combinations of the linear columns), so the omega0 block of the
inverse information is the same for any noise covariance.

The noise: the residual is tested for whiteness (Ljung-Box over :data:`LAGS` lags, white unless its
p-value is below :data:`P_WHITE`).

* White: the information is J^T J / sigma_w^2, sigma_w^2 = r^T r / (n - k): the bound is the white-noise
  covariance the fit already reports.
* Coloured: an autoregressive model of the residual (Yule-Walker, its order by Akaike's criterion up to
  :data:`MAX_ORDER`) gives its spectrum S(f) = sigma_e^2 dt / |A(f)|^2. Whittle's (generalised least
  squares) information sum_f J(f)^* J(f) / S(f) equals the sum of squares of the Jacobian's columns
  filtered by the whitening filter A, divided by sigma_e^2; it is computed so, in the time domain
  (``lfilter``), so that the samples next to a gap can be left out.

Sampling: the samples are placed on a grid of the record's median step (rounded to the nearest grid
point: timestamp jitter well under half a step is assumed and ignored). A filtered sample whose filter
reaches back over a missing grid point is left out (the conditional likelihood of each run between gaps,
first ``order`` samples dropped: slightly conservative; the noise's correlation across a gap is ignored).
Samples that do not fall on distinct grid points (uneven sampling) are taken in their order, as if
evenly spaced (a noise correlated per sample, not per second).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.linalg import solve_toeplitz
from scipy.signal import lfilter
from scipy.stats import chi2

LAGS = 20  # Ljung-Box lags: a few correlation times of tracker noise at 60-240 fps
P_WHITE = 0.01  # below it, the residual is judged coloured
MAX_ORDER = 30  # the autoregressive model's largest order (colour times up to ~0.1 s at 240 fps)


@dataclass(frozen=True)
class Bound:
    """The bound's variance of the parameter asked for, the noise judged ('white' or 'coloured'), the
    Ljung-Box p-value of whiteness, and the autoregressive order used (0: white)."""

    variance: float
    noise: str
    p_white: float
    order: int


def cramer_rao(tau: np.ndarray, r: np.ndarray, jac: np.ndarray, step: float, index: int = 1,
               held: np.ndarray | None = None, prior_sd: np.ndarray | None = None) -> Bound:
    """The Cramér-Rao bound of parameter ``index`` of a least-squares fit with Jacobian ``jac`` (n x k)
    and residual ``r`` at times ``tau`` (s), sampled at a median ``step`` (s) (module docstring).

    ``held`` (n x m): the columns of parameters the fit held at an estimate made elsewhere (the amplitude
    law's), whose doubt its variance carries; they join the information, with their priors' precision
    1 / ``prior_sd``^2 (Van Trees' Bayesian bound). The variance returned is the record's part of it,
    (V F V)[index, index], V = (F + P)^-1 with F the record's information and P the priors' (the split of
    the statistical sigma from the law's prior part that :mod:`.fit` makes)."""
    n, k = jac.shape
    grid = _grid(tau, step)
    mask = np.zeros(grid[-1] + 1, dtype=bool)
    mask[grid] = True
    p_white = _ljung_box(r, grid, mask, min(LAGS, max(n // 10, 1)))
    full_jac = jac if held is None or held.shape[1] == 0 else np.column_stack([jac, held])
    precision = np.zeros(full_jac.shape[1])
    if full_jac.shape[1] > k:
        precision[k:] = 1.0 / np.asarray(prior_sd, dtype=float) ** 2
    if p_white >= P_WHITE:
        info = full_jac.T @ full_jac / (float(r @ r) / max(n - k, 1))
        return Bound(_record_part(info, precision, index), "white", p_white, 0)
    a, innovation, order = _autoregression(r, grid, mask, n, k)
    full = np.zeros((len(mask), full_jac.shape[1]))
    full[grid] = full_jac
    white = lfilter(a, [1.0], full, axis=0)  # the whitening filter A on each column
    whole_past = np.convolve(~mask, np.ones(order + 1), mode="full")[:len(mask)] == 0
    whole_past[:order] = False  # the record's first samples: their past is not in it
    info = white[whole_past].T @ white[whole_past] / innovation
    return Bound(_record_part(info, precision, index), "coloured", p_white, order)


def _grid(tau: np.ndarray, step: float) -> np.ndarray:
    """Each sample's grid point at the median step, or the samples' order where two share one."""
    grid = np.rint((tau - tau[0]) / step).astype(int)
    return grid if np.all(np.diff(grid) > 0) else np.arange(len(tau))


def _autocovariance(r: np.ndarray, grid: np.ndarray, mask: np.ndarray, lags: int) -> np.ndarray:
    """Lags 0..``lags`` of the residual's autocovariance, each from the pairs observed at that lag, tapered
    by (1 - lag / N) as the biased estimator is (which keeps a gapless record's Toeplitz matrix positive)."""
    size = 1 << int(math.ceil(math.log2(2 * len(mask))))
    x = np.zeros(len(mask))
    x[grid] = r
    sums = np.fft.irfft(np.abs(np.fft.rfft(x, size)) ** 2, size)[:lags + 1]
    pairs = np.fft.irfft(np.abs(np.fft.rfft(mask.astype(float), size)) ** 2, size)[:lags + 1]
    pairs = np.maximum(np.rint(pairs), 1.0)
    return sums / pairs * (1.0 - np.arange(lags + 1) / len(mask))


def _ljung_box(r: np.ndarray, grid: np.ndarray, mask: np.ndarray, lags: int) -> float:
    """The p-value of Ljung-Box's test that the residual is white over ``lags`` lags."""
    n = len(r)
    c = _autocovariance(r, grid, mask, lags)
    rho = c[1:] / max(c[0], 1e-300)
    q = n * (n + 2) * float(np.sum(rho**2 / (n - np.arange(1, lags + 1))))
    return float(chi2.sf(q, lags))


def _autoregression(r, grid, mask, n, k):
    """The whitening filter A = [1, -a_1, .., -a_p] of the residual's autoregressive model, its
    innovation variance (scaled by n / (n - k) for the fitted parameters) and its order p, chosen by
    Akaike's criterion n ln sigma_p^2 + 2 p among p = 1 .. :data:`MAX_ORDER` (at least 1: the residual
    was judged coloured)."""
    top = int(min(MAX_ORDER, max(n // 20, 1)))
    c = _autocovariance(r, grid, mask, top)
    best = None
    for p in range(1, top + 1):
        try:
            coef = solve_toeplitz(c[:p], c[1:p + 1])
        except np.linalg.LinAlgError:
            break
        innovation = float(c[0] - coef @ c[1:p + 1])
        if innovation <= 0.0:
            break
        aic = n * math.log(innovation) + 2.0 * p
        if best is None or aic < best[0]:
            best = (aic, coef, innovation, p)
    if best is None:  # no stable model: white
        return np.array([1.0]), float(c[0]) * n / max(n - k, 1), 0
    _, coef, innovation, p = best
    return np.concatenate([[1.0], -coef]), innovation * n / max(n - k, 1), p


def _record_part(info: np.ndarray, precision: np.ndarray, index: int) -> float:
    """(V F V)[index, index], V = (F + diag(precision))^-1, equilibrated before a pseudo-inverse (a
    parameter the record does not determine, e.g. a second mode's that has died away, takes no
    information from the others)."""
    total = info + np.diag(precision)
    scale = 1.0 / np.sqrt(np.maximum(np.diag(total), 1e-300))
    v = scale[:, None] * np.linalg.pinv(scale[:, None] * total * scale[None, :]) * scale[None, :]
    return float((v @ info @ v)[index, index])
