"""The Kane kernel's kinematic matrices against finite differences, and its dynamics against an
independent formulation (Newton-Euler with the wire tensions as Lagrange multipliers)."""

import numpy as np
import pytest
from thesis_appendix import printed_beta, printed_V, printed_Vdot

from bifilar.motion import kane_kernel as K
from bifilar.motion.kane import POLAR, TILT
from bifilar.rig.statics import initial_state, rest_pose

H = 1e-6  # central differences: truncation ~H^2 = 1e-12, rounding ~1e-16/H = 1e-10 -> compare at 1e-8


def random_states(model, n, seed=0):
    """Random taut states of the model's rig, as (chart, theta, theta')."""
    rng = np.random.default_rng(seed)
    rest = rest_pose(model.rig)
    out = []
    for _ in range(n):
        s = initial_state(model.rig.with_initial(0.3 * rng.standard_normal(3), rng.standard_normal(3)), rest)
        for chart in (POLAR, TILT):
            th = model.angles(s.com, s.rotation, chart)
            out.append((chart, th, model.rates(th, s.velocity, s.omega, chart)))
    return out


def fd(f, th, dth):
    return (f(th + H * dth) - f(th - H * dth)) / (2 * H)


def test_body_frame_is_a_rotation():
    rng = np.random.default_rng(1)
    for _ in range(20):
        R = K.body_frame(*rng.uniform(-3, 3, 3))
        np.testing.assert_allclose(R.T @ R, np.eye(3), atol=1e-14)
        assert np.linalg.det(R) == pytest.approx(1.0, abs=1e-14)


def test_velocity_jacobians_match_finite_differences(asym_model):
    p = asym_model.p
    for chart, th, dth in random_states(asym_model, 5):
        kin = K.kinematics(th, dth, p, chart)
        V, G = kin[3], kin[4]
        com_rate = fd(lambda t: K.pose(t, p, chart)[0], th, dth)
        np.testing.assert_allclose(V @ dth, com_rate, atol=1e-8)
        Rdot = fd(lambda t: K.body_frame(t[0], t[3], t[4]), th, dth)
        W = Rdot @ K.body_frame(th[0], th[3], th[4]).T  # skew(omega) in world axes
        np.testing.assert_allclose(G @ dth, [W[2, 1], W[0, 2], W[1, 0]], atol=1e-8)
        d_rate = fd(lambda t: K.kinematics(t, dth, p, chart)[7], th, dth)
        np.testing.assert_allclose(kin[8] @ dth, d_rate, atol=1e-8)


def test_velocity_product_terms_match_finite_differences(asym_model):
    """Vdot theta', Gdot theta' and Jdot theta' are the time derivatives at constant theta'."""
    p = asym_model.p
    for chart, th, dth in random_states(asym_model, 5, seed=2):
        kin = K.kinematics(th, dth, p, chart)
        for idx_matrix, idx_bias in ((3, 5), (4, 6), (8, 9)):
            rate = fd(lambda t: K.kinematics(t, dth, p, chart)[idx_matrix] @ dth, th, dth)
            np.testing.assert_allclose(kin[idx_bias], rate, atol=1e-7)


def test_beta_is_the_gradient_of_the_loop_closure(asym_model):
    p = asym_model.p
    for chart, th, _ in random_states(asym_model, 3, seed=3):
        kin = K.kinematics(th, np.zeros(5), p, chart)
        beta = 2 * kin[8].T @ kin[7]
        for i in range(5):
            e = np.zeros(5)
            e[i] = 1.0
            g = fd(lambda t: np.sum(K.kinematics(t, np.zeros(5), p, chart)[7] ** 2), th, e)
            assert beta[i] == pytest.approx(g, abs=1e-7)


