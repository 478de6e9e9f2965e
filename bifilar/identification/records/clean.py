"""What a tracker or a gyro adds to a record that is not the rig's motion, found and left out.

* Stuck values: a tracker that loses its target repeats the last value; every repeat after the first
  of a run of exactly equal samples is left out. A quantized record (an integer pixel tracker: fewer
  distinct values than half the samples) repeats values honestly near its turning points, and keeps them.
* Bad cycles: the fit measures each cycle on its own (:mod:`.cycles`); a cycle whose residual is far above
  the record's typical one (the tracker locking on at the start, or losing the target), whose samples do
  not cover it, or whose amplitude jumps away from its neighbours' is left out whole (:func:`mark`; one
  whose phase slips off the law: :meth:`.phase_law.Model.fit`).
* Glitches: single samples beyond :data:`OUTLIER_Z` robust standard deviations of the residual's second
  differences (:func:`glitches`).

Everything left out is reported (:class:`Rejected`): samples and the time spans they cover, with why.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.ndimage import median_filter

from .read import MIN_CYCLES

OUTLIER_Z = 6.0  # robust sigmas: a normal sample exceeds it with probability 2e-9 (none in 1e6 samples)
_QUANTIZED = 0.5  # distinct values / samples below this: a quantized record
_BAD_RMS = 3.0  # a cycle's residual RMS above this times the record's median: not the rig's motion
# ... and above this share of its own amplitude: a tracker that has not locked on writes values tens of
# per cent off the swing, where what a window's model leaves of a clean large swing is below 1 %
_LOCK_FLOOR = 0.02
_GLITCH_NEIGHBOURHOOD = 31  # samples (about half a cycle of a 60 fps video at 1 s): a glitch's scale
_JUMP = math.log(1.5)  # a cycle's amplitude this far (in ln) from its neighbours' median: a jump


def stuck(y: np.ndarray) -> np.ndarray:
    """Mask of the samples that repeat the previous one exactly (not for a quantized record)."""
    if len(np.unique(y)) < _QUANTIZED * len(y):
        return np.zeros(len(y), dtype=bool)
    repeat = np.zeros(len(y), dtype=bool)
    repeat[1:] = y[1:] == y[:-1]
    return repeat


def glitches(windows: list, n: int) -> np.ndarray:
    """Single-sample glitches among the ``n`` samples, from ``windows``: each fitted window's (sample
    indices, residual) (:func:`.cycles.measure`): a window's residual stepping out of line with its
    neighbours in the same window, d_i = r_i - (r_prev + r_next) / 2 (at a window's ends, where the
    next window's fit takes over, r_i - 2 r_next + r_next_next), beyond :data:`OUTLIER_Z` robust sigmas of d, over the
    record and over its neighbourhood, and the largest of its neighbours'. A glitch is a spike; what a
    model leaves of a clean record (a harmonic it does not hold, at a large swing) is smooth, and
    stays however small the noise."""
    glitch = np.zeros(n, dtype=bool)
    parts = []
    for idx, x in windows:
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


def mark(cyc) -> None:
    """``good``: the windows of a pass (``cyc``, :class:`.cycles.Cycles`) fitted whose residual and
    amplitude look like the rest (module docstring, bad cycles); ``reason`` says why the others are left out."""
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


def spans(t: np.ndarray, mask: np.ndarray, gap: float) -> list[tuple[float, float]]:
    """The time spans (s) of the runs of ``mask``; runs closer than ``gap`` (s) are merged."""
    idx = np.flatnonzero(mask)
    if not len(idx):
        return []
    out = [[t[idx[0]], t[idx[0]]]]
    for i in idx[1:]:
        if t[i] - out[-1][1] <= gap:
            out[-1][1] = t[i]
        else:
            out.append([t[i], t[i]])
    return [(float(a), float(b)) for a, b in out]


@dataclass
class Rejected:
    """Samples left out of a fit, by reason: ``stuck`` (repeats), ``cycles`` (whole cycles: lock-on,
    tracker lost, too few samples), ``glitches`` (single samples); and the spans (s) they cover."""

    stuck: int = 0
    cycles: int = 0
    glitches: int = 0
    spans: list = field(default_factory=list)
    reasons: list = field(default_factory=list)  # one line per left-out cycle span

    @property
    def samples(self) -> int:
        return self.stuck + self.cycles + self.glitches

    def as_dict(self) -> dict:
        return {"samples": self.samples, "stuck": self.stuck, "cycles": self.cycles, "glitches": self.glitches,
                "spans": [list(s) for s in self.spans], "reasons": list(self.reasons)}
