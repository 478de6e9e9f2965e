"""The Solar Boat study of the thesis's ch. 8.2-8.4, redone with the exact method, for any suspension
file (:mod:`bifilar.bodies.boat`).

For every configuration:

* Moments (ch. 8.3). The thesis's three motions, each released at pi/80 along the mode that turns
  about the axis (:func:`bifilar.identification.identify.released`): torsion (its theta4) for yaw I1, the swing in
  the wires' plane (theta2: the wire turns by pi/80) for pitch I2, and the roll about CD (theta1) for
  roll I3. The Kane model's period of that release is the "measured" period; the exact inversion
  (:func:`bifilar.identification.identify.identify`, with the amplitude correction) turns it into the moment,
  starting from the thesis's own estimate (Table 8.3.4). The truth is the parts' moment about the
  body axis. The rest pose, the modes and the predicted standard deviation of each moment (the
  suspension file's ``[uncertainty]`` propagated through the exact inversion) are the sweep's: each
  configuration is a point of :func:`sweep_space` evaluated by :func:`bifilar.sweep.evaluate.evaluate`,
  as ``python -m validate sweep models/solar_boat/configurations.toml`` does.
* Loads and clearance (ch. 8.3-8.4). The torsion at pi/12 (Fig. 8.4.1) and the other two motions at
  pi/80, each simulated for five periods of the rig's slowest mode and sampled every 0.01 s (an
  extreme between samples is missed by at most (omega dt)^2 / 8 of the oscillating part; the
  tension of the fastest, the torsion, oscillates at twice its 3.4 rad/s: 6e-4): wire tensions, the
  force of each wire on the deck (body frame), and the lowest point of the parts.

Axes: yaw, pitch and roll are about the body z, y and x axes (the thesis's I1, I2, I3).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from bifilar.identification import identify as ident
from bifilar.bodies.boat import Configuration, Suspension, attachment_forces, lowest_point
from bifilar.identification.identify import Identified
from bifilar.rig import Rig, RigError
from bifilar.motion.simulate import KaneRun, simulate
from bifilar.rig.statics import Rest
from bifilar.sweep.axes import configure
from bifilar.sweep.evaluate import Row, evaluate
from bifilar.sweep.space import Limits, Space

from ..assets import MODELS

SUSPENSION = MODELS / "solar_boat" / "suspension.toml"  # the shipped hall and configurations

AXES = (("yaw", "z"), ("pitch", "y"), ("roll", "x"))
AXIS_NAME = {axis: name for name, axis in AXES}

# Thesis ch. 8.1: the earlier project's geometric moments (kg m^2), and Table 8.3.4: the thesis's
# estimates for its configurations, as differences from them.
THESIS_GEOMETRIC = {"z": 317.278, "y": 317.154, "x": 83.143}
TABLE_8_3_4 = {
    "1": {"z": -11.49, "y": +11.95, "x": -0.162},
    "2": {"z": +25.05, "y": -86.39, "x": -0.162},
    "3": {"z": +34.68, "y": -132.80, "x": -0.162},
}

RTOL = 1e-10  # Kane integrator, as in every validation case
DT_OUT = 0.01  # s
PERIODS = 5  # load runs last this many periods of the rig's slowest mode


@dataclass(frozen=True)
class Motion:
    """A release along the mode that turns about body ``axis``; ``amplitude`` (rad) is the rotation
    about the axis, or with ``of_wire`` the angle wire 1 turns through (the thesis's theta2)."""

    name: str
    axis: str
    amplitude: float
    of_wire: bool = False


TIMED = (Motion("torsion", "z", np.pi / 80), Motion("swing", "y", np.pi / 80, of_wire=True),
         Motion("roll", "x", np.pi / 80))  # ch. 8.3
LOADED = (Motion("torsion", "z", np.pi / 12), *TIMED[1:])  # ch. 8.4 (Fig. 8.4.1) and 8.3


def axis_amplitude(rig: Rig, motion: Motion, rest: Rest) -> float:
    """The motion's rotation about its axis (rad) at release.

    For ``of_wire`` the linear mode's shape gives the ratio: per unit of the mode the body turns by
    ``turn`` and its COM moves by ``shift``, so wire 1's attachment moves by
    ``d = shift + turn x (attachment - COM)``, which turns the wire by the part of d normal to it over
    the wire's length.
    """
    if not motion.of_wire:
        return motion.amplitude
    p = ident.pencil(rig, motion.axis, rest)
    k, _, v = p.associated(p.moment0)
    turn, shift = p.partial_omega @ v[:, k], p.partial_com @ v[:, k]
    wire = rig.wires[0]
    point = rest.com + rest.rotation @ (wire.attach - rig.com)
    d = shift + np.cross(turn, point - rest.com)
    along = (point - wire.anchor) / wire.length
    swing = np.linalg.norm(d - (d @ along) * along) / wire.length
    return float(motion.amplitude * abs(turn @ p.rotation @ p.axis) / swing)


@dataclass(frozen=True)
class Moment:
    """One moment identified from a timed motion: the truth, the thesis's estimate (None for a
    configuration the thesis did not study), the period timed at ``amplitude`` and what it gives;
    the predicted relative standard deviation and its budget are the sweep's (module docstring)."""

    name: str
    axis: str
    truth: float
    thesis: float | None
    amplitude: float  # rad about the axis
    period: float  # s, at that amplitude
    found: Identified
    sigma: float  # relative standard deviation of the moment
    budget: dict  # uncertainty group -> its share of the variance

    @property
    def std(self) -> float:
        """Predicted standard deviation (kg m^2)."""
        return self.sigma * self.truth


def time_moment(rig: Rig, config: Configuration, motion: Motion, rest: Rest, row: Row) -> Moment:
    """Time the motion on the rig (the Kane model) and identify the moment from that period starting
    from the thesis's estimate (or its geometric value); its uncertainty is the sweep's ``row``'s."""
    axis = motion.axis
    delta = TABLE_8_3_4.get(config.name, {}).get(axis)
    thesis = None if delta is None else THESIS_GEOMETRIC[axis] + delta
    amplitude = axis_amplitude(rig, motion, rest)
    period = ident.simulated_period(rig, axis, amplitude, rest)
    start = ident.with_moment(rig, axis, THESIS_GEOMETRIC[axis] if thesis is None else thesis)
    found = ident.identify(start, axis, period, amplitude, rest)
    return Moment(AXIS_NAME[axis], axis, ident.moment(rig, axis), thesis, amplitude, period, found,
                  row.sigma[axis], row.budget[axis])


@dataclass(frozen=True)
class Loads:
    """A load run: its samples, the wire tensions (n, 2; N), the wires' forces on the deck (n, 2, 3;
    body frame, N) and the depth of the parts' lowest point under the hooks (n; m)."""

    motion: Motion
    amplitude: float  # rad about the axis
    run: KaneRun
    forces: np.ndarray
    depth: np.ndarray
    lowest_part: str  # the part that reaches deepest

    @property
    def in_plane_max(self) -> np.ndarray:
        """Largest force of each wire on the deck in the deck's plane (body x, y), N."""
        return np.linalg.norm(self.forces[:, :, :2], axis=2).max(axis=0)


def load_run(s: Suspension, rig: Rig, motion: Motion, rest: Rest, duration: float) -> Loads:
    """Release the motion, simulate it (Kane) and collect tensions, deck forces and depths."""
    amplitude = axis_amplitude(rig, motion, rest)
    start = ident.released(rig, motion.axis, amplitude, rest)
    run = simulate(start.model, start.state, duration, dt_out=DT_OUT, rtol=RTOL)
    if run.slack is not None:
        wire, t = run.slack
        raise RigError(s.source, "hall", f"{rig.name}, {motion.name} at {amplitude:.4g} rad: wire[{wire}] goes "
                                         f"slack at t = {t:.4g} s")
    depth, part = depth_under_hooks(s, rig, run.com, run.rotation)
    forces = attachment_forces(rig, run.com, run.rotation, run.tension)
    return Loads(motion, amplitude, run, forces, depth, s.parts[int(part[np.argmax(depth)])].name)


def depth_under_hooks(s: Suspension, rig: Rig, com: np.ndarray, rotation: np.ndarray):
    """Depth (m) of the parts' lowest point under the highest hook, and the index of the part that
    has it, for poses given by the COM (world) and body->world rotation (one or many)."""
    com, rotation = np.atleast_2d(com), np.reshape(rotation, (-1, 3, 3))
    low, part = lowest_point(s.parts, com - rotation @ rig.com, rotation)
    return float(s.hooks[:, 2].max()) - low, part


@dataclass(frozen=True)
class ConfigurationStudy:
    """Everything the study finds for one configuration."""

    config: Configuration
    row: Row  # the sweep's evaluation of the configuration
    rig: Rig
    rest: Rest
    rest_forces: np.ndarray  # (2, 3), body frame, N
    rest_depth: float  # m, lowest point under the hooks at rest
    moments: tuple[Moment, ...]  # yaw, pitch, roll
    loads: tuple[Loads, ...]  # torsion pi/12, swing, roll

    @property
    def tension_max(self) -> np.ndarray:
        return np.max([run.run.tension.max(axis=0) for run in self.loads], axis=0)

    @property
    def in_plane_max(self) -> np.ndarray:
        return np.max([run.in_plane_max for run in self.loads], axis=0)

    @property
    def depth(self) -> float:
        """Depth (m) under the hooks that the motions need: the floor must be lower."""
        return float(max(run.depth.max() for run in self.loads))


def sweep_space(s: Suspension) -> Space:
    """The suspension's configurations as the points of a sweep, as models/solar_boat/configurations.toml
    writes them (bifilar/sweep/space.py): the boat at the deck's ends, each inset an ``attach_inset``,
    the hall's floor, the three moments, the timed amplitude pi/80."""
    insets = np.array([c.inset for c in s.configurations])
    return Space(s.source, s.base_rig(), {"attach_inset": insets}, Limits(floor=s.floor), tuple(a for _, a in AXES),
                 np.pi / 80, "worst", explicit=True, names=tuple(c.name for c in s.configurations), parts=s.parts)


def study_configuration(s: Suspension, config: Configuration, space: Space) -> ConfigurationStudy:
    values = {"attach_inset": config.inset}
    row = evaluate(space, values)
    if row.rest is None:
        raise RigError(s.source, "configuration", f"configuration {config.name}: {row.reason}")
    rig, rest = configure(space.rig, values), row.rest
    slowest = max(p for p in row.periods if p is not None)
    moments = tuple(time_moment(rig, config, m, rest, row) for m in TIMED)
    loads = tuple(load_run(s, rig, m, rest, PERIODS * slowest) for m in LOADED)
    depth, _ = depth_under_hooks(s, rig, rest.com, rest.rotation)
    forces = attachment_forces(rig, rest.com, rest.rotation, rest.tensions)[0]
    return ConfigurationStudy(config, row, rig, rest, forces, float(depth[0]), moments, loads)


@dataclass(frozen=True)
class Study:
    """The study of every configuration of a suspension file."""

    suspension: Suspension
    configurations: tuple[ConfigurationStudy, ...]


def run_study(s: Suspension) -> Study:
    space = sweep_space(s)
    return Study(s, tuple(study_configuration(s, c, space) for c in s.configurations))


def recommend(study: Study) -> dict:
    """The configuration to hang the boat in, and why: per axis the configuration with the smallest
    predicted relative standard deviation ("any" when every one is within 5 % of the best); overall the
    one whose largest relative standard deviation of the three moments is smallest; and the loads."""
    confs = study.configurations
    names = [c.config.name for c in confs]
    rel = np.array([[m.sigma for m in c.moments] for c in confs])  # (configuration, axis)
    choice, reasons = {}, []
    for k, (axis, _) in enumerate(AXES):
        best = int(np.argmin(rel[:, k]))
        choice[axis] = "any" if rel[:, k].max() <= 1.05 * rel[best, k] else names[best]
        m = confs[best].moments[k]
        top = max(m.budget, key=m.budget.get)
        reasons.append(f"{axis}: sigma {100 * rel[best, k]:.2g} % in configuration {names[best]}, "
                       f"{100 * rel[:, k].max():.2g} % in configuration {names[int(np.argmax(rel[:, k]))]} "
                       f"(d ln T / d ln I = {m.found.sensitivity:.2g}, largest error source: {top}, "
                       f"{100 * m.budget[top]:.0f} % of the variance)")
    # A configuration whose swinging boat reaches the floor is out, whatever its accuracy.
    margin = np.array([study.suspension.hook_height - c.depth for c in confs])
    if np.all(margin < 0.0):
        choice["configuration"] = None
        reasons.insert(0, f"no configuration clears the floor: the boat reaches {-margin.max():.3g} m below it at "
                          f"best; hang the hooks higher or the wires shorter")
    else:
        worst = np.where(margin >= 0.0, rel.max(axis=1), np.inf)
        overall = int(np.argmin(worst))
        choice["configuration"] = names[overall]
        reasons.insert(0, f"configuration {names[overall]} has the smallest worst-case sigma of the three moments "
                          f"among those that clear the floor, {100 * rel[overall].max():.2g} %")
        for c, m in zip(names, margin):
            if m < 0.0:
                reasons.append(f"configuration {c} is excluded: the boat reaches {-m:.3g} m below the floor")
    for label, values in (("peak wire tension", [c.tension_max.max() for c in confs]),
                          ("peak in-plane pull on the deck", [c.in_plane_max.max() for c in confs])):
        low, high = int(np.argmin(values)), int(np.argmax(values))
        reasons.append(f"{label}: {values[low]:.0f} N in configuration {names[low]}, "
                       f"{values[high]:.0f} N in configuration {names[high]}")
    choice["reasons"] = reasons
    return choice


def summary(study: Study) -> dict:
    """The study as plain JSON types (see ``python -m validate boat --json``)."""
    s = study.suspension
    props = s.properties
    moments, axes = props.principal()
    by_axis = {a: float(moments[np.argmax(np.abs(axes[i]))]) for i, a in enumerate("xyz")}
    pilot = sum(p.mass for p in s.parts if p.name == "pilot")  # the thesis's "nearly 44 %" (ch. 8.1)
    return {
        "mass": float(props.mass),
        "com_below_deck": float(s.deck.position[2] + 0.5 * s.deck.dims["height"] - props.com[2]),
        "pilot_fraction": float(pilot / props.mass),
        "principal_inertia": [by_axis[a] for _, a in AXES],
        "axes": [n for n, _ in AXES],
        "thesis_geometric": [THESIS_GEOMETRIC[a] for _, a in AXES],
        "hall": {"hooks": s.hooks.tolist(), "wire_length": s.wire_length, "hook_height": s.hook_height},
        "uncertainty": s.uncertainty,
        "configurations": [_configuration(c, s.hook_height) for c in study.configurations],
        "recommendation": recommend(study),
    }


def _configuration(c: ConfigurationStudy, hook_height: float) -> dict:
    return {
        "name": c.config.name,
        "inset": c.config.inset,
        "attach": [w.attach.tolist() for w in c.rig.wires],
        "truth": [m.truth for m in c.moments],
        "estimates": [m.found.moment for m in c.moments],
        "thesis": [m.thesis for m in c.moments],
        "periods": [m.period for m in c.moments],
        "amplitudes": [m.amplitude for m in c.moments],
        "sensitivity": [m.found.sensitivity for m in c.moments],
        "std": [m.std for m in c.moments],
        "budget": [m.budget for m in c.moments],
        "tension_rest": c.rest.tensions.tolist(),
        "tension_max": c.tension_max.tolist(),
        "attachment_rest": c.rest_forces.tolist(),
        "in_plane_max": c.in_plane_max.tolist(),
        "motions": [
            {
                "name": run.motion.name,
                "axis": run.motion.axis,
                "amplitude": run.amplitude,
                "tension_min": run.run.tension.min(axis=0).tolist(),
                "tension_max": run.run.tension.max(axis=0).tolist(),
                # The force on the deck when its wire pulls hardest, and the largest part in the deck's plane.
                "attachment_peak": [run.forces[np.argmax(run.run.tension[:, i]), i].tolist() for i in range(2)],
                "in_plane_max": run.in_plane_max.tolist(),
                "depth": float(run.depth.max()),
            }
            for run in c.loads
        ],
        "clearance_rest": c.rest_depth,
        "clearance": c.depth,
        "lowest_part": max(c.loads, key=lambda run: run.depth.max()).lowest_part,
        "floor_margin": hook_height - c.depth,
    }
