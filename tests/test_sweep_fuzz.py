"""Sweep defects found by fuzzing (issue 19, item 8): a truncated chunk file left by a killed run is
recomputed, not fatal; a bad ``--scheduler`` is exit 2 within seconds; two sweeps into one ``--out``
cannot run at once; axis values outside the rig file's ranges are errors, not infeasible rows. Every
refusal is one line on stderr, exit 2."""

import json

import pytest

from bifilar.sweep import run as sweep_run
from bifilar.sweep.space import load_space

from test_sweep import _cli, _write

SPACE = 'rig = "rig.toml"\n[vary]\nwire_length = [1.0, 1.5]\nattach_span = [0.3, 0.4]\n[measure]\naxes = ["z"]\n'


def _chunks(path, chunk):
    return sweep_run.Path(path).parent / "out" / ".chunks" / sweep_run.digest(str(path), chunk)


def test_a_truncated_chunk_is_named_and_recomputed(tmp_path, capsys):
    path = _write(tmp_path, SPACE)
    space = load_space(path)
    clean = list(sweep_run.run(str(path), space, tmp_path / "clean", jobs=1, chunk=2).rows())
    folder = _chunks(path, 2)
    folder.mkdir(parents=True)
    whole = json.dumps(sweep_run.run_chunk(str(path), 0, 2))
    (folder / "000000.json").write_text(whole)
    (folder / "000001.json").write_text(whole[: len(whole) // 2])  # a crash before the data reached the disk
    rows = list(sweep_run.run(str(path), space, tmp_path / "out", jobs=1, chunk=2).rows())
    assert json.dumps(rows) == json.dumps(clean)
    err = capsys.readouterr().err
    assert err == f"sweep: {folder / '000001.json'} is unreadable (truncated?): recomputing it\n"
    assert json.loads((folder / "000001.json").read_text()) == clean[2:]


def test_a_truncated_chunk_does_not_fail_the_command(tmp_path, capsys):
    path = _write(tmp_path, SPACE)
    folder = _chunks(path, sweep_run.chunk_size(load_space(path).size))
    folder.mkdir(parents=True)
    (folder / "000000.json").write_text('[{"values": {"wire_length": 1.0')
    code, out, err = _cli(capsys, "sweep", path, "--out", tmp_path / "out", "--jobs", 1)
    assert code == 0 and "4 configurations" in out, err
    assert err.count("\n") == 1 and "000000.json is unreadable (truncated?): recomputing it" in err, err


@pytest.mark.slow
def test_an_unreachable_scheduler_is_exit_2_within_seconds(tmp_path):
    """In a process of its own, so that the wall time counts the imports and Dask's shutdown too."""
    import subprocess
    import sys
    import time

    path = _write(tmp_path, SPACE)
    start = time.perf_counter()
    done = subprocess.run([sys.executable, "-m", "validate", "sweep", str(path), "--out", str(tmp_path / "out"),
                           "--scheduler", "tcp://127.0.0.1:1"], capture_output=True, text=True, timeout=60)
    seconds = time.perf_counter() - start
    assert done.returncode == 2 and done.stdout == "", done.stderr
    assert done.stderr == "error: sweep: --scheduler tcp://127.0.0.1:1: cannot connect (timeout 5 s)\n"
    assert seconds < 12, seconds
    assert not (tmp_path / "out" / ".chunks").exists()


@pytest.mark.parametrize("address, problem", [
    ("", "empty"), ("  ", "empty"), ("nowhere", "not a scheduler address (missing port"),
    ("xyz://a:1", "not a scheduler address (unknown address scheme"),
])
def test_a_malformed_or_empty_scheduler_is_refused_not_run_locally(tmp_path, capsys, address, problem):
    path = _write(tmp_path, SPACE)
    code, out, err = _cli(capsys, "sweep", path, "--out", tmp_path / "out", "--scheduler", address)
    assert code == 2 and out == "" and err.count("\n") == 1, err
    assert err.startswith("error: sweep: --scheduler ") and problem in err, err
    assert not (tmp_path / "out" / "sweep.csv").exists()


def test_a_second_sweep_into_a_folder_in_use_refuses(tmp_path, capsys):
    """The lock held here, as a running sweep holds it: the sweep refuses in one line and touches
    nothing; once released, the same command runs, and leaves the lock free."""
    import fcntl

    path = _write(tmp_path, SPACE)
    out = tmp_path / "out"
    out.mkdir()
    with open(out / ".lock", "a") as held:
        fcntl.flock(held, fcntl.LOCK_EX | fcntl.LOCK_NB)
        code, stdout, err = _cli(capsys, "sweep", path, "--out", out, "--jobs", 1)
        assert code == 2 and stdout == "", err
        assert err == f"error: sweep: {out} is in use by another sweep (lock {out / '.lock'})\n"
        assert sorted(p.name for p in out.iterdir()) == [".lock"]
    code, stdout, err = _cli(capsys, "sweep", path, "--out", out, "--jobs", 1)
    assert code == 0 and (out / "sweep.csv").exists(), err
    with open(out / ".lock", "a") as again:
        fcntl.flock(again, fcntl.LOCK_EX | fcntl.LOCK_NB)  # released: no BlockingIOError


@pytest.mark.parametrize("space, field, value", [
    ('[vary]\nwire_length = [1e300]\n', "vary.wire_length", "1e+300"),
    ('[vary]\nwire_length = {from = 1.0, to = 2000.0, steps = 3}\n', "vary.wire_length", "2000"),
    ('[vary]\nwire_length = [1.0]\nwire_length_2 = [1e-4, 1.0]\n', "vary.wire_length_2", "0.0001"),
    ('[vary]\naxial_stiffness = [1e20]\n', "vary.axial_stiffness", "1e+20"),
    ('[vary]\nanchor_span = [1.0, 1e5]\n', "vary.anchor_span", "100000"),
    ('[vary]\nattach_height = [-1e6, 0.0]\n', "vary.attach_height", "-1e+06"),
    ('[[point]]\nwire_length = 1.0\n[[point]]\nwire_length = 1e300\n', "point[2].wire_length", "1e+300"),
])
def test_axis_values_outside_the_rig_files_ranges_are_errors(tmp_path, capsys, space, field, value):
    """As docs/sweep.md says: the limits a rig file's fields get (bifilar.rig.ranges), one line naming
    the sweep file, the axis and the value; not a grid of infeasible rows."""
    path = _write(tmp_path, 'rig = "rig.toml"\n' + space + '[measure]\naxes = ["z"]\n')
    code, out, err = _cli(capsys, "sweep", path, "--out", tmp_path / "out", "--jobs", 1)
    assert code == 2 and out == "" and err.count("\n") == 1, err
    assert err.startswith(f"error: {path}: {field}: {value} is outside the rig file's ranges ("), err
