"""Uncertainty of a moment identified from a period: the rig file's ``[uncertainty]`` propagated.

The inputs are the measured quantities of the rig and the period, independent and normal with the
standard deviations of :class:`bifilar.rig.Uncertainty`, one per group:

* ``length``: each wire's length (m);
* ``anchor``: each world coordinate of each ceiling anchor (m), i.e. isotropic per coordinate;
* ``attach``: each body coordinate of each attachment (m);
* ``mass`` (kg); ``com``: each body coordinate of the centre of mass (m);
* ``period`` (s): the measured period.

The other entries of the inertia tensor and gravity are taken as exact.

Linear (:func:`linear`): the Jacobian of the exact inversion (:func:`bifilar.identification.identify.invert_period`)
by the implicit function theorem. The identified J solves ln T_k(J, x) = ln T_measured, so
dJ/dx_i = -(d ln T/dx_i) / (d ln T/dJ): d ln T/dJ = s / J with s the inversion's sensitivity
(Hellmann-Feynman, exact), and d ln T/dx_i, the change of the associated mode's period at fixed J, by
forward differences with steps of 1e-3 sigma per input (small against the scale on which the period
curves, large against its ~1e-13 rounding); the period's own entry is dJ/dT = J / (s T). Each
perturbed rig's rest pose is continued from the base pose and its mode's omega^2 taken as a Rayleigh
quotient, shared by every axis and compiled (:mod:`bifilar.identification.slopes_kernel`); where the
base equilibrium is singular, each perturbed rig is solved afresh (:func:`_slopes_resolved`). var J = sum_i (dJ/dx_i sigma_i)^2, the 95 % interval J +- 1.96 sigma,
and the budget gives each group's share of the variance. :func:`period_only` is that entry alone, the rig's
inputs left out (the tensor fit's choice for every hanging, and so for its tares).

Monte Carlo (:func:`monte_carlo`): the inputs drawn around their measured values and each draw
inverted; the standard deviation and the 2.5 / 97.5 % quantiles of the draws, and a budget from the
least-squares regression of the draws on the standardised inputs (the linear part of the spread).

:func:`coverage` checks the intervals: synthetic experiments on a known rig, each with a measured
rig and period drawn from the stated uncertainties, and the fraction whose interval holds the truth.
"""

from __future__ import annotations

from dataclasses import dataclass, fields, replace
from functools import lru_cache

import numpy as np
from scipy.stats import norm

from bifilar.rig.air import added_mass
from bifilar.identification.identify import Identified, invert_period, linear_period, moment, pencil, with_moment
from bifilar.identification.slopes_kernel import period_slopes
from bifilar.motion.modes import Modes, linearize
from bifilar.rig import Rig, Uncertainty, Wire
from bifilar.rig.statics import Rest, rest_pose, rig_scale

GROUPS = tuple(f.name for f in fields(Uncertainty))
LEVEL = 0.95
_Z = float(norm.ppf(0.5 + LEVEL / 2.0))  # 1.96: half-width of the 95 % interval in sigmas
_STEP = 1e-3  # forward-difference step, in standard deviations of each input


@dataclass(frozen=True)
class Inputs:
    """The measured inputs as one vector: name, group, value and standard deviation of each."""

    names: tuple[str, ...]
    groups: tuple[str, ...]
    values: np.ndarray
    std: np.ndarray


def inputs(rig: Rig, period: float, period_std: float) -> Inputs:
    """The rig's measured quantities and the period, with the rig file's standard deviations."""
    unc = rig.uncertainty
    names, groups = _layout(len(rig.wires))
    per_group = {"length": unc.length, "anchor": unc.anchor, "attach": unc.attach, "mass": unc.mass,
                 "com": unc.com, "period": period_std}
    wires = [np.concatenate([[w.length], w.anchor, w.attach]) for w in rig.wires]
    values = np.concatenate(wires + [[rig.mass], rig.com, [period]]).astype(float)
    std = np.array([per_group[g] for g in groups], dtype=float)
    return Inputs(names, groups, values, std)


@lru_cache(maxsize=None)
def _layout(n_wires: int) -> tuple[tuple[str, ...], tuple[str, ...]]:
    """Names and groups of the inputs of a rig with ``n_wires`` wires, in the order of :func:`inputs`."""
    names, groups = [], []
    for i in range(1, n_wires + 1):
        names += [f"wire[{i}].length"] + [f"wire[{i}].anchor[{k}]" for k in range(3)]
        names += [f"wire[{i}].attach[{k}]" for k in range(3)]
        groups += ["length"] + ["anchor"] * 3 + ["attach"] * 3
    names += ["body.mass"] + [f"body.com[{k}]" for k in range(3)] + ["period"]
    groups += ["mass"] + ["com"] * 3 + ["period"]
    return tuple(names), tuple(groups)


