"""The air model (bifilar.rig.air) and its use in the Kane equations, MuJoCo and identify."""

import json
import tomllib
from dataclasses import replace

import mujoco
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from bifilar.rig.air import (
    added_mass,
    added_mass_principal,
    drag_wrench,
    fluid_drag,
    fluid_momentum,
    lamb_coefficients,
)
from bifilar.motion import kane_kernel as K
from bifilar.motion.kane import KaneModel
from bifilar.motion.simulate import simulate
from bifilar.rig import load_rig, rig_from_dict
from bifilar.rig.statics import initial_state
from validate.assets import RIGS
from validate.cli import main
from validate.engines.kane import run as kane_run
from validate.metrics import yaw

WING = (RIGS / "foam_wing.toml").read_text()


@pytest.mark.parametrize("semi", [(1.0, 2.0, 3.0), (0.75, 0.02, 0.18), (5.0, 1.0, 1.0)])
def test_lamb_coefficients_sum_to_two(semi):
    # alpha0 + beta0 + gamma0 = 2 for every ellipsoid (Lamb §114): an identity the integrals must keep.
    assert lamb_coefficients(semi).sum() == pytest.approx(2.0, rel=1e-13)


def test_sphere_and_thin_disc_limits():
    a, rho = 0.4, 1.2
    sphere = added_mass_principal([a, a, a], rho)
    assert sphere[:3] == pytest.approx(np.full(3, 0.5 * rho * 4 / 3 * np.pi * a**3), rel=1e-14)
    assert np.all(sphere[3:] == 0.0)  # a turning sphere moves no fluid in potential flow
    disc = added_mass_principal([a, a, 1e-7 * a], rho)
    assert disc[2] == pytest.approx(8 / 3 * rho * a**3, rel=1e-6)  # O(c/a) from the disc
    assert disc[3] == pytest.approx(16 / 45 * rho * a**5, rel=1e-6)


def test_tensor_about_the_com_is_the_fluid_energy_of_the_ellipsoid_motion():
    # 1/2 x^T M_A x about the COM must equal the energy computed from the ellipsoid centre's own velocity.
    r = load_rig(RIGS / "foam_wing.toml")
    rot = Rotation.from_rotvec([0.3, -0.2, 0.5]).as_matrix()
    air = replace(r.air, center=np.array([0.1, -0.05, 0.2]), axes=rot)
    com = np.array([0.02, 0.01, -0.03])
    rng = np.random.default_rng(0)
    for _ in range(5):
        v, w = rng.normal(size=3), rng.normal(size=3)
        v_c = rot.T @ (v + np.cross(w, air.center - com))
        x_e = np.concatenate([v_c, rot.T @ w])
        direct = 0.5 * x_e @ (added_mass_principal(air.semi_axes, air.density) * x_e)
        x = np.concatenate([v, w])
        assert 0.5 * x @ added_mass(air, com) @ x == pytest.approx(direct, rel=1e-13)


def test_drag_is_mujocos_fluid_force_less_its_added_mass_velocity_terms():
    # MuJoCo's ellipsoid model, Kutta and Magnus off, applies drag + viscous terms + Kirchhoff's velocity
    # products (m_A v) x w and (m_A v) x v + (I_A w) x w (fluid.rst); the rest must be our drag.
    semi, rho, mu, coef = np.array([0.5, 0.1, 0.25]), 1.2, 1.8e-5, (0.5, 0.25, 1.5)
    xml = f"""<mujoco><option density="{rho}" viscosity="{mu}" gravity="0 0 0"/><worldbody><body>
      <freejoint/><inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/>
      <geom type="ellipsoid" size="{semi[0]} {semi[1]} {semi[2]}" fluidshape="ellipsoid"
            fluidcoef="{coef[0]} {coef[1]} {coef[2]} 0 0" contype="0" conaffinity="0"/></body></worldbody></mujoco>"""
    model = mujoco.MjModel.from_xml_string(xml)
    data = mujoco.MjData(model)
    q = np.concatenate([semi, [rho, mu], coef])
    ma = model.geom_fluid[0, 6:12] * rho  # MuJoCo's own (quadrature) added masses, to isolate the drag
    rng = np.random.default_rng(1)
    for _ in range(5):
        v, w = rng.normal(size=3), rng.normal(size=3)
        data.qvel[:] = np.concatenate([v, w])  # body at the origin, unrotated: world = body axes
        mujoco.mj_forward(model, data)
        gyro_f = np.cross(ma[:3] * v, w)
        gyro_g = np.cross(ma[:3] * v, v) + np.cross(ma[3:] * w, w)
        f, g = drag_wrench(v, w, q)
        assert data.qfrc_passive[:3] - gyro_f == pytest.approx(f, rel=1e-10, abs=1e-15)
        assert data.qfrc_passive[3:] - gyro_g == pytest.approx(g, rel=1e-10, abs=1e-15)


def test_kane_in_air_without_drag_keeps_body_plus_fluid_energy():
    # No drag: the fluid is conservative, so body + fluid kinetic energy + potential is constant. A
    # general tumbling start exercises every block of the 6x6 tensor and its velocity terms.
    r = load_rig(RIGS / "foam_wing.toml")
    air = replace(r.air, drag=np.zeros(3), viscosity=0.0, center=np.array([0.05, 0.0, 0.03]),
                  axes=Rotation.from_rotvec([0.1, 0.2, 0.3]).as_matrix())
    rr = replace(r, air=air).with_initial(rotation=(0.05, 0.02, 0.1), omega=(0.1, 0.2, 0.3))
    run = simulate(KaneModel.from_rig(rr), initial_state(rr), 3.0, 0.01)
    assert np.ptp(run.energy) < 1e-9 * run.energy[0]  # integration at rtol 1e-10 (measured 6e-11)
    with_drag = simulate(KaneModel.from_rig(replace(rr, air=r.air)), initial_state(rr), 3.0, 0.01)
    assert np.all(np.diff(with_drag.energy) < 1e-12)  # drag only ever takes energy out


