"""The sweep file: a base rig and the axes to vary over, the limits and what is to be measured.

TOML, SI units and radians, the rig file's conventions::

    rig = "../rigs/plate.toml"     # the base rig (body, [uncertainty]); path relative to this file
    [vary]                         # each axis (bifilar.sweep.axes): a list, or {from, to, steps[, log]}
    wire_length = {from = 1.0, to = 6.0, steps = 26}
    attach_span = [2.0, 3.0, 4.0]
    [limits]                       # all optional
    tension = 1500.0               # N per wire, at rest and in the measured motions
    floor = -6.0                   # world z of the floor, m
    clearance = 0.05               # m the body's lowest point must keep above the floor
    [measure]
    axes = ["x", "y", "z"]         # the body axes whose moments are identified
    amplitude = 0.05               # rad, the swing at which periods are timed
    objective = "worst"            # "worst" (max relative sigma over axes, default) or "mean"

The grid is the Cartesian product of the axes, in file order, the last axis fastest.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from bifilar.rig import Rig, RigError, load_rig
from bifilar.rig.checks import no_unknown, number, positive, read_toml, required, table
from bifilar.sweep.axes import AXES, POSITIVE

MAX_POINTS = 10**7  # a larger grid is a mistake: 10^7 configurations take hours even at 1000/s
MAX_STEPS = 10**6  # per axis
OBJECTIVES = ("worst", "mean")
_TOP = {"rig", "vary", "limits", "measure"}
_LIMITS = {"tension", "floor", "clearance"}
_MEASURE = {"axes", "amplitude", "objective"}
_RANGE = {"from", "to", "steps", "log"}


@dataclass(frozen=True)
class Limits:
    tension: float | None = None  # N
    floor: float | None = None  # world z, m
    clearance: float = 0.0  # m


@dataclass(frozen=True)
class Space:
    source: str
    rig: Rig
    axes: dict[str, np.ndarray]  # name -> values, file order
    limits: Limits
    measure: tuple[str, ...]  # body axes "x", "y", "z"
    amplitude: float  # rad
    objective: str

    @property
    def size(self) -> int:
        return int(np.prod([len(v) for v in self.axes.values()]))

    def points(self):
        """Every configuration as a dict axis -> value, in grid order."""
        names = list(self.axes)
        for combo in itertools.product(*self.axes.values()):
            yield dict(zip(names, (float(v) for v in combo)))


def _values(raw, src: str, name: str) -> np.ndarray:
    field = f"vary.{name}"
    if isinstance(raw, list):
        if not raw:
            raise RigError(src, field, "empty list: give at least one value")
        if len(raw) > MAX_STEPS:
            raise RigError(src, field, f"{len(raw)} values, at most {MAX_STEPS}")
        values = np.array([number(v, src, f"{field}[{i}]") for i, v in enumerate(raw)])
    elif isinstance(raw, dict):
        no_unknown(raw, _RANGE, src, field + ".")
        low = number(required(raw, "from", src, field + "."), src, field + ".from")
        high = number(required(raw, "to", src, field + "."), src, field + ".to")
        steps = required(raw, "steps", src, field + ".")
        if isinstance(steps, bool) or not isinstance(steps, int) or not 1 <= steps <= MAX_STEPS:
            raise RigError(src, field + ".steps", f"must be a whole number from 1 to {MAX_STEPS}")
        log = raw.get("log", False)
        if not isinstance(log, bool):
            raise RigError(src, field + ".log", "must be true or false")
        if steps > 1 and low == high:
            raise RigError(src, field, f"empty range: from = to = {low:g} with {steps} steps")
        if log:
            if low <= 0.0 or high <= 0.0:
                raise RigError(src, field, "log = true needs from and to above zero")
            values = np.geomspace(low, high, steps)
        else:
            values = np.linspace(low, high, steps)
    else:
        raise RigError(src, field, "must be a list of values or a table {from, to, steps}")
    if name in POSITIVE and values.min() <= 0.0:
        raise RigError(src, field, f"must be above zero (a distance, m); found {values.min():g}")
    return values


def load_space(path: str | Path) -> Space:
    """Read and check a sweep file; raise :class:`RigError` (file, field, problem) on any problem."""
    src = str(path)
    data = read_toml(path)
    no_unknown(data, _TOP, src, "")
    rig_name = required(data, "rig", src, "")
    if not isinstance(rig_name, str):
        raise RigError(src, "rig", "must be the path of a rig file (relative to this file)")
    rig = load_rig(Path(path).parent / rig_name)
    vary = table(data, "vary", src, mandatory=True)
    if not vary:
        raise RigError(src, "vary", "no axis to vary: name at least one of " + ", ".join(AXES))
    axes = {}
    for name, raw in vary.items():
        if name not in AXES:
            raise RigError(src, f"vary.{name}", "unknown axis; the axes are " + ", ".join(AXES))
        axes[name] = _values(raw, src, name)
    total = math.prod(len(v) for v in axes.values())
    if total > MAX_POINTS:
        raise RigError(src, "vary", f"{total} configurations: at most {MAX_POINTS}")
    lim = table(data, "limits", src, mandatory=False)
    no_unknown(lim, _LIMITS, src, "limits.")
    limits = Limits(
        tension=positive(lim["tension"], src, "limits.tension") if "tension" in lim else None,
        floor=number(lim["floor"], src, "limits.floor") if "floor" in lim else None,
        clearance=number(lim.get("clearance", 0.0), src, "limits.clearance"),
    )
    if limits.clearance < 0.0:
        raise RigError(src, "limits.clearance", "must be zero or more (m)")
    meas = table(data, "measure", src, mandatory=False)
    no_unknown(meas, _MEASURE, src, "measure.")
    measured = meas.get("axes", ["x", "y", "z"])
    if not isinstance(measured, list) or not measured or not all(a in ("x", "y", "z") for a in measured):
        raise RigError(src, "measure.axes", 'must be a non-empty list of "x", "y", "z"')
    amplitude = positive(meas.get("amplitude", 0.05), src, "measure.amplitude")
    if amplitude > 1.0:
        raise RigError(src, "measure.amplitude", f"{amplitude:g} rad: a timed swing is at most 1 rad")
    objective = meas.get("objective", "worst")
    if objective not in OBJECTIVES:
        raise RigError(src, "measure.objective", "must be one of " + ", ".join(OBJECTIVES))
    return Space(src, rig, axes, limits, tuple(dict.fromkeys(measured)), amplitude, objective)
