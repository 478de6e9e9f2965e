"""Runs of one system by different engines, paired and differenced, and the signal that describes
each run's motion with its period cycle by cycle: what a recording plots and the HTML report draws.

A case hands its runs to ``ctx.keep`` (:class:`validate.registry.CaseContext`); runs are grouped by
the rig they swing (``meta["rig"]``, ``"system"`` without one), and the first run of each group is the
reference that the group's runs by other engines are compared with.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import TypeVar

import numpy as np
from scipy.spatial.transform import Rotation

from bifilar.identification.periods import crossing_times

from .trajectory import Trajectory

T = TypeVar("T")


def rig_name(traj: Trajectory) -> str:
    """The name of the system a run swings: its rig, or ``"system"``."""
    return str(traj.meta.get("rig") or "system")


def by_rig(items: Sequence[T], rig: Callable[[T], str]) -> dict[str, list[T]]:
    """``items`` grouped by ``rig(item)``, in order of first appearance."""
    groups: dict[str, list[T]] = {}
    for item in items:
        groups.setdefault(rig(item), []).append(item)
    return groups


def compared(items: Sequence[T], rig: Callable[[T], str], engine: Callable[[T], str]) -> list[tuple[T, T]]:
    """(reference, other) pairs: the first item of each rig against that rig's items by other engines."""
    return [(g[0], r) for g in by_rig(items, rig).values() for r in g[1:] if engine(r) != engine(g[0])]


def columns(traj: Trajectory) -> dict[str, np.ndarray]:
    """Every numeric channel as an (n, k) float array."""
    n = len(traj.t)
    out = {}
    for name, values in traj.channels.items():
        arr = np.asarray(values)
        if arr.dtype.kind in "fiub" and arr.ndim in (1, 2) and len(arr) == n:
            out[name] = arr.reshape(n, -1).astype(float, copy=False)
    return out


def differences(ref: Trajectory, other: Trajectory) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """``other - ref`` for each channel both carry with the same width, on ``ref``'s times within the
    overlap of the two runs (``other`` interpolated linearly: exact where the grids coincide). The
    quaternion channel becomes ``attitude``, the rotation angle (rad) from ``ref``'s attitude to
    ``other``'s, which does not depend on the quaternions' signs."""
    keep = overlap(ref, other)
    t = ref.t[keep]
    a, b = columns(ref), columns(other)
    out = {}
    for name in a.keys() & b.keys():
        if a[name].shape[1] != b[name].shape[1]:
            continue
        theirs = np.column_stack([np.interp(t, other.t, col) for col in b[name].T])
        if name == "quat":
            angle = (Rotation.from_quat(a[name][keep], scalar_first=True).inv()
                     * Rotation.from_quat(theirs, scalar_first=True)).magnitude()
            out["attitude"] = (t, angle[:, None])
        else:
            out[name] = (t, theirs - a[name][keep])
    return dict(sorted(out.items()))


def overlap(ref: Trajectory, other: Trajectory) -> np.ndarray:
    """The samples of ``ref`` inside the time span of ``other`` (a boolean mask)."""
    return (ref.t >= other.t[0] - 1e-12) & (ref.t <= other.t[-1] + 1e-12)


def signals(traj: Trajectory) -> dict[str, tuple[np.ndarray, str, float]]:
    """The scalar signals that describe a run's motion: name -> (values, unit, scale). A rig's run
    (``com`` and ``quat``): the components of the body's rotation vector (rad, world frame) and of the
    COM's displacement from its start (m, world frame; scale: the longest wire, so that a swing and a
    turn compare as angles). Any other system (a seed pendulum): the components of its ``q``
    channel if it has one, else of every channel but ``energy`` (scale 1)."""
    n = len(traj.t)
    out = {}
    if "quat" in traj and "com" in traj:
        rotvec = Rotation.from_quat(np.asarray(traj["quat"]), scalar_first=True).as_rotvec()
        spec = traj.meta.get("rig_spec")
        length = max((w.length for w in spec.wires), default=1.0) if spec is not None else 1.0
        com = np.asarray(traj["com"], dtype=float)
        for k, axis in enumerate("xyz"):
            out[f"rotation about world {axis}"] = (rotvec[:, k], "rad", 1.0)
            out[f"COM {axis} displacement"] = (com[:, k] - com[0, k], "m", length)
        return out
    names = ["q"] if "q" in traj else [c for c in traj.channels if c != "energy"]
    for c in names:
        values = np.asarray(traj[c])
        if values.dtype.kind not in "fiu" or values.ndim not in (1, 2) or len(values) != n:
            continue
        values = values.reshape(n, -1).astype(float)
        for k in range(values.shape[1]):
            out[c if values.shape[1] == 1 else f"{c}[{k}]"] = (values[:, k], "", 1.0)
    return out


def dominant(candidates: dict[str, tuple[np.ndarray, str, float]]) -> str | None:
    """The name of the signal of :func:`signals` with the largest range over its scale (None: none)."""

    def swing(name: str) -> float:
        values, _, scale = candidates[name]
        finite = values[np.isfinite(values)]
        return float(np.ptp(finite)) / scale if finite.size else -1.0

    return max(candidates, key=swing, default=None)


def cycle_periods(traj: Trajectory) -> tuple[str, np.ndarray, np.ndarray] | None:
    """The period of the run's :func:`dominant` signal cycle by cycle: (its name, the first sample
    time at or after each cycle's end (s), that cycle's period (s)), from the signal's rising
    crossings of its mid-range (refined between samples); None for fewer than two crossings or a
    signal that is not finite throughout."""
    candidates = signals(traj)
    name = dominant(candidates)
    if name is None or not np.all(np.isfinite(candidates[name][0])):
        return None
    x = candidates[name][0]
    times = crossing_times(traj.t, x, 0.5 * (x.max() + x.min()))
    if len(times) < 2:
        return None
    ends = traj.t[np.minimum(np.searchsorted(traj.t, times[1:]), len(traj.t) - 1)]
    return name, ends, np.diff(times)
