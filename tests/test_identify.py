"""Moments of inertia from periods (exact linearisation, amplitude correction, uncertainty) and from
wire tensions, against the Kane model's own simulated motion and the 1-DOF closed forms."""

import json
import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation
from scipy.stats import binom

from bifilar.identification import identify as ident
from bifilar.motion import lagrange
from bifilar.motion.kane import KaneModel
from bifilar.motion.modes import linearize
from bifilar.identification.propagation import LEVEL, coverage, linear, monte_carlo
from bifilar.rig import RigError, load_rig
from bifilar.motion.simulate import simulate
from bifilar.rig.statics import initial_state, length_errors
from bifilar.rig.statics import rest_pose as rest_pose_of
from bifilar.identification.tension_inertia import angular_acceleration, fit_inertia
from validate import cli
from validate.assets import RIGS, rig
from validate.cases.identify import SMALL, TABLE_7_1_1, thesis_rest

# A period simulated at 1e-6 rad is good to ~1e-8 (validate/cases/identify.py); a moment inherits
# that divided by d ln T / d ln I >= 0.06 here.
EXACT_RTOL = 1e-6


def test_mass_matrix_is_linear_in_the_moment():
    """M(J) = M(J0) + (J - J0) w w^T against linearize at J, also about a tilted (non-body) axis."""
    r = rig("asymmetric")
    for axis in ("x", "z", np.array([0.3, -0.5, 0.8])):
        p = ident.pencil(r, axis)
        for value in (0.6, 2.4):
            lin = linearize(ident.with_moment(r, axis, value), p.lin.rest)
            # both sides are sums of the same O(1) products: rounding only
            np.testing.assert_allclose(p.mass(value), lin.mass, rtol=0.0, atol=1e-13 * np.abs(lin.mass).max())


def test_a_principal_axis_changes_only_its_principal_moment():
    r = rig("asymmetric")
    moments, axes = np.linalg.eigh(r.inertia)
    changed = ident.with_moment(r, axes[:, 1], 1.7)
    np.testing.assert_allclose(np.linalg.eigvalsh(changed.inertia), [moments[0], 1.7, moments[2]], rtol=1e-14)
    body = ident.with_moment(r, "y", 1.7).inertia - r.inertia
    assert body[1, 1] == pytest.approx(1.7 - r.inertia[1, 1], rel=1e-14) and np.count_nonzero(body) == 1


@pytest.mark.parametrize("axis", ["x", "y", "z"])
def test_sensitivity_is_the_log_derivative_of_the_period(axis):
    """d ln T / d ln J = J (w . v)^2 / 2 (Hellmann-Feynman) against a central difference."""
    r = rig("asymmetric")
    found = ident.invert_period(r, axis, ident.linear_period(r, axis))
    h = 1e-5
    up, down = (ident.linear_period(ident.with_moment(r, axis, found.moment * (1 + s)), axis) for s in (h, -h))
    # central difference: truncation ~h^2, rounding ~1e-13 / h
    assert np.log(up / down) / (2 * h) == pytest.approx(found.sensitivity, rel=1e-6)


@pytest.mark.parametrize("name, axis", [("asymmetric", "x"), ("asymmetric", "y"), ("asymmetric", "z"),
                                        ("plate", "x"), ("parallel", "x"), ("bench_plate", "z")])
def test_inverting_a_simulated_period_recovers_the_moment(name, axis):
    r = rig(name)
    truth = 1.3 * ident.moment(r, axis)
    measured = ident.simulated_period(ident.with_moment(r, axis, truth), axis, SMALL)
    assert ident.invert_period(r, axis, measured).moment == pytest.approx(truth, rel=EXACT_RTOL)


