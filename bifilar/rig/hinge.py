"""The hinge rig file: a body turning about one fixed axis, on a knife edge (a compound pendulum) or on a
vertical torsion rod, read from TOML and checked before any physics runs.

Labs measure parts that hang badly from wires (a bicycle wheel, a fork) on two 1-DOF rigs:

* ``[pivot]``: the body hangs on a horizontal knife edge or rod (a compound pendulum) and swings about
  it. ``point`` is a point of the axis and ``axis`` its direction, both in the body frame (m); the axis
  must miss the COM, else gravity has no arm and the body does not swing.
* ``[torsion]``: the body hangs from the lower end of a vertical rod whose axis passes through the COM,
  and twists about it; ``axis`` is the rod's direction in the body frame, ``stiffness`` the rod's
  torsional stiffness (N m/rad), left out for a calibration rod whose inertia is known and whose
  stiffness is what is measured.

Units are SI and angles radians. ``com`` and the inertia (about the COM, body axes) are as in a wire rig
(:mod:`bifilar.rig.file`); the moment about the hinge axis may be ``nan`` (unknown, the one measured)
when the axis is a body axis. A calibration rod's body may be given by its shape instead,
``cylinder = { radius, length, inner_radius }`` with its own axis along body x (:func:`cylinder_inertia`).
The world frame has z up and gravity along -z; the motion is in :mod:`bifilar.motion.hinge`.

Every problem is a one-line :class:`bifilar.rig.checks.RigError` naming the file and the field.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from bifilar.rig.checks import (
    RigError,
    inertia_tensor,
    no_unknown,
    non_negative,
    positive,
    required,
    rig_name,
    table,
    vector3,
    within,
)
from bifilar.rig.ranges import MAX_RELATIVE_SIGMA, MAX_PERIOD_SIGMA, MIN_RELATIVE_SIGMA, RANGES

__all__ = ["HingeRig", "HingeUncertainty", "cylinder_inertia", "hinge_from_dict", "HINGE_TABLES"]

HINGE_TABLES = ("pivot", "torsion")  # a rig file with one of these is a hinge rig
MIN_ARM = 1e-6  # x the body's size: a pivot axis nearer the COM than this has no restoring moment
_AXIS_TOL = 1e-12  # an axis whose other components are below this (relative) is a body axis


@dataclass(frozen=True)
class HingeUncertainty:
    """Standard deviations of the measured quantities of a hinge rig; zero where not stated: ``mass``
    (kg), ``com`` and ``point`` (m, of each coordinate, body frame), ``stiffness`` (N m/rad), ``period``
    (s, of one timed period), ``radius`` and ``length`` (m, of a ``body.cylinder``'s radii, each, and
    length)."""

    mass: float = 0.0
    com: float = 0.0
    point: float = 0.0
    stiffness: float = 0.0
    period: float = 0.0
    radius: float = 0.0
    length: float = 0.0


@dataclass(frozen=True)
class HingeRig:
    """A rigid body turning about one fixed axis (see the module docstring for ``kind``)."""

    name: str
    mass: float  # kg
    inertia: np.ndarray  # 3x3 about the COM, body axes, kg m^2; the axis's entry may be nan (unknown)
    kind: str  # "pivot" (compound pendulum) or "torsion" (vertical rod through the COM)
    axis: np.ndarray  # unit vector, body frame
    point: np.ndarray | None = None  # pivot: a point of the axis, body frame, m; torsion: None
    stiffness: float | None = None  # torsion: N m/rad; None for a calibration rod (and for a pivot)
    com: np.ndarray = field(default_factory=lambda: np.zeros(3))  # body frame, m
    gravity: float = 9.81  # m/s^2, along world -z
    uncertainty: HingeUncertainty = field(default_factory=HingeUncertainty)
    source: str = "<memory>"
    cylinder: tuple[float, float, float] | None = None  # body.cylinder's radius, length, inner radius (m)

    @property
    def arm(self) -> float:
        """d (m): the distance from the COM to the axis, perpendicular to it; 0 for a torsion rig."""
        if self.point is None:
            return 0.0
        r = self.com - self.point
        return float(np.linalg.norm(r - (r @ self.axis) * self.axis))

    @property
    def size(self) -> float:
        """The body's size (m): its largest radius of gyration about the COM, from the known moments."""
        return body_size(self.inertia, self.mass)


