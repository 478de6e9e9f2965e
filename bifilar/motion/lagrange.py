"""One-degree-of-freedom torsion models of a symmetric bifilar rig (seed 000, ch. 5.2 and 6.2), and of
a symmetric platform on N wires, which obeys the same law (:func:`from_rig`).

The rig: two wires of length ``l`` from hooks ``b`` apart to attachments ``D`` apart, the attachments
level, the centre of mass on the vertical through their midpoint and the vertical a principal axis of
the body. Rotated by ``theta`` about that vertical, the body stays level and on the axis (the motion is
invariant under the half turn about the vertical), so it has one degree of freedom and rises by
``z(theta)``. Each attachment's horizontal distance to its hook is r, with

    r^2 = (b^2 + D^2)/4 - (b D / 2) cos(theta) = r0^2 + b D sin^2(theta/2),   r0 = (b - D)/2,

(law of cosines in the horizontal plane; r0 > 0 for wires splayed outwards), so that

    z(theta) = H - sqrt(H^2 - b D sin^2(theta/2)),   H = sqrt(l^2 - r0^2).

Parallel wires (b = D, l = h) give the thesis's (5.2.7). The models, all conservative:

* :func:`printed_acceleration` - (5.2.13) as printed: L = I theta'^2/2 - m g z, parallel wires only.
* :func:`dropped_acceleration` - the same Lagrangian for any spacing: the adjusted model of ch. 6.2.
  Both drop the vertical kinetic energy m z'^2/2 (5.2.11).
* :func:`exact_acceleration` - keeps it: L = (I + m z'(theta)^2) theta'^2/2 - m g z. Exact for the
  rigid body on inextensible taut wires.
* :func:`linear_acceleration` - (5.2.15), the small-angle limit of all three.

:func:`period` gives the period at an amplitude by quadrature of the energy integral;
:func:`linear_period` and :func:`inertia_from_period` are (5.2.17-18) for any spacing.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import quad

from bifilar.rig import Rig, RigError

# Relative tolerance of the period quadrature. The integrand is analytic on the closed interval
# (see :func:`period`), so adaptive Gauss-Kronrod meets it in a few dozen evaluations.
_QUAD_RTOL = 1e-13
# Relative mismatch below which two measured rig quantities count as equal in :func:`from_rig`.
_SYMMETRY_RTOL = 1e-9


@dataclass(frozen=True)
class TorsionRig:
    """A symmetric two-wire rig for torsion about the vertical through its centre of mass (SI)."""

    mass: float  # kg
    inertia: float  # about the vertical through the COM, kg m^2
    length: float  # l, each wire, m
    hook_span: float  # b, between the hooks, m
    attach_span: float  # D, between the attachments, m
    gravity: float = 9.81  # m/s^2

    def __post_init__(self):
        for name in ("mass", "inertia", "length", "hook_span", "attach_span", "gravity"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0.0):
                raise RigError("<TorsionRig>", name, f"must be positive and finite, got {value!r}")
        if abs(self.offset) >= self.length:
            raise RigError(
                "<TorsionRig>",
                "length",
                f"{self.length:g} m cannot bridge the horizontal offset |b - D|/2 = {abs(self.offset):g} m",
            )

    @classmethod
    def parallel(cls, mass: float, inertia: float, length: float, span: float, gravity: float = 9.81):
        """The rig of ch. 5.2: parallel wires of length h = ``length``, D = ``span`` apart."""
        return cls(mass, inertia, length, span, span, gravity)

    @property
    def offset(self) -> float:
        """r0 = (b - D)/2, horizontal hook-to-attachment distance at rest (m; > 0 splayed outwards)."""
        return 0.5 * (self.hook_span - self.attach_span)

    @property
    def height(self) -> float:
        """H, height of the hooks above the attachments at rest (m)."""
        return math.sqrt(self.length**2 - self.offset**2)

    @property
    def splay(self) -> float:
        """phi0 of ch. 6.2, the wires' angle to the vertical at rest (rad; > 0 splayed outwards)."""
        return math.asin(self.offset / self.length)

    @property
    def max_amplitude(self) -> float:
        """Largest rotation the wires can reach (rad): pi, or less where they would turn horizontal."""
        reach = self.height**2 / (self.hook_span * self.attach_span)
        return math.pi if reach >= 1.0 else 2.0 * math.asin(math.sqrt(reach))