@pytest.mark.parametrize("axis, factor", [("z", 0.5), ("x", 3.0)])
def test_the_rotation_about_an_axis_can_pass_to_another_mode(axis, factor):
    """In the asymmetric rig the mode turning most about z at 0.5 I_zz (or about x at 3 I_xx) comes
    from another mode of the rig file's inertia: followed from there it is found, ordering is not used."""
    r = rig("asymmetric")
    truth = factor * ident.moment(r, axis)
    true_rig = ident.with_moment(r, axis, truth)
    p0, p1 = ident.pencil(r, axis), ident.pencil(true_rig, axis)
    # modes come in order of period: the associated mode changes rank between the two inertias
    assert p0.associated(p0.moment0)[0] != p1.associated(p1.moment0)[0]
    found = ident.invert_period(r, axis, ident.linear_period(true_rig, axis))
    assert found.moment == pytest.approx(truth, rel=1e-10)  # linear period in, Newton to 1e-13 in ln T


def test_a_moment_no_mode_turns_about_is_refused():
    with pytest.raises(RigError) as err:  # parallel equal wires: the in-plane swing is a pure translation
        ident.invert_period(rig("parallel"), "y", 2.0)
    assert err.value.field == "axis"


def test_an_unreachable_period_is_refused():
    r = rig("bench_plate")
    # the pitch about y hardly depends on I_yy (d ln T / d ln I = 1.5e-4): at I_yy -> 0 its period
    # is only 1.5e-4 shorter, so 1e-3 shorter is out of reach of any moment
    with pytest.raises(RigError) as err:
        ident.invert_period(r, "y", 0.999 * ident.linear_period(r, "y"))
    assert err.value.field == "period" and "\n" not in str(err.value)


@pytest.mark.parametrize("name, axis, label, printed, coordinates", TABLE_7_1_1)
def test_table_7_1_1(name, axis, label, printed, coordinates):
    """The thesis's set-ups: from its printed estimate, the exact inversion of the simulated period
    lands on the analytical moment."""
    r = rig(name)
    rest = thesis_rest(name)
    if rest is not None:  # the level plate is a pose with both wires at length
        assert np.abs(length_errors(r, rest.com, rest.rotation)).max() < 1e-12
    measured = ident.simulated_period(r, axis, SMALL, rest)
    found = ident.invert_period(ident.with_moment(r, axis, printed), axis, measured, rest)
    assert found.moment == pytest.approx(ident.moment(r, axis), rel=EXACT_RTOL)
    # the thesis's estimates are off by 4.6e-3, 3.1e-2 and 3.8e-4 of the analytical values
    assert abs(printed / ident.moment(r, axis) - 1.0) > 100 * EXACT_RTOL


@pytest.mark.parametrize("name", ["parallel", "plate"])
def test_released_torsion_is_the_exact_one_dof_motion(name):
    """Released at 0.3 rad about the vertical, the Kane period equals bifilar.motion.lagrange's quadrature
    of the exact 1-DOF model: integrator rtol 1e-10, crossing fit ~1e-10, quadrature 1e-13."""
    r = rig(name)
    exact = lagrange.period(lagrange.from_rig(r), 0.3, vertical_ke=True)
    assert ident.simulated_period(r, "z", 0.3) == pytest.approx(exact, rel=1e-9)


def test_amplitude_coefficient_is_the_series_of_the_one_dof_model():
    r = rig("parallel")
    series = lagrange.period_amplitude_coefficient(lagrange.from_rig(r))
    # c from the ratio at 0.05 rad carries the A^4 term: (0.05)^2 d / c with d / c = O(1)
    assert ident.amplitude_coefficient(r, "z") == pytest.approx(series, rel=5e-3)


@pytest.mark.parametrize("axis", ["x", "z"])
def test_a_period_timed_at_an_amplitude_maps_to_the_right_moment(axis):
    r = rig("bench_plate")
    truth = 1.2 * ident.moment(r, axis)
    measured = ident.simulated_period(ident.with_moment(r, axis, truth), axis, 0.2)
    corrected = ident.identify(r, axis, measured, amplitude=0.2)
    # the truth is the fixed point (the same release is simulated at the answer), and it is followed
    # until the error left is under 1e-13 (identify.settled): 1e-12 allows the inversion's rounding
    assert corrected.moment == pytest.approx(truth, rel=1e-12)
    assert corrected.amplitude_ratio == pytest.approx(measured / ident.linear_period(corrected.rig, axis), rel=1e-12)
    # without the correction the error is ~2 c A^2 / (2 s) = 5e-3 here
    assert abs(ident.invert_period(r, axis, measured).moment / truth - 1.0) > 3e-3


