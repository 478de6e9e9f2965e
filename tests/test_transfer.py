"""The parallel-axis theorem (bifilar.identification.transfer) against the tensor summed point by point."""

import numpy as np
import pytest

from bifilar.identification.transfer import object_part, parallel_axis, parallel_axis_moment


def _point_tensor(masses, points):
    """sum m (|r|^2 1 - r r^T) of point masses at ``points`` about the origin (kg m^2)."""
    return sum(m * (p @ p * np.eye(3) - np.outer(p, p)) for m, p in zip(masses, points))


def test_parallel_axis_is_the_point_sum_moved():
    """Eight random point masses: their tensor about the origin equals the tensor about their COM plus
    parallel_axis(mass, COM) to rounding (1e-13 of the tensor), and the moment about a unit axis is its
    quadratic form."""
    rng = np.random.default_rng(7)
    masses, points = rng.uniform(0.1, 2.0, 8), rng.normal(0.0, 0.3, (8, 3))
    com = masses @ points / masses.sum()
    about_origin = _point_tensor(masses, points)
    about_com = _point_tensor(masses, points - com)
    moved = about_com + parallel_axis(masses.sum(), com)
    np.testing.assert_allclose(moved, about_origin, rtol=0, atol=1e-13 * np.abs(about_origin).max())
    e = rng.normal(size=3)
    e /= np.linalg.norm(e)
    assert parallel_axis_moment(masses.sum(), com, e) == pytest.approx(e @ parallel_axis(masses.sum(), com) @ e,
                                                                       rel=0, abs=1e-14)


def test_object_part_is_the_assembly_less_the_fixture():
    """A 3 kg fixture at (0, 0, 0.1) m with a 1 kg object at (0.2, 0, 0): the assembly (4 kg at its
    COM) less the fixture gives the object back exactly."""
    assembly_com = (3.0 * np.array([0.0, 0.0, 0.1]) + 1.0 * np.array([0.2, 0.0, 0.0])) / 4.0
    mass, com = object_part(4.0, assembly_com, 3.0, [0.0, 0.0, 0.1])
    assert mass == 1.0
    np.testing.assert_allclose(com, [0.2, 0.0, 0.0], atol=1e-15)
