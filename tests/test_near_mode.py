"""A mode beating in near the first one's frequency lifts the envelope (bifilar.identification.records.near): decaying envelopes do not.
Fits of one rig whose learned laws disagree (a record's halves, trials) carry the laws' spread through their T0."""

import math
from types import SimpleNamespace

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.stats import chi2

from bifilar.identification.records import AmplitudeLaw, Record, RecordOptions, fit_oscillation
from bifilar.identification.records import synthetic as Y
from bifilar.identification.records import fit as fit_module
from bifilar.identification.records import near
from bifilar.identification.records.near import DECAY_P, decay_misfit, envelope_rises
from bifilar.identification.records.pipeline import CONSISTENCY, _own_variances, halves
from bifilar.motion import lagrange as L
from validate.cases.records import ROD


def _envelope(rng, share, ratio, cycles=25, zeta=5e-4, noise=2e-3):
    """Cycle centres and amplitudes of a decaying swing with a mode beating in (the analytic signal's
    modulus, A e^(-zeta t) |1 + share e^(i (ratio - 1) t)|), each amplitude with relative noise."""
    t = 2.0 * math.pi * (np.arange(cycles) + 0.5)
    beat = np.abs(1.0 + share * np.exp(1j * (ratio - 1.0) * t))
    return t, np.exp(-zeta * t) * beat * (1.0 + noise * rng.standard_normal(cycles))


def test_a_decaying_envelope_does_not_rise():
    # damping only shrinks the swing: 30 noisy decaying (or flat) envelopes of 25 cycles, none called a beat
    rng = np.random.default_rng(40)
    assert not any(envelope_rises(*_envelope(rng, 0.0, 1.0, zeta=z)) for z in np.linspace(0.0, 3e-3, 30))


def test_a_beat_under_one_cycle_lifts_the_envelope():
    # a sway at 0.96 omega0, 5 % of the swing: one beat over 25 cycles, its envelope falls and rises by
    # ~10 % against a decay of 7.6 % (zeta 5e-4) and a noise of 0.2 % a cycle
    rng = np.random.default_rng(41)
    assert envelope_rises(*_envelope(rng, 0.05, 0.96))


def _damped(rng, linear, quadratic, dry, cycles=25, noise=2e-3):
    """Cycle centres and amplitudes of one mode's decay, dA/dt = -(linear A + quadratic A^2 + dry)
    (scipy's DOP853), each amplitude with relative noise ``noise``."""
    t = 2.0 * math.pi * (np.arange(cycles) + 0.5)
    sol = solve_ivp(lambda s, a: -(linear * a + quadratic * a * a + dry), (0.0, t[-1]), [1.0], t_eval=t,
                    method="DOP853", rtol=1e-10, atol=1e-12)
    return t, sol.y[0] * (1.0 + noise * rng.standard_normal(cycles)), noise * sol.y[0]


def test_one_mode_s_decay_is_a_damping_law_s():
    # 60 decays of 25 cycles with linear, quadratic and dry damping in turn and together (the swing
    # falling to 40-95 % of the start), 0.2 % noise: the test is an F test, so its p-values are uniform
    # under one mode: none below DECAY_P (1e-6), and below 0.05 at most 9 of 60 (binomial 99.5 % bound)
    rng = np.random.default_rng(41)
    p = []
    for k in range(60):
        linear, quadratic, dry = rng.uniform(0.0, 2e-3, 3) * np.array([k % 3 != 1, k % 3 != 2, k % 3 != 0])
        p.append(decay_misfit(*_damped(rng, linear, quadratic, dry), 8))
    p = np.array(p)
    assert p.min() > DECAY_P and np.sum(p < 0.05) <= 9