def from_rig(rig: Rig) -> TorsionRig:
    """The torsion model of a rig file, which must be symmetric as the module docstring says.

    The rest pose is taken to be the body frame translated (as in ``models/rigs/plate.toml``): the
    attachments level in the body frame, the hooks level in the world. Two wires: the two spans
    parallel. Any number N >= 2: every anchor at one radius R_a from the anchors' centroid, every
    attachment at one radius R_b from theirs, each anchor in the direction of its attachment; each
    attachment's horizontal distance to its hook is then r^2 = (R_a - R_b)^2 + 4 R_a R_b sin^2(theta/2),
    the module's law with b = 2 R_a and D = 2 R_b. Turned about the vertical the body stays level and
    on the axis: the static tensions balance the weight with no horizontal resultant (the COM on the
    axis: sum t_i e_i = 0 for the unit offsets e_i), and every wire keeps the same inclination, so the
    tensions stay in proportion and their horizontal parts still cancel (N = 2: the half turn).
    """
    src = rig.source
    n = len(rig.wires)
    if n < 2:
        raise RigError(src, "wire", f"the torsion models need at least two wires, found {n}")
    w1 = rig.wires[0]
    anchors = np.array([w.anchor for w in rig.wires])
    attach = np.array([w.attach for w in rig.wires])
    for i, w in enumerate(rig.wires[1:], start=2):
        if not math.isclose(w.length, w1.length, rel_tol=_SYMMETRY_RTOL):
            raise RigError(src, f"wire[{i}].length", f"{w.length:g} m differs from wire[1].length {w1.length:g} m")
    hooks = anchors[:, :2] - anchors[:, :2].mean(axis=0)
    arms = attach[:, :2] - attach[:, :2].mean(axis=0)
    r_a, r_b = np.linalg.norm(hooks, axis=1), np.linalg.norm(arms, axis=1)
    for i in range(1, n):
        if abs(anchors[i, 2] - anchors[0, 2]) > _SYMMETRY_RTOL * r_a[0]:
            raise RigError(src, f"wire[{i + 1}].anchor", "not at the height of wire[1].anchor")
        if abs(attach[i, 2] - attach[0, 2]) > _SYMMETRY_RTOL * r_b[0]:
            raise RigError(src, f"wire[{i + 1}].attach", "not at the height of wire[1].attach (body frame)")
        if not math.isclose(r_a[i], r_a[0], rel_tol=_SYMMETRY_RTOL):
            raise RigError(src, f"wire[{i + 1}].anchor", f"{r_a[i]:g} m from the anchors' centroid, wire[1]'s "
                                                         f"{r_a[0]:g} m: not on one circle")
        if not math.isclose(r_b[i], r_b[0], rel_tol=_SYMMETRY_RTOL):
            raise RigError(src, f"wire[{i + 1}].attach", f"{r_b[i]:g} m from the attachments' centroid, wire[1]'s "
                                                         f"{r_b[0]:g} m: not on one circle")
    for i in range(n):
        if abs(hooks[i, 0] * arms[i, 1] - hooks[i, 1] * arms[i, 0]) > _SYMMETRY_RTOL * r_a[0] * r_b[0] or \
                hooks[i] @ arms[i] <= 0:
            raise RigError(src, "wire", f"wire[{i + 1}]'s anchor is not in the direction of its attachment from "
                                        "the centroids at rest (the spans are not parallel)")
    arm = rig.com[:2] - attach[:, :2].mean(axis=0)
    if math.hypot(arm[0], arm[1]) > _SYMMETRY_RTOL * r_b[0]:
        raise RigError(src, "body.com", "not on the vertical through the centroid of the attachments")
    inertia = rig.inertia
    if math.hypot(inertia[0, 2], inertia[1, 2]) > _SYMMETRY_RTOL * inertia[2, 2]:
        raise RigError(src, "body.inertia", "the vertical is not a principal axis: torsion would couple to swing")
    return TorsionRig(rig.mass, float(inertia[2, 2]), w1.length, float(2.0 * r_a[0]), float(2.0 * r_b[0]), rig.gravity)


def _reach(rig: TorsionRig, theta):
    """w = sqrt(H^2 - b D sin^2(theta/2)), the wires' vertical extent at rotation theta (m)."""
    return np.sqrt(rig.height**2 - rig.hook_span * rig.attach_span * np.sin(0.5 * theta) ** 2)


def lift(rig: TorsionRig, theta):
    """z(theta), rise of the body above its rest height (m)."""
    return rig.height - _reach(rig, theta)


def lift_slope(rig: TorsionRig, theta):
    """z'(theta) = b D sin(theta) / (4 w) (m/rad); (5.2.8) divided by theta' for parallel wires."""
    return rig.hook_span * rig.attach_span * np.sin(theta) / (4.0 * _reach(rig, theta))


def lift_curvature(rig: TorsionRig, theta):
    """z''(theta) = b D cos(theta) / (4 w) + z'^2 / w (m/rad^2), using w' = -z'."""
    return _slope_and_curvature(rig, theta)[1]


def _slope_and_curvature(rig: TorsionRig, theta):
    """(z'(theta), z''(theta)) of :func:`lift_slope` and :func:`lift_curvature`, the same arithmetic with w
    computed once: :func:`exact_acceleration` is a synthetic record's right-hand side, called ~10^4 times
    a record."""
    w = _reach(rig, theta)
    slope = rig.hook_span * rig.attach_span * np.sin(theta) / (4.0 * w)
    return slope, rig.hook_span * rig.attach_span * np.cos(theta) / (4.0 * w) + slope**2 / w


def stiffness(rig: TorsionRig) -> float:
    """Small-angle torsional stiffness m g z''(0) = m g b D / (4 H) (N m/rad)."""
    return rig.mass * rig.gravity * rig.hook_span * rig.attach_span / (4.0 * rig.height)


