"""Recordings read back with rerun's own reader (``rerun.chunk.RrdReader``) hold what was simulated.

Scalars are stored as float64, so plotted channels must come back bit for bit; 3D geometry is stored
as float32, so positions are checked to float32 resolution (~6e-8 relative) of a 5 m scene.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from rerun.chunk import RrdReader
from scipy.spatial.transform import Rotation

from validate.assets import rig
from validate.engines import kane
from validate.recording import (
    SLACK_RGB,
    VIRIDIS,
    inertia_box,
    record,
    record_case,
    record_trajectory,
    tension_colors,
)
from validate.registry import check
from validate.suite import CaseResult
from validate.trajectory import Trajectory

DURATION = 2.0
F32 = 5.0 * 2.0**-23 * 4  # a few float32 ulps of a 5 m coordinate


def read(path) -> dict[str, dict]:
    """entity -> {"static": {component: pylist}, "time": ns array, component: per-row pylists}."""
    out: dict[str, dict] = {}
    for chunk in RrdReader(path).stream():
        batch = chunk.to_record_batch()
        entry = out.setdefault(chunk.entity_path.lstrip("/"), {"static": {}})
        data = {n: batch.column(n).to_pylist() for n in batch.schema.names if ":" in n}
        if chunk.is_static:
            entry["static"].update(data)
            continue
        time = batch.column("sim_time").cast("int64").to_numpy()
        assert "time" not in entry, f"{chunk.entity_path}: split over several chunks; concatenate them here"
        entry["time"] = time
        entry.update(data)
    return out


def scalars(entry: dict) -> np.ndarray:
    return np.array(entry["Scalars:scalars"], dtype=float)


@pytest.fixture(scope="module")
def plate_run() -> Trajectory:
    return kane.run(rig("plate"), DURATION, 0.01, 1e-10)


@pytest.fixture(scope="module")
def plate_rec(plate_run, tmp_path_factory):
    path = record_trajectory(plate_run, tmp_path_factory.mktemp("rec") / "plate.rrd")
    return read(path)


def test_entities_of_a_rig_run(plate_rec):
    base = "world/plate/kane"
    expected = {"world/plate/anchors", f"{base}/wires", f"{base}/body", f"{base}/body/box", f"{base}/trail", "summary"}
    expected |= {f"plots/{c}/kane" for c in ("tension", "theta", "length_error", "energy", "com", "quat")}
    assert expected <= plate_rec.keys()
    assert not any(e.startswith("diff/") for e in plate_rec), "one run: nothing to compare"
    assert len(plate_rec["world/plate/anchors"]["static"]["Points3D:positions"][0]) == 2


def test_time_range_is_the_simulated_span(plate_run, plate_rec):
    n = len(plate_run.t)
    assert plate_run.t[0] == 0.0 and abs(plate_run.t[-1] - DURATION) < 1e-12
    for entity, entry in plate_rec.items():
        if "time" in entry:
            assert len(entry["time"]) == n, entity
            assert entry["time"][0] == 0 and entry["time"][-1] == round(DURATION * 1e9), entity
            # ns ticks: each sample within half a nanosecond of the engine's time
            assert np.max(np.abs(entry["time"] - plate_run.t * 1e9)) <= 0.5, entity


def test_plotted_channels_are_bit_exact(plate_run, plate_rec):
    for channel in ("tension", "theta", "length_error", "energy", "com"):
        logged = scalars(plate_rec[f"plots/{channel}/kane"])
        np.testing.assert_array_equal(logged, np.asarray(plate_run[channel]).reshape(len(plate_run.t), -1))
    names = plate_rec["plots/tension/kane"]["static"]["SeriesLines:names"][0]
    assert names == ["kane wire 1", "kane wire 2"]


def test_wires_run_from_anchor_to_attachment(plate_run, plate_rec):
    """The logged wire ends, to float32 resolution, are the anchors and the attachments the run
    implies, so their length is the wire length (5 m) plus the run's length error (< 1e-9 m)."""
    r = plate_run.meta["rig_spec"]
    wires = plate_rec["world/plate/kane/wires"]
    strips = np.array(wires["LineStrips3D:strips"])  # (n, wire, end, xyz)
    rot = Rotation.from_quat(plate_run["quat"], scalar_first=True)
    for k, w in enumerate(r.wires):
        np.testing.assert_allclose(strips[:, k, 0], np.broadcast_to(w.anchor, (len(plate_run.t), 3)), atol=F32)
        attach = plate_run["com"] + rot.apply(w.attach - r.com)
        np.testing.assert_allclose(strips[:, k, 1], attach, atol=F32)
        length = np.linalg.norm(strips[:, k, 1] - strips[:, k, 0], axis=1)
        np.testing.assert_allclose(length, w.length, atol=2 * F32)
    assert wires["LineStrips3D:labels"][0] == [f"{v:.1f} N" for v in plate_run["tension"][0]]
    packed = np.array(wires["LineStrips3D:colors"], dtype=np.uint32)
    rgb = np.stack([(packed >> s) & 0xFF for s in (24, 16, 8)], axis=-1)
    np.testing.assert_array_equal(rgb, tension_colors(plate_run["tension"], plate_run["tension"].max()))


