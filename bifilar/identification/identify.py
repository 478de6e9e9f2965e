"""A moment of inertia from a measured period: the thesis's ch. 7.1, done with the exact linearisation.

One moment is unknown: J = e^T I e about a body axis e (a unit vector in the body frame; ``x``, ``y``,
``z`` name the body axes, for which J is the diagonal entry I_xx, I_yy or I_zz). The tensor varies
only along e, I(J) = I + (J - e^T I e) e e^T: the other entries are held, and for a principal axis e
only that principal moment changes. A measured period of the mode that turns about e then fixes J.

Exact and cheap. At rest the stiffness K of :func:`bifilar.motion.modes.linearize` holds gravity and the
wires only, and the mass matrix is linear in the inertia, so with the rest pose computed once

    M(J) = M(J0) + (J - J0) w w^T,   w = G^T R e,

(G: angular velocity per independent speed, the rotation half of the null-space basis of the wire
constraints; R: rest rotation body -> world). Every period at every J is then an n x n generalised
eigenproblem (n = 4 for two wires) with all the modes and their coupling;
nothing is truncated as in the thesis's 2x2 systems.

Which mode belongs to the axis. For K v = w2 M v with v^T M v = 1, Hellmann-Feynman gives

    d ln T / d ln J = J (w . v)^2 / 2 =: s,

half the share of the mode's kinetic energy stored by the moment about e: the rotation shape's
component along the body axis, weighed in kinetic energy (a swing with a small but pure rotation
about e has a small share). The mode associated with the axis is the one with the largest share; its
period is also the one that determines J best. Modes are followed continuously from the rig's own J0
(each step takes the mode of largest M-overlap with the previous one, never the same index in a
sorted list) by Newton's method on ln T(ln(J - J_min)), to the measured period. Since M grows with J,
a followed period never decreases and its root is unique. Every mode of J0 is followed, because a
strongly coupled rig can hand the rotation about e from one mode to another as J moves; a root counts
where the followed mode has the largest share there. No root, or several, and the period is refused.

Amplitude. A period measured at a finite amplitude differs from the linear one; the Kane model,
released at the stated amplitude along the mode, gives the ratio T(A)/T(0) that maps it back
(:func:`amplitude_ratio`, :func:`identify`). The amplitude is the peak rotation about the axis, where
the body is let go.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from scipy.linalg import eigh
from scipy.spatial.transform import Rotation

from bifilar.motion.kane import KaneModel
from bifilar.motion.modes import Modes, degenerate_sets, linearize, oscillating
from bifilar.identification.periods import period as crossing_period
from bifilar.rig import Rig, RigError
from bifilar.motion.nwire import NWireModel
from bifilar.motion.nwire import simulate as nwire_simulate
from bifilar.motion.simulate import simulate
from bifilar.rig.statics import Rest, State, taut_shift

AXES = {"x": np.array([1.0, 0.0, 0.0]), "y": np.array([0.0, 1.0, 0.0]), "z": np.array([0.0, 0.0, 1.0])}

_STEP = 0.05  # first Newton step limit in ln(J - J_min): 5 %, small enough to follow a mode by overlap
_OVERLAP = 0.99  # |v_new^T M v_old| above which the step limit may double (up to 1 in ln J)
_REACH = np.log(1e6)  # J - J_min is searched within a factor 1e6 of the rig's own value
_MAX_STEPS = 2 * int(_REACH / _STEP)  # enough to cross the search range twice at the smallest limit
_TOL = 1e-13  # |ln T - ln T_measured| at the root: rounding of a small eigenproblem
_ROUNDING = 1e3 * np.finfo(float).eps  # eigh's absolute error on w2, relative to the largest w2
# Amplitude correction: the fixed point J -> J(T / ratio(J)) contracts by a factor k per pass (at most
# ~A^2; ~0.004 measured at 0.3 rad on the trifilar). After a relative step s the error left is
# ~s k / (1 - k), k measured as the ratio of the last two steps; the fixed point is settled when that is
# under AMPLITUDE_RTOL (the inversion's own rounding, ~1e-13). A step that no longer shrinks (k >= 1/2)
# below _RATIO_NOISE is the simulated ratio's floor (crossing times good to ~1e-10 of the period).
AMPLITUDE_RTOL = 1e-13
AMPLITUDE_PASSES = 12
_RATIO_NOISE = 1e-10
_CYCLES = 8  # periods simulated to measure T(A): crossing times fitted over 8 cycles
_SAMPLES_PER_PERIOD = 100  # crossing refinement is good to ~1e-10 of the period at this rate
# Integrator tolerance: the angles are O(1) rad, so the local error rtol is an error of rtol / A
# relative to an oscillation of amplitude A; it is kept below 1e-6 of the amplitude.
_RTOL = 1e-10
_RTOL_PER_RAD = 1e-6


def axis_vector(axis) -> np.ndarray:
    """A unit body-frame vector from ``x``, ``y``, ``z`` or any non-zero 3-vector."""
    if isinstance(axis, str):
        return AXES[axis].copy()  # already unit
    e = np.asarray(axis, dtype=float)
    return e / np.linalg.norm(e)


def moment(rig: Rig, axis) -> float:
    """J = e^T I e, the moment of inertia about the body axis (kg m^2)."""
    e = axis_vector(axis)
    return float(e @ rig.inertia @ e)


def with_moment(rig: Rig, axis, value: float) -> Rig:
    """The rig with its moment about the body axis set to ``value``, the rest of the tensor held."""
    e = axis_vector(axis)
    return replace(rig, inertia=rig.inertia + (value - e @ rig.inertia @ e) * np.outer(e, e))


@dataclass(frozen=True)
class Pencil:
    """The linearised rig as a function of the moment J about one body axis: K v = w2 M(J) v."""

    axis: np.ndarray  # e, body frame
    lin: Modes  # at the rig's own moment J0
    rotation: np.ndarray  # rest pose, body -> world (the frame of lin.mass)
    partial_com: np.ndarray  # (3 x n): COM velocity (world) per independent speed
    partial_omega: np.ndarray  # (3 x n): angular velocity (world) per independent speed
    moment0: float  # J0
    floor: float  # J_min: I(J) is positive definite for J > J_min

    @property
    def w(self) -> np.ndarray:
        """G^T R e: angular velocity about the axis per independent speed."""
        return self.partial_omega.T @ (self.rotation @ self.axis)

    def mass(self, value: float) -> np.ndarray:
        return self.lin.mass + (value - self.moment0) * np.outer(self.w, self.w)

    def modes(self, value: float):
        """(w2, v) of the oscillating modes at moment ``value``, longest period first: v M-normalised,
        neutral modes dropped. Within a set of equal frequencies (a yaw that happens to have a sway's
        period) the basis is the one that degenerate perturbation theory picks for a change of J:
        dM = dJ w w^T splits the set along the eigenvectors of (V^T w)(V^T w)^T, so one vector carries
        all of the set's share about the axis and the others none (eigh's own basis would mix them,
        and the association and the sensitivity with them)."""
        w2, v = eigh(self.lin.stiffness, self.mass(value))
        keep = oscillating(w2, self.lin.pendulum)
        w2, v = w2[keep], v[:, keep]
        for k, j in degenerate_sets(w2, self.lin.pendulum):
            c = self.w @ v[:, k:j]
            if c @ c > 0.0:
                # an orthogonal transform of the set whose first column is c / |c| (Householder)
                v[:, k:j] = v[:, k:j] @ np.linalg.qr(np.column_stack([c, np.eye(j - k)[:, 1:]]))[0]
        return w2, v

    def shares(self, value: float, v: np.ndarray) -> np.ndarray:
        """Kinetic share of the moment about the axis in each mode (columns of v, M-normalised)."""
        return value * (self.w @ v) ** 2

    def associated(self, value: float):
        """(k, w2, v): :meth:`modes` at ``value`` and the index of the one with the largest share."""
        w2, v = self.modes(value)
        return int(np.argmax(self.shares(value, v))), w2, v


def pencil(rig: Rig, axis, rest: Rest | None = None, lin: Modes | None = None) -> Pencil:
    """Linearise the rig once (about ``rest``, default its computed rest pose; or take ``lin``, its
    linearisation, if known) for any moment about ``axis``."""
    lin = linearize(rig, rest) if lin is None else lin
    e = axis_vector(axis)
    j0 = moment(rig, e)
    floor = j0 - 1.0 / float(e @ np.linalg.solve(rig.inertia, e))
    return Pencil(e, lin, lin.rest.rotation, lin.partial_com, lin.partial_omega, j0, floor)


@dataclass(frozen=True)
class Identified:
    """The moment (kg m^2) about ``axis`` whose associated mode has the linear ``period`` (s).

    ``sensitivity`` is d ln T / d ln J of that mode at the solution (1/2 for a pure rotation about
    the axis): a period error dT gives dJ / J = dT / T / sensitivity. ``amplitude_ratio`` is T(A)/T(0)
    when a finite amplitude was corrected for, else 1.
    """

    moment: float
    period: float
    sensitivity: float
    rig: Rig
    amplitude_ratio: float = 1.0


def _track(p: Pencil, k: int, target: float):
    """Follow mode ``k`` of J0 continuously to ln T = ``target``: (J, index there, w2, v), or None if
    the mode does not reach that period for J - J_min within :data:`_REACH` of J0 - J_min.

    Newton steps in u = ln(J - J_min) start limited to :data:`_STEP`; the limit doubles while the
    followed mode keeps an M-overlap of at least :data:`_OVERLAP` and falls back otherwise, so that
    a mode that never reaches the period is walked out of range in a few steps.
    """
    value = p.moment0
    w2, v = p.modes(value)
    u0 = u = np.log(value - p.floor)
    limit = _STEP
    for _ in range(_MAX_STEPS):
        residual = np.log(2.0 * np.pi) - 0.5 * np.log(w2[k]) - target  # ln T - ln T_measured
        # eigh resolves w2[k] to ~eps * max(w2) absolutely: a slow mode beside fast ones is known to less.
        if abs(residual) < _TOL + _ROUNDING * w2.max() / w2[k]:
            return value, k, w2, v
        slope = 0.5 * (p.w @ v[:, k]) ** 2 * (value - p.floor)  # d ln T / du
        step = -residual / slope if slope > 0.0 else -np.sign(residual) * limit
        u += float(np.clip(step, -limit, limit))
        if abs(u - u0) > _REACH:
            return None
        value = p.floor + np.exp(u)
        previous = v[:, k]
        w2, v = p.modes(value)
        overlap = np.abs(v.T @ p.mass(value) @ previous)
        k = int(np.argmax(overlap))
        limit = min(2.0 * limit, 1.0) if overlap[k] >= _OVERLAP else _STEP
    return None


def invert_period(rig: Rig, axis, period: float, rest: Rest | None = None, p: Pencil | None = None) -> Identified:
    """The moment about ``axis`` for which the mode associated with the axis has ``period``.

    Every oscillating mode of J0 is followed to the period (a strongly coupled rig can hand the
    rotation about the axis from one mode to another as J moves); a solution counts where the
    followed mode has the largest kinetic share about the axis. Raises :class:`RigError`: field
    ``axis`` if no mode turns about the axis, field ``period`` if no solution or several exist.
    """
    p = pencil(rig, axis, rest) if p is None else p
    src, name = rig.source, _fmt(p.axis)
    w2, v = p.modes(p.moment0)
    if p.shares(p.moment0, v).max() < 1e-12:
        raise RigError(src, "axis", f"no oscillating mode turns about body axis {name}: its moment cannot be "
                                    "measured by timing this rig")
    target = np.log(period)
    found = {}
    for k in range(len(w2)):
        hit = _track(p, k, target)
        if hit is not None and p.associated(hit[0])[0] == hit[1]:
            found[round(hit[0], 9 - int(np.floor(np.log10(hit[0]))))] = hit
    if not found:
        ends = [p.associated(j) for j in (p.floor + np.exp(np.log(p.moment0 - p.floor) - _REACH),
                                          p.floor + np.exp(np.log(p.moment0 - p.floor) + _REACH))]
        low, high = sorted(2.0 * np.pi / np.sqrt(w2_[k_]) for k_, w2_, _ in ends)
        raise RigError(src, "period", f"{period:.9g} s: no moment about {name} within a factor 1e6 of the "
                                      f"rig's {p.moment0:.6g} kg m^2 gives the mode turning about it this period "
                                      f"(it spans {low:.9g}..{high:.9g} s there; d ln T / d ln J = "
                                      f"{predicted(rig, p).sensitivity:.2g} at the rig's moment)")
    if len(found) > 1:
        raise RigError(src, "period", f"{period:.9g} s is ambiguous: moments {', '.join(f'{j:.6g}' for j in found)} "
                                      f"kg m^2 about {name} all give it")
    value, k, w2, v = next(iter(found.values()))
    sensitivity = float(0.5 * p.shares(value, v[:, k:k + 1])[0])
    return Identified(float(value), float(2.0 * np.pi / np.sqrt(w2[k])), sensitivity, with_moment(rig, p.axis, value))


def predicted(rig: Rig, p: Pencil) -> Identified:
    """The inversion of the period the rig itself predicts for the mode associated with the axis:
    its root is the rig's own moment J0 by construction (what a sweep asks: how well would this rig
    measure its own moment), so no mode needs following to it."""
    k, w2, v = p.associated(p.moment0)
    sensitivity = float(0.5 * p.shares(p.moment0, v[:, k:k + 1])[0])
    return Identified(p.moment0, float(2.0 * np.pi / np.sqrt(w2[k])), sensitivity, rig)


def linear_period(rig: Rig, axis, rest: Rest | None = None) -> float:
    """Small-amplitude period (s) of the mode associated with ``axis`` at the rig's own inertia."""
    return predicted(rig, pencil(rig, axis, rest)).period


