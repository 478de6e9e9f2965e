"""Mass properties of a rigid body built from simple homogeneous parts (thesis ch. 3 and 8.1).

The thesis estimates the Solar Boat's moments of inertia by approximating it with boxes, cylinders
and spheres and summing their inertias with the parallel axis theorem. This module does the same for
any list of parts and returns the full tensor, not only its diagonal, so that tilted principal axes
are not lost.

Units are SI. Each part has its own frame: origin at its centroid, cylinders along the part z axis,
boxes with edges ``length``, ``width``, ``height`` along the part x, y, z axes. A part's ``position``
is its centroid and its ``rotation`` maps part axes to body axes; the body frame is whatever frame
the parts are given in. Thin shells carry all their mass on one surface of zero thickness (the
cylindrical shell is open: a tube without end caps), so their ``density`` is per area (kg/m^2); for
all other shapes it is per volume (kg/m^3).

A parts file is TOML with one ``[[part]]`` table per part; :func:`load_parts` reads it and raises
:class:`~bifilar.rig.RigError` (``source: field: problem``) on any problem.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np
from scipy.spatial.transform import Rotation

from bifilar.rig.checks import RigError, no_unknown, positive, read_toml, required, vector3


def _box(a: float, b: float, c: float) -> tuple[float, float, float]:
    return ((b * b + c * c) / 12.0, (a * a + c * c) / 12.0, (a * a + b * b) / 12.0)


def _hollow_cylinder(r: float, ri: float, length: float) -> tuple[float, float, float]:
    s = r * r + ri * ri
    side = (3.0 * s + length * length) / 12.0
    return (side, side, s / 2.0)


def _hollow_sphere(r: float, ri: float) -> tuple[float, float, float]:
    # 2/5 (r^5 - ri^5) / (r^3 - ri^3), factored so that it stays exact as ri -> r (limit 2/3 r^2).
    k = 0.4 * (r**4 + r**3 * ri + r**2 * ri**2 + r * ri**3 + ri**4) / (r * r + r * ri + ri * ri)
    return (k, k, k)


@dataclass(frozen=True)
class Shape:
    """A primitive: its dimension names, its measure (volume in m^3, or area in m^2 for a thin
    shell, to turn a density into a mass) and its principal moments per unit mass (m^2) about the
    centroid along the part axes."""

    dims: tuple[str, ...]
    measure: Callable[..., float]
    gyration: Callable[..., tuple[float, float, float]]


_BOX = Shape(("length", "width", "height"), lambda a, b, c: a * b * c, _box)

SHAPES: dict[str, Shape] = {
    "box": _BOX,
    "beam": _BOX,  # a long box, named as in the thesis's Table 8.1.1
    "plate": _BOX,  # a thin box, named as in the thesis's Table 8.1.1
    "cylinder": Shape(
        ("radius", "length"), lambda r, h: math.pi * r * r * h, lambda r, h: _hollow_cylinder(r, 0.0, h)
    ),
    "hollow_cylinder": Shape(
        ("radius", "inner_radius", "length"),
        lambda r, ri, h: math.pi * (r * r - ri * ri) * h,
        _hollow_cylinder,
    ),
    "cylindrical_shell": Shape(
        ("radius", "length"), lambda r, h: 2.0 * math.pi * r * h, lambda r, h: _hollow_cylinder(r, r, h)
    ),
    "sphere": Shape(("radius",), lambda r: 4.0 / 3.0 * math.pi * r**3, lambda r: _hollow_sphere(r, 0.0)),
    "hollow_sphere": Shape(
        ("radius", "inner_radius"), lambda r, ri: 4.0 / 3.0 * math.pi * (r**3 - ri**3), _hollow_sphere
    ),
    "spherical_shell": Shape(("radius",), lambda r: 4.0 * math.pi * r * r, lambda r: _hollow_sphere(r, r)),
}


@dataclass(frozen=True)
class Part:
    """One homogeneous primitive of a composite body."""

    name: str
    shape: str  # a key of SHAPES
    dims: dict[str, float]  # m, the names in SHAPES[shape].dims
    mass: float  # kg
    position: np.ndarray  # centroid, body frame, m
    rotation: np.ndarray  # 3x3, columns are the part axes in the body frame

    def principal_moments(self) -> np.ndarray:
        """Moments about the centroid along the part axes (kg m^2)."""
        shape = SHAPES[self.shape]
        return self.mass * np.array(shape.gyration(*(self.dims[d] for d in shape.dims)))

    def inertia(self) -> np.ndarray:
        """Inertia tensor about the part's centroid, body axes (kg m^2)."""
        return self.rotation @ np.diag(self.principal_moments()) @ self.rotation.T


@dataclass(frozen=True)
class MassProperties:
    """Mass (kg), centre of mass (body frame, m) and inertia tensor about it (body axes, kg m^2)."""

    mass: float
    com: np.ndarray
    inertia: np.ndarray

    def principal(self) -> tuple[np.ndarray, np.ndarray]:
        """Principal moments, ascending (kg m^2), and the principal axes as the columns of a proper
        rotation matrix (body frame)."""
        moments, axes = np.linalg.eigh(self.inertia)
        if np.linalg.det(axes) < 0.0:
            axes[:, 2] = -axes[:, 2]
        return moments, axes


