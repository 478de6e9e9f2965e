"""Rest pose, static tensions and the rig file's [initial] semantics (engine-neutral statics)."""

from dataclasses import replace

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from bifilar.rig import statics
from bifilar.rig.statics import attachments, initial_state, length_errors, rest_pose
from validate.assets import rig


def test_rest_pose_balances_forces_and_moments(any_rig):
    rest = rest_pose(any_rig)
    pts = attachments(any_rig, rest.com, rest.rotation)
    pull = np.array([w.anchor for w in any_rig.wires]) - pts
    pull = pull / np.linalg.norm(pull, axis=1)[:, None] * rest.tensions[:, None]
    weight = any_rig.mass * any_rig.gravity
    np.testing.assert_allclose(pull.sum(axis=0), [0, 0, weight], atol=1e-10 * weight)
    np.testing.assert_allclose(np.cross(pts - rest.com, pull).sum(axis=0), 0, atol=1e-10 * weight)
    assert np.abs(length_errors(any_rig, rest.com, rest.rotation)).max() < 1e-12
    assert np.all(rest.tensions > 0)


def test_inverted_start_rolls_to_the_stable_pose():
    """A COM 5 m above the attachments must hang below them, not balance on top."""
    r = rig("plate")
    from dataclasses import replace

    top = replace(r, com=np.array([0.0, 0.0, 5.0]))
    rest = rest_pose(top)
    attach_z = attachments(top, rest.com, rest.rotation)[:, 2]
    assert np.all(rest.com[2] < attach_z)


def test_symmetric_twist_is_a_pure_lift():
    """Issue 2: for a symmetric rig twisted about the vertical, the displacement is a pure lift."""
    r = rig("plate")
    s = initial_state(r)
    np.testing.assert_allclose(s.com[:2], 0.0, atol=1e-12)
    # Each attachment turns on a circle of radius 2.5 m: the wire's horizontal reach becomes
    # sqrt(2.5^2 + 5^2 - 2*2.5*5 cos(0.1745)) and the lift follows from Pythagoras.
    reach = np.sqrt(2.5**2 + 5**2 - 2 * 2.5 * 5 * np.cos(0.1745))
    lift = np.sqrt(25 - 2.5**2) - np.sqrt(25 - reach**2)
    assert s.com[2] == pytest.approx(lift, abs=1e-12)
    np.testing.assert_allclose(s.rotation, Rotation.from_rotvec([0, 0, 0.1745]).as_matrix(), atol=1e-15)
    np.testing.assert_allclose(s.velocity, 0.0, atol=1e-15)


def test_initial_velocity_is_the_least_norm_one_that_keeps_lengths():
    r = rig("asymmetric")
    s = initial_state(r)
    pts = attachments(r, s.com, s.rotation)
    dirs = pts - np.array([w.anchor for w in r.wires])
    rates = np.einsum("ij,ij->i", dirs, s.velocity + np.cross(s.omega, pts - s.com))
    np.testing.assert_allclose(rates, 0.0, atol=1e-13)
    # Least norm: the velocity lies in the span of the wire directions.
    residual = s.velocity - dirs.T @ np.linalg.lstsq(dirs.T, s.velocity, rcond=None)[0]
    np.testing.assert_allclose(residual, 0.0, atol=1e-13)
    np.testing.assert_allclose(s.omega, r.initial_omega)
    assert np.abs(length_errors(r, s.com, s.rotation)).max() < 1e-12


def test_neutral_tilt_rests_in_the_files_orientation():
    """The thin plate's COM is on CD: every tilt about CD is a rest pose; the file's one is chosen."""
    rest = rest_pose(rig("sidesway"))
    np.testing.assert_allclose(rest.rotation, np.eye(3), atol=1e-12)
    np.testing.assert_allclose(rest.com, 0.0, atol=1e-12)


