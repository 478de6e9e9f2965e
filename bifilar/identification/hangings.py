"""A hangings file (``validate tensor HANGINGS.toml``): read, measured and turned into what
:func:`bifilar.identification.tensor.identify_tensor` fits.

The file holds ``[[hanging]]`` tables (docs/identification.md section 8 gives every key):

* ``rig``: the rig as hung (path relative to the hangings file). Without a ``tare``, its ``[body]`` is
  the object in its own axes, the same table in every hanging (mass; ``com`` in object axes from the
  origin of the rig's body frame; ``inertia`` a starting guess or ``nan``), and the rig hangs it turned
  by ``orientation``: COM at Q com, inertia Q X Q^T. With a ``tare``, its ``[body]`` mass and ``com``
  (rig body frame) are the whole assembly's (fixture and object), its ``inertia`` is not used.
* ``orientation``: object axes -> the rig's body axes, a rotation vector (rad) or a 3x3 matrix.
* ``period`` (s, the small-amplitude yaw period, or the period timed at ``amplitude`` rad) with an
  optional ``period_std`` (s; default the rig's ``[uncertainty].period``), or ``signal`` (records)
  with identify's record options (``column``, ``kind``, ``time_column``, ``fps``, ``time_unit``,
  ``angle_unit``, ``from``, ``to``, ``law_sigma``, ``amplitude_scale``, ``max_amplitude``).
* ``tare = { rig = "FIXTURE.toml", period = s, period_std = s }`` or ``{ rig = ..., signal = [...] }``:
  the fixture alone, hung the same way, in the same body frame. Its moment about its vertical is
  measured once per distinct tare (identical tare tables are one measurement, shared by every hanging
  naming it: its error is correlated between them); the object's mass and COM are the assembly's
  minus the fixture's, and the held part of each hanging's inertia is the fixture's tensor and both
  parallel-axis terms about the assembly's COM, exactly.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from bifilar.rig import Rig, RigError
from bifilar.rig.checks import no_unknown, number, positive, read_toml, required, vector3, within
from bifilar.rig.file import rig_from_dict
from bifilar.rig.ranges import MAX_PERIOD_SIGMA, MAX_RELATIVE_SIGMA, rig_size
from bifilar.rig.statics import rest_pose

from .measurement import measure, said_once, start_moment
from .identify import AMPLITUDE_PASSES, amplitude_ratio, axis_vector, invert_period, settled, with_moment
from .records.law import EXCESS_PRIOR
from .records.pipeline import RecordOptions, identify_records
from .tensor import Hanging, Tare, Tensor, identify_tensor, moment_row, tensor_of
from .transfer import parallel_axis

_RECORD_KEYS = {"column", "kind", "time_column", "fps", "time_unit", "angle_unit", "from", "to", "law_sigma",
                "amplitude_scale", "max_amplitude"}
_HANGING_KEYS = {"rig", "orientation", "period", "period_std", "amplitude", "signal", "tare", "name"} | _RECORD_KEYS
_TARE_KEYS = {"rig", "period", "period_std", "signal"} | _RECORD_KEYS
_PLACEHOLDER = 1e-2  # m^2 x mass: an isotropic stand-in for an unknown inertia while the rig is read
_GUESSES = (0.5, 0.2, 1.0, 0.05, 2.0)  # x m r^2: a first pass's isotropic guesses, most likely first
_ROTATION_TOL = 1e-6  # |Q^T Q - 1| and |det Q - 1| of a given matrix
_SAME_MASS = 1e-3  # relative: objects whose masses differ by more are not the same object
_SAME_COM = 1e-3  # x rig size: the same for the COM
PERIOD_RANGE = (1e-3, 1e5)  # s: a measured period, from a millisecond to a day; beyond, a unit or typing mistake
MAX_TURN = 2.0 * math.pi  # rad: the norm of an orientation's rotation vector; more is a unit mistake (degrees?)


@dataclass(frozen=True)
class Measured:
    """A period (s) with its sigma (s), how it was obtained, and the records' trials (if any)."""

    period: float
    std: float
    source: str
    trials: tuple = ()


@dataclass(frozen=True)
class Fixture:
    """A tare as measured: the fixture rig with its identified moment about ``axis``."""

    rig: Rig
    axis: np.ndarray
    moment: float
    std: float
    measured: Measured
    key: tuple
    assumed: tuple[int, ...] = ()  # body axes whose moment the file left nan: taken as a flat platform's


