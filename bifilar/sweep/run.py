"""Run a sweep in chunks: on local processes or a Dask cluster, resumable, results bit for bit alike.

The grid is cut into chunks of consecutive configurations (grid order, the last axis fastest, so that
neighbours follow each other and each rest pose continues from the previous one's). A chunk is a pure
function of the sweep file and its index range, so any executor gives identical rows. Each finished
chunk is saved whole (temp + rename) under ``DIR/.chunks/``; a restarted sweep with the same ``--out``
reuses the saved chunks of the same sweep file (checked by a digest of its contents) and runs the rest;
a saved chunk that cannot be read back (a crash before its data reached the disk, a full disk) is named
and recomputed. The rows stay in the chunk files: :func:`run` returns :class:`Chunks`, which reads them
back in grid order a file at a time, so a sweep of 10^7 rows (~20 GB as rows in memory) needs the
memory of one chunk.
"""

from __future__ import annotations

import fcntl
import hashlib
import json
import math
import os
import pickle
import sys
import tempfile
from collections.abc import Iterator
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

from threadpoolctl import threadpool_limits

from bifilar.rig.statics import Rest
from bifilar.sweep.evaluate import AXES, Row, evaluate
from bifilar.sweep.space import Space, load_space

# Configurations per chunk: each chunk's first rest pose is a global search (~0.1 s), the rest are
# continued (~1 ms each), so chunks are long; but at least ~32 of them, to balance the workers. A pure
# function of the grid's size, never of the executor: the rows are the same on any of them.
MIN_CHUNK, MAX_CHUNK, CHUNKS = 64, 512, 32
CONNECT_TIMEOUT = 5  # s: a Dask scheduler that has not answered by then is not there


class Unreachable(Exception):
    """The Dask scheduler cannot be used: a malformed address, or nothing answered in time."""


def connect(address: str):
    """A Dask client of the scheduler at ``address``, or :class:`Unreachable` within
    :data:`CONNECT_TIMEOUT` (Dask's own default waits 30 s, then prints a traceback)."""
    from dask.distributed import Client

    try:
        return Client(address, timeout=CONNECT_TIMEOUT)
    except ValueError as exc:  # no port, unknown scheme
        raise Unreachable(f"not a scheduler address ({exc})") from None
    except (OSError, TimeoutError):
        raise Unreachable(f"cannot connect (timeout {CONNECT_TIMEOUT} s)") from None


class InUse(Exception):
    """Another sweep holds the output folder's lock (the message is the lock file)."""


