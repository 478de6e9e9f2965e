"""A hinge rig's moment, or a calibration rod's stiffness, as ``validate identify`` and ``validate
calibrate`` report it, from a timed period or from records.

:func:`measure_hinge` is :func:`bifilar.identification.measurement.measure` for a compound or torsion
pendulum (:class:`bifilar.rig.hinge.HingeRig`) and returns the same :class:`Measurement`, so that the
text, the JSON and the page of ``identify`` are the wire rig's: the moment about the body axis through
the COM parallel to the hinge axis (``axis`` must name that axis), with the sigma of
:func:`bifilar.identification.hinge.moment_from_period`. :func:`calibrate_rod` gives a torsion rod's
stiffness from a body of known moment (:func:`bifilar.identification.hinge.stiffness_from_period`).

A timed period is taken to zero amplitude by the exact law (the elliptic integral for a pivot; a rod is
isochronous); its sigma is the file's ``[uncertainty].period``. Records go through the wire rig's loop,
:func:`bifilar.identification.records.pipeline.identify_records`, with this rig's :class:`Target`
(:func:`hinge_target`: the law of :func:`bifilar.identification.hinge.law_for_hinge`, the period inverted
by the functions above): read, fitted cycle by cycle, halves, pooled. The pooled zero-amplitude period's
sigma then stands for the period's in the propagation, and the rig's sigmas (mass, COM, pivot point,
stiffness) enter once, common to every trial.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from bifilar.rig import RigError
from bifilar.rig.hinge import HingeRig

from .hinge import law_for_hinge, moment_from_period, propagate, stiffness_from_period
from .measurement import AXIS_INDEX, WEAK_SENSITIVITY, Z95, Measurement, record_flags, tensor_check, trial_dict
from .records.pipeline import Inverted, Pooled, RecordOptions, Target, Trial, identify_records

__all__ = ["Calibration", "calibrate_rod", "hinge_axis", "hinge_target", "measure_hinge"]

_AXIS_TOL = 1e-12  # the hinge axis's other components below this: it is a body axis


def hinge_axis(rig: HingeRig, axis: str) -> int:
    """The index (0, 1, 2) of body axis ``axis`` (``x``, ``y``, ``z``), refused in one line
    (:class:`RigError` on ``pivot.axis`` or ``torsion.axis``) unless the hinge axis is along it: the
    moment a hinge rig measures is about the COM axis parallel to the hinge, and nothing else."""
    field = f"{rig.kind}.axis"
    main = int(np.argmax(np.abs(rig.axis)))
    if np.any(np.abs(np.delete(rig.axis, main)) > _AXIS_TOL):
        raise RigError(rig.source, field, f"{np.round(rig.axis, 6).tolist()} is not along a body axis: identify "
                       "reports a moment about body x, y or z; give the body frame an axis along the hinge")
    if main != AXIS_INDEX[axis]:
        name = "xyz"[main]
        raise RigError(rig.source, field, f"is along body {name}, not {axis}: the rig measures the moment about the "
                       f"COM axis parallel to it (--axis {name})")
    return main


def hinge_target(rig: HingeRig, quantity: str = "moment") -> Target:
    """The record loop's :class:`Target` of a hinge rig: fitted with :func:`law_for_hinge` (it does not
    depend on the moment, so no refit), a period inverted into the moment about the axis (``quantity``
    ``moment``) or, for a calibration rod, into the rod's stiffness (``stiffness``; d ln T / d ln k is
    -1/2)."""
    law = law_for_hinge(rig)
    if quantity == "stiffness":
        def invert(period: float) -> Inverted:
            return Inverted(stiffness_from_period(rig, period).stiffness, -0.5)
    else:
        def invert(period: float) -> Inverted:
            found = moment_from_period(rig, period)
            return Inverted(found.moment, found.sensitivity)
    return Target(law, lambda _fit: law, invert)


def _with_period_sigma(rig: HingeRig, sigma: float) -> HingeRig:
    """The rig with ``sigma`` (s) as its zero-amplitude period's standard deviation."""
    return replace(rig, uncertainty=replace(rig.uncertainty, period=sigma))


