"""The record fit's statistical sigma on records whose noise its covariance does not model
(bifilar.identification.records.phase_law, fit): tracking noise correlated over a fraction of a cycle
leaves Akaike's criterion unsure of the envelope's degree, whose choice moves T0 by about its sigma
(Model.envelope_doubt carries it); a delete-a-group jackknife, taken over its leverage, checks the rest;
on short clean records neither adds anything and the covariance's efficiency is kept. Coverage over many
records with every real trait is the slow case ``identify-record-coverage``."""

import math

import numpy as np
import pytest

import bifilar.identification.records.fit as F
import bifilar.identification.records.phase_law as P
from bifilar.identification.records import synthetic as Y
from bifilar.identification.records.law import AmplitudeLaw
from bifilar.motion import lagrange as L

ROD = L.TorsionRig.parallel(0.5, 0.0016, 0.8, 0.196)
LAW = AmplitudeLaw.torsion(ROD)
# 100 cycles from 0.8 rad with AR(1) noise of 6.6 mrad over 0.12 s (a video tracker's), a law 25 %
# stronger than the ideal
VIDEO = Y.Traits(amplitude=0.8, cycles=100.0, white=0.0035, coloured=0.0066, colour_time=0.12, zeta=1.2e-3,
                 excess=0.25, shape=0.1)


@pytest.mark.slow
def test_the_envelope_degree_s_doubt_widens_a_covariance_that_coloured_noise_leaves_short(monkeypatch):
    # seed 0: Akaike's weights spread over degrees 2-8 (0.04-0.27 each), whose phase fits put T0 up to
    # 9.6e-4 s from the chosen degree's; without that doubt the truth was 2.2 sigma out
    rec = Y.record(ROD, np.random.default_rng(0), VIDEO)
    fit = F.fit_oscillation(rec.t, rec.y, "angle", LAW)
    monkeypatch.setattr(P.Model, "envelope_doubt", lambda self, phase, cyc: 0.0)
    alone = F.fit_oscillation(rec.t, rec.y, "angle", LAW)
    assert fit.period == alone.period  # the doubt changes the sigma, never T0
    assert fit.period_std_statistical / alone.period_std_statistical > 1.4  # measured 1.72
    assert (abs(fit.period - rec.period) / fit.period_std < 1.96
            < abs(alone.period - rec.period) / alone.period_std)  # measured 1.38 and 2.22


@pytest.mark.slow
def test_video_records_with_coloured_noise_state_their_scatter():
    # 32 such records (seeds 0-31): the statistical sigma is the same trait for each, so its rms against
    # the scatter of T0 about the truth is the sigma's honesty, within the scatter's own 3-sigma error
    # for 32 draws (1 +- 3 / sqrt(64)); measured 0.92, and 31 in their 95 % intervals. The jackknife over groups of cycles, reselecting
    # the envelope's degree in every refit, had set 69 % of these sigmas at 1.8x the scatter, and still
    # left 1 in 16 of them outside 95 % intervals
    errors, sigmas, inside = [], [], 0
    for seed in range(32):
        rec = Y.record(ROD, np.random.default_rng(seed), VIDEO)
        fit = F.fit_oscillation(rec.t, rec.y, "angle", LAW)
        errors.append(fit.period - rec.period)
        sigmas.append(fit.period_std_statistical)
        inside += abs(fit.period - rec.period) < 1.96 * fit.period_std
    ratio = math.sqrt(float(np.mean(np.square(sigmas))) / float(np.mean(np.square(errors))))
    assert 1.0 - 3.0 / 8.0 < ratio < 1.0 + 3.0 / 8.0
    assert inside >= 27  # binomial 99 % lower bound of 32 draws at 95 %


@pytest.mark.parametrize("seed", [0, 1])
def test_the_covariance_holds_on_a_short_clean_record(seed):
    # identify-record-efficiency's records: 10 cycles at 60 fps from 0.1 rad, 2 mrad of white noise
    rec = Y.record(ROD, np.random.default_rng(seed), Y.Traits(amplitude=0.1, cycles=10.0, white=0.002, zeta=1e-3))
    fit = F.fit_oscillation(rec.t, rec.y, "angle", LAW)
    assert fit.jackknife == 0


@pytest.mark.slow
def test_a_law_no_rig_has_is_said_and_its_sigma_holds_both_periods():
    # a law 4x the ideal's in its A^2 coefficient (excess 3.0: the prior allows +-35 %, real rigs up to
    # 30-40 %): the fit learns ~2.3 of it, 9 prior sigmas off, and T0 under the ideal law is 11 % away;
    # either may be the right one (the rig file's law wrong, or a beat read as a chirp), so the sigma
    # holds both and the record cannot pin T0 to 1 %
    rec = Y.record(ROD, np.random.default_rng(1), Y.Traits(amplitude=0.8, cycles=40.0, excess=3.0, white=0.003,
                                                            zeta=1e-3))
    fit = F.fit_oscillation(rec.t, rec.y, "angle", LAW)
    assert fit.law.conflict is not None and fit.law.conflict > P.LAW_CONFLICT  # measured 9.4
    assert fit.period_std > 0.01 * fit.period  # measured 11 %: the ideal law's T0 is that far
    assert abs(fit.period - rec.period) < 1.0 * fit.period_std  # the learned T0 is the near one (0.6 %)