@dataclass
class Setup:
    """Everything the tensor fit needs, and what the report says of the inputs."""

    hangings: list[Hanging]
    tares: tuple[Tare, ...]
    fixtures: list[Fixture]
    measured: list[Measured]
    start: np.ndarray
    mass: float
    com: np.ndarray | None  # object axes (without a tare), else None
    flags: list[str] = field(default_factory=list)

    @property
    def unknowns(self) -> int:
        """The components fitted: all six (a hinge hangings file may hold some known)."""
        return 6


def read_hangings(path: str | Path) -> Setup:
    """Read the hangings file, measure every period (records fitted, tares identified) and build the
    hangings; every problem is a one-line :class:`RigError` naming the file and the field."""
    src, folder = str(path), Path(path).parent
    data = read_toml(path)
    no_unknown(data, {"hanging", "name"}, src, "")
    raw = data.get("hanging")
    if not isinstance(raw, list) or not raw or not all(isinstance(h, dict) for h in raw):
        raise RigError(src, "hanging", "missing: give the hangings as [[hanging]] tables")
    if len(raw) < 6:
        raise RigError(src, "hanging", f"{len(raw)} hangings cannot determine the 6 tensor components: give at "
                                       "least 6 orientations")
    entries = [_entry(h, i, src, folder) for i, h in enumerate(raw, start=1)]
    _tare_in_all_or_none(entries, src)
    fixtures: dict[tuple, Fixture] = {}
    for e in entries:
        if e.tare is not None and e.tare.key not in fixtures:
            fixtures[e.tare.key] = _measure_fixture(e.tare)
    keys = list(fixtures)
    mass, com = _object_body(entries, fixtures, src)
    held = [_held(e, fixtures.get(e.tare.key) if e.tare else None, mass) for e in entries]
    start = _given_start(entries)
    if start is not None:
        measured = [_measure(e, h, start) for e, h in zip(entries, held)]
    else:  # the amplitude law depends on the inertia: a first pass at guesses, then all at a real start
        measured = [_first_pass(e, h, mass) for e, h in zip(entries, held)]
        start = _start_from_periods(entries, held, measured, mass)
        measured = [_measure(e, h, start) if e.signals or e.amplitude else m
                    for e, h, m in zip(entries, held, measured)]
    tares = tuple(Tare(f.axis, f.std) for f in fixtures.values())
    tare_of = [keys.index(e.tare.key) if e.tare else None for e in entries]
    hangings = _hangings(entries, held, measured, start, tare_of)
    if any(e.amplitude > 0.0 and not e.signals for e in entries):
        start, measured, hangings = _amplitude_fixed_point(entries, held, measured, hangings, start, tares, tare_of,
                                                           src)
    # a record's flag is said once for every record it applies to (30 records of one rig share most)
    said = [(f"{e.label} {name}", what) for e, m in zip(entries, measured) for tr in m.trials for name, what in tr.said]
    said += [(f"tare {f.rig.source} {name}", what) for f in fixtures.values() for tr in f.measured.trials
             for name, what in tr.said]
    flags = said_once(said)
    flags += [f"tare {f.rig.source}: I_{'xy'[i]}{'xy'[i]} is nan there: taken as a flat platform's, I_zz / 2"
              for f in fixtures.values() for i in f.assumed]
    return Setup(hangings, tares, list(fixtures.values()), measured, start, mass, com, flags)


def _hangings(entries: list[_Entry], held: list[np.ndarray], measured: list[Measured], x: np.ndarray,
              tare_of: list[int | None]) -> list[Hanging]:
    """The hangings as the tensor fit takes them, each rig hung with the object's tensor ``x``."""
    return [Hanging(_hung(e, h, x), m.period, m.std, e.orientation, h, t, e.label)
            for e, h, m, t in zip(entries, held, measured, tare_of)]


