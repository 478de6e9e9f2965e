"""Sweeps (bifilar/sweep, python -m validate sweep): every CSV field against an independent computation
for a few rows, the parallel-wire closed form, Dask against local, resuming, bad sweep files."""

import csv
import json
import math

import numpy as np
import pytest

from bifilar.identification import identify as ident
from bifilar.motion.kane import KaneModel
from bifilar.motion.modes import linearize
from bifilar.motion.simulate import simulate
from bifilar.rig.statics import rest_pose
from bifilar.sweep import run as sweep_run
from bifilar.sweep.axes import configure
from bifilar.sweep.evaluate import evaluate, lowest_point, measured_mode, peak_tension
from bifilar.sweep.space import load_space
from validate.cli import main

PARALLEL = """name = "parallel_unc"
[body]
mass = 2.0
inertia = [0.02, 0.05, 0.06]
[[wire]]
anchor = [-0.2, 0.0, 1.5]
attach = [-0.2, 0.0, 0.0]
length = 1.5
[[wire]]
anchor = [0.2, 0.0, 1.5]
attach = [0.2, 0.0, 0.0]
length = 1.5
[uncertainty]
length = 2e-3
mass = 1e-2
period = 3e-3
"""


def _write(tmp_path, space: str, rig: str = PARALLEL):
    (tmp_path / "rig.toml").write_text(rig)
    (tmp_path / "space.toml").write_text(space)
    return tmp_path / "space.toml"


