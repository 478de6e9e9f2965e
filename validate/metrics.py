"""Metrics on trajectories: periods, drifts and differences between engines.

Every function takes plain arrays or :class:`~validate.trajectory.Trajectory` channels and returns
floats, so that a case states its tolerance next to the number it measures.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from bifilar.identification.periods import Period, crossing_times, period  # noqa: F401  (metrics on trajectories)

from .trajectory import Trajectory


def yaw(traj: Trajectory) -> np.ndarray:
    """Torsion angle (rad): the vertical (world z) component of the body's rotation vector, which for
    a twist about the vertical is the twist itself."""
    return Rotation.from_quat(traj["quat"], scalar_first=True).as_rotvec()[:, 2]


def max_abs(x) -> float:
    """Largest absolute value of an array (NaN propagates)."""
    x = np.asarray(x, dtype=float)
    return float(np.max(np.abs(x))) if x.size else float("nan")


def energy_drift(traj: Trajectory) -> float:
    """Largest departure of the ``energy`` channel from its first value (J)."""
    e = traj["energy"]
    return max_abs(e - e[0])


def channel_difference(a: Trajectory, b: Trajectory, name: str, t_end: float | None = None) -> float:
    """Largest absolute difference of a channel between two runs sampled on the same grid, up to
    ``t_end`` (s): the horizon must stay shorter than the divergence time of chaotic motion."""
    if t_end is not None:
        a, b = a.window(t_end), b.window(t_end)
    n = min(len(a.t), len(b.t))
    if n == 0 or not np.allclose(a.t[:n], b.t[:n], rtol=0.0, atol=1e-9):
        raise ValueError(f"{a.engine} and {b.engine} are not sampled on the same grid")
    return max_abs(np.asarray(a[name])[:n] - np.asarray(b[name])[:n])


def quat_angle_difference(a: Trajectory, b: Trajectory, t_end: float | None = None) -> float:
    """Largest rotation angle (rad) between the two runs' body orientations."""
    if t_end is not None:
        a, b = a.window(t_end), b.window(t_end)
    n = min(len(a.t), len(b.t))
    qa = Rotation.from_quat(a["quat"][:n], scalar_first=True)
    qb = Rotation.from_quat(b["quat"][:n], scalar_first=True)
    return float((qa.inv() * qb).magnitude().max())