def _amplitude_fixed_point(entries, held, measured, hangings, x, tares, tare_of, src):
    """:func:`bifilar.identification.identify.identify`'s fixed point J = invert(T / ratio(J)), for the
    tensor: a period given at an amplitude is taken to zero amplitude by the law of the rig hung with
    the fitted tensor, and the tensor refitted, until it has settled by identify's rule
    (:func:`bifilar.identification.identify.settled`). Without it the law was the start tensor's, and a hanging's
    moment differed from identify's for the same rig, period and amplitude by ~1e-6 at 0.3 rad.
    Records are left as measured: their fit learns the law's excess from the record itself. ``hangings``:
    as hung with ``x``."""
    step = np.inf
    for _ in range(AMPLITUDE_PASSES):
        fitted = identify_tensor(hangings, x, tares, src).inertia
        measured = [_measure(e, h, fitted) if e.amplitude > 0.0 and not e.signals else m
                    for e, h, m in zip(entries, held, measured)]
        hangings = _hangings(entries, held, measured, fitted, tare_of)
        previous, step = step, np.abs(fitted - x).max() / np.abs(fitted).max()
        if settled(step, previous):
            return fitted, measured, hangings
        x = fitted
    raise RigError(src, "hanging", f"the amplitude correction did not converge in {AMPLITUDE_PASSES} passes")


def fit_hangings(setup: Setup, source: str) -> Tensor:
    """The object's tensor from a read :class:`Setup`."""
    return identify_tensor(setup.hangings, setup.start, setup.tares, source)


@dataclass(frozen=True)
class _Tare:
    path: Path
    period: float | None
    period_std: float | None
    signals: tuple[Path, ...]
    options: RecordOptions
    name: str

    @property
    def key(self) -> tuple:
        return (self.path.resolve(), self.period, self.period_std, tuple(p.resolve() for p in self.signals),
                self.options)


@dataclass(frozen=True)
class _Entry:
    label: str
    data: dict  # the rig file as parsed
    rig_path: Path
    orientation: np.ndarray
    period: float | None
    period_std: float | None
    amplitude: float
    signals: tuple[Path, ...]
    options: RecordOptions
    tare: _Tare | None
    inertia_given: np.ndarray | None  # the [body] inertia (object axes) if finite


def _entry(h: dict, i: int, src: str, folder: Path) -> _Entry:
    prefix = f"hanging[{i}]."
    no_unknown(h, _HANGING_KEYS, src, prefix)
    rig_path = _path(required(h, "rig", src, prefix), folder, src, prefix + "rig")
    data = read_toml(rig_path)
    inertia_given = _body_inertia(data, str(rig_path))
    period, period_std, signals, options = _source(h, src, prefix, folder)
    amplitude = _amplitude(h, src, prefix, period)
    tare = None
    if "tare" in h:
        t = h["tare"]
        if not isinstance(t, dict):
            raise RigError(src, prefix + "tare", "must be a table: { rig = \"FIXTURE.toml\", period = s } or "
                                                 "{ rig = ..., signal = [...] }")
        no_unknown(t, _TARE_KEYS, src, prefix + "tare.")
        tp = _path(required(t, "rig", src, prefix + "tare."), folder, src, prefix + "tare.rig")
        tare = _Tare(tp, *_source(t, src, prefix + "tare.", folder), name=f"{src}: {prefix}tare")
    label = h.get("name", f"hanging[{i}]")
    if not isinstance(label, str):
        raise RigError(src, prefix + "name", "must be a string")
    return _Entry(label, data, rig_path, orientation(h.get("orientation"), src, prefix + "orientation"), period,
                  period_std, amplitude, signals, options, tare, inertia_given)


def _path(value, folder: Path, src: str, name: str) -> Path:
    if not isinstance(value, str) or not value:
        raise RigError(src, name, "must be a file name (a string, relative to the hangings file)")
    return folder / value


