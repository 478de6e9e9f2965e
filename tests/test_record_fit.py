"""The record fit on synthetic records whose truth is known (bifilar.identification.records): the
exact law at large amplitude with a stronger real law learned from the record, what trackers add (lock-on,
stuck values, lost runs, glitches, folding), a second mode beating in, proportional records of unknown
scale, the honesty and efficiency of the stated sigma, and records whose units are wrong."""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.stats import binom

from bifilar.identification.records import AmplitudeLaw, Record, RecordOptions, fit_oscillation, identify_records
from bifilar.identification.records import synthetic as Y
from bifilar.identification.records.read import unfold
from bifilar.motion import lagrange as L
from bifilar.rig import RigError
from validate.assets import rig
from validate.cases.records import ROD, plain_damped_sine, zero_crossing_period

BENCH = L.from_rig(rig("bench_plate"))
LAW = AmplitudeLaw.torsion(BENCH)
ROD_LAW = AmplitudeLaw.torsion(ROD)
Z95 = 1.959963984540054


def test_exact_law_ratio_is_the_lagrange_quadrature():
    """The law's own T(A)/T0 (the energy integral of its rho, lam form, Gauss-Legendre) against
    lagrange.period's quadrature of the rig (1e-13): at a knot (the ratio's last one is A) both are exact
    to rounding, 1e-12; between the table's knots the spline in A^2 holds 1e-9."""
    omega = 2.0 * math.pi / L.linear_period(BENCH)
    assert LAW.coefficient(omega) == pytest.approx(L.period_amplitude_coefficient(BENCH), rel=1e-12)
    table = LAW.table(omega, 1.4)
    for a in (0.05, 0.3, 0.77, 1.0, 1.4):
        exact = L.period(BENCH, a) / L.linear_period(BENCH)
        assert LAW.ratio(a, omega) == pytest.approx(exact, rel=1e-12)
        assert float(table.ratio_at(a)) == pytest.approx(exact, rel=1e-9)


@pytest.mark.parametrize("law", [AmplitudeLaw("series", s=0.086, quintic=-0.02), AmplitudeLaw("series", s=-0.03),
                                 AmplitudeLaw("exact", rho=3.2, lam=0.02)], ids=["series", "softening", "exact-wide"])
def test_law_table_is_its_equation_of_motion_integrated(law):
    """The table's energy integral against the law's own equation of motion (``acceleration``)
    integrated from rest at A by scipy's DOP853 at rtol 1e-12, the quarter period at the first zero
    crossing (an event): the two agree to 1e-9 (the integrator's tolerance times the crossing's
    sensitivity), up to 0.98 of the law's limit where the exact law's r nears zero."""
    omega = 3.1
    top = 0.98 * law.limit if law.kind == "exact" else 1.2
    table = law.table(omega, top)

    def crossing(t, y):
        return y[0]

    crossing.terminal, crossing.direction = True, -1
    for a in table.amplitude[[0, 11, -1]]:
        run = solve_ivp(lambda t, y: [y[1], law.acceleration(y[0], y[1], omega)], (0.0, 10.0 / omega), [a, 0.0],
                        method="DOP853", rtol=1e-12, atol=1e-14 * a, events=crossing)
        quarter = run.t_events[0][0]
        assert law.ratio(a, omega) == pytest.approx(4.0 * quarter * omega / (2.0 * math.pi), rel=1e-9)


def test_a_law_that_does_not_return_is_refused():
    """A softening series law, s = 0.3: its potential V = omega^2 (A^2 / 2 - 2 s A^4 / 3) peaks at
    A^2 = 3 / (8 s) = 1.25, A = 1.118 rad; a swing from 1.2 rad never comes back, one from 1.0 rad does."""
    law = AmplitudeLaw("series", s=0.3)
    assert law.ratio(1.0, 2.0) > 1.0
    with pytest.raises(RigError, match="does not return from 1.2 rad"):
        law.table(2.0, 1.2)


def test_matched_quintic_holds_both_ends_of_the_amplitude_range():
    """A series law with its quintic matched at A: T(A)/T0 equals the target there (to the match's
    1e-9), and at 0.05 rad it is the cubic law's to O(q A^4) = O(1e-7) (the quintic leaves s alone)."""
    law = AmplitudeLaw("series", s=0.086)
    omega = 5.68
    target = law.ratio(0.8, omega) + 0.002
    matched = law.matched(0.8, target, omega)
    assert matched.ratio(0.8, omega) == pytest.approx(target, abs=1e-9)
    assert matched.ratio(0.05, omega) == pytest.approx(law.ratio(0.05, omega), abs=1e-7)