def test_linear_and_monte_carlo_propagation_agree():
    r = rig("bench_plate")
    period = ident.linear_period(r, "z")
    lin = linear(r, "z", period, r.uncertainty.period)
    assert lin.moment == pytest.approx(ident.moment(r, "z"), rel=1e-12)
    assert sum(lin.budget.values()) == pytest.approx(1.0, rel=1e-12)
    # closed form for the dominant inputs: I ~ T^2 and I ~ m, so these shares are known exactly
    relative = lin.std / lin.moment
    assert lin.budget["period"] == pytest.approx((2 * r.uncertainty.period / period / relative) ** 2, rel=1e-3)
    assert lin.budget["mass"] == pytest.approx((r.uncertainty.mass / r.mass / relative) ** 2, rel=1e-3)
    mc = monte_carlo(r, "z", period, r.uncertainty.period, 100, np.random.default_rng(7))
    # sample std of 100 draws: relative standard error 1/sqrt(2 * 99) = 0.07; 3 of them
    assert mc.std == pytest.approx(lin.std, rel=0.21)
    assert mc.budget["anchor"] == pytest.approx(lin.budget["anchor"], abs=0.15)


@pytest.mark.slow
def test_the_95_percent_interval_covers_the_truth_95_percent_of_the_time():
    trials = 200
    result = coverage(rig("bench_plate"), "z", trials, np.random.default_rng(11))
    low, high = binom.interval(0.999, trials, LEVEL)  # a correct method fails this once in 1000 seeds
    assert low <= result.hits <= high
    # sample std of 200 normal estimates: relative standard error 0.05; 4 of them
    assert result.spread == pytest.approx(result.std, rel=0.2)


def _tension_fit(r, principal):
    run = simulate(KaneModel.from_rig(r), initial_state(r), 20.0, dt_out=0.01)
    inner = slice(2, -2)
    return fit_inertia(r, run.com[inner], run.rotation[inner], run.omega[inner],
                       angular_acceleration(run.t, run.omega), run.tension[inner], principal)


def test_tensions_give_every_entry_from_a_rich_motion():
    r = rig("asymmetric")  # products of inertia, turning about every axis
    fit = _tension_fit(r, principal=False)
    # alpha from 4th-order differences at >= 130 samples per period: ~1e-8 of alpha
    np.testing.assert_allclose(fit.inertia, r.inertia, rtol=0.0, atol=1e-6 * np.abs(r.inertia).max())
    assert fit.condition < 10.0


def test_torsion_alone_leaves_the_other_moments_undetermined():
    """The thesis's 7.2 experiment (theta4 = pi/12 on the plate): I_zz to ~1e-8, I_xx and I_yy lost."""
    r = rig("plate").with_initial((0.0, 0.0, np.pi / 12))
    fit = _tension_fit(r, principal=True)
    assert fit.inertia[2, 2] == pytest.approx(r.inertia[2, 2], rel=1e-6)
    assert fit.condition > 1e6
    assert fit.std["I_xx"] > r.inertia[0, 0] and fit.std["I_zz"] < 1e-6 * r.inertia[2, 2]


@pytest.fixture
def main():
    return cli.main


FIELDS = {"period", "period_std", "inertia", "std", "interval95", "inertia_per_mass", "std_per_mass", "amplitude",
          "damping", "law", "halves", "rejected", "residual_rms", "outliers", "trials", "between_trial_std",
          "chi2_per_dof"}
BENCH = str(RIGS / "bench_plate.toml")


def run_json(main, capsys, *args):
    assert main(["identify", *args, "--json"]) == 0
    text = capsys.readouterr().out
    assert "NaN" not in text and "Infinity" not in text  # JSON has neither
    return json.loads(text)


