"""The 1-DOF torsion models of bifilar.motion.lagrange against the thesis's printed formulas, numerical
integration of their own equations, their small-amplitude series and the full Kane engine."""

import dataclasses
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from bifilar.motion import lagrange as L
from bifilar.motion.modes import linearize
from bifilar.rig import RigError
from validate.assets import rig
from validate.engines.kane import run as kane_run
from validate.metrics import period as crossing_period

PARALLEL = L.from_rig(rig("parallel"))  # 2 kg box, D = 0.4 m, h = 1.5 m
PLATE = L.from_rig(rig("plate"))  # 100 kg plate, b = 10 m, D = 5 m, l = 5 m (splayed 30 deg)
CONVERGING = L.TorsionRig(mass=3.0, inertia=0.2, length=1.2, hook_span=0.3, attach_span=0.7)
RIGS = {"parallel": PARALLEL, "plate": PLATE, "converging": CONVERGING}
ACCELERATIONS = {False: L.dropped_acceleration, True: L.exact_acceleration}


def integrated_period(r, acceleration, amplitude):
    """Period from DOP853 at rtol 1e-13: twice the time between the first two zero crossings."""
    sol = solve_ivp(
        lambda t, y: [y[1], acceleration(r, y[0], y[1])],
        (0.0, 1.5 * L.period(r, amplitude, True)),
        [amplitude, 0.0],
        method="DOP853",
        rtol=1e-13,
        atol=1e-15 * amplitude,
        events=lambda t, y: y[0],
    )
    down, up = sol.t_events[0][:2]
    return 2.0 * (up - down)


def test_from_rig_reads_the_plate():
    assert (PLATE.hook_span, PLATE.attach_span, PLATE.length) == pytest.approx((10.0, 5.0, 5.0), rel=1e-15)
    assert PLATE.inertia == pytest.approx(100.0 * (2.5**2 + 5.0**2) / 12.0, rel=1e-15)
    assert PLATE.splay == pytest.approx(math.pi / 6.0, rel=1e-15)


def test_from_rig_names_the_asymmetric_field():
    with pytest.raises(RigError) as err:
        L.from_rig(rig("asymmetric"))
    assert err.value.source.endswith("asymmetric.toml") and err.value.field == "wire[2].length"


def test_wires_that_cannot_bridge_the_offset_are_refused():
    with pytest.raises(RigError, match="cannot bridge"):
        L.TorsionRig(mass=1.0, inertia=1.0, length=1.0, hook_span=3.0, attach_span=0.5)


def test_printed_5_2_17_and_5_2_18_are_the_linear_model():
    m, g, d, h, i = PARALLEL.mass, PARALLEL.gravity, PARALLEL.attach_span, PARALLEL.length, PARALLEL.inertia
    t_printed = 2.0 * math.pi / math.sqrt(m * g * d**2 / (4.0 * h * i))  # (5.2.17)
    assert L.linear_period(PARALLEL) == pytest.approx(t_printed, rel=1e-15)
    assert L.inertia_from_period(PARALLEL, t_printed) == pytest.approx(m * g * d**2 * t_printed**2 / (16 * h * math.pi**2), rel=1e-15)
    assert L.inertia_from_period(PARALLEL, t_printed) == pytest.approx(i, rel=1e-15)  # (5.2.18) inverts (5.2.17)
    # (5.2.15) integrated: its period is (5.2.17) at any amplitude, to the integrator's 1e-13.
    for amplitude in (1e-3, 1.0):
        assert integrated_period(PARALLEL, L.linear_acceleration, amplitude) == pytest.approx(t_printed, rel=1e-10)


def test_splayed_linear_period_matches_the_kane_linearisation():
    """T0 = 2 pi sqrt(4 H I / (m g b D)) for splayed wires (5.2.17 has D^2 and h); the Kane torsion
    mode comes from 4th-order differences good to ~1e-11 (tests/test_modes.py)."""
    modes = linearize(rig("plate")).modes
    torsion = [m for m in modes if abs(m.rotation[2]) > 0.99]
    assert len(torsion) == 1 and torsion[0].period == pytest.approx(L.linear_period(PLATE), rel=1e-10)


@pytest.mark.parametrize("name", RIGS)
@pytest.mark.parametrize("vertical_ke", [False, True])
def test_small_amplitude_series(name, vertical_ke):
    """T(a) / T0 - 1 = s a^2 + O(a^4); the a^4 coefficient is O(1) here (|s| < 1, b D / H^2 < 3)."""
    r = RIGS[name]
    s = L.period_amplitude_coefficient(r, vertical_ke)
    for a in (1e-3, 1e-2):
        excess = L.period(r, a, vertical_ke) / L.linear_period(r) - 1.0
        assert abs(excess - s * a**2) < 2.0 * a**4 + 1e-13  # + quadrature rtol


@pytest.mark.parametrize("name", RIGS)
@pytest.mark.parametrize("vertical_ke", [False, True])
@pytest.mark.parametrize("amplitude", [0.3, 1.0])
def test_quadrature_matches_integration(name, vertical_ke, amplitude):
    """Both are accurate to ~1e-13 (quadrature rtol; DOP853 rtol and event location)."""
    r = RIGS[name]
    integrated = integrated_period(r, ACCELERATIONS[vertical_ke], amplitude)
    assert L.period(r, amplitude, vertical_ke) == pytest.approx(integrated, rel=1e-9)