@pytest.mark.slow
def test_noise_free_decay_recovers_t0_and_the_excess():
    """The rod from 1.2 rad, a law 30 % stronger than the ideal one, quadratic damping to 0.4 rad,
    1e-6 rad of noise: T0 to 5e-6 (what the three-term excess leaves of a cubic one over 0.4-1.2 rad,
    1.5e-5 of T(A) there, extrapolated to A = 0) and the excess to 1 % of the ideal coefficient; the
    amplitude of the first cycle (centred half a period in) read off the waveform itself: the record's
    turning point there, to the 1e-3 a 60 fps sampling of the peak leaves ((omega dt / 2)^2 / 2)."""
    rec = Y.record(ROD, np.random.default_rng(1), Y.Traits(amplitude=1.2, cycles=60, excess=0.3, zeta=0.0,
                                                            quadratic=0.02, white=1e-6))
    fit = fit_oscillation(rec.t, rec.y, "angle", ROD_LAW)
    assert fit.period / rec.period - 1.0 == pytest.approx(0.0, abs=5e-6)
    assert fit.law.excess / fit.law.ideal == pytest.approx(0.3, abs=0.01)
    turn = (rec.t > 0.25 * rec.period) & (rec.t < 0.75 * rec.period)
    assert fit.amplitude[0] == pytest.approx(float(np.max(np.abs(rec.y[turn]))), rel=2e-3)
    assert fit.amplitude[1] < 0.6


@pytest.mark.slow
def test_a_swing_that_stays_large_keeps_its_own_third_harmonic():
    """The rod released at 1.2 rad with hardly any damping (1.2 -> 1.18 rad over 80 cycles), the ideal
    law, 1e-4 rad of noise: it swings 9 % below its zero-swing frequency all along, and its waveform's
    third harmonic (1 % of the swing) lies at three times that, its periodogram's sidelobes far above
    the noise. It is the first mode's, not a second mode: none of its size is reported and the peak
    amplitude is the release's to the 1e-3 a 60 fps sampling of the turning point leaves (taken for a
    sway and subtracted, it took 1 % off the swing). A swing this constant cannot teach the law: T0's
    sigma is the law's prior doubt, about 1 % of T0 (30 % of s A^2 = 0.1), and T0 is within 3 of it."""
    rec = Y.record(ROD, np.random.default_rng(5), Y.Traits(amplitude=1.2, cycles=80, zeta=2e-5, white=1e-4))
    fit = fit_oscillation(rec.t, rec.y, "angle", ROD_LAW)
    assert fit.second_mode is None or fit.second_mode[1] < 1e-3 * 1.2  # what a waveform's misfit may leave
    assert fit.amplitude[0] == pytest.approx(1.2, rel=1e-3)
    assert 0.005 < fit.period_std_law / rec.period < 0.05
    assert abs(fit.period - rec.period) < 3.0 * fit.period_std


def test_a_long_clean_record_has_no_second_mode_and_no_bias():
    """The rod from 0.8 rad over 100 cycles, light damping (to 0.56 rad), no noise: the periodogram of
    what the first mode leaves has a peak just past the band the first mode swept (the law's and the
    envelope's 1e-6 misfit, which no noise floor hides), and the sinusoid fitted there walked into the
    band: it took the first mode's own misfit as a mode of 2.7e-4 of the swing, the first amplitude came
    out 3.7e-4 high and T0 1e-4 short. A mode in the band is the first mode's (second_mode.outside):
    none is fitted, T0 is the truth's to 2.6e-6 and the first amplitude to 2e-6."""
    traits = Y.Traits(amplitude=0.8, cycles=100, zeta=5e-4, white=0.0)
    rec = Y.record(ROD, np.random.default_rng(1), traits)
    fit = fit_oscillation(rec.t, rec.y, "angle", ROD_LAW)
    assert fit.second_mode is None
    assert fit.period == pytest.approx(rec.period, rel=1e-5)
    assert fit.amplitude[0] == pytest.approx(Y.peaks(ROD, traits, fit.cycle_time[:1])[0], rel=1e-4)


