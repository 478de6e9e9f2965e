"""Seed 001 (bifilar.seeds.seed001): the model files, the independently derived equations against MuJoCo,
the seed's printed equations against both, the seed's RK4 and the friction's coupling to MuJoCo."""

from __future__ import annotations

import itertools
import math

import mujoco
import numpy as np
import pytest

from bifilar.seeds.seed001 import integrate, seed
from bifilar.seeds.seed001.chain import Chain
from bifilar.seeds.seed001.params import Params, load_params
from validate.assets import MODELS
from validate.engines.seed001_mjcf import build_model
from validate.engines.seed001_mujoco import Prober, simulate

DIR = MODELS / "seed001"
EPS = float(np.finfo(float).eps)


@pytest.fixture(scope="module")
def params() -> Params:
    return load_params(DIR / "params.toml")


def random_params(rng: np.random.Generator, base: Params) -> Params:
    """Any plausible pendulum: masses 0.05..1 kg, arm lengths 0.1..0.5 m, weights anywhere on them."""
    a1, a2 = rng.uniform(0.1, 0.5, 2)
    return base.with_(
        m_arm1=rng.uniform(0.05, 1.0), a1=a1, b1=rng.uniform(0.0, 0.05), M=rng.uniform(0.05, 1.0),
        r1=rng.uniform(0.1, 0.5) * a1, m1=rng.uniform(0.05, 1.0), r_m1=rng.uniform(-0.5, 0.5) * a1,
        m_arm2=rng.uniform(0.05, 1.0), a2=a2, b2=rng.uniform(0.0, 0.05), m2=rng.uniform(0.05, 1.0),
        r_m2=rng.uniform(0.0, 0.5) * a2, k1=rng.uniform(0.0, 0.5), k2=rng.uniform(0.0, 0.5),
    )


def states(rng: np.random.Generator, n: int):
    return [(rng.uniform(-np.pi, np.pi, 2), rng.uniform(-40.0, 40.0, 2)) for _ in range(n)]


def test_xml_is_the_params_file(params):
    """The XML that opens in the viewer compiles to the model the builder makes from params.toml."""
    built = build_model(DIR / "seed001.xml", params)
    plain = mujoco.MjModel.from_xml_path(str(DIR / "seed001.xml"))
    for name in ("body_mass", "body_inertia", "body_pos", "body_ipos", "body_quat", "jnt_axis", "geom_size",
                 "key_qpos", "key_qvel"):
        # the XML's decimals of 1/12-fractions round differently from the builder's arithmetic: 1 ulp
        np.testing.assert_allclose(getattr(plain, name), getattr(built, name), rtol=4 * EPS, atol=1e-300, err_msg=name)
    assert (plain.opt.timestep, plain.opt.integrator) == (built.opt.timestep, built.opt.integrator)
    np.testing.assert_array_equal(plain.opt.gravity, built.opt.gravity)


def test_scene_steps_without_warnings():
    """The viewer's scene loads and runs 2 s from its keyframe with no MuJoCo warning."""
    model = mujoco.MjModel.from_xml_path(str(DIR / "scene.xml"))
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("initial").id)
    mujoco.mj_step(model, data, nstep=2000)
    assert all(w.number == 0 for w in data.warning)
    assert np.all(np.isfinite(data.qpos))


@pytest.mark.parametrize("seed_", range(4))
def test_chain_matches_mujoco(params, seed_):
    """The independent derivation's M, bias, friction and accelerations equal MuJoCo's, for random
    pendula at random states: each is a few dozen rounded products, ~1e-15 of its scale; 1e-12 leaves
    room for the 2x2 solve's conditioning (condition numbers below ~100 here)."""
    rng = np.random.default_rng(seed_)
    p = params if seed_ == 0 else random_params(rng, params)
    chain, probe = Chain.from_params(p), Prober(build_model(DIR / "seed001.xml", p), p)
    pairs = {"mass": [], "bias": [], "friction": [], "qacc": []}
    for q, qd in states(rng, 50):
        mj = probe(q, qd)
        pairs["mass"].append((chain.mass_matrix(q), mj.mass))
        pairs["bias"].append((chain.bias(q, qd), mj.bias))
        pairs["friction"].append((-chain.friction_matrix(q) @ qd, mj.friction))
        pairs["qacc"].append((np.array(chain.accel(*q, *qd)), mj.qacc))
    for name, pp in pairs.items():
        scale = max(np.abs(b).max() for _, b in pp)
        error = max(np.abs(a - b).max() for a, b in pp)
        assert error <= 1e-12 * scale, name


