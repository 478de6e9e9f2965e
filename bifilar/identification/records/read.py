"""Measured records as they come out of trackers and gyros: one signal column against time.

A record file is delimited text: comma, tab, semicolon or whitespace (sniffed from its first data
line), optionally with a header row naming the columns (a UTF-8 byte-order mark is dropped); a file
whose first row is all numbers has no header and its columns are named by their 1-based position,
``1``, ``2``, ... (as ``cut`` and ``awk`` count). Lines starting with ``#`` are comments.

Time: the column ``time_column`` (default: the first of ``t``, ``time``, ``timestamp``; with ``fps``
first ``frame``), in seconds or milliseconds (``time_unit``); with ``fps`` it holds frame numbers and
t = frame / fps (s). A record with ``fps`` and no time-like column is numbered by row. Frames may be
missing (gaps); times must increase.

Value: the column ``column`` (default: the kind's name, ``angle`` or ``rate``, else the only column
that is not the time). ``kind`` is ``angle`` (rad, or deg with ``angle_unit``), ``rate`` (rad/s or
deg/s) or ``proportional`` (any unit, e.g. pixels: only its time course is used, its scale is fitted).
An empty cell or ``nan`` in the value column is a lost frame: the row is dropped and counted. A line
tracker that folds angles into (-pi/2, pi/2] is unfolded (:func:`unfold`) and the jumps counted.

Every problem is a :class:`~bifilar.rig.RigError` naming the file, the column and what is wrong.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from bifilar.rig import RigError

KINDS = ("angle", "rate", "proportional")
TIME_COLUMNS = ("t", "time", "timestamp")
MIN_SAMPLES = 20  # the fit has up to a dozen parameters and needs residual degrees of freedom
MIN_CYCLES = 3  # cycles measured on their own: fewer, and no phase slope can be told from the law
_MAX_BYTES = 200 * 2**20  # 200 MB: a day of 240 fps video; anything larger is not a record
_FOLD = math.pi  # a line tracker cannot tell theta from theta + pi
_TO_SECONDS = {"s": 1.0, "ms": 1e-3}
_TO_RAD = {"rad": 1.0, "deg": math.pi / 180.0}


@dataclass(frozen=True)
class Record:
    """Samples ``y`` at times ``t`` (s, increasing) of column ``column`` in ``source``.

    ``y`` is in rad (angle), rad/s (rate) or the file's own unit (proportional). ``dropped`` rows had
    no value (lost frames); ``unfolded`` is the number of pi jumps removed (:func:`unfold`).
    """

    source: str
    column: str
    kind: str
    t: np.ndarray
    y: np.ndarray
    dropped: int = 0
    unfolded: int = 0


def read_record(path: str | Path, column: str | None = None, kind: str = "angle", *, time_column: str | None = None,
                fps: float | None = None, time_unit: str = "s", angle_unit: str = "rad",
                start: float | None = None, end: float | None = None) -> Record:
    """Read, convert and window one record (see the module docstring); ``start``/``end`` in s."""
    if kind not in KINDS:
        raise ValueError(f"kind must be one of {KINDS}, got {kind!r}")
    src = str(path)
    header, rows, first_line = _table(path)
    t_name = _time_column(src, header, time_column, fps)
    value = _value_column(src, header, column, kind, t_name)
    i_v = header.index(value)
    i_t = header.index(t_name) if t_name is not None else None
    times, values, dropped = [], [], 0
    for line, row in rows:
        if len(row) != len(header):
            raise RigError(src, f"line {line}", f"has {len(row)} fields, the header has {len(header)}")
        x = _cell(row[i_v], src, value, line, missing_ok=True)
        if x is None:
            dropped += 1
            continue
        times.append(float(line - first_line) if i_t is None else _cell(row[i_t], src, t_name, line))
        values.append(x)
        if len(times) > 1 and times[-1] <= times[-2]:
            raise RigError(src, t_name or "line", f"line {line}: time {times[-1]:g} does not increase "
                                                  f"(previous {times[-2]:g})")
    t = np.array(times) / fps if fps is not None else np.array(times) * _TO_SECONDS[time_unit]
    y = np.array(values) * (_TO_RAD[angle_unit] if kind != "proportional" else 1.0)
    if start is not None or end is not None:
        keep = (t >= (-np.inf if start is None else start)) & (t <= (np.inf if end is None else end))
        if keep.sum() < MIN_SAMPLES and len(t):
            raise RigError(src, value, f"{int(keep.sum())} samples between --from and --to (the record spans "
                                       f"{t[0]:.6g} .. {t[-1]:.6g} s); at least {MIN_SAMPLES} are needed")
        t, y = t[keep], y[keep]
    if len(t) < MIN_SAMPLES:
        raise RigError(src, value, f"{len(t)} samples; at least {MIN_SAMPLES} are needed")
    if np.ptp(y) == 0.0:
        raise RigError(src, value, f"constant ({y[0]:g}) over the whole record: nothing oscillates")
    unfolded = 0
    if kind == "angle":
        y, unfolded = unfold(y, t)
    return Record(src, value, kind, t, y, dropped, unfolded)


def unfold(y: np.ndarray, t: np.ndarray | None = None) -> tuple[np.ndarray, int]:
    """A folded angle record made continuous, and the number of jumps removed.

    A line tracker reports angles in (-pi/2, pi/2]; where the body turns past +-pi/2 the record jumps
    by ~pi between frames. A step between neighbouring frames (``t``: sample times, s; a gap is a step
    over 1.5 median steps; without ``t`` every step is between neighbours) is a fold if it is within
    pi/4 of +-pi: the body turns far less in one frame at any rate the fit can follow. The record is
    folded if every sample lies in [-pi/2, pi/2] and at least two steps are folds, more than the steps
    that are neither a fold nor small (between pi/4 and 3 pi/4: a tracker locking on, a glitch).
    Otherwise it is returned as it is: a record that was never folded jumps by over pi/2 only where
    frames were lost during a fast swing or the tracker locked on, and reducing those steps modulo pi
    put pieces of it pi apart (a 1.2 rad swing with a sway at twice its frequency and runs of lost frames
    was refused so).

    A folded record is unfolded piece by piece: within a piece (neighbouring frames, no step between
    pi/4 and 3 pi/4) each fold is removed; a gap or an unclear step starts a new piece, whose own
    multiple of pi is the one that brings its median within pi/2 of the longest piece's median (the
    swing's centre: pieces do not fold across a gap, where the body may turn by more than pi/2). A
    single-frame glitch stays a single-frame glitch (its jump and its return cancel).
    """
    step = np.diff(y)
    if len(step) == 0 or np.abs(y).max() > 0.5 * _FOLD * (1.0 + 1e-9):
        return y, 0
    dt = np.diff(t) if t is not None else np.ones(len(step))
    neighbours = dt <= 1.5 * np.median(dt)
    folds = neighbours & (np.abs(np.abs(step) - _FOLD) < 0.25 * _FOLD)
    unclear = ~neighbours | ((np.abs(step) > 0.25 * _FOLD) & ~folds)
    if folds.sum() < 2 or folds.sum() <= (neighbours & unclear).sum():
        return y, 0
    fixed = np.where(unclear, step, step - _FOLD * np.round(step / _FOLD))
    out = np.concatenate([[y[0]], y[0] + np.cumsum(fixed)])
    starts = np.concatenate([[0], np.flatnonzero(unclear) + 1, [len(y)]])
    pieces = [(a, b) for a, b in zip(starts[:-1], starts[1:]) if b > a]
    a, b = max(pieces, key=lambda p: p[1] - p[0])
    centre = float(np.median(out[a:b]))
    for a, b in pieces:
        out[a:b] += _FOLD * np.round((centre - float(np.median(out[a:b]))) / _FOLD)
    return out, int(folds.sum())


def _table(path) -> tuple[list[str], list[tuple[int, list[str]]], int]:
    """(column names, [(line number, cells)], line number of the first data row) of a record file."""
    src = str(path)
    try:
        p = Path(path)
        if p.is_dir():
            raise RigError(src, "file", "is a directory, not a record file")
        if not p.is_file():  # a FIFO or device would block or never end
            if p.exists():
                raise RigError(src, "file", "not a regular file")
            raise RigError(src, "file", "cannot read (No such file or directory)")
        if p.stat().st_size > _MAX_BYTES:
            raise RigError(src, "file", f"{p.stat().st_size} bytes: larger than {_MAX_BYTES} bytes")
        text = p.read_text(encoding="utf-8-sig")
    except OSError as exc:
        raise RigError(src, "file", f"cannot read ({exc.strerror or exc})") from None
    except UnicodeDecodeError as exc:
        raise RigError(src, "file", f"not UTF-8 text (byte {exc.start})") from None
    lines = [(n, s.strip()) for n, s in enumerate(text.splitlines(), start=1)]
    lines = [(n, s) for n, s in lines if s and not s.startswith("#")]
    if not lines:
        raise RigError(src, "file", "empty: expected rows of numbers, optionally under a header row")
    split = _splitter(lines[0][1] if len(lines) == 1 else lines[1][1])
    first = split(lines[0][1])
    if all(_is_number(c) for c in first):
        return [str(i) for i in range(1, len(first) + 1)], [(n, split(s)) for n, s in lines], lines[0][0]
    header = [c.strip().strip('"').strip() for c in first]
    duplicated = sorted({h for h in header if header.count(h) > 1})
    if duplicated:
        raise RigError(src, "header", f"column {duplicated[0]!r} appears more than once")
    data = [(n, split(s)) for n, s in lines[1:]]
    return header, data, lines[1][0] if len(lines) > 1 else lines[0][0] + 1


def _splitter(sample: str):
    """The cell splitter for a data line: tab, semicolon, comma, else runs of whitespace."""
    for sep in ("\t", ";", ","):
        if sep in sample:
            return lambda s, sep=sep: [c.strip() for c in s.split(sep)]
    return lambda s: s.split()


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def _time_column(src: str, header: list[str], name: str | None, fps: float | None) -> str | None:
    if name is not None:
        if name not in header:
            raise RigError(src, name, f"missing time column (columns: {', '.join(header)})")
        return name
    candidates = (("frame",) if fps is not None else ()) + TIME_COLUMNS
    for c in candidates:
        if c in header:
            return c
    if fps is not None:
        return None  # numbered by row
    raise RigError(src, "t", f"no time column (looked for {', '.join(TIME_COLUMNS)}; columns: {', '.join(header)}): "
                             "name it with --time-column, or give --fps for frame numbers")


def _value_column(src: str, header: list[str], name: str | None, kind: str, t_name: str | None) -> str:
    if name is not None:
        if name not in header:
            raise RigError(src, name, f"missing column (columns: {', '.join(header)})")
        if name == t_name:
            raise RigError(src, name, "is the time column; name the signal column with --column")
        return name
    if kind in header:
        return kind
    others = [h for h in header if h != t_name]
    if len(others) == 1:
        return others[0]
    raise RigError(src, kind, f"missing column (columns: {', '.join(header)}): choose one with --column")


_MISSING = re.compile(r"^(|nan|NaN|NAN|na|NA|null|-)$")


def _cell(text: str, src: str, column: str, line: int, missing_ok: bool = False) -> float | None:
    text = text.strip().strip('"')
    if missing_ok and _MISSING.match(text):
        return None
    try:
        x = float(text)
    except ValueError:
        raise RigError(src, column, f"line {line}: not a number: {text!r}") from None
    if not math.isfinite(x):
        raise RigError(src, column, f"line {line}: not finite: {text!r}")
    return x