@pytest.mark.parametrize(("beats", "share"), [(0.5, 0.1), (1.0, 0.03), (1.5, 0.03)])
def test_two_modes_do_not_decay_as_one(beats, share):
    # a second mode of 3-10 % of the swing decaying at 3x the first's rate, 0.5 to 1.5 beats over 25
    # cycles, 0.2 % amplitude noise: the sum wobbles as no damping law does (measured p 1e-11, 2e-17,
    # 1e-17). Its limit: at 0.1-0.3 beats and 3-5 % the bend was not seen at this noise (p 0.002-0.8)
    rng = np.random.default_rng(42)
    t = 2.0 * math.pi * (np.arange(25) + 0.5)
    dw = 2.0 * math.pi * beats / t[-1]
    a = np.abs(np.exp(-5e-4 * t) + share * np.exp((-1.5e-3 + 1j * dw) * t)) * (1.0 + 2e-3 * rng.standard_normal(25))
    assert decay_misfit(t, a, 2e-3 * a, 8) < DECAY_P  # 8: the record fit's envelope's top degree


@pytest.mark.slow
def test_a_sway_beating_near_the_torsion_is_fitted_where_the_record_allows(monkeypatch):
    # a 250 Hz gyro record of 25 cycles with a sway at 1.058 T0 (3.7 % of the swing; 1.4 beats), its
    # envelope never rising. The periodogram finds the sway (outside the band the first mode swept) but
    # fits it beside a law that took part of the beat; refitted beside the first mode in the cycles
    # (near.near_refit, the first mode's envelope its damping's decay) it comes out at 1.0590 T0, and T0
    # within its sigma (measured z +0.16, sigma 5.6e-4 s; a cubic envelope in its place took a share of the
    # beat: 1.0624 T0, z +1.74). Without the refit its decay is no one mode's (p < 1e-6): the flag says so and T0
    # under the ideal law is in its sigma (measured z +1.16, sigma 3.6e-3 s, 16x wider); without the
    # decay test either it was 8.1 sigma off.
    rng = np.random.default_rng(8027)
    traits = Y.gyro(rng, rate=250.0, cycles=25.0)
    rec = Y.record(ROD, rng, traits)
    law = AmplitudeLaw.torsion(ROD)
    fit = fit_oscillation(rec.t, rec.y, "rate", law)
    assert fit.second_mode[0] / rec.period == pytest.approx(traits.second[0], abs=2e-3)  # 1/20 of a resolution, 1/25
    assert not fit.law.beat and abs(fit.period - rec.period) < 1.96 * fit.period_std
    monkeypatch.setattr("bifilar.identification.records.fit.near_refit", lambda *args: args[-1])
    flagged = fit_oscillation(rec.t, rec.y, "rate", law)
    assert flagged.law.beat and abs(flagged.period - rec.period) < 1.96 * flagged.period_std
    assert flagged.period_std > 4.0 * fit.period_std
    monkeypatch.setattr(near, "DECAY_P", 0.0)
    monkeypatch.setattr("bifilar.identification.records.phase_law.DECAY_P", 0.0)
    blind = fit_oscillation(rec.t, rec.y, "rate", law)
    assert not blind.law.beat and abs(blind.period - rec.period) > 5.0 * blind.period_std


def _fit(excess, excess_std, gap, own=1e-4):
    """A stand-in for a fit (what bifilar.identification.records.pipeline._own_variances reads): T0's
    own sigma ``own`` (s, no prior part), the excess learned with its sigma, T0 under the ideal law less
    T0 learned (``gap``, s)."""
    law = SimpleNamespace(excess=excess, excess_std=excess_std, ideal_gap=gap, conflict=None, beat=False)
    return SimpleNamespace(law=law, period_std=own, period_std_statistical=own, prior_gain=np.zeros(3))


def test_fits_whose_laws_agree_keep_their_own_variances():
    # six fits of one rig (trials, or halves) learning ds = 0.02 +- 0.005 within 1.2 sigma of each
    # other (chi^2 2.3 on 5 dof, under the 99 % quantile 15.1): the law they learned is the rig's, their
    # gaps to the ideal law (3e-3 s, 30 sigmas) are that law's effect, not a doubt
    fits = [_fit(0.02 + 0.005 * d, 0.005, 3e-3) for d in (-1.2, -0.4, 0.0, 0.3, 0.5, 0.6)]
    assert np.allclose(_own_variances(fits), 1e-8, rtol=1e-12)


