"""Runs of one system by different engines, paired and differenced: what a recording plots and the
HTML report draws.

A case hands its runs to ``ctx.keep`` (:class:`validate.registry.CaseContext`); runs are grouped by
the rig they swing (``meta["rig"]``, ``"system"`` without one), and the first run of each group is the
reference that the group's runs by other engines are compared with.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import TypeVar

import numpy as np
from scipy.spatial.transform import Rotation

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
