"""Moments and rod stiffnesses measured on a hinge rig (:mod:`bifilar.rig.hinge`) from a timed period.

A period T (s) timed at amplitude A (rad) is first taken to zero amplitude by the exact law of
:mod:`bifilar.motion.hinge`, T0 = T / R(A) with R(A) = T(A) / T0 = (2 / pi) K(sin^2(A / 2)) for a compound
pendulum and 1 for a torsion rod (R depends on A alone, so T0 carries no rig quantity but T). Then, from
T0 = 2 pi sqrt(J / restoring):

* compound pendulum (:func:`moment_from_period`): J_p = m g d T0^2 / (4 pi^2), and about the COM axis
  parallel to the hinge J = J_p - m d^2 = m g d T0^2 / (4 pi^2) - m d^2;
* torsion rod (:func:`moment_from_period`): J = k T0^2 / (4 pi^2), about the rod's axis through the COM;
* calibration (:func:`stiffness_from_period`): a body of known moment J on the rod gives k = 4 pi^2 J / T0^2.

The standard deviation is the linear propagation of the rig's :class:`bifilar.rig.hinge.HingeUncertainty`,
each input independent and normal: mass, each body coordinate of the COM and of the pivot point (they move
d), the rod's stiffness and the period. With c = g T0^2 / (4 pi^2) and n the unit vector from the axis to
the COM, perpendicular to it (body frame), the partial derivatives are, analytically:

* pivot: dJ/dm = c d - d^2, dJ/dd = m c - 2 m d, dJ/dcom = (dJ/dd) n, dJ/dpoint = -(dJ/dd) n,
  dJ/dT = 2 m g d T0 / (4 pi^2) / R(A);
* torsion: dJ/dk = T0^2 / (4 pi^2), dJ/dT = 2 k T0 / (4 pi^2) / R(A);
* calibration: dk/dm = k / m (the rod's moment is its mass times a known squared length: the tensor of
  the file, or a cylinder's, scales with the mass at fixed shape), dk/dT = -2 k / T0 / R(A), and for a
  ``body.cylinder`` (:func:`bifilar.rig.hinge.cylinder_inertia`, its axis body x) dk/dr =
  (4 pi^2 / T0^2) e^T (dI/dr) e with dI/dr = m r diag(1, 1/2, 1/2), the same for the inner radius, and
  dk/dL = (4 pi^2 / T0^2) e^T (dI/dL) e with dI/dL = m L diag(0, 1/6, 1/6), e the rod's axis.

var = sum_i (dJ/dx_i sigma_i)^2 over every coordinate of every input; the budget gives each group's share
of the variance (0 everywhere when no sigma is stated). Gravity, the axis's direction and the other entries
of the inertia tensor are taken as exact.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from bifilar.identification.records.law import AmplitudeLaw
from bifilar.motion.hinge import period_ratio
from bifilar.rig.checks import RigError, positive
from bifilar.rig.hinge import HingeRig

__all__ = ["HingeMoment", "HingeStiffness", "law_for_hinge", "moment_from_period", "propagate",
           "stiffness_from_period"]

_GROUPS = ("mass", "com", "point", "stiffness", "period", "radius", "length")


def law_for_hinge(rig: HingeRig) -> AmplitudeLaw:
    """The amplitude law of a hinge rig for the record fit (:mod:`bifilar.identification.records.law`):
    the compound pendulum's theta'' = -omega^2 sin(theta) is the ``exact`` law with rho = lam = 0 (then
    u = sin(theta), the kinetic term 1); a torsion rod's is ``linear``."""
    return AmplitudeLaw("exact", rho=0.0, lam=0.0) if rig.kind == "pivot" else AmplitudeLaw()


@dataclass(frozen=True)
class HingeMoment:
    """A moment (kg m^2) about the COM axis parallel to the hinge axis, identified from a period.

    ``gradient``: the partial derivatives of the moment by each input group (module docstring; ``com``
    and ``point`` as body-frame 3-vectors, kg m; the others scalars); ``budget``: group -> share of the
    variance; ``sensitivity``: d ln T / d ln J, J / (2 J_p) for a pivot (J_p = J + m d^2), 1/2 for a rod."""

    rig: str
    kind: str
    moment: float
    std: float
    period: float  # s, as timed
    amplitude: float  # rad
    period0: float  # s, at zero amplitude
    gradient: dict
    budget: dict
    sensitivity: float = 0.5

    def as_dict(self) -> dict:
        return {"rig": self.rig, "kind": self.kind, "moment": self.moment, "std": self.std, "period": self.period,
                "amplitude": self.amplitude, "period0": self.period0, "gradient": _plain(self.gradient),
                "budget": dict(self.budget), "sensitivity": self.sensitivity}


@dataclass(frozen=True)
class HingeStiffness:
    """A torsion rod's stiffness (N m/rad) from the period of a body of known moment ``moment`` (kg m^2)."""

    rig: str
    stiffness: float
    std: float
    moment: float
    period: float  # s, as timed
    amplitude: float  # rad
    period0: float  # s
    gradient: dict
    budget: dict

    def as_dict(self) -> dict:
        return {"rig": self.rig, "stiffness": self.stiffness, "std": self.std, "moment": self.moment,
                "period": self.period, "amplitude": self.amplitude, "period0": self.period0,
                "gradient": _plain(self.gradient), "budget": dict(self.budget)}