def test_fits_whose_laws_disagree_carry_their_spread_through_their_periods():
    # a sway beating in, its phase and size new in each fit, makes each learn its own law: ds 0.002 to
    # 0.030 +- 0.005 (benchmarks/near_mode.py's misses learned 0.007-0.024 +- 0.005-0.008; chi^2 27 on 5
    # dof, past the 99 % quantile 15.1). With equal sigmas the between-fits variance that brings chi^2 to
    # its 5 dof is in closed form, the excesses' sample variance less their own (0.0106^2), and each
    # fit's T0 carries it at its own response to the excess (gap / ds = 0.09 s per unit here)
    ds = np.array([0.002, 0.030, 0.016, 0.024, 0.006, 0.028])
    gaps = 0.09 * ds  # the excess's effect on T0 at 0.3 rad: ds A^2 (relative, T0 ~ 1 s)
    fits = [_fit(d, 0.005, g) for d, g in zip(ds, gaps)]
    tau2 = ds.var(ddof=1) - 0.005**2
    assert np.allclose(_own_variances(fits), 1e-8 + 0.09**2 * tau2, rtol=1e-9)


def test_an_excess_within_its_sigma_takes_the_others_response():
    # the fits of test_fits_whose_laws_disagree_...'s, but the first learned ds = 1e-12 +- 0.005 with a
    # gap of rounding size (3e-13 s): its ratio means nothing, and it takes the median of the others'
    # responses (0.09 s per unit), not 0.3
    ds = np.array([1e-12, 0.030, 0.016, 0.024, 0.006, 0.028])
    gaps = 0.09 * ds
    gaps[0] = 3e-13
    fits = [_fit(d, 0.005, g) for d, g in zip(ds, gaps)]
    tau2 = ds.var(ddof=1) - 0.005**2
    assert np.allclose(_own_variances(fits), 1e-8 + 0.09**2 * tau2, rtol=1e-9)


def test_the_between_fits_variance_brings_chi2_to_its_degrees_of_freedom():
    # unequal sigmas: no closed form; the excesses' chi^2 about their weighted mean, each variance
    # widened by what _own_variances found (over the slopes' squares), is their 3 degrees of freedom
    ds = np.array([0.01, 0.05, -0.02, 0.03])
    sd = np.array([0.004, 0.008, 0.006, 0.01])
    slopes = np.array([0.05, 0.08, 0.12, 0.02])
    fits = [_fit(d, s, k * d) for d, s, k in zip(ds, sd, slopes)]
    tau2 = (_own_variances(fits) - 1e-8) / slopes**2
    assert np.allclose(tau2, tau2[0], rtol=1e-9)  # one variance of the law, each T0 at its own slope
    w = 1.0 / (sd**2 + tau2[0])
    chi = float(np.sum(w * (ds - np.sum(w * ds) / np.sum(w)) ** 2))
    assert chi == pytest.approx(3.0, rel=1e-6)  # brentq stops within 2e-12 of tau^2 = 8.4e-4


@pytest.mark.slow
def test_halves_that_learn_different_laws_hold_the_ideal_law_s_periods():
    # a 250 Hz gyro record of 25 cycles from 0.5 rad (a law 27 % stronger than the ideal) with a sway at
    # 0.955 omega0, 9.7 % of the swing (drawn as identify-record-near-trials draws them): each half learns
    # the beat its part of the sway asks for, ds 0.054 +- 0.010 and 0.022 +- 0.007 (chi^2 7.2 on 1 dof,
    # past its 99 % quantile 6.6), and their T0 were 7.1 sigmas apart. Their T0 under the ideal law
    # now enter the halves' test: z -0.55 (of 12 such draws, seeds 0-11, 5 had |z| > 3 before, 2 after)
    traits = Y.Traits(kind="rate", rate=250.0, amplitude=0.503, cycles=25.0, excess=0.272, shape=0.129, zeta=7.3e-4,
                      quadratic=0.0107, dry=6.8e-4, white=0.0308, coloured=0.0057, colour_time=0.073, offset=-0.041,
                      drift=0.0027, bias_walk=0.0016, lost=0.006, burst=2.0, second=(1.047, 0.097, 0.041))
    rec = Y.record(ROD, np.random.default_rng(5), traits)
    law = AmplitudeLaw.torsion(ROD)
    record = Record("gyro.csv", "rate", "rate", rec.t, rec.y)
    h = halves(record, law, RecordOptions(kind="rate"))
    split = rec.t < h.split
    a, b = (fit_oscillation(rec.t[part], rec.y[part], "rate", law) for part in (split, ~split))
    apart = (a.law.excess - b.law.excess) ** 2 / (a.law.excess_std**2 + b.law.excess_std**2)
    assert apart > chi2.ppf(CONSISTENCY, 1)  # the halves' laws disagree (measured 7.2)
    assert abs(h.z) < 3.0  # measured -0.55; a 3-sigma margin as the halves' own test (HALVES_Z)


