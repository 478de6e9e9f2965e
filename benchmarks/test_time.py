"""Wall time of the test tiers (CONTRIBUTING.md) on an empty and on a warm numba cache, side by side.

Each tier runs twice in a new, empty cache (a temporary NUMBA_CACHE_DIR): first cold (every kernel a
test loops over compiles there) and then warm (all of it cached). Issue 34's targets on a quiet 2-core
machine: the quick tier within 60 s warm, the whole suite (the README's command) within 180 s cold.

    python benchmarks/test_time.py              # quick, then whole (about 10 minutes on 2 cores)
    python benchmarks/test_time.py quick        # only the tiers named: quick, whole

The machine is shared: compare figures of one run, not of two. Prints pytest's closing line for each run,
so a figure from a failing run is not taken for a passing one.
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
TIERS = {
    "quick": ["-m", "not slow", "-n", "2"],
    "whole": ["-n", "auto"],  # the README's test command
}
TARGETS = {"quick": ("warm", 60.0), "whole": ("cold", 180.0)}  # s, on a quiet 2-core machine


def timed(args: list[str], cache: str) -> tuple[float, str]:
    """Wall seconds of ``python -m pytest ARGS`` from the project root with the numba cache in
    ``cache``, and pytest's closing line."""
    env = dict(os.environ, NUMBA_CACHE_DIR=cache)
    start = time.perf_counter()
    run = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", *args], cwd=ROOT,
                         env=env, capture_output=True, text=True)
    seconds = time.perf_counter() - start
    closing = run.stdout.strip().splitlines()[-1] if run.stdout.strip() else run.stderr.strip()[-300:]
    return seconds, closing


def main(names: list[str]) -> None:
    print(f"{'tier':<8} {'cold s':>8} {'warm s':>8} {'target':>14}  closing line (cold | warm)")
    for name in names or list(TIERS):
        with tempfile.TemporaryDirectory(prefix="numba-test-time-") as cache:
            cold, cold_line = timed(TIERS[name], cache)
            warm, warm_line = timed(TIERS[name], cache)
        which, limit = TARGETS[name]
        verdict = "ok" if {"cold": cold, "warm": warm}[which] <= limit else "MISSED"
        target = f"{which} <= {limit:.0f} {verdict}"
        print(f"{name:<8} {cold:8.1f} {warm:8.1f} {target:>14}  {cold_line} | {warm_line}", flush=True)


if __name__ == "__main__":
    unknown = [n for n in sys.argv[1:] if n not in TIERS]
    if unknown:
        sys.exit(f"usage: python benchmarks/test_time.py [{' | '.join(TIERS)}]...; unknown {unknown}")
    main(sys.argv[1:])
