"""Work bounds (issue 35, items 1-3): records whose units are wrong, dense records and the largest
candidate files end in seconds, with one line and exit 2 where the input is wrong, never a hang."""

import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from bifilar.identification.records import synthetic as Y
from bifilar.motion import lagrange as L
from validate.assets import rig

ROOT = Path(__file__).resolve().parents[1]
BENCH = L.from_rig(rig("bench_plate"))
HANG = 30.0  # s: a command still running then would have run on (each finished in ~2 s when fixed)


def cli(*args: str, timeout: float = HANG) -> subprocess.CompletedProcess:
    """``python -m validate ARGS`` with this tree's code; a hang fails the test at ``timeout``."""
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    return subprocess.run([sys.executable, "-m", "validate", *args], capture_output=True, text=True, timeout=timeout,
                          env=env, cwd=ROOT)


def write(path: Path, t: np.ndarray, y: np.ndarray) -> str:
    np.savetxt(path, np.column_stack([t, y]), delimiter=",", header="t,angle", comments="", fmt="%.10g")
    return str(path)


def torsion(amplitude: float, rate: float = 60.0, cycles: float = 30.0, seed: int = 1) -> Y.Synthetic:
    return Y.record(BENCH, np.random.default_rng(seed), Y.Traits(amplitude=amplitude, rate=rate, cycles=cycles,
                                                                 white=1e-3))


@pytest.mark.parametrize("amplitude, time_scale, angle_scale, likely", [
    (0.054, 1.0, 180.0 / math.pi, "--angle-unit deg"),  # 3.09 "rad": just under pi, the law's limit
    (0.3, 1.0, 1.0, "--time-unit s"),  # seconds, read with --time-unit ms below
])
def test_a_record_in_the_wrong_unit_is_refused_in_one_line(tmp_path, amplitude, time_scale, angle_scale, likely):
    """Item 1: the fit's windows stepped by the law's local frequency, which a law fitted to such a
    record makes negative: the loop ran backwards for ever. Now one line naming the file and the likely
    unit, exit 2, in seconds."""
    rec = torsion(amplitude)
    path = write(tmp_path / "record.csv", rec.t * time_scale, rec.y * angle_scale)
    unit = ["--time-unit", "ms"] if likely == "--time-unit s" else []
    out = cli("identify", "bench_plate", "--axis", "z", "--signal", path, *unit)
    assert out.returncode == 2 and out.stdout == ""
    assert out.stderr.count("\n") == 1 and out.stderr.startswith(f"error: {path}: angle: ")
    assert likely in out.stderr and "Traceback" not in out.stderr
