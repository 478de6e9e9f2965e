"""Rerun recordings (.rrd) of validation runs: the rig in 3D beside the signals that validate it.

One recording holds every trajectory a case kept, overlaid in one 3D scene: the ceiling anchors, each
wire coloured by its tension (viridis from 0 to the largest tension in the recording, red when slack)
and labelled with it, the body as its inertia-equivalent box with its axes, and a trail of its COM.
Every channel is also a time series on the ``sim_time`` timeline, so is each run's period cycle by
cycle (of the signal that moves most: :func:`validate.compare.cycle_periods`), and for runs of one
rig by different engines the difference from the first engine, on that engine's time grid. The
case's metrics and verdict are a text document. The default blueprint opens on the ``sim_time``
timeline (or the one :func:`record` is given), with the 3D view, the tensions, the periods, the
thesis angles and the differences; the other channels are tabs beside the metrics.

A hinge rig's run (a compound or torsion pendulum, ``meta["hinge"]``: :mod:`validate.engines.hinge`) is
drawn with its axis instead of wires: a compound pendulum's pivot axis along world x through the origin,
a torsion rod rising from the COM along world z. Trajectories without a rig (seed pendula) are plotted
only. Time-varying data goes through
``send_columns``, one call per entity, so that recording costs little next to simulating
(``python benchmarks/recording.py``). A file is written under a temporary name and renamed: a
recording is whole or absent.
"""

from __future__ import annotations

import os
import re
import uuid
from collections import Counter
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import rerun as rr
import rerun.blueprint as rrb
from scipy.spatial.transform import Rotation

from bifilar.bodies.composite import equivalent_box

from .compare import by_rig, columns, compared, cycle_periods, differences
from .outputs import check_writable
from .registry import Metric
from .trajectory import RIG_CHANNELS, Trajectory

if TYPE_CHECKING:
    from .suite import CaseResult

APP_ID = "bifilar-validate"
TIMELINE = "sim_time"
TRAIL_SECONDS = 5.0  # how much COM history the 3D view shows behind the time cursor
SLACK_RGB = (230, 30, 30)  # tension <= 0 (slack, or an equality cable pushing): a red viridis never reaches
# Viridis sampled at 0, 1/8, ..., 1: perceptually uniform, so equal colour steps are equal tension steps.
VIRIDIS = np.array([(68, 1, 84), (71, 44, 122), (59, 81, 139), (44, 113, 142), (33, 144, 141),
                    (39, 173, 129), (92, 200, 99), (170, 220, 50), (253, 231, 37)], dtype=float)
_BEAM_RGB = (115, 90, 75)  # a hinge's axis or rod, as the MJCF scene's beam
RUN_RGB = ((31, 119, 180), (255, 127, 14), (44, 160, 44), (148, 103, 189), (140, 86, 75), (227, 119, 194))
MAIN_PLOTS = ("tension", "period", "theta")  # plotted in full view; every other channel gets a tab
UNITS = {"com": "m", "tension": "N", "length_error": "m", "velocity": "m/s", "omega": "rad/s",
         "energy": "J", "theta": "rad", "attitude": "rad", "period": "s"}


@dataclass(frozen=True)
class _Run:
    """A trajectory with its label (unique in the recording: entity paths and legends) and colour."""

    label: str
    traj: Trajectory
    rgb: tuple[int, int, int]

    @property
    def rig(self) -> str:
        return _safe(str(self.traj.meta.get("rig") or "system"))

    @property
    def drawn(self) -> bool:
        if "hinge" in self.traj.meta:
            return "com" in self.traj and "quat" in self.traj
        return "rig_spec" in self.traj.meta and all(c in self.traj for c in RIG_CHANNELS)


@dataclass(frozen=True)
class Extra:
    """More than runs in a recording (a sweep's table): ``log`` logs it into the open recording,
    ``views`` show it, in tabs before the runs' layout."""

    log: Callable[[rr.RecordingStream], None]
    views: tuple


