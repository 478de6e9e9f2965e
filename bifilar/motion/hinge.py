"""The exact motion of a hinge rig (:class:`bifilar.rig.hinge.HingeRig`): one angle about one fixed axis.

Let e be the unit axis and theta the rotation about it from rest (body frame; world z up, gravity along
-z). The body turns rigidly about a fixed line, so its kinetic energy is J theta'^2 / 2 with J the moment
about that line.

Compound pendulum (``pivot``): the axis is horizontal and passes through the point p; r = c - p from it to
the COM c. The inertia about p is I_p = I + m (|r|^2 1 - r r^T) (parallel axis theorem), so

    J_p = e^T I_p e = e^T I e + m (|r|^2 - (r . e)^2) = e^T I e + m d^2,

d the COM's perpendicular distance from the axis. At rest the COM hangs straight below the axis; turned by
theta it has risen by d (1 - cos theta), so V = m g d (1 - cos theta) and Lagrange's equation is

    J_p theta'' = -m g d sin(theta),

the simple pendulum of length J_p / (m d). Its period at amplitude A (|A| < pi) is exact in closed form,
T(A) = 4 sqrt(J_p / (m g d)) K(sin^2(A / 2)), K the complete elliptic integral of the first kind as a
function of the parameter m = k^2 (scipy.special.ellipk's convention); T(0) = 2 pi sqrt(J_p / (m g d)).

Torsion pendulum (``torsion``): the rod is vertical and its axis passes through the COM, so turning about
it moves the COM nowhere and gravity does no work; the rod's twist stores k theta^2 / 2, so

    J theta'' = -k theta,   J = e^T I e,

linear at every amplitude (isochronous, T = 2 pi sqrt(J / k)) as long as the rod twists elastically.

An unknown moment (nan in the rig's tensor) gives nan here; :mod:`bifilar.identification.hinge` inverts
these periods into the moment.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import solve_ivp
from scipy.special import ellipk

from bifilar.motion.simulate import output_grid
from bifilar.rig.checks import RigError
from bifilar.rig.hinge import HingeRig

__all__ = ["moment_about_axis", "restoring", "linear_period", "period_ratio", "period_at", "simulate"]


def moment_about_axis(rig: HingeRig) -> float:
    """J (kg m^2): the moment about the hinge axis, J_p = e^T I e + m d^2 for a pivot, e^T I e for a torsion
    rod (module docstring)."""
    return float(rig.axis @ rig.inertia @ rig.axis) + rig.mass * rig.arm**2


def restoring(rig: HingeRig) -> float:
    """The restoring moment per unit angle at small angles (N m/rad): m g d for a pivot, k for a rod.
    A calibration rod without a stated stiffness has none to give: :class:`RigError`."""
    if rig.kind == "pivot":
        return rig.mass * rig.gravity * rig.arm
    if rig.stiffness is None:
        raise RigError(rig.source, "torsion.stiffness", "missing: the rod's stiffness is needed for its motion "
                       "(calibrate it with a rod of known inertia)")
    return rig.stiffness


def linear_period(rig: HingeRig) -> float:
    """T0 (s), the small-amplitude period: 2 pi sqrt(J_p / (m g d)) or 2 pi sqrt(J / k)."""
    return 2.0 * math.pi * math.sqrt(moment_about_axis(rig) / restoring(rig))


def period_ratio(kind: str, amplitude: float, source: str = "<memory>") -> float:
    """T(A) / T0 (dimensionless) at amplitude A (rad): (2 / pi) K(sin^2(A / 2)) for a pivot, 1 for a
    torsion rod. It depends on A alone, not on the body: the exact law is the simple pendulum's. An
    amplitude of pi or more (over the top) is a :class:`RigError` on ``source``."""
    a = abs(float(amplitude))
    if kind == "torsion":
        return 1.0
    if not a < math.pi:
        raise RigError(source, "amplitude", f"{a:.6g} rad: a compound pendulum swings below pi (it goes over the top)")
    return 2.0 / math.pi * float(ellipk(math.sin(0.5 * a) ** 2))


def period_at(rig: HingeRig, amplitude: float) -> float:
    """T(A) (s), the exact period at amplitude A (rad): 4 sqrt(J_p / (m g d)) K(sin^2(A / 2)) for a pivot,
    the linear period for a torsion rod (module docstring)."""
    return linear_period(rig) * period_ratio(rig.kind, amplitude, rig.source)


def simulate(rig: HingeRig, amplitude: float, duration: float, dt_out: float,
             rtol: float = 1e-10) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Integrate the equation of motion from rest at theta = ``amplitude`` (rad) for ``duration`` (s) by
    scipy's DOP853 at ``rtol`` (atol 1e-3 of it in rad and rad/s, the angle being O(1)); returns the times
    (s, every ``dt_out`` up to ``duration``: :func:`bifilar.motion.simulate.output_grid`, the grid of every
    engine), the angle (rad) and its rate (rad/s), from the dense output."""
    omega2 = restoring(rig) / moment_about_axis(rig)  # (rad/s)^2
    if rig.kind == "pivot":
        def rhs(_t, y):
            return (y[1], -omega2 * math.sin(y[0]))
    else:
        def rhs(_t, y):
            return (y[1], -omega2 * y[0])
    times = output_grid(duration, dt_out)
    sol = solve_ivp(rhs, (0.0, times[-1]), [float(amplitude), 0.0], method="DOP853", rtol=rtol,
                    atol=1e-3 * rtol, t_eval=times)
    return sol.t, sol.y[0], sol.y[1]