@dataclass(frozen=True)
class Release:
    """The rig let go from rest displaced along the mode associated with an axis (:func:`released`)."""

    model: KaneModel | NWireModel  # Kane-Tseng for two wires, the N-wire model for more
    state: State
    period: float  # the mode's linear period, s
    rest_rotation: np.ndarray  # body -> world at rest
    axis_world: np.ndarray  # the axis at rest, world frame


def released(rig: Rig, axis, amplitude: float, rest: Rest | None = None) -> Release:
    """An experimenter's start: the body turned about ``axis`` by ``amplitude`` (rad) and let go.

    The rest pose is displaced by the associated mode's linear shape, scaled so that the rotation
    vector's component along the axis is ``amplitude``, then moved the shortest way onto the taut-wire
    poses (:func:`bifilar.rig.statics.taut_shift`). Every speed is zero, so the rotation about the axis
    starts at its turning point: the amplitude is the peak rotation. For a mode that only turns about
    the axis (the torsion of a symmetric rig) this is exactly the 1-DOF motion of :mod:`bifilar.motion.lagrange`.
    """
    p = pencil(rig, axis, rest)
    k, w2, v = p.associated(p.moment0)
    axis_world = p.rotation @ p.axis
    turn, shift = p.partial_omega @ v[:, k], p.partial_com @ v[:, k]
    scale = amplitude / (turn @ axis_world)
    rotation = Rotation.from_rotvec(scale * turn).as_matrix() @ p.rotation
    com = p.lin.rest.com + scale * shift
    com = com + taut_shift(rig, com, rotation)
    state = State(com, rotation, np.zeros(3), np.zeros(3))
    model = KaneModel.from_rig(rig) if len(rig.wires) == 2 else NWireModel.from_rig(rig)
    return Release(model, state, float(2.0 * np.pi / np.sqrt(w2[k])), p.rotation, axis_world)


