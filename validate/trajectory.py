"""The engine-neutral trajectory that every engine produces and every metric consumes.

A :class:`Trajectory` is a time vector and named channels sampled on it. Rig trajectories (the Kane
model, MuJoCo) carry the channels in :data:`RIG_CHANNELS`; other systems (seed pendula) carry their
own, e.g. ``q`` and ``energy``. Every vector channel is in the world frame (z up, gravity along -z).
"""

from __future__ import annotations

import csv
import errno
import os
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping

import numpy as np
from scipy.spatial.transform import Rotation

# name -> (columns in the CSV, meaning)
RIG_CHANNELS = {
    "com": (("com_x", "com_y", "com_z"), "COM position, world frame, m"),
    "quat": (("qw", "qx", "qy", "qz"), "body->world rotation, unit quaternion, scalar first"),
    "tension": (("tension_1", "tension_2"), "wire tension, N, positive when pulling; 0 when slack"),
    "length_error": (("length_error_1", "length_error_2"), "anchor-attachment distance minus length, m"),
}
RIG_CSV_HEADER = ("t",) + tuple(c for cols, _ in RIG_CHANNELS.values() for c in cols)


@dataclass(frozen=True)
class Trajectory:
    """Samples ``channels[name][i]`` at times ``t[i]`` (s) from one engine run."""

    engine: str
    t: np.ndarray
    channels: Mapping[str, np.ndarray]
    meta: Mapping[str, Any] = field(default_factory=dict)

    def __getitem__(self, name: str) -> np.ndarray:
        return self.channels[name]

    def __contains__(self, name: str) -> bool:
        return name in self.channels

    def window(self, t_end: float) -> "Trajectory":
        """The samples with t <= t_end."""
        keep = self.t <= t_end + 1e-12
        return Trajectory(self.engine, self.t[keep], {k: v[keep] for k, v in self.channels.items()}, self.meta)


def rig_quaternions(rotation: Rotation) -> np.ndarray:
    """The ``quat`` channel: unit quaternions (n, 4), scalar first, in one hemisphere (qw >= 0) so
    that engines that agree give equal numbers."""
    quat = rotation.as_quat(scalar_first=True)
    return quat * np.where(quat[:, :1] < 0.0, -1.0, 1.0)


def atomic_write_text(path: str | Path, text: str) -> None:
    """Write a whole text file or nothing (see :func:`atomic_write_bytes`)."""
    atomic_write_bytes(path, text.encode())


def atomic_write_bytes(path: str | Path, data: bytes) -> None:
    """Write a whole file or nothing: write a temporary file beside it, then rename. Any failure is an
    :class:`OSError` naming ``path`` (the user's file), never the temporary one."""
    path = Path(path)
    check_writable(path)
    tmp = None
    try:
        # The temporary name is at most ~70 characters, whatever the length of the final one (<= 255).
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name[:48]}.", suffix=".tmp", dir=path.parent)
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
        os.chmod(tmp, 0o666 & ~_umask())  # mkstemp creates 0600; give the file the usual mode
        os.replace(tmp, path)
    except OSError as exc:
        if tmp is not None:
            Path(tmp).unlink(missing_ok=True)
        raise OSError(exc.errno, exc.strerror or str(exc), str(path)) from None
    except BaseException:
        if tmp is not None:
            Path(tmp).unlink(missing_ok=True)
        raise


def check_writable(path: str | Path) -> None:
    """Raise :class:`OSError` (naming ``path``) unless a file can be written at ``path``: not a folder,
    its folder exists or can be made, and is writable. Commands call this before their work, so that
    a bad output path fails at once, not after the run."""
    path = Path(path)
    if path.is_dir():
        raise IsADirectoryError(errno.EISDIR, "is a directory", str(path))
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise OSError(exc.errno, exc.strerror or str(exc), str(path)) from None
    if not os.access(path.parent, os.W_OK | os.X_OK):
        raise PermissionError(errno.EACCES, "Permission denied", str(path))
    if len(path.name.encode()) > 255:
        raise OSError(errno.ENAMETOOLONG, "File name too long", str(path))


class NonFiniteTrajectory(ValueError):
    """A trajectory with NaN or infinite samples: never written."""


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def write_rig_csv(traj: Trajectory, path: str | Path) -> None:
    """The rig CSV contract: header :data:`RIG_CSV_HEADER`, one row per sample, full precision."""
    columns = [traj.t[:, None]] + [np.asarray(traj[name]).reshape(len(traj.t), -1) for name in RIG_CHANNELS]
    table = np.hstack(columns)
    if not np.all(np.isfinite(table)):
        raise NonFiniteTrajectory(f"{path}: trajectory has non-finite values; nothing written")
    lines = [",".join(RIG_CSV_HEADER)]
    lines += [",".join(repr(float(x)) for x in row) for row in table]
    atomic_write_text(path, "\n".join(lines) + "\n")


def read_rig_csv(path: str | Path, engine: str = "csv") -> Trajectory:
    """Read a rig CSV written by :func:`write_rig_csv`."""
    with open(path, newline="") as fh:
        rows = list(csv.reader(fh))
    if not rows or tuple(rows[0]) != RIG_CSV_HEADER:
        raise ValueError(f"{path}: header is not {','.join(RIG_CSV_HEADER)}")
    table = np.array(rows[1:], dtype=float)
    channels, col = {}, 1
    for name, (cols, _) in RIG_CHANNELS.items():
        channels[name] = table[:, col : col + len(cols)]
        col += len(cols)
    return Trajectory(engine, table[:, 0], channels)
