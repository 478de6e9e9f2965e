"""Every class of bad rig file gets one line naming file, field and problem, and exit status 2."""

import json
import tomllib

import numpy as np
import pytest

from bifilar.rig import load_rig
from validate.assets import RIGS
from validate.cli import main

GOOD = (RIGS / "plate.toml").read_text()


def run_cli(capsys, *args):
    code = main(list(args))
    out, err = capsys.readouterr()
    return code, out, err


@pytest.mark.parametrize(
    "edit, field, words",
    [
        (lambda s: s.replace("mass = 100.0", ""), "body.mass", "missing"),
        (lambda s: s.replace("mass = 100.0", "mass = 100.0\ncolour = 3"), "body.colour", "unknown key"),
        (lambda s: s.replace("gravity = 9.81", "gravity = 9.81\nfoo = 1"), "foo", "unknown key"),
        (lambda s: s.replace("com = [0.0, 0.0, 0.0]", "com = [0.0, 0.0]"), "body.com", "three numbers"),
        (lambda s: s.replace("mass = 100.0", "mass = nan"), "body.mass", "finite"),
        (lambda s: s.replace("mass = 100.0", "mass = -1.0"), "body.mass", "positive"),
        (lambda s: s.replace("length = 5.0", "length = 0.0", 1), "wire[1].length", "positive"),
        (lambda s: s.replace("length = 5.0", "length = inf", 1), "wire[1].length", "finite"),
        (lambda s: s.replace("mass = 100.0", 'mass = "heavy"'), "body.mass", "number"),
        (lambda s: s.replace("inertia = [216.66666666666666, 60.416666666666664, 260.4166666666667]",
                             "inertia = [1.0, -2.0, 1.5]"), "body.inertia", "not positive definite"),
        (lambda s: s.replace("inertia = [216.66666666666666, 60.416666666666664, 260.4166666666667]",
                             "inertia = [1.0, 1.0, 5.0]"), "body.inertia", "triangle inequality"),
        (lambda s: s.replace("inertia = [216.66666666666666, 60.416666666666664, 260.4166666666667]",
                             "inertia = [[2.0, 0.1, 0.0], [0.2, 2.0, 0.0], [0.0, 0.0, 2.0]]"),
         "body.inertia", "not symmetric"),
        (lambda s: s[: s.index("[[wire]]", s.index("[[wire]]") + 1)], "wire", "2 to 64 [[wire]] tables needed"),
        (lambda s: s.replace("anchor = [0.0, 5.0,", "anchor = [0.0, 50.0,"), "wire", "no taut pose"),
        (lambda s: s.replace("attach = [0.0, 2.5, 0.5]", "attach = [0.0, -2.5, 0.5]"), "wire[2].attach", "coincides"),
        (lambda s: s.replace("com = [0.0, 0.0, 0.0]", "com = [0.0, 9.0, 0.0]").replace("-5.0,", "-1.0,")
         .replace("[0.0, 5.0,", "[0.0, 1.0,"), "wire[1]", "slack at rest"),
        (lambda s: s.replace("[initial]", "[initial]\nspin = 1"), "initial.spin", "unknown key"),
        (lambda s: s.replace("mass = 100.0", "mass = = 100.0"), "toml", "not valid TOML"),
    ],
)
def test_bad_rig_is_one_line_with_file_and_field(tmp_path, capsys, edit, field, words):
    path = tmp_path / "bad.toml"
    path.write_text(edit(GOOD))
    code, out, err = run_cli(capsys, "modes", str(path), "--json")
    assert code == 2
    assert out == ""
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith(f"error: {path}: {field}: "), lines[0]
    assert words in lines[0]


def test_three_wires_run_through_the_kane_engine(tmp_path, capsys):
    # A third wire ends the two-wire Kane-Tseng model's reach: the kane engine hands N != 2 to the
    # N-wire model, and the CSV grows one tension and one length-error column per wire.
    code, _, err = run_cli(capsys, "simulate", str(RIGS / "trifilar.toml"), "--engine", "kane", "--duration", "0.2",
                           "--out", str(tmp_path / "out.csv"))
    assert code == 0, err
    header = (tmp_path / "out.csv").read_text().splitlines()[0].split(",")
    assert header[-6:] == ["tension_1", "tension_2", "tension_3", "length_error_1", "length_error_2", "length_error_3"]


def test_missing_file(capsys):
    code, _, err = run_cli(capsys, "modes", "/no/such/rig.toml")
    assert code == 2 and err.startswith("error: /no/such/rig.toml: file: cannot read")