def _cli(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def test_parallel_yaw_sigma_matches_the_closed_form_propagation(tmp_path):
    """(5.2.18) I = m g D^2 T^2 / (16 pi^2 h): with only m, both wire lengths (h = their mean for the
    torsion of vertical wires: dh = (dL1 + dL2) / 2) and T uncertain, (sigma_I / I)^2 =
    (sigma_m / m)^2 + (2 sigma_T / T)^2 + (sigma_L / (sqrt 2 h))^2. The sweep's forward differences
    (step 1e-3 sigma) are good to ~1e-6 relative."""
    path = _write(tmp_path, 'rig = "rig.toml"\n[vary]\nwire_length = [1.0, 2.5]\n[measure]\naxes = ["z"]\n')
    space = load_space(path)
    for values in space.points():
        row = evaluate(space, values)
        h, m, D, I = values["wire_length"], 2.0, 0.4, 0.06
        T = 2 * np.pi * np.sqrt(16 * np.pi**2 * h * I / (m * 9.81 * D**2)) / (2 * np.pi)
        assert max(p for p in row.periods if p) >= T  # the yaw is one of the modes
        closed = math.sqrt((1e-2 / m) ** 2 + (2 * 3e-3 / T) ** 2 + (2e-3 / (math.sqrt(2) * h)) ** 2)
        assert row.sigma["z"] == pytest.approx(closed, rel=1e-5)
        assert row.tensions == pytest.approx((m * 9.81 / 2, m * 9.81 / 2), rel=1e-12)  # vertical wires


@pytest.mark.slow
def test_every_csv_field_against_an_independent_computation(tmp_path, capsys):
    path = _write(
        tmp_path,
        'rig = "../../models/rigs/bench_plate.toml"\n[vary]\nwire_length = [1.0, 2.0]\nattach_span = [0.3, 0.5]\n'
        '[limits]\ntension = 20.5\nfloor = 0.5\nclearance = 0.02\n[measure]\naxes = ["x", "z"]\namplitude = 0.05\n',
        rig="",
    )
    (tmp_path / "space.toml").write_text((tmp_path / "space.toml").read_text().replace(
        "../../models/rigs/bench_plate.toml", str((__import__("pathlib").Path(__file__).parents[1] / "models/rigs/bench_plate.toml").resolve())))
    code, out, err = _cli(capsys, "sweep", path, "--out", tmp_path / "out", "--jobs", 1)
    assert code == 0, err
    # one summary (wrapped at 100 columns, continuations indented), no edge warning on a 2 x 2 grid
    assert out.startswith("sweep space.toml: 4 configurations") and "warning" not in out
    assert all(len(line) <= 100 and (k == 0 or line.startswith("  ")) for k, line in enumerate(out.splitlines()))
    rows = list(csv.DictReader(open(tmp_path / "out" / "sweep.csv")))
    assert list(rows[0])[:16] == ["wire_length", "attach_span", "period_1", "period_2", "period_3", "period_4",
                                  "tension_1", "tension_2", "tension_peak", "sigma_x", "sigma_y", "sigma_z",
                                  "clearance", "feasible", "motion_1", "motion_2"]
    space = load_space(path)
    for row in rows:
        rig = configure(space.rig, {"wire_length": float(row["wire_length"]), "attach_span": float(row["attach_span"])})
        # attach_span moves both attachments symmetrically along their line.
        assert np.linalg.norm(rig.wires[0].attach - rig.wires[1].attach) == pytest.approx(float(row["attach_span"]))
        rest = rest_pose(rig)  # SLSQP from scratch, not the sweep's continuation
        lin = linearize(rig, rest)
        assert [float(row[f"period_{k}"]) for k in range(1, 5)] == pytest.approx([m.period for m in lin.modes], rel=1e-10)
        assert [float(row["tension_1"]), float(row["tension_2"])] == pytest.approx(rest.tensions, rel=1e-10)
        assert row["sigma_y"] == ""  # not measured
        for axis in ("x", "z"):
            found = ident.invert_period(rig, axis, ident.linear_period(rig, axis, rest), rest)
            from bifilar.identification.propagation import linear

            spread = linear(rig, axis, found.period, rig.uncertainty.period, rest)
            assert float(row[f"sigma_{axis}"]) == pytest.approx(spread.std / spread.moment, rel=1e-9)
        assert float(row["clearance"]) == pytest.approx(lowest_point(rig, rest) - 0.5, abs=1e-12)
        peak = float(row["tension_peak"])
        assert peak >= rest.tensions.max()
        feasible = peak <= 20.5 and float(row["clearance"]) >= 0.02
        assert row["feasible"] == ("true" if feasible else "false")
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["n"] == 4 and summary["feasible"] == sum(r["feasible"] == "true" for r in rows)
    if summary["best"]:
        worst = [max(float(r["sigma_x"]), float(r["sigma_z"])) for r in rows if r["feasible"] == "true"]
        assert summary["best"]["objective"] == pytest.approx(min(worst), rel=1e-12)
    assert not (tmp_path / "out" / ".chunks").exists()


def test_peak_tension_against_the_kane_model():
    """The bottom-of-swing tension is exact, the turning points first order: against the Kane model's
    simulated tensions over two periods of the yaw released at 0.05 rad, the peak's excess over the
    static tension agrees to 5 % (the neglected second-order turning-point terms)."""
    from validate.assets import rig as shipped

    rig = shipped("bench_plate")
    rest = rest_pose(rig)
    lin = linearize(rig, rest)
    release = ident.released(rig, "z", 0.05, rest)
    run = simulate(KaneModel.from_rig(rig), release.state, 2 * release.period, dt_out=release.period / 400)
    index = measured_mode(rig, lin, release.axis_world)
    ours = peak_tension(rig, lin, index, release.axis_world, 0.05)
    kane = run.tension.max()
    assert (ours - rest.tensions.max()) == pytest.approx(kane - rest.tensions.max(), rel=0.05)


@pytest.mark.slow
def test_dask_cluster_gives_the_local_rows_bit_for_bit_and_a_sweep_resumes(tmp_path):
    from dask.distributed import Client, LocalCluster

    path = _write(tmp_path, 'rig = "rig.toml"\n[vary]\nwire_length = {from = 1.0, to = 2.0, steps = 3}\n'
                            'attach_span = [0.3, 0.4]\n[measure]\naxes = ["z"]\n')
    space = load_space(path)
    local = list(sweep_run.run(str(path), space, tmp_path / "a", jobs=1, chunk=2).rows())
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                      dashboard_address=None) as cluster, Client(cluster):
        remote = list(sweep_run.run(str(path), space, tmp_path / "b", scheduler=cluster.scheduler_address,
                                    chunk=2).rows())
    assert json.dumps(remote) == json.dumps(local)
    # Interrupted after the first chunk: a restart reuses it (a changed saved row shows it was read).
    chunks = tmp_path / "c" / ".chunks" / sweep_run.digest(str(path), 2)
    chunks.mkdir(parents=True)
    first = sweep_run.run_chunk(str(path), 0, 2)
    first[0]["reason"] = "from the saved chunk"
    (chunks / "000000.json").write_text(json.dumps(first))
    resumed = list(sweep_run.run(str(path), space, tmp_path / "c", jobs=1, chunk=2).rows())
    assert resumed[0]["reason"] == "from the saved chunk" and json.dumps(resumed[1:]) == json.dumps(local[1:])