def test_body_pose_and_inertia_box(plate_run, plate_rec):
    """The plate is a uniform 2.5 x 5 x 1 m box, so its inertia-equivalent box is that box."""
    body = plate_rec["world/plate/kane/body"]
    np.testing.assert_allclose(np.array(body["Transform3D:translation"])[:, 0], plate_run["com"], atol=F32)
    logged = Rotation.from_quat(np.array(body["Transform3D:quaternion"])[:, 0])
    np.testing.assert_allclose((logged.inv() * Rotation.from_quat(plate_run["quat"], scalar_first=True)).magnitude(),
                               0.0, atol=1e-6)  # float32 quaternion components: ~1e-7 rad
    box = plate_rec["world/plate/kane/body/box"]["static"]
    half = np.array(box["Boxes3D:half_sizes"][0][0])
    extent = np.abs(Rotation.from_quat(box["Boxes3D:quaternions"][0][0]).as_matrix() @ np.diag(half)).sum(axis=1)
    np.testing.assert_allclose(extent, [1.25, 2.5, 0.5], rtol=1e-6)


def test_inertia_box_of_a_rotated_body():
    """A box rotated by R has inertia R I R^T; its equivalent box recovers the sizes and the axes."""
    R = Rotation.from_rotvec([0.3, -0.7, 1.1])
    m, size = 3.0, np.array([0.2, 0.5, 1.3])
    sq = size**2
    inertia = m / 12.0 * np.diag([sq[1] + sq[2], sq[0] + sq[2], sq[0] + sq[1]])
    half, quat = inertia_box(R.as_matrix() @ inertia @ R.as_matrix().T, m)
    corners = Rotation.from_quat(quat).as_matrix() @ np.diag(half)
    expected = R.as_matrix() @ np.diag(size / 2)
    # Same set of half-axes up to order and sign.
    for axis in corners.T:
        assert min(np.linalg.norm(axis - s * e) for e in expected.T for s in (1, -1)) < 1e-12


def test_tension_colors():
    out = tension_colors(np.array([0.0, -1.0, np.nan, 5.0, 10.0, 20.0]), 10.0)
    np.testing.assert_array_equal(out[:3], [SLACK_RGB] * 3)  # slack, pushing, unknown: all flagged
    np.testing.assert_array_equal(out[3], VIRIDIS[4])  # half way: the middle stop
    np.testing.assert_array_equal(out[4:], [VIRIDIS[-1]] * 2)  # full scale and beyond


def test_engines_are_compared_on_the_common_grid(plate_run, tmp_path):
    """A second engine whose tensions are 1 N higher, sampled at half the rate over a shorter span:
    the difference is 1 N at the first engine's times inside the overlap."""
    other = Trajectory("other", plate_run.t[:101:2], {k: v[:101:2] for k, v in plate_run.channels.items()},
                       plate_run.meta)
    other = replace(other, channels={**other.channels, "tension": other["tension"] + 1.0})
    rec = read(record(tmp_path / "two.rrd", "two engines", [plate_run, other]))
    diff = rec["diff/tension/other"]
    np.testing.assert_array_equal(diff["time"], np.round(plate_run.t[:101] * 1e9))
    shared = scalars(diff)[::2]  # samples both runs have: 1 N up to the rounding of T + 1 (T ~ 566 N)
    np.testing.assert_allclose(shared, 1.0, atol=1e-12 * 600)
    assert np.max(np.abs(scalars(rec["diff/attitude/other"])[::2])) < 1e-7  # same rotations
    assert "diff/theta/other" in rec  # every shared channel is compared
    assert {"world/plate/kane/wires", "world/plate/other/wires"} <= rec.keys()  # overlaid in one scene


def test_system_without_rig_is_plotted_only(tmp_path):
    t = np.linspace(0.0, 1.0, 11)
    q = np.column_stack([np.sin(t), np.cos(t)])
    traj = Trajectory("lagrange", t, {"q": q, "energy": np.ones_like(t)}, {"system": "double pendulum"})
    rec = read(record(tmp_path / "seed.rrd", "seed", [traj]))
    assert set(rec) - {"__properties"} == {"plots/q/lagrange", "plots/energy/lagrange", "summary"}
    np.testing.assert_array_equal(scalars(rec["plots/q/lagrange"]), q)


def test_case_summary_and_verdict(plate_run, tmp_path):
    metrics = [check("wire length error", 3e-10, 1e-9, "integration error", unit="m"),
               check("period", 2.0, 1.0, "deliberately failing")]
    result = CaseResult("demo-case", "000 ch. 7", False, 0.1, metrics, None, [plate_run])
    text = read(record_case(result, tmp_path / "case.rrd"))["summary"]["static"]["TextDocument:text"][0][0]
    assert text.startswith("# demo-case (000 ch. 7)") and "**FAIL**" in text
    assert "| wire length error | 3.000e-10 m | <= 1.0e-09 | pass |" in text
    assert "| period | 2.000e+00 | <= 1.0e+00 | FAIL |" in text


def test_failed_write_leaves_nothing(plate_run, tmp_path):
    broken = replace(plate_run, channels={**plate_run.channels, "com": plate_run["com"][:-1]})
    with pytest.raises(ValueError):
        record(tmp_path / "broken.rrd", "broken", [broken])
    assert list(tmp_path.iterdir()) == []