def record(path: str | Path, title: str, trajectories: Sequence[Trajectory], metrics: Iterable[Metric] = (),
           passed: bool | None = None, note: str = "", extra: Extra | None = None, timeline: str = TIMELINE) -> Path:
    """Write one .rrd of ``trajectories`` (see the module docstring) with ``metrics``, the verdict
    ``passed`` (None: no verdict), a free ``note`` (e.g. the error a case raised) and ``extra``; the
    viewer opens on ``timeline``. Returns the path."""
    runs = _runs(trajectories)
    diffs = [(ref, run, differences(ref.traj, run.traj)) for ref, run in compared(runs, _rig, _engine)]
    periods = {r.label: p for r in runs if (p := cycle_periods(r.traj)) is not None}
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    check_writable(path)
    # Created by rerun, with default permissions; short whatever the final name's length.
    tmp = path.with_name(f".{path.name[:48]}.{uuid.uuid4().hex}.rrd")
    try:
        rec = rr.RecordingStream(APP_ID)
        rec.save(tmp, default_blueprint=_blueprint(runs, diffs, periods, extra.views if extra else (), timeline))
        rec.send_recording_name(title)
        if extra:
            extra.log(rec)
        _log_scene(rec, [r for r in runs if r.drawn])
        _log_series(rec, runs, diffs, periods)
        rec.log("summary", rr.TextDocument(_summary(title, runs, list(metrics), passed, note),
                                           media_type=rr.MediaType.MARKDOWN), static=True)
        rec.flush()
        rec.disconnect()
        os.replace(tmp, path)
    except OSError as exc:
        Path(tmp).unlink(missing_ok=True)
        raise OSError(exc.errno, exc.strerror or str(exc), str(path)) from None
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path


def record_case(result: CaseResult, path: str | Path) -> Path:
    """Record a :class:`~validate.suite.CaseResult` (run with its trajectories kept)."""
    note = result.error or ""
    return record(path, f"{result.name} ({result.source})", result.trajectories, result.metrics, result.passed, note)


def record_trajectory(traj: Trajectory, path: str | Path) -> Path:
    """Record one engine run, as ``simulate --rerun`` does."""
    title = f"{traj.engine} on {traj.meta.get('rig', 'system')}, {traj.t[-1]:g} s"
    failure = traj.meta.get("taut_failure")
    note = f"wire {failure[0]} went slack at t = {failure[1]:.6g} s; the run stops there" if failure else ""
    return record(path, title, [traj], note=note)


# ---------------------------------------------------------------------------------------- runs


def _safe(name: str) -> str:
    """An entity-path part: letters, digits, '-', '_' and '.' only."""
    return re.sub(r"[^\w.-]", "_", name)


def _runs(trajectories: Sequence[Trajectory]) -> list[_Run]:
    """Label each trajectory by its engine; add the rig, then a counter, where labels would clash."""
    names = [_safe(t.engine) for t in trajectories]
    if len(set(names)) < len(names):
        names = [_safe(f"{t.engine}-{t.meta['rig']}" if "rig" in t.meta else t.engine) for t in trajectories]
    seen: Counter = Counter()
    runs = []
    for i, (name, traj) in enumerate(zip(names, trajectories)):
        seen[name] += 1
        label = name if seen[name] == 1 else f"{name}-{seen[name]}"
        runs.append(_Run(label, traj, RUN_RGB[i % len(RUN_RGB)]))
    return runs


def _rig(run: _Run) -> str:
    return run.rig


def _engine(run: _Run) -> str:
    return run.traj.engine


def _time(t: np.ndarray) -> list[rr.TimeColumn]:
    return [rr.TimeColumn(TIMELINE, duration=t)]


# ---------------------------------------------------------------------------------------- 3D scene


def tension_colors(tension: np.ndarray, t_max: float) -> np.ndarray:
    """RGB (uint8) per tension: viridis over [0, t_max], :data:`SLACK_RGB` where tension <= 0."""
    x = np.clip(np.asarray(tension, dtype=float) / t_max, 0.0, 1.0) * (len(VIRIDIS) - 1)
    stops = np.arange(len(VIRIDIS))
    rgb = np.stack([np.interp(x, stops, VIRIDIS[:, c]) for c in range(3)], axis=-1)
    rgb[~(tension > 0.0)] = SLACK_RGB
    return np.round(rgb).astype(np.uint8)


def inertia_box(inertia: np.ndarray, mass: float) -> tuple[np.ndarray, np.ndarray]:
    """:func:`bifilar.bodies.composite.equivalent_box` as half sizes and an xyzw quaternion (rerun's order)."""
    half, axes = equivalent_box(mass, inertia)
    return half, Rotation.from_matrix(axes).as_quat()


