"""The parallel-axis theorem, one implementation for every face that moves a moment between points.

A body of mass m whose COM sits at ``offset`` d (m) from a point has, about that point, its own tensor
plus m P(d), P(d) = |d|^2 1 - d d^T (kg m^2), in the frame d is given in; about an axis e through the
point, its moment plus m (|d|^2 - (d . e)^2). A fixture carrying an object (a tare) hangs as one
assembly: the object's mass and COM are the assembly's less the fixture's, and the object's moment about
its own COM is the assembly's less the fixture's and both parallel-axis terms about the assembly's COM.
``identify --tare`` (one axis) and the tensor's hangings (the whole tensor) both use these.
"""

from __future__ import annotations

import numpy as np


def parallel_axis(mass: float, offset) -> np.ndarray:
    """m P(d): what a body of ``mass`` (kg) adds to its tensor about a point its COM is ``offset`` (m)
    from (3x3, kg m^2, in the frame of ``offset``)."""
    d = np.asarray(offset, dtype=float)
    return mass * (float(d @ d) * np.eye(3) - np.outer(d, d))


def parallel_axis_moment(mass: float, offset, axis) -> float:
    """m (|d|^2 - (d . e)^2): what a body of ``mass`` adds to its moment about the unit ``axis`` e
    through a point its COM is ``offset`` d from (kg m^2)."""
    d, e = np.asarray(offset, dtype=float), np.asarray(axis, dtype=float)
    return mass * float(d @ d - (d @ e) ** 2)


def object_part(assembly_mass: float, assembly_com, fixture_mass: float, fixture_com) -> tuple[float, np.ndarray]:
    """The object's mass (kg) and COM (m, the frame of the COMs given) in an assembly with a fixture:
    the assembly's less the fixture's. The mass may come out non-positive: the caller says whose it is."""
    mass = assembly_mass - fixture_mass
    com = (assembly_mass * np.asarray(assembly_com, float) - fixture_mass * np.asarray(fixture_com, float)) / mass
    return mass, com