def printed_acceleration(rig: TorsionRig, theta, theta_dot):
    """theta'' of (5.2.13) as printed, for parallel wires (h = l, D = b); theta_dot does not enter."""
    if rig.hook_span != rig.attach_span:
        raise RigError("<TorsionRig>", "hook_span", "(5.2.13) is for parallel wires: hook_span must equal attach_span")
    m, g, i, d, h = rig.mass, rig.gravity, rig.inertia, rig.attach_span, rig.length
    return -(m * g * d**2 / (4.0 * h * i)) * np.sin(theta) / np.sqrt(1.0 - 0.5 * (d / h) ** 2 * (1.0 - np.cos(theta)))


def dropped_acceleration(rig: TorsionRig, theta, theta_dot):
    """theta'' = -m g z'(theta) / I: the adjusted model of ch. 6.2 (any spacing), without m z'^2/2."""
    return -rig.mass * rig.gravity * lift_slope(rig, theta) / rig.inertia


def exact_acceleration(rig: TorsionRig, theta, theta_dot):
    """theta'' of L = (I + m z'^2) theta'^2 / 2 - m g z, which keeps the vertical kinetic energy.

    Lagrange's equation: (I + m z'^2) theta'' + m z' z'' theta'^2 + m g z' = 0.
    """
    m = rig.mass
    slope, curv = _slope_and_curvature(rig, theta)
    return -m * slope * (curv * theta_dot**2 + rig.gravity) / (rig.inertia + m * slope**2)


def linear_acceleration(rig: TorsionRig, theta, theta_dot):
    """theta'' = -(k / I) theta, k = m g b D / (4 H): (5.2.15), which is m g D^2 / (4 h I) for b = D."""
    return -stiffness(rig) / rig.inertia * theta


def linear_period(rig: TorsionRig) -> float:
    """T0 = 2 pi sqrt(I / k) (s): (5.2.17) = 2 pi sqrt(4 h I / (m g D^2)) for parallel wires."""
    return 2.0 * math.pi * math.sqrt(rig.inertia / stiffness(rig))


def inertia_from_period(rig: TorsionRig, period: float) -> float:
    """I = k T^2 / (4 pi^2) (kg m^2): (5.2.18) = m g D^2 T^2 / (16 pi^2 h) for parallel wires.

    ``rig.inertia`` is not used: this is the inertia that gives ``period`` in the linear model.
    """
    return stiffness(rig) * period**2 / (4.0 * math.pi**2)


def period(rig: TorsionRig, amplitude: float, vertical_ke: bool = True) -> float:
    """Period (s) of the oscillation between -amplitude and +amplitude (rad), by quadrature.

    ``vertical_ke=False`` is the model of (5.2.13) and ch. 6.2, ``True`` the exact model. Energy
    conservation gives T = 4 int_0^a sqrt(J(theta) / (2 m g (z(a) - z(theta)))) dtheta with
    J = I (+ m z'^2). With theta = a cos(v) the end singularity cancels, and z(a) - z(theta) is
    evaluated without cancellation as b D sin((a+theta)/2) sin(a sin^2(v/2)) / (w(theta) + w(a)),
    since a - theta = 2 a sin^2(v/2); the integrand is then analytic on [0, pi/2].
    """
    a = float(amplitude)
    if not 0.0 < a < rig.max_amplitude:
        raise ValueError(f"amplitude must be in (0, {rig.max_amplitude:.6g}) rad, got {a!r}")
    m, bd = rig.mass, rig.hook_span * rig.attach_span
    w_a = _reach(rig, a)

    def integrand(v: float) -> float:
        theta = a * math.cos(v)
        drop = bd * math.sin(0.5 * (a + theta)) * math.sin(a * math.sin(0.5 * v) ** 2) / (_reach(rig, theta) + w_a)
        inertia = rig.inertia + (m * lift_slope(rig, theta) ** 2 if vertical_ke else 0.0)
        return a * math.sin(v) * math.sqrt(inertia / (2.0 * m * rig.gravity * drop))

    value, _ = quad(integrand, 0.0, 0.5 * math.pi, epsabs=0.0, epsrel=_QUAD_RTOL, limit=200)
    return 4.0 * value


def period_amplitude_coefficient(rig: TorsionRig, vertical_ke: bool = True) -> float:
    """s in T(a) = T0 (1 + s a^2 + O(a^4)) (1/rad^2), from the series of the energy integral.

    The potential is k (theta^2/2 + beta theta^4/4 + ...) with beta = -1/6 + b D / (8 H^2), and the
    inertia I (1 + eps theta^2 + ...) with eps = m (b D / (4 H))^2 / I when the vertical kinetic
    energy is kept; the quadrature then gives s = eps/4 - 3 beta/8.
    """
    bd, h = rig.hook_span * rig.attach_span, rig.height
    beta = -1.0 / 6.0 + bd / (8.0 * h**2)
    eps = rig.mass * (bd / (4.0 * h)) ** 2 / rig.inertia if vertical_ke else 0.0
    return 0.25 * eps - 0.375 * beta
