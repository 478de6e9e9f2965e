"""The engine-neutral trajectory that every engine produces and every metric consumes.

A :class:`Trajectory` is a time vector and named channels sampled on it. Rig trajectories (the Kane
model, MuJoCo) carry the channels in :data:`RIG_CHANNELS`; other systems (seed pendula) carry their
own, e.g. ``q`` and ``energy``. Every vector channel is in the world frame (z up, gravity along -z).
"""

from __future__ import annotations

import csv
import os
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO, Any, Mapping

import numpy as np
from scipy.spatial.transform import Rotation

from .outputs import check_writable

# name -> (columns in the CSV, meaning); the per-wire channels have one column per wire, numbered
# from 1 like the [[wire]] tables (tension_1..tension_N, length_error_1..length_error_N).
RIG_CHANNELS = {
    "com": (("com_x", "com_y", "com_z"), "COM position, world frame, m"),
    "quat": (("qw", "qx", "qy", "qz"), "body->world rotation, unit quaternion, scalar first"),
    "tension": (("tension_1", "tension_2"), "wire tension, N, positive when pulling; 0 when slack"),
    "length_error": (("length_error_1", "length_error_2"), "anchor-attachment distance minus length, m"),
}
PER_WIRE = ("tension", "length_error")
# A hinge rig's CSV (validate.engines.hinge): the body's pose as for a wire rig, then the one coordinate
# and its rate instead of the wires' columns.
HINGE_CHANNELS = {
    "com": RIG_CHANNELS["com"],
    "quat": RIG_CHANNELS["quat"],
    "angle": (("angle",), "rotation about the hinge axis from rest, rad (right hand about the axis)"),
    "rate": (("rate",), "its rate, rad/s"),
}


def rig_columns(n_wires: int = 2) -> dict[str, tuple[str, ...]]:
    """Channel name -> CSV columns for a rig with ``n_wires`` wires."""
    return {name: tuple(f"{name}_{i}" for i in range(1, n_wires + 1)) if name in PER_WIRE else cols
            for name, (cols, _) in RIG_CHANNELS.items()}


def rig_csv_header(n_wires: int = 2) -> tuple[str, ...]:
    """The CSV header for a rig with ``n_wires`` wires."""
    return ("t",) + tuple(c for cols in rig_columns(n_wires).values() for c in cols)


RIG_CSV_HEADER = rig_csv_header(2)


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
    """Write a whole file or nothing (see :func:`atomic_file`)."""
    with atomic_file(path, "wb") as fh:
        fh.write(data)


@contextmanager
def atomic_file(path: str | Path, mode: str = "w") -> Iterator[IO]:
    """A file written whole or not at all, in as many pieces as wanted: yields a temporary file beside
    ``path`` (``mode`` "w": UTF-8 text, newlines as written; "wb": bytes), renamed to ``path`` when the
    block ends and deleted if it raises. Any failure is an :class:`OSError` naming ``path`` (the user's
    file), never the temporary one."""
    path = Path(path)
    check_writable(path)
    tmp = None
    try:
        # The temporary name is at most ~70 characters, whatever the length of the final one (<= 255).
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name[:48]}.", suffix=".tmp", dir=path.parent)
        with os.fdopen(fd, mode, **({} if "b" in mode else {"encoding": "utf-8", "newline": ""})) as fh:
            yield fh
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


class NonFiniteTrajectory(ValueError):
    """A trajectory with NaN or infinite samples: never written."""


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def write_rig_csv(traj: Trajectory, path: str | Path) -> None:
    """The rig CSV contract: header :func:`rig_csv_header` (one tension and one length-error column
    per wire), one row per sample, full precision."""
    n_wires = np.asarray(traj["tension"]).reshape(len(traj.t), -1).shape[1]
    _write_csv(traj, path, RIG_CHANNELS, rig_csv_header(n_wires))


def write_hinge_csv(traj: Trajectory, path: str | Path) -> None:
    """A hinge rig's CSV: ``t``, the COM and quaternion columns of the rig CSV, ``angle`` and ``rate``
    (:data:`HINGE_CHANNELS`), one row per sample, full precision."""
    _write_csv(traj, path, HINGE_CHANNELS, ("t",) + tuple(c for cols, _ in HINGE_CHANNELS.values() for c in cols))


def _write_csv(traj: Trajectory, path: str | Path, names, header: tuple[str, ...]) -> None:
    """``t`` and the channels ``names`` under ``header``, written whole or not at all."""
    columns = [traj.t[:, None]] + [np.asarray(traj[name]).reshape(len(traj.t), -1) for name in names]
    table = np.hstack(columns)
    if not np.all(np.isfinite(table)):
        raise NonFiniteTrajectory(f"{path}: trajectory has non-finite values; nothing written")
    lines = [",".join(header)]
    lines += [",".join(repr(float(x)) for x in row) for row in table]
    atomic_write_text(path, "\n".join(lines) + "\n")


def read_rig_csv(path: str | Path, engine: str = "csv") -> Trajectory:
    """Read a rig CSV written by :func:`write_rig_csv`."""
    with open(path, newline="") as fh:
        rows = list(csv.reader(fh))
    n_wires = sum(1 for c in rows[0] if c.startswith("tension_")) if rows else 0
    header = rig_csv_header(max(n_wires, 2))
    if not rows or tuple(rows[0]) != header:
        raise ValueError(f"{path}: header is not {','.join(header)}")
    table = np.array(rows[1:], dtype=float)
    channels, col = {}, 1
    for name, cols in rig_columns(max(n_wires, 2)).items():
        channels[name] = table[:, col : col + len(cols)]
        col += len(cols)
    return Trajectory(engine, table[:, 0], channels)
