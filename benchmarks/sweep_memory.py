"""Peak memory of a whole sweep against the number of configurations: a sweep's memory must not grow
with its grid (issue 19, item 9).

For each size N, a sweep file is written to a temporary folder: the bench-plate sweep
(models/sweeps/bench_plate.toml: its rig, limits and measured axes) with its three axes' ranges cut
into lengths whose product is N (as near the cube root as N's divisors allow). Then
``python -m validate sweep FILE --out DIR --jobs 2`` runs in a child process which, as it ends, reports
its own peak resident set (``getrusage(RUSAGE_SELF)``: the sweep's main process, which gathers the
chunks and writes the outputs) and that of its largest worker (``RUSAGE_CHILDREN``: the largest
child it waited for). Printed per N: both peaks (MB), the wall time (s) and the main process's
bytes per row, its peak above that of a two-chunk sweep (128 configurations, run first) over N.

    python benchmarks/sweep_memory.py              # N = 10^4 and 10^5 (~3 min on 2 busy cores)
    python benchmarks/sweep_memory.py --large      # and 10^6 (~20 min more: 1194 s on 2 quiet cores)
    python benchmarks/sweep_memory.py 2000 50000   # these sizes
"""

from __future__ import annotations

import math
import subprocess
import sys
import tempfile
import time
import tomllib
from pathlib import Path

BASE = Path(__file__).resolve().parents[1] / "models" / "sweeps" / "bench_plate.toml"
BASELINE = 128  # configurations: two chunks (one would run in the main process), as good as no rows
JOBS = 2

# Run as the child: `python -m validate ARGS...`, then its own and its largest child's peak resident
# set (ru_maxrss, KiB on Linux) written to the file named first.
CHILD = """
import resource, runpy, sys
report, sys.argv = sys.argv[1], ["validate"] + sys.argv[2:]
try:
    runpy.run_module("validate", run_name="__main__", alter_sys=True)
finally:
    peaks = [resource.getrusage(who).ru_maxrss for who in (resource.RUSAGE_SELF, resource.RUSAGE_CHILDREN)]
    open(report, "w").write(" ".join(map(str, peaks)))
"""


def shape(n: int, axes: int = 3) -> list[int]:
    """``axes`` whole numbers whose product is ``n``, each the divisor of what is left nearest to
    its fair share (the k-th root of it, for the k axes still to fill)."""
    out = []
    for k in range(axes, 0, -1):
        target = n ** (1.0 / k)
        divisors = [d for d in range(1, math.isqrt(n) + 1) if n % d == 0]
        divisors += [n // d for d in divisors]
        length = min(divisors, key=lambda d: (abs(d - target), d))
        out.append(length)
        n //= length
    return out


def sweep_file(n: int, folder: Path) -> Path:
    """The bench-plate sweep with N configurations (see the module docstring)."""
    base = tomllib.loads(BASE.read_text())
    rig = (BASE.parent / base["rig"]).resolve()
    lines = [f'rig = "{rig}"', "", "[vary]"]
    for (name, axis), steps in zip(base["vary"].items(), shape(n, len(base["vary"]))):
        lines.append(f"{name} = {{from = {axis['from']!r}, to = {axis['to']!r}, steps = {steps}}}"
                     if steps > 1 else f"{name} = [{axis['from']!r}]")
    for table in ("limits", "measure"):
        lines += ["", f"[{table}]"] + [f"{k} = {v!r}".replace("'", '"') for k, v in base[table].items()]
    path = folder / f"bench_{n}.toml"
    path.write_text("\n".join(lines) + "\n")
    return path


def measure(n: int) -> tuple[float, float, float]:
    """(main process peak, largest worker peak, wall time): bytes, bytes, s, of a sweep of ``n``."""
    with tempfile.TemporaryDirectory(prefix="sweep_memory_") as tmp:
        folder = Path(tmp)
        report = folder / "rusage"
        argv = [sys.executable, "-c", CHILD, str(report), "sweep", str(sweep_file(n, folder)),
                "--out", str(folder / "out"), "--jobs", str(JOBS)]
        start = time.perf_counter()
        subprocess.run(argv, check=True, stdout=subprocess.DEVNULL)
        seconds = time.perf_counter() - start
        own, worker = (1024.0 * int(k) for k in report.read_text().split())
    return own, worker, seconds


def main(sizes: list[int]) -> None:
    base, _, _ = measure(BASELINE)
    print(f"baseline ({BASELINE} configurations): main process peak {base / 1e6:.0f} MB")
    print(f"{'N':>9} {'main peak MB':>13} {'worker peak MB':>15} {'seconds':>8} {'bytes/row':>10}")
    for n in sizes:
        own, worker, seconds = measure(n)
        print(f"{n:>9} {own / 1e6:>13.0f} {worker / 1e6:>15.0f} {seconds:>8.1f} {(own - base) / n:>10.0f}",
              flush=True)


if __name__ == "__main__":
    args = sys.argv[1:]
    sizes = [int(float(a)) for a in args if a != "--large"] or [10**4, 10**5]
    main(sizes + ([10**6] if "--large" in args else []))