def _source(t: dict, src: str, prefix: str, folder: Path):
    """(period, period_std, signals, record options) of a hanging or tare table."""
    has_period, has_signal = "period" in t, "signal" in t
    if has_period == has_signal:
        raise RigError(src, prefix + "period", "give either period (s) or signal (records), not "
                       + ("both" if has_period else "neither"))
    period = None
    if has_period:
        period = within(positive(t["period"], src, prefix + "period"), *PERIOD_RANGE, src, prefix + "period", "s",
                        "a measured period, from a millisecond to a day")
    period_std = None
    if "period_std" in t:
        if not has_period:
            raise RigError(src, prefix + "period_std", "goes with period; a record's sigma is fitted")
        period_std = period_sigma(t["period_std"], src, prefix + "period_std", period)
    signals: tuple[Path, ...] = ()
    if has_signal:
        value = t["signal"]
        value = [value] if isinstance(value, str) else value
        if not isinstance(value, list) or not value:
            raise RigError(src, prefix + "signal", "must be a list of record files")
        signals = tuple(_path(v, folder, src, f"{prefix}signal[{k}]") for k, v in enumerate(value, start=1))
    given = sorted(k for k in _RECORD_KEYS if k in t)
    if given and not has_signal:
        raise RigError(src, prefix + given[0], "goes with signal (records)")
    return period, period_std, signals, _options(t, src, prefix)


def _options(t: dict, src: str, prefix: str) -> RecordOptions:
    choices = {"kind": ("angle", "rate", "proportional"), "time_unit": ("s", "ms"), "angle_unit": ("rad", "deg")}
    for key, allowed in choices.items():
        if key in t and t[key] not in allowed:
            raise RigError(src, prefix + key, f"must be one of {', '.join(allowed)}, got {t[key]!r}")
    for key in ("column", "time_column"):
        if key in t and not isinstance(t[key], str):
            raise RigError(src, prefix + key, "must be a column name (a string)")
    num = {k: number(t[k], src, prefix + k) for k in ("from", "to") if k in t}
    if "from" in num and "to" in num and num["to"] <= num["from"]:
        raise RigError(src, prefix + "to", f"{num['to']:g} must be after from = {num['from']:g}")
    fps = positive(t["fps"], src, prefix + "fps") if "fps" in t else None
    scale = positive(t["amplitude_scale"], src, prefix + "amplitude_scale") if "amplitude_scale" in t else None
    peak = positive(t["max_amplitude"], src, prefix + "max_amplitude") if "max_amplitude" in t else None
    if peak is not None and peak > math.pi:
        raise RigError(src, prefix + "max_amplitude", f"{peak:g} rad is more than pi")
    law_sigma = EXCESS_PRIOR
    if "law_sigma" in t:
        law_sigma = number(t["law_sigma"], src, prefix + "law_sigma")
        if not 0.0 <= law_sigma <= 10.0:
            raise RigError(src, prefix + "law_sigma", f"{law_sigma:g} outside 0 .. 10")
    return RecordOptions(t.get("column"), t.get("kind", "angle"), t.get("time_column"), fps, t.get("time_unit", "s"),
                         t.get("angle_unit", "rad"), num.get("from"), num.get("to"), law_sigma, scale, peak)


def _amplitude(h: dict, src: str, prefix: str, period) -> float:
    if "amplitude" not in h:
        return 0.0
    if period is None:
        raise RigError(src, prefix + "amplitude", "goes with period; a record's amplitude is fitted")
    value = positive(h["amplitude"], src, prefix + "amplitude")
    if value > 0.5 * math.pi:
        raise RigError(src, prefix + "amplitude", f"{value:g} rad is past pi/2: is it in degrees?")
    return value


def period_sigma(value, src: str, name: str, period: float | None = None) -> float:
    """A period's sigma (s): positive, at most the rig file's bound for ``[uncertainty].period`` and, with
    the ``period`` it goes with, at most the share of it a rig file allows for any sigma."""
    sigma = within(positive(value, src, name), 0.0, MAX_PERIOD_SIGMA, src, name, "s", "a period's sigma")
    if period is not None and sigma > MAX_RELATIVE_SIGMA * period:
        raise RigError(src, name, f"{sigma:.6g} s is more than {MAX_RELATIVE_SIGMA:g} of the period {period:.6g} s: "
                                  "not a measurement's sigma")
    return sigma


def orientation(value, src: str, name: str) -> np.ndarray:
    """Q (object axes -> rig body axes) from a rotation vector (rad) or a 3x3 rotation matrix."""
    if value is None:
        return np.eye(3)
    if isinstance(value, list) and len(value) == 3 and all(isinstance(r, list) for r in value):
        q = np.array([[number(x, src, f"{name}[{i}][{k}]") for k, x in enumerate(r)] if len(r) == 3 else
                      _bad_matrix(src, name) for i, r in enumerate(value)])
        if np.abs(q.T @ q - np.eye(3)).max() > _ROTATION_TOL or abs(np.linalg.det(q) - 1.0) > _ROTATION_TOL:
            raise RigError(src, name, f"is not a rotation matrix (Q^T Q = 1 and det Q = +1 to {_ROTATION_TOL:g})")
        return q
    vector = vector3(value, src, name)
    within(math.hypot(*vector), 0.0, MAX_TURN, src, name, "rad",
           "the norm of a rotation vector, at most a turn: is it in degrees?")
    return Rotation.from_rotvec(vector).as_matrix()


