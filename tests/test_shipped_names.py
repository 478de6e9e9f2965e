"""Shipped rigs, sweeps and suspensions by name from any folder (validate.assets.resolve): ``modes
plate`` in a folder without models/ reads models/rigs/plate.toml, ``sweep bench_plate`` means the
sweep of that name (not the rig), a path that exists always wins over a name, and ``list --rigs``
names every shipped file in lines of at most 100 columns."""

import json

import pytest

from validate import assets
from validate.cli import main


def _modes_json(capsys, *argv):
    assert main(["modes", *argv, "--json"]) == 0
    return json.loads(capsys.readouterr().out)


def test_modes_by_name_from_another_folder(tmp_path, monkeypatch, capsys):
    by_path = _modes_json(capsys, str(assets.RIGS / "plate.toml"))
    monkeypatch.chdir(tmp_path)
    assert _modes_json(capsys, "plate") == by_path  # the same file, bit for bit
    assert _modes_json(capsys, "models/rigs/plate.toml") == by_path  # the README's path, from elsewhere


def test_a_path_that_exists_wins_over_a_name(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    text = (assets.RIGS / "plate.toml").read_text().replace('name = "plate"', 'name = "mine"')
    assert 'name = "mine"' in text
    (tmp_path / "plate").write_text(text)
    assert _modes_json(capsys, "plate")["rig"] == "mine"


def test_each_kind_resolves_its_own_folder(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert assets.resolve("bench_plate", "rig") == str(assets.RIGS / "bench_plate.toml")
    assert assets.resolve("bench_plate", "sweep") == str(assets.MODELS / "sweeps" / "bench_plate.toml")
    assert assets.resolve("hall", "sweep") == str(assets.MODELS / "solar_boat" / "hall.toml")
    assert assets.resolve("suspension", "suspension") == str(assets.MODELS / "solar_boat" / "suspension.toml")
    assert assets.resolve("solar_boat/hall", "sweep") == str(assets.MODELS / "solar_boat" / "hall.toml")
    assert assets.resolve("no/such/file.toml", "rig") == "no/such/file.toml"  # left for the loader to refuse


def test_an_unknown_name_is_one_line_and_exit_2(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main(["modes", "platee"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("error: platee: file: ") and "list --rigs" in err


def test_list_rigs_names_every_shipped_file(capsys):
    assert main(["list", "--rigs"]) == 0
    out = capsys.readouterr().out
    lines = out.splitlines()
    assert all(len(line) <= 100 for line in lines), max(lines, key=len)
    listed = [line.split()[0] for line in lines if line.startswith("  ")]
    expected = [name for kind in assets.KINDS for name in assets.shipped(kind)]
    assert listed == expected
    assert {p.stem for p in assets.RIGS.glob("*.toml")} <= set(listed)
    assert "  plate " in out and "Thesis rig of ch. 6.1" in out


@pytest.mark.parametrize("kind", sorted(assets.KINDS))
def test_every_shipped_file_has_a_description(kind):
    for name, path in assets.shipped(kind).items():
        text = assets.description(path)
        assert 10 <= len(text) <= 72, (name, text)