def body_size(inertia: np.ndarray, mass: float) -> float:
    """sqrt(largest principal moment / mass) (m) over the rows and columns without a nan."""
    known = [i for i in range(3) if not np.isnan(inertia[i, i])]
    return float(math.sqrt(np.linalg.eigvalsh(inertia[np.ix_(known, known)])[-1] / mass))


def cylinder_inertia(mass: float, radius: float, length: float, inner_radius: float = 0.0) -> np.ndarray:
    """The 3x3 inertia (kg m^2) about the COM of a uniform solid (``inner_radius`` 0) or hollow cylinder,
    its own axis along body x: I_xx = m (r^2 + ri^2) / 2, I_yy = I_zz = m (3 (r^2 + ri^2) + L^2) / 12.

    Derivation (any mechanics text, e.g. Meriam & Kraige, Dynamics, table D/4): a thin disc of radius a
    has m a^2 / 2 about its axis and m a^2 / 4 about a diameter; a ring between ri and r integrates
    rho 2 pi s ds to m (r^2 + ri^2) / 2 and half that about a diameter; stacking rings along x adds,
    by the parallel axis theorem, the integral of x^2 dm over -L/2 .. L/2, m L^2 / 12.
    """
    r2 = radius**2 + inner_radius**2
    return np.diag([0.5 * mass * r2, mass * (3.0 * r2 + length**2) / 12.0, mass * (3.0 * r2 + length**2) / 12.0])


_TOP_KEYS = {"name", "gravity", "body", "pivot", "torsion", "uncertainty"}
_BODY_KEYS = {"mass", "com", "inertia", "cylinder"}
_CYLINDER_KEYS = {"radius", "length", "inner_radius"}
_KIND_KEYS = {"pivot": {"point", "axis"}, "torsion": {"axis", "stiffness"}}
_UNCERTAINTY_KEYS = set(HingeUncertainty.__dataclass_fields__)


def hinge_from_dict(data: dict, source: str = "<memory>", default_name: str = "rig") -> HingeRig:
    """Build a checked :class:`HingeRig` from a parsed TOML table with a ``[pivot]`` or ``[torsion]``
    table (the module docstring); :func:`bifilar.rig.file.rig_from_dict` sends such tables here."""
    if "wire" in data:
        kind = "pivot" if "pivot" in data else "torsion"
        raise RigError(source, kind, "a rig hangs from [[wire]] tables or turns about a hinge, not both")
    if "pivot" in data and "torsion" in data:
        raise RigError(source, "torsion", "give [pivot] (a compound pendulum) or [torsion] (a rod), not both")
    no_unknown(data, _TOP_KEYS, source, "")
    name = rig_name(data, source, default_name)
    gravity = positive(data.get("gravity", 9.81), source, "gravity")
    kind = "pivot" if "pivot" in data else "torsion"
    hinge = table(data, kind, source, mandatory=True)
    no_unknown(hinge, _KIND_KEYS[kind], source, kind + ".")
    axis = _unit(required(hinge, "axis", source, kind + "."), source, kind + ".axis")
    point = vector3(required(hinge, "point", source, "pivot."), source, "pivot.point") if kind == "pivot" else None
    stiffness = None
    if "stiffness" in hinge:
        stiffness = positive(hinge["stiffness"], source, "torsion.stiffness")
        low, high, unit, why = RANGES["torsion.stiffness"]
        within(stiffness, low, high, source, "torsion.stiffness", unit, why)

    body = table(data, "body", source, mandatory=True)
    no_unknown(body, _BODY_KEYS, source, "body.")
    mass = positive(required(body, "mass", source, "body."), source, "body.mass")
    com = vector3(body.get("com", [0.0, 0.0, 0.0]), source, "body.com")
    inertia, cylinder = _body_inertia(body, mass, axis, source)

    unc_raw = table(data, "uncertainty", source, mandatory=False)
    no_unknown(unc_raw, _UNCERTAINTY_KEYS, source, "uncertainty.")
    unc = HingeUncertainty(**{k: non_negative(v, source, f"uncertainty.{k}") for k, v in unc_raw.items()})
    rig = HingeRig(name=name, mass=mass, inertia=inertia, kind=kind, axis=axis, point=point, stiffness=stiffness,
                   com=com, gravity=gravity, uncertainty=unc, source=source, cylinder=cylinder)
    _check_ranges(rig)
    return rig


