"""``sweep --rerun``: DIR/sweep.rrd read back with rerun's own reader holds the table of sweep.csv (the
objective, sigmas and periods per configuration, bit for bit; infeasible rows marked) and the MuJoCo
check's motion, and opens on the configuration timeline with the map, the series and the table; a path
that cannot be written is exit 2 before any work."""

import csv
import json
import time

import numpy as np
import pytest
from rerun.chunk import RrdReader
from rrd_check import timeline, verify, views

from validate.cli import main
from validate.recording import SLACK_RGB
from validate.studies.sweep_check import CYCLES

from test_sweep import PARALLEL as RIG  # the vertical-wire rig with an [uncertainty] of the sweep tests

# Wires of 0.1 m cannot reach attachments 0.4 m apart from anchors 1.0 m apart: one infeasible row.
SPACE = 'rig = "rig.toml"\n[vary]\nanchor_span = [0.4, 1.0]\nwire_length = [0.1, 0.8]\n[measure]\naxes = ["z"]\n'


def _read(path) -> dict[str, dict]:
    """entity -> {component or timeline: values}, static and temporal chunks merged."""
    out: dict[str, dict] = {}
    for chunk in RrdReader(path).stream():
        batch = chunk.to_record_batch()
        entry = out.setdefault(chunk.entity_path.lstrip("/"), {})
        for name in batch.schema.names:
            if ":" in name or name in ("configuration", "sim_time"):
                entry.setdefault(name, []).extend(batch.column(name).to_pylist())
    return out


def _sweep(tmp_path, *extra):
    (tmp_path / "rig.toml").write_text(RIG)
    (tmp_path / "space.toml").write_text(SPACE)
    return main([str(a) for a in ("sweep", tmp_path / "space.toml", "--out", tmp_path / "out", "--jobs", 1, *extra)])


@pytest.mark.slow
def test_rerun_holds_the_table_and_the_mujoco_motion(tmp_path, capsys):
    assert _sweep(tmp_path, "--rerun", "--check-mujoco", 1) == 0
    out = tmp_path / "out"
    with open(out / "sweep.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    summary = json.loads((out / "summary.json").read_text())
    rec = _read(out / "sweep.rrd")
    feasible = [r["feasible"] == "true" for r in rows]
    assert feasible.count(False) == 1

    # the objective (worst sigma over ["z"]: sigma_z) of the feasible rows, bit for bit, at their row index
    objective = rec["sweep/series/objective"]
    assert objective["configuration"] == [i for i, ok in enumerate(feasible) if ok]
    sigma_z = [float(rows[i]["sigma_z"]) for i in objective["configuration"]]
    assert [v[0] for v in objective["Scalars:scalars"]] == sigma_z
    assert [v[0] for v in rec["sweep/series/feasible"]["Scalars:scalars"]] == [float(ok) for ok in feasible]
    for axis in ("anchor_span", "wire_length"):
        assert [v[0] for v in rec[f"sweep/series/axes/{axis}"]["Scalars:scalars"]] == [float(r[axis]) for r in rows]

    # the map: one point per row at its axis values (float32), infeasible ones red and saying why
    points = rec["sweep/map"]
    positions = np.array(points["Points3D:positions"][0])
    most_varied = ("anchor_span", "wire_length")  # both have two values: file order
    np.testing.assert_allclose(positions[:, :2], [[float(r[a]) for a in most_varied] for r in rows], rtol=1e-7)
    packed = np.array(points["Points3D:colors"][0], dtype=np.uint32)
    red = [tuple(int(packed[i] >> s) & 0xFF for s in (24, 16, 8)) == SLACK_RGB for i in range(len(rows))]
    assert red == [not ok for ok in feasible]
    labels = points["Points3D:labels"][0]
    assert all(("infeasible" in label) == (not ok) for label, ok in zip(labels, feasible))
    best = summary["best"]
    assert rec["sweep/map/best"]["Points3D:labels"][0][0].startswith(
        f"best: anchor_span = {best['anchor_span']:g}, wire_length = {best['wire_length']:g}")

    # the MuJoCo check's run of the best configuration: wires and body over five periods of its yaw
    (mode,) = summary["mujoco_check"][0]["modes"]
    (run,) = {e.rsplit("/", 1)[0] for e in rec if e.startswith("world/rank1_z/") and e.endswith("/body")}
    body = rec[f"{run}/body"]
    assert len(rec[f"{run}/wires"]["LineStrips3D:strips"][0]) == 2
    span = (body["sim_time"][-1] - body["sim_time"][0]).total_seconds()
    assert abs(span - CYCLES * mode["predicted"]) <= mode["predicted"] / 200  # one sample step
    assert "MuJoCo check rank1" in rec["summary"]["TextDocument:text"][0][0]

    # the periods per configuration, bit for bit, where a row has them (vertical wires: mode 1, the
    # tilt about the line through the attachments, is neutral and has none)
    assert not any(r["period_1"] for r in rows) and "Scalars:scalars" not in rec["sweep/series/period_1"]
    for k in (2, 3, 4):
        period = rec[f"sweep/series/period_{k}"]
        assert period["configuration"] == [i for i, r in enumerate(rows) if r[f"period_{k}"]]
        assert [v[0] for v in period["Scalars:scalars"]] == [float(rows[i][f"period_{k}"]) for i in period["configuration"]]

    # the layout: opens on the configuration timeline, with the map, the series and the table
    verify(out / "sweep.rrd")
    assert timeline(out / "sweep.rrd") == "configuration"
    shown = views(out / "sweep.rrd")
    assert shown["configurations"] == ("3D", "sweep/map") and shown["table"] == ("Dataframe", "sweep/series")
    assert shown["periods (s)"] == ("TimeSeries", "sweep/series") and shown["rig"] == ("3D", "world")


def test_a_bad_rerun_path_is_exit_2_before_any_work(tmp_path, capsys):
    (tmp_path / "out" / "sweep.rrd").mkdir(parents=True)
    start = time.perf_counter()
    code = _sweep(tmp_path, "--rerun", "--check-mujoco", 1)
    out, err = capsys.readouterr()
    assert code == 2 and out == "" and err.count("\n") == 1 and "sweep.rrd" in err, err
    assert not (tmp_path / "out" / "sweep.csv").exists()
    assert time.perf_counter() - start < 2.0  # the sweep and the MuJoCo run would take several seconds