@pytest.mark.slow
def test_the_ideal_law_alone_is_biased_and_the_learned_one_is_not():
    """A record whose real law is 30 % stronger: held at the ideal law (--law-sigma 0) its T0 is off by
    more than 3 of its sigmas (the cycles' sandwich widens with the misfit: 3.8 here) and by 2e-3 of
    T0; learning the excess puts it within 3 sigmas and cuts the error at least threefold. The held fit
    searches no second mode: with the first mode's envelope its damping's decay (records.near), the
    near-mode search takes the held law's misfit for a mode beside the torsion (its doubt 1.1e-3 s, z 2.8),
    which is not what this test is about."""
    rec = Y.record(ROD, np.random.default_rng(4), Y.Traits(amplitude=0.6, cycles=80, excess=0.3, quadratic=0.01,
                                                            white=0.003))
    held = fit_oscillation(rec.t, rec.y, "angle", ROD_LAW, excess_prior=0.0, second_mode=False)
    learned = fit_oscillation(rec.t, rec.y, "angle", ROD_LAW)
    assert abs(held.period - rec.period) > 3.0 * held.period_std
    assert abs(learned.period - rec.period) < 3.0 * learned.period_std
    assert abs(learned.period - rec.period) < abs(held.period - rec.period) / 3.0


@pytest.mark.slow
def test_a_record_that_barely_decays_carries_the_laws_doubt():
    """At 0.8 rad with no decay the record cannot tell T0 from the law: its sigma is the prior's doubt
    (0.35 of s A^2 and more: ~1 % of T0), and it still covers a law 30 % stronger."""
    rec = Y.record(ROD, np.random.default_rng(5), Y.Traits(amplitude=0.8, cycles=40, excess=0.3, zeta=0.0,
                                                            white=0.002))
    fit = fit_oscillation(rec.t, rec.y, "angle", ROD_LAW)
    s = L.period_amplitude_coefficient(ROD)
    assert fit.period_std_law > 0.3 * s * 0.64 * rec.period
    assert abs(fit.period - rec.period) < 3.0 * fit.period_std


@pytest.mark.slow
def test_a_tracker_locking_on_losing_frames_and_sticking_is_fitted_and_says_what_it_left_out():
    """The issue's refused record: 94 cycles at 60 fps, 12 % of frames lost in runs, a lock-on of 1.5 s
    with values stuck at exactly -pi/4, a tracker that repeats values: fitted, T0 within 3 sigma, the
    lock-on reported from the first frame, the stuck values counted. T0 within 3.5 sigma: the AR(1)
    tracking noise (4e-3 rad over 0.3 s) biases the learned excess up by ~0.04 and T0 down by ~1.2
    of its sigma on average over seeds (-3.2 on this one; docs/identification.md, "what is left")."""
    rec = Y.record(ROD, np.random.default_rng(6), Y.Traits(amplitude=0.7, cycles=94, excess=0.2, zeta=3e-4,
                                                            quadratic=0.005, white=0.002, coloured=0.004,
                                                            colour_time=0.3, lost=0.12, burst=20.0, lockon=1.5,
                                                            holds=0.004, glitches=0.002))
    fit = fit_oscillation(rec.t, rec.y, "angle", ROD_LAW)
    assert abs(fit.period - rec.period) < 3.5 * fit.period_std
    assert fit.rejected.spans[0][0] == pytest.approx(rec.t[0]) and fit.rejected.spans[0][1] >= 1.0
    assert fit.rejected.stuck > 0 and fit.rejected.glitches > 0
    assert fit.cycles >= 0.8 * 94  # the lock-on's 1.5 cycles and the runs of lost frames left out


@pytest.mark.slow
def test_a_large_swing_with_a_sway_near_twice_its_frequency_read_from_a_tracker_file(tmp_path):
    """Issue 37 item 3: 1.15 rad on a 60 fps tracker, a sway at 0.496 T0 with 14 % of the swing, runs of
    ~20 lost frames, 1.5 s of lock-on. Never folded, but over a lost run at full speed (the sway doubles
    the rate) and in the lock-on the angle steps by over pi/2; read_record took three such steps for folds
    and put the pieces between them pi apart: "no oscillation stands out of the noise" (2.9 < 3). Now the
    file is read as written and fitted within 3 sigma (measured z +0.16; 30 records of these traits drawn
    at random: all fitted, rms z 0.74)."""
    from bifilar.identification.records.read import read_record

    traits = Y.Traits(kind="angle", rate=60.0, amplitude=1.15, cycles=19.4, excess=0.3, shape=-0.15, zeta=2.4e-4,
                      quadratic=2e-3, dry=1.4e-3, white=0.0018, coloured=0.0054, colour_time=0.16, offset=-0.047,
                      drift=0.01, lost=0.113, burst=19.6, lockon=1.49, holds=0.0032, glitches=0.0017,
                      second=(0.496, 0.144, 0.0077))
    rec = Y.record(ROD, np.random.default_rng(4), traits)
    Y.write_tracker_csv(tmp_path / "video.csv", rec)
    read = read_record(tmp_path / "video.csv", fps=60.0)
    assert read.unfolded == 0
    fit = fit_oscillation(read.t, read.y, "angle", ROD_LAW)
    assert abs(fit.period - rec.period) < 3.0 * fit.period_std


