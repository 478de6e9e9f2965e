"""Work bounds (issue 35, items 1-3): records whose units are wrong, dense records and the largest
candidate files end in seconds, with one line and exit 2 where the input is wrong, never a hang."""

import json
import math
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from bifilar.identification.records import Record, identify_records
from bifilar.identification.records import synthetic as Y
from bifilar.motion import lagrange as L
from validate.assets import rig

ROOT = Path(__file__).resolve().parents[1]
BENCH = L.from_rig(rig("bench_plate"))
HANG = 30.0  # s: a command still running then would have run on (each finished in ~2 s when fixed)


def cli(*args: str, timeout: float = HANG) -> subprocess.CompletedProcess:
    """``python -m validate ARGS`` from the project root (its code first on the path); a hang fails the
    test at ``timeout``."""
    return subprocess.run([sys.executable, "-m", "validate", *args], capture_output=True, text=True, timeout=timeout,
                          cwd=ROOT)


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


@pytest.mark.slow
def test_a_dense_record_gives_the_moment_in_bins_in_seconds():
    """Item 2: a 2500 Hz record (30 cycles, 1.5e5 rows). Its frequency was taken from a stride of its
    noisy derivative (the full rate's noise, 1e-3 rad at 2500 Hz, drowns the swing's derivative): the
    law was built at a wrong frequency (400 cycles: 'does not return within 10 periods'), and every
    window held 5000 samples. Now the frequency comes from bin means and the fit from bins of 25
    samples (200 a cycle): the right moment, the fit's time set by the cycles, not the rows."""
    truth = rig("bench_plate")
    rec = torsion(0.3, rate=2500.0, cycles=30.0)
    started = time.monotonic()
    (trial,), _ = identify_records(truth, "z", [Record("dense.csv", "angle", "angle", rec.t, rec.y)])
    assert time.monotonic() - started < 5.0
    assert trial.fit.binned == 25 and trial.halves is not None
    assert abs(trial.moment - 0.15) < 3.0 * trial.moment_std
    assert abs(trial.fit.period - rec.period) < 3.0 * trial.fit.period_std


def test_identify_honours_max_seconds(tmp_path):
    """Item 2: identify's fits have a wall-time budget, as simulate's run: exit 4, one line naming the
    record and the option."""
    rec = torsion(0.3)
    path = write(tmp_path / "record.csv", rec.t, rec.y)
    out = cli("identify", "bench_plate", "--axis", "z", "--signal", path, "--max-seconds", "1e-6")
    assert out.returncode == 4 and out.stdout == "" and out.stderr.count("\n") == 1
    assert out.stderr.startswith(f"error: {path}: angle: ") and "(--max-seconds 1e-06)" in out.stderr


@pytest.mark.slow
@pytest.mark.parametrize("com, generate", [("[0.0, 0.0, 0.0]", 5000), ("[0.01, 0.005, 0.02]", 1000)])
def test_plan_with_the_most_generated_candidates_ends_in_seconds(tmp_path, com, generate):
    """Item 3: every candidate had its own rest-pose search (a trifilar's: 14 starts, ~0.1 s), and the
    greedy step and the exchanges built 3e5 designs one at a time: 1000 candidates took 61 s, 5000 ran
    past 120 s. Candidates with one COM now share a rest pose, a new COM continues the nearest one's,
    and the designs are batched: 5000 in ~3 s (an object COM off its origin: every candidate its own
    COM, 1000 in ~2 s)."""
    text = open(rig("trifilar").source).read()
    (tmp_path / "rig.toml").write_text("\n".join(f"com = {com}" if line.startswith("com") else line
                                                 for line in text.splitlines()))
    (tmp_path / "c.toml").write_text(f'rig = "rig.toml"\nperiod_std = 1e-4\ngenerate = {generate}\n')
    out = cli("plan", str(tmp_path / "c.toml"), "--count", "6", "--json")
    assert out.returncode == 0, out.stderr
    report = json.loads(out.stdout)
    assert report["candidates"] == generate and len(report["chosen"]["hangings"]) == 6
    assert report["chosen"]["worst_relative_std"] <= report["textbook"]["worst_relative_std"]
