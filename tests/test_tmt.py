"""The TMT implementation (bifilar.seeds.tmt) on textbook systems with closed forms, its kinematics
against finite differences, and a skewed spatial chain against MuJoCo (validate.engines.tmt_mujoco)."""

import mujoco
import numpy as np
import pytest
from scipy.spatial.transform import Rotation
from scipy.special import ellipk

from bifilar.seeds import tmt
from bifilar.seeds.tmt import Body, Chain, Frame
from validate.engines import tmt_mujoco as tm
from validate.metrics import period

G = 9.81
E1 = (1.0, 0.0, 0.0)
# Closed forms and the TMT differ only by rounding: a few dozen operations on O(1) numbers.
RTOL = 1e-12


def rod(name, m, length):
    """Thin uniform rod along its body e2 axis: J = m L^2/12 about e1 and e3."""
    return Body(name, m, np.diag([m * length**2 / 12, 0.0, m * length**2 / 12]))


def double_pendulum(m1=1.3, m2=0.7, L1=0.9, L2=0.6):
    """Two rods turning about e1, each hinged at its end; q measured from the horizontal e2 axis."""
    frames = [
        Frame(axis=E1, coordinate=0),
        Frame(s=(0.0, L1 / 2, 0.0), body=rod("one", m1, L1)),
        Frame(s=(0.0, L1 / 2, 0.0), axis=E1, coordinate=1),
        Frame(s=(0.0, L2 / 2, 0.0), body=rod("two", m2, L2)),
    ]
    return Chain(frames, (0.0, 0.0, -G)), (m1, m2, L1, L2)


def random_chain(seed=5):
    """Three hinges on skewed axes, two of them in one body, a constant rotation, offsets in every
    direction and full inertia tensors: nothing in it lines up with a coordinate axis."""
    rng = np.random.default_rng(seed)

    def body(name):
        m = rng.uniform(0.5, 2.0)
        a, b, c = rng.uniform(0.05, 0.5, 3)
        principal = m / 12 * np.diag([b * b + c * c, a * a + c * c, a * a + b * b])  # a box
        R = Rotation.random(random_state=rng).as_matrix()
        return Body(name, m, R @ principal @ R.T)

    def vec():
        return tuple(rng.uniform(-0.5, 0.5, 3))

    frames = [
        Frame(s=vec(), axis=vec(), coordinate=0),
        Frame(s=vec(), axis=vec(), angle=0.4, body=body("a")),
        Frame(s=vec(), axis=vec(), coordinate=1),
        Frame(s=vec(), axis=vec(), coordinate=2, body=body("b")),
        Frame(s=vec(), body=body("c")),
    ]
    return Chain(frames, (0.0, 0.0, -G))


def test_single_pendulum_matches_closed_form():
    m, c, J = 2.0, 0.4, 0.03  # kg, COM distance from the hinge (m), inertia about the COM (kg m^2)
    chain = Chain([Frame(axis=E1, coordinate=0), Frame(s=(0.0, c, 0.0), body=Body("bob", m, np.diag([J, J, J])))],
                  (0.0, 0.0, -G))
    for th, thd in [(0.3, 1.1), (-2.0, -4.0), (3.0, 0.0)]:
        eom = chain.eom([th], [thd])
        # (J + m c^2) th'' = -m g c cos(th): the COM height is c sin(th)
        assert eom.Mstar[0, 0] == pytest.approx(J + m * c**2, rel=RTOL)
        assert eom.Nstar[0, 0] == pytest.approx(0.0, abs=RTOL)
        assert eom.Fstar[0] == pytest.approx(-m * G * c * np.cos(th), rel=RTOL)


def test_single_pendulum_period_matches_elliptic_integral():
    """Large swing: T = 4 sqrt(I / (m g c)) K(sin^2(a/2)) for amplitude a about the hanging pose."""
    m, c, J, amp = 1.0, 0.5, 0.02, 2.0
    chain = Chain([Frame(axis=E1, coordinate=0), Frame(s=(0.0, c, 0.0), body=Body("bob", m, np.diag([J, J, J])))],
                  (0.0, 0.0, -G))
    exact = 4.0 * np.sqrt((J + m * c**2) / (m * G * c)) * ellipk(np.sin(amp / 2) ** 2)
    sol = tmt.simulate(chain, [-np.pi / 2 + amp], [0.0], 6 * exact, dt_out=exact / 200)
    # DOP853 at rtol 1e-11 and crossings refined to ~1e-10 of a period (validate.metrics)
    assert period(sol.t, sol.q[:, 0], level=-np.pi / 2).value == pytest.approx(exact, rel=1e-9)


def test_double_pendulum_matches_closed_form():
    chain, (m1, m2, L1, L2) = double_pendulum()
    c1, c2, J1, J2 = L1 / 2, L2 / 2, m1 * L1**2 / 12, m2 * L2**2 / 12
    rng = np.random.default_rng(0)
    for _ in range(20):
        q, qd = rng.uniform(-np.pi, np.pi, 2), rng.uniform(-5.0, 5.0, 2)
        th, ph = q
        cp, sp = np.cos(ph), np.sin(ph)
        # Lagrange: T = 1/2 q'^T M q', V = g (m1 c1 sin th + m2 (L1 sin th + c2 sin(th + ph)))
        M = np.array([
            [J1 + m1 * c1**2 + J2 + m2 * (L1**2 + c2**2 + 2 * L1 * c2 * cp), J2 + m2 * (c2**2 + L1 * c2 * cp)],
            [J2 + m2 * (c2**2 + L1 * c2 * cp), J2 + m2 * c2**2],
        ])
        h = m2 * L1 * c2 * sp
        coriolis = np.array([-h * (2 * qd[0] * qd[1] + qd[1] ** 2), h * qd[0] ** 2])
        g2 = m2 * c2 * np.cos(th + ph)
        gravity = G * np.array([(m1 * c1 + m2 * L1) * np.cos(th) + g2, g2])
        eom = chain.eom(q, qd)
        np.testing.assert_allclose(eom.Mstar, M, rtol=0, atol=RTOL * np.abs(M).max())
        np.testing.assert_allclose(eom.Nstar @ qd, coriolis, rtol=0, atol=RTOL * 10)
        np.testing.assert_allclose(-eom.Fstar, gravity, rtol=0, atol=RTOL * np.abs(gravity).max())


