"""The sweep file: a base rig and the configurations to evaluate, the limits and what is to be measured.

TOML, SI units and radians, the rig file's conventions::

    rig = "../rigs/plate.toml"     # the base rig (body, [uncertainty]); path relative to this file
    [vary]                         # each axis (bifilar.sweep.axes): a list, or {from, to, steps[, log]}
    wire_length = {from = 1.0, to = 6.0, steps = 26}
    attach_span = [2.0, 3.0, 4.0]
    [limits]                       # all optional
    tension = 1500.0               # N per wire, at rest and in the measured motions
    floor = -6.0                   # world z of the floor, m
    clearance = 0.05               # m the body's lowest point must keep above the floor
    separation = 0.05              # each measured mode this far in frequency from every other mode
    [measure]
    axes = ["x", "y", "z"]         # the body axes whose moments are identified
    amplitude = 0.05               # rad, the swing at which periods are timed
    objective = "worst"            # "worst" (max relative sigma over axes, default) or "mean"

The grid is the Cartesian product of the axes, in file order, the last axis fastest.

Instead of ``[vary]``, a file may list explicit configurations, each a ``[[point]]`` table of axis
values (every point the same axes; an optional unique ``name``), evaluated in file order::

    [[point]]
    name = "3"                     # optional
    attach_inset = 1.0             # m, any axis of bifilar.sweep.axes

Instead of ``rig``, ``suspension = "suspension.toml"`` names a suspension file
(:mod:`bifilar.bodies.boat`): the base rig is its body hung from the hall's hooks with the attachments
at the deck's ends (so ``attach_inset`` is the thesis's inset), ``limits.floor`` defaults to the hall's
floor, and the clearance is that of the lowest point of the body's parts, not of its inertia box.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from bifilar.bodies.boat import load_suspension
from bifilar.bodies.composite import Part
from bifilar.rig import Rig, RigError, load_rig
from bifilar.rig.checks import no_unknown, number, positive, read_toml, required, table
from bifilar.rig.file import check_heavy_inextensible
from bifilar.rig.ranges import check_ranges
from bifilar.sweep.axes import AXES, POSITIVE, attach_span_of, configure

MAX_POINTS = 10**7  # a larger grid is a mistake: 10^7 configurations take hours even at 1000/s
MAX_STEPS = 10**6  # per axis
OBJECTIVES = ("worst", "mean")
_TOP = {"rig", "suspension", "vary", "point", "limits", "measure"}
_LIMITS = {"tension", "floor", "clearance", "separation"}
_MEASURE = {"axes", "amplitude", "objective"}
_RANGE = {"from", "to", "steps", "log"}


@dataclass(frozen=True)
class Limits:
    tension: float | None = None  # N
    floor: float | None = None  # world z, m
    clearance: float = 0.0  # m
    separation: float | None = None  # relative gap in frequency (evaluate.nearest)


@dataclass(frozen=True)
class Space:
    source: str
    rig: Rig
    axes: dict[str, np.ndarray]  # name -> values, file order
    limits: Limits
    measure: tuple[str, ...]  # body axes "x", "y", "z"
    amplitude: float  # rad
    objective: str
    explicit: bool = False  # the configurations are the [[point]] tables: axes[name][k] is point k's
    names: tuple[str | None, ...] = ()  # the points' names (explicit files)
    parts: tuple[Part, ...] | None = None  # the body's parts (suspension files): its clearance

    @property
    def size(self) -> int:
        if self.explicit:
            return len(next(iter(self.axes.values())))
        return int(np.prod([len(v) for v in self.axes.values()]))

    def points(self, start: int = 0, stop: int | None = None):
        """Configurations ``start`` .. ``stop - 1`` (default every one) as dicts axis -> value, in grid
        (or file) order: the last axis fastest. Each is reached from its index (C order), so a chunk
        deep in a large grid costs no walk through the configurations before it."""
        names, values = list(self.axes), list(self.axes.values())
        shape = [len(v) for v in values]
        for index in range(start, self.size if stop is None else min(stop, self.size)):
            at = [index] * len(values) if self.explicit else np.unravel_index(index, shape)
            yield {name: float(v[k]) for name, v, k in zip(names, values, at)}


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
    return values


def _check_axis(rig: Rig, name: str, values: np.ndarray, src: str, field: str) -> None:
    """The values' physical range: lengths and stiffnesses above zero, an inset short of the attachments' midpoint."""
    if name in POSITIVE and values.min() <= 0.0:
        raise RigError(src, field, f"must be above zero ({POSITIVE[name]}); found {values.min():g}")
    if name == "attach_inset":
        half = 0.5 * attach_span_of(rig)
        if values.min() < 0.0 or values.max() >= half:
            raise RigError(src, field, f"must be from 0 to under half the base rig's attachment span ({half:g} m); "
                                       f"found {values.min():g} to {values.max():g}")
    for value in sorted({float(values.min()), float(values.max())}):
        configured = configure(rig, {name: value})
        try:  # the rig file's ranges (bifilar.rig.ranges), on the base rig with this axis at this value
            check_ranges(configured)
        except RigError as exc:
            raise RigError(src, field, f"{value:g} is outside the rig file's ranges ({exc.field}: {exc.problem})") from None
        try:  # and the file's rules across fields: an elastic axis on heavy wires (issue 35 item 6)
            check_heavy_inextensible(configured.wires, src)
        except RigError as exc:
            raise RigError(src, field, f"{value:g} makes a rig that a rig file refuses ({exc.field} of the base "
                                       f"rig: {exc.problem})") from None


def _points(raw, src: str) -> tuple[dict[str, np.ndarray], tuple]:
    """The [[point]] tables as axis -> values (point order) and their names."""
    if not isinstance(raw, list) or not raw or not all(isinstance(p, dict) for p in raw):
        raise RigError(src, "point", "must be [[point]] tables of axis values")
    if len(raw) > MAX_POINTS:
        raise RigError(src, "point", f"{len(raw)} points: at most {MAX_POINTS}")
    first = [k for k in raw[0] if k != "name"]
    columns, names = {k: [] for k in first}, []
    for i, point in enumerate(raw, start=1):
        prefix = f"point[{i}]."
        no_unknown(point, set(AXES) | {"name"}, src, prefix)
        keys = [k for k in point if k != "name"]
        if not keys:
            raise RigError(src, f"point[{i}]", "no axis value: give at least one of " + ", ".join(AXES))
        if set(keys) != set(first):
            raise RigError(src, f"point[{i}]", f"gives {', '.join(sorted(keys))}; every point must give the same "
                                               f"axes as point[1] ({', '.join(sorted(first))})")
        name = point.get("name")
        if name is not None and (not isinstance(name, str) or not name or name in names):
            raise RigError(src, prefix + "name", f"must be a non-empty, unique string, got {name!r}")
        names.append(name)
        for k in first:
            columns[k].append(number(point[k], src, prefix + k))
    return {k: np.array(v) for k, v in columns.items()}, tuple(names)


def _base(data: dict, src: str, path: Path):
    """The base rig and, for a suspension file, its parts and the hall's floor."""
    given = [k for k in ("rig", "suspension") if k in data]
    if len(given) != 1:
        raise RigError(src, "rig", "give the base as rig = RIG.toml or suspension = SUSPENSION.toml (one of them)")
    key = given[0]
    if not isinstance(data[key], str):
        raise RigError(src, key, f"must be the path of a {key} file (relative to this file)")
    if key == "rig":
        return load_rig(path.parent / data[key]), None, None
    s = load_suspension(path.parent / data[key])
    return s.base_rig(), s.parts, s.floor