def test_modes_json_contract(capsys):
    code, out, _ = run_cli(capsys, "modes", str(RIGS / "plate.toml"), "--json")
    assert code == 0
    data = json.loads(out)
    assert data["rig"] == "plate"
    eq = data["equilibrium"]
    np.testing.assert_allclose(eq["com"], [0, 0, 0], atol=1e-12)
    np.testing.assert_allclose(eq["rotation"], np.eye(3), atol=1e-12)
    # 7.2: m g / (2 cos 30 deg) per wire, solved to machine precision.
    np.testing.assert_allclose(eq["tensions"], [566.3806140750229] * 2, rtol=1e-12)
    periods = [m["period"] for m in data["modes"]]
    assert len(periods) == 4 and periods == sorted(periods, reverse=True)
    assert [m["frequency"] * m["period"] for m in data["modes"]] == pytest.approx([1.0] * 4, rel=1e-15)
    # The plate hangs from wires in the y-z plane: a sway across it (x), along it (y), the tilt
    # about y and the yaw, each named by the motion holding most of its kinetic energy.
    assert [m["motion"] for m in data["modes"]] == ["sway x", "sway y", "tilt", "yaw"]


def test_neutral_mode_is_null_and_first(capsys):
    """The thin plate's COM is on CD: tilting about CD (theta1) costs no energy."""
    code, out, _ = run_cli(capsys, "modes", str(RIGS / "sidesway.toml"), "--json")
    periods = [m["period"] for m in json.loads(out)["modes"]]
    assert periods[0] is None and all(p > 0 for p in periods[1:])
    # Side-sway: planar pendulum of length 5 cos(pi/6) (thesis 6.1), exactly in the linear limit.
    assert periods[1] == pytest.approx(2 * np.pi * np.sqrt(5 * np.cos(np.pi / 6) / 9.81), rel=1e-10)


def test_simulate_writes_the_csv_contract(tmp_path, capsys):
    out = tmp_path / "plate.csv"
    code, _, err = run_cli(capsys, "simulate", str(RIGS / "plate.toml"), "--engine", "kane",
                           "--duration", "2", "--dt-out", "0.1", "--out", str(out))
    assert code == 0, err
    lines = out.read_text().splitlines()
    assert lines[0] == "t,com_x,com_y,com_z,qw,qx,qy,qz,tension_1,tension_2,length_error_1,length_error_2"
    table = np.array([[float(x) for x in line.split(",")] for line in lines[1:]])
    assert table.shape == (21, 12)
    np.testing.assert_allclose(table[:, 0], np.arange(21) * 0.1, atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(table[:, 4:8], axis=1), 1.0, atol=1e-12)
    # Initial state: 0.1745 rad about z, then the pure lift that keeps both wires taut.
    assert table[0, 4] == pytest.approx(np.cos(0.1745 / 2), abs=1e-12)
    assert table[0, 7] == pytest.approx(np.sin(0.1745 / 2), abs=1e-12)
    np.testing.assert_allclose(table[0, 1:3], 0.0, atol=1e-12)
    assert table[0, 3] > 0.0
    assert np.abs(table[:, 10:12]).max() < 1e-9


def test_simulate_rejects_unknown_engine_and_bad_duration(tmp_path, capsys):
    code, _, err = run_cli(capsys, "simulate", str(RIGS / "plate.toml"), "--engine", "bogus",
                           "--duration", "1", "--out", str(tmp_path / "x.csv"))
    assert code == 2 and "--engine: invalid choice: 'bogus'" in err and "mujoco-eq" in err and err.count("\n") == 1
    code, _, err = run_cli(capsys, "simulate", str(RIGS / "plate.toml"), "--duration", "nan",
                           "--out", str(tmp_path / "x.csv"))
    assert code == 2 and "--duration" in err
    assert not (tmp_path / "x.csv").exists()


def test_mujoco_output_step_must_be_whole_time_steps(tmp_path, capsys):
    code, _, err = run_cli(capsys, "simulate", str(RIGS / "plate.toml"), "--engine", "mujoco", "--duration", "0.1",
                           "--dt-out", "0.0123457", "--out", str(tmp_path / "x.csv"))
    assert code == 2 and err.startswith("error: --dt-out: ") and err.count("\n") == 1
    assert not (tmp_path / "x.csv").exists()


def test_jobs_must_be_positive(capsys):
    code, _, err = run_cli(capsys, "all", "--jobs", "0")
    assert code == 2 and "--jobs must be at least 1" in err


