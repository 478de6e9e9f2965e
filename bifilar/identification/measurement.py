"""One measured moment of inertia, as every face of the tool reports it: the library behind ``validate identify``.

:func:`measure` takes a rig (the body as hung; the unknown moment may be ``nan``) and a period timed at
an amplitude, or record files, and returns a frozen :class:`Measurement`: the moment about a body axis
with its propagated sigma (the period's and the rig file's, or the period's alone, as a hangings file's
tare is measured for the tensor fit) and the sigma's parts, the figures per unit mass, the variance
budget, the check of the identified tensor, the records' trials and the flags. :func:`subtract_tare` turns the
measurements of an assembly and of its fixture alone into the object's own moment
(:class:`ObjectMoment`). ``as_dict()`` is the JSON object ``identify --json`` prints (its fields:
docs/identification.md); the CLI, the HTML page and the tensor's hangings read the typed fields.

The steps are those of docs/identification.md: a ``nan`` moment gets a start value (:func:`start_moment`),
the air's drag is left out of the model and its added mass kept (the moment found is the body's own;
the apparent one, with the air's added moment, is reported beside it), the rig is linearised once
(:func:`bifilar.identification.identify.pencil`), the period is taken to zero amplitude (the amplitude
law's fixed point for a timed period, the records' fits for records), inverted and propagated
(:mod:`bifilar.identification.propagation`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from bifilar.rig import Rig, RigError

from .air import added_moment, still, with_air
from .identify import axis_vector, identify, invert_period, pencil, with_moment
from .propagation import budget, linear_axes, monte_carlo, period_only
from .records.pipeline import (NEAR_BEATS, PART_THE_MODES, Pooled, RecordOptions, Trial, beats, identify_records,
                               near_modes, rig_has)
from .transfer import object_part, parallel_axis_moment

AXIS_INDEX = {"x": 0, "y": 1, "z": 2}
WEAK_SENSITIVITY = 0.02  # d ln T / d ln I below this: the period barely depends on the moment
Z95 = 1.959963984540054  # the standard normal's 97.5 % point: a 95 % interval is +- Z95 sigma
PROPAGATE = ("all", "period")  # what measure() propagates: the period's sigma and the rig file's, or the period's


@dataclass(frozen=True)
class TensorCheck:
    """Whether a tensor (kg m^2) can be a body's: its principal moments (ascending), positive
    definite, and the triangle inequality of the principal moments (to rounding)."""

    principal: tuple[float, float, float]
    positive_definite: bool
    triangle: bool

    @property
    def body(self) -> bool:
        """A body can have it."""
        return self.positive_definite and self.triangle

    def as_dict(self) -> dict:
        return {"principal": list(self.principal), "positive_definite": self.positive_definite,
                "triangle": self.triangle}


def tensor_check(inertia: np.ndarray) -> TensorCheck:
    """:class:`TensorCheck` of a 3x3 inertia tensor."""
    principal = np.linalg.eigvalsh(inertia)
    return TensorCheck(tuple(principal.tolist()), bool(principal[0] > 0.0),
                       bool(principal[0] + principal[1] >= principal[2] * (1.0 - 1e-9)))


@dataclass(frozen=True)
class AirPart:
    """The body's own moment (kg m^2) and sigma with the air's added moment taken out, the air's share
    of the measured moment, and the check of the body's own tensor."""

    inertia: float
    std: float
    share: float
    tensor_check: TensorCheck


@dataclass(frozen=True)
class ObjectMoment:
    """The object's own moment (kg m^2) about the axis through its own COM, from an assembly and its
    fixture (:func:`subtract_tare`): mass (kg), COM (body frame, m), sigma (None if neither states one),
    95 % interval, moment per unit mass (m^2) and flags."""

    mass: float
    com: tuple[float, float, float]
    inertia: float
    std: float | None
    inertia_per_mass: float
    flags: tuple[str, ...]

    @property
    def interval95(self) -> tuple[float, float] | None:
        return None if self.std is None else (self.inertia - 1.96 * self.std, self.inertia + 1.96 * self.std)

    def as_dict(self) -> dict:
        return {"mass": self.mass, "com": list(self.com), "inertia": self.inertia, "std": self.std,
                "interval95": None if self.interval95 is None else list(self.interval95),
                "inertia_per_mass": self.inertia_per_mass, "flags": list(self.flags)}