@pytest.mark.slow
def test_folded_line_tracker_record():
    rec = Y.record(BENCH, np.random.default_rng(12), Y.Traits(amplitude=0.9, cycles=30, fold=True, white=0.004))
    y, jumps = unfold(rec.y, rec.t)
    assert jumps > 0
    fit = fit_oscillation(rec.t, y, "angle", LAW)
    assert abs(fit.period - rec.period) < 3.0 * fit.period_std


def test_a_second_mode_close_to_the_first_is_found_and_taken_out():
    """A sway at 1.29 T0 (0.78 of the first mode's frequency) with 6 % of the swing in a 18-cycle gyro
    record: the cycles' own fits cannot tell it from the first mode, the law's rigid phase can. Found to
    1 %, and T0 within 3 sigma with a sigma below a third of the 1.4e-2 of T0 it has without it
    (measured 2.9e-3 and 3.7e-3: the jackknife of 19 groups sets it, itself a variance of 18 dof)."""
    rec = Y.record(ROD, np.random.default_rng(2), Y.Traits(kind="rate", rate=100.0, amplitude=0.69, cycles=18,
                                                            zeta=1.7e-3, quadratic=6e-3, white=0.02, coloured=0.013,
                                                            colour_time=0.18, second=(1.29, 0.063, 0.048)))
    fit = fit_oscillation(rec.t, rec.y, "rate", ROD_LAW)
    assert fit.second_mode[0] == pytest.approx(1.29 * rec.period, rel=1e-2)
    assert abs(fit.period - rec.period) < 3.0 * fit.period_std < 1.4e-2 * rec.period


@pytest.mark.slow
def test_laser_spot_of_unknown_scale_is_the_plain_fits_period():
    """240 fps laser spots (pixels, scale unknown) over 6 cycles that hardly decay, a sway at 1.95 T0
    beating in (the issue's degenerate and short records), six draws: T0 near the period at the
    record's amplitude, never a scale traded for the law (which is not applied, and said so). Six z
    of a calibrated sigma have an rms below 1.8 with probability 0.99 (chi^2 with 6 dof below 19.4)
    and none beyond 3.5 (6 x 5e-4); measured here: rms 1.24, the largest 2.5."""
    s = L.period_amplitude_coefficient(BENCH)
    z = []
    for seed in range(6, 12):
        traits = Y.laser(np.random.default_rng(seed), amplitude=0.05, cycles=6.0, second=(1.95, 0.2, 0.0))
        rec = Y.record(BENCH, np.random.default_rng(seed), traits)
        fit = fit_oscillation(rec.t, rec.y, "proportional", LAW)
        at_amplitude = rec.period * LAW.ratio(0.05, 2.0 * math.pi / rec.period) * (1.0 + traits.excess * s * 0.05**2)
        z.append((fit.period - at_amplitude) / fit.period_std)
        assert fit.law.ideal is None and "scale unknown" in fit.law.note
        assert fit.second_mode is not None
    assert math.sqrt(float(np.mean(np.square(z)))) < 1.8 and max(np.abs(z)) < 3.5


@pytest.mark.slow
def test_a_stated_largest_swing_applies_the_law_and_its_doubt():
    """The same kind of record with --max-amplitude 0.12 rad (truth 0.08): the law is applied with the
    scale fitted in [0, 0.12 / first amplitude], T0 within 3 sigma of the zero-amplitude truth."""
    rng = np.random.default_rng(8)
    rec = Y.record(BENCH, rng, Y.laser(rng, amplitude=0.08, cycles=8.0))
    fit = fit_oscillation(rec.t, rec.y, "proportional", LAW, max_amplitude=0.12)
    assert fit.law.ideal is not None
    assert abs(fit.period - rec.period) < 3.0 * fit.period_std