def test_a_wire_that_must_push_at_the_start_is_refused_by_the_kane_engine(tmp_path, capsys):
    """The thin plate tilted 0.9 rad about x: wire 2 would have to push from t = 0 (MuJoCo reads 0 N).
    The taut-wire model has no motion to start, so nothing is written (a CSV row with the negative
    tension the taut model needs would contradict "0 when slack")."""
    path = tmp_path / "push.toml"
    path.write_text((RIGS / "sidesway.toml").read_text() + "\n[initial]\nrotation = [0.9, 0.0, 0.0]\n")
    out = tmp_path / "push.csv"
    code, _, err = run_cli(capsys, "simulate", str(path), "--duration", "1", "--out", str(out))
    assert code == 2 and err.count("\n") == 1
    assert err.startswith(f"error: {path}: initial: ") and "wire[2] goes slack at once" in err
    assert not out.exists()


def test_the_last_sample_survives_rounding(tmp_path, capsys):
    """3 x 0.1 > 0.3 in floating point: the sample at 0.3 s must still be written, by both engines."""
    for engine in ("kane", "mujoco"):
        out = tmp_path / f"{engine}.csv"
        assert run_cli(capsys, "simulate", str(RIGS / "plate.toml"), "--engine", engine, "--duration", "0.3",
                       "--dt-out", "0.1", "--out", str(out))[0] == 0
        assert out.read_text().splitlines()[-1].startswith("0.3,")


@pytest.mark.parametrize(
    "content, field, words",
    [
        (b"\xff\xfe not text", "file", "not UTF-8"),
        (GOOD.replace('name = "plate"', 'name = "../x y"').encode(), "name", "letters, digits"),
        # Hooks exactly l + b' + l' apart: a flat loop, infinite tension.
        (GOOD.replace("anchor = [0.0, 5.0,", "anchor = [0.0, 10.0,").encode(), "wire", "not shorter"),
    ],
)
def test_more_bad_rig_files(tmp_path, capsys, content, field, words):
    path = tmp_path / "bad.toml"
    path.write_bytes(content)
    code, _, err = run_cli(capsys, "modes", str(path))
    assert code == 2 and err.startswith(f"error: {path}: {field}: ") and words in err and err.count("\n") == 1


def test_unwritable_output_is_one_line(tmp_path, capsys):
    code, _, err = run_cli(capsys, "simulate", str(RIGS / "plate.toml"), "--duration", "0.1", "--out", str(tmp_path))
    assert code == 2 and err == f"error: {tmp_path}: cannot write (is a directory)\n"


def test_the_csv_reads_back_as_written(tmp_path, capsys):
    from validate.engines.kane import run
    from validate.trajectory import read_rig_csv

    out = tmp_path / "plate.csv"
    assert run_cli(capsys, "simulate", str(RIGS / "plate.toml"), "--duration", "1", "--dt-out", "0.1",
                   "--out", str(out))[0] == 0
    back = read_rig_csv(out)
    direct = run(load_rig(RIGS / "plate.toml"), 1.0, 0.1)
    np.testing.assert_array_equal(back.t, direct.t)  # repr() of floats round-trips exactly
    for name in ("com", "quat", "tension", "length_error"):
        np.testing.assert_array_equal(back[name], direct[name])


def test_every_pair_of_wires_must_close_its_loop(tmp_path, capsys):
    """The trifilar platform with wire 3's attachment moved 3.5 m out: wires 1-2 close their loop, but
    wires 1 and 3 cannot (attachment span 3.81 m > 0.52 + 1.5 + 1.5 m): one line naming that pair."""
    text = (RIGS / "trifilar.toml").read_text()
    data = tomllib.loads(text)
    attach = data["wire"][2]["attach"]
    path = tmp_path / "far.toml"
    path.write_text(text.replace(f"attach = [{attach[0]!r}, {attach[1]!r}, {attach[2]!r}]",
                                 f"attach = [-3.5, {attach[1]!r}, {attach[2]!r}]"))
    assert main(["modes", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "no taut pose" in err and "wires 1 and 3" in err, err


@pytest.mark.parametrize("line, field", [
    ("density = 1e30", "air.density"),  # had given periods of 1e15 s
    ("density = 1e-30", "air.density"),
    ("viscosity = 1e9", "air.viscosity"),
    ("size = [1e9, 0.02, 0.18]", "air.size[0]"),
    ("size = [1e-9, 0.02, 0.18]", "air.size[0]"),
    ("added_std = 2.0", "air.added_std"),
])
def test_air_fields_have_physical_ranges(tmp_path, capsys, line, field):
    key = line.split(" =")[0]
    text = "\n".join(line if row.startswith(f"{key} =") else row
                     for row in (RIGS / "foam_wing.toml").read_text().splitlines())
    path = tmp_path / "wing.toml"
    path.write_text(text + "\n")
    assert main(["modes", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"{path}: {field}: " in err, err