@pytest.mark.parametrize("seed_", range(3))
def test_printed_equations_equal_the_chain(params, seed_):
    """The seed's printed E_k, E_p, F, f and g (away from g's singular set) and g_fixed equal the
    independent derivation for random pendula: f and g are ~20 rounded terms over a denominator that
    cancels by at most ~100x here, hence 1e-12."""
    rng = np.random.default_rng(10 + seed_)
    p = params if seed_ == 0 else random_params(rng, params)
    c, chain = seed.Constants.from_params(p), Chain.from_params(p)
    for q, qd in states(rng, 100):
        args = (*q, *qd)
        a1, a2 = chain.accel(*args)
        scale = max(abs(a1), abs(a2), 1.0)
        assert seed.kinetic(c, *args) + seed.potential(c, *q) == pytest.approx(chain.energy(q, qd), rel=1e-13, abs=1e-15)
        assert seed.dissipation(c, *args) == pytest.approx(chain.dissipation(q, qd), rel=1e-13, abs=1e-15)
        assert abs(seed.f(c, *args) - a1) <= 1e-12 * scale
        assert abs(seed.g_fixed(c, *args) - a2) <= 1e-12 * scale
        if abs(2 * c.C - c.B * math.cos(q[1])) > 0.01 * 2 * c.C:
            assert abs(seed.g(c, *args) - a2) <= 1e-12 * scale


def test_printed_g_divides_by_zero_at_a_regular_configuration(params):
    """With B > 2C (params.toml), 2C - B cos(phi2) is exactly 0.0 at some phi2 within a few ulp of
    acos(2C/B): the printed g raises there, g_fixed gives MuJoCo's finite phi2''."""
    c = seed.Constants.from_params(params)
    assert c.B > 2 * c.C
    phi2 = math.acos(2 * c.C / c.B)
    for _ in range(64):
        if 2 * c.C - c.B * math.cos(phi2) == 0.0:
            break
        phi2 = math.nextafter(phi2, 0.0 if 2 * c.C - c.B * math.cos(phi2) < 0 else 4.0)
    else:
        pytest.fail("no exact zero of 2C - B cos(phi2) near acos(2C/B)")
    state = (0.7, phi2, 3.0, -5.0)  # Python floats, as the integrators pass them
    with pytest.raises(ZeroDivisionError):
        seed.g(c, *state)
    qacc = Prober(build_model(DIR / "seed001.xml", params), params)(np.array(state[:2]), np.array(state[2:])).qacc
    assert seed.g_fixed(c, *state) == pytest.approx(qacc[1], rel=1e-13)


@pytest.mark.parametrize("frictionless", [True, False])
def test_chain_energy_balance(params, frictionless):
    """The independent equations conserve E without friction and lose exactly the dissipated work
    W = integral of 2F with it: E + W, integrated as a fifth state by DOP853 at rtol 1e-12 over 10 s
    from the file's chaotic start, stays within (steps = nfev/12) x rtol x the energy's scale."""
    p = params.frictionless if frictionless else params
    chain = Chain.from_params(p)
    rhs = integrate.chain_rhs(chain)
    augmented = lambda y: np.append(rhs(y[:4]), 2 * chain.dissipation(y[:2], y[2:4]))
    sol = integrate.dop853(augmented, np.append(p.state0, 0.0), 10.0, 0.01, rtol=1e-12)
    total = np.array([chain.energy(y[:2], y[2:4]) + y[4] for y in sol.y])
    kinetic = max(chain.energy(y[:2], y[2:4]) - chain.energy(y[:2], 0 * y[2:4]) for y in sol.y)
    scale = 2 * kinetic + abs(chain.link.G1) + abs(chain.link.G2)
    assert frictionless or sol.y[-1, 4] > 0.1  # the friction does dissipate: 0.38 J in 10 s
    assert np.abs(total - total[0]).max() <= sol.nfev / 12 * 1e-12 * scale


