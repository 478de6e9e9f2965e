"""BLAS threads and the project's small least squares: one thread against OpenBLAS's default, side by side.

The record fits solve thousands of small, tall least-squares problems (a few thousand rows, 2-10
columns). OpenBLAS splits each over every core by default; on two cores already busy with
``validate all``'s two workers (or pytest's), its threads wait on each other and a 0.1 ms solve can
take several ms. ``validate`` sets ``OPENBLAS_NUM_THREADS=1`` (and its OMP/MKL twins) unless the user set
them (``validate/__main__.py``). This prints both, measured in one run, alternating so that the
machine's load of the moment weighs on both alike:

    python benchmarks/blas_threads.py          # numpy.linalg.lstsq micro-benchmark, then `validate all`
    python benchmarks/blas_threads.py lstsq    # the micro-benchmark only (seconds)

Each run is a new process with the variables set to 1 or to the number of cores (OpenBLAS's default,
which ``validate`` leaves alone when the user sets it), twice each, in the order 1, default, 1, default.
"""

from __future__ import annotations

import os
import subprocess
import sys
import time

_VARIABLES = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")
_LSTSQ = """
import time, numpy as np
rng = np.random.default_rng(0)
u = np.linspace(-1.0, 1.0, {rows})
x = np.column_stack([np.ones_like(u), u] + [f(k * 30.0 * u) for k in (3, 5) for f in (np.cos, np.sin)])
y = rng.normal(size=u.size)
start = time.perf_counter()
for _ in range(200):
    np.linalg.lstsq(x, y, rcond=None)
print((time.perf_counter() - start) / 200)
"""


def _env(threads: str | None) -> dict:
    """The environment with the BLAS thread variables at ``threads``, None: the number of cores."""
    return dict(os.environ, **{k: threads or str(os.cpu_count()) for k in _VARIABLES})


def lstsq(rows: int) -> None:
    """One lstsq of ``rows`` x 6 with one BLAS thread and with the default, each in a fresh process."""
    times = {}
    for threads in ("1", None, "1", None):
        out = subprocess.run([sys.executable, "-c", _LSTSQ.format(rows=rows)], env=_env(threads),
                             capture_output=True, text=True, check=True).stdout
        times.setdefault(threads, []).append(float(out))
    one, default = min(times["1"]), min(times[None])
    print(f"lstsq {rows} x 6: 1 thread {one * 1e3:.3f} ms, default {default * 1e3:.3f} ms, "
          f"default / 1 thread = {default / one:.2f}")


def validate_all() -> None:
    """Wall seconds of ``python -m validate all`` with one BLAS thread and with the default."""
    times = {}
    for threads in ("1", None, "1", None):
        start = time.perf_counter()
        run = subprocess.run([sys.executable, "-m", "validate", "all"], env=_env(threads), capture_output=True,
                             text=True)
        if run.returncode not in (0, 1):
            sys.exit(f"python -m validate all failed (exit {run.returncode}): {run.stderr.strip()[-300:]}")
        times.setdefault(threads, []).append(time.perf_counter() - start)
        print(f"  validate all, {'1 thread' if threads else 'default'}: {times[threads][-1]:.1f} s", flush=True)
    one, default = min(times["1"]), min(times[None])
    print(f"validate all: 1 thread {one:.1f} s, default {default:.1f} s (best of 2), default / 1 thread = "
          f"{default / one:.2f}")


if __name__ == "__main__":
    which = sys.argv[1:] or ["lstsq", "all"]
    if "lstsq" in which:
        for rows in (300, 3000, 30000):
            lstsq(rows)
    if "all" in which:
        validate_all()