def _found(rig: HingeRig, invert, quantity: str, period, amplitude, signals, options):
    """``invert(rig, period, amplitude)`` of a timed period or of the records' pooled one: (the result,
    the rig with the period sigma used, where that sigma came from, trials, pool, flags)."""
    if signals is None:
        source = ("the rig file's [uncertainty].period" if rig.uncertainty.period > 0.0
                  else "none: the rig file states no [uncertainty].period")
        return invert(rig, period, amplitude or 0.0), rig, source, (), None, []
    if quantity == "stiffness":
        invert(rig, 1.0, 0.0)  # a pivot or an unknown moment refused before any record is read
    trials, pooled = identify_records(rig, None, list(signals), options, target=hinge_target(rig, quantity))
    used = _with_period_sigma(rig, pooled.period_std)
    flags = record_flags(trials, pooled)
    return invert(used, pooled.period, 0.0), used, "the records' fits", tuple(trials), pooled, flags


def measure_hinge(rig: HingeRig, axis: str, *, period: float | None = None, amplitude: float | None = None,
                  signals: Sequence | None = None, options: RecordOptions = RecordOptions()) -> Measurement:
    """The moment about body axis ``axis`` (the hinge's, :func:`hinge_axis`) from a ``period`` (s) timed at
    peak rotation ``amplitude`` (rad; None: small) or from ``signals`` (record files or records read,
    trials of this rig, pooled), propagated linearly (module docstring). Raises :class:`RigError` for a
    period no body gives (field ``period``) and for records that cannot be used."""
    k = hinge_axis(rig, axis)
    found, propagated_rig, std_source, trials, pooled, flags = _found(rig, moment_from_period, "moment", period,
                                                                      amplitude, signals, options)
    ratio = found.period / found.period0
    period_std = propagated_rig.uncertainty.period / ratio
    j, m = found.moment, rig.mass
    relevant = [g for g, v in found.gradient.items() if np.any(np.asarray(v) != 0.0)]
    rig_sigmas = [g for g in relevant if g != "period" and getattr(rig.uncertainty, g) > 0.0]
    propagated = bool(rig_sigmas) or period_std > 0.0
    if not rig_sigmas:
        flags.append("the rig file has no [uncertainty] for " + ("the stiffness" if rig.kind == "torsion" else
                     "mass, com or pivot point") + ": nothing of the rig was propagated"
                     + ("" if period_std > 0.0 else ", nor of the period: no uncertainty is stated"))
    if found.sensitivity < WEAK_SENSITIVITY:
        flags.append(f"the period hardly depends on this moment (d ln T / d ln I = {found.sensitivity:.3g}: the "
                     "pivot is far from the COM for this body): its uncertainty is amplified 1/(2 x that) times")
    rep = math.sqrt(found.budget["period"]) * found.std
    # I / m: the same inputs, the mass entering as d(I/m)/dm = (dI/dm) / m - I / m^2
    per_mass = {g: np.asarray(v) / m for g, v in found.gradient.items()}
    per_mass["mass"] = per_mass["mass"] - j / m**2
    std_pm, budget_pm = propagate(propagated_rig, per_mass)
    inertia = np.array(rig.inertia, dtype=float)
    inertia[k, k] = j
    check = tensor_check(np.where(np.isnan(inertia), 0.0, inertia))
    if not check.body:
        flags.append(f"the identified tensor (principal moments {', '.join(f'{x:.6g}' for x in check.principal)}) "
                     f"{'is not positive definite' if not check.positive_definite else 'breaks the triangle inequality'}"
                     ": no body has it (a wrong period, pivot point or rig file)")
    gyration = math.sqrt(j / m)
    keep = relevant + (["mass"] if "mass" not in relevant else [])
    return Measurement(
        rig=rig.name, source=rig.source, axis=axis, mass=m, com=tuple(rig.com.tolist()), inertia=j,
        std=found.std if propagated else None,
        interval95=(j - Z95 * found.std, j + Z95 * found.std) if propagated else None,
        std_repeatability=rep if period_std > 0.0 else None,
        std_rig=math.sqrt(max(found.std**2 - rep**2, 0.0)) if rig_sigmas else None,
        period=found.period0, period_std=period_std if period_std > 0.0 else None, period_std_source=std_source,
        sensitivity=found.sensitivity, inertia_per_mass=j / m, std_per_mass=std_pm if propagated else None,
        radius_of_gyration=gyration, radius_of_gyration_std=std_pm / (2.0 * gyration) if propagated else None,
        method="linear", budget={g: found.budget[g] for g in relevant} if propagated else None,
        budget_per_mass={g: budget_pm[g] for g in keep} if propagated else None, tensor_check=check,
        flags=tuple(flags), start_value="the hinge's exact law (no start value needed)",
        amplitude=(amplitude, amplitude) if amplitude and signals is None else None,
        timed_period=period if signals is None and ratio != 1.0 else None, trials=trials, pooled=pooled)


