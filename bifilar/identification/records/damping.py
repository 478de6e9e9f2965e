"""The damping a record's decay shows, and what it does to the period.

The record fit (:mod:`.fit`) never models the damping in its cycles: each is measured on its own. But
damping lengthens the period at second order in itself, ~1e-5 of T0 for a hardly damped video record
released at 1 rad, as large as its statistical sigma, so the phase law (:mod:`.phase_law`) divides its
rate by that lengthening: :func:`damping_of` describes the decay of the cycles' amplitudes as linear,
quadratic and dry damping, :func:`damping_shift` integrates that description over a cycle from each
amplitude and reads the period off it.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from bifilar.jit import announce_compile


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
    grid, RK4 at h = 2 pi / 256 for at most three cycles: a swing that dry friction stops has no second
    crossing), the period from descending crossing to descending crossing, and the amplitude half way
    (the trough) it belongs to. The shift is right to RK4's phase error h^4 / 120 = 3e-9 of the period
    and ~1e-3 of itself; with dry friction, whose switch at the turning points a fixed step straddles,
    to a few % of itself (tests/test_record_fit.py, against DOP853 at rtol 1e-12). The integration is
    compiled (:func:`_cycle_from`): the same steps in numpy cost ~20 ms a call, a third of a record fit."""
    zeta, quad, dry = damping["linear"], damping["quadratic"], damping["dry"]
    amplitude = np.asarray(amplitude, dtype=float)
    if zeta == quad == dry == 0.0 or not len(amplitude):
        return np.zeros_like(amplitude)
    top = float(amplitude.max())
    a = np.linspace(0.5 * float(amplitude.min()), 1.05 * top, 16)
    announce_compile("the record fit's damping kernel", _cycle_from, seconds="2-5")
    crossings = np.full((2, len(a)), np.nan)
    trough = np.zeros(len(a))
    for i in range(len(a)):
        crossings[0, i], crossings[1, i], trough[i] = _cycle_from(a[i], zeta, quad, dry, 1e-4 * top)
    shift = (crossings[1] - crossings[0]) / (2.0 * math.pi) - 1.0
    ok = np.isfinite(shift) & (trough > 0.0)
    if ok.sum() < 2:
        return np.zeros_like(amplitude)
    order = np.argsort(trough[ok])
    return np.interp(amplitude, trough[ok][order], shift[ok][order])


_STEPS = 256  # RK4 steps per undamped period (2 pi)


@nb.njit(cache=True)
def _acceleration(th, v, zeta, quad, dry, eps):
    """theta'' of :func:`_cycle_from`'s oscillator (time in radians of the undamped period)."""
    return -th - 2.0 * zeta * v - quad * abs(v) * v - dry * math.tanh(v / eps)


@nb.njit(cache=True)
def _cycle_from(a, zeta, quad, dry, eps):
    """(first, second descending crossing, trough between) of theta'' + theta = -2 zeta theta' -
    c |theta'| theta' - m tanh(theta' / eps) released at rest from ``a``: :func:`damping_shift`'s RK4 at
    h = 2 pi / 256 for at most three cycles, a crossing interpolated linearly between steps (nan if
    none came), the trough the deepest step between the crossings."""
    h = 2.0 * math.pi / _STEPS
    th, v = a, 0.0
    first, trough = np.nan, 0.0
    for n in range(3 * _STEPS):
        k1x, k1v = v, _acceleration(th, v, zeta, quad, dry, eps)
        k2x = v + 0.5 * h * k1v
        k2v = _acceleration(th + 0.5 * h * k1x, k2x, zeta, quad, dry, eps)
        k3x = v + 0.5 * h * k2v
        k3v = _acceleration(th + 0.5 * h * k2x, k3x, zeta, quad, dry, eps)
        k4x = v + h * k3v
        k4v = _acceleration(th + h * k3x, k4x, zeta, quad, dry, eps)
        new = th + h / 6.0 * (k1x + 2 * k2x + 2 * k3x + k4x)
        new_v = v + h / 6.0 * (k1v + 2 * k2v + 2 * k3v + k4v)
        if th > 0.0 and new <= 0.0:
            at = n * h + h * th / (th - new)
            if np.isnan(first):
                first = at
            else:
                return first, at, trough
        elif not np.isnan(first):
            trough = max(trough, -new)
        th, v = new, new_v
    return first, np.nan, trough