@pytest.mark.parametrize("space, field", [
    ('rig = "rig.toml"\n[vary]\nwire_lenght = [1.0]\n', "vary.wire_lenght"),
    ('rig = "rig.toml"\n[vary]\nwire_length = []\n', "vary.wire_length"),
    ('rig = "rig.toml"\n[vary]\nwire_length = {from = 1.0, to = 1.0, steps = 3}\n', "vary.wire_length"),
    ('rig = "rig.toml"\n[vary]\nwire_length = {from = 1.0, to = 2.0, steps = 10000}\n'
     'anchor_span = {from = 1.0, to = 2.0, steps = 10000}\n', "vary"),
    ('rig = "rig.toml"\n[vary]\nwire_length = [-1.0]\n', "vary.wire_length"),
    ('rig = "nope.toml"\n[vary]\nwire_length = [1.0]\n', "nope.toml"),
    ('rig = "rig.toml"\n[vary]\nwire_length = [1.0]\n[measure]\naxes = ["w"]\n', "measure.axes"),
    ('rig = "rig.toml"\n[vary]\nwire_length = [1.0]\n[limits]\nseparation = 1.5\n', "limits.separation"),
    ('rig = "rig.toml"\n[vary]\nwire_length = [1.0]\n[limits]\nseparation = 0.0\n', "limits.separation"),
])
def test_bad_sweep_files_are_one_line_exit_2(tmp_path, capsys, space, field):
    path = _write(tmp_path, space)
    code, out, err = _cli(capsys, "sweep", path, "--out", tmp_path / "out")
    assert code == 2 and out == "" and err.count("\n") == 1 and field in err, err


