"""Seed 002's pendulum: the TMT chain against MuJoCo, the shipped MJCF against the parameter file,
and the seed's printed kinematics against both (the evidence for docs/seed002.md)."""

import mujoco
import numpy as np
import pytest

from bifilar.seeds import seed002
from bifilar.seeds import tmt
from validate.engines import seed002_mujoco
from validate.engines import tmt_mujoco as tm


@pytest.fixture(scope="module")
def params():
    return seed002.load()


@pytest.fixture(scope="module")
def chain(params):
    return seed002.chain(params)


@pytest.fixture(scope="module")
def model(params):
    return seed002_mujoco.model(params)


def random_states(n, seed):
    rng = np.random.default_rng(seed)
    return [(rng.uniform(-np.pi, np.pi, 2), rng.uniform(-40.0, 40.0, 2)) for _ in range(n)]


def test_mass_matrix_and_bias_match_mujoco(chain, model):
    """Relative to the largest entry: rounding of a few dozen O(1) products on either side."""
    data = mujoco.MjData(model)
    for q, qd in random_states(50, 0):
        M, bias = tm.mass_and_bias(model, data, q, qd)
        eom = chain.eom(q, qd)
        np.testing.assert_allclose(eom.Mstar, M, rtol=0, atol=1e-12 * np.abs(M).max())
        np.testing.assert_allclose(eom.Nstar @ qd - eom.Fstar, bias, rtol=0, atol=1e-12 * np.abs(bias).max())


def test_body_loads_match_cfrc_int(chain, model):
    """The seed's per-body net forces and moments against MuJoCo's cfrc_int (see validate.engines.tmt_mujoco);
    each engine uses its own accelerations (a 2x2 solve, condition number up to 115)."""
    data = mujoco.MjData(model)
    for q, qd in random_states(50, 1):
        forces, moments = chain.body_loads(q, qd, chain.accelerations(q, qd))
        f_mj, m_mj = tm.body_loads(model, data, q, qd, seed002.BODIES)
        np.testing.assert_allclose(forces, f_mj, rtol=0, atol=1e-11 * np.abs(f_mj).max())
        np.testing.assert_allclose(moments, m_mj, rtol=0, atol=1e-11 * np.abs(m_mj).max())