def apply(rig: Rig, x: np.ndarray) -> tuple[Rig, float]:
    """The rig and period with the input vector ``x`` (in the order of :func:`inputs`)."""
    wires, j = [], 0
    for w in rig.wires:  # an elastic wire keeps its axial stiffness: the stretch is in the propagation
        wires.append(Wire(anchor=x[j + 1 : j + 4].copy(), attach=x[j + 4 : j + 7].copy(), length=float(x[j]),
                          axial_stiffness=w.axial_stiffness))
        j += 7
    changed = replace(rig, wires=tuple(wires), mass=float(x[j]), com=x[j + 1 : j + 4].copy())
    return changed, float(x[j + 4])


@dataclass(frozen=True)
class Propagation:
    """An identified moment (kg m^2) with its standard deviation, 95 % interval and error budget.

    ``budget`` maps each :class:`~bifilar.rig.Uncertainty` group to its share of the variance;
    ``gradient`` is dJ/dx per input (linear: the Jacobian; Monte Carlo: the regression slopes).
    """

    moment: float
    std: float
    low: float
    high: float
    method: str
    budget: dict[str, float]
    inputs: Inputs
    gradient: np.ndarray


def budget(inp: Inputs, gradient: np.ndarray) -> dict[str, float]:
    """Each :data:`GROUPS` entry's share of the variance sum_i (gradient_i std_i)^2 (0 where it is 0)."""
    parts = (gradient * inp.std) ** 2
    total = parts.sum()
    shares = np.zeros(len(GROUPS))
    np.add.at(shares, _group_index(inp.groups), parts)
    return {g: float(shares[n] / total) if total > 0.0 else 0.0 for n, g in enumerate(GROUPS)}


@lru_cache(maxsize=None)
def _group_index(groups: tuple[str, ...]) -> np.ndarray:
    """Index in :data:`GROUPS` of each input's group."""
    return np.array([GROUPS.index(g) for g in groups])


def linear(rig: Rig, axis, period: float, period_std: float, rest: Rest | None = None) -> Propagation:
    """First-order propagation through the exact inversion (see the module docstring); ``rest``: the
    rig's rest pose if known."""
    return linear_axes(rig, {axis: period}, period_std, rest)[axis]


def linear_axes(rig: Rig, periods: dict, period_std: float, rest: Rest | None = None, bases: dict | None = None,
                lin: Modes | None = None) -> dict:
    """:func:`linear` for several axes at once (axis -> measured period): the perturbed rigs' rest
    poses are shared, as the geometry inputs are the same for every axis. ``bases``: the inversions
    (axis -> :class:`Identified`) and ``lin``: the rig's linearisation about ``rest``, if known."""
    rest = rest_pose(rig) if rest is None else rest
    lin = linearize(rig, rest) if lin is None else lin
    pencils = {a: pencil(rig, a, lin=lin) for a in periods}
    if bases is None:
        bases = {a: invert_period(rig, a, t, rest, pencils[a]) for a, t in periods.items()}
    inp = inputs(rig, 0.0, period_std)
    axes = list(bases)
    shapes, inertias = np.empty((len(axes), 6)), np.empty((len(axes), 3, 3))
    for n, a in enumerate(axes):
        k, _, v = pencils[a].associated(bases[a].moment)
        shapes[n] = lin.basis @ v[:, k]
        inertias[n] = with_moment(rig, a, bases[a].moment).inertia
    # The compiled kernel continues inextensible wires; elastic ones (their stretch is in every changed
    # rig: apply keeps axial_stiffness) take the general path.
    table, ok = (None, False) if rig.elastic else kernel_slopes(rig, rest, inp, shapes, inertias)
    slopes = {a: table[n] for n, a in enumerate(axes)} if ok else _slopes_resolved(rig, rest, inp, bases)
    return {a: propagate(b, slopes[a], inputs(b.rig, periods[a], period_std)) for a, b in bases.items()}


def propagate(base: Identified, slopes: np.ndarray, own: Inputs) -> Propagation:
    """The linear propagation for one axis from d ln T / d x_i at fixed J (``slopes``, the period's
    entry unused) and the inputs ``own`` of the identified rig with its measured period."""
    dlnT_dJ = base.sensitivity / base.moment
    gradient = -slopes / dlnT_dJ
    gradient[-1] = 1.0 / (base.period * dlnT_dJ)  # dJ / dT of the measured period
    gradient = np.where(own.std > 0.0, gradient, 0.0)
    std = float(np.sqrt(np.sum((gradient * own.std) ** 2)))
    return Propagation(base.moment, std, base.moment - _Z * std, base.moment + _Z * std, "linear",
                       budget(own, gradient), own, gradient)


def period_only(base: Identified, period: float, period_std: float) -> Propagation:
    """The period's sigma alone propagated to the moment, to first order (dJ / dT = J / (T d ln T / d ln J)),
    the rig's geometry and mass left out: what the tensor fit propagates for every hanging
    (:func:`bifilar.identification.measurement.measure` with ``propagate="period"``)."""
    own = inputs(base.rig, period, period_std)
    own = replace(own, std=np.where(np.array(own.groups) == "period", own.std, 0.0))
    gradient = np.zeros(len(own.values))
    gradient[-1] = base.moment / period / base.sensitivity
    std = base.moment * period_std / period / base.sensitivity
    return Propagation(base.moment, std, base.moment - _Z * std, base.moment + _Z * std, "linear",
                       budget(own, gradient), own, gradient)


