"""Work bounds of the record fit (:mod:`.fit`): it never runs without end, whatever the record.

The fit cuts a record into windows one local period long, the local frequency being what the last
pass's amplitude law gives (:meth:`.phase_fit.PhaseFit.local`). A law fitted to a record it cannot describe
(seconds read as milliseconds: the exact law's lam omega^2 a million times a real rig's; a swing near
the law's limit, where T(A) runs off) can give a frequency that is zero, negative or not finite, and a
loop stepping by it never ends. :func:`window_centres` holds every local frequency to a band about the
record's own (its periodogram's peak, :data:`BAND` either way), so that the windows are at most
``BAND`` times the record's cycles, and refuses the record (:class:`LawBandError`) where the law leaves
the band: no rig's law changes its frequency by that much within one record.

A dense record (a 2500 Hz gyro over 400 cycles, a 25 kHz logger: 2e6 rows) holds far more samples a
cycle than the fit's windows need (seven harmonics: 24). :func:`binned` averages it in bins of whole
sample steps down to :data:`SAMPLES_PER_CYCLE` (the fit's work then grows with the cycles, not the rows,
and the bins' noise falls with their size, so the moment loses nothing), and the fit says so
(``OscillationFit.binned``). And every fit has a wall-time budget (:class:`Deadline`, identify's
``--max-seconds``).
"""

from __future__ import annotations

import math
import time

import numpy as np

BAND = 4.0  # a local frequency within this factor of the record's own (a decay from near the limit: < 2)
# A bin's mean is a boxcar filter: the fundamental loses (omega h)^2 / 24 of itself (4e-5 at 200 a
# cycle, corrected below), the seventh harmonic 2 %, a second mode at 5 times the frequency 1 % of a
# swing the fit does not use: the record's bandwidth is kept.
SAMPLES_PER_CYCLE = 200


class WorkSpent(RuntimeError):
    """A fit spent its wall-time budget (:class:`Deadline`)."""


class Deadline:
    """A wall-time budget of ``seconds`` (None: unbounded) from its making; :meth:`check` raises
    :class:`WorkSpent` once it is spent."""

    def __init__(self, seconds: float | None = None):
        self.seconds = seconds
        self._end = None if seconds is None else time.monotonic() + seconds

    def check(self) -> None:
        if self._end is not None and time.monotonic() > self._end:
            raise WorkSpent(f"the fit's wall-time budget of {self.seconds:g} s is spent")


def binned(tau: np.ndarray, y: np.ndarray, usable: np.ndarray, omega: float, step: float):
    """(times, values, k): the usable samples of a record sampled every ``step`` s whose frequency is
    ``omega`` (rad/s) averaged in bins k steps wide on a uniform grid, k the most that leaves
    :data:`SAMPLES_PER_CYCLE` bins a cycle (1: the record as it is). A bin at a gap holding under half
    its samples is left out (a lost frame's gap stays a gap); the values are scaled by the bin's
    attenuation of the fundamental, sin(k x) / (k sin x) with x = omega step / 2, about their median."""
    k = int(2.0 * math.pi / (omega * step) // SAMPLES_PER_CYCLE)
    if k < 2:
        return tau, y, 1
    which = np.floor(tau[usable] / (k * step) + 0.5 / k).astype(np.int64)
    count = np.bincount(which)
    full = count >= 0.5 * k
    t_bin = np.bincount(which, tau[usable])[full] / count[full]
    y_bin = np.bincount(which, y[usable])[full] / count[full]
    x = 0.5 * omega * step
    gain = math.sin(k * x) / (k * math.sin(x))
    middle = float(np.median(y_bin))
    return t_bin, middle + (y_bin - middle) / gain, k


class LawBandError(ValueError):
    """The amplitude law gives a local frequency (rad/s, ``local``) outside :data:`BAND` of the
    record's own (``omega``) at ``time`` (s from the first sample)."""

    def __init__(self, local: float, omega: float, time: float):
        super().__init__(f"the amplitude law fitted gives a frequency of {local:.4g} rad/s at {time:.4g} s, not within "
                         f"a factor {BAND:g} of the record's own {omega:.4g} rad/s (a period of "
                         f"{2.0 * math.pi / omega:.4g} s)")
        self.local, self.omega, self.time = local, omega, time


def window_centres(span: float, omega: float, local) -> np.ndarray:
    """The centres (s) of windows one local period long over a record ``span`` s long whose own
    frequency is ``omega`` (rad/s): the first window starts at the first sample, each next centre one
    local period (``local(times)[0]``, rad/s) on, while three quarters of a window fit in the record.
    Raises :class:`LawBandError` where a local frequency leaves the band (module docstring)."""

    def at(time: float) -> float:
        w = float(local(np.array([time]))[0][0])
        if not omega / BAND <= w <= omega * BAND:  # nan fails too
            raise LawBandError(w, omega, time)
        return w

    centres = [math.pi / at(0.0)]
    most = math.ceil(BAND * omega * span / (2.0 * math.pi)) + 2  # what the band allows: a guard, never reached
    while len(centres) < most:
        w = at(centres[-1])
        nxt = centres[-1] + 2.0 * math.pi / w
        if nxt + 0.5 * math.pi / w > span:  # a window needs three quarters of its cycle
            break
        centres.append(nxt)
    return np.array(centres)