def moment_from_period(rig: HingeRig, period: float, amplitude: float = 0.0) -> HingeMoment:
    """The moment about the COM axis parallel to the hinge axis from ``period`` (s) timed at ``amplitude``
    (rad), with its propagated standard deviation (module docstring)."""
    period = positive(period, rig.source, "period")
    ratio = period_ratio(rig.kind, amplitude, rig.source)
    t0 = period / ratio
    four_pi2 = 4.0 * math.pi**2
    zero = np.zeros(3)
    if rig.kind == "pivot":
        m, d = rig.mass, rig.arm
        c = rig.gravity * t0**2 / four_pi2
        moment = m * c * d - m * d**2
        if not moment > 0.0:
            shortest = 2.0 * math.pi * math.sqrt(d / rig.gravity) * ratio
            raise RigError(rig.source, "period", f"{period:.9g} s is not longer than {shortest:.9g} s, the period of "
                           f"a point mass {d:.6g} m below the pivot at this amplitude: no body gives it")
        sensitivity = moment / (2.0 * (moment + m * d**2))
        r = rig.com - rig.point
        n = (r - (r @ rig.axis) * rig.axis) / d
        by_d = m * c - 2.0 * m * d
        gradient = {"mass": c * d - d**2, "com": by_d * n, "point": -by_d * n, "stiffness": 0.0,
                    "period": 2.0 * m * rig.gravity * d * t0 / four_pi2 / ratio}
    else:
        if rig.stiffness is None:
            raise RigError(rig.source, "torsion.stiffness", "missing: a moment needs the rod's stiffness "
                           "(calibrate the rod with a body of known inertia first)")
        k = rig.stiffness
        moment = k * t0**2 / four_pi2
        gradient = {"mass": 0.0, "com": zero, "point": zero, "stiffness": t0**2 / four_pi2,
                    "period": 2.0 * k * t0 / four_pi2 / ratio}
        sensitivity = 0.5
    std, budget = propagate(rig, gradient)
    return HingeMoment(rig.name, rig.kind, float(moment), std, period, float(amplitude), t0, gradient, budget,
                       float(sensitivity))


def stiffness_from_period(rig: HingeRig, period: float, amplitude: float = 0.0) -> HingeStiffness:
    """The stiffness of a torsion rod carrying a body of known moment about the rod (a calibration rod,
    ``rig`` a torsion rig) from ``period`` (s) timed at ``amplitude`` (rad): k = 4 pi^2 J / T0^2, with its
    standard deviation from the mass and the period (module docstring)."""
    if rig.kind != "torsion":
        raise RigError(rig.source, "pivot", "a stiffness is calibrated on a torsion rig ([torsion]), not a pivot")
    moment = float(rig.axis @ rig.inertia @ rig.axis)
    if not math.isfinite(moment):
        raise RigError(rig.source, "body.inertia", "the moment about the rod is unknown (nan): calibrating the "
                       "rod needs a body of known inertia")
    period = positive(period, rig.source, "period")
    ratio = period_ratio(rig.kind, amplitude, rig.source)
    t0 = period / ratio
    k = 4.0 * math.pi**2 * moment / t0**2
    zero = np.zeros(3)
    gradient = {"mass": k / rig.mass, "com": zero, "point": zero, "stiffness": 0.0, "period": -2.0 * k / t0 / ratio,
                **_shape_gradient(rig, 4.0 * math.pi**2 / t0**2)}
    std, budget = propagate(rig, gradient)
    return HingeStiffness(rig.name, float(k), std, moment, period, float(amplitude), t0, gradient, budget)


def propagate(rig: HingeRig, gradient: dict) -> tuple[float, dict]:
    """The standard deviation and the variance budget (group -> share) of ``gradient`` times the rig's
    sigmas, each coordinate of a vector group independent with the group's sigma."""
    parts = {g: float(np.sum(np.square(gradient.get(g, 0.0)))) * getattr(rig.uncertainty, g) ** 2 for g in _GROUPS}
    total = sum(parts.values())
    budget = {g: (v / total if total > 0.0 else 0.0) for g, v in parts.items()}
    return math.sqrt(total), budget


def _shape_gradient(rig: HingeRig, per_moment: float) -> dict:
    """d(quantity)/d(radius: outer, inner) and d/d(length) of a ``body.cylinder`` rig, for a quantity
    ``per_moment`` times the moment about the rod (module docstring); empty without a cylinder."""
    if rig.cylinder is None:
        return {}
    radius, length, inner = rig.cylinder
    e2 = rig.axis**2  # e^T diag(a, b, c) e
    per_r2 = float(e2 @ np.array([1.0, 0.5, 0.5])) * rig.mass * per_moment  # d/dr = this x r
    return {"radius": np.array([per_r2 * radius, per_r2 * inner]),
            "length": float(e2 @ np.array([0.0, 1.0, 1.0])) * rig.mass * length / 6.0 * per_moment}


def _plain(gradient: dict) -> dict:
    """The gradient as JSON-ready floats and lists."""
    return {g: (np.asarray(v, dtype=float).tolist() if np.ndim(v) else float(v)) for g, v in gradient.items()}
