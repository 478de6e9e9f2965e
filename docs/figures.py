"""Remake the README's figures under docs/ from the code as it is, each by the command the README shows.

    python docs/figures.py              # every figure below (about a minute on 2 cores)
    python docs/figures.py sweep        # only the figures named: sweep, boat

* ``docs/sweep.png``: ``python -m validate sweep models/sweeps/bench_plate.toml --out DIR --png`` (the
  README's sweep, with its edge warnings), copied from DIR.
* ``docs/boat_tensions.png``: ``python -m validate boat --png docs/boat_tensions.png``.

Two figures are made elsewhere, by their own scripts, since they need more than the command line:
``docs/recording.png`` (``python docs/recording_png.py``: rerun's viewer, through a software Vulkan
driver) and ``docs/speed_accuracy.png`` (``python benchmarks/speed_accuracy.py``: minutes of runs).
A command that fails stops the script with its message and leaves the committed figure as it was.
"""

from __future__ import annotations

import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

DOCS = Path(__file__).resolve().parent
ROOT = DOCS.parent


def validate(*argv: str) -> None:
    """``python -m validate ARGV`` from the project root; exits with its message if it fails."""
    run = subprocess.run([sys.executable, "-m", "validate", *argv], cwd=ROOT, capture_output=True, text=True)
    if run.returncode != 0:
        sys.exit(f"python -m validate {' '.join(argv)}: exit {run.returncode}: {run.stderr.strip()}")
    print(run.stdout.strip().splitlines()[0] if run.stdout.strip() else f"python -m validate {' '.join(argv)}: ok")


def sweep() -> None:
    with tempfile.TemporaryDirectory(prefix="figures-sweep-") as out:
        validate("sweep", "models/sweeps/bench_plate.toml", "--out", out, "--png")
        shutil.copyfile(Path(out) / "sweep.png", DOCS / "sweep.png")


def boat() -> None:
    with tempfile.TemporaryDirectory(prefix="figures-boat-") as out:  # written whole, then moved in
        validate("boat", "--png", str(Path(out) / "boat_tensions.png"))
        shutil.copyfile(Path(out) / "boat_tensions.png", DOCS / "boat_tensions.png")


FIGURES = {"sweep": sweep, "boat": boat}

if __name__ == "__main__":
    unknown = [n for n in sys.argv[1:] if n not in FIGURES]
    if unknown:
        sys.exit(f"usage: python docs/figures.py [{' | '.join(FIGURES)}]...; unknown {unknown}")
    for name in sys.argv[1:] or FIGURES:
        FIGURES[name]()
