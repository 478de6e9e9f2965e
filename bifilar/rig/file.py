"""The rig file: a body hung from wires, read from TOML and checked before any physics runs.

Units are SI and angles radians. Vectors named ``anchor`` are in the world frame (z up, gravity along
-z); ``attach`` and ``com`` are in the body frame, whose origin and axes the file chooses freely; the
inertia tensor is about the centre of mass along the body axes. Wire 1 is the first ``[[wire]]`` in
the file, everywhere in this project. An optional ``[air]`` table describes the fluid around the body
and its aerodynamic shape (:mod:`bifilar.rig.air`, docs/air.md); without it the body is in a vacuum.

Every problem is raised as :class:`RigError`, which names the file, the field and what is wrong, so
that the command line can print it as one line and exit with status 2.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from bifilar.rig.air import Air, air_from_dict
from bifilar.rig.hinge import HINGE_TABLES, HingeRig, hinge_from_dict
from bifilar.rig.ranges import MAX_WIRES, check_ranges
from bifilar.rig.checks import (
    RigError,
    inertia_tensor,
    no_unknown,
    non_negative,
    positive,
    read_toml,
    required,
    rig_name,
    table,
    vector3,
)

__all__ = ["Rig", "RigError", "Uncertainty", "Wire", "load_rig", "rig_from_dict", "check_reachable", "check_hanging"]


@dataclass(frozen=True)
class Wire:
    """A wire from a ceiling ``anchor`` (world, m) to ``attach`` (body, m): inextensible of ``length`` (m)
    when ``axial_stiffness`` is None, else elastic: ``length`` is its unstretched length and it pulls
    with EA (d - L) / L at a distance d > L (``axial_stiffness`` = EA, N), never pushes. Massless unless
    ``linear_density`` (kg/m) is given (heavy wires, inextensible only: :mod:`bifilar.rig.heavy`)."""

    anchor: np.ndarray
    attach: np.ndarray
    length: float
    axial_stiffness: float | None = None

    @property
    def spring(self) -> float:
        """EA / L (N/m), the elastic wire's spring constant; inf for an inextensible wire."""
        return np.inf if self.axial_stiffness is None else self.axial_stiffness / self.length
    linear_density: float = 0.0  # kg/m; 0: massless


@dataclass(frozen=True)
class Uncertainty:
    """Standard deviations of measured rig quantities (m, kg, s); zero where not stated."""

    length: float = 0.0
    anchor: float = 0.0
    attach: float = 0.0
    mass: float = 0.0
    com: float = 0.0
    period: float = 0.0


@dataclass(frozen=True)
class Rig:
    """A rigid body hung from wires, with an optional initial disturbance from its rest pose."""

    name: str
    mass: float
    inertia: np.ndarray  # 3x3 about the COM, body axes, kg m^2
    wires: tuple[Wire, ...]
    com: np.ndarray = field(default_factory=lambda: np.zeros(3))  # body frame, m
    gravity: float = 9.81  # m/s^2, along world -z
    initial_rotation: np.ndarray = field(default_factory=lambda: np.zeros(3))  # rad, world frame
    initial_omega: np.ndarray = field(default_factory=lambda: np.zeros(3))  # rad/s, world frame
    uncertainty: Uncertainty = field(default_factory=Uncertainty)
    source: str = "<memory>"
    air: Air | None = None  # the optional [air] table (bifilar.rig.air); None: a vacuum

    @property
    def elastic(self) -> bool:
        """True when any wire has an ``axial_stiffness`` (then every wire must: :func:`rig_from_dict`)."""
        return any(w.axial_stiffness is not None for w in self.wires)

    def with_initial(self, rotation=(0.0, 0.0, 0.0), omega=(0.0, 0.0, 0.0)) -> "Rig":
        """The same rig with another initial disturbance (rotation vector and angular velocity)."""
        return replace(
            self,
            initial_rotation=np.asarray(rotation, dtype=float),
            initial_omega=np.asarray(omega, dtype=float),
        )


_TOP_KEYS = {"name", "gravity", "body", "wire", "initial", "uncertainty", "air"}
_BODY_KEYS = {"mass", "com", "inertia"}
_WIRE_KEYS = {"anchor", "attach", "length", "axial_stiffness", "linear_density"}
_INITIAL_KEYS = {"rotation", "omega"}
_UNCERTAINTY_KEYS = set(Uncertainty.__dataclass_fields__)