def test_a_least_separation_keeps_the_measured_mode_clear_of_the_others(tmp_path, capsys):
    """bench_plate's attachments drawn in from 0.35 to 0.15 m apart slow its yaw (2.40 -> 3.65 s) through
    its two sways (2.76-2.85 s): each row's near_z is the yaw's gap in frequency to the nearest other mode,
    as identify's pencil gives it on the configured rig (the continued rows' compiled modes against
    eigh), and with limits.separation = 0.05 exactly the rows under it are infeasible, saying so, and the
    best is not among them (a sway within a beat or so of the yaw over a record hides in its law)."""
    rig_path = (__import__("pathlib").Path(__file__).parents[1] / "models/rigs/bench_plate.toml").resolve()
    path = _write(tmp_path, f'rig = "{rig_path}"\n[vary]\nattach_span = {{from = 0.15, to = 0.35, steps = 21}}\n'
                            '[limits]\nseparation = 0.05\n[measure]\naxes = ["z"]\n', rig="")
    code, _, err = _cli(capsys, "sweep", path, "--out", tmp_path / "out", "--jobs", 1)
    assert code == 0, err
    rows = list(csv.DictReader(open(tmp_path / "out" / "sweep.csv")))
    space = load_space(path)
    under = []
    for row in rows:
        p = ident.pencil(configure(space.rig, {"attach_span": float(row["attach_span"])}), "z")
        k, w2, _ = p.associated(p.moment0)
        periods = 2.0 * math.pi / np.sqrt(w2)
        gap = min(abs(periods[k] / periods[j] - 1.0) for j in range(len(w2)) if j != k)
        assert float(row["near_z"]) == pytest.approx(gap, rel=1e-7)  # ~1e-2 from periods equal to 1e-10
        assert row["near_x"] == row["near_y"] == ""  # not measured
        assert (row["feasible"] == "true") == (gap >= 0.05)
        if gap < 0.05:
            under.append(row["attach_span"])
            assert "the z mode" in row["reason"] and "from another mode's frequency, under 5 %" in row["reason"]
    assert 4 <= len(under) <= 8  # the crossing: measured 0.23-0.28 m, near_z down to 0.0073
    best = json.loads((tmp_path / "out" / "summary.json").read_text())["best"]
    assert best is not None and float(best["attach_span"]) not in map(float, under)


def test_unreachable_points_inside_a_valid_grid_are_infeasible_rows(tmp_path):
    """Wires of 0.1 m cannot reach attachments 0.4 m apart from anchors 1.0 m apart: a row, not an error."""
    path = _write(tmp_path, 'rig = "rig.toml"\n[vary]\nanchor_span = [0.4, 1.0]\nwire_length = [0.1]\n'
                            '[measure]\naxes = ["z"]\n')
    rows = list(sweep_run.run(str(path), load_space(path), tmp_path / "o", jobs=1).rows())
    assert [r["feasible"] for r in rows] == [True, False] and "no taut pose" in rows[1]["reason"]


def test_trifilar_axes_move_every_wire(tmp_path):
    """platform_radius and wire_length on the three-wire platform: the yaw period of every row is the
    closed form 2 pi sqrt(L I / (M g R^2)) of vertical wires (exact in the linear limit)."""
    from validate.assets import MODELS

    rig = (MODELS / "rigs" / "trifilar.toml").read_text() + "\n[uncertainty]\nlength = 1e-3\nmass = 1e-3\nperiod = 1e-3\n"
    path = _write(tmp_path, 'rig = "rig.toml"\n[vary]\nplatform_radius = [0.2, 0.3]\nwire_length = [1.0, 2.0]\n'
                            '[measure]\naxes = ["z"]\n', rig=rig)
    space = load_space(path)
    for values in space.points():
        row = evaluate(space, values)
        R, L = values["platform_radius"], values["wire_length"]
        closed = 2 * np.pi * np.sqrt(L * 0.1225 / (2.0 * 9.81 * R**2))
        yaw = [p for p, m in zip(row.periods, row.motions) if m == "yaw"]
        assert yaw == pytest.approx([closed], rel=1e-10) and row.sigma["z"] > 0 and row.feasible


def test_a_sweep_in_air_says_how_much_of_each_period_is_air(tmp_path):
    """The foam wing's yaw (air 17.0 % of the measured yaw inertia, case air-wing-share): the sweep's
    air share of the yaw period at the rig's own wire length is the share of the apparent moment,
    I_A / (I + I_A), for this pure rotation, to the modes' coupling (1e-3)."""
    from bifilar.rig.air import added_inertia
    from validate.assets import MODELS, rig as shipped

    wing = shipped("foam_wing")
    text = (MODELS / "rigs" / "foam_wing.toml").read_text()
    if "[uncertainty]" not in text:
        text += "\n[uncertainty]\nlength = 1e-3\nmass = 1e-3\nperiod = 1e-3\n"
    path = _write(tmp_path, f'rig = "rig.toml"\n[vary]\nwire_length = [{wing.wires[0].length!r}]\n[measure]\naxes = ["z"]\n',
                  rig=text)
    row = sweep_run.run_chunk(str(path), 0, 1)[0]
    own = wing.inertia[2, 2]
    air = added_inertia(wing.air, wing.com, np.array([0.0, 0.0, 1.0]))
    assert row["air_share"]["z"] == pytest.approx(air / (own + air), rel=1e-3)
    assert row["air_share"]["x"] is None  # not measured