@dataclass(frozen=True)
class Measurement:
    """A moment of inertia (kg m^2) about the body axis ``axis`` of the rig named ``rig``.

    ``std`` is the propagated standard deviation (None where nothing was: the rig file states no
    sigma), ``std_repeatability`` its part from the period, ``std_rig`` from the rig's geometry and
    mass; ``period`` (s) is the zero-amplitude period inverted, ``timed_period`` the one given at
    ``amplitude`` (rad) where that differs; ``sensitivity`` is d ln T / d ln I (of the apparent moment in air). ``budget`` maps each
    uncertainty group to its share of var(I) (``budget_per_mass``: of var(I / m)). ``trials`` are the
    records' fits (empty for a period), ``pooled`` their pooled period. ``air`` is the body's own moment
    where the rig has an ``[air]`` table. ``tare`` and ``object_part`` are set by :func:`subtract_tare`.
    """

    rig: str
    source: str
    axis: str | tuple[float, float, float]
    mass: float
    com: tuple[float, float, float]
    inertia: float
    std: float | None
    interval95: tuple[float, float] | None
    std_repeatability: float | None
    std_rig: float | None
    period: float
    period_std: float | None
    period_std_source: str
    sensitivity: float
    inertia_per_mass: float
    std_per_mass: float | None
    radius_of_gyration: float | None
    radius_of_gyration_std: float | None
    method: str
    budget: dict | None
    budget_per_mass: dict | None
    tensor_check: TensorCheck
    flags: tuple[str, ...]
    start_value: str
    amplitude: tuple[float, float] | None = None  # a timed period's amplitude, twice (rad)
    timed_period: float | None = None
    trials: tuple[Trial, ...] = ()
    pooled: Pooled | None = None
    air: AirPart | None = None
    tare: Measurement | None = None
    object_part: ObjectMoment | None = None

    def trial_dicts(self) -> list[dict]:
        """Each trial as its JSON object (:func:`trial_dict`)."""
        return [trial_dict(tr, self.mass) for tr in self.trials]

    def as_dict(self) -> dict:
        """The JSON object of ``identify --json``: numbers, lists, strings, None (non-finite numbers kept:
        the writer maps them to null)."""
        out = {"axis": self.axis, "inertia": self.inertia, "std": self.std,
               "interval95": None if self.interval95 is None else list(self.interval95),
               "std_repeatability": self.std_repeatability, "std_rig": self.std_rig, "period": self.period,
               "period_std": self.period_std, "sensitivity": self.sensitivity,
               "inertia_per_mass": self.inertia_per_mass, "std_per_mass": self.std_per_mass,
               "radius_of_gyration": self.radius_of_gyration, "radius_of_gyration_std": self.radius_of_gyration_std,
               "method": self.method, "budget": self.budget, "budget_per_mass": self.budget_per_mass,
               "tensor_check": self.tensor_check.as_dict(), "flags": list(self.flags),
               "period_std_source": self.period_std_source, "start_value": self.start_value}
        trials = self.trial_dicts()
        one = trials[0] if len(trials) == 1 else None
        per_record = {key: one[key] if one else None for key in PER_RECORD}
        if self.pooled is None:
            per_record["amplitude"] = None if self.amplitude is None else list(self.amplitude)
            out.update(per_record, trials=[], between_trial_std=None, chi2_per_dof=None)
            if self.timed_period is not None:
                out["timed_period"] = self.timed_period
        else:
            out.update(trials=trials, **per_record, between_trial_std=self.pooled.between_trial_std,
                       chi2_per_dof=self.pooled.chi2_per_dof)
        out["rig"] = self.rig
        if self.air is not None:
            out.update(inertia_without_air=self.air.inertia, inertia_without_air_std=self.air.std,
                       air_share=self.air.share, tensor_check_without_air=self.air.tensor_check.as_dict())
        if self.tare is not None:
            out["tare"] = self.tare.as_dict()
        if self.object_part is not None:
            out["object"] = self.object_part.as_dict()
        return out