def _log_scene(rec: rr.RecordingStream, runs: list[_Run]) -> None:
    """Each rig's anchors (or hinge axis) once, then every run's wires, body and trail; rigs side by side
    along x."""
    if not runs:
        return
    rec.log("world", rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
    t_max = max((float(np.nanmax(r.traj["tension"], initial=0.0)) for r in runs if "tension" in r.traj),
                default=0.0) or 1.0
    x = last_reach = 0.0
    for rig_name, group in by_rig(runs, _rig).items():
        hinge = group[0].traj.meta.get("hinge")
        if hinge is None:
            rig = group[0].traj.meta["rig_spec"]
            reach = max(abs(w.anchor[0]) for w in rig.wires) + max(w.length for w in rig.wires)  # in x, from x = 0
            scale = max(w.length for w in rig.wires)
        else:
            scale = reach = 2.0 * (hinge.size + hinge.arm)
        x += 1.1 * (last_reach + reach) if last_reach else 0.0
        last_reach = reach
        base = f"world/{rig_name}"
        rec.log(base, rr.Transform3D(translation=(x, 0.0, 0.0)), static=True)
        if hinge is None:
            rec.log(f"{base}/anchors", rr.Points3D([w.anchor for w in rig.wires], radii=0.01 * scale,
                                                   labels=[f"anchor {k + 1}" for k in range(len(rig.wires))]),
                    static=True)
        else:
            rec.log(f"{base}/hinge", _hinge_axis(hinge, scale), static=True)
        for run in group:
            _log_run(rec, f"{base}/{run.label}", run, t_max, scale)


def _hinge_axis(rig, scale: float) -> rr.LineStrips3D:
    """The hinge of :mod:`validate.engines.hinge`'s world: a pivot axis along x through the origin, or a
    torsion rod from the COM (the origin) up along z, ``scale`` m long."""
    if rig.kind == "pivot":
        ends, label = [(-0.5 * scale, 0.0, 0.0), (0.5 * scale, 0.0, 0.0)], "pivot axis"
    else:
        ends, label = [(0.0, 0.0, 0.0), (0.0, 0.0, scale)], f"torsion rod, {rig.stiffness:.6g} N m/rad"
    return rr.LineStrips3D([ends], radii=0.006 * scale, colors=[_BEAM_RGB], labels=[label])


def _log_run(rec: rr.RecordingStream, base: str, run: _Run, t_max: float, scale: float) -> None:
    traj = run.traj
    rig = traj.meta.get("hinge") or traj.meta["rig_spec"]
    n, time = len(traj.t), _time(traj.t)
    com = np.asarray(traj["com"])
    rot = Rotation.from_quat(traj["quat"], scalar_first=True)
    if "hinge" not in traj.meta:
        _log_wires(rec, base, traj, rig, com, rot, t_max, scale)
    rec.send_columns(f"{base}/body", time, rr.Transform3D.columns(translation=com, quaternion=rot.as_quat()))
    half, quat = inertia_box(rig.inertia, rig.mass)
    rec.log(f"{base}/body", rr.TransformAxes3D(1.5 * float(half.max())), static=True)
    rec.log(f"{base}/body/box", rr.Boxes3D(half_sizes=[half], quaternions=[quat], colors=[run.rgb],
                                           labels=[run.label]), static=True)

    segments = np.stack([np.vstack([com[:1], com[:-1]]), com], axis=1)  # (n, 2, 3): previous -> current
    rec.send_columns(f"{base}/trail", time, rr.LineStrips3D.columns(
        strips=segments, colors=np.tile(np.array(run.rgb, dtype=np.uint8), (n, 1)),
        radii=np.full(n, 0.003 * scale, dtype=np.float32)))


def _log_wires(rec: rr.RecordingStream, base: str, traj: Trajectory, rig, com: np.ndarray, rot: Rotation,
               t_max: float, scale: float) -> None:
    """Each wire from its anchor to its attachment, coloured and labelled by its tension."""
    n, tension = len(traj.t), np.asarray(traj["tension"])
    ends = np.stack([np.stack([np.broadcast_to(w.anchor, (n, 3)), com + rot.apply(w.attach - rig.com)], axis=1)
                     for w in rig.wires], axis=1)  # (n, wire, 2, 3)
    labels = [f"{v:.1f} N" for v in tension.ravel()]
    rec.send_columns(f"{base}/wires", _time(traj.t), rr.LineStrips3D.columns(
        strips=ends.reshape(-1, 2, 3), colors=tension_colors(tension, t_max).reshape(-1, 3), labels=labels,
        radii=np.full(tension.size, 0.004 * scale, dtype=np.float32)).partition([len(rig.wires)] * n))


# ---------------------------------------------------------------------------------------- series


def _components(channel: str, k: int) -> list[str]:
    """Legend names for the columns of a channel."""
    if channel in ("tension", "length_error"):
        return [f"wire {i + 1}" for i in range(k)]
    if channel == "quat":
        return list("wxyz")
    if channel == "theta":
        return [f"theta{i + 1}" for i in range(k)]
    if k == 3:
        return list("xyz")
    return [channel] if k == 1 else [f"{channel}[{i}]" for i in range(k)]


def _send_series(rec: rr.RecordingStream, entity: str, t: np.ndarray, values: np.ndarray, names: list[str]) -> None:
    rec.log(entity, rr.SeriesLines(names=names), static=True)
    rec.send_columns(entity, _time(t), rr.Scalars.columns(scalars=values))


def _log_series(rec: rr.RecordingStream, runs: list[_Run], diffs: list, periods: dict) -> None:
    """``plots/<channel>/<run>`` for every channel, ``plots/period/<run>`` for the period cycle by
    cycle (:func:`validate.compare.cycle_periods`) and ``diff/<channel>/<run>`` for every difference."""
    for run in runs:
        for name, values in columns(run.traj).items():
            names = [f"{run.label} {c}" for c in _components(name, values.shape[1])]
            _send_series(rec, f"plots/{name}/{run.label}", run.traj.t, values, names)
        if run.label in periods:
            signal, t, values = periods[run.label]
            _send_series(rec, f"plots/period/{run.label}", t, values[:, None], [f"{run.label} period of {signal}"])
    for ref, run, channels in diffs:
        for name, (t, values) in channels.items():
            names = [f"{run.label} - {ref.label} {c}" for c in _components(name, values.shape[1])]
            _send_series(rec, f"diff/{name}/{run.label}", t, values, names)


# ---------------------------------------------------------------------------------------- summary, layout


def _summary(title: str, runs: list[_Run], metrics: list[Metric], passed: bool | None, note: str) -> str:
    verdict = {True: "**PASS**", False: "**FAIL**", None: "no verdict"}[passed]
    lines = [f"# {title}", "", verdict, ""]
    if note:
        lines += ["```", note.strip(), "```", ""]
    if metrics:
        lines += ["| metric | value | tolerance | | reason |", "|---|---|---|---|---|"]
        for m in metrics:
            unit = f" {m.unit}" if m.unit else ""
            cmp = ">=" if m.at_least else "<="
            lines.append(f"| {m.name} | {m.value:.3e}{unit} | {cmp} {m.tolerance:.1e} | "
                         f"{'pass' if m.passed else 'FAIL'} | {m.reason} |")
        lines.append("")
    for r in runs:
        failure = r.traj.meta.get("taut_failure")
        stop = f", taut-wire model stopped at t = {failure[1]:.6g} s (wire {failure[0]})" if failure else ""
        lines.append(f"- {r.label}: engine {r.traj.engine}, rig {r.traj.meta.get('rig', '-')}, "
                     f"{len(r.traj.t)} samples over {r.traj.t[0]:g}..{r.traj.t[-1]:g} s{stop}")
        spec = r.traj.meta.get("rig_spec")
        if spec is not None and spec.elastic:  # the stiffness the run used; length_error is the stretch
            lines.append("  elastic wires, axial stiffness EA = " + ", ".join(f"{w.axial_stiffness:.6g}" for w in spec.wires)
                         + " N (length error = stretch beyond the unstretched length)")
    return "\n".join(lines) + "\n"


def _plot(origin: str, channel: str, what: str) -> rrb.TimeSeriesView:
    unit = UNITS.get(channel)
    return rrb.TimeSeriesView(origin=origin, name=f"{what} ({unit})" if unit else what)


def _blueprint(runs: list[_Run], diffs: list, periods: dict, extra_views: tuple = (),
               timeline: str = TIMELINE) -> rrb.Blueprint:
    """3D scene on the left; tensions, thesis angles and differences on the right, the other
    channels in tabs behind the metrics; ``extra_views`` in tabs before all that; the time panel on
    ``timeline``."""
    channels = list(dict.fromkeys(c for r in runs for c in columns(r.traj))) + (["period"] if periods else [])
    main = [c for c in MAIN_PLOTS if c in channels]
    rest = [c for c in channels if c not in main]
    if not set(main) - {"period"}:  # no rig channels: the system's own channels are what matters
        main, rest = main + rest, []
    differenced = sorted({c for _, _, channels in diffs for c in channels}, key=lambda c: (c not in MAIN_PLOTS, c))
    panels: list = [_plot(f"plots/{c}", c, c) for c in main]
    if differenced:
        panels.append(rrb.Tabs(*[_plot(f"diff/{c}", c, f"{c} difference") for c in differenced]))
    panels.append(rrb.Tabs(rrb.TextDocumentView(origin="summary", name="metrics"),
                           *[_plot(f"plots/{c}", c, c) for c in rest]))
    right = rrb.Vertical(*panels)
    drawn = [r for r in runs if r.drawn]
    if drawn:
        trail = rrb.VisibleTimeRanges(timeline=TIMELINE, end=rrb.TimeRangeBoundary.cursor_relative(),
                                      start=rrb.TimeRangeBoundary.cursor_relative(seconds=-TRAIL_SECONDS))
        scene = rrb.Spatial3DView(origin="world", name="rig",
                                  overrides={f"world/{r.rig}/{r.label}/trail": trail for r in drawn})
        layout = rrb.Horizontal(scene, right, column_shares=[3, 2])
    else:
        layout = right
    if extra_views:
        layout = rrb.Tabs(*extra_views, layout)
    return rrb.Blueprint(layout, rrb.BlueprintPanel(state="collapsed"), rrb.SelectionPanel(state="collapsed"),
                         rrb.TimePanel(timeline=timeline, state="collapsed"))