@pytest.mark.parametrize("turn", [(90.0, 0.0, 0.0), (0.0, 90.0, 0.0), (30.0, 40.0, 50.0)])
def test_rest_pose_does_not_depend_on_the_body_frame(turn):
    """The asymmetric trifilar platform described in a body frame turned by ``turn`` (xyz Euler, deg):
    the same physical rest pose (COM height, tensions) and periods. From the file's orientation alone
    SLSQP settled 90 deg off in a twisted equilibrium 0.13 m higher that is stable too (periods 3.99 /
    2.59 / 2.42 s instead of 2.47 / 2.46 / 1.88 s); the second start from the hanging orientation finds
    the lower one. Tolerances: both are Newton solutions to 1e-12 of the weight and rig size."""
    from dataclasses import replace

    from bifilar.motion.modes import linearize

    tri = rig("trifilar_asymmetric")
    q = Rotation.from_euler("xyz", turn, degrees=True).as_matrix()  # body coordinates x' = q^T x
    turned = replace(tri, wires=tuple(replace(w, attach=q.T @ w.attach) for w in tri.wires), com=q.T @ tri.com,
                     inertia=q.T @ tri.inertia @ q)
    a, b = rest_pose(tri), rest_pose(turned)
    assert b.com == pytest.approx(a.com, abs=1e-10) and b.tensions == pytest.approx(a.tensions, rel=1e-9)
    periods = [[m.period for m in linearize(r).modes] for r in (tri, turned)]
    assert periods[1] == pytest.approx(periods[0], rel=1e-9)


@pytest.mark.parametrize("v", [[0.3, -1.1, 2.0], [1e-8, 0.0, 2e-8], [0.0, 0.0, 3.1]])
def test_the_rest_search_slopes_are_the_rotation_s_derivatives(v):
    # d(R(v) r)/dv = -[R(v) r]x J_l(v), the constraint Jacobian SLSQP is given in the rest-pose search:
    # against central differences of scipy's rotation (step 1e-6: truncation ~1e-12, rounding ~1e-10).
    from bifilar.rig.so3 import left_jacobian as _left_jacobian, skew as _skew

    v, r, h = np.array(v), np.array([0.2, -0.5, 0.7]), 1e-6
    numeric = np.column_stack([(Rotation.from_rotvec(v + h * e).apply(r) - Rotation.from_rotvec(v - h * e).apply(r))
                               / (2.0 * h) for e in np.eye(3)])
    turned = Rotation.from_rotvec(v).apply(r)
    np.testing.assert_allclose(-_skew(turned) @ _left_jacobian(v), numeric, atol=1e-9)


@pytest.mark.parametrize("v", [[0.3, -1.1, 2.0], [1e-8, 0.0, 2e-8], [4e-7, -9e-7, 0.0], [0.0, 0.0, 3.1]])
def test_the_rest_search_rotation_is_scipy_s(v):
    # Rodrigues' formula (the search's inner loop) against scipy's quaternion route: the same matrix to a
    # few units of rounding (entries of order 1), on both sides of the series' switch at |v| = 1e-6.
    from bifilar.rig.so3 import rotation as _rotation

    np.testing.assert_allclose(_rotation(np.array(v)), Rotation.from_rotvec(v).as_matrix(), rtol=0, atol=4e-16)


def test_a_remembered_rest_pose_is_the_search_s_for_another_inertia():
    """The rest pose is remembered by the wires, COM, mass and gravity: a rig that differs only in its
    inertia gets exactly (bitwise) what a fresh multi-start search gives it, as a copy the caller may
    change without changing the next caller's."""
    first = rig("trifilar_asymmetric")
    heavier = replace(first, inertia=first.inertia * 3.0 + np.diag([0.0, 0.01, 0.0]))
    rest_pose(first)
    remembered = rest_pose(heavier)
    fresh = statics._global_rest_pose(heavier)
    for part in ("com", "rotation", "tensions"):
        assert np.array_equal(getattr(remembered, part), getattr(fresh, part))
    remembered.com[:] = 1.0
    assert np.array_equal(rest_pose(heavier).com, fresh.com)