PER_RECORD = ("amplitude", "damping", "law", "halves", "rejected", "residual_rms", "outliers")  # one record's, on top


def start_moment(inertia: np.ndarray, k: int) -> float | None:
    """A start value for an unknown (``nan``) diagonal entry ``k`` of a tensor: the mean of the other
    diagonal entries that are known (positive, and inside the triangle inequality of a diagonal tensor),
    None if none is."""
    known = [inertia[i, i] for i in range(3) if i != k and not math.isnan(inertia[i, i])]
    return sum(known) / len(known) if known else None


def _started(rig: Rig, axis) -> tuple[Rig, bool]:
    """The rig with a ``nan`` moment about ``axis`` replaced by :func:`start_moment` (the tensor's other
    ``nan`` entries read as 0), and whether it was ``nan``; about a vector axis the rig as given (its
    start value is the caller's: :mod:`.hangings` reads a fixture's)."""
    if not isinstance(axis, str) or not math.isnan(rig.inertia[AXIS_INDEX[axis], AXIS_INDEX[axis]]):
        return rig, False
    inertia = np.where(np.isnan(rig.inertia), 0.0, rig.inertia)
    return with_moment(replace(rig, inertia=inertia), axis, start_moment(inertia, AXIS_INDEX[axis])), True


def measure(rig: Rig, axis, *, period: float | None = None, amplitude: float | None = None,
            period_std: float | None = None, signals: Sequence | None = None,
            options: RecordOptions = RecordOptions(), samples: int | None = None,
            propagate: str = "all") -> Measurement:
    """The moment about body axis ``axis`` (``x``, ``y``, ``z``, or a body-frame vector: a fixture's
    vertical at rest) from a ``period`` (s) timed at peak rotation ``amplitude`` (rad; None or 0: small)
    with sigma ``period_std`` (s; None: the rig's ``[uncertainty].period``), or from ``signals`` (record
    files, or records already read: trials of this rig, pooled), with the rig's ``[uncertainty]``
    propagated linearly or, with ``samples``, by that many Monte Carlo draws. ``propagate``
    (:data:`PROPAGATE`): ``"all"``, the period's sigma and the rig file's; ``"period"``, the period's
    alone (:func:`.propagation.period_only`), as the tensor fit propagates it for every hanging: a tare
    measured for the tensor (:mod:`.hangings`) leaves out what its hangings leave out.

    Raises :class:`RigError` for a period no moment gives (field ``period``) and for records that cannot
    be used, :class:`bifilar.identification.records.bounds.WorkSpent` once ``options.max_seconds`` is spent.
    """
    if propagate not in PROPAGATE:
        raise ValueError(f"propagate must be one of {PROPAGATE}, got {propagate!r}")
    if not isinstance(axis, str):  # a vector: hashable, as the propagation keys its axes
        axis = tuple(float(c) for c in axis)
    rig_in_air, was_nan = _started(rig, axis)
    rig = still(rig_in_air)  # the moment identified is the body's own: the air's added mass is in the model
    added = added_moment(rig, axis_vector(axis))  # reported: the apparent moment, the body's + the air's
    flags: list[str] = []
    p = pencil(rig, axis)  # the rig's one rest-pose search: everything below is about this rest pose
    trials: tuple[Trial, ...] = ()
    pooled = None
    if signals is None:
        found = identify(rig, axis, period, amplitude or 0.0, p.lin.rest)
        ratio, small = found.amplitude_ratio, period / found.amplitude_ratio
        small_std = (rig.uncertainty.period if period_std is None else period_std) / ratio
        std_source = ("the period's own sigma" if period_std is not None else
                      "the rig file's [uncertainty].period" if small_std > 0.0 else
                      "none: the rig file states no [uncertainty].period")
        flags.extend(_near_period_flags(p, found.moment, small))
    else:
        found_trials, pooled = identify_records(rig, axis, list(signals), options, p)
        trials, ratio = tuple(found_trials), 1.0
        small, small_std = pooled.period, pooled.period_std
        std_source = "the records' fits"
        flags.extend(record_flags(trials, pooled))
    result = _propagate(rig, axis, small, small_std, samples, flags, p, added, propagate)
    result = replace(result, period_std_source=std_source,
                     start_value="nan in the rig file" if was_nan else "the rig file's value (a start only)",
                     amplitude=(amplitude, amplitude) if amplitude and signals is None else None,
                     timed_period=period if signals is None and ratio != 1.0 else None,
                     trials=trials, pooled=pooled)
    if rig_in_air.air is None:
        return result
    # The body's own moment. The air is no rigid body: the apparent tensor may break the triangle
    # inequality; the body's must not.
    own = with_air(rig, axis_vector(axis), result.inertia - added, result.std or 0.0)
    check = tensor_check(with_moment(rig, axis, own.inertia).inertia)
    flags = result.flags
    if check.body:
        flags = tuple(f for f in flags if not f.startswith(_NO_BODY))
    return replace(result, air=AirPart(own.inertia, own.std, own.air_share, check), flags=flags)


