"""Stiff elastic wires and the verbs that meet them (issue 35 items 4-7): the slow modes of a platform on
wires of E A = 1e10 N (inside the field's range), a sweep over ``axial_stiffness``, that axis on heavy
wires, and ``tensor`` on an elastic platform from a rough start."""

import json

import pytest

from validate.assets import RIGS
from validate.cli import main

QUAD = (RIGS / "quadrifilar.toml").read_text()


def _stiff(tmp_path, stiffness: str = "1e10"):
    """The shipped quadrifilar with every wire's E A set to ``stiffness`` (N)."""
    path = tmp_path / f"quad_{stiffness}.toml"
    path.write_text(QUAD.replace("axial_stiffness = 2.0e5", f"axial_stiffness = {stiffness}"))
    return path


def _json(capsys, *args) -> dict:
    code = main(list(args) + ["--json"])
    out, err = capsys.readouterr()
    assert code == 0, err
    return json.loads(out)


def test_stiff_wires_keep_their_slow_modes_and_identify(tmp_path, capsys):
    # Item 4: the neutral test was a fraction (1e-9) of the largest omega^2, the bounce's ~1e10 rad^2/s^2 here:
    # the sways (6.5) and the yaw (9.8) came out neutral (JSON null) and identify --axis z refused.
    path = _stiff(tmp_path)
    modes = _json(capsys, "modes", str(path))["modes"]
    periods = {m["motion"]: m["period"] for m in modes}
    assert periods["sway x"] == pytest.approx(2.4569, abs=1e-4) and periods["sway y"] == pytest.approx(2.4569, abs=1e-4)
    assert periods["yaw"] == pytest.approx(2.0061, abs=1e-4)
    assert all(p is not None for p in periods.values())
    # The same as on wires 100 times softer, to the stretch (7.4e-9 m here, 7.4e-7 m there).
    soft = {m["motion"]: m["period"] for m in _json(capsys, "modes", str(_stiff(tmp_path, "1e8")))["modes"]}
    for motion in ("sway x", "sway y", "yaw"):
        assert periods[motion] == pytest.approx(soft[motion], rel=1e-6)
    found = _json(capsys, "identify", str(path), "--axis", "z", "--period", repr(periods["yaw"]))
    assert found["inertia"] == pytest.approx(0.24, rel=1e-6)
