"""What the report draws of a case that compares motions: each engine's trace of one signal, and
each engine's difference from the reference, small enough to carry back from a worker process.

A case hands its runs to ``ctx.keep`` (for recordings too); :func:`comparisons` groups them as the
recordings do (:func:`validate.compare.compared`: the first run of each rig is the reference, the
runs of that rig by other engines are compared with it) and draws, per group, the signal that moves
most in the reference run (:func:`validate.compare.dominant`).

Each line is thinned to at most :data:`POINTS` buckets, each keeping its smallest and largest sample
(in time order), so the peaks a metric measures stay in the figure.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..compare import compared, dominant, overlap, rig_name, signals
from ..lineplot import Panel, Series, render_png
from ..trajectory import Trajectory

POINTS = 400  # buckets per line: two samples each, ~800 points across a 960 px figure
RGB = ((31, 119, 180), (255, 127, 14), (44, 160, 44), (148, 103, 189), (140, 86, 75), (227, 119, 194))


@dataclass(frozen=True)
class Line:
    label: str
    t: np.ndarray
    y: np.ndarray


@dataclass(frozen=True)
class Comparison:
    """One system's runs: ``signal`` (with ``unit``) of each engine, and each other engine minus
    ``reference``, on the reference's time grid."""

    system: str
    signal: str
    unit: str
    reference: str
    traces: tuple[Line, ...]
    differences: tuple[Line, ...]


def comparisons(trajectories: Sequence[Trajectory], points: int = POINTS) -> list[Comparison]:
    """One :class:`Comparison` per system that two engines ran (see the module docstring)."""
    pairs = compared(list(trajectories), rig_name, lambda t: t.engine)
    groups: dict[int, tuple[Trajectory, list[Trajectory]]] = {}
    for ref, other in pairs:
        groups.setdefault(id(ref), (ref, []))[1].append(other)
    out = []
    for ref, others in groups.values():
        candidates = signals(ref)
        name = dominant(candidates)
        if name is None:
            continue
        unit = candidates[name][1]
        traces, diffs = [_thin(ref.engine, ref.t, candidates[name][0], points)], []
        for other in others:
            theirs = signals(other).get(name)
            if theirs is None:
                continue
            keep = overlap(ref, other)
            traces.append(_thin(other.engine, other.t, theirs[0], points))
            diffs.append(_thin(f"{other.engine} - {ref.engine}", ref.t[keep],
                               np.interp(ref.t[keep], other.t, theirs[0]) - candidates[name][0][keep], points))
        if diffs:
            out.append(Comparison(rig_name(ref), name, unit, ref.engine, tuple(traces), tuple(diffs)))
    return out


def _thin(label: str, t: np.ndarray, y: np.ndarray, points: int) -> Line:
    """The finite samples in at most ``points`` buckets of consecutive samples, each bucket kept as
    its smallest and its largest sample."""
    t, y = np.asarray(t, dtype=float), np.asarray(y, dtype=float)
    finite = np.isfinite(y)
    t, y = t[finite], y[finite]
    if len(t) <= 2 * points:
        return Line(label, t, y)
    edges = np.linspace(0, len(t), points + 1).astype(int)
    keep = []
    for a, b in zip(edges[:-1], edges[1:]):
        keep.extend(sorted({a + int(np.argmin(y[a:b])), a + int(np.argmax(y[a:b]))}))
    return Line(label, t[keep], y[keep])


def figure(c: Comparison) -> bytes:
    """Two panels over time: the engines' traces, and their differences from the reference (PNG)."""
    unit = f" ({c.unit})" if c.unit else ""
    traces = tuple(Series(line.t, line.y, line.label, RGB[i % len(RGB)], dashed=i > 0)
                   for i, line in enumerate(c.traces))
    diffs = tuple(Series(line.t, line.y, line.label, RGB[(i + 1) % len(RGB)])
                  for i, line in enumerate(c.differences))
    return render_png([Panel(f"{c.system}: {c.signal}{unit}, each engine", "", traces),
                       Panel(f"{c.system}: {c.signal}{unit}, difference from {c.reference}", "", diffs,
                             ((0.0, (120, 120, 120)),))], "t (s)")