def simulated_period(rig: Rig, axis, amplitude: float, rest: Rest | None = None) -> float:
    """The period (s) the Kane model shows for the mode associated with ``axis`` at ``amplitude``.

    From :func:`released`, :data:`_CYCLES` cycles are integrated and the period is the mean interval
    of the crossings of the rotation angle about the axis (:func:`bifilar.identification.periods.period`).
    """
    start = released(rig, axis, amplitude, rest)
    rtol = min(_RTOL, _RTOL_PER_RAD * amplitude)
    integrate = simulate if isinstance(start.model, KaneModel) else nwire_simulate
    run = integrate(start.model, start.state, _CYCLES * start.period, dt_out=start.period / _SAMPLES_PER_PERIOD,
                   rtol=rtol)
    if run.slack is not None:
        wire, t = run.slack
        raise RigError(rig.source, "amplitude", f"{amplitude:g} rad: wire[{wire}] goes slack at t = {t:.4g} s")
    turned = Rotation.from_matrix(run.rotation @ start.rest_rotation.T).as_rotvec() @ start.axis_world
    return crossing_period(run.t, turned).value


def amplitude_ratio(rig: Rig, axis, amplitude: float, rest: Rest | None = None) -> float:
    """T(A) / T(0) of the mode associated with ``axis``: :func:`simulated_period` over
    :func:`linear_period`."""
    return simulated_period(rig, axis, amplitude, rest) / linear_period(rig, axis, rest)


