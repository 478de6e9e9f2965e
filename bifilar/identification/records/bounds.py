"""Work bounds of the record fit (:mod:`.fit`): it never runs without end, whatever the record.

The fit cuts a record into windows one local period long, the local frequency being what the last
pass's amplitude law gives (:meth:`.fit._Model.local`). A law fitted to a record it cannot describe
(seconds read as milliseconds: the exact law's lam omega^2 a million times a real rig's; a swing near
the law's limit, where T(A) runs off) can give a frequency that is zero, negative or not finite, and a
loop stepping by it never ends. :func:`window_centres` holds every local frequency to a band about the
record's own (its periodogram's peak, :data:`BAND` either way), so that the windows are at most
``BAND`` times the record's cycles, and refuses the record (:class:`LawBandError`) where the law leaves
the band: no rig's law changes its frequency by that much within one record.
"""

from __future__ import annotations

import math

import numpy as np

BAND = 4.0  # a local frequency within this factor of the record's own (a decay from near the limit: < 2)


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