def test_the_functions_for_other_models_are_the_kernels_terms():
    # fluid_momentum and fluid_drag (world frame, for the N-wire model) against the Kane kernel's own.
    r = load_rig(RIGS / "foam_wing.toml")
    rr = replace(r, com=np.array([0.01, 0.02, -0.03]),
                 air=replace(r.air, center=np.array([0.05, 0.0, 0.03]), axes=Rotation.from_rotvec([0.1, 0.2, 0.3]).as_matrix()))
    model = KaneModel.from_rig(rr)
    theta, dtheta = np.array([0.1, 0.3, 0.2, 0.05, 0.02]), np.array([0.2, -0.1, 0.3, 0.1, 0.0])
    state = model.state(theta, dtheta)
    R_n = K.kinematics(theta, dtheta, model.p, 0)[1]
    maw, _, drag = K.air_terms(R_n, state.velocity, state.omega, model.p)
    x = np.concatenate([state.velocity, state.omega])
    assert fluid_momentum(rr.air, rr.com, state.rotation, state.velocity, state.omega) == pytest.approx(maw @ x, rel=1e-12)
    force, torque = fluid_drag(rr.air, rr.com, state.rotation, state.velocity, state.omega)
    assert np.concatenate([force, torque]) == pytest.approx(drag, rel=1e-12, abs=1e-18)


def test_a_box_is_its_inscribed_ellipsoid():
    ellipsoid = load_rig(RIGS / "foam_wing.toml")
    text = WING.replace('shape = "ellipsoid"', 'shape = "box"').replace("size = [0.75, 0.02, 0.18]", "size = [1.5, 0.04, 0.36]")
    assert np.array_equal(rig_from_dict(tomllib.loads(text)).air.semi_axes, ellipsoid.air.semi_axes)


def test_vacuum_rig_has_no_air_in_the_kernel():
    m = KaneModel.from_rig(load_rig(RIGS / "plate.toml"))
    assert m.p.shape == (K.P_SIZE,) and np.all(m.p[K.P_AIR :] == 0.0)  # the air branch is skipped


def test_bad_air_table_is_one_line(tmp_path, capsys):
    path = tmp_path / "wing.toml"
    for bad, field in ((WING.replace('shape = "ellipsoid"', 'shape = "cone"'), "air.shape"),
                       (WING.replace("density = 1.204", "density = -1.0"), "air.density"),
                       (WING.replace("size = [0.75, 0.02, 0.18]", "size = [0.75, 0.0, 0.18]"), "air.size[1]"),
                       (WING.replace("density = 1.204", "density = 1.204\nwind = 3"), "air.wind")):
        path.write_text(bad)
        assert main(["modes", str(path)]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and str(path) in err and field in err


@pytest.mark.slow
def test_identify_recovers_the_wings_own_inertia_from_a_record_in_air(tmp_path, capsys):
    # A Kane record of the wing in air (added mass and drag) with 2e-4 rad of tracker noise: the
    # apparent moment holds the air; subtracting it must give the body's own I_zz within its sigma.
    r = load_rig(RIGS / "foam_wing.toml")
    traj = kane_run(r, 20.0, 0.02, 1e-10)
    angle = yaw(traj) + np.random.default_rng(1).normal(0.0, 2e-4, len(traj.t))
    record = tmp_path / "wing.csv"
    np.savetxt(record, np.column_stack([traj.t, angle]), delimiter=",", header="t,angle", comments="")
    assert main(["identify", str(RIGS / "foam_wing.toml"), "--axis", "z", "--signal", str(record), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    own = r.inertia[2, 2]
    assert abs(report["inertia_without_air"] - own) < report["inertia_without_air_std"]
    assert abs(report["inertia"] - own) > 10 * report["std"]  # the apparent moment is not the body's
    assert 0.10 < report["air_share"] < 0.25


def test_the_nwire_model_in_air_agrees_with_the_kane_model():
    """The foam wing (two wires, added mass and drag) twisted 0.1 rad: the N-wire model with the air
    (Newton-Euler, the fluid's M_A,w in the mass matrix, its velocity terms and drag applied) against
    the Kane model with the air (generalised inertia and active forces) over 2 s: both integrate at
    rtol 1e-10, so they agree to ~1e-10 (measured 2.4e-12 m, 1.1e-12 of the tension)."""
    from validate.assets import rig as shipped
    from validate.engines import kane as kane_engine
    from validate.engines import nwire as nwire_engine

    wing = shipped("foam_wing").with_initial(rotation=(0.0, 0.0, 0.1))
    a, b = kane_engine.run(wing, 2.0, 0.01), nwire_engine.run(wing, 2.0, 0.01)
    assert np.abs(a["com"] - b["com"]).max() < 1e-9
    assert np.abs(a["quat"] - b["quat"]).max() < 1e-9
    assert np.abs(a["tension"] - b["tension"]).max() < 1e-8 * np.abs(a["tension"]).max()
    assert np.abs(a["energy"] - b["energy"]).max() < 1e-9 * wing.mass * wing.gravity  # fluid KE included in both
    assert a["energy"][0] - a["energy"][-1] > 1e-4  # the drag dissipates: not a vacuum run
