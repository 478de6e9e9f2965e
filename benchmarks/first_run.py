"""The first run on a fresh machine against a warm one: each command run twice in a new, empty numba
cache (a temporary NUMBA_CACHE_DIR), first cold (nothing compiled) and then warm (everything the first
run compiled is cached), wall time of the whole process, side by side with the ratio. Issue 19's
targets: the first ``modes`` of a shipped rig within 3x of a warm one, the first ``validate all``
within 1.5x.

    python benchmarks/first_run.py            # modes plate, then validate all (minutes when cold)
    python benchmarks/first_run.py modes      # only the commands whose name is given: modes, all

On a shared machine the ratios vary with the load of the moment: run it when the machine is quiet.
Whatever each command prints on stderr about compiling is shown once (the cold run's notes).
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import time

COMMANDS = {
    "modes": ["modes", "plate"],
    "all": ["all"],
}
TARGETS = {"modes": 3.0, "all": 1.5}


def timed(argv: list[str], cache: str) -> tuple[float, str]:
    """Wall seconds of ``python -m validate ARGV`` with the numba cache in ``cache``, and its stderr's
    compile notes."""
    env = dict(os.environ, NUMBA_CACHE_DIR=cache)
    start = time.perf_counter()
    run = subprocess.run([sys.executable, "-m", "validate", *argv], env=env, capture_output=True, text=True)
    seconds = time.perf_counter() - start
    if run.returncode not in (0, 1):  # 1: a case failed; the time still counts, the failure is not ours to judge
        sys.exit(f"python -m validate {' '.join(argv)} failed (exit {run.returncode}): {run.stderr.strip()[-500:]}")
    notes = [line for line in run.stderr.splitlines() if line.startswith("note: compiling")]
    return seconds, "\n".join(notes)


def main(names: list[str]) -> None:
    print(f"{'command':<24} {'cold s':>8} {'warm s':>8} {'cold/warm':>10} {'target':>7}")
    for name in names or list(COMMANDS):
        argv = COMMANDS[name]
        with tempfile.TemporaryDirectory(prefix="numba-first-run-") as cache:
            cold, notes = timed(argv, cache)
            warm, _ = timed(argv, cache)
        ratio = cold / warm
        verdict = "ok" if ratio <= TARGETS[name] else "MISSED"
        label = "validate " + " ".join(argv)
        print(f"{label:<24} {cold:8.1f} {warm:8.1f} {ratio:10.2f} {TARGETS[name]:6.1f}x {verdict}", flush=True)
        for line in notes.splitlines():
            print(f"    {line}")


if __name__ == "__main__":
    unknown = [n for n in sys.argv[1:] if n not in COMMANDS]
    if unknown:
        sys.exit(f"usage: python benchmarks/first_run.py [{' | '.join(COMMANDS)}]...; unknown {unknown}")
    main(sys.argv[1:])