def mass_properties(parts: list[Part]) -> MassProperties:
    """Combine the parts: total mass, mass-weighted centroid, and each part's inertia moved to the
    common centre of mass by the parallel axis theorem, I += m (|d|^2 E - d d^T)."""
    if not parts:
        raise ValueError("mass_properties needs at least one part")
    mass = sum(p.mass for p in parts)
    com = sum(p.mass * p.position for p in parts) / mass
    inertia = np.zeros((3, 3))
    for p in parts:
        d = p.position - com
        inertia += p.inertia() + p.mass * (d @ d * np.eye(3) - np.outer(d, d))
    return MassProperties(mass=mass, com=com, inertia=0.5 * (inertia + inertia.T))


def rig_body(props: MassProperties) -> dict:
    """The ``[body]`` table of a rig file (see :mod:`bifilar.rig`) for this composite, in the parts'
    frame, as plain floats ready to be written as TOML or passed to ``rig_from_dict``."""
    return {
        "mass": float(props.mass),
        "com": [float(x) for x in props.com],
        "inertia": [[float(x) for x in row] for row in props.inertia],
    }


def rotation_from_axis(axis) -> np.ndarray:
    """The smallest rotation taking the part z axis onto ``axis`` (any non-zero length): enough to
    place an axisymmetric part, whose spin about its own axis does not matter."""
    a = np.asarray(axis, dtype=float)
    a = a / np.linalg.norm(a)
    cross = np.cross([0.0, 0.0, 1.0], a)
    sin, cos = float(np.linalg.norm(cross)), float(a[2])
    if sin < 1e-15:
        return np.eye(3) if cos > 0.0 else np.diag([1.0, -1.0, -1.0])  # half turn about x
    return Rotation.from_rotvec(cross / sin * math.atan2(sin, cos)).as_matrix()


_PART_KEYS = {"name", "shape", "mass", "density", "position", "rotation", "axis"}


def load_parts(path: str | Path) -> list[Part]:
    """Read and check a parts file (``[[part]]`` tables); raise :class:`RigError` on any problem."""
    data = read_toml(path)
    return parts_from_dict(data, source=str(path))


def parts_from_dict(data: dict, source: str = "<memory>") -> list[Part]:
    """Build checked parts from a parsed parts file (a ``part`` list of tables)."""
    no_unknown(data, {"part"}, source, "")
    raw = data.get("part")
    if not isinstance(raw, list) or not raw or not all(isinstance(p, dict) for p in raw):
        raise RigError(source, "part", "missing: give the parts as [[part]] tables")
    parts = [part_from_dict(p, source, f"part[{i}].") for i, p in enumerate(raw, start=1)]
    seen = set()
    for i, p in enumerate(parts, start=1):
        if p.name in seen:
            raise RigError(source, f"part[{i}].name", f"duplicate name {p.name!r}")
        seen.add(p.name)
    return parts


def part_from_dict(table: dict, source: str = "<memory>", prefix: str = "part.") -> Part:
    """Build one checked :class:`Part` from its table.

    Keys: ``name``; ``shape`` (a key of :data:`SHAPES`); the shape's dimensions (m); exactly one of
    ``mass`` (kg) and ``density``; ``position`` (centroid, m, default origin); at most one of
    ``rotation`` (rotation vector, rad) and ``axis`` (direction of the part z axis).
    """
    name = required(table, "name", source, prefix)
    if not isinstance(name, str) or not name:
        raise RigError(source, prefix + "name", "must be a non-empty string")
    shape_name = required(table, "shape", source, prefix)
    if shape_name not in SHAPES:
        raise RigError(source, prefix + "shape", f"unknown shape {shape_name!r} (known: {', '.join(SHAPES)})")
    shape = SHAPES[shape_name]
    no_unknown(table, _PART_KEYS | set(shape.dims), source, prefix)
    dims = {d: positive(required(table, d, source, prefix), source, prefix + d) for d in shape.dims}
    if dims.get("inner_radius", 0.0) >= dims.get("radius", math.inf):
        raise RigError(source, prefix + "inner_radius", f"must be less than radius ({dims['radius']:g} m)")

    if ("mass" in table) == ("density" in table):
        raise RigError(source, prefix + "mass", "give exactly one of mass and density")
    if "mass" in table:
        mass = positive(table["mass"], source, prefix + "mass")
    else:
        density = positive(table["density"], source, prefix + "density")
        mass = density * shape.measure(*dims.values())

    position = vector3(table.get("position", [0.0, 0.0, 0.0]), source, prefix + "position")
    if "rotation" in table and "axis" in table:
        raise RigError(source, prefix + "axis", "give at most one of rotation and axis")
    if "axis" in table:
        axis = vector3(table["axis"], source, prefix + "axis")
        if not np.linalg.norm(axis) > 0.0:
            raise RigError(source, prefix + "axis", "must not be zero")
        rotation = rotation_from_axis(axis)
    else:
        rotvec = vector3(table.get("rotation", [0.0, 0.0, 0.0]), source, prefix + "rotation")
        rotation = Rotation.from_rotvec(rotvec).as_matrix()
    return Part(name=name, shape=shape_name, dims=dims, mass=mass, position=position, rotation=rotation)


def equivalent_box(mass: float, inertia: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Half sizes (m) and orientation (rotation matrix, columns = box axes in the body frame) of the
    uniform box with this mass and inertia tensor (about the COM): along principal axis i,
    edge_i^2 = 6 (I_j + I_k - I_i) / m. Used to draw a body whose shape is not known."""
    moments, axes = np.linalg.eigh(inertia)
    if np.linalg.det(axes) < 0.0:
        axes[:, 2] *= -1.0  # a rotation, not a reflection
    edges = np.sqrt(np.maximum(6.0 * (moments.sum() - 2.0 * moments) / mass, 0.0))
    return 0.5 * edges, axes