@pytest.mark.slow
def test_white_noise_sigma_is_honest_and_efficient():
    """40 short clean records: the 95 % intervals hold the truth within the binomial 99.9 % range, and
    the statistical sigma is within 1.3x of a plain damped-sine least-squares fit's in the median and
    2.5x on every one (the sandwich over 10 cycles is itself uncertain): efficiency, not only honesty."""
    rng = np.random.default_rng(2024)
    omega = 2.0 * math.pi / L.linear_period(ROD)
    z, ratio = [], []
    for _ in range(40):
        rec = Y.record(ROD, rng, Y.Traits(amplitude=0.1, cycles=10.0, white=0.002, zeta=1e-3))
        fit = fit_oscillation(rec.t, rec.y, "angle", ROD_LAW)
        z.append((fit.period - rec.period) / fit.period_std)
        ratio.append(fit.period_std_statistical / plain_damped_sine(rec.t, rec.y, omega)[1])
    low, high = binom.interval(0.999, 40, 0.95)
    assert low <= np.sum(np.abs(z) <= Z95) <= high
    assert np.median(ratio) < 1.3 and max(ratio) < 2.5


@pytest.mark.slow
def test_two_halves_of_a_coloured_record_agree():
    """A 120-cycle record with noise correlated over half a second: its halves, fitted alone, agree
    within 3 of their sigmas (the law's common prior taken out); the block sigma is above the white."""
    from bifilar.identification.records.pipeline import halves

    rec = Y.record(BENCH, np.random.default_rng(21), Y.Traits(amplitude=1.0, cycles=120, excess=0.2, zeta=4e-4,
                                                               quadratic=0.01, white=0.002, coloured=0.008,
                                                               colour_time=0.5))
    split = halves(Record("r", "angle", "angle", rec.t, rec.y), LAW, RecordOptions())
    assert abs(split.z) < 3.0


@pytest.mark.slow
def test_interval_coverage_on_records_with_every_trait():
    """12 video records with every trait: the 95 % intervals hold the truth within the binomial 99.9 %
    range of 12 draws; the 90-record run is the slow case identify-record-coverage."""
    rng = np.random.default_rng(31)
    hits = 0
    for _ in range(12):
        rec = Y.record(ROD, rng, Y.video(rng, cycles=rng.uniform(12.0, 40.0)))
        y = unfold(rec.y, rec.t)[0]
        fit = fit_oscillation(rec.t, y, "angle", ROD_LAW)
        hits += abs(fit.period - rec.period) <= Z95 * fit.period_std
    low, _ = binom.interval(0.999, 12, 0.95)
    assert hits >= low


def test_the_zero_crossing_reference_is_right_on_a_clean_record():
    """The reference estimator of the trials case: on a clean gyro record it gives T0 to 1e-3 (its
    amplitude, max |rate| T / 2 pi, and the decay over a cycle leave ~5e-4 of bias; the trials case
    compares spreads, which a bias common to every trial does not touch)."""
    rec = Y.record(ROD, np.random.default_rng(3), Y.Traits(kind="rate", rate=250.0, amplitude=0.4, cycles=20,
                                                            white=1e-4))
    assert zero_crossing_period(rec.t, rec.y, ROD_LAW, 2.0 * math.pi / rec.period) == pytest.approx(rec.period,
                                                                                                    rel=1e-3)


def _damping_shift_reference(damping, amplitude):
    """damping_shift's construction (its amplitude grid, its eps, descending crossing to descending
    crossing, the trough between) with each amplitude integrated by scipy's DOP853 at rtol 1e-12 and
    the crossings and the trough found as events (to ~1e-12 of the period)."""
    zeta, quad, dry = damping["linear"], damping["quadratic"], damping["dry"]
    top = float(np.max(amplitude))
    eps = 1e-4 * top

    def rhs(_, s):
        return [s[1], -s[0] - 2.0 * zeta * s[1] - quad * abs(s[1]) * s[1] - dry * math.tanh(s[1] / eps)]

    def down(_, s):
        return s[0]

    def low(_, s):
        return s[1]

    down.direction, low.direction = -1, 1
    shift, trough = [], []
    for a in np.linspace(0.5 * float(np.min(amplitude)), 1.05 * top, 16):
        run = solve_ivp(rhs, (0.0, 6.0 * math.pi), [a, 0.0], method="DOP853", rtol=1e-12, atol=1e-14 * a,
                        events=[down, low])
        first, second = run.t_events[0][:2]
        shift.append((second - first) / (2.0 * math.pi) - 1.0)
        trough.append(-float(run.y_events[1][(run.t_events[1] > first) & (run.t_events[1] < second)][0][0]))
    order = np.argsort(trough)
    return np.interp(amplitude, np.array(trough)[order], np.array(shift)[order])