def test_rk4_is_fourth_order(params):
    """Halving the seed's RK4 step divides its error after 0.5 s by 2^4 = 16. The next order adds
    O(w dt) <= 0.06 to the ratio (w <= 30 rad/s, dt <= 2 ms) and the largest error may move between
    samples: 10%. (Over 1 s the chaotic growth already mixes the samples: ratios 13-15.)"""
    p = params.frictionless
    rhs = integrate.seed_rhs(seed.Constants.from_params(p))
    exact = integrate.dop853(integrate.chain_rhs(Chain.from_params(p)), p.state0, 0.5, 0.1, rtol=1e-13).y
    errors = [np.abs(integrate.rk4(rhs, p.state0, 0.5, dt, 0.1).y - exact).max() for dt in (2e-3, 1e-3, 5e-4)]
    for coarse, fine in itertools.pairwise(errors):
        assert 16 / 1.1 <= coarse / fine <= 16 * 1.1


@pytest.mark.parametrize("k2", [0.0, 0.3])
def test_special_case_constant_absolute_rate(params, k2):
    """r_m2 = 0: arm 2's rate in the fixed frame is constant without friction and decays as
    exp(-k2 t) with it, by the independent equations (DOP853, 5 s: error ~ rtol x steps) and by the
    seed's special-case formulas, which equal the chain's accelerations at every state."""
    p = params.with_(r_m2=0.0, k2=k2, qd0=(1.0, 5.0))
    chain, c = Chain.from_params(p), seed.Constants.from_params(p)
    sol = integrate.dop853(integrate.chain_rhs(chain), p.state0, 5.0, 0.01, rtol=1e-12)
    omega = sol.y[:, 2] + sol.y[:, 3]
    np.testing.assert_allclose(omega, 6.0 * np.exp(-k2 * sol.t), rtol=1e-9)
    for y in sol.y[::50]:
        expected = chain.accel(*y)
        assert seed.special_f(c, *y) == pytest.approx(expected[0], rel=1e-12, abs=1e-12)
        assert seed.special_g(c, *y) == pytest.approx(expected[1], rel=1e-12, abs=1e-12)


def test_friction_held_per_step_is_first_order(params):
    """Holding the friction in qfrc_applied over each RK4 step (the alternative to the per-stage
    callback) errs by O(k dt): halving dt halves it (ratio 2 within 10%: the O(dt^2) remainder is
    ~k dt ~ 1e-4 relative, chaos over 0.5 s amplifies both alike). The callback is restored after."""
    errors = []
    for dt in (1e-3, 5e-4):
        model = build_model(DIR / "seed001.xml", params, timestep=dt)
        staged, held = simulate(model, params, 0.5, 0.01), simulate(model, params, 0.5, 0.01, per_step=True)
        errors.append(np.abs(held.q - staged.q).max())
    assert 1.8 <= errors[0] / errors[1] <= 2.2
    assert mujoco.get_mjcb_passive() is None


def test_params_file_is_checked(tmp_path, params):
    text = (DIR / "params.toml").read_text()
    bad = tmp_path / "bad.toml"
    bad.write_text(text.replace("mass = 0.15", "mass = -0.15"))
    with pytest.raises(ValueError, match="weight2.mass"):
        load_params(bad)
    bad.write_text(text.replace("k2 = 0.10", "k3 = 0.10"))
    with pytest.raises(ValueError, match=r"\[friction\]"):
        load_params(bad)
