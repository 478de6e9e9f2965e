"""The record fit's statistical sigma checked by its jackknife (bifilar.identification.records.fit,
_Model.jackknife): tracking noise correlated over a fraction of a cycle moves a cycle's phase,
amplitude and waveform together, which the fit's covariance does not model. On such records the
jackknife over 20 groups of cycles is larger than the covariance at 95 % and sets the sigma; on short
clean records it is not, and the covariance's efficiency is kept. Coverage over many records with
every real trait is the slow case ``identify-record-coverage``."""

import numpy as np
import pytest

import bifilar.identification.records.fit as F
from bifilar.identification.records import synthetic as Y
from bifilar.identification.records.law import AmplitudeLaw
from bifilar.motion import lagrange as L

ROD = L.TorsionRig.parallel(0.5, 0.0016, 0.8, 0.196)
LAW = AmplitudeLaw.torsion(ROD)


def test_the_jackknife_widens_a_covariance_that_coloured_noise_leaves_short(monkeypatch):
    # 100 cycles from 0.8 rad with AR(1) noise of 6.6 mrad over 0.12 s (a video tracker's), a law 25 %
    # stronger than the ideal: over 16 such records T0 scattered 1.9x the covariance's sigma
    traits = Y.Traits(amplitude=0.8, cycles=100.0, white=0.0035, coloured=0.0066, colour_time=0.12,
                      zeta=1.2e-3, excess=0.25, shape=0.1)
    rec = Y.record(ROD, np.random.default_rng(0), traits)
    fit = F.fit_oscillation(rec.t, rec.y, "angle", LAW)
    monkeypatch.setattr(F, "JACKKNIFE_GROUPS", 0)
    alone = F.fit_oscillation(rec.t, rec.y, "angle", LAW)
    assert fit.jackknife == 20 and alone.jackknife == 0
    assert fit.period == alone.period  # the jackknife changes the sigma, never T0
    assert fit.period_std / alone.period_std > 1.5  # measured 2.04
    assert abs(fit.period - rec.period) / fit.period_std < 1.96 < abs(alone.period - rec.period) / alone.period_std


@pytest.mark.parametrize("seed", [0, 1])
def test_the_covariance_holds_on_a_short_clean_record(seed):
    # identify-record-efficiency's records: 10 cycles at 60 fps from 0.1 rad, 2 mrad of white noise
    rec = Y.record(ROD, np.random.default_rng(seed), Y.Traits(amplitude=0.1, cycles=10.0, white=0.002, zeta=1e-3))
    fit = F.fit_oscillation(rec.t, rec.y, "angle", LAW)
    assert fit.jackknife == 0
