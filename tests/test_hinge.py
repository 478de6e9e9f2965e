"""Hinge rigs (bifilar/rig/hinge.py): the compound and torsion pendulum's exact periods against DOP853, the
cylinder's inertia against a volume integral, the identified moment and rod stiffness back from their
periods, the propagated sigma's partial derivatives against finite differences, and one-line refusals."""

import math
from dataclasses import replace

import numpy as np
import pytest

from bifilar.identification.hinge import law_for_hinge, moment_from_period, stiffness_from_period
from bifilar.identification.periods import period
from bifilar.motion.hinge import linear_period, moment_about_axis, period_at, simulate
from bifilar.rig import RigError, load_rig, rig_from_dict
from bifilar.rig.hinge import HingeUncertainty, cylinder_inertia
from validate.assets import RIGS

WHEEL = {  # a compound pendulum with an axis along no body axis, so every gradient component is non-zero
    "body": {"mass": 1.55, "com": [0.01, -0.02, 0.0], "inertia": [[0.1, 0.004, -0.002], [0.004, 0.05, 0.003],
                                                                   [-0.002, 0.003, 0.052]]},
    "pivot": {"point": [0.05, 0.03, 0.296], "axis": [1.0, 0.2, -0.1]},
    "uncertainty": {"mass": 0.01, "com": 0.001, "point": 0.002, "period": 0.003},
}
ROD = {"body": {"mass": 0.9944, "cylinder": {"radius": 0.00635, "length": 1.0}},
       "torsion": {"axis": [0.0, 0.0, 1.0], "stiffness": 11.71}, "uncertainty": {"mass": 0.001, "stiffness": 0.35}}


def _rig(data):
    return rig_from_dict(data, "test.toml", hinge=True)


def _simulated_period(rig, amplitude):
    """The mean period of eight cycles at rtol 1e-12, from the rising zero crossings of samples 400 per
    period (refined by a degree-5 polynomial: bifilar.identification.periods)."""
    t_exact = period_at(rig, amplitude)
    t, angle, _ = simulate(rig, amplitude, 8.2 * t_exact, t_exact / 400.0, rtol=1e-12)
    return period(t, angle, level=0.0).value


@pytest.mark.parametrize("amplitude", [0.1, 1.0, 2.5])
def test_the_simulated_period_is_the_elliptic_integral(amplitude):
    rig = _rig(WHEEL)
    # 1e-9: DOP853 at rtol 1e-12 keeps the phase to ~1e-11 over eight cycles, the crossing polynomial
    # is good to ~1e-11 of a period at 400 samples; 1e-9 leaves a hundredfold margin.
    assert _simulated_period(rig, amplitude) == pytest.approx(period_at(rig, amplitude), rel=1e-9)


def test_the_small_amplitude_limit():
    rig = _rig(WHEEL)
    t0 = linear_period(rig)
    # T(A) = T0 (1 + A^2 / 16 + 11 A^4 / 3072 + ...): at 1e-4 rad the A^2 term is 6e-10 and the next
    # 4e-19, so 1e-15 bounds the rest and the rounding.
    a = 1e-4
    assert period_at(rig, a) / t0 == pytest.approx(1.0 + a**2 / 16.0, rel=1e-15, abs=0.0)
    assert period_at(rig, 0.0) == t0
    # the closed form against the parallel axis theorem written out: J_p = e^T (I + m (|r|^2 1 - r r^T)) e
    r, e, m = rig.com - rig.point, rig.axis, rig.mass
    j_p = e @ (rig.inertia + m * (r @ r * np.eye(3) - np.outer(r, r))) @ e
    assert moment_about_axis(rig) == pytest.approx(j_p, rel=1e-14)  # the same sum in another order


def test_the_torsion_pendulum_is_isochronous():
    rig = _rig(ROD)
    t0 = linear_period(rig)
    # 1e-9 as for the compound pendulum (the linear solution is a cosine, just as smooth)
    for amplitude in (0.1, 1.0, 2.5):
        assert period_at(rig, amplitude) == t0
        assert _simulated_period(rig, amplitude) == pytest.approx(t0, rel=1e-9)
    assert law_for_hinge(rig).kind == "linear"
    law = law_for_hinge(_rig(WHEEL))  # theta'' = -omega^2 sin(theta): the exact law with rho = lam = 0
    theta = np.linspace(-2.5, 2.5, 11)
    assert np.allclose(law.acceleration(theta, 0.7 * theta, 3.0), -9.0 * np.sin(theta), rtol=1e-14, atol=1e-15)


