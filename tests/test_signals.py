"""The record fit on synthetic records whose truth is known: the fit's own oscillator, the exact
torsion law at large amplitude with a stronger real amplitude dependence, glitches, a superposed
mode, coloured noise, and the honesty of the reported standard deviation."""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.stats import binom

from bifilar.identification import signals as S
from bifilar.identification import synthetic as Y
from bifilar.identification.records import unfold
from bifilar.motion import lagrange as L
from validate.assets import rig

TRUE_PERIOD, ZETA, QUADRATIC = 1.7, 0.003, 0.05  # s, -, 1/rad
OMEGA = 2.0 * math.pi / TRUE_PERIOD
OFFSET, DRIFT = 0.02, 5e-4  # rad, rad/s (tracker zero, slow drift)
BENCH = L.from_rig(rig("bench_plate"))
LAW = S.AmplitudeLaw.torsion(BENCH)


def damped(span):
    """Dense solution of Jardin & Mueller's linear oscillator with viscous and quadratic damping from
    (0.15 rad, 0), DOP853 at rtol 1e-12: the truth to ~1e-11, far below any fit's sigma here."""
    return solve_ivp(lambda t, y: [y[1], -2 * ZETA * OMEGA * y[1] - QUADRATIC * abs(y[1]) * y[1] - OMEGA**2 * y[0]],
                     (0.0, span), [0.15, 0.0], method="DOP853", rtol=1e-12, atol=1e-14, dense_output=True).sol


TRUTH = damped(27.0)


def jm_record(rng, noise, kind="angle", span=25.0, rate=18.0):
    """The oscillator at nominal ``rate`` Hz with +-40 % jitter and 10 % of the samples dropped."""
    n = int(span * rate)
    t = 0.37 + (np.arange(n) + rng.uniform(-0.4, 0.4, n)) / rate
    t = t[rng.uniform(size=n) > 0.1]
    clean = TRUTH(t - 0.37)[0 if kind == "angle" else 1]
    return t, OFFSET + DRIFT * (t - t[0]) + clean + noise * rng.standard_normal(len(t))


def test_fit_recovers_period_damping_offset_and_drift():
    rng = np.random.default_rng(7)
    t, y = jm_record(rng, noise=0.003)
    fit = S.fit_oscillation(t, y, "angle")
    # A single draw: each estimate within 3 sigma of the truth (probability ~0.997 per quantity).
    assert abs(fit.period - TRUE_PERIOD) < 3 * fit.period_std
    assert abs(fit.zeta - ZETA) < 3 * fit.zeta_std
    assert abs(fit.quadratic - QUADRATIC) < 3 * fit.quadratic_std
    assert abs(fit.offset - OFFSET) < 3 * fit.std["offset"]
    assert abs(fit.drift - DRIFT) < 3 * fit.std["drift"]
    # white noise of 0.003 rad, ~420 samples: rms within 4 standard errors (1 / sqrt(2 n) relative)
    assert fit.rms == pytest.approx(0.003, rel=4 / math.sqrt(2 * fit.samples))
    assert fit.block == 1 and fit.outliers.size == 0 and fit.second_mode is None


def test_gyro_rate_signal():
    rng = np.random.default_rng(11)
    t, y = jm_record(rng, noise=0.01, kind="rate", rate=50.0)
    fit = S.fit_oscillation(t, y, "rate")
    assert abs(fit.period - TRUE_PERIOD) < 3 * fit.period_std
    assert abs(fit.quadratic - QUADRATIC) < 3 * fit.quadratic_std


def test_reported_period_std_is_honest_for_white_noise():
    """Coverage of +-2 sigma over 200 records: Binomial(200, 0.9545), central 99.8 % accepted."""
    rng = np.random.default_rng(2024)
    trials, z = 200, []
    for _ in range(trials):
        t, y = jm_record(rng, noise=0.004, span=20.0, rate=15.0)
        fit = S.fit_oscillation(t, y, "angle", second_mode=False)
        z.append((fit.period - TRUE_PERIOD) / fit.period_std)
    z = np.array(z)
    p = math.erf(2.0 / math.sqrt(2.0))
    assert binom.ppf(0.001, trials, p) <= int(np.sum(np.abs(z) < 2.0)) <= binom.ppf(0.999, trials, p)
    assert abs(z.mean()) < 3.0 / math.sqrt(trials)  # no bias beyond 3 standard errors of the mean


def test_exact_law_coefficient_is_the_lagrange_series():
    omega = 2.0 * math.pi / L.linear_period(BENCH)
    assert LAW.coefficient(omega) == pytest.approx(L.period_amplitude_coefficient(BENCH), rel=1e-12)
    # the law's own T(A)/T0, integrated by the fit's RK4 kernel, against the quadrature
    for a in (0.3, 1.0, 1.4):
        assert LAW.ratio(a, omega) == pytest.approx(L.period(BENCH, a) / L.linear_period(BENCH), rel=1e-9)