def test_cli_period_json(main, capsys):
    r = rig("bench_plate")
    out = run_json(main, capsys, BENCH, "--axis", "z", "--period", repr(ident.linear_period(r, "z")))
    assert FIELDS <= set(out) and out["flags"] == []
    assert out["inertia"] == pytest.approx(0.15, rel=1e-12) and out["method"] == "linear"
    assert out["period_std"] == r.uncertainty.period and max(out["budget"], key=out["budget"].get) == "anchor"
    # parallel-ish wires, symmetric body: I/m does not depend on the mass, so the mass's share vanishes
    assert out["inertia_per_mass"] == pytest.approx(0.15 / 4.0, rel=1e-12)
    assert out["budget_per_mass"]["mass"] < 1e-12 < out["budget"]["mass"]
    # the rig's sigma (common to all trials) and the period's (repeatability) add up to the total
    assert math.hypot(out["std_repeatability"], out["std_rig"]) == pytest.approx(out["std"], rel=1e-12)


def torsion_csv(tmp_path, name, amplitude, seed, noise=1e-3, axis="z"):
    """A recorded rotation about ``axis``: Kane, released at ``amplitude``, 30 s at 50 Hz, white noise."""
    r = rig("bench_plate")
    start = ident.released(r, axis, amplitude)
    run = simulate(start.model, start.state, 30.0, dt_out=0.02)
    angle = Rotation.from_matrix(run.rotation @ start.rest_rotation.T).as_rotvec() @ start.axis_world
    angle += noise * np.random.default_rng(seed).standard_normal(len(angle))
    path = tmp_path / name
    np.savetxt(path, np.column_stack([run.t, angle]), delimiter=",", header="t,angle", comments="")
    return str(path)


@pytest.mark.slow
def test_cli_signals_are_pooled_trials(main, capsys, tmp_path):
    """Two Kane records (0.1 and 0.8 rad) through the exact torsion law: each and the pooled moment
    within 3 sigma of the truth; the trials' chi^2 is reported."""
    paths = [torsion_csv(tmp_path, "a.csv", 0.1, 3), torsion_csv(tmp_path, "b.csv", 0.8, 4)]
    out = run_json(main, capsys, BENCH, "--axis", "z", "--signal", paths[0], "--signal", paths[1], "--law-sigma", "0")
    truth = ident.moment(rig("bench_plate"), "z")
    assert len(out["trials"]) == 2 and out["chi2_per_dof"] is not None and out["between_trial_std"] > 0.0
    for trial in out["trials"]:
        assert FIELDS - {"trials", "between_trial_std", "chi2_per_dof"} <= set(trial)
        assert abs(trial["inertia"] - truth) < 3.0 * trial["std"]
    assert out["trials"][1]["amplitude"][0] == pytest.approx(0.8, abs=1e-3)
    assert abs(out["inertia"] - truth) < 3.0 * out["std_repeatability"]
    assert out["amplitude"] is None  # per-record quantities live in the trials when there are several


@pytest.mark.slow
def test_cli_signal_about_a_swing_axis_uses_the_kane_series(main, capsys, tmp_path):
    """About x (the plate turning about the wire line, a swing, not a 1-DOF torsion) the law is the
    Kane model's period-amplitude series: at 0.3 rad its O(A^4) error is below the record's sigma."""
    path = torsion_csv(tmp_path, "x.csv", 0.3, 6, axis="x")
    out = run_json(main, capsys, BENCH, "--axis", "x", "--signal", path)
    trial = out["trials"][0]
    assert trial["law"]["kind"] == "series"
    assert abs(trial["inertia"] - ident.moment(rig("bench_plate"), "x")) < 3.0 * trial["std"]


def test_no_uncertainty_says_nothing_was_propagated(main, capsys):
    out = run_json(main, capsys, str(RIGS / "parallel.toml"), "--axis", "z", "--period", "2.0")
    assert out["std"] is None and out["interval95"] is None and out["budget"] is None
    assert any("nothing of the rig was propagated" in f for f in out["flags"])
    main(["identify", str(RIGS / "parallel.toml"), "--axis", "z", "--period", "2.0"])
    text = capsys.readouterr().out
    assert "no uncertainty propagated" in text and "+- 0 " not in text