@dataclass(frozen=True)
class Calibration:
    """A torsion rod's stiffness (N m/rad) from a body of known moment ``moment`` (kg m^2): the value,
    its sigma and 95 % interval, the zero-amplitude period (s) and its sigma, the variance budget (group
    -> share), the records' trials and pool (empty, None for a timed period) and the flags."""

    rig: str
    source: str
    stiffness: float
    std: float
    moment: float
    period: float
    period_std: float
    period_std_source: str
    budget: dict
    flags: tuple[str, ...]
    amplitude: float | None = None
    timed_period: float | None = None
    trials: tuple[Trial, ...] = ()
    pooled: Pooled | None = None

    @property
    def interval95(self) -> tuple[float, float]:
        return (self.stiffness - Z95 * self.std, self.stiffness + Z95 * self.std)

    def trial_dicts(self) -> list[dict]:
        """Each trial's JSON object: :func:`bifilar.identification.measurement.trial_dict` with the
        stiffness (N m/rad) where a moment's trial has its inertia."""
        out = []
        for tr in self.trials:
            d = trial_dict(tr, 1.0)
            for key in ("inertia_per_mass", "std_per_mass"):
                del d[key]
            d["stiffness"] = d.pop("inertia")
            out.append(d)
        return out

    def as_dict(self) -> dict:
        """The JSON object of ``calibrate --json``."""
        pooled = self.pooled
        return {"rig": self.rig, "stiffness": self.stiffness, "stiffness_std": self.std,
                "interval95": list(self.interval95), "moment": self.moment, "period": self.period,
                "period_std": self.period_std or None, "period_std_source": self.period_std_source,
                "amplitude": self.amplitude, "timed_period": self.timed_period, "budget": self.budget,
                "trials": self.trial_dicts(),
                "between_trial_std": None if pooled is None else pooled.between_trial_std,
                "chi2_per_dof": None if pooled is None else pooled.chi2_per_dof, "flags": list(self.flags)}


def calibrate_rod(rig: HingeRig, *, period: float | None = None, amplitude: float | None = None,
                  signals: Sequence | None = None, options: RecordOptions = RecordOptions()) -> Calibration:
    """The stiffness of ``rig``'s torsion rod from the period of its body of known moment (the file's
    tensor or cylinder), timed (``period`` s at ``amplitude`` rad) or from ``signals`` (pooled trials),
    with its sigma from the period's, the mass's and a cylinder's radius and length. A stiffness in the file
    is not used (it is what is measured): a flag compares it with the one found. Raises :class:`RigError` for a pivot rig or a body
    whose moment about the rod is unknown."""
    found, used, source, trials, pooled, flags = _found(rig, stiffness_from_period, "stiffness", period, amplitude,
                                                        signals, options)
    if rig.stiffness is not None:
        off = f"{100.0 * (rig.stiffness / found.stiffness - 1.0):+.3g} %" + (
            f", {(rig.stiffness - found.stiffness) / found.std:+.2g} sigma" if found.std > 0.0 else "")
        flags.append(f"the rig file's torsion.stiffness {rig.stiffness:.6g} N m/rad is not used (it is what is "
                     f"calibrated); it is {off} off the one found")
    if found.std == 0.0:
        flags.append("no uncertainty is stated (no [uncertainty].mass, .radius, .length or .period): the stiffness has "
                     "no sigma")
    ratio = found.period / found.period0
    budget = {g: found.budget[g] for g in (("mass", "radius", "length", "period") if rig.cylinder else ("mass", "period"))}
    return Calibration(rig.name, rig.source, found.stiffness, found.std, found.moment, found.period0,
                       used.uncertainty.period / ratio, source, budget, tuple(flags),
                       amplitude=amplitude if amplitude and signals is None else None,
                       timed_period=period if signals is None and ratio != 1.0 else None, trials=trials, pooled=pooled)