def test_large_release_with_a_stronger_amplitude_dependence():
    """1.4 rad decaying over 100 cycles (60 fps video, coloured noise, glitches, gaps), the real
    rig's s 30 % above the ideal one: T0 and s within 3 sigma; the start cannot slip a cycle."""
    rec = Y.torsion_record(BENCH, np.random.default_rng(4), amplitude=1.4, cycles=100, excess=0.3, zeta=5e-4,
                           quadratic=0.01)
    fit = S.fit_oscillation(rec.frames / rec.fps, rec.values, "angle", LAW)
    assert abs(fit.period - rec.period) < 3 * fit.period_std
    s_true = 1.3 * L.period_amplitude_coefficient(BENCH)
    assert abs(fit.amplitude_coefficient - s_true) < 3 * fit.amplitude_coefficient_std
    assert fit.amplitude[0] == pytest.approx(1.4, abs=0.01) and 0.15 < fit.amplitude[1] < 0.5
    # the same record under the ideal law alone (the excess held at 0) is biased by many sigmas
    ideal = S.AmplitudeLaw("series", s=L.period_amplitude_coefficient(BENCH))
    plain = S.fit_oscillation(rec.frames / rec.fps, rec.values, "angle", ideal, second_mode=False)
    assert abs(plain.period - rec.period) > 3 * fit.period_std


def test_glitches_are_rejected_and_reported():
    rng = np.random.default_rng(8)
    rec = Y.torsion_record(BENCH, rng, amplitude=0.5, cycles=20, glitches=0.01, glitch=0.3, colour=0.0)
    fit = S.fit_oscillation(rec.frames / rec.fps, rec.values, "angle", LAW)
    clean = Y.torsion_record(BENCH, np.random.default_rng(8), amplitude=0.5, cycles=20, glitches=0.01, glitch=0.0,
                             colour=0.0)
    glitched = rec.frames[np.abs(rec.values - clean.values) > 0.1] / rec.fps
    # every 0.3 rad glitch (43 noise sigmas) is found, and nothing else beyond 6 sigmas of noise
    np.testing.assert_array_equal(np.sort(fit.outliers), glitched)
    assert abs(fit.period - rec.period) < 3 * fit.period_std


def test_pixel_tracker_with_a_superposed_swing():
    """x pixels at 240 fps, 300 px/rad (unknown to the fit), the pendulum swing superposed."""
    rng = np.random.default_rng(9)
    rec = Y.torsion_record(BENCH, rng, amplitude=0.3, cycles=25, fps=240.0, kind="proportional", noise=0.004,
                           second=(2.9, 40.0))
    fit = S.fit_oscillation(rec.frames / rec.fps, rec.values, "proportional", LAW)
    assert abs(fit.period - rec.period) < 3 * fit.period_std
    assert fit.second_mode is not None and fit.second_mode[0] == pytest.approx(2.9, rel=2e-3)


def test_folded_line_tracker_record():
    rec = Y.torsion_record(BENCH, np.random.default_rng(12), amplitude=0.9, cycles=30, fold=True)
    y, jumps = unfold(rec.values)
    assert jumps > 0
    fit = S.fit_oscillation(rec.frames / rec.fps, y, "angle", LAW)
    assert abs(fit.period - rec.period) < 3 * fit.period_std


def test_two_halves_of_a_record_agree_within_their_sigmas():
    """A 120-cycle record with strongly coloured noise: its first and second half, fitted alone,
    agree within 3 combined sigmas; the white-noise sigma would be too small by the block factor."""
    rec = Y.torsion_record(BENCH, np.random.default_rng(21), amplitude=1.0, cycles=120, colour=0.9, excess=0.2,
                           zeta=4e-4, quadratic=0.01)
    t = rec.frames / rec.fps
    half = t < 0.5 * t[-1]
    a = S.fit_oscillation(t[half], rec.values[half], "angle", LAW)
    b = S.fit_oscillation(t[~half], rec.values[~half], "angle", LAW)
    assert abs(a.period - b.period) < 3.0 * math.hypot(a.period_std, b.period_std)
    assert a.block > 1 and a.period_std > 1.5 * a.period_std_white  # AR(1) at 0.9: variance x 19


def test_interval_coverage_on_records_with_every_trait():
    """20 short records drawn with the issue's traits: 95 % intervals hold the truth within the
    Binomial(20, 0.95) 99.9 % range; the 200-record run is the case identify-record-coverage (--slow)."""
    rng = np.random.default_rng(31)
    hits, trials = 0, 20
    for _ in range(trials):
        rec = Y.torsion_record(BENCH, rng, **Y.random_traits(rng, max_cycles=15))
        y, _ = unfold(rec.values)
        fit = S.fit_oscillation(rec.frames / rec.fps, y, "angle", LAW)
        hits += abs(fit.period - rec.period) <= 1.96 * fit.period_std
    low, high = binom.interval(0.999, trials, 0.95)
    assert low <= hits <= high