@pytest.mark.parametrize("inner", [0.0, 0.004])
def test_the_cylinder_inertia_is_the_volume_integral(inner):
    """The tensor integrated over the volume in cylindrical coordinates (x along the axis, s, phi) by a
    Gauss-Legendre product rule: the integrands are polynomials in x and s and trigonometric in phi, so
    20 nodes in x and s and 16 equal steps in phi are exact to rounding, independent of the closed form."""
    mass, radius, length = 0.9944, 0.00635, 1.0
    nodes, weights = np.polynomial.legendre.leggauss(20)
    x, wx = 0.5 * length * nodes, 0.5 * length * weights
    s, ws = inner + 0.5 * (radius - inner) * (nodes + 1.0), 0.5 * (radius - inner) * weights
    phi = np.arange(16) * 2.0 * np.pi / 16
    X, S, P = np.meshgrid(x, s, phi, indexing="ij")
    dv = wx[:, None, None] * (ws * s)[None, :, None] * (2.0 * np.pi / 16)  # s ds dphi dx
    points = np.stack([X, S * np.cos(P), S * np.sin(P)], axis=-1)
    density = mass / float(np.sum(dv * np.ones_like(X)))
    tensor = np.empty((3, 3))
    for i in range(3):
        for k in range(3):
            integrand = (i == k) * np.sum(points**2, axis=-1) - points[..., i] * points[..., k]
            tensor[i, k] = density * np.sum(dv * integrand)
    # 1e-12 of the largest moment: the quadrature is exact, what is left is the rounding of 6400 terms
    assert np.allclose(cylinder_inertia(mass, radius, length, inner), tensor, rtol=1e-12, atol=1e-12 * tensor.max())


def test_a_simulated_part_is_identified_back():
    wheel = _rig(WHEEL)
    truth = float(wheel.axis @ wheel.inertia @ wheel.axis)
    # 1e-9: the exact period inverted by the same closed forms; what is left is the rounding of
    # m g d T0^2 / (4 pi^2) - m d^2, whose terms are ~2x the result here (J_p / J ~ 2)
    assert moment_from_period(wheel, period_at(wheel, 0.5), 0.5).moment == pytest.approx(truth, rel=1e-9)
    rod = _rig(ROD)
    truth = float(rod.axis @ rod.inertia @ rod.axis)
    assert moment_from_period(rod, linear_period(rod), 0.3).moment == pytest.approx(truth, rel=1e-12)
    calibration = _rig({**ROD, "torsion": {"axis": [0.0, 0.0, 1.0]}, "uncertainty": {"mass": 0.001}})
    # 1e-12: k = 4 pi^2 J / T0^2 of T0 = 2 pi sqrt(J / k), a few roundings
    assert stiffness_from_period(calibration, linear_period(rod)).stiffness == pytest.approx(11.71, rel=1e-12)


def _central(f, x, h):
    return (f(x + h) - f(x - h)) / (2.0 * h)