@pytest.mark.parametrize("damping", [{"linear": 0.0, "quadratic": 0.05, "dry": 0.0},
                                     {"linear": 1.3e-3, "quadratic": 7.5e-3, "dry": 0.0},
                                     {"linear": 0.0, "quadratic": 0.0, "dry": 1e-3}], ids=["quadratic", "mixed", "dry"])
def test_damping_shift_is_its_equation_integrated(damping):
    """The damping's lengthening of the period (records.damping.damping_shift, RK4 at h = 2 pi / 256)
    against the same construction integrated by DOP853 at rtol 1e-12. What RK4 leaves: its phase error,
    h^4 / 120 = 3.0e-9 of the period whatever the damping (measured 3.0e-9), the damping's own truncation
    and the trough read at the steps, ~1e-3 of the shift (measured 1.3e-3 at quadratic 0.05: 7e-8), and
    dry friction's switch at the turning points, which a fixed step straddles: ~(mu / A) h^2 (measured
    7.7e-8, 5 % of the shift; the fit's records show mu below 1e-6)."""
    from bifilar.identification.records.damping import damping_shift

    amplitude = np.linspace(0.5, 1.0, 50)
    h = 2.0 * math.pi / 256
    reference = _damping_shift_reference(damping, amplitude)
    tol = 3.5e-9 + 2e-3 * np.abs(reference) + damping["dry"] / amplitude * h**2
    assert np.all(np.abs(damping_shift(damping, amplitude) - reference) <= tol)


@pytest.mark.parametrize("samples", [40, 1024])
def test_the_periodogram_is_scipys_floating_mean_lomb_scargle(samples):
    """records.cycles.periodogram takes the tau-shifted sums from the unshifted ones (angle-sum
    identities) and, on an evenly spaced grid, the phasors from products of a few evaluated ones instead
    of evaluating the trigonometry at every entry twice: scipy's values to rounding, on unevenly spaced
    samples with an offset, a drift and noise, on an even and an uneven grid of frequencies."""
    from scipy.signal import lombscargle

    from bifilar.identification.records.cycles import periodogram

    rng = np.random.default_rng(samples)
    x = np.sort(rng.uniform(0.0, 60.0, samples))
    y = 0.7 * np.cos(3.1 * x + 0.3) * np.exp(-0.01 * x) + 0.2 + 0.01 * x + 0.05 * rng.standard_normal(samples)
    grid = np.arange(0.1, math.pi * (samples - 1) / 60.0, math.pi / 60.0)
    uneven = np.sort(rng.uniform(0.1, grid[-1], len(grid)))  # the phasors evaluated directly
    for omega in (grid, uneven):
        reference = lombscargle(x, y, omega, floating_mean=True)
        np.testing.assert_allclose(periodogram(x, y, omega), reference, rtol=0, atol=1e-12 * reference.max())


@pytest.mark.parametrize("zeta", [1e-3, 0.02])
def test_damping_shift_of_linear_damping_is_the_damped_frequencys(zeta):
    """Linear damping lengthens every cycle alike, T_d / T - 1 = 1 / sqrt(1 - zeta^2) - 1 (~zeta^2 / 2):
    damping_shift gives it to RK4's phase error h^4 / 120 = 3.0e-9 (h = 2 pi / 256) and the crossings'
    linear interpolation, ~2e-3 of the shift (measured 3e-9 and 3e-4 of it at zeta 0.02)."""
    from bifilar.identification.records.damping import damping_shift

    exact = 1.0 / math.sqrt(1.0 - zeta**2) - 1.0
    shift = damping_shift({"linear": zeta, "quadratic": 0.0, "dry": 0.0}, np.linspace(0.1, 1.0, 20))
    assert np.all(np.abs(shift - exact) <= 3.5e-9 + 2e-3 * exact)


def test_too_few_cycles_is_refused():
    t = np.linspace(0.0, 1.0, 200)
    with pytest.raises(ValueError, match="cycles"):
        fit_oscillation(t, np.cos(2.0 * t), "angle")