def _unit(value, source: str, name: str) -> np.ndarray:
    """A direction (three numbers, any non-zero length) normalised to unit length."""
    v = vector3(value, source, name)
    norm = float(np.linalg.norm(v))
    if not norm > 1e-300 or not math.isfinite(norm):
        raise RigError(source, name, "must be a non-zero direction (its length cannot be normalised to 1)")
    return v / norm


def _body_inertia(body: dict, mass: float, axis: np.ndarray,
                  source: str) -> tuple[np.ndarray, tuple[float, float, float] | None]:
    """``body.inertia`` (the axis's diagonal entry may be nan when the axis is a body axis) or the
    inertia of ``body.cylinder``, with the cylinder's (radius, length, inner radius) or None."""
    if "cylinder" in body:
        if "inertia" in body:
            raise RigError(source, "body.cylinder", "give inertia or cylinder, not both")
        shape = table(body, "cylinder", source, mandatory=True)
        no_unknown(shape, _CYLINDER_KEYS, source, "body.cylinder.")
        radius = positive(required(shape, "radius", source, "body.cylinder."), source, "body.cylinder.radius")
        length = positive(required(shape, "length", source, "body.cylinder."), source, "body.cylinder.length")
        inner = non_negative(shape.get("inner_radius", 0.0), source, "body.cylinder.inner_radius")
        if inner >= radius:
            raise RigError(source, "body.cylinder.inner_radius", f"{inner:g} m is not smaller than radius {radius:g} m")
        return cylinder_inertia(mass, radius, length, inner), (radius, length, inner)
    main = int(np.argmax(np.abs(axis)))
    free = main if np.all(np.abs(np.delete(axis, main)) <= _AXIS_TOL) else None  # nan only about a body axis
    return inertia_tensor(required(body, "inertia", source, "body."), source, free), None


def _check_ranges(rig: HingeRig) -> None:
    """The absolute ranges of :data:`bifilar.rig.ranges.RANGES`, the pivot's arm, and the sigmas."""
    src = rig.source
    for key, value in (("gravity", rig.gravity), ("body.mass", rig.mass)):
        low, high, unit, why = RANGES[key]
        within(value, low, high, src, key, unit, why)
    low, high, unit, why = RANGES["coordinates"]
    points = (("body.com", rig.com),) + ((("pivot.point", rig.point),) if rig.point is not None else ())
    for name, vec in points:
        for k, x in enumerate(vec):
            within(float(x), low, high, src, f"{name}[{k}]", unit, why)
    size = rig.size
    if rig.kind == "pivot" and rig.arm < MIN_ARM * size:
        raise RigError(src, "pivot.point", f"the axis passes {rig.arm:.3g} m from the COM (less than {MIN_ARM:g} of "
                       f"the body's size {size:.3g} m): gravity has no arm, the body would not swing")
    unc = rig.uncertainty
    cylinder = rig.cylinder or (None, None, None)
    scales = {"mass": (rig.mass, "kg"), "com": (size, "m"), "point": (size, "m"),
              "stiffness": (rig.stiffness, "N m/rad"), "radius": (cylinder[0], "m"), "length": (cylinder[1], "m")}
    for name, (scale, unit) in scales.items():
        sigma = getattr(unc, name)
        if not sigma:
            continue
        if scale is None:
            raise RigError(src, f"uncertainty.{name}", "given, but the rig has no "
                           + ("torsion.stiffness" if name == "stiffness" else "body.cylinder"))
        if name == "point" and rig.point is None:
            raise RigError(src, "uncertainty.point", "given, but a torsion rig has no pivot.point")
        within(sigma, MIN_RELATIVE_SIGMA * scale, MAX_RELATIVE_SIGMA * scale, src, f"uncertainty.{name}", unit,
               f"0 or {MIN_RELATIVE_SIGMA:g} .. {MAX_RELATIVE_SIGMA:g} of the quantity, {scale:.6g} {unit}")
    if unc.period:
        within(unc.period, 1e-12, MAX_PERIOD_SIGMA, src, "uncertainty.period", "s", "0 or 1e-12 .. 100 s")