def test_out_of_plane_moments_come_from_products_of_inertia(chain, params):
    """The swing is planar (omega along e1) but the arm and rod have J12 != 0, so w x J w has a
    component along e3 of the body, w^2 J12 (body axes): the hinge must carry it. At rest it vanishes."""
    q, qd = np.array([0.4, -0.9]), np.array([3.0, -5.0])
    _, moments = chain.body_loads(q, qd, np.zeros(2))
    arm, rod, ball = params.bodies
    w = np.array([qd[0], qd.sum(), qd.sum()])
    expected_e3 = w**2 * np.array([arm.inertia[0, 1], rod.inertia[0, 1], ball.inertia[0, 1]])
    np.testing.assert_allclose(moments[:, 2], expected_e3, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(moments[:, 1], 0.0, atol=1e-15)  # J13 = 0 for every body


def test_energy_is_conserved(chain, params):
    """DOP853 at rtol 1e-11 over 3 s of the chaotic release: state error ~1e-10, energy slope
    |dE/dy| <= 40 J per unit, so 1e-8 J bounds the drift of a correct model."""
    sol = tmt.simulate(chain, params.q0, params.qd0, 3.0, 0.01)
    assert np.abs(sol.energy - sol.energy[0]).max() < 1e-8
    # released from rest with every COM at the pivot height l1: E = g l1 (m1 + m2 + m3)
    total_mass = sum(b.mass for b in params.bodies)
    assert sol.energy[0] == pytest.approx(params.gravity * params.lengths["l1"] * total_mass, rel=1e-15)
    assert np.ptp(sol.q[:, 0]) > 2.0  # it did swing through a large arc


def test_shipped_xml_is_the_model_built_from_params(model):
    """models/seed002/seed002.xml repeats params.toml by hand: every physical and visual array must
    agree exactly with the MjSpec model."""
    xml = mujoco.MjModel.from_xml_path(str(seed002.XML))
    fields = ["body_pos", "body_quat", "body_mass", "body_inertia", "body_iquat", "body_ipos", "body_parentid",
              "jnt_type", "jnt_pos", "jnt_axis", "dof_armature", "dof_damping", "dof_frictionloss",
              "geom_type", "geom_size", "geom_pos", "geom_quat", "geom_bodyid", "key_qpos", "key_qvel"]
    for name in fields:
        np.testing.assert_array_equal(getattr(xml, name), getattr(model, name), err_msg=name)
    for name in ["timestep", "gravity", "integrator", "enableflags", "disableflags"]:
        np.testing.assert_array_equal(getattr(xml.opt, name), getattr(model.opt, name), err_msg=name)
    assert [xml.joint(j).name for j in range(xml.njnt)] == list(seed002.JOINTS)


def test_scene_steps_without_warnings():
    """The viewer scene, stepped 2 s from the release keyframe (menagerie's stability test)."""
    scene = mujoco.MjModel.from_xml_path(str(seed002.MODEL_DIR / "scene.xml"))
    data = mujoco.MjData(scene)
    mujoco.mj_resetDataKeyframe(scene, data, scene.key("release").id)
    for _ in range(round(2.0 / scene.opt.timestep)):
        mujoco.mj_step(scene, data)
    assert not any(w.number for w in data.warning)
    assert np.all(np.isfinite(data.qpos))


# --- The seed's printed kinematics (docs/seed002.md, "Errors in the seed") ---------------------------


def mujoco_com_velocity(model, data, body, q, qd):
    """Velocity of a body's COM (world frame, m/s) from MuJoCo's Jacobian."""
    tm.set_state(model, data, q, qd)
    jacp = np.zeros((3, model.nv))
    mujoco.mj_jacBodyCom(model, data, jacp, None, model.body(body).id)
    return jacp @ qd


def test_printed_body1_kinematics_are_right(params, model):
    """x^1 = (l2, l3 cos th, l1 + l3 sin th) and xdot^1 = th' l3 (0, -sin th, cos th), as printed."""
    L, data = params.lengths, mujoco.MjData(model)
    th, thd = 0.7, -1.3
    tm.set_state(model, data, [th, 0.2], [thd, 0.5])
    x1 = [L["l2"], L["l3"] * np.cos(th), L["l1"] + L["l3"] * np.sin(th)]
    np.testing.assert_allclose(data.xipos[model.body("arm").id], x1, atol=1e-15)
    v = mujoco_com_velocity(model, data, "arm", [th, 0.2], [thd, 0.5])
    np.testing.assert_allclose(v, thd * L["l3"] * np.array([0.0, -np.sin(th), np.cos(th)]), atol=1e-15)


def test_printed_rod_velocity_misses_theta_dot_l6(params, model):
    """The seed's Omega^2 (and so xdot^2, xdot^3 and B) lacks th' l6 in its (3,4) entry: the printed
    xdot^2 is off by exactly th' l6 (0, -sin(th+ph), cos(th+ph)); with the term it matches MuJoCo."""
    L, data = params.lengths, mujoco.MjData(model)
    Ls, l6, l7 = L["l3"] + L["l4"], L["l6"], L["l7"]
    for q, qd in random_states(10, 3):
        (th, ph), (thd, phd) = q, qd
        e = np.array([0.0, -np.sin(th + ph), np.cos(th + ph)])
        arm_term = thd * Ls * np.array([0.0, -np.sin(th), np.cos(th)])
        printed_rod = arm_term + phd * l6 * e  # the seed's final xdot^2
        printed_ball = arm_term + (phd * l6 + l7 * (thd + phd)) * e  # the seed's xdot^3 (dots fixed)
        rod, ball = (mujoco_com_velocity(model, data, b, q, qd) for b in ("rod", "ball"))
        np.testing.assert_allclose(rod - printed_rod, thd * l6 * e, atol=1e-13)
        np.testing.assert_allclose(ball - printed_ball, thd * l6 * e, atol=1e-13)
        np.testing.assert_allclose(rod, arm_term + (thd + phd) * l6 * e, atol=1e-13)
        np.testing.assert_allclose(ball, arm_term + (thd + phd) * (l6 + l7) * e, atol=1e-13)
