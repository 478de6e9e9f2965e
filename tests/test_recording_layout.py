"""Every .rrd the commands write opens on a layout: ``rerun rrd verify`` passes, the blueprint holds
the 3D scene, the tensions and the periods as time series, on the ``sim_time`` timeline (a sweep's
on ``configuration``: tests/test_sweep_rerun.py); and the period series is the motion's period cycle
by cycle."""

from __future__ import annotations

import numpy as np
import pytest
from rrd_check import timeline, verify, views
from test_recording import read, scalars

from validate.assets import RIGS, rig
from validate.cli import main
from validate.recording import record

LAYOUT = {"rig": ("3D", "world"), "tension (N)": ("TimeSeries", "plots/tension"),
          "period (s)": ("TimeSeries", "plots/period"), "metrics": ("TextDocument", "summary")}


def _check_layout(path) -> None:
    verify(path)
    assert timeline(path) == "sim_time"
    shown = views(path)
    assert {k: shown.get(k) for k in LAYOUT} == LAYOUT


@pytest.mark.slow
def test_simulate_case_and_all_recordings_verify_and_open_on_their_layout(tmp_path, capsys):
    assert main(["simulate", str(RIGS / "plate.toml"), "--engine", "kane", "--duration", "8", "--out",
                 str(tmp_path / "p.csv"), "--rerun", str(tmp_path / "simulate.rrd")]) == 0
    assert main(["case", "kane-sidesway-6.1", "--rerun", str(tmp_path / "case.rrd")]) == 0
    assert main(["all", "-k", "kane-parallel-torsion", "--jobs", "1", "--rerun", str(tmp_path / "all")]) == 0
    capsys.readouterr()
    for path in (tmp_path / "simulate.rrd", tmp_path / "case.rrd", tmp_path / "all" / "kane-parallel-torsion-5.2.18.rrd"):
        _check_layout(path)

    # Parallel wires at 1e-4 rad: each cycle's torsion period is (5.2.17), 2 pi sqrt(4 h I / (m g D^2)),
    # to the amplitude effect ~amp^2 = 1e-8 and a crossing time's refinement (~1e-10 of a period).
    r = rig("parallel")
    closed = 2.0 * np.pi * np.sqrt(4.0 * 1.5 * r.inertia[2, 2] / (r.mass * r.gravity * 0.4**2))
    rec = read(tmp_path / "all" / "kane-parallel-torsion-5.2.18.rrd")
    period = rec["plots/period/kane"]
    assert period["static"]["SeriesLines:names"][0] == ["kane period of rotation about world z"]
    cycles = scalars(period)[:, 0]
    assert len(cycles) == int(20.0 / closed) - 1
    np.testing.assert_allclose(cycles, closed, rtol=2e-8)
    # logged at the first sample at or after each cycle's end: on the run's 0.01 s grid (to 1 ns ticks)
    ticks = period["time"]
    assert np.all(np.diff(ticks) > 0) and np.max(np.abs(ticks - np.round(ticks / 1e7) * 1e7)) <= 1


def test_a_system_without_a_rig_plots_its_period_with_its_own_channels(tmp_path):
    """A 0.5 s sine over 5 s at 100 samples per second, rising through zero at 0.42 s, 0.92 s, ...
    4.92 s: nine cycles of 0.5 s, each to the crossing refinement (a degree-5 polynomial through six
    samples: ~1e-9 of the period at 50 samples per period)."""
    from validate.trajectory import Trajectory

    t = np.arange(501) * 0.01
    traj = Trajectory("lagrange", t, {"q": np.sin(2 * np.pi * t / 0.5 + 1.0)[:, None], "energy": np.ones_like(t)})
    path = record(tmp_path / "seed.rrd", "seed", [traj])
    verify(path)
    cycles = scalars(read(path)["plots/period/lagrange"])[:, 0]
    assert len(cycles) == 9
    np.testing.assert_allclose(cycles, 0.5, rtol=1e-8)
    shown = views(path)
    assert shown["period (s)"] == ("TimeSeries", "plots/period") and shown["q"] == ("TimeSeries", "plots/q")