def load_space(path: str | Path) -> Space:
    """Read and check a sweep file; raise :class:`RigError` (file, field, problem) on any problem."""
    src = str(path)
    data = read_toml(path)
    no_unknown(data, _TOP, src, "")
    rig, parts, hall_floor = _base(data, src, Path(path))
    if ("vary" in data) == ("point" in data):
        raise RigError(src, "vary", "give the configurations as a [vary] grid or as [[point]] tables (one of them)")
    if "point" in data:
        axes, names = _points(data["point"], src)
        for name, values in axes.items():
            for i in range(len(values)):
                _check_axis(rig, name, values[i:i + 1], src, f"point[{i + 1}].{name}")
    else:
        vary, names = table(data, "vary", src, mandatory=True), ()
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
        for name, values in axes.items():
            _check_axis(rig, name, values, src, f"vary.{name}")
    if "attach_span" in axes and "attach_inset" in axes:
        raise RigError(src, "attach_inset", "give attach_span or attach_inset, not both")
    lim = table(data, "limits", src, mandatory=False)
    no_unknown(lim, _LIMITS, src, "limits.")
    limits = Limits(
        tension=positive(lim["tension"], src, "limits.tension") if "tension" in lim else None,
        floor=number(lim["floor"], src, "limits.floor") if "floor" in lim else hall_floor,
        clearance=number(lim.get("clearance", 0.0), src, "limits.clearance"),
        separation=positive(lim["separation"], src, "limits.separation") if "separation" in lim else None,
    )
    if limits.clearance < 0.0:
        raise RigError(src, "limits.clearance", "must be zero or more (m)")
    if limits.separation is not None and limits.separation >= 1.0:
        raise RigError(src, "limits.separation", f"{limits.separation:g}: a relative gap in frequency, under 1")
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
    return Space(src, rig, axes, limits, tuple(dict.fromkeys(measured)), amplitude, objective,
                 explicit="point" in data, names=names, parts=parts)