_UNDER_A_BEAT = Y.Traits(kind="rate", rate=250.0, amplitude=0.6, cycles=25.0, excess=0.115, shape=0.32, zeta=0.0013,
                         quadratic=0.0083, dry=0.0024, white=0.0306, coloured=0.0058, colour_time=0.036, drift=0.0168,
                         bias_walk=0.0017, lost=0.01, burst=2.0, second=(1.0054, 0.06, 0.022))


@pytest.mark.slow
def test_a_sway_under_a_beat_off_is_found_and_its_trade_with_the_law_is_in_the_sigma(monkeypatch):
    # 250 Hz gyro records of 25 cycles from 0.6 rad with a sway at 1.0054 T0 (6 % of the swing, 0.13
    # beats over the record; identify-record-near-mode's record that was 3.7 sigma off): the cycles'
    # phase and envelope wobble together, so near.near_mode_of finds a mode in the band where its gain
    # over one mode reaches NEAR_GAIN (measured gains 8-177: 7 of 10 found, the frequency ill-determined
    # under a beat, 0.996-1.021 T0) and it is subtracted. Mode and law trade what the record says of
    # them: with that trade (near.near_doubt) 8 of 10 are within 1.96 sigma (one found at -2.05, one
    # not found at +4.46; 10 honest draws give <= 7 inside 1.2 % of the time); held, 5 of 10 are
    # 3-7 sigma off.
    law = AmplitudeLaw.torsion(ROD)
    records = [Y.record(ROD, np.random.default_rng(seed), _UNDER_A_BEAT) for seed in range(10)]
    fits = [fit_oscillation(rec.t, rec.y, "rate", law) for rec in records]
    found = [f.second_mode is not None and abs(f.second_mode[0] / r.period - 1.0) < near.NEAR_BAND
             for r, f in zip(records, fits)]
    assert sum(found) >= 6
    assert sum(abs(f.period - r.period) < 1.96 * f.period_std for r, f in zip(records, fits)) >= 8
    monkeypatch.setattr("bifilar.identification.records.fit.near_doubt", lambda *args: 0.0)
    held = [fit_oscillation(rec.t, rec.y, "rate", law) for rec in records]
    assert sum(abs(h.period - r.period) > 3.0 * h.period_std for r, h in zip(records, held)) >= 4


@pytest.mark.slow
def test_no_near_mode_is_found_where_there_is_none(monkeypatch):
    # video and gyro records with no second mode (their noise coloured, their offsets drifting, the
    # law's excess up to 40 %) and clean 100-cycle records: near.near_mode_of finds nothing in any
    # (measured on the random kinds with their second modes: 0 of 30 video records, 1 of 40 gyro
    # records, whose sway was at 1.057 omega0 and was found at 1.056; 0 of 16 clean long records)
    found = []
    real = near.near_mode_of

    def spy(*args):
        out = real(*args)
        found.append(out)
        return out

    monkeypatch.setattr("bifilar.identification.records.fit.near_mode_of", spy)
    law = AmplitudeLaw.torsion(ROD)
    for seed in range(6):
        rng = np.random.default_rng(900 + seed)
        for traits, kind in [(Y.video(rng, fold=False, second=None), "angle"), (Y.gyro(rng, second=None), "rate"),
                             (Y.Traits(amplitude=0.8, cycles=100.0, white=0.003, zeta=1e-3, excess=0.2), "angle")]:
            rec = Y.record(ROD, rng, traits)
            fit_oscillation(rec.t, rec.y, kind, law)
    assert len(found) >= 15 and not any(found)  # (a record whose search found a far mode has no near search)