@pytest.mark.parametrize("axis, period, flagged", [
    ("y", "2.83", ("95 % interval reaches", "triangle inequality", "hardly depends")),  # I_yy = 0.647 +- 0.584
    ("z", "150", ("triangle inequality",)),  # 839 kg m^2 for a 4 kg plate
])
def test_implausible_results_are_flagged(main, capsys, axis, period, flagged):
    out = run_json(main, capsys, BENCH, "--axis", axis, "--period", period)
    for words in flagged:
        assert any(words in f for f in out["flags"]), (words, out["flags"])
    assert out["tensor_check"]["triangle"] is False


def write_rig(tmp_path, inertia: str, mass="4.0", com="[0.0, 0.0, 0.0]", name="rig.toml"):
    text = (RIGS / "bench_plate.toml").read_text()
    text = text.replace("inertia = [0.030833333333333334, 0.12083333333333333, 0.15]", f"inertia = {inertia}")
    text = text.replace("mass = 4.0\n", f"mass = {mass}\n").replace("com = [0.0, 0.0, 0.0]", f"com = {com}")
    path = tmp_path / name
    path.write_text(text)
    return str(path)


@pytest.mark.parametrize("value", ["nan", "5.0"])  # unknown, or a start value breaking the triangle inequality
def test_the_identified_moment_needs_no_guess(main, capsys, tmp_path, value):
    path = write_rig(tmp_path, f"[0.030833333333333334, 0.12083333333333333, {value}]")
    out = run_json(main, capsys, path, "--axis", "z", "--period", repr(ident.linear_period(rig("bench_plate"), "z")))
    assert out["inertia"] == pytest.approx(0.15, rel=1e-10)
    assert out["tensor_check"] == {"principal": pytest.approx(sorted([0.030833333333333334, 0.12083333333333333, 0.15])),
                                   "positive_definite": True, "triangle": True}
    # other commands still need every moment, and the file's value is checked for them
    assert main(["modes", path]) == 2
    assert "body.inertia" in capsys.readouterr().err


def test_tare_and_parallel_axis_transfer(main, capsys, tmp_path):
    """bench_plate alone, and with a 1 kg object (own I_zz 0.01) on top at z = 0.05 m: the object's
    own moment from the two periods. The COMs lie on the axis, so the transfer terms vanish here and
    I_obj = I - I_fixture exactly."""
    fixture = rig("bench_plate")
    combined = write_rig(tmp_path, "[0.04, 0.13, 0.16]", mass="5.0", com="[0.0, 0.0, 0.01]", name="loaded.toml")
    period = ident.linear_period(load_rig(combined), "z")
    out = run_json(main, capsys, combined, "--axis", "z", "--period", repr(period), "--tare", BENCH,
                   "--tare-period", repr(ident.linear_period(fixture, "z")))
    assert out["object"]["mass"] == pytest.approx(1.0, rel=1e-12)
    assert out["object"]["com"] == pytest.approx([0.0, 0.0, 0.05], abs=1e-12)
    assert out["object"]["inertia"] == pytest.approx(0.01, rel=1e-8)
    assert out["object"]["std"] == pytest.approx(math.hypot(out["std"], out["tare"]["std"]), rel=1e-12)


@pytest.mark.parametrize("args, where", [
    (["--axis", "z", "--period", "0.01"], "identify: --period: 0.01 s: no moment"),
    (["--axis", "z", "--signal", "missing.csv"], "missing.csv: file:"),
    (["--axis", "z", "--period", "2.0", "--signal", "x.csv"], "not allowed with"),
    (["--axis", "z", "--period", "2.0", "--column", "angle"], "--column goes with --signal"),
    (["--axis", "z", "--period", "2.0", "--fps", "60"], "--fps goes with --signal"),
    (["--axis", "z", "--period", "2.0", "--tare-period", "2.0"], "go with --tare"),
    (["--axis", "w", "--period", "2.0"], "invalid choice"),
])
def test_cli_bad_input_is_one_line_and_status_2(main, capsys, args, where):
    assert main(["identify", BENCH, *args]) == 2
    err = capsys.readouterr().err
    assert where in err and err.count("\n") == 1