def newton_euler(model, chart, th, dth):
    """Independent dynamics: body accelerations and tensions from Newton-Euler plus the second
    derivative of each wire's length constraint (8 linear equations, 8 unknowns)."""
    rig = model.rig
    com, R = model.pose(th, chart)
    v, w = model.velocity(th, dth, chart)
    Iw = R @ rig.inertia @ R.T
    A = np.zeros((8, 8))
    b = np.zeros(8)
    A[:3, :3] = rig.mass * np.eye(3)
    A[3:6, 3:6] = Iw
    b[:3] = [0, 0, -rig.mass * rig.gravity]
    b[3:6] = -np.cross(w, Iw @ w)
    for i, wire in enumerate(rig.wires):
        arm = R @ (wire.attach - rig.com)
        s = com + arm - wire.anchor
        e = -s / np.linalg.norm(s)  # towards the anchor
        A[:3, 6 + i] = -e
        A[3:6, 6 + i] = -np.cross(arm, e)
        # s . s'' + s' . s' = 0 with s'' = a + alpha x arm + w x (w x arm)
        sdot = v + np.cross(w, arm)
        A[6 + i, :3] = s
        A[6 + i, 3:6] = np.cross(arm, s)
        b[6 + i] = -sdot @ sdot - s @ np.cross(w, np.cross(w, arm))
    x = np.linalg.solve(A, b)
    return x[:3], x[3:6], x[6:]


def test_dynamics_match_newton_euler(asym_model):
    """Kane's M5 theta'' = N5 and the tension recovery agree with an independent formulation."""
    p = asym_model.p
    for chart, th, dth in random_states(asym_model, 6, seed=4):
        acc_ne, alpha_ne, tension_ne = newton_euler(asym_model, chart, th, dth)
        tension, acc, alpha, residual = K.loads(th, dth, p, chart)
        # Both solve well-conditioned linear systems in double precision: agreement ~1e-12 relative.
        np.testing.assert_allclose(acc, acc_ne, atol=1e-10 * asym_model.gravity)
        np.testing.assert_allclose(alpha, alpha_ne, atol=1e-10)
        np.testing.assert_allclose(tension, tension_ne, rtol=1e-10)
        assert residual < 1e-9 * asym_model.mass * asym_model.gravity


def test_printed_appendix_matches_except_the_listed_typos(plate_model):
    """Appendix B of seed 000 against the kernel: every printed entry agrees except v24, vdot12 and
    the sign of beta5 (docs/thesis-corrections.md). Uses the thesis's own setting AB = -b n2."""
    m = plate_model
    rng = np.random.default_rng(5)
    th = np.array([0.3, 0.5, 1.4, 0.2, -0.1])
    dth = rng.standard_normal(5)
    kin = K.kinematics(th, dth, m.p, POLAR)
    V = kin[3]
    Vdot = fd(lambda t: K.kinematics(t, dth, m.p, POLAR)[3], th, dth)
    beta = 2 * kin[8].T @ kin[7] / (2 * m.b_prime**2)  # the printed beta is dg/dtheta / (2 b'^2)
    dV = np.abs(printed_V(th, m.l, m.r, m.lam) - V) > 1e-12
    dVdot = np.abs(printed_Vdot(th, dth, m.l, m.r, m.lam) - Vdot) > 1e-7
    dbeta = np.abs(printed_beta(th, m.b, m.b_prime, m.l) - beta) > 1e-12
    assert [tuple(i) for i in np.argwhere(dV)] == [(1, 3)]  # v24
    assert [tuple(i) for i in np.argwhere(dVdot)] == [(0, 1)]  # vdot12
    assert list(np.flatnonzero(dbeta)) == [4]  # beta5
    assert printed_beta(th, m.b, m.b_prime, m.l)[4] == pytest.approx(-beta[4], rel=1e-12)


def test_theta5_completion_closes_the_loop_and_keeps_it_closed(plate_model):
    """(5.1.2) and (5.1.4): theta5 from g(theta) = a, and theta5' = gamma . theta'_{1..4} keeps dg/dt = 0."""
    rng = np.random.default_rng(6)
    base = np.array([0.0, np.pi / 6, np.pi / 2, 0.0])
    for _ in range(10):
        th14 = base + 0.1 * rng.standard_normal(4)
        dth14 = rng.standard_normal(4)
        th5, dth5 = plate_model.complete_theta5(th14, dth14, 0.0)
        theta, dtheta = np.append(th14, th5), np.append(dth14, dth5)
        assert abs(plate_model.constraint(theta)) < 1e-12  # m^2, Newton to rounding
        g_rate = fd(lambda t: np.array([plate_model.constraint(t)]), theta, dtheta)[0]
        assert abs(g_rate) < 1e-7  # finite difference of a quantity that is zero to first order