def load_rig(path: str | Path, free_moment: int | None = None, hinge: bool = False) -> Rig | HingeRig:
    """Read and check a rig file; raise :class:`RigError` on any problem.

    ``free_moment`` (0, 1, 2): the diagonal inertia entry being identified, which may be ``nan`` or
    any positive start value (:func:`bifilar.rig.checks.inertia_tensor`); a ``nan`` stays in the
    returned tensor for the caller to fill. ``hinge``: whether the caller takes a hinge rig
    (:mod:`bifilar.rig.hinge`, a file with ``[pivot]`` or ``[torsion]``); without it such a file is
    refused in one line, so a tool made for wires never meets a rig without them.
    """
    data = read_toml(path)
    return rig_from_dict(data, source=str(path), default_name=re.sub(r"[^A-Za-z0-9_.-]", "_", Path(path).stem),
                         free_moment=free_moment, hinge=hinge)


def rig_from_dict(data: dict, source: str = "<memory>", default_name: str = "rig", free_moment: int | None = None,
                  hinge: bool = False) -> Rig | HingeRig:
    """Build a checked :class:`Rig` from the parsed TOML table (see the module docstring and
    :func:`load_rig` for ``free_moment`` and ``hinge``; a hinge rig's unknown moment is the one about its
    axis, so ``free_moment`` is for wire rigs only)."""
    kind = next((k for k in HINGE_TABLES if k in data), None)
    if kind is not None:
        if not hinge:
            raise RigError(source, kind, "a hinge rig (compound or torsion pendulum): this tool takes wire rigs only")
        return hinge_from_dict(data, source, default_name)
    no_unknown(data, _TOP_KEYS, source, "")
    name = rig_name(data, source, default_name)
    gravity = positive(data.get("gravity", 9.81), source, "gravity")

    body = table(data, "body", source, mandatory=True)
    no_unknown(body, _BODY_KEYS, source, "body.")
    mass = positive(required(body, "mass", source, "body."), source, "body.mass")
    com = vector3(body.get("com", [0.0, 0.0, 0.0]), source, "body.com")
    inertia = inertia_tensor(required(body, "inertia", source, "body."), source, free_moment)

    wires_raw = data.get("wire")
    if not isinstance(wires_raw, list) or not all(isinstance(w, dict) for w in wires_raw):
        raise RigError(source, "wire", "missing: give the wires as [[wire]] tables")
    if not 2 <= len(wires_raw) <= MAX_WIRES:
        raise RigError(source, "wire", f"2 to {MAX_WIRES} [[wire]] tables needed, found {len(wires_raw)}")
    wires = []
    for i, w in enumerate(wires_raw, start=1):
        prefix = f"wire[{i}]."
        no_unknown(w, _WIRE_KEYS, source, prefix)
        wires.append(
            Wire(
                anchor=vector3(required(w, "anchor", source, prefix), source, prefix + "anchor"),
                attach=vector3(required(w, "attach", source, prefix), source, prefix + "attach"),
                length=positive(required(w, "length", source, prefix), source, prefix + "length"),
                axial_stiffness=(positive(w["axial_stiffness"], source, prefix + "axial_stiffness")
                                 if "axial_stiffness" in w else None),
                linear_density=positive(w["linear_density"], source, prefix + "linear_density")
                if "linear_density" in w else 0.0,
            )
        )
    check_heavy_inextensible(wires, source)
    given = [w.axial_stiffness is not None for w in wires]
    if any(given) and not all(given):
        first = given.index(not given[0]) + 1
        raise RigError(source, f"wire[{first}].axial_stiffness", "give every wire an axial_stiffness or none: a rig "
                       "mixing elastic and inextensible wires is not modelled")

    initial = table(data, "initial", source, mandatory=False)
    no_unknown(initial, _INITIAL_KEYS, source, "initial.")
    rotation = vector3(initial.get("rotation", [0.0, 0.0, 0.0]), source, "initial.rotation")
    omega = vector3(initial.get("omega", [0.0, 0.0, 0.0]), source, "initial.omega")

    unc_raw = table(data, "uncertainty", source, mandatory=False)
    no_unknown(unc_raw, _UNCERTAINTY_KEYS, source, "uncertainty.")
    unc = Uncertainty(
        **{k: non_negative(v, source, f"uncertainty.{k}") for k, v in unc_raw.items()}
    )

    air = None
    if "air" in data:
        air = air_from_dict(table(data, "air", source, mandatory=True), source)
    rig = Rig(
        name=name,
        mass=mass,
        inertia=inertia,
        wires=tuple(wires),
        com=com,
        gravity=gravity,
        initial_rotation=rotation,
        initial_omega=omega,
        uncertainty=unc,
        source=source,
        air=air,
    )
    check_ranges(rig, free_moment)
    check_reachable(rig)
    return rig