_NO_BODY = "the identified tensor"  # how the flag of a tensor no body has starts


def _near_period_flags(p, moment: float, period: float) -> list[str]:
    """A given period's flag where the rig has modes near the one timed (:func:`.records.pipeline.near_modes`
    at the identified ``moment``): timed over fewer cycles than make :data:`NEAR_BEATS` beats, a sway of
    one moves the period timed, and the crossings do not show it."""
    near = [(t2, f"{NEAR_BEATS / abs(period / t2 - 1.0):.3g} cycles make {NEAR_BEATS:g} beats")
            for t2 in near_modes(p, moment)]
    if not near:
        return []
    return [f"{rig_has(period, near)}: a period timed over fewer cycles may hold a sway of it, which its crossings "
            f"do not show; time that many cycles or more, repeat the trial, or {PART_THE_MODES}"]


def _propagate(rig: Rig, axis, period: float, period_std: float, samples, flags: list, p,
               added: float = 0.0, propagate: str = "all") -> Measurement:
    """The propagated moment and everything derived from it (per mass, checks, flags); ``p`` is the
    rig's pencil about ``axis`` (its rest pose and linearisation); ``added``: the air's added moment
    about ``axis``, added to the body's to report the apparent moment (its floor check is the body's);
    ``propagate``: :func:`measure`'s. The fields :func:`measure` sets after are left at placeholders."""
    found = invert_period(rig, axis, period, p.lin.rest, p)
    geometry = [g for g in ("length", "anchor", "attach", "mass", "com") if getattr(rig.uncertainty, g) > 0.0]
    if propagate == "period":
        geometry = []
        result = period_only(found, period, period_std)
    elif samples and (geometry or period_std > 0.0):
        result = monte_carlo(rig, axis, period, period_std, samples, np.random.default_rng(0))
    else:
        result = linear_axes(rig, {axis: period}, period_std, p.lin.rest, {axis: found}, p.lin)[axis]
    j, m = result.moment + added, found.rig.mass
    inp = result.inputs
    parts = (result.gradient * inp.std) ** 2
    groups = np.array(inp.groups)
    rep_var, rig_var = float(parts[groups == "period"].sum()), float(parts[groups != "period"].sum())
    # J / m: the same inputs; the mass enters as d(J/m)/dm = (dJ/dm)/m - J/m^2
    per_mass_gradient = result.gradient / m
    per_mass_gradient[groups == "mass"] -= j / m**2
    std_pm = float(np.sqrt(np.sum((per_mass_gradient * inp.std) ** 2)))
    propagated = bool(np.any(inp.std > 0.0))
    if not geometry and propagate == "all":
        flags.append("the rig file has no [uncertainty] for geometry or mass: nothing of the rig was propagated"
                     + ("" if period_std > 0.0 else ", nor of the period: no uncertainty is stated"))
    floor = p.floor
    if propagated and result.low <= max(floor, 0.0):
        flags.append(f"the 95 % interval reaches {result.low:.6g} kg m^2, a moment no body has (the tensor is "
                     f"positive definite only above {max(floor, 0.0):.6g}): this rig cannot determine it")
    check = tensor_check(with_moment(rig, axis, j).inertia)
    if not check.body:
        flags.append(f"{_NO_BODY} (principal moments {', '.join(f'{x:.6g}' for x in check.principal)}) "
                     f"{'is not positive definite' if not check.positive_definite else 'breaks the triangle inequality'}"
                     ": no body has it (a wrong period, mode or rig file)")
    if found.sensitivity < WEAK_SENSITIVITY:  # the body's own moment's (in air, less than the apparent's)
        flags.append(f"the period hardly depends on this moment (d ln T / d ln I = {found.sensitivity:.3g}): "
                     "its uncertainty is amplified 1/(2 x that) times")
    per_mass = j / m
    k = math.sqrt(per_mass) if per_mass > 0.0 else None
    return Measurement(
        rig=rig.name, source=rig.source, axis=axis, mass=rig.mass, com=tuple(rig.com.tolist()), inertia=j,
        std=result.std if propagated else None,
        interval95=(result.low + added, result.high + added) if propagated else None,
        std_repeatability=math.sqrt(rep_var) if period_std > 0.0 else None,
        std_rig=math.sqrt(rig_var) if geometry else None,
        period=period, period_std=period_std if period_std > 0.0 else None, period_std_source="",
        sensitivity=found.sensitivity * (j / result.moment if added else 1.0), inertia_per_mass=per_mass,
        std_per_mass=std_pm if propagated else None,
        radius_of_gyration=k, radius_of_gyration_std=std_pm / (2.0 * k) if propagated and k else None,
        method=result.method, budget=result.budget if propagated else None,
        budget_per_mass=budget(inp, per_mass_gradient) if propagated else None,
        tensor_check=check, flags=tuple(flags), start_value="")


