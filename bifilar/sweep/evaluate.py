"""One configuration of a sweep: rest pose, modes, identification uncertainty, tensions, clearance.

Everything goes through the project's one code path: the rest pose of :mod:`bifilar.rig.statics`
(continued from the neighbouring configuration's), the modes of :mod:`bifilar.motion.modes`, the mode
associated with each measured axis and the linear propagation of the rig's ``[uncertainty]`` through
the exact inversion that ``identify`` uses (:func:`bifilar.identification.propagation.linear`, its
period slopes compiled). Where the neighbour's rest pose continues cleanly, the rest pose and the modes
come from one compiled call instead (:mod:`bifilar.sweep.kernel`: the same Newton and the same reduced
M and K), which tests/test_sweep_continued.py holds to this path row by row.

Peak tension in a measured motion of amplitude A (the peak rotation about the axis, rad). The wire
tensions of a state follow exactly from Newton-Euler with the wires as constraints (pose coordinates
q = (x, theta) of :mod:`bifilar.rig.pose_kernel`): with J the constraint Jacobian, M = diag(m I, I_w),
F the weight and the gyroscopic wrench, differentiating J q' = 0 gives

    t = (J M^-1 J^T)^-1 (J M^-1 (F - gyro) + h),   h_i = q'^T (hess g_i) q',

the generalised force of wire i being -t_i grad g_i. In the linear mode the state passes the rest pose
with the peak velocity (there h, the centripetal part, is largest) and turns at the displaced poses
+-A shape with no velocity (there the first-order part is largest); the peak tension is the largest
over these three states: exact at the bottom, first order at the turning points. The tensions of a
state are the N-wire model's (:mod:`bifilar.motion.nwire`, which solves exactly this). The test checks
the peak against the Kane model's simulated tensions.

With ``[air]`` in the base rig the modes carry the air's added mass, and ``air_share`` says how much of
each measured period is air: 1 - (T_vacuum / T)^2 of the measured mode, the air's share of the
apparent moment for a pure rotation.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from functools import lru_cache

import numpy as np

from bifilar.bodies.boat import lowest_point as boat_lowest_point
from bifilar.bodies.composite import equivalent_box
from bifilar.identification import identify as ident
from bifilar.identification.air import vacuum
from bifilar.identification.propagation import inputs, kernel_slopes, linear_axes, propagate
from bifilar.motion.modes import DEGENERATE_RTOL, NEUTRAL_RTOL, Modes, linearize, motion_of
from bifilar.motion.nwire import NWireModel
from bifilar.rig import Rig, RigError
from bifilar.rig.file import check_reachable
from bifilar.rig.statics import NEUTRAL_SLACK, NULL_RTOL, Rest, anchors, arms, lengths, rest_pose, rig_scale
from bifilar.sweep import kernel as SK
from bifilar.sweep.axes import configure
from bifilar.sweep.space import Space

AXES = ("x", "y", "z")


@dataclass
class Row:
    """The results for one configuration (SI; relative sigma is std / moment)."""

    values: dict[str, float]
    feasible: bool = False
    reason: str = ""
    periods: tuple = (None, None, None, None)  # s, longest first; None for neutral / absent
    motions: tuple = ("", "", "", "")
    tensions: tuple = (math.nan, math.nan)  # N at rest, wires 1 and 2
    tension_peak: float = math.nan  # N
    sigma: dict | None = None  # axis -> relative sigma (None: not identifiable or not measured)
    dominant: dict | None = None  # axis -> the uncertainty group with the largest share
    budget: dict | None = None  # axis -> {uncertainty group: its share of the variance}
    separation: float = math.nan  # smallest relative gap between two mode periods
    near: dict | None = None  # axis -> relative gap in frequency from its mode to the nearest other one
    clearance: float = math.nan  # m of the lowest point above the floor (the margin is a limit)
    air_share: dict | None = None  # axis -> 1 - (T_vacuum / T)^2 of its mode: the air's part (rigs with [air])
    rest: Rest | None = None


def peak_tension(rig: Rig, lin: Modes, index: int, amplitude_about: np.ndarray, amplitude: float) -> float:
    """Largest wire tension (N) over the motion of mode ``index`` whose peak rotation about the world
    axis ``amplitude_about`` is ``amplitude`` (see the module docstring)."""
    mode = lin.modes[index]
    if mode.period is None:
        return math.nan
    model = NWireModel.from_rig(rig)  # its tensions at a state are the formula above
    return _peak(model, lin.rest, [np.concatenate([mode.com, mode.rotation])], [mode.period], [amplitude_about], amplitude)


def _peak(model: NWireModel, rest: Rest, shapes: list, periods: list, abouts: list, amplitude: float) -> float:
    """:func:`peak_tension` over modes of any scale ``shapes`` (x, theta; world) with ``periods``, each
    scaled to peak rotation ``amplitude`` about its world axis in ``abouts``."""
    scaled, omegas = [], []
    for shape, period, about in zip(shapes, periods, abouts):
        turn = abs(shape[3:] @ about)
        if turn > 0.0:
            scaled.append(shape * (amplitude / turn))
            omegas.append(2.0 * np.pi / period)
    if not scaled:
        return math.nan
    springs = np.zeros(0) if model.springs is None else model.springs
    return float(SK.peak_tension(rest.com, rest.rotation, np.array(scaled), np.array(omegas), springs,
                                 np.asarray(rest.tensions, float), *model.args))


def measured_mode(rig: Rig, lin: Modes, about: np.ndarray) -> int:
    """Index in ``lin.modes`` of the oscillating mode with the largest share of its kinetic energy in
    the rotation about the world axis ``about`` (the mode timed to measure that moment)."""
    inertia = lin.rest.rotation @ rig.inertia @ lin.rest.rotation.T
    moment = about @ inertia @ about

    def share(mode):
        if mode.period is None:
            return -1.0
        total = rig.mass * mode.com @ mode.com + mode.rotation @ inertia @ mode.rotation
        return moment * (mode.rotation @ about) ** 2 / total

    return max(range(len(lin.modes)), key=lambda i: share(lin.modes[i]))


def lowest_point(rig: Rig, rest: Rest, parts=None) -> float:
    """World z (m) of the body's lowest point at rest: of its ``parts`` (a suspension file's,
    :func:`bifilar.bodies.boat.lowest_point`, exact per primitive) if given, else the lowest corner of
    its inertia-equivalent box."""
    if parts is not None:
        return float(boat_lowest_point(parts, rest.com - rest.rotation @ rig.com, rest.rotation)[0][0])
    body = rig.com + _box_corners(float(rig.mass), *np.asarray(rig.inertia, dtype=float).ravel())
    world = rest.com + (body - rig.com) @ rest.rotation.T
    return float(world[:, 2].min())


@lru_cache(maxsize=64)
def _box_corners(mass: float, *inertia: float) -> np.ndarray:
    """Corners (8 x 3, body frame, about the COM) of the inertia-equivalent box: one per body, not
    one per configuration (a sweep varies the wires, not the body)."""
    half, axes = equivalent_box(mass, np.array(inertia).reshape(3, 3))
    corners = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]) * half
    return corners @ axes.T


def evaluate(space: Space, values: dict[str, float], guess: Rest | None = None) -> Row:
    """Evaluate one configuration; an unreachable one is a row marked infeasible, never an error.

    With ``guess`` (the neighbouring configuration's rest pose) the compiled continuation of
    :mod:`bifilar.sweep.kernel` is tried first; the general path takes every configuration it
    hands back, every first configuration of a chunk and every rig with ``[air]``."""
    row = Row(values=values)
    try:
        rig = configure(space.rig, values)
        check_reachable(rig)
        if guess is None or rig.air is not None or rig.elastic or not _continued(space, rig, row, guess):
            _general(space, rig, row, guess)
    except (RigError, np.linalg.LinAlgError) as exc:
        row.reason = exc.problem if isinstance(exc, RigError) else f"singular: {exc}"
        return row
    _limits(space, rig, row)
    return row


def _continued(space: Space, rig: Rig, row: Row, guess: Rest) -> bool:
    """Fill ``row`` from the compiled continuation; False, with ``row`` untouched, if it hands back."""
    status, com, rot, tensions, w2, shapes = SK.continued_modes(
        arms(rig), anchors(rig), lengths(rig), rig.mass, rig.gravity, rig.inertia, rig_scale(rig), guess.com,
        guess.rotation, guess.tensions, NULL_RTOL, NEUTRAL_RTOL, DEGENERATE_RTOL, NEUTRAL_SLACK)
    if status != SK.OK:
        return False
    rest = Rest(com, rot, tensions)
    periods = 2.0 * np.pi / np.sqrt(w2)  # w2 ascending: the longest period first
    bases, chosen, unmeasurable = {}, {}, []
    for axis in space.measure:
        about = rot @ ident.axis_vector(axis)
        j0 = ident.moment(rig, axis)
        shares = j0 * (about @ shapes[3:]) ** 2  # the pencil's shares: the shapes are M-normalised
        if shares.max() < 1e-12:  # no mode turns about the axis
            unmeasurable.append(axis)
            continue
        k = int(np.argmax(shares))
        chosen[axis] = k
        bases[axis] = ident.Identified(j0, float(periods[k]), float(0.5 * shares[k]), rig)
    inp = inputs(rig, 0.0, rig.uncertainty.period)
    table, ok = kernel_slopes(rig, rest, inp, np.array([shapes[:, k] for k in chosen.values()]).reshape(-1, 6),
                              np.array([rig.inertia] * len(chosen)).reshape(-1, 3, 3))
    if not ok:
        return False
    row.rest = rest
    row.tensions = tuple(float(t) for t in tensions[:2])
    row.periods = tuple(([float(p) for p in periods] + [None] * 4)[:4])
    row.motions = tuple(([motion_of(rig, rest, shapes[:3, k], shapes[3:, k]) for k in range(len(w2))] + [""] * 4)[:4])
    row.separation = float(np.min((periods[:-1] - periods[1:]) / periods[:-1])) if len(w2) > 1 else math.nan
    row.near = {axis: nearest(list(periods), k) for axis, k in chosen.items()} | {a: None for a in unmeasurable}
    row.sigma, row.dominant, row.budget = {a: None for a in unmeasurable}, {a: None for a in unmeasurable}, {}
    for n, (axis, k) in enumerate(chosen.items()):
        values = inp.values.copy()
        values[-1] = bases[axis].period  # the measured period: the one input that differs between axes
        _record(row, axis, propagate(bases[axis], table[n], replace(inp, values=values)))
    peak = _peak(NWireModel.from_rig(rig), rest, [shapes[:, k] for k in chosen.values()],
                 [periods[k] for k in chosen.values()], [rot @ ident.axis_vector(a) for a in chosen], space.amplitude)
    row.tension_peak = float(np.nanmax([tensions.max(), peak]))
    return True


def nearest(periods: list, k: int) -> float:
    """The relative gap in frequency, |w_j / w_k - 1|, from mode ``k`` to the nearest other one of
    ``periods`` (s; None: neutral), nan where it is alone. Under ~1.5 beats over a record such a mode
    can hide in the amplitude law a record learns (:mod:`bifilar.identification.records.near`)."""
    gaps = [abs(periods[k] / p - 1.0) for j, p in enumerate(periods) if j != k and p is not None]
    return min(gaps) if gaps else math.nan


def _record(row: Row, axis: str, spread) -> None:
    row.sigma[axis] = spread.std / spread.moment
    row.dominant[axis] = max(spread.budget, key=spread.budget.get) if spread.std > 0.0 else None
    row.budget[axis] = spread.budget


def _general(space: Space, rig: Rig, row: Row, guess: Rest | None) -> None:
    """Fill ``row`` by the general path: :func:`rest_pose`, :func:`linearize`, the pencils and
    :func:`linear_axes`, as ``identify`` and ``modes`` do."""
    rest = rest_pose(rig, guess)
    lin = linearize(rig, rest)
    row.rest = rest
    row.tensions = tuple(float(t) for t in rest.tensions[:2])
    periods = [m.period for m in lin.modes] + [None] * 4
    row.periods = tuple(periods[:4])
    row.motions = tuple(([m.motion for m in lin.modes] + [""] * 4)[:4])
    osc = sorted(p for p in row.periods if p is not None)
    row.separation = min((b - a) / b for a, b in zip(osc, osc[1:])) if len(osc) > 1 else math.nan
    row.sigma, row.dominant, row.budget, row.near = {}, {}, {}, {}
    peaks = [float(rest.tensions.max())]
    bases = {}
    for axis in space.measure:
        p = ident.pencil(rig, axis, lin=lin)
        k, w2, v = p.associated(p.moment0)
        if p.shares(p.moment0, v).max() < 1e-12:  # no mode turns about the axis
            row.sigma[axis], row.dominant[axis], row.near[axis] = None, None, None
            continue
        row.near[axis] = nearest(list(2.0 * np.pi / np.sqrt(w2)), k)
        bases[axis] = ident.predicted(rig, p)
    periods = {axis: b.period for axis, b in bases.items()}
    spreads = linear_axes(rig, periods, rig.uncertainty.period, rest, bases, lin)
    for axis, spread in spreads.items():
        _record(row, axis, spread)
        about = rest.rotation @ ident.axis_vector(axis)
        peaks.append(peak_tension(rig, lin, measured_mode(rig, lin, about), about, space.amplitude))
    row.tension_peak = float(np.nanmax(peaks))
    if rig.air is not None:  # how much of each measured period is the air's added inertia
        bare = vacuum(rig)
        row.air_share = {}
        for axis, b in bases.items():
            p = ident.pencil(bare, axis, lin=linearize(bare, rest))
            k, w2, _ = p.associated(p.moment0)
            row.air_share[axis] = 1.0 - (2.0 * np.pi / np.sqrt(w2[k]) / b.period) ** 2


def _limits(space: Space, rig: Rig, row: Row) -> None:
    """Clearance and the limits: ``row.feasible`` and the reasons it is not."""
    limits = space.limits
    if limits.floor is not None:
        row.clearance = lowest_point(rig, row.rest, space.parts) - limits.floor
    problems = []
    if any(v is None for v in row.sigma.values()):
        problems.append("an axis cannot be identified")
    if limits.tension is not None and row.tension_peak > limits.tension:
        problems.append(f"peak tension {row.tension_peak:.6g} N over {limits.tension:g} N")
    if limits.floor is not None and row.clearance < limits.clearance:
        problems.append(f"clearance {row.clearance:.4g} m under {limits.clearance:g} m")
    if limits.separation is not None:
        problems += [f"the {axis} mode {100.0 * gap:.2g} % from another mode's frequency, under "
                     f"{100.0 * limits.separation:g} %" for axis, gap in row.near.items()
                     if gap is not None and gap < limits.separation]
    row.feasible = not problems
    row.reason = "; ".join(problems)