# --- explicit points and suspension files (issue 10, item 6) ------------------------------------

POINTS = 'rig = "rig.toml"\n[[point]]\nname = "a"\nwire_length = 1.0\nattach_span = 0.3\n' \
         '[[point]]\nwire_length = 2.5\nattach_span = 0.6\n[measure]\naxes = ["z"]\n'


def test_points_are_evaluated_in_file_order_as_given(tmp_path):
    """Two [[point]] tables: two configurations, not their 2 x 2 grid, each configured as written."""
    space = load_space(_write(tmp_path, POINTS))
    assert space.size == 2 and space.names == ("a", None)
    assert list(space.points()) == [{"wire_length": 1.0, "attach_span": 0.3}, {"wire_length": 2.5, "attach_span": 0.6}]
    rows = sweep_run.run(str(tmp_path / "space.toml"), space, tmp_path / "o", jobs=1).rows()
    for values, row in zip(space.points(), rows):
        rig = configure(space.rig, values)
        assert rig.wires[0].length == values["wire_length"]
        assert np.linalg.norm(rig.wires[0].attach - rig.wires[1].attach) == pytest.approx(values["attach_span"], rel=1e-15)
        expected = [m.period for m in linearize(rig, rest_pose(rig)).modes]
        # A neutral mode's period is None (no restoring force): it must be None in the row at the same
        # place; the others agree to the eigen-solver's rounding (same formulation, rel 1e-10).
        assert [p is None for p in row["periods"]] == [p is None for p in expected]
        assert [p for p in row["periods"] if p is not None] == pytest.approx([p for p in expected if p is not None],
                                                                              rel=1e-10)


def test_attach_inset_moves_both_attachments_in_from_the_base():
    """attach_inset d: each attachment moves d towards the other, so the span shrinks by 2 d and the
    midpoint stays."""
    from validate.assets import rig as shipped

    rig = shipped("bench_plate")
    moved = configure(rig, {"attach_inset": 0.05})
    a, b = rig.wires[0].attach, rig.wires[1].attach
    unit = (b - a) / np.linalg.norm(b - a)
    np.testing.assert_allclose(moved.wires[0].attach, a + 0.05 * unit, atol=1e-15)
    np.testing.assert_allclose(moved.wires[1].attach, b - 0.05 * unit, atol=1e-15)


@pytest.mark.parametrize("space, field", [
    (POINTS.replace("attach_span = 0.6\n", ""), "point[2]"),  # not the same axes
    (POINTS.replace('name = "a"\n', 'name = "a"\nwire_lenght = 1.0\n'), "point[1].wire_lenght"),
    (POINTS.replace("wire_length = 2.5", "wire_length = -2.5"), "point[2].wire_length"),
    (POINTS.replace("wire_length = 2.5", 'wire_length = "long"'), "point[2].wire_length"),
    (POINTS.replace("[[point]]\nwire_length = 2.5", '[[point]]\nname = "a"\nwire_length = 2.5'), "point[2].name"),
    (POINTS.replace('[[point]]\nname = "a"\n', '[vary]\nwire_length = [1.0]\n[[point]]\nname = "a"\n'), "vary"),
    ('rig = "rig.toml"\n[[point]]\nname = "only"\n', "point[1]"),
    ('rig = "rig.toml"\n[[point]]\nattach_inset = 0.2\n', "point[1].attach_inset"),  # half the 0.4 m span
    ('rig = "rig.toml"\n[vary]\nattach_inset = [0.1]\nattach_span = [0.3]\n', "attach_inset"),
    ('rig = "rig.toml"\nsuspension = "rig.toml"\n[vary]\nwire_length = [1.0]\n', "rig"),
])
def test_bad_points_are_one_line_exit_2(tmp_path, capsys, space, field):
    test_bad_sweep_files_are_one_line_exit_2(tmp_path, capsys, space, field)


