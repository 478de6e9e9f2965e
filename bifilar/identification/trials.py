"""Repeated trials on one rig: each record fitted and inverted, then pooled with a consistency test.

Each record (:mod:`bifilar.identification.records`) is fitted with the rig's own amplitude law
(:func:`law_for`) and its zero-amplitude period inverted into the moment (:func:`fit_trial`). Its
repeatability is the period's standard deviation alone; the rig's geometry and mass are common to
every trial and enter once, after pooling (:mod:`bifilar.identification.propagation`).

Pooling (:func:`pool`): the weighted mean of the periods, chi^2 = sum (T_i - T)^2 / sigma_i^2 over
n - 1 degrees of freedom. A chi^2 per degree of freedom above 1 means the trials scatter more than
their stated sigmas: the pooled sigma is then scaled by sqrt(chi^2 / dof) (the Birge ratio), and
above the 99 % point of the chi^2 law the trials are reported as inconsistent.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.stats import chi2

from bifilar.identification.identify import (AXES, Pencil, amplitude_coefficient, amplitude_ratio, axis_vector,
                                             invert_period, linear_period, pencil)
from bifilar.identification.records import Record
from bifilar.identification.signals import EXCESS_PRIOR, AmplitudeLaw, OscillationFit, fit_record
from bifilar.motion import lagrange
from bifilar.rig import Rig, RigError
from bifilar.rig.statics import Rest

CONSISTENCY = 0.99  # chi^2 quantile above which the trials are called inconsistent
_LAW_RTOL = 1e-3  # a series law this close to the one fitted with does not change the fit
# Below this amplitude (rad) the series law's O(A^4) error, ~s^2 A^4, is under 1e-6: no quintic.
_MATCH_FROM = 0.1


def law_for(rig: Rig, axis, amplitude: float | None = None, rest: Rest | None = None) -> AmplitudeLaw:
    """The exact 1-DOF torsion law for the vertical axis of a symmetric rig, else the Kane model's
    period-amplitude series at the rig's moment (module docstring of :mod:`.signals`), right at
    O(A^2); with the record's largest ``amplitude`` (rad) its quintic is matched to the Kane model's
    T(A) / T0 there (:meth:`AmplitudeLaw.matched`), so that the law holds over the record's range.
    ``rest``: the rig's rest pose if known (it does not depend on the inertia)."""
    if np.allclose(axis_vector(axis), AXES["z"]):
        try:
            return AmplitudeLaw.torsion(lagrange.from_rig(rig))
        except RigError:
            pass  # not a symmetric torsion: the Kane series below
    law = AmplitudeLaw("series", s=amplitude_coefficient(rig, axis, rest))
    if amplitude is not None and amplitude > _MATCH_FROM:
        omega = 2.0 * math.pi / linear_period(rig, axis, rest)
        law = law.matched(amplitude, amplitude_ratio(rig, axis, amplitude, rest), omega)
    return law


@dataclass(frozen=True)
class Trial:
    """One record: its fit, the moment it gives (kg m^2) and that moment's repeatability sigma (from
    the period's sigma alone), the sensitivity d ln T / d ln J."""

    record: Record
    fit: OscillationFit
    moment: float
    moment_std: float
    sensitivity: float


def fit_trial(rig: Rig, axis, record: Record, p: Pencil | None = None, excess_prior: float = EXCESS_PRIOR) -> Trial:
    """Fit ``record`` with the rig's law and invert its period (see the module docstring).

    A series law depends weakly on the moment: it is recomputed at the identified moment and the
    record refitted once if it changed. Raises :class:`RigError` naming the record for a record the
    fit cannot use or a period no moment gives.
    """
    p = pencil(rig, axis) if p is None else p
    law = law_for(rig, axis, rest=p.lin.rest)
    try:
        fit = fit_record(record, law, excess_prior=excess_prior)
        found = invert_period(rig, axis, fit.period, p=p)
        if law.kind == "series":
            better = law_for(found.rig, axis, fit.amplitude[0] if fit.amplitude else None, p.lin.rest)
            if abs(better.s - law.s) > _LAW_RTOL * abs(law.s) or better.quintic != law.quintic:
                fit = fit_record(record, better, excess_prior=excess_prior)
                found = invert_period(rig, axis, fit.period, p=p)
    except RigError as exc:
        if exc.field != "period":
            raise
        raise RigError(record.source, record.column, f"fitted period {exc.problem}") from None
    except ValueError as exc:  # a record the fit cannot use
        raise RigError(record.source, record.column, str(exc)) from None
    std = found.moment * fit.period_std / fit.period / found.sensitivity
    return Trial(record, fit, found.moment, std, found.sensitivity)


@dataclass(frozen=True)
class Pooled:
    """The trials' weighted mean period (s) and its sigma (Birge-scaled), chi^2 per degree of freedom
    (None for one trial), the sample standard deviation of the trials' moments (kg m^2; None for
    one) and whether the scatter is consistent with the stated sigmas."""

    period: float
    period_std: float
    chi2_per_dof: float | None
    between_trial_std: float | None
    consistent: bool


def pool(trials: list[Trial]) -> Pooled:
    """Pool the trials' periods (module docstring)."""
    t = np.array([tr.fit.period for tr in trials])
    s = np.array([tr.fit.period_std for tr in trials])
    w = 1.0 / s**2
    mean = float(np.sum(w * t) / np.sum(w))
    std = float(1.0 / math.sqrt(np.sum(w)))
    if len(trials) == 1:
        return Pooled(mean, std, None, None, True)
    dof = len(trials) - 1
    value = float(np.sum(w * (t - mean) ** 2))
    ratio = value / dof
    moments = np.array([tr.moment for tr in trials])
    return Pooled(mean, std * math.sqrt(max(1.0, ratio)), ratio, float(moments.std(ddof=1)),
                  value <= chi2.ppf(CONSISTENCY, dof))