def test_cli_record_that_cannot_be_used_names_it(main, capsys, tmp_path):
    path = tmp_path / "noise.csv"
    t = np.arange(0.0, 30.0, 0.02)
    np.savetxt(path, np.column_stack([t, 1e-3 * np.random.default_rng(0).standard_normal(t.size)]), delimiter=",",
               header="t,angle", comments="")
    assert main(["identify", BENCH, "--axis", "z", "--signal", str(path)]) == 2
    err = capsys.readouterr().err
    # pure noise: no cycle looks like the rig's (or, where a few do, nothing stands out of the noise)
    assert f"{path}: angle: " in err and err.count("\n") == 1
    assert "no oscillation stands out of the noise" in err or "cycles could be measured on their own" in err


@pytest.mark.slow
def test_png_is_written(main, capsys, tmp_path):
    path = torsion_csv(tmp_path, "a.csv", 0.5, 5)
    png = tmp_path / "fit.png"
    assert main(["identify", BENCH, "--axis", "z", "--signal", path, "--png", str(png)]) == 0
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.slow
def test_cli_signal_of_a_trifilar_platform(main, capsys, tmp_path):
    """A trifilar video record: the N-wire model released at 0.5 rad, 20 cycles, frames at 120 fps with
    no time column, 0.005 rad of noise, an offset. The platform is symmetric, so the fit uses the exact
    torsion law (lagrange.from_rig with b = D = 2R); the moment lands within 3 sigma of the truth."""
    from bifilar.motion.nwire import simulate as nwire_simulate

    r = rig("trifilar")
    start = ident.released(r, "z", 0.5)
    run = nwire_simulate(start.model, start.state, 20 * start.period, dt_out=1.0 / 120.0, rtol=1e-10)
    angle = Rotation.from_matrix(run.rotation @ start.rest_rotation.T).as_rotvec() @ start.axis_world
    angle += 0.02 + 0.005 * np.random.default_rng(7).standard_normal(len(angle))
    path = tmp_path / "tri.csv"
    np.savetxt(path, np.column_stack([np.arange(len(angle)), angle]), delimiter=",", header="frame,angle",
               comments="", fmt=["%d", "%.9f"])
    out = run_json(main, capsys, str(RIGS / "trifilar.toml"), "--axis", "z", "--signal", str(path), "--fps", "120")
    trial = out["trials"][0]
    assert trial["law"]["kind"] == "exact"
    assert abs(trial["inertia"] - ident.moment(r, "z")) < 3.0 * trial["std"]


def test_a_yaw_degenerate_with_a_sway_keeps_its_sensitivity():
    """Vertical wires 0.5 m long, attachments 0.4 m and anchors 0.6 m apart under the parallel rig's
    box: its yaw has the period of its sway along y (1.4041004 s both; symmetry keeps them uncoupled).
    eigh mixes the pair arbitrarily (the rest pose found from a neighbour's gave d ln T / d ln J =
    0.437 instead of 0.5, and a sigma 14 % off); the pencil now splits the pair as a change of J does,
    so the yaw is the pure one, s = 1/2 to rounding, from either rest pose."""
    from bifilar.sweep.axes import configure

    base = load_rig(RIGS / "parallel_measured.toml")
    r = configure(base, {"wire_length": 0.5, "attach_span": 0.4, "anchor_span": 0.6})
    neighbour = rest_pose_of(configure(base, {"wire_length": 0.5, "attach_span": 0.4, "anchor_span": 0.4}))
    for rest in (rest_pose_of(r), rest_pose_of(r, neighbour)):
        p = ident.pencil(r, "z", rest)
        periods = sorted(2 * math.pi / np.sqrt(p.modes(p.moment0)[0]))
        assert periods[1] == pytest.approx(periods[2], rel=1e-12)  # the degenerate pair
        assert ident.predicted(r, p).sensitivity == pytest.approx(0.5, abs=1e-9)