def _bad_matrix(src: str, name: str):
    raise RigError(src, name, "must be a rotation vector (three numbers, rad) or a 3x3 matrix")


def _body_inertia(data: dict, src: str) -> np.ndarray | None:
    """The [body] inertia if every entry is a finite number, None if any is nan (checked when the rig
    is built)."""
    body = data.get("body")
    value = body.get("inertia") if isinstance(body, dict) else None
    flat = np.ravel(np.array(value, dtype=object)) if isinstance(value, list) else []
    if any(isinstance(v, float) and math.isnan(v) for v in flat):
        return None
    rig = rig_from_dict(data, src)  # the checks of a finite tensor
    return rig.inertia


def _rig(data: dict, src: str, com=None, inertia=None) -> Rig:
    """The rig of a parsed file (checked as a rig file, a nan inertia read as a stand-in), then with its
    COM and inertia replaced where given. The replaced tensor is a model's (a thin platform's, held, plus
    an object's guess) and is not held to a rig file's checks: only the fitted object's tensor is."""
    body = dict(data.get("body") or {})
    if any(isinstance(v, float) and math.isnan(v) for v in np.ravel(np.array(body.get("inertia", []), dtype=object))):
        m = positive(required(body, "mass", src, "body."), src, "body.mass")
        body["inertia"] = [_PLACEHOLDER * m] * 3
    rig = rig_from_dict({**data, "body": body}, src)
    return replace(rig, com=rig.com if com is None else np.asarray(com, float),
                   inertia=rig.inertia if inertia is None else np.asarray(inertia, float))


def _measure_fixture(t: _Tare) -> Fixture:
    """The tare's fixture measured about its vertical at rest by :func:`.measurement.measure`, the step
    ``identify`` takes, with the period's sigma alone propagated (``propagate="period"``): the tensor
    fit propagates no rig geometry for any hanging, and the tare is one of its inputs."""
    data = read_toml(t.path)
    rig, unknown = _fixture_rig(data, str(t.path))
    axis = _vertical(rig)
    m = measure(rig, axis, period=t.period, period_std=t.period_std, signals=list(t.signals) if t.signals else None,
                options=t.options, propagate="period")
    period_std = m.period_std or 0.0
    source = f"{len(m.trials)} record(s)" if t.signals else f"given, sigma: {_sigma_source(t.period_std, period_std)}"
    measured = Measured(m.period, period_std, source, m.trials)
    own = m if m.air is None else m.air  # in air: the body's own moment, as the hangings' rigs carry their air
    moment, std = own.inertia, own.std or 0.0
    fixture = with_moment(rig, axis_vector(axis), moment)  # as the inversion's rig (its axis is a unit vector)
    if unknown:  # a flat platform: I_xx = I_yy = I_zz / 2 where the file does not say
        inertia = fixture.inertia.copy()
        for i in unknown:
            inertia[i, i] = 0.5 * moment
        fixture = replace(fixture, inertia=inertia)
    return Fixture(fixture, axis, moment, std, measured, t.key, tuple(unknown))