def test_adjusted_6_2_model_reduces_to_5_2_13_for_parallel_wires():
    theta = np.linspace(-3.0, 3.0, 601)
    np.testing.assert_allclose(
        L.dropped_acceleration(PARALLEL, theta, 0.0), L.printed_acceleration(PARALLEL, theta, 0.0), rtol=1e-14, atol=1e-16
    )
    with pytest.raises(RigError, match="parallel"):
        L.printed_acceleration(PLATE, 0.1, 0.0)


@pytest.mark.parametrize("name", ["plate", "converging"])
def test_printed_6_2_law_of_cosines_gives_the_lift(name):
    """The thesis's phi and z of ch. 6.2, transcribed; phi0 signed (< 0 for converging wires)."""
    r = RIGS[name]
    l, d, phi0 = r.length, r.attach_span, r.splay
    theta = np.linspace(0.0, 0.95 * r.max_amplitude, 200)
    chord = d * np.sin(theta / 2)
    horizontal = np.sqrt(chord**2 + (l * np.sin(phi0)) ** 2 - 2 * chord * l * np.sin(phi0) * np.cos(np.pi - (np.pi - theta) / 2))
    phi = np.arcsin(horizontal / l)
    z_printed = l * np.cos(phi0) - l * np.cos(phi)
    np.testing.assert_allclose(z_printed, L.lift(r, theta), rtol=1e-12, atol=1e-15 * l)


def test_lift_derivatives_are_consistent():
    """Central differences with step 1e-5: truncation ~1e-10, rounding ~1e-11 relative."""
    h = 1e-5
    for r in RIGS.values():
        theta = np.linspace(-0.8, 0.8, 81) * min(r.max_amplitude, 2.5)  # away from w = 0
        slope = (L.lift(r, theta + h) - L.lift(r, theta - h)) / (2 * h)
        curv = (L.lift_slope(r, theta + h) - L.lift_slope(r, theta - h)) / (2 * h)
        np.testing.assert_allclose(L.lift_slope(r, theta), slope, rtol=1e-8, atol=1e-12)
        np.testing.assert_allclose(L.lift_curvature(r, theta), curv, rtol=1e-8, atol=1e-12)


def test_exact_model_matches_the_kane_engine_on_the_thesis_plate():
    """The symmetric rig's torsion is one degree of freedom, so the exact model is the 6-DOF motion.

    Kane at rtol 1e-11, periods from crossings refined to ~1e-10: agreement to 1e-9. The model of
    ch. 6.2, which drops m z'^2 / 2, is 2.4 % short at 10 degrees on this rig (eps = 3.2).
    """
    amplitude = 0.1745
    traj = kane_run(rig("plate").with_initial(rotation=(0.0, 0.0, amplitude)), 6.0, dt_out=0.002, rtol=1e-11)
    q = traj["quat"]
    measured = crossing_period(traj.t, 2.0 * np.arctan2(q[:, 3], q[:, 0]), 0.0)
    assert measured.value == pytest.approx(L.period(PLATE, amplitude, True), rel=1e-9)
    assert measured.value / L.period(PLATE, amplitude, False) - 1.0 == pytest.approx(0.02411, abs=1e-5)


def test_dropped_vertical_energy_on_the_issue_rig():
    """2 kg, D = 0.4 m, h = 1.5 m, a 0.5 x 0.2 m box (I = 0.04833 kg m^2), a = 0.3 rad.

    Series: eps a^2 / 4 = 6.62e-4 with eps = m (D^2 / 4h)^2 / I; the O(a^4) rest lowers it by ~2 %.
    The issue's 6.3e-4 is 3 % below the exact 6.48e-4: it needs I = 0.0497 kg m^2.
    """
    a = 0.3
    shift = L.period(PARALLEL, a, True) / L.period(PARALLEL, a, False) - 1.0
    assert shift == pytest.approx(6.4835e-4, rel=1e-4)
    eps = PARALLEL.mass * (PARALLEL.attach_span**2 / (4 * PARALLEL.length)) ** 2 / PARALLEL.inertia
    assert shift == pytest.approx(eps * a**2 / 4, rel=0.03)
    heavier = dataclasses.replace(PARALLEL, inertia=0.04974)
    assert L.period(heavier, a, True) / L.period(heavier, a, False) - 1.0 == pytest.approx(6.3e-4, rel=1e-3)


def test_amplitude_beyond_reach_is_refused():
    with pytest.raises(ValueError, match="amplitude"):
        L.period(PLATE, PLATE.max_amplitude, True)


def test_from_rig_reads_a_symmetric_trifilar_as_the_same_law():
    """Three wires on one circle (R = 0.3 m, vertical, L = 1.5 m): the law with b = D = 2R. Its linear
    period is the N-wire linearisation's 2 pi sqrt(L I / (M g R^2)) to rounding, and a platform with
    its COM off the axis is refused (the torsion would swing)."""
    from bifilar.identification.identify import linear_period as modes_period

    tri = rig("trifilar")
    torsion = L.from_rig(tri)
    assert (torsion.hook_span, torsion.attach_span) == pytest.approx((0.6, 0.6), rel=1e-12)
    assert L.linear_period(torsion) == pytest.approx(modes_period(tri, "z"), rel=1e-13)
    with pytest.raises(RigError) as err:
        L.from_rig(rig("trifilar_offset"))
    assert err.value.field == "body.com"