def subtract_tare(whole: Measurement, fixture: Measurement) -> Measurement:
    """``whole`` (the assembly: fixture and object) with the fixture alone and the object's own moment
    about the axis through its own COM: (whole - fixture, both about their own COM) by the parallel-axis
    theorem, the two sigmas combined as independent (conservative: the shared geometry errors correlate
    and partly cancel). Both measured about the same body axis, in the same body frame."""
    if whole.mass - fixture.mass <= 0.0:
        raise RigError(fixture.source, "body.mass", f"{fixture.mass:g} kg: not less than the rig's {whole.mass:g} kg, "
                                                    "so no object is left")
    e = axis_vector(whole.axis)
    com, fix_com = np.array(whole.com), np.array(fixture.com)
    m_obj, c_obj = object_part(whole.mass, com, fixture.mass, fix_com)
    about_com = whole.inertia - (fixture.inertia + parallel_axis_moment(fixture.mass, fix_com - com, e))
    own = about_com - parallel_axis_moment(m_obj, c_obj - com, e)
    stds = (whole.std, fixture.std)
    std = math.sqrt(sum(s**2 for s in stds)) if all(s is not None for s in stds) else None
    part = ObjectMoment(m_obj, tuple(c_obj.tolist()), own, std, own / m_obj,
                        () if own > 0 else ("the object's moment is not positive",))
    return replace(whole, tare=fixture, object_part=part)


