"""The parameters of seed 001's pendulum, read from ``models/seed001/params.toml``.

The seed's plane of motion is the complex plane x + iy with y up; angles are counter-clockwise from
the x axis, phi2 relative to the inner arm. Units are SI. The file's tables and keys are named after
the seed's symbols (see the file's comments); :meth:`Params.bodies` lists the five rigid parts in
one place for every model built from them (the independent equations and the MuJoCo model).
"""

from __future__ import annotations

import tomllib
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

# table -> keys; every key is required and every value must be a number
_SCHEMA = {
    "arm1": ("mass", "length", "width"),
    "counterweight": ("mass", "radius"),
    "weight1": ("mass", "radius"),
    "arm2": ("mass", "length", "width"),
    "weight2": ("mass", "radius"),
    "friction": ("k1", "k2"),
    "layout": ("gap",),
    "initial": ("phi1", "phi2", "rate1", "rate2"),
}


@dataclass(frozen=True)
class Body:
    """One rigid part: ``arm`` 1 or 2, mass (kg), inertia about its own COM and the axis normal to the
    plane (kg m^2), and ``offset`` (m), the signed distance of its COM from its arm's axis along the
    arm. ``size`` (m, length and width) is the plate drawn for arms, () for point masses."""

    name: str
    arm: int
    mass: float
    inertia: float
    offset: float
    size: tuple[float, ...] = ()


@dataclass(frozen=True)
class Params:
    """The seed's symbols (SI). ``r_m1`` is signed; ``gap`` only places arm2 in front of arm1."""

    g: float
    m_arm1: float
    a1: float
    b1: float
    M: float
    r1: float
    m1: float
    r_m1: float
    m_arm2: float
    a2: float
    b2: float
    m2: float
    r_m2: float
    k1: float
    k2: float
    gap: float
    q0: tuple[float, float]  # (phi1, phi2), rad
    qd0: tuple[float, float]  # (dphi1/dt, dphi2/dt), rad/s

    @property
    def I_arm1(self) -> float:
        return self.m_arm1 * (self.a1**2 + self.b1**2) / 12.0

    @property
    def I_arm2(self) -> float:
        return self.m_arm2 * (self.a2**2 + self.b2**2) / 12.0

    def bodies(self) -> tuple[Body, ...]:
        """The plates are centred on their axes (the seed's sum m_j r_j = 0); the weights are points."""
        return (
            Body("arm1", 1, self.m_arm1, self.I_arm1, 0.0, (self.a1, self.b1)),
            Body("counterweight", 1, self.M, 0.0, self.r1),
            Body("weight1", 1, self.m1, 0.0, self.r_m1),
            Body("arm2", 2, self.m_arm2, self.I_arm2, 0.0, (self.a2, self.b2)),
            Body("weight2", 2, self.m2, 0.0, self.r_m2),
        )

    def with_(self, **changes) -> Params:
        """A copy with some symbols changed, e.g. ``with_(r_m2=0.0)`` or ``with_(k1=0.0, k2=0.0)``."""
        return replace(self, **changes)

    @property
    def frictionless(self) -> Params:
        return self.with_(k1=0.0, k2=0.0)

    @property
    def state0(self) -> np.ndarray:
        """Initial state (phi1, phi2, dphi1/dt, dphi2/dt)."""
        return np.array([*self.q0, *self.qd0], dtype=float)


def load_params(path: str | Path) -> Params:
    """Read and check a parameter file; raise ``ValueError`` naming the file and field at fault."""
    path = Path(path)
    data = tomllib.loads(path.read_text())
    data.pop("name", None)
    g = data.pop("gravity", None)
    unknown = set(data) - set(_SCHEMA)
    if unknown:
        raise ValueError(f"{path}: unknown tables {sorted(unknown)}")
    values = {}
    for table, keys in _SCHEMA.items():
        section = data.get(table)
        if not isinstance(section, dict) or set(section) != set(keys):
            raise ValueError(f"{path}: [{table}] must have exactly the keys {list(keys)}")
        for key in keys:
            if not isinstance(section[key], (int, float)) or isinstance(section[key], bool):
                raise ValueError(f"{path}: {table}.{key} must be a number")  # noqa: TRY004 (one error type per file)
            values[f"{table}.{key}"] = float(section[key])
    if not isinstance(g, (int, float)) or g <= 0:
        raise ValueError(f"{path}: gravity must be a positive number")
    positive = ["arm1.mass", "arm1.length", "arm2.mass", "arm2.length", "counterweight.radius"]
    non_negative = ["arm1.width", "arm2.width", "counterweight.mass", "weight1.mass", "weight2.mass",
                    "weight2.radius", "friction.k1", "friction.k2"]
    for key in positive:
        if values[key] <= 0.0:
            raise ValueError(f"{path}: {key} must be positive")
    for key in non_negative:
        if values[key] < 0.0:
            raise ValueError(f"{path}: {key} must not be negative")
    v = values
    return Params(
        g=float(g),
        m_arm1=v["arm1.mass"], a1=v["arm1.length"], b1=v["arm1.width"],
        M=v["counterweight.mass"], r1=v["counterweight.radius"],
        m1=v["weight1.mass"], r_m1=v["weight1.radius"],
        m_arm2=v["arm2.mass"], a2=v["arm2.length"], b2=v["arm2.width"],
        m2=v["weight2.mass"], r_m2=v["weight2.radius"],
        k1=v["friction.k1"], k2=v["friction.k2"],
        gap=v["layout.gap"],
        q0=(v["initial.phi1"], v["initial.phi2"]),
        qd0=(v["initial.rate1"], v["initial.rate2"]),
    )