def kernel_slopes(rig: Rig, rest: Rest, inp: Inputs, shapes: np.ndarray, inertias: np.ndarray):
    """(table axes x inputs, ok): d ln T / d x_i at fixed J of the modes with pose shapes ``shapes`` at
    the inertias ``inertias``, compiled (:func:`bifilar.identification.slopes_kernel.period_slopes`); ok is
    False where the rest pose does not continue uniquely (then :func:`_slopes_resolved` is the path)."""
    h = _STEP * inp.std
    h[-1] = 0.0
    air_base, air_com = np.zeros((6, 6)), np.zeros((3, 6, 6))
    if rig.air is not None:
        air_base = added_mass(rig.air, rig.com)
        for k in range(3):
            air_com[k] = added_mass(rig.air, rig.com + h[-4 + k] * np.eye(3)[k])
    return period_slopes(inp.values, h, len(rig.wires), float(rig.gravity), rig_scale(rig), rest.com,
                         rest.rotation, rest.tensions, inertias, shapes, air_base, air_com)


def _slopes_resolved(rig: Rig, rest: Rest, inp: Inputs, bases: dict) -> dict:
    """The slopes of :func:`kernel_slopes` with each changed rig's rest pose found by :func:`rest_pose` (from the base
    pose) and its modes solved afresh: the general path, for a singular base equilibrium."""
    slopes = {a: np.zeros(len(inp.values)) for a in bases}
    for i in np.flatnonzero(inp.std[:-1] > 0.0):
        x = inp.values.copy()
        h = _STEP * inp.std[i]
        x[i] += h
        changed, _ = apply(rig, x)
        lin = linearize(changed, rest_pose(changed, guess=rest))
        for a, b in bases.items():
            p = pencil(changed, a, lin=lin)
            k, w2, _ = p.associated(b.moment)
            slopes[a][i] = (np.log(2.0 * np.pi / np.sqrt(w2[k])) - np.log(b.period)) / h
    return slopes


def monte_carlo(rig: Rig, axis, period: float, period_std: float, samples: int, rng: np.random.Generator) -> Propagation:
    """Propagation by ``samples`` random draws of the inputs (see the module docstring)."""
    base = invert_period(rig, axis, period)
    inp = inputs(base.rig, period, period_std)
    noise = rng.standard_normal((samples, len(inp.values)))
    draws = np.empty(samples)
    for n in range(samples):
        changed, t = apply(base.rig, inp.values + inp.std * noise[n])
        draws[n] = invert_period(changed, axis, t).moment
    varied = inp.std > 0.0
    design = np.column_stack([np.ones(samples), noise[:, varied]])
    slopes = np.linalg.lstsq(design, draws, rcond=None)[0][1:]
    gradient = np.zeros(len(inp.values))
    gradient[varied] = slopes / inp.std[varied]
    low, high = np.quantile(draws, [0.5 - LEVEL / 2.0, 0.5 + LEVEL / 2.0])
    return Propagation(base.moment, float(draws.std(ddof=1)), float(low), float(high), f"monte-carlo ({samples})",
                       budget(inp, gradient), inp, gradient)


@dataclass(frozen=True)
class Coverage:
    """Outcome of :func:`coverage`: how many of ``trials`` 95 % intervals held the true moment;
    ``std`` the linear standard deviation reported, ``spread`` the standard deviation of the estimates."""

    trials: int
    hits: int
    std: float
    spread: float

    @property
    def fraction(self) -> float:
        return self.hits / self.trials


def coverage(rig: Rig, axis, trials: int, rng: np.random.Generator) -> Coverage:
    """Synthetic experiments on ``rig`` (the truth, with its ``[uncertainty]``) for the linear method.

    Each trial draws a measured rig and period from the stated uncertainties about the truth (the
    small-amplitude period of the true rig), inverts, and asks whether J +- 1.96 sigma holds the true
    moment. sigma is computed once, at the first trial's measured rig, and reused: between draws it
    changes by the relative size of the measurement errors (~1e-3), which cannot move the coverage.
    """
    truth = moment(rig, axis)
    true_period = linear_period(rig, axis)
    inp = inputs(rig, true_period, rig.uncertainty.period)
    estimates = np.empty(trials)
    std = None
    for n in range(trials):
        measured, t = apply(rig, inp.values + inp.std * rng.standard_normal(len(inp.values)))
        estimates[n] = invert_period(measured, axis, t).moment
        if std is None:
            std = linear(measured, axis, t, rig.uncertainty.period).std
    hits = int(np.sum(np.abs(estimates - truth) <= _Z * std))
    return Coverage(trials, hits, std, float(estimates.std(ddof=1)))