def _fixture_rig(data: dict, src: str) -> tuple[Rig, list[int]]:
    """The fixture's rig and the indices of its unknown (nan) I_xx, I_yy. The moment its period
    measures, I_zz, may be nan (a start value then: the mean of the others, or a stand-in), and so
    may I_xx and I_yy (then taken as a flat platform's, I_zz / 2: they enter only through the
    platform's tilt)."""
    body = dict(data.get("body") or {})
    value = body.get("inertia")
    if isinstance(value, list) and len(value) == 3 and all(isinstance(r, list) and len(r) == 3 for r in value):
        cells = [[value[i][k] for k in range(3)] for i in range(3)]
    elif isinstance(value, list) and len(value) == 3:
        cells = [[value[i] if i == k else 0.0 for k in range(3)] for i in range(3)]
    else:
        return rig_from_dict(data, src), []  # its own one-line error
    nan = [i for i in range(3) if isinstance(cells[i][i], float) and math.isnan(cells[i][i])]
    if nan:
        mass = positive(required(body, "mass", src, "body."), src, "body.mass")
        diagonal = np.diag([math.nan if i in nan else number(cells[i][i], src, f"body.inertia[{i}]") for i in (0, 1)]
                           + [0.0])
        zz = cells[2][2] if 2 not in nan else (start_moment(diagonal, 2) or _PLACEHOLDER * mass)
        for i in nan:
            cells[i][i] = zz if i == 2 else 0.5 * number(zz, src, "body.inertia[2]")
        body["inertia"] = cells
    return rig_from_dict({**data, "body": body}, src), [i for i in nan if i != 2]


def _measure_period(rig: Rig, axis, period, period_std, signals, options, amplitude) -> Measured:
    """The small-amplitude yaw period of ``rig`` from a given period or from records."""
    if signals:
        trials, pooled = identify_records(rig, axis, list(signals), options)
        return Measured(pooled.period, pooled.period_std, f"{len(trials)} record(s)", tuple(trials))
    std = rig.uncertainty.period if period_std is None else period_std
    source = _sigma_source(period_std, std)
    if amplitude > 0.0:
        ratio = amplitude_ratio(rig, axis, amplitude)
        return Measured(period / ratio, std / ratio, f"given at {amplitude:g} rad, sigma: {source}")
    return Measured(period, std, f"given, sigma: {source}")


def _sigma_source(period_std: float | None, std: float) -> str:
    """Where a given period's sigma ``std`` came from: the file's ``period_std``, else the rig's."""
    return "period_std" if period_std is not None else ("the rig's [uncertainty].period" if std > 0.0 else "none")


def _tare_in_all_or_none(entries: list[_Entry], src: str) -> None:
    """Refuse a tare in some hangings only, naming the first hanging without one: the rigs' bodies are
    read differently with a tare (the whole assembly's) than without (the object's), so a mix would
    be blamed on a body's mass or COM, far from the cause."""
    tared = [e.tare is not None for e in entries]
    if any(tared) and not all(tared):
        i, k = tared.index(False), tared.index(True)
        raise RigError(src, f"hanging[{i + 1}].tare", f"missing in {entries[i].label}, given in {entries[k].label}: "
                       "give a tare in every hanging or in none (with one, each rig's body is the whole assembly)")


def _object_body(entries: list[_Entry], fixtures: dict, src: str) -> tuple[float, np.ndarray | None]:
    """The object's mass (kg) and, without tares, its COM (object axes); refused if they differ."""
    masses, coms = [], []
    for e in entries:
        body = e.data.get("body") or {}
        m = positive(required(body, "mass", str(e.rig_path), "body."), str(e.rig_path), "body.mass")
        if e.tare is not None:
            f = fixtures[e.tare.key]
            if m <= f.rig.mass:
                raise RigError(str(e.rig_path), "body.mass", f"{m:.6g} kg is not more than the tare's {f.rig.mass:.6g} kg "
                               f"({f.rig.source}): with a tare the rig's body is the whole assembly")
            m -= f.rig.mass
        masses.append(m)
        coms.append(None if e.tare else vector3(body.get("com", [0.0, 0.0, 0.0]), str(e.rig_path), "body.com"))
    for e, m in zip(entries, masses):
        if abs(m - masses[0]) > _SAME_MASS * masses[0]:
            what = "object's mass (assembly minus tare)" if e.tare else "body.mass"
            raise RigError(str(e.rig_path), "body.mass", f"the {what} {m:.6g} kg differs from {entries[0].label}'s "
                           f"{masses[0]:.6g} kg by more than {_SAME_MASS:.1%}: not the same object")
    if any(c is None for c in coms):  # every hanging has a tare (_tare_in_all_or_none)
        return masses[0], None
    size = min(rig_size(_rig(e.data, str(e.rig_path)).wires) for e in entries)
    for e, c in zip(entries, coms):
        if np.linalg.norm(c - coms[0]) > _SAME_COM * size:
            raise RigError(str(e.rig_path), "body.com", f"{np.round(c, 6).tolist()} m differs from "
                           f"{entries[0].label}'s {np.round(coms[0], 6).tolist()} m (object axes): not the same body "
                           "in the same body frame")
    return masses[0], coms[0]


