"""Hinge rigs on the engines and the command line: MuJoCo's hinge joint against the exact period, the rest
pose, and ``modes``, ``simulate`` and ``mjcf`` on the shipped hinge rigs (with refusals in one line)."""

from __future__ import annotations

import csv
import json
import math

import numpy as np
import pytest

from bifilar.motion.hinge import period_at
from validate.cases.hinge import skew_body, wheel_compound
from validate.cli import main
from validate.engines import hinge as kane_hinge
from validate.engines import mujoco_hinge
from validate.metrics import period

KNOWN = """name = "wc_known"
[body]
mass = 1.55
inertia = [0.1, 0.05, 0.05]
[pivot]
point = [0.0, 0.0, 0.296]
axis = [1.0, 0.0, 0.0]
"""


@pytest.fixture
def known_rig(tmp_path):
    path = tmp_path / "wc_known.toml"
    path.write_text(KNOWN)
    return str(path)


def test_mujoco_compound_period_matches_elliptic():
    rig = wheel_compound()
    exact = period_at(rig, 1.5)
    traj = mujoco_hinge.run(rig, 1.5, 3.2 * exact, 0.005)
    assert period(traj.t, traj["angle"], level=0.0).value == pytest.approx(exact, rel=1e-10)


def test_rest_pose_hangs_com_below_axis():
    rig = skew_body()
    ch = kane_hinge.channels(rig, np.array([0.0]), np.array([0.0]))
    assert ch["com"][0] == pytest.approx([0.0, 0.0, -rig.arm], abs=1e-14)
    r0 = kane_hinge.rest_rotation(rig)
    assert r0 @ rig.axis == pytest.approx([1.0, 0.0, 0.0], abs=1e-14)
    assert np.linalg.det(r0) == pytest.approx(1.0)


def test_modes_on_shipped_hinge_rigs(capsys):
    assert main(["modes", "wheel_compound"]) == 0
    out = capsys.readouterr().out
    assert "compound pendulum" in out and "unknown" in out and "4.500828 N m/rad" in out
    assert main(["modes", "calibration_rod", "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["moment"] == pytest.approx(0.9944 * (3 * 0.00635**2 + 1.0) / 12)
    assert report["modes"][0]["period"] is None  # the rod's stiffness is what it measures


def test_modes_known_rig_prints_period(known_rig, capsys):
    assert main(["modes", known_rig, "--json"]) == 0
    mode = json.loads(capsys.readouterr().out)["modes"][0]
    j = 0.1 + 1.55 * 0.296**2
    assert mode["period"] == pytest.approx(2 * math.pi * math.sqrt(j / (1.55 * 9.81 * 0.296)), rel=1e-14)


@pytest.mark.parametrize("engine", ["kane", "mujoco"])
def test_simulate_writes_hinge_csv(known_rig, tmp_path, engine, capsys):
    out = tmp_path / f"{engine}.csv"
    assert main(["simulate", known_rig, "--engine", engine, "--amplitude", "1.0", "--duration", "1",
                 "--out", str(out)]) == 0
    assert "wrote" in capsys.readouterr().out
    rows = list(csv.reader(out.open()))
    assert rows[0] == ["t", "com_x", "com_y", "com_z", "qw", "qx", "qy", "qz", "angle", "rate"]
    assert len(rows) == 102 and float(rows[1][8]) == 1.0


def test_mjcf_writes_hinge_model(known_rig, tmp_path, capsys):
    import mujoco

    assert main(["mjcf", known_rig, "--out", str(tmp_path)]) == 0
    model = mujoco.MjModel.from_xml_path(str(tmp_path / "wc_known" / "scene.xml"))
    assert model.njnt == 1 and model.jnt_type[0] == mujoco.mjtJoint.mjJNT_HINGE


@pytest.mark.parametrize("argv, message", [
    (["simulate", "wheel_torsion", "--amplitude", "1", "--duration", "1", "--out", "x.csv"], "body.inertia: "),
    (["simulate", "KNOWN", "--engine", "nwire", "--amplitude", "1", "--duration", "1", "--out", "x.csv"], "--engine"),
    (["simulate", "KNOWN", "--duration", "1", "--out", "x.csv"], "--amplitude"),
    (["simulate", "KNOWN", "--amplitude", "3.5", "--duration", "1", "--out", "x.csv"], "amplitude"),
    (["simulate", "plate", "--amplitude", "1", "--duration", "1", "--out", "x.csv"], "--amplitude"),
    (["mjcf", "calibration_rod", "--out", "out"], "torsion.stiffness"),
])
def test_refusals_are_one_line(argv, message, known_rig, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    argv = [known_rig if a == "KNOWN" else a for a in argv]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and message in err
    assert not (tmp_path / "x.csv").exists() and not list(tmp_path.glob("out/*"))  # nothing written


def test_wire_only_loading_refuses_hinge_rigs():
    from bifilar.rig import RigError
    from validate.assets import RIGS
    from validate.commands.shared import load

    with pytest.raises(RigError, match="wire rigs only"):
        load(str(RIGS / "wheel_torsion.toml"))


def test_simulate_records_a_hinge_rig_for_rerun(known_rig, tmp_path, capsys):
    """``--rerun`` on a hinge rig: a recording rerun itself verifies, opening on the 3D scene (the pivot
    axis, the body, its trail) beside the angle and rate plotted."""
    from rerun.chunk import RrdReader

    from rrd_check import verify, views

    rrd = tmp_path / "swing.rrd"
    assert main(["simulate", known_rig, "--engine", "kane", "--amplitude", "0.5", "--duration", "2",
                 "--out", str(tmp_path / "swing.csv"), "--rerun", str(rrd)]) == 0
    verify(rrd)
    shown = views(rrd)
    assert shown["rig"][0] == "3D"
    assert any(name == "angle" for name in shown)
    (store,) = RrdReader(rrd).recordings()
    entities = {chunk.entity_path.lstrip("/") for chunk in RrdReader(rrd).stream(store=store)}
    assert {"world/wc_known/hinge", "world/wc_known/kane/body", "world/wc_known/kane/trail"} <= entities