def test_boat_sweep_files_load_as_the_suspension_hangs_the_boat():
    """models/solar_boat/configurations.toml: the thesis's three configurations, whose rigs are
    suspension.toml's; hall.toml: a grid on the same base, the hall's floor, the parts' clearance."""
    from bifilar.bodies.boat import load_suspension
    from bifilar.bodies.boat import lowest_point as parts_lowest
    from validate.assets import MODELS

    boat = MODELS / "solar_boat"
    s = load_suspension(boat / "suspension.toml")
    configurations = load_space(boat / "configurations.toml")
    assert configurations.names == tuple(c.name for c in s.configurations)
    for values, c in zip(configurations.points(), s.configurations):
        for mine, theirs in zip(configure(configurations.rig, values).wires, s.rig(c).wires):
            np.testing.assert_allclose(mine.attach, theirs.attach, atol=1e-15)
            np.testing.assert_array_equal(mine.anchor, theirs.anchor)
            assert mine.length == theirs.length
    hall = load_space(boat / "hall.toml")
    assert hall.limits.floor == -6.5 and len(hall.parts) == len(s.parts) and 1000 < hall.size < 3000  # < 2 min, 2 cores
    assert set(hall.axes) == {"attach_inset", "wire_length"}
    rig = configure(hall.rig, {"attach_inset": 1.0, "wire_length": 4.0})
    rest = rest_pose(rig)
    row = evaluate(hall, {"attach_inset": 1.0, "wire_length": 4.0})
    low, _ = parts_lowest(s.parts, rest.com - rest.rotation @ rig.com, rest.rotation)
    assert row.clearance == pytest.approx(low[0] + 6.5, abs=1e-9)  # the foils, not the inertia box
    assert row.clearance < lowest_point(rig, rest) + 6.5 - 0.3  # the box ends ~0.55 m higher


def test_resume_digest_follows_every_file_the_sweep_reads(tmp_path):
    """A boat sweep reads its suspension file and that file's parts file: a changed part mass is a
    different sweep, whose saved chunks must not be resumed."""
    import shutil

    from bifilar.sweep.run import digest
    from validate.assets import MODELS

    folder = tmp_path / "solar_boat"
    shutil.copytree(MODELS / "solar_boat", folder)
    before = digest(str(folder / "configurations.toml"), 64)
    parts = folder / "parts.toml"
    parts.write_text(parts.read_text().replace("mass = 15.0", "mass = 15.5", 1))
    assert digest(str(folder / "configurations.toml"), 64) != before
    assert digest(str(folder / "configurations.toml"), 64) == digest(str(folder / "configurations.toml"), 64)


def test_a_chunk_of_points_is_that_slice_of_the_grid():
    """points(start, stop), reached from the index (C order, the last axis fastest), is the slice of
    the whole grid in grid order; for explicit points, of the file's list."""
    from validate.assets import MODELS

    for name in ("sweeps/bench_plate.toml", "solar_boat/configurations.toml"):
        space = load_space(MODELS / name)
        every = list(space.points())
        assert len(every) == space.size
        assert list(space.points(1, space.size - 1)) == every[1:-1]
    grid = list(load_space(MODELS / "sweeps" / "bench_plate.toml").points(0, 2))
    assert grid[0]["attach_span"] != grid[1]["attach_span"] and grid[0]["wire_length"] == grid[1]["wire_length"]