def _vertical(rig: Rig) -> np.ndarray:
    """World z at the rig's rest pose, in its body frame: the axis its yaw turns about."""
    return rest_pose(rig).rotation.T @ np.array([0.0, 0.0, 1.0])


def _held(e: _Entry, fixture: Fixture | None, object_mass: float) -> np.ndarray:
    """H: the fixed part of the hanging rig's inertia about its COM, rig body axes (kg m^2)."""
    if fixture is None:
        return np.zeros((3, 3))
    src = str(e.rig_path)
    body = e.data.get("body") or {}
    m_a = positive(body["mass"], src, "body.mass")
    c_a = vector3(body.get("com", [0.0, 0.0, 0.0]), src, "body.com")
    f = fixture.rig
    c_o = (m_a * c_a - f.mass * f.com) / object_mass  # the object's mass shared by every hanging
    return f.inertia + parallel_axis(f.mass, f.com - c_a) + parallel_axis(object_mass, c_o - c_a)


def _hung(e: _Entry, held: np.ndarray, x: np.ndarray) -> Rig:
    """The hanging's rig as it hangs with the object's tensor ``x`` (3x3, object axes)."""
    q = e.orientation
    src = str(e.rig_path)
    if e.tare is not None:
        return _rig(e.data, src, inertia=held + q @ x @ q.T)
    body = e.data.get("body") or {}
    com = q @ vector3(body.get("com", [0.0, 0.0, 0.0]), src, "body.com")
    return _rig(e.data, src, com=com, inertia=q @ x @ q.T)


def _measure(e: _Entry, held: np.ndarray, x: np.ndarray) -> Measured:
    rig = _hung(e, held, x)
    axis = _vertical(rig)
    try:
        return _measure_period(rig, axis, e.period, e.period_std, e.signals, e.options, e.amplitude)
    except RigError as exc:
        raise RigError(exc.source, exc.field, f"{exc.problem} ({e.label})") from None


def _first_pass(e: _Entry, held: np.ndarray, mass: float) -> Measured:
    """The hanging measured with the object's tensor unknown: isotropic guesses f m r^2 (r the
    attachments' mean distance from the COM's vertical) in turn, from a disc's f = 1/2, until the
    records fit (at a large swing a wrong guess gives a law the record does not follow)."""
    rig = _hung(e, held, _PLACEHOLDER * mass * np.eye(3))
    vertical = _vertical(rig)
    arms = np.array([w.attach - rig.com for w in rig.wires])
    radius2 = float(np.mean(np.sum(arms ** 2, axis=1) - (arms @ vertical) ** 2))
    problem = None
    for f in _GUESSES:
        try:
            return _measure(e, held, f * mass * radius2 * np.eye(3))
        except RigError as exc:
            problem = problem or exc
    raise problem


def _given_start(entries: list[_Entry]) -> np.ndarray | None:
    """The first hanging's [body] inertia (object axes) if finite and the object hangs alone."""
    e = entries[0]
    return e.inertia_given if e.tare is None and e.inertia_given is not None else None


def _start_from_periods(entries: list[_Entry], held: list[np.ndarray], measured: list[Measured],
                        mass: float) -> np.ndarray:
    """A start tensor from each hanging's moment about its vertical alone (the rest of the tensor
    isotropic): n^T X n = J_h solved for the six components (least squares), or, where that is not
    positive definite, the mean moment times the identity."""
    rows, moments = [], []
    for e, h, m in zip(entries, held, measured):
        rig = _hung(e, h, _PLACEHOLDER * mass * np.eye(3))
        vertical = _vertical(rig)
        j = invert_period(rig, vertical, m.period).moment - float(vertical @ h @ vertical)
        rows.append(moment_row(e.orientation.T @ vertical))
        moments.append(j)
    x = tensor_of(np.linalg.lstsq(np.array(rows), np.array(moments), rcond=None)[0])
    if np.linalg.eigvalsh(x)[0] > 0.0:
        return x
    return max(float(np.mean(moments)), 1e-12) * np.eye(3)