def test_too_few_cycles_is_refused():
    t = np.linspace(0.0, 1.0, 200)
    with pytest.raises(ValueError, match="cycles"):
        S.fit_oscillation(t, np.cos(2.0 * t), "angle")


def test_noise_alone_is_refused():
    """White noise has a "best" period too; the fit must say there is no oscillation instead."""
    rng = np.random.default_rng(0)
    t = np.arange(0.0, 30.0, 0.02)
    with pytest.raises(ValueError, match="no oscillation stands out of the noise"):
        S.fit_oscillation(t, 0.01 + 1e-3 * rng.standard_normal(t.size), "angle")


def test_undamped_coupled_mode_is_fitted_not_refused():
    """A Kane record of the bench plate's tilt about body x (a coupled mode, the series law), released
    at 0.1 rad, undamped, 25 cycles at 60 samples per period, 0.005 rad of white noise: swing / noise
    ~14. With damping coefficients free to go negative, a short first window at constant amplitude
    let them cancel (zeta -0.1, quadratic +2.5) and the longer windows ran to a wrong minimum, refusing
    this noise draw as "no oscillation stands out of the noise (1.4 < 3)". Both are now >= 0 (a free
    oscillation loses energy), and the period comes out within its sigma (3 sigma: a 0.3 % chance)."""
    from scipy.spatial.transform import Rotation

    from bifilar.identification import identify as ident
    from bifilar.identification.trials import law_for
    from bifilar.motion.simulate import simulate

    plate = rig("bench_plate")
    start = ident.released(plate, "x", 0.1)
    run = simulate(start.model, start.state, 25 * start.period, dt_out=start.period / 60, rtol=1e-10)
    angle = Rotation.from_matrix(run.rotation @ start.rest_rotation.T).as_rotvec() @ start.axis_world
    rng = np.random.default_rng(1)
    rng.standard_normal(len(angle))  # the draw that failed is the second of this seed
    fit = S.fit_oscillation(run.t, angle + 0.005 * rng.standard_normal(len(angle)), "angle", law_for(plate, "x"))
    assert fit.zeta >= 0.0 and fit.quadratic >= 0.0
    # T0 is the mode's linear period; the series law is right to O(s^2 A^4) ~ 1e-6 of it
    assert abs(fit.period - start.period) < 3.0 * fit.period_std + 1e-5 * start.period


def test_matched_quintic_holds_both_ends_of_the_amplitude_range():
    """A series law with its quintic matched at A: T(A)/T0 equals the target there (to the match's
    1e-9), and at 0.05 rad it is the cubic law's to O(q A^4) = O(1e-7) (the quintic leaves s alone)."""
    law = S.AmplitudeLaw("series", s=0.086)
    omega = 5.68
    target = law.ratio(0.8, omega) + 0.002
    matched = law.matched(0.8, target, omega)
    assert matched.ratio(0.8, omega) == pytest.approx(target, abs=1e-9)
    assert matched.ratio(0.05, omega) == pytest.approx(law.ratio(0.05, omega), abs=1e-7)
    assert matched.coefficient(omega) == law.coefficient(omega)


def test_coupled_mode_at_large_amplitude_uses_the_kane_models_amplitude_law():
    """The bench plate's tilt about body x released at 0.8 rad (a coupled mode: the series law),
    undamped, noise-free, 25 cycles: the O(A^2) law alone biased the moment by -1.07e-2; with its
    quintic matched to the Kane model's T(A)/T0 at the record's start amplitude the bias is -5.6e-4
    (what is left: the coupled waveform and the slow exchange with the other modes over 25 cycles
    against the 8 the match is timed over). 2e-3 bounds it and fails the O(A^2) law by five times."""
    from scipy.spatial.transform import Rotation

    from bifilar.identification import identify as ident
    from bifilar.identification.records import Record
    from bifilar.identification.trials import fit_trial
    from bifilar.motion.simulate import simulate

    plate = rig("bench_plate")
    start = ident.released(plate, "x", 0.8)
    run = simulate(start.model, start.state, 25 * start.period, dt_out=start.period / 60, rtol=1e-10)
    angle = Rotation.from_matrix(run.rotation @ start.rest_rotation.T).as_rotvec() @ start.axis_world
    trial = fit_trial(plate, "x", Record("kane", "angle", "angle", run.t, angle))
    assert abs(trial.moment / ident.moment(plate, "x") - 1.0) < 2e-3
