"""Sweep defects found by fuzzing (issue 19, item 8): a truncated chunk file left by a killed run is
recomputed, not fatal; a bad ``--scheduler`` is exit 2 within seconds; two sweeps into one ``--out``
cannot run at once; axis values outside the rig file's ranges are errors, not infeasible rows. Every
refusal is one line on stderr, exit 2."""

import json

from bifilar.sweep import run as sweep_run
from bifilar.sweep.space import load_space

from test_sweep import _cli, _write

SPACE = 'rig = "rig.toml"\n[vary]\nwire_length = [1.0, 1.5]\nattach_span = [0.3, 0.4]\n[measure]\naxes = ["z"]\n'


def _chunks(path, chunk):
    return sweep_run.Path(path).parent / "out" / ".chunks" / sweep_run.digest(str(path), chunk)


def test_a_truncated_chunk_is_named_and_recomputed(tmp_path, capsys):
    path = _write(tmp_path, SPACE)
    space = load_space(path)
    clean = sweep_run.run(str(path), space, tmp_path / "clean", jobs=1, chunk=2)
    folder = _chunks(path, 2)
    folder.mkdir(parents=True)
    whole = json.dumps(sweep_run.run_chunk(str(path), 0, 2))
    (folder / "000000.json").write_text(whole)
    (folder / "000001.json").write_text(whole[: len(whole) // 2])  # killed mid-write (before the rename)
    rows = sweep_run.run(str(path), space, tmp_path / "out", jobs=1, chunk=2)
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