@pytest.mark.parametrize("degree", [2, near.DAMPING])
def test_the_two_mode_fit_s_jacobian_is_its_residual_s_derivative(monkeypatch, degree):
    # near._Near's analytic Jacobian (the law's phase integral differentiated through R(A), the
    # envelope and the excess; the near mode through its sinc window) against central differences of
    # its residual, on the cycles of a gyro record with a sway at 1.04 T0: each column the same within
    # 1e-6 of its largest entry (measured <= 3e-7: at steps of 1e-5 of each parameter the differences'
    # truncation and the residual's rounding, summed over the law's integral, are both about that). The
    # envelope a Chebyshev series, or the damping law's decay, its derivatives from the sensitivities' RK4
    # (the record damped by all three kinds, each term away from its bound 0)
    rec = Y.record(ROD, np.random.default_rng(3), Y.Traits(kind="rate", rate=250.0, amplitude=0.6, cycles=20.0,
                                                           excess=0.2, white=0.02, second=(1.04, 0.05, 0.02),
                                                           quadratic=0.02, dry=2e-3))
    captured = {}
    real = fit_module.fit_whole

    def spy(rec_, cyc, phase, baseline, second):
        captured.update(cyc=cyc, phase=phase)
        return real(rec_, cyc, phase, baseline, second)

    monkeypatch.setattr(fit_module, "fit_whole", spy)
    fit_oscillation(rec.t, rec.y, "rate", AmplitudeLaw.torsion(ROD))
    data = near._Near.of(captured["cyc"], captured["phase"], True, 0.35)
    one = data.fit(degree).x.copy()
    k = near._terms(degree)
    one[2 + k:4 + k] = [0.3, -0.2]  # the excess away from zero, where its terms' derivatives are not
    if degree == near.DAMPING:
        one[3:6] = np.maximum(one[3:6], [1e-3, 1e-2, 1e-3])  # linear, quadratic, dry: off their bound
    for p, second in [(one, False), (np.concatenate([one, [one[1] * 1.04, 0.02, 0.03, -0.02]]), True)]:
        steps = 1e-5 * np.maximum(np.abs(p), 1e-2)
        numeric = np.column_stack([(data.residual(p + h * e, degree, second) - data.residual(p - h * e, degree, second))
                                   / (2 * h) for h, e in zip(steps, np.eye(len(p)))])
        analytic = data.jacobian(p, degree, second)
        assert np.all(np.max(np.abs(numeric - analytic), axis=0) <= 1e-6 * np.max(np.abs(numeric), axis=0))


def test_the_damping_decay_is_each_damping_s_closed_form():
    # d ln A / dt = -(a + b A + c / A) alone in each term: ln A0 - a t; A0 / (1 + b A0 t); A0 - c t. RK4 at
    # 0.1 s steps of decays of at most 0.3 over 10 s: its error ~(0.03 x 0.1)^5, far below the 1e-9 asked
    grid = np.linspace(0.0, 10.0, 101)
    a0 = math.log(0.6)
    for (a, b, c), exact in [((0.02, 0.0, 0.0), a0 - 0.02 * grid),
                             ((0.0, 0.05, 0.0), a0 - np.log1p(0.05 * 0.6 * grid)),
                             ((0.0, 0.0, 0.015), np.log(0.6 - 0.015 * grid))]:
        log_a, slope = near._damping_decay(grid, a0, a, b, c)
        assert np.max(np.abs(log_a - exact)) < 1e-9
        # the sensitivities against central differences of the decay itself (steps 1e-6: truncation
        # ~1e-12 and rounding ~1e-10 of the derivative's size)
        p = np.array([a0, a, b, c])
        for j in range(4):
            h = 1e-6
            up = near._damping_decay(grid, *(p + h * np.eye(4)[j]))[0]
            down = near._damping_decay(grid, *(p - h * np.eye(4)[j]))[0]
            assert np.allclose(slope[:, j], (up - down) / (2 * h), rtol=1e-6, atol=1e-8)