def test_the_propagated_gradient_is_the_finite_difference():
    wheel = _rig(WHEEL)
    amplitude, t = 0.5, 1.3 * period_at(wheel, 0.5)
    result = moment_from_period(wheel, t, amplitude)

    def moment(**change):
        return moment_from_period(replace(wheel, **change), t, amplitude).moment

    # central differences, steps 1e-5 of each quantity's scale: truncation ~1e-10 and rounding
    # ~1e-16 / 1e-5 = 1e-11 of the moment, both far below the 1e-6 asked
    checks = [("mass", _central(lambda m: moment(mass=m), wheel.mass, 1e-5 * wheel.mass)),
              ("period", _central(lambda p: moment_from_period(wheel, p, amplitude).moment, t, 1e-5 * t))]
    for group in ("com", "point"):
        base = getattr(wheel, group)
        for k in range(3):
            step = np.eye(3)[k] * 1e-5 * 0.3
            value = (moment(**{group: base + step}) - moment(**{group: base - step})) / (2.0 * 1e-5 * 0.3)
            checks.append((f"{group}[{k}]", value))
    for name, numeric in checks:
        group, k = (name[:-3], int(name[-2])) if "[" in name else (name, None)
        analytic = result.gradient[group] if k is None else result.gradient[group][k]
        assert analytic == pytest.approx(numeric, rel=1e-6), name
    sigma = math.sqrt(sum((np.sum(np.square(result.gradient[g])) * getattr(wheel.uncertainty, g) ** 2)
                          for g in ("mass", "com", "point", "period")))
    assert result.std == pytest.approx(sigma, rel=1e-14) and sum(result.budget.values()) == pytest.approx(1.0)
    assert set(result.as_dict()) >= {"moment", "std", "budget", "gradient", "period0"}

    rod = _rig(ROD)
    t = linear_period(rod)
    by_k = _central(lambda k: moment_from_period(replace(rod, stiffness=k), t).moment, 11.71, 1e-5 * 11.71)
    assert moment_from_period(rod, t).gradient["stiffness"] == pytest.approx(by_k, rel=1e-6)
    calibration = replace(rod, stiffness=None, uncertainty=HingeUncertainty(mass=0.001, period=0.001))
    k = stiffness_from_period(calibration, t)

    def by_mass(m):  # the rod's tensor scales with its mass at fixed shape
        return stiffness_from_period(replace(calibration, mass=m, inertia=rod.inertia * m / rod.mass), t).stiffness

    assert k.gradient["mass"] == pytest.approx(_central(by_mass, rod.mass, 1e-5 * rod.mass), rel=1e-6)
    by_t = _central(lambda p: stiffness_from_period(calibration, p).stiffness, t, 1e-5 * t)
    assert k.gradient["period"] == pytest.approx(by_t, rel=1e-6)


def _toml(tmp_path, text):
    path = tmp_path / "hinge.toml"
    path.write_text(text)
    return path


GOOD = """
[body]
mass = 1.55
inertia = [nan, 0.05, 0.05]
[pivot]
point = [0.0, 0.0, 0.296]
axis = [1.0, 0.0, 0.0]
"""
TORSION = GOOD.replace("[pivot]\npoint = [0.0, 0.0, 0.296]", "[torsion]\nstiffness = 11.71")


@pytest.mark.parametrize("text, field, words", [
    (GOOD + "[torsion]\naxis = [0.0, 0.0, 1.0]\n", "torsion", "not both"),
    (GOOD.replace("0.296", "1e-9"), "pivot.point", "no arm"),
    (GOOD.replace("axis = [1.0, 0.0, 0.0]", "axis = [0.0, 0.0, 0.0]"), "pivot.axis", "non-zero direction"),
    (TORSION.replace("11.71", "-1.0"), "torsion.stiffness", "positive"),
    (TORSION.replace("11.71", "1e7"), "torsion.stiffness", "outside"),
    (GOOD + "[[wire]]\nanchor = [0.0, 0.0, 1.0]\nattach = [0.0, 0.0, 0.1]\nlength = 0.9\n", "pivot", "not both"),
    (GOOD.replace("axis = [1.0, 0.0, 0.0]", "axis = [1.0, 0.1, 0.0]"), "body.inertia[0]", "finite"),
    (GOOD.replace("inertia = [nan, 0.05, 0.05]",
                  "inertia = [nan, 0.05, 0.05]\ncylinder = { radius = 0.3, length = 0.1 }"),
     "body.cylinder", "not both"),
    (GOOD + "[uncertainty]\nstiffness = 0.1\n", "uncertainty.stiffness", "no torsion.stiffness"),
    (GOOD.replace("[pivot]", "[pivot]\nlength = 1.0"), "pivot.length", "unknown key"),
])
def test_bad_input_is_one_line_naming_the_field(tmp_path, text, field, words):
    with pytest.raises(RigError) as info:
        load_rig(_toml(tmp_path, text), hinge=True)
    assert info.value.field == field and words in info.value.problem and "\n" not in str(info.value), str(info.value)


def test_a_wire_tool_refuses_a_hinge_rig_in_one_line(tmp_path):
    for name, kind in (("wheel_torsion", "torsion"), ("wheel_compound", "pivot"), ("calibration_rod", "torsion")):
        with pytest.raises(RigError) as info:
            load_rig(RIGS / f"{name}.toml")
        assert info.value.field == kind and "wire rigs only" in str(info.value) and "\n" not in str(info.value)
        assert load_rig(RIGS / f"{name}.toml", hinge=True).kind == kind
    wheel = load_rig(_toml(tmp_path, GOOD), hinge=True)
    with pytest.raises(RigError) as info:
        period_at(wheel, 3.2)
    assert info.value.field == "amplitude"
