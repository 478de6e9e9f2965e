"""What a tracker or a gyro adds to a record that is not the rig's motion, found and left out.

* Stuck values: a tracker that loses its target repeats the last value; every repeat after the first
  of a run of exactly equal samples is left out. A quantized record (an integer pixel tracker: fewer
  distinct values than half the samples) repeats values honestly near its turning points, and keeps them.
* Bad cycles: the fit (:mod:`.fit`) measures each cycle on its own; a cycle whose residual is far above
  the record's typical one (the tracker locking on at the start, or losing the target), whose samples do
  not cover it, or whose amplitude jumps away from its neighbours' is left out whole.
* Glitches: single samples beyond :data:`OUTLIER_Z` robust standard deviations of the residual.

Everything left out is reported (:class:`Rejected`): samples and the time spans they cover, with why.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

OUTLIER_Z = 6.0  # robust sigmas: a normal sample exceeds it with probability 2e-9 (none in 1e6 samples)
_QUANTIZED = 0.5  # distinct values / samples below this: a quantized record


def stuck(y: np.ndarray) -> np.ndarray:
    """Mask of the samples that repeat the previous one exactly (not for a quantized record)."""
    if len(np.unique(y)) < _QUANTIZED * len(y):
        return np.zeros(len(y), dtype=bool)
    repeat = np.zeros(len(y), dtype=bool)
    repeat[1:] = y[1:] == y[:-1]
    return repeat


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