@pytest.mark.slow
def test_a_sway_beside_strong_quadratic_and_dry_damping_is_fitted_at_its_own_frequency():
    # 6 gyro records of 25 cycles from 0.5-0.8 rad, quadratic damping 0.025-0.04 and dry 1-3e-3, a sway
    # 4-10 % off the torsion's frequency (1-2.5 beats) of 5-10 % of the swing (benchmarks/near_mode.py's
    # damped records): the first mode's envelope beside the sway is its damping's decay, so the sway
    # does not take the envelope's bend. Measured: every sway within 5.1e-4 of its frequency (asked: 2e-3,
    # 1/20 of the record's resolution 1/25), |z| <= 1.37; with a quadratic envelope beside the sway (stop
    # 50's) a sway 2.1e-3 off and one T0 at z -2.07: both asserts fail
    rng = np.random.default_rng(5301)
    law = AmplitudeLaw.torsion(ROD)
    for _ in range(6):
        off = rng.uniform(0.04, 0.10) * rng.choice([-1, 1])
        traits = Y.gyro(rng, rate=250.0, cycles=25.0, quadratic=rng.uniform(0.025, 0.04), dry=rng.uniform(1e-3, 3e-3),
                        amplitude=rng.uniform(0.5, 0.8))
        traits = Y.Traits(**{**traits.__dict__, "second": (1.0 / (1.0 + off), rng.uniform(0.05, 0.1), traits.second[2])})
        rec = Y.record(ROD, rng, traits)
        fit = fit_oscillation(rec.t, rec.y, "rate", law)
        assert fit.second_mode is not None and fit.second_mode[0] / rec.period * (1.0 + off) == pytest.approx(1.0, abs=2e-3)
        assert abs(fit.period - rec.period) < 1.96 * fit.period_std


@pytest.mark.slow
def test_a_near_mode_s_doubt_is_at_most_what_the_mode_can_move_t0():
    # short 50 Hz gyro records (10-14 cycles; a quadrotor's log) with a mode of 1-4 % of the swing
    # 0.3-0.6 beats off: where the search fits it, the linearised doubt (free less held) of a near
    # degenerate fit ran to 1.5-4x what the mode can move T0 at all, eps (|delta| + 2 s A^2) T0 (eps its
    # size, delta its frequency's offset, s A^2 the law's strength at the swing; near._Near.reach), and on
    # a real 12-cycle log to 0.116 s of T0 = 0.84 s. Held to that reach (its eps the fitted mode's largest
    # over the record: up to ~1.5x the true initial size as the first mode decays), the doubt is within
    # 1.5x of the bound from the truth (measured 1.01 and 0.90) and T0 still within its sigma (z -0.27, +0.45)
    law = AmplitudeLaw.torsion(ROD)
    s = L.period_amplitude_coefficient(ROD)
    rng = np.random.default_rng(7)
    found = 0
    for _ in range(12):
        cycles = rng.uniform(10, 14)
        beats = rng.uniform(0.3, 0.6) * rng.choice([-1, 1])
        traits = Y.Traits(kind="rate", rate=50.0, amplitude=rng.uniform(0.2, 0.5), cycles=cycles,
                          zeta=rng.uniform(5e-4, 3e-3), white=rng.uniform(0.005, 0.03), offset=rng.uniform(-0.05, 0.05),
                          second=(1.0 / (1.0 + beats / cycles), rng.uniform(0.01, 0.04), rng.uniform(0.0, 0.1)))
        rec = Y.record(ROD, rng, traits)
        fit = fit_oscillation(rec.t, rec.y, "rate", law)
        doubt = fit.period_std_parts.get("near_mode", 0.0)
        if doubt:
            found += 1
            bound = rec.period * traits.second[1] * (abs(beats) / cycles + 2.0 * s * traits.amplitude**2)
            assert doubt <= 1.5 * bound
            assert abs(fit.period - rec.period) < 1.96 * fit.period_std
    assert found == 2  # records 1 and 12 of the 12 (their modes 3.5 and 2.0 % of the swing)
