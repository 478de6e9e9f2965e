"""Period of a measured torsion signal: a damped-oscillation model fitted by nonlinear least squares.

The signal is an angle (video tracker) or an angular rate (gyro), sampled at increasing, possibly
uneven times, with noise, an offset and a linear drift. Its model is the 1-DOF oscillator of Jardin &
Mueller (AIAA 2007-6822) with viscous and quadratic (aerodynamic) damping,

    theta'' + 2 zeta omega theta' + c |theta'| theta' + omega^2 (theta + kappa theta^3) = 0,
    signal(t) = offset + drift (t - t0) + (theta or theta')(t),

integrated by RK4 on a fixed grid and read at the sample times by cubic Hermite interpolation.

Why this stiffness law: the bifilar restoring torque is not omega^2 sin(theta) (a pendulum's) but
the lift slope of :mod:`bifilar.lagrange`, and its inertia varies with theta; what the period sees
of both is T(a) = T0 (1 + s a^2 + O(a^4)). The cubic term with kappa = -8 s / 3 gives the same
period-amplitude law, so that omega is the small-amplitude undamped frequency that (5.2.17-18)
want even while the amplitude decays. ``s`` comes from the rig
(:func:`bifilar.lagrange.period_amplitude_coefficient`) and is not fitted: over a decaying record
it is nearly collinear with omega. ``s = 0`` is the linear oscillator.

The initial guess: omega from a Lomb-Scargle periodogram (uneven sampling), then a closed-form fit of
an exponentially damped sinusoid, exact for viscous damping, from which the ODE fit starts. The
standard deviations assume white noise: they are the Jacobian covariance scaled by the residual
variance. Coloured noise (a smoothing tracker) makes them optimistic.
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numba import njit
from scipy.optimize import least_squares
from scipy.signal import lombscargle

from bifilar.rig import RigError

KINDS = ("angle", "rate")
PARAMETERS = ("omega", "zeta", "quadratic", "theta0", "rate0", "offset", "drift")
MIN_SAMPLES = 20  # seven parameters, and enough residual degrees of freedom to estimate the noise
MIN_CYCLES = 2.0  # fewer cycles in the record and the periodogram cannot locate the peak
MIN_SNR = 3.0  # a swing whose RMS is 3x the residual is unmistakable: noise fits reach ~0.2-0.5
# RK4 steps per period: its relative frequency error (omega h)^4 / 120 is then 3e-9, far below the
# statistical error of any real record, and cubic Hermite interpolation is of the same order.
_STEPS_PER_PERIOD = 256
_PERIODOGRAM_SAMPLES = 512  # at most this many samples in the periodogram (the initial guess only)


@dataclass(frozen=True)
class OscillationFit:
    """A fitted damped oscillation; parameters in the order of :data:`PARAMETERS`.

    ``period`` is 2 pi / omega (s), the undamped small-amplitude period; ``zeta`` the viscous damping
    ratio; ``quadratic`` c (1/rad); ``offset`` and ``drift`` in signal units and per second; ``rms``
    the residual root mean square in signal units.
    """

    period: float
    period_std: float
    zeta: float
    zeta_std: float
    quadratic: float
    quadratic_std: float
    offset: float
    drift: float
    rms: float
    parameters: np.ndarray
    covariance: np.ndarray
    samples: int


def read_csv(path: str | Path, value: str, time: str = "t") -> tuple[np.ndarray, np.ndarray]:
    """Times (s) and values of column ``value`` from a CSV file with a header row.

    Raises :class:`~bifilar.rig.RigError` (file, column, problem) for an unreadable file, a missing
    column, a short row, a non-numeric or non-finite entry, a time that does not increase, or fewer
    than :data:`MIN_SAMPLES` rows.
    """
    src = str(path)
    try:
        with open(path, newline="") as handle:
            rows = list(csv.reader(handle))
    except (OSError, UnicodeDecodeError) as exc:
        raise RigError(src, "file", f"cannot read ({getattr(exc, 'strerror', None) or exc})") from None
    except csv.Error as exc:
        raise RigError(src, "file", f"not valid CSV ({exc})") from None
    if not rows:
        raise RigError(src, "header", "empty file: expected a header row naming the columns")
    header = [name.strip() for name in rows[0]]
    for column in (time, value):
        if column not in header:
            raise RigError(src, column, f"missing column (columns: {', '.join(header)})")
    i_t, i_v = header.index(time), header.index(value)
    t, y = [], []
    for line, row in enumerate(rows[1:], start=2):
        if not any(cell.strip() for cell in row):
            continue  # blank line
        if len(row) != len(header):
            raise RigError(src, f"line {line}", f"has {len(row)} fields, the header has {len(header)}")
        t.append(_cell(row[i_t], src, time, line))
        y.append(_cell(row[i_v], src, value, line))
        if len(t) > 1 and t[-1] <= t[-2]:
            raise RigError(src, time, f"line {line}: time {t[-1]:g} does not increase (previous {t[-2]:g})")
    if len(t) < MIN_SAMPLES:
        raise RigError(src, value, f"{len(t)} samples; at least {MIN_SAMPLES} are needed")
    return np.array(t), np.array(y)


def _cell(text: str, src: str, column: str, line: int) -> float:
    try:
        x = float(text)
    except ValueError:
        raise RigError(src, column, f"line {line}: not a number: {text.strip()!r}") from None
    if not math.isfinite(x):
        raise RigError(src, column, f"line {line}: not finite: {text.strip()!r}")
    return x


def fit_csv(path: str | Path, value: str, kind: str, time: str = "t", amplitude_coefficient: float = 0.0):
    """:func:`fit_oscillation` of a CSV column read by :func:`read_csv`."""
    t, y = read_csv(path, value, time)
    return fit_oscillation(t, y, kind, amplitude_coefficient)


def fit_oscillation(t, y, kind: str, amplitude_coefficient: float = 0.0) -> OscillationFit:
    """Fit the module's model to samples ``y`` (rad or rad/s, per ``kind``) at increasing times ``t``.

    ``amplitude_coefficient`` is s in T(a) = T0 (1 + s a^2) (1/rad^2); see the module docstring.
    """
    if kind not in KINDS:
        raise ValueError(f"kind must be one of {KINDS}, got {kind!r}")
    t, y = np.asarray(t, dtype=float), np.asarray(y, dtype=float)
    if t.ndim != 1 or t.shape != y.shape or len(t) < MIN_SAMPLES:
        raise ValueError(f"need two 1-D arrays of equal length >= {MIN_SAMPLES}, got shapes {t.shape} and {y.shape}")
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(y)) and np.all(np.diff(t) > 0.0)):
        raise ValueError("times must increase and every sample be finite")
    tau = t - t[0]
    rate_out = kind == "rate"
    kappa = -8.0 / 3.0 * amplitude_coefficient
    omega_d, alpha, c, s, offset, drift = _damped_sinusoid(tau, y, _periodogram_peak(tau, y))
    cycles = abs(omega_d) * tau[-1] / (2.0 * math.pi)
    if cycles < MIN_CYCLES:
        raise ValueError(f"the record holds {cycles:.3g} cycles; at least {MIN_CYCLES:g} are needed")

    omega = math.hypot(omega_d, alpha)  # omega_d^2 = omega^2 - alpha^2 for viscous damping
    if rate_out:  # theta' = e^(-alpha tau) (c cos + s sin), so theta'' (0) = -alpha c + omega_d s
        theta0, rate0 = -(alpha * c + omega_d * s) / omega**2, c
    else:
        theta0, rate0 = c, -alpha * c + omega_d * s
    x0 = np.array([omega, alpha / omega, 0.0, theta0, rate0, offset, drift])
    step = 2.0 * math.pi / (omega * _STEPS_PER_PERIOD)  # fixed, so the model is smooth in omega

    def residual(p):
        return _response(p, kappa, tau, step, rate_out) - y

    sol = least_squares(residual, x0, x_scale="jac", method="trf", xtol=1e-12, ftol=1e-12, gtol=1e-12)
    # A record of noise alone also yields a "best" period: refuse one whose oscillation does not stand
    # out of the residual (the fitted swing's RMS below MIN_SNR times the residual's).
    swing = sol.fun + y - sol.x[5] - sol.x[6] * tau
    snr = float(np.sqrt(np.mean(swing**2)) / max(np.sqrt(np.mean(sol.fun**2)), 1e-300))
    if snr < MIN_SNR:
        raise ValueError(f"no oscillation stands out of the noise (fitted swing / residual RMS = {snr:.2g} "
                         f"< {MIN_SNR:g})")
    dof = len(y) - len(x0)
    variance = 2.0 * sol.cost / dof
    _, sv, vt = np.linalg.svd(sol.jac, full_matrices=False)
    cov = (vt.T / sv**2) @ vt * variance
    std = np.sqrt(np.diag(cov))
    omega = sol.x[0]
    return OscillationFit(
        period=2.0 * math.pi / omega,
        period_std=2.0 * math.pi * std[0] / omega**2,
        zeta=sol.x[1],
        zeta_std=std[1],
        quadratic=sol.x[2],
        quadratic_std=std[2],
        offset=sol.x[5],
        drift=sol.x[6],
        rms=math.sqrt(2.0 * sol.cost / len(y)),
        parameters=sol.x,
        covariance=cov,
        samples=len(y),
    )


def _detrended(tau: np.ndarray, y: np.ndarray) -> np.ndarray:
    """y minus its least-squares line, so that drift does not leak into the low frequencies."""
    return y - np.polyval(np.polyfit(tau, y, 1), tau)


def _periodogram_peak(tau: np.ndarray, y: np.ndarray) -> float:
    """Angular frequency (rad/s) of the Lomb-Scargle peak of the detrended signal.

    The cost is samples x frequencies, so the search uses at most :data:`_PERIODOGRAM_SAMPLES`
    evenly strided samples (signals of fewer than half as many cycles are resolved) on a grid of
    half the record's resolution 2 pi / span, fine enough to land in the peak's main lobe; a grid of
    1/20 of the resolution across that lobe and a parabola through its top then locate the peak.
    """
    span = tau[-1]
    resolution = 2.0 * math.pi / span
    stride = max(1, -(-len(tau) // _PERIODOGRAM_SAMPLES))
    x, v = tau[::stride], _detrended(tau, y)[::stride]
    nyquist = math.pi * (len(x) - 1) / (x[-1] - x[0])  # of the mean sampling rate
    coarse = np.arange(MIN_CYCLES * resolution, nyquist, 0.5 * resolution)
    if len(coarse) < 3:
        raise ValueError(f"the record is too short or too sparse to hold {MIN_CYCLES:g} cycles")
    k = int(np.argmax(lombscargle(x, v, coarse, floating_mean=True)))
    if k == 0 or k == len(coarse) - 1:
        raise ValueError(f"no oscillation peak inside {coarse[0]:.4g}..{coarse[-1]:.4g} rad/s: fewer than "
                         f"{MIN_CYCLES:g} cycles, or undersampled")
    fine = coarse[k] + np.linspace(-0.5, 0.5, 21) * resolution
    power = lombscargle(x, v, fine, floating_mean=True)
    j = min(max(int(np.argmax(power)), 1), len(fine) - 2)
    p0, p1, p2 = power[j - 1 : j + 2]
    return float(fine[j] + 0.5 * (p0 - p2) / (p0 - 2.0 * p1 + p2) * (fine[1] - fine[0]))


def _damped_sinusoid(tau: np.ndarray, y: np.ndarray, omega_d: float) -> np.ndarray:
    """(omega_d, alpha, c, s, offset, drift) of y = offset + drift tau + e^(-alpha tau)(c cos + s sin).

    The start: the linear least-squares fit at the periodogram frequency with alpha = 0.
    """
    basis = np.column_stack([np.cos(omega_d * tau), np.sin(omega_d * tau), np.ones_like(tau), tau])
    c, s, offset, drift = np.linalg.lstsq(basis, y, rcond=None)[0]

    def residual(p):
        w, a, cc, ss, off, dr = p
        return off + dr * tau + np.exp(-a * tau) * (cc * np.cos(w * tau) + ss * np.sin(w * tau)) - y

    return least_squares(residual, [omega_d, 0.0, c, s, offset, drift], x_scale="jac").x


@njit(cache=True)
def _acceleration(theta, rate, omega, zeta, quadratic, kappa):
    return -2.0 * zeta * omega * rate - quadratic * abs(rate) * rate - omega**2 * theta * (1.0 + kappa * theta**2)


@njit(cache=True)
def _response(p, kappa, tau, h, rate_out):
    """The model signal at the sample times ``tau`` (tau[0] = 0) with RK4 steps of ``h``."""
    omega, zeta, quadratic, theta, rate, offset, drift = p[0], p[1], p[2], p[3], p[4], p[5], p[6]
    out = np.empty(tau.shape[0])
    acc = _acceleration(theta, rate, omega, zeta, quadratic, kappa)
    k, i = 0, 0
    while k < tau.shape[0]:
        r2 = rate + 0.5 * h * acc
        a2 = _acceleration(theta + 0.5 * h * rate, r2, omega, zeta, quadratic, kappa)
        r3 = rate + 0.5 * h * a2
        a3 = _acceleration(theta + 0.5 * h * r2, r3, omega, zeta, quadratic, kappa)
        r4 = rate + h * a3
        a4 = _acceleration(theta + h * r3, r4, omega, zeta, quadratic, kappa)
        theta1 = theta + h / 6.0 * (rate + 2.0 * r2 + 2.0 * r3 + r4)
        rate1 = rate + h / 6.0 * (acc + 2.0 * a2 + 2.0 * a3 + a4)
        acc1 = _acceleration(theta1, rate1, omega, zeta, quadratic, kappa)
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