def lock(out: Path):
    """The open lock file ``out/.lock``, locked exclusively (``with`` it: released on close, and by the
    system when its process ends, however it ends), or :class:`InUse` at once: two sweeps into one
    folder would resume from and delete each other's chunks and overwrite each other's outputs."""
    path = out / ".lock"
    held = open(path, "a")
    try:
        fcntl.flock(held, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        held.close()
        raise InUse(str(path)) from None
    return held


def chunk_size(size: int) -> int:
    """Configurations per chunk for a grid of ``size`` (see above)."""
    return int(min(MAX_CHUNK, max(MIN_CHUNK, math.ceil(size / CHUNKS))))


def _plain(row: Row) -> dict:
    """A row as JSON-safe values (None for missing numbers)."""
    def num(x):
        return None if x is None or (isinstance(x, float) and not math.isfinite(x)) else float(x)

    return {
        "values": row.values, "feasible": row.feasible, "reason": row.reason,
        "periods": [num(p) for p in row.periods], "motions": list(row.motions),
        "tensions": [num(t) for t in row.tensions], "tension_peak": num(row.tension_peak),
        "sigma": {a: num((row.sigma or {}).get(a)) for a in AXES},
        "dominant": {a: (row.dominant or {}).get(a) for a in AXES},
        "separation": num(row.separation), "clearance": num(row.clearance),
        "air_share": {a: num((row.air_share or {}).get(a)) for a in AXES},
        "near": {a: num((row.near or {}).get(a)) for a in AXES},
    }


def run_chunk(path: str, start: int, stop: int) -> list[dict]:
    """Evaluate configurations ``start`` .. ``stop - 1`` of the sweep file, each rest pose continued
    from the last one found. BLAS runs on one thread whatever the executor (Dask workers default to
    one, a local process to all cores): its rounding depends on the thread count, and a near-degenerate
    eigenproblem turns a last-digit difference into a visible one."""
    with threadpool_limits(1):
        return _evaluate_range(path, start, stop)


def _evaluate_range(path: str, start: int, stop: int) -> list[dict]:
    space = load_space(path)
    guess: Rest | None = None
    rows = []
    for values in space.points(start, stop):
        row = evaluate(space, values, guess)
        guess = row.rest if row.rest is not None else guess
        rows.append(_plain(row))
    return rows


def digest(path: str, chunk: int) -> str:
    """Identifies the sweep for resuming: its file, everything loaded from it and the files it names
    (the base rig, or the suspension and its parts: the loaded space, pickled), and the chunk size."""
    h = hashlib.sha256(Path(path).read_bytes())
    h.update(pickle.dumps(load_space(path), protocol=5))
    h.update(str(chunk).encode())
    return h.hexdigest()[:16]


def _name(k: int) -> str:
    return f"{k:06d}.json"


def _save(folder: Path, name: str, rows: list[dict]) -> None:
    fd, tmp = tempfile.mkstemp(dir=folder, suffix=".tmp")
    with os.fdopen(fd, "w") as f:
        json.dump(rows, f)
    os.replace(tmp, folder / name)


def _intact(f: Path, size: int) -> bool:
    """Whether chunk file ``f`` holds its ``size`` rows (read, checked, and let go). A file that is not
    such a list (truncated or garbled by a killed run or a full disk) is named on stderr and deleted,
    so that its chunk is recomputed rather than every rerun failing on it."""
    if not f.exists():
        return False
    try:
        rows = json.loads(f.read_text())
        if isinstance(rows, list) and len(rows) == size and all(isinstance(r, dict) for r in rows):
            return True
    except (OSError, ValueError):  # JSONDecodeError and UnicodeDecodeError are ValueErrors
        pass
    print(f"sweep: {f} is unreadable (truncated?): recomputing it", file=sys.stderr, flush=True)
    f.unlink(missing_ok=True)
    return False


class Chunks:
    """The rows of a finished sweep, kept on disk in its chunk files, never in memory: ``size`` rows;
    :meth:`rows` reads them back one chunk file at a time, in grid order, as often as asked (while
    the files are there: the sweep command deletes them once its outputs are written)."""

    def __init__(self, folder: Path, ranges: list[tuple[int, int]]):
        self.folder, self.ranges = folder, ranges
        self.size = ranges[-1][1] if ranges else 0

    def rows(self) -> Iterator[dict]:
        for k in range(len(self.ranges)):
            yield from json.loads((self.folder / _name(k)).read_text())


def run(path: str, space: Space, out: Path, jobs: int = 1, scheduler: str | None = None, progress=None,
        chunk: int | None = None) -> Chunks:
    """Run the sweep in chunks of ``chunk`` configurations (default :func:`chunk_size`), each saved as
    it finishes, and return them as :class:`Chunks` (the rows in grid order, read from the files):
    memory holds a chunk at a time, whatever the grid's size. ``progress(n_done)`` is called as chunks
    finish."""
    client = connect(scheduler) if scheduler else None  # before any file is made: a bad address fails at once
    chunk = chunk_size(space.size) if chunk is None else chunk
    chunks = [(s, min(s + chunk, space.size)) for s in range(0, space.size, chunk)]
    folder = out / ".chunks" / digest(path, chunk)
    folder.mkdir(parents=True, exist_ok=True)
    todo = [k for k, (start, stop) in enumerate(chunks) if not _intact(folder / _name(k), stop - start)]
    finished = space.size - sum(stop - start for start, stop in (chunks[k] for k in todo))
    if progress:
        progress(finished)
    absolute = str(Path(path).resolve())

    def finish(k, rows):
        nonlocal finished
        _save(folder, _name(k), rows)
        finished += len(rows)
        if progress:
            progress(finished)

    if client is not None:
        from dask.distributed import as_completed

        with client:
            futures = {client.submit(run_chunk, absolute, *chunks[k], pure=False): k for k in todo}
            for fut in as_completed(futures):
                finish(futures.pop(fut), fut.result())  # popped: a finished future holds its rows
    elif jobs > 1 and len(todo) > 1:
        with ProcessPoolExecutor(max_workers=jobs) as pool:
            futures = {pool.submit(run_chunk, absolute, *chunks[k]): k for k in todo}
            from concurrent.futures import as_completed as done_in_order

            for fut in done_in_order(futures):
                finish(futures.pop(fut), fut.result())
    else:
        for k in todo:
            finish(k, run_chunk(absolute, *chunks[k]))
    return Chunks(folder, chunks)