def identify(rig: Rig, axis, period: float, amplitude: float = 0.0, rest: Rest | None = None) -> Identified:
    """The moment about ``axis`` from a ``period`` measured at rotation ``amplitude`` (rad; 0: small).

    With an amplitude, the fixed point J = invert(T / ratio(J)) is iterated (:func:`amplitude_ratio`
    at the current J); it contracts by ~A^2 per pass.
    """
    p = pencil(rig, axis, rest)
    result = invert_period(rig, axis, period, rest, p)
    if amplitude == 0.0:
        return result
    step = np.inf
    for _ in range(AMPLITUDE_PASSES):
        ratio = amplitude_ratio(result.rig, axis, amplitude, rest)
        new = invert_period(rig, axis, period / ratio, rest, p)
        previous, step = step, abs(new.moment / result.moment - 1.0)
        result = replace(new, amplitude_ratio=ratio)
        if settled(step, previous):
            return result
    raise RigError(rig.source, "amplitude", f"{amplitude:g} rad: the amplitude correction did not converge")


def settled(step: float, previous: float) -> bool:
    """Whether an amplitude fixed point has settled, from its last two relative steps (``previous``
    infinite on the first pass): the error left, ~step k / (1 - k) with k = step / previous, is under
    :data:`AMPLITUDE_RTOL`, or the steps stopped shrinking at the simulated ratio's noise floor."""
    if step < AMPLITUDE_RTOL or not np.isfinite(previous):
        return step < AMPLITUDE_RTOL
    k = step / previous
    return (k < 0.5 and step * k / (1.0 - k) < AMPLITUDE_RTOL) or (k >= 0.5 and step < _RATIO_NOISE)


def amplitude_coefficient(rig: Rig, axis, rest: Rest | None = None, amplitude: float = 0.05) -> float:
    """c in T(A) = T(0) (1 + c A^2 + O(A^4)) (1/rad^2), from :func:`amplitude_ratio` at ``amplitude``
    (0.05 rad: the O(A^4) term changes c by ~A^2 of itself, the crossing-time error ~1e-9 / A^2)."""
    return (amplitude_ratio(rig, axis, amplitude, rest) - 1.0) / amplitude**2


def _fmt(e: np.ndarray) -> str:
    names = [n for n, a in AXES.items() if np.allclose(a, e)]
    return names[0] if names else "[" + ", ".join(f"{x:.6g}" for x in e) + "]"