def test_kinematics_match_finite_differences():
    """B's velocity rows are dx/dq, its omega rows unskew(R^T dR/dt), Bdot is dB/dt. Central
    differences with step 1e-6: truncation ~1e-12, rounding ~1e-10, so 1e-8 is a safe bound."""
    chain = random_chain()
    rng = np.random.default_rng(1)
    h, nb = 1e-6, len(chain.bodies)
    for _ in range(5):
        q, qd = rng.uniform(-3.0, 3.0, 3), rng.uniform(-3.0, 3.0, 3)
        kin = chain.kinematics(q, qd)
        ahead, behind = chain.kinematics(q + h * qd, qd), chain.kinematics(q - h * qd, qd)
        np.testing.assert_allclose((ahead.B - behind.B) / (2 * h), kin.Bdot, rtol=0, atol=1e-8)
        Rdot = (ahead.R - behind.R) / (2 * h)
        for i in range(nb):
            W = kin.R[i].T @ Rdot[i]
            np.testing.assert_allclose([W[2, 1], W[0, 2], W[1, 0]], kin.omega[i], rtol=0, atol=1e-8)
            np.testing.assert_allclose((ahead.x[i] - behind.x[i]) / (2 * h), kin.B[6 * i : 6 * i + 3] @ qd,
                                       rtol=0, atol=1e-8)
            np.testing.assert_allclose(kin.omega[i], kin.B[6 * i + 3 : 6 * i + 6] @ qd, rtol=0, atol=1e-13)


def test_body_loads_project_onto_the_generalized_forces():
    """D'Alembert: B^T (per-body loads) = F* whenever qdd solves the reduced equations."""
    chain = random_chain()
    q, qd = np.array([0.3, -1.2, 2.0]), np.array([1.5, -0.4, 2.2])
    forces, moments = chain.body_loads(q, qd, chain.accelerations(q, qd))
    loads = np.hstack([forces, moments]).ravel()
    eom = chain.eom(q, qd)
    np.testing.assert_allclose(chain.kinematics(q, qd).B.T @ loads, eom.Fstar, rtol=0, atol=1e-12 * np.abs(loads).max())


def test_spatial_chain_matches_mujoco():
    """Mass matrix, bias and per-body loads of the skewed chain against MuJoCo, relative to the largest
    entry: both sides round at ~1e-16 per operation, and MuJoCo diagonalizes each inertia."""
    chain = random_chain()
    model = tm.chain_spec(chain).compile()
    data = mujoco.MjData(model)
    rng = np.random.default_rng(2)
    for _ in range(20):
        q, qd = rng.uniform(-np.pi, np.pi, 3), rng.uniform(-5.0, 5.0, 3)
        M, bias = tm.mass_and_bias(model, data, q, qd)
        eom = chain.eom(q, qd)
        np.testing.assert_allclose(eom.Mstar, M, rtol=0, atol=RTOL * np.abs(M).max())
        np.testing.assert_allclose(eom.Nstar @ qd - eom.Fstar, bias, rtol=0, atol=RTOL * np.abs(bias).max())
        kin = chain.kinematics(q, qd)
        np.testing.assert_allclose(data.xipos[1:], kin.x, rtol=0, atol=1e-14)
        np.testing.assert_allclose(data.xmat[1:].reshape(-1, 3, 3), kin.R, rtol=0, atol=1e-14)
        forces, moments = chain.body_loads(q, qd, chain.accelerations(q, qd))
        f_mj, m_mj = tm.body_loads(model, data, q, qd, ["a", "b", "c"])
        np.testing.assert_allclose(forces, f_mj, rtol=0, atol=1e-11 * np.abs(f_mj).max())
        np.testing.assert_allclose(moments, m_mj, rtol=0, atol=1e-11 * np.abs(m_mj).max())


@pytest.mark.parametrize(
    "frames, message",
    [
        ([Frame(coordinate=1), Frame(body=Body("b", 1.0, np.eye(3)))], "coordinates must be 0..n-1"),
        ([Frame(body=Body("b", 1.0, np.eye(3))), Frame(coordinate=0)], "moves no body"),
        ([Frame(coordinate=0), Frame(body=Body("b", 1.0, np.diag([1.0, 1.0, 3.0])))], "not that of a real body"),
        ([Frame(coordinate=0), Frame(body=Body("b", 0.0, np.eye(3)))], "mass must be positive"),
        ([Frame(axis=(0.0, 0.0, 0.0), coordinate=0), Frame(body=Body("b", 1.0, np.eye(3)))], "axis is zero"),
    ],
)
def test_invalid_chains_are_refused(frames, message):
    with pytest.raises(ValueError, match=message):
        Chain(frames, (0.0, 0.0, -G))