@pytest.mark.slow
def test_a_law_a_real_rig_has_is_learned_not_held():
    # the same record with a law 40 % stronger, the most real rigs show: learned, not flagged
    rec = Y.record(ROD, np.random.default_rng(1), Y.Traits(amplitude=0.8, cycles=40.0, excess=0.4, white=0.003,
                                                            zeta=1e-3))
    fit = F.fit_oscillation(rec.t, rec.y, "angle", LAW)
    assert fit.law.conflict is None and fit.law.learned > 0.5  # mostly the record's (measured 0.90)
    assert abs(fit.period - rec.period) < 3.0 * fit.period_std  # 3 sigma: one draw


@pytest.mark.slow
def test_a_mode_beating_near_the_torsion_is_not_read_as_a_law():
    # a 250 Hz gyro record of 25 cycles from 0.22 rad with a sway at 0.9675 T0 (2.5 % of the swing):
    # under one beat over the record, its slow phase wobble reads as a chirp, and the law learned
    # from it (an excess 14 prior sigmas off) put T0 1.4 % short at 5 sigma. The beat's wobble of the
    # cycles' phase and envelope together finds it (.near.near_mode_of: measured at 0.9663 T0, 2.7 % of
    # the swing; the frequency to ~1 / (beats x SNR) of the gap, the size to its noise and decay): it is
    # subtracted and the law learned without it (measured z -0.44; the law's conflict, which held the
    # ideal law's T0 in the sigma, z -0.99, is gone)
    traits = Y.Traits(kind="rate", rate=250.0, amplitude=0.2176, cycles=25.0, excess=0.061, shape=-0.34,
                      zeta=4.4e-4, quadratic=0.0035, dry=0.0014, white=0.0368, coloured=0.005, colour_time=0.083,
                      offset=0.039, drift=0.002, bias_walk=0.002, lost=0.015, burst=2.0,
                      second=(0.9675, 0.0252, 0.013))
    rec = Y.record(ROD, np.random.default_rng(6), traits)
    fit = F.fit_oscillation(rec.t, rec.y, "rate", LAW)
    assert fit.second_mode is not None
    assert fit.second_mode[0] / rec.period == pytest.approx(0.9675, abs=0.003)
    assert fit.second_mode[1] / (traits.amplitude * 2.0 * np.pi / rec.period) == pytest.approx(0.0252, rel=0.3)
    assert fit.law.conflict is None
    assert abs(fit.period - rec.period) < 1.96 * fit.period_std


@pytest.mark.slow
def test_a_narrow_range_of_swings_carries_the_law_s_extrapolation():
    # The rod from 1.2 rad to 1.05 over 80 cycles (light viscous damping), the ideal law, 1e-4 rad of
    # white noise: the three excess terms, fixed by the law's value, slope and curvature over that
    # range, extrapolate a 1e-5 misfit of its shape to ~1e-3 of T0, where the ideal law held gives T0 to
    # 6.7e-7. The sigma must carry that extrapolation and cover it. (With the envelope's terms chosen by
    # an F test it sat in the law's part, 1.5e-3, the error 1.6e-3; with Akaike's criterion the freer
    # envelope leaves it in the statistical part, 2.3e-3, the error 5.4e-4.)
    rec = Y.record(ROD, np.random.default_rng(5), Y.Traits(amplitude=1.2, cycles=80, zeta=2e-4, white=1e-4))
    fit = F.fit_oscillation(rec.t, rec.y, "angle", LAW)
    ideal = F.fit_oscillation(rec.t, rec.y, "angle", LAW, excess_prior=0.0)
    error = abs(fit.period - rec.period)
    assert abs(ideal.period - rec.period) < 3.0 * ideal.period_std  # measured 1.0
    assert fit.period_std > 100.0 * ideal.period_std  # measured 3400
    assert error < 1.96 * fit.period_std  # measured 0.23


@pytest.mark.parametrize("count, bound", [
    pytest.param(40, 0.35, marks=pytest.mark.slow),  # ~1 min: the old envelope's +0.40 fails it
    pytest.param(200, 0.15, marks=pytest.mark.long),  # ~5 min: issue 37's figure (python -m pytest -m long)
])
def test_long_clean_records_are_unbiased(count, bound):
    # ``count`` records of the rod from 0.8 rad over 100 cycles (light viscous damping, to 0.56 rad), 3 mrad
    # of white noise alone: the mean z of T0 is within ``bound`` (its standard error is 1 / sqrt(count):
    # 0.16 for 40, 0.07 for 200) and the first amplitude's mean error within 5e-4 (the draws' own ~3e-5).
    # The envelope chosen by an F test at ~3 sigma left ln A's curvature out: z +0.40 +- 0.11 and the first
    # amplitude -3.0e-4 over 40 such records; with Akaike's criterion z -0.02 +- 0.10 and -7e-5.
    traits = Y.Traits(amplitude=0.8, cycles=100.0, zeta=5e-4, white=0.003)
    z, first, at = [], [], []
    for seed in range(count):
        rec = Y.record(ROD, np.random.default_rng(seed), traits)
        fit = F.fit_oscillation(rec.t, rec.y, "angle", LAW)
        z.append((fit.period - rec.period) / fit.period_std)
        first.append(fit.amplitude[0])
        at.append(fit.cycle_time[0])
    assert abs(np.mean(z)) < bound
    assert abs(np.mean(np.array(first) / Y.peaks(ROD, traits, np.array(at)) - 1.0)) < 5e-4
