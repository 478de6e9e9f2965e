"""From record files to a moment of inertia: read -> fit -> amplitude law -> refit -> invert -> pool.

:func:`identify_records` is the whole loop, in the order it runs:

1. read each file (:func:`.read.read_record`: delimiter, header, units, lost frames, a folded tracker);
2. fit it with the rig's ideal amplitude law (:func:`law_for`; :mod:`.fit` measures each cycle's
   phase and learns the real law's excess from the record's own T(A));
3. check that the swing the record implies is one the rig can make (an angle in degrees read as
   radians, a rate in deg/s read as rad/s, the wrong column: refused in one line naming the likely
   unit, :func:`swing_problem`; the fit checks it on its first cycles, before the law is built); a
   plausible swing whose periods change with it as a swing 180 / pi times smaller would is flagged
   (:mod:`.units`);
4. for a mode that is not a symmetric torsion, the law is the Kane model's series at the identified
   moment with its quintic matched at the record's amplitude: refit once if it moved;
5. invert the zero-amplitude period into the moment (:func:`bifilar.identification.identify.invert_period`),
   and list the rig's other modes within :data:`.near.NEAR_BAND` of the timed one's frequency there
   (:func:`near_modes`): a sway of one of them that beats less than :data:`NEAR_BEATS` times over the
   record is, in one record, taken by the amplitude law (:mod:`.near`), so where the record showed no
   mode near the torsion it is fitted again with a mode at the rig's frequency, how far that moves T0
   enters the sigma (:func:`_with_rig_mode`), and the record is flagged;
6. fit each half of the record alone: their agreement is the record's own test of its sigma (``halves``);
7. pool the trials (:func:`pool`): the records of one rig share its amplitude law, so the part of each
   sigma that is the law's prior is common to all of them (a full covariance, not independent noise).

A trial's repeatability sigma is its period's alone; the rig's geometry and mass are common to every
trial and enter once, after pooling (:mod:`bifilar.identification.propagation`).

Steps 2 and 4-5 are the rig's: a :class:`Target` says which law a record is fitted with and how a period
becomes the quantity identified. A wire rig's is built here (:func:`wire_target`); a hinge rig passes its
own (:func:`bifilar.identification.hinge_measurement.hinge_target`), so that compound and torsion
pendulums share every other step of this loop.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np
from scipy.optimize import brentq
from scipy.stats import chi2

from bifilar.identification.identify import (
    AXES,
    Pencil,
    amplitude_coefficient,
    amplitude_ratio,
    axis_vector,
    invert_period,
    linear_period,
    pencil,
)
from bifilar.motion import lagrange
from bifilar.rig import Rig, RigError

from .bounds import Deadline, LawBandError, WorkSpent
from .fit import OscillationFit, SwingError, fit_oscillation
from .law import EXCESS_PRIOR, AmplitudeLaw
from .near import NEAR_BAND
from .read import Record, read_record
from .units import degrees_read_as_rad

CONSISTENCY = 0.99  # chi^2 quantile above which the trials are called inconsistent
HALVES_Z = 3.0  # halves further apart than this many sigmas: flagged
SUSPECT_TORSION = 0.5 * math.pi  # a torsion beyond this is rare enough to say so (rad)
NEAR_BEATS = 1.5  # a near mode beating fewer times than this over a record may hide in its law (.near;
# identify-record-near-mode: sways of 1.2 beats and more were fitted or flagged, of 0.28 and 0.87 not)
PART_THE_MODES = "part the modes (the wires further apart or closer together)"  # a near mode flag's advice
_DEGREE = math.pi / 180.0
# Below this amplitude (rad) the series law's O(A^4) error, ~s^2 A^4, is under 1e-6: no quintic.
_MATCH_FROM = 0.1


@dataclass(frozen=True)
class RecordOptions:
    """How to read and fit the records (identify's record options; units as :mod:`.read` says).
    ``law_sigma``: the prior std of the real law's excess relative to the ideal coefficient;
    ``amplitude_scale`` (signal units per rad) and ``max_amplitude`` (rad): what is known of a
    proportional record's scale; ``max_seconds``: the fits' wall-time budget, s."""

    column: str | None = None
    kind: str = "angle"
    time_column: str | None = None
    fps: float | None = None
    time_unit: str = "s"
    angle_unit: str = "rad"
    start: float | None = None
    end: float | None = None
    law_sigma: float = EXCESS_PRIOR
    amplitude_scale: float | None = None
    max_amplitude: float | None = None
    max_seconds: float | None = None  # wall-time budget of all the records' fits (None: unbounded)


@dataclass(frozen=True)
class Halves:
    """The record's two halves fitted alone: periods and sigmas (s), the split time (s), and z, their
    difference in its own sigma (the law's common prior taken out)."""

    first: tuple[float, float]
    second: tuple[float, float]
    split: float
    z: float


@dataclass(frozen=True)
class Trial:
    """One record: its fit, its halves (None where a half is too short to fit), the moment it gives
    (kg m^2; a calibration rod's stiffness, N m/rad, where its :class:`Target` identifies that) and its
    repeatability sigma (from the period's sigma alone), the sensitivity d ln T / d ln J, and what it
    flags."""

    record: Record
    fit: OscillationFit
    halves: Halves | None
    moment: float
    moment_std: float
    sensitivity: float
    flags: tuple[str, ...]  # each "<record file name>: <what>"
    near: tuple[float, ...] = ()  # s, the rig's other modes near the timed one (:func:`near_modes`)

    @property
    def said(self) -> list[tuple[str, str]]:
        """The flags as (record file name, what) pairs."""
        name = file_name(self.record)
        return [(name, flag.removeprefix(f"{name}: ")) for flag in self.flags]


@dataclass(frozen=True)
class Pooled:
    """The trials' pooled period (s) and its sigma (Birge-scaled), chi^2 per degree of freedom (None
    for one trial), the sample standard deviation of the trials' moments (kg m^2; None for one), and
    whether the scatter is consistent with the stated sigmas."""

    period: float
    period_std: float
    chi2_per_dof: float | None
    between_trial_std: float | None
    consistent: bool


@dataclass(frozen=True)
class Inverted:
    """A period inverted: the quantity identified (a moment, kg m^2; a rod's stiffness, N m/rad) and
    d ln T / d ln(quantity) (its sign kept); ``near``: the periods (s) of the rig's other modes within
    :data:`.near.NEAR_BAND` of the timed one's frequency there (:func:`near_modes`)."""

    value: float
    sensitivity: float
    near: tuple[float, ...] = ()


@dataclass(frozen=True)
class Target:
    """What a rig does with a record: ``ideal``, the law it is fitted with first; ``law_at(fit)``, the
    law to refit with once a fit is known (``ideal`` where it does not depend on the moment);
    ``invert(period)``, the zero-amplitude period (s) as :class:`Inverted`, raising :class:`RigError` on
    field ``period`` for a period no rig of this kind gives."""

    ideal: AmplitudeLaw
    law_at: Callable[[OscillationFit], AmplitudeLaw]
    invert: Callable[[float], Inverted]


def wire_target(rig: Rig, axis, p: Pencil) -> Target:
    """A wire rig's :class:`Target` about ``axis``: :func:`law_for`, recomputed at the identified moment
    (step 4), and :func:`bifilar.identification.identify.invert_period`; ``p``: its pencil."""
    ideal = law_for(rig, axis, rest=p.lin.rest)

    def invert(period: float) -> Inverted:
        found = invert_period(rig, axis, period, p=p)
        return Inverted(found.moment, found.sensitivity, near_modes(p, found.moment))

    return Target(ideal, lambda fit: _law_at(rig, axis, fit, ideal, p), invert)


def near_modes(p: Pencil, value: float) -> tuple[float, ...]:
    """The periods (s) of the rig's oscillating modes, other than the one timed about the pencil's
    axis, whose frequency is within :data:`.near.NEAR_BAND` of that one's at moment ``value``: a
    bifilar's sway where the body's radius of gyration nears half the wires' spacing, or a roll the
    moment tunes the yaw onto. A real rig couples such a sway into the record even where the model's
    symmetry does not (its share about the axis 0): it beats with the timed mode."""
    k, w2, _ = p.associated(value)
    ratio = np.sqrt(w2 / w2[k])
    return tuple(float(2.0 * math.pi / math.sqrt(w2[j])) for j in range(len(w2))
                 if j != k and abs(ratio[j] - 1.0) <= NEAR_BAND)


def identify_records(rig, axis, paths: list, options: RecordOptions = RecordOptions(),
                     p: Pencil | None = None, target: Target | None = None) -> tuple[list[Trial], Pooled]:
    """The module's loop over ``paths`` (record files, or :class:`.read.Record` objects already read) of
    one rig: the trials and their pool. ``p``: the rig's pencil about ``axis`` (its rest pose), if
    known; ``target``: the rig's :class:`Target` (None: a wire rig's, :func:`wire_target`). Raises
    :class:`RigError` naming the file and column of a record that cannot be used,
    :class:`.bounds.WorkSpent` naming the file once ``options.max_seconds`` is spent."""
    if target is None:
        target = wire_target(rig, axis, pencil(rig, axis) if p is None else p)
    deadline = Deadline(options.max_seconds)
    trials = []
    for path in paths:
        record = path if isinstance(path, Record) else read_record(
            path, options.column, options.kind, time_column=options.time_column, fps=options.fps,
            time_unit=options.time_unit, angle_unit=options.angle_unit, start=options.start, end=options.end)
        try:
            trials.append(_trial(record, target, options, deadline))
        except WorkSpent as exc:
            raise WorkSpent(f"{record.source}: {record.column}: {exc}") from None
    return trials, pool(trials)


def _trial(record: Record, target: Target, options: RecordOptions, deadline: Deadline) -> Trial:
    """Steps 2-6 of the module docstring for one record."""
    fit = _fit(record, target.ideal, options, deadline)
    law = target.law_at(fit)
    if not law.same_as(target.ideal):
        fit = _fit(record, law, options, deadline)
    found = _invert(target, fit, record)
    slow = _slow_near(record, fit, found.near)
    if slow:  # the rig's mode the record cannot show by its beat: what fitting it at its frequency moves T0
        try:
            held = _fit(record, law, options, deadline, slow)
        except RigError:  # the record fitted without the mode: it keeps the flag that its sigma may not hold it
            held = None
        if held is not None and held.near_held:
            fit = _with_rig_mode(fit, held)
            found = _invert(target, fit, record)
    split = halves(record, law, options, deadline)
    std = abs(found.value * fit.period_std / fit.period / found.sensitivity)
    flags = _flags(record, fit, split, options) + _near_flags(record, fit, found.near)
    return Trial(record, fit, split, found.value, std, found.sensitivity, tuple(flags), found.near)


def _with_rig_mode(fit: OscillationFit, held: OscillationFit) -> OscillationFit:
    """``fit`` with what fitting the rig's near mode at its frequency (``held``, :func:`.near.near_held`)
    moves T0 in its sigma: under the beats a record cannot show, the mode's size is not told from the
    law's (module docstring of :mod:`.near`), so the fit with it is no better an estimate (its sigma
    ~2-10x wider, its T0 moved by a phantom where the record holds no sway), but how far it moves T0 is
    how far a sway of the rig's may have moved the fit without it."""
    shift = held.period - fit.period
    parts = {**fit.period_std_parts, "rig_mode": abs(shift)}
    return replace(fit, period_std=math.hypot(fit.period_std, shift),
                   period_std_statistical=math.hypot(fit.period_std_statistical, shift), period_std_parts=parts,
                   rig_mode_shift=shift)


def _fit(record: Record, law: AmplitudeLaw, options: RecordOptions, deadline: Deadline | None = None,
         near: tuple[float, ...] = ()) -> OscillationFit:
    try:
        return fit_oscillation(record.t, record.y, record.kind, law, excess_prior=options.law_sigma,
                               scale=options.amplitude_scale, max_amplitude=options.max_amplitude,
                               near_periods=near, deadline=deadline)
    except SwingError as exc:
        raise RigError(record.source, record.column, swing_problem(record, exc.swing, law, options)) from None
    except LawBandError as exc:
        raise RigError(record.source, record.column, band_problem(record, exc, options)) from None
    except ValueError as exc:  # a record the fit cannot use
        raise RigError(record.source, record.column, str(exc)) from None


def law_for(rig: Rig, axis, amplitude: float | None = None, rest=None) -> AmplitudeLaw:
    """The rig's own law about ``axis``: the exact 1-DOF torsion for the vertical axis of a symmetric
    rig, else the Kane model's period-amplitude series at the rig's moment, right at O(A^2); with the
    record's largest ``amplitude`` (rad) its quintic is matched to the Kane model's T(A) / T0 there
    (:meth:`AmplitudeLaw.matched`). ``rest``: the rig's rest pose if known (it does not depend on the
    inertia)."""
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


def _law_at(rig: Rig, axis, fit: OscillationFit, ideal: AmplitudeLaw, p: Pencil) -> AmplitudeLaw:
    """Step 4: a series law recomputed at the identified moment and matched at the record's largest
    amplitude; the exact torsion law needs neither."""
    if ideal.kind != "series":
        return ideal
    found = invert_period(rig, axis, fit.period, p=p)
    return law_for(found.rig, axis, fit.amplitude[0] if fit.amplitude else None, p.lin.rest)


def _invert(target: Target, fit: OscillationFit, record: Record) -> Inverted:
    try:
        return target.invert(fit.period)
    except RigError as exc:
        if exc.field != "period":
            raise
        raise RigError(record.source, record.column, f"fitted period {exc.problem}") from None


def swing_problem(record: Record, swing: float, law: AmplitudeLaw, options: RecordOptions) -> str:
    """Step 3: what is wrong with a record whose swing (rad) is past what the rig can do, naming the
    unit that would make it possible (a factor pi / 180 away) or the column and kind."""
    what = "the rate" if record.kind == "rate" else "the angle"
    past = ("the body would go over the top" if law.kind == "exact" and law.rho == 0.0 else  # a compound pendulum
            "the wires would turn horizontal or cross" if law.kind == "exact" else "the body would rise to the hooks")
    text = (f"{what} implies a swing of {swing:.4g} rad ({swing / _DEGREE:.4g} deg), past the rig's "
            f"{law.limit:.4g} rad where {past}")
    if options.angle_unit == "rad" and swing * _DEGREE <= law.limit:
        unit = "deg/s" if record.kind == "rate" else "degrees"
        return text + f": are the values in {unit} (--angle-unit deg)?"
    return text + f": check --column and --kind (this is column {record.column!r} read as {record.kind})"


def band_problem(record: Record, exc: LawBandError, options: RecordOptions) -> str:
    """What is wrong with a record whose fitted law leaves its own frequency band (:mod:`.bounds`):
    an angle past pi / 2 read in rad is likely in degrees; otherwise the time unit is the likely mistake
    (seconds read as ms put lam omega^2 a million times a real rig's), or the column."""
    swing = float(np.max(np.abs(record.y - np.median(record.y)))) if record.kind == "angle" else 0.0
    if options.angle_unit == "rad" and swing > SUSPECT_TORSION:
        return f"{exc}; the angle reaches {swing:.3g} rad: are the values in degrees (--angle-unit deg)?"
    other = "s" if options.time_unit == "ms" else "ms"
    return (f"{exc}; no rig's law does that: is the time column in {other} (--time-unit {other}), or the "
            f"column {record.column!r} not the {record.kind}?")


def halves(record: Record, law: AmplitudeLaw, options: RecordOptions,
           deadline: Deadline | None = None) -> Halves | None:
    """Step 6: the record cut at the middle of its time span, each half fitted alone; None if a half
    cannot be fitted (too few cycles)."""
    t = record.t
    split = 0.5 * (t[0] + t[-1])
    fits = []
    for part in (t < split, t >= split):
        try:
            fits.append(fit_oscillation(t[part], record.y[part], record.kind, law, excess_prior=options.law_sigma,
                                        scale=options.amplitude_scale, max_amplitude=options.max_amplitude,
                                        deadline=deadline))
        except ValueError:
            return None
    a, b = fits
    common = a.prior_gain - b.prior_gain  # the law's prior moves both: only its difference separates them
    var = float(np.sum(_own_variances(fits))) + float(common @ common)
    return Halves((a.period, a.period_std), (b.period, b.period_std), float(split),
                  float((a.period - b.period) / math.sqrt(var)))


def _independent(fit: OscillationFit) -> float:
    """The variance of T0 that is this record's own: all but the law's prior part."""
    return max(fit.period_std**2 - float(fit.prior_gain @ fit.prior_gain), fit.period_std_statistical**2)


def _own_variances(fits: list[OscillationFit]) -> np.ndarray:
    """Each fit's own variance of T0 (:func:`_independent`), of fits of one rig (a record's halves in
    :func:`halves`, repeated trials in :func:`pool`), which share its amplitude law. Where the excesses
    they learned disagree (their chi^2 about the weighted mean past the :data:`CONSISTENCY` quantile),
    what each learned is not that one law: a mode near the torsion's frequency, less than a beat over a
    record, is to first order a law moving the frequency with ln A, and each record's sway (its phase
    and size new each time) asks for its own (:mod:`.near`). Their spread beyond their sigmas is then
    measured (the between-fits variance tau^2 of the excess that brings their chi^2 to its degrees of
    freedom, Paule and Mandel's) and each fit's T0 carries it through its own response to the excess
    (``law.ideal_gap`` over ``law.excess``: T0 under the ideal law less T0 learned, per unit of excess),
    as :meth:`.phase_law.Model.check_law` holds a law no rig has (and then already has)."""
    own = np.array([_independent(f) for f in fits])
    learned = [i for i, f in enumerate(fits) if f.law.excess_std > 0.0]
    if len(learned) < 2:
        return own
    ds = np.array([fits[i].law.excess for i in learned])
    var = np.array([fits[i].law.excess_std for i in learned]) ** 2
    if _dispersion(ds, var, 0.0) <= chi2.ppf(CONSISTENCY, len(learned) - 1) - (len(learned) - 1):
        return own
    # the excess's variance between fits: the dispersion falls as it grows, to zero past the plain variance
    top = float(np.sum((ds - ds.mean()) ** 2)) / (len(learned) - 1)
    tau2 = brentq(lambda t2: _dispersion(ds, var, t2), 0.0, top) if _dispersion(ds, var, top) < 0.0 else top
    # T0 per unit of excess, where the excess stands out of its sigma (else the ratio of two roundings):
    # the others take the median of those (the fits of one rig swing alike)
    slopes = {i: abs(fits[i].law.ideal_gap / fits[i].law.excess) for i in learned
              if abs(fits[i].law.excess) > fits[i].law.excess_std}
    typical = float(np.median(list(slopes.values()))) if slopes else 0.0
    for i in learned:
        f = fits[i]
        if f.law.conflict is None and not f.law.beat:
            own[i] += slopes.get(i, typical) ** 2 * tau2
    return own


def _dispersion(x: np.ndarray, var: np.ndarray, tau2: float) -> float:
    """chi^2 of ``x`` (variances ``var``, plus ``tau2`` each) about their weighted mean, less its degrees
    of freedom."""
    w = 1.0 / (var + tau2)
    mean = float(np.sum(w * x) / np.sum(w))
    return float(np.sum(w * (x - mean) ** 2)) - (len(x) - 1)


def file_name(record: Record) -> str:
    """The record's file name without its folder: what its flags begin with."""
    return record.source.rsplit("/", 1)[-1]


def _flags(record: Record, fit: OscillationFit, halves: Halves | None, options: RecordOptions) -> list[str]:
    name = file_name(record)
    flags = []
    if fit.amplitude is not None and record.kind != "proportional" and fit.amplitude[0] > SUSPECT_TORSION:
        flags.append(f"{name}: a swing of {fit.amplitude[0]:.3g} rad is more than pi/2: check the angle unit")
    if options.angle_unit == "rad" and record.kind != "proportional":
        unit = degrees_read_as_rad(fit, record.kind, options.law_sigma)
        if unit:
            flags.append(f"{name}: {unit}")
    if fit.law.note:
        flags.append(f"{name}: {fit.law.note}; give --max-amplitude (rad) or --amplitude-scale (units per rad) "
                     "to correct it")
    if halves is not None and abs(halves.z) > HALVES_Z:
        flags.append(f"{name}: its halves disagree by {halves.z:+.2g} sigma (T0 {halves.first[0]:.7g} against "
                     f"{halves.second[0]:.7g} s): its sigma may not hold")
    if fit.law.beat:
        flags.append(f"{name}: its swing does not decay as one mode's does (it grows again, or bends as no damping "
                     "law bends it): a mode near the torsion's frequency beating in, which the amplitude law learns as "
                     "its own; T0's sigma holds T0 under the ideal law too")
    if fit.law.conflict is not None:
        flags.append(f"{name}: its periods ask for an amplitude law {fit.law.conflict:.2g} prior sigmas (each "
                     f"+-{options.law_sigma:.0%} of the ideal) off the ideal rig's, more than a real rig's: T0's "
                     "sigma holds both the T0 learned and the ideal law's (a mode near the torsion's frequency "
                     "beating in? check the angle unit, the column and the rig file)")
    if fit.period_std > 0.01 * fit.period:
        flags.append(f"{name}: T0 is known to {100.0 * fit.period_std / fit.period:.2g} % only")
    return flags


def beats(record: Record, fit: OscillationFit, period: float) -> float:
    """How many times a mode of ``period`` (s) beats with the one fitted over the record's span."""
    return float(record.t[-1] - record.t[0]) * abs(1.0 / period - 1.0 / fit.period)


def _slow_near(record: Record, fit: OscillationFit, near: tuple[float, ...]) -> tuple[float, ...]:
    """The rig's modes near the one timed (s, :func:`near_modes`) that beat fewer than :data:`NEAR_BEATS`
    times over the record, where the fit kept no mode near the torsion's frequency (a mode the record
    showed: its trade with the law is in the sigma, :func:`.near.near_doubt`)."""
    second = fit.second_mode
    if second is not None and abs(fit.period / second[0] - 1.0) <= NEAR_BAND:
        return ()
    return tuple(t2 for t2 in near if beats(record, fit, t2) < NEAR_BEATS)


def _near_flags(record: Record, fit: OscillationFit, near: tuple[float, ...]) -> list[str]:
    """A flag naming the rig's modes near the one timed (:func:`near_modes`) that beat fewer than
    :data:`NEAR_BEATS` times over the record (:func:`_slow_near`): where a refit with one of them at its
    frequency moved T0 (:func:`_with_rig_mode`) the flag quotes the move and the sigma that holds it;
    where no such refit could be made, T0's sigma may not hold the sway."""
    slow = _slow_near(record, fit, near)
    if not slow:
        return []
    modes = rig_has(fit.period, [(t2, f"{beats(record, fit, t2):.2g} beats over the record") for t2 in slow])
    if fit.rig_mode_shift:
        return [f"{file_name(record)}: {modes}: too few beats to tell its size from the amplitude law's; fitted at "
                f"the rig's frequency it moves T0 by {fit.rig_mode_shift:+.2g} s, which is in the sigma "
                f"({100.0 * fit.period_std / fit.period:.2g} % of T0); time longer records or {PART_THE_MODES}"]
    return [f"{file_name(record)}: {modes}: a sway beating less than about once over a record is taken by the "
            "amplitude law, and T0's sigma may not hold it; pool repeated trials (their laws' spread enters the "
            f"sigma), time longer records, or {PART_THE_MODES}"]


def rig_has(period: float, near: list[tuple[float, str]]) -> str:
    """'the rig has a mode at T2 s (x % off the timed one's frequency, <what>)', for each (T2, what) of
    ``near`` (s; the rig's modes near the one timed, of ``period`` s): the start of a near mode's flag."""
    modes = " and ".join(f"{t2:.4g} s ({100.0 * abs(period / t2 - 1.0):.2g} % off the timed one's frequency, {what})"
                         for t2, what in near)
    return f"the rig has {'a mode' if len(near) == 1 else 'modes'} at {modes}"


def pool(trials: list[Trial]) -> Pooled:
    """The generalised least-squares mean of the trials' periods under their full covariance: each
    record's own variance on the diagonal (:func:`_own_variances`), and the law's prior part shared by all
    (C_ij = g_i . g_j, :attr:`OscillationFit.prior_gain`); chi^2 = r^T C^-1 r over n - 1 degrees of
    freedom. Above 1 per degree of freedom the pooled sigma is scaled by its square root (Birge); above
    the :data:`CONSISTENCY` quantile the trials are called inconsistent."""
    t = np.array([tr.fit.period for tr in trials])
    gains = [tr.fit.prior_gain for tr in trials]
    width = max(len(g) for g in gains)
    g = np.array([np.pad(x, (0, width - len(x))) for x in gains]) if width else np.zeros((len(trials), 0))
    cov = np.diag(_own_variances([tr.fit for tr in trials])) + g @ g.T
    ones = np.ones(len(t))
    inv = np.linalg.pinv(cov)
    var = 1.0 / float(ones @ inv @ ones)
    mean = var * float(ones @ inv @ t)
    if len(trials) == 1:
        return Pooled(mean, math.sqrt(var), None, None, True)
    dof = len(trials) - 1
    r = t - mean
    value = float(r @ inv @ r)
    ratio = value / dof
    moments = np.array([tr.moment for tr in trials])
    return Pooled(mean, math.sqrt(var * max(1.0, ratio)), ratio, float(moments.std(ddof=1)),
                  value <= chi2.ppf(CONSISTENCY, dof))