def test_noise_alone_is_refused():
    """White noise has a "best" period too; the fit must say there is no oscillation instead."""
    rng = np.random.default_rng(0)
    t = np.arange(0.0, 30.0, 0.02)
    with pytest.raises(ValueError, match="oscillation|cycles"):
        fit_oscillation(t, 0.01 + 1e-3 * rng.standard_normal(t.size), "angle")


PLATE = rig("bench_plate")


@pytest.mark.parametrize("kind, scale, unit", [("angle", 180.0 / math.pi, "degrees"),
                                               ("rate", 180.0 / math.pi, "deg/s"),
                                               ("angle", 600.0, "check --column")])
def test_a_swing_the_rig_cannot_make_is_refused_naming_the_unit(kind, scale, unit):
    """A 0.6 rad torsion written in degrees (or deg/s) but read as rad is a 34 rad swing, past the
    wires' pi: refused naming --angle-unit deg; a +-360 signal that degrees cannot explain either names
    the column and kind."""
    rec = Y.record(BENCH, np.random.default_rng(9), Y.Traits(kind=kind, rate=100.0, amplitude=0.6, cycles=12))
    record = Record("log.csv", "value", kind, rec.t, scale * rec.y)
    with pytest.raises(RigError, match=unit) as err:
        identify_records(PLATE, "z", [record])
    assert err.value.source == "log.csv" and err.value.field == "value"


@pytest.mark.slow
def test_pooling_shares_the_laws_prior():
    """Two records of one rig at one amplitude that cannot learn the law: their T0 share its doubt, so
    the pooled sigma is not that doubt over sqrt(2) (independent noise) but the doubt itself."""
    from bifilar.identification.records.pipeline import Trial, pool

    fits = []
    for seed in (1, 2):
        rec = Y.record(ROD, np.random.default_rng(seed), Y.Traits(amplitude=0.8, cycles=30, zeta=0.0, white=0.002))
        fits.append(fit_oscillation(rec.t, rec.y, "angle", ROD_LAW))
    pooled = pool([Trial(None, f, None, f.period, f.period_std, 0.5, ()) for f in fits])
    assert pooled.period_std > 0.9 * min(f.period_std_law for f in fits)


@pytest.mark.slow
def test_a_law_no_rig_has_is_flagged_by_identify():
    """A record of the bench plate whose periods follow a law 4x the ideal one in A^2 (a rig file whose
    law is wrong, or a beat read as a chirp): identify says so, names what to check, and says that T0 is
    known to more than 1 % only (the sigma holds the ideal law's T0 too)."""
    rec = Y.record(BENCH, np.random.default_rng(3), Y.Traits(amplitude=0.7, cycles=30, excess=3.0, white=0.003))
    trials, _ = identify_records(PLATE, "z", [Record("log.csv", "angle", "angle", rec.t, rec.y)])
    flags = " ".join(trials[0].flags)
    assert trials[0].fit.law.conflict > 3.0
    assert "more than a real rig's" in flags and "the rig file" in flags and "known to" in flags


def test_the_baseline_smoother_is_a_running_weighted_straight_line():
    """records.cycles.smooth takes the local line from its weighted sums at every point at once: numpy's
    weighted polyfit at each point to rounding (1e-10 of the values: the normal equations of a line
    through a few close points lose a few digits), a lone point in reach its own value, none the
    interpolation."""
    from bifilar.identification.records.cycles import smooth

    rng = np.random.default_rng(7)
    x = np.sort(rng.uniform(0.0, 50.0, 60))
    y = 0.4 + 0.01 * x + 0.01 * rng.standard_normal(60)
    at = np.linspace(-5.0, 60.0, 300)
    for width in (0.3, 2.0, 10.0):
        w = np.clip(1.0 - np.abs((x[None, :] - at[:, None]) / width) ** 3, 0.0, None) ** 3
        expected = []
        for i, a in enumerate(at):
            keep = w[i] > 0.0
            if keep.sum() >= 2:
                expected.append(np.polyval(np.polyfit(x[keep] - a, y[keep], 1, w=np.sqrt(w[i, keep])), 0.0))
            else:
                expected.append(y[keep][0] if keep.any() else np.interp(a, x, y))
        np.testing.assert_allclose(smooth(x, y, at, width), expected, rtol=0, atol=1e-10)