def check_heavy_inextensible(wires, source: str) -> None:
    """Refuse heavy wires (``linear_density``) on a rig with elastic ones (``axial_stiffness``): the
    heavy-wire correction (docs/heavy-wires.md) is derived for inextensible wires only. On the
    :class:`Wire` objects, so that a sweep's configured rig is held to it as a file is."""
    heavy = [i for i, w in enumerate(wires, start=1) if w.linear_density > 0.0]
    elastic = [i for i, w in enumerate(wires, start=1) if w.axial_stiffness is not None]
    if heavy and elastic:
        raise RigError(source, f"wire[{heavy[0]}].linear_density", f"heavy wires are modelled inextensible: not "
                       f"with axial_stiffness (wire[{elastic[0]}]); give one or the other")


def check_reachable(rig: Rig) -> None:
    """Raise unless every pair of wires, their anchor span and their attachment span can close a loop.

    In any taut pose, anchor A_i -> attach P_i -> attach P_j -> anchor A_j is a closed quadrilateral with
    sides |A_i A_j|, L_i, |P_i P_j| (fixed in the body) and L_j; a taut pose exists only if, for every
    pair, no side is longer than the sum of the other three (distinct attachment points are checked
    with the ranges, :mod:`bifilar.rig.ranges`). Necessary, not sufficient, for three or more wires.
    """
    for i in range(len(rig.wires)):
        for j in range(i + 1, len(rig.wires)):
            _check_loop(rig, i, j)


def _check_loop(rig: Rig, i: int, j: int) -> None:
    wi, wj = rig.wires[i], rig.wires[j]
    pair = "" if len(rig.wires) == 2 else f" of wires {i + 1} and {j + 1}"  # named where not implied
    sides = {"anchor span": float(np.linalg.norm(wi.anchor - wj.anchor)), f"wire[{i + 1}].length": wi.length,
             "attachment span": float(np.linalg.norm(wi.attach - wj.attach)), f"wire[{j + 1}].length": wj.length}
    total = sum(sides.values())
    for label, side in sides.items():
        if side >= (total - side) * (1.0 - 1e-9):  # equal is a flat loop: no sag, infinite tension
            raise RigError(
                rig.source,
                "wire",
                f"no taut pose: the {label}{pair if 'span' in label else ''} ({side:.6g} m) is not shorter than the sum of the other three "
                f"sides of the anchor-wire-body loop ({total - side:.6g} m)",
            )


MIN_REST_SHARE = 1e-6  # of the weight: a wire carrying less at rest is slack to rounding


def check_hanging(rig: Rig, rest) -> None:
    """Raise unless every wire hangs down from its anchor at the rest pose ``rest`` (a
    :class:`bifilar.rig.statics.Rest`) and carries a share of the weight: an anchor below its
    attachment (the sign of a z flipped) makes a guy wire, not a pendulum, though its tension may well be
    positive; a wire that carries ~0 N (the COM straight below the other wire's attachment) is slack or
    taut by the sign of a rounding error, so a run would be accepted or refused at random."""
    weight = rig.mass * rig.gravity
    for i, tension in enumerate(rest.tensions, start=1):
        if tension < MIN_REST_SHARE * weight:
            raise RigError(rig.source, f"wire[{i}]", f"carries {tension:.3g} N of the {weight:.6g} N weight at rest "
                           f"(less than {MIN_REST_SHARE:g} of it): the body hangs from the other wire alone")
    for i, w in enumerate(rig.wires, start=1):
        attach = rest.com + rest.rotation @ (w.attach - rig.com)
        rise = float(w.anchor[2] - attach[2])
        if rise <= 0.0:
            raise RigError(rig.source, f"wire[{i}].anchor", f"is {-rise:.6g} m below (or level with) its attachment "
                           "at rest: a wire must hang down from its anchor (is the sign of z right?)")