def record_flags(trials: Sequence[Trial], pooled: Pooled) -> list[str]:
    """The flags of records pooled: each trial's (:func:`said_once`), and the pool's scatter where it is
    more than the trials' stated sigmas allow."""
    flags = said_once([said for tr in trials for said in tr.said])
    if not pooled.consistent:
        flags.append(f"the {len(trials)} trials scatter more than their stated sigmas (chi^2 per degree of "
                     f"freedom {pooled.chi2_per_dof:.3g}): the pooled sigma is scaled by its square root")
    return flags


def said_once(said: Sequence[tuple[str, str]]) -> list[str]:
    """Flags as (who, what) pairs, each ``what`` said once with every ``who`` it applies to, in the order
    first said: ``"a.csv, b.csv: what"`` (a tensor of 30 records with one warning says it once)."""
    whom: dict[str, list[str]] = {}
    for who, what in said:
        names = whom.setdefault(what, [])
        if who not in names:
            names.append(who)
    return [f"{', '.join(names)}: {what}" for what, names in whom.items()]


SIGMA_PARTS = {"noise": "the record's noise", "law": "the law's excess as the record's noise moves it",
               "jackknife": "the jackknife's excess over the covariance", "envelope": "choosing the envelope's degree",
               "near_mode": "a near mode trading with the law",
               "rig_mode": "what the rig's near mode, fitted at its frequency, moves T0"}


def sigma_shares(trial: dict) -> list[tuple[str, float]]:
    """What makes a trial's (:func:`trial_dict`) statistical T0 variance, from ``period_std_parts``: (what
    in words, :data:`SIGMA_PARTS`, its share of the variance), largest first, each 1 % or more."""
    total = trial["period_std_statistical"] ** 2
    shares = sorted(((std**2 / total, name) for name, std in trial["period_std_parts"].items()), reverse=True)
    return [(SIGMA_PARTS[name], share) for share, name in shares if share >= 0.01]


def trial_dict(tr: Trial, mass: float) -> dict:
    """The JSON object of one trial: its fit and the moment from it alone (repeatability sigma)."""
    fit = tr.fit
    halves = None
    if tr.halves is not None:
        h = tr.halves
        halves = {"first": {"period": h.first[0], "period_std": h.first[1]},
                  "second": {"period": h.second[0], "period_std": h.second[1]}, "split": h.split, "z": h.z}
    return {
        "source": tr.record.source,
        "period": fit.period,
        "period_std": fit.period_std,
        "period_std_statistical": fit.period_std_statistical,
        "period_std_law": fit.period_std_law,
        "period_std_white": fit.period_std_white,
        "crb": fit.crb,
        "crb_noise": fit.crb_noise,
        "crb_ratio": fit.period_std_statistical / fit.crb if fit.crb > 0.0 else None,
        "period_std_parts": dict(fit.period_std_parts),
        "inertia": tr.moment,
        "std": tr.moment_std,
        "interval95": [tr.moment - Z95 * tr.moment_std, tr.moment + Z95 * tr.moment_std],
        "inertia_per_mass": tr.moment / mass,
        "std_per_mass": tr.moment_std / mass,
        "amplitude": list(fit.amplitude) if fit.amplitude is not None else None,
        "damping": fit.damping,
        "law": fit.law.as_dict(),
        "halves": halves,
        "rejected": fit.rejected.as_dict(),
        "residual_rms": fit.rms,
        "outliers": fit.outliers.tolist(),
        "second_mode": None if fit.second_mode is None else dict(zip(("period", "amplitude", "decay"), fit.second_mode)),
        "near_modes": [{"period": t2, "beats": beats(tr.record, fit, t2)} for t2 in tr.near],
        "samples": fit.samples,
        "binned": fit.binned,
        "cycles": fit.cycles,
        "dropped": tr.record.dropped,
        "unfolded": tr.record.unfolded,
        "block": fit.block,
        "jackknife": fit.jackknife,
        "flags": list(tr.flags),
    }
