"""Issue 37 item 1, where the too-wide sigma of ordinary gyro trials comes from: for configurations of
``identify-record-trials`` (as ``benchmarks/trial_width.py`` draws them), COUNT repeated trials each,
the scatter of T0 against the statistical sigma the fit states and against the law-induced part of the
phase fit's covariance (:func:`bifilar.identification.records.phase_law._covariance`) as each candidate
estimator of the phase scores' covariance would make it (1 for an honest sigma; below 1: too wide):

    used   the estimator the fit uses (stop 49: the long-run covariance, :func:`.spread.long_run`, at
           least the white one) plus the envelope's part (before the jackknife, the envelope degree's
           doubt and the law's doubts, which ``stated`` adds)
    white  the white covariance unscaled (the cycles' own phase variances taken as they are)
    scaled the white covariance scaled by chi^2 per degree of freedom
    hc     the heteroscedastic sandwich (scores summed per cycle), dof from the hat matrix's trace
    nw2    Newey-West (Bartlett weights, lags 1-2): neighbouring cycles' scores may err together or
           alternate, which a white or block estimator reads as wider

The fits are this checkout's; the estimators other than ``used`` are computed here from the same
scores, by hooking the phase fit's covariance (the fit itself is unchanged). Prints the mean chi^2 per
degree of freedom of the phase fit and how often the jackknife set the sigma.

    PYTHONPATH=. python benchmarks/phase_variance.py COUNT [CONFIGURATIONS, default 0,2,5,7]

Measured on stop 48's code (30 trials each; docs/identification.md, "What is left"):

    configuration  stated    used   white  scaled      hc     nw2  chi2/dof  jackknife
    0               0.69    0.99    3.85    1.30    1.44    1.10    658.09        60%
    2               0.75    0.76    1.92    0.78    0.85    1.18      6.13         3%
    5               0.63    0.73    1.46    0.76    0.84    0.94      3.53        20%
    7               0.63    0.84    2.25    0.91    1.06    0.93     26.88        47%

On stop 49's (``used`` the long-run covariance; ``stated`` with the envelope degree's doubt and the
jackknife over its leverage; the same trials):

    configuration  stated    used   white  scaled      hc     nw2  chi2/dof  jackknife
    0               0.99    0.99    3.85    1.30    1.44    1.10    658.09         0%
    2               1.03    1.13    1.92    0.78    0.85    1.18      6.13        13%
    5               0.79    0.90    1.46    0.76    0.84    0.94      3.53        13%
    7               0.88    0.89    2.25    0.91    1.06    0.93     26.88         0%
"""

import math
import sys
from dataclasses import replace

import numpy as np

from bifilar.identification.records import phase_law
from bifilar.identification.records import synthetic as Y
from bifilar.identification.records.fit import fit_oscillation
from bifilar.identification.records.law import AmplitudeLaw
from bifilar.identification.records.phase_fit import EXCESS_TERMS, law_induced
from validate.cases.records import ROD

ESTIMATORS = ("used", "white", "scaled", "hc", "nw2")
_calls: list = []  # every phase fit's inputs to its covariance, in order
_final: list = []  # how many there were when the law's doubts were checked: the last is the final fit's
_covariance = phase_law._covariance
_check_law = phase_law.Model.check_law


def _recording(jd, jp, r, j_envelope, cov_envelope, excess, bread_inv):
    out = _covariance(jd, jp, r, j_envelope, cov_envelope, excess, bread_inv)
    _calls.append((jd, jp, r, j_envelope, cov_envelope, excess, out[0]))
    return out


def _checking(model, fit, cyc):
    _final.append(len(_calls))
    return _check_law(model, fit, cyc)


def estimates(jd, jp, r, j_envelope, cov_envelope, excess, cov_used) -> dict[str, float]:
    """omega0's law-induced variance less its priors' part (what the fit's statistical sigma holds
    beyond the whole fit's own) under each estimator of the phase scores' covariance."""
    bread = phase_law.bread(jd, jp)
    n, k = jd.shape
    hat = float(np.trace(jd @ bread @ jd.T))
    cross = jd.T @ j_envelope
    envelope = bread @ cross @ cov_envelope @ cross.T @ bread
    prior = bread @ (jp.T @ jp) @ bread
    white = bread @ (jd.T @ jd) @ bread
    scores = jd * r[:, None]
    meat = scores.T @ scores
    hac = meat.copy()
    for lag in (1, 2):
        c = scores[lag:].T @ scores[:-lag]
        hac += (1.0 - lag / 3.0) * (c + c.T)
    dof = n / max(n - hat, 1.0)
    covs = {"used": cov_used, "white": white + envelope,
            "scaled": white * max(1.0, float(r @ r) / max(n - k, 1)) + envelope,
            "hc": bread @ meat @ bread * dof + envelope, "nw2": bread @ hac @ bread * dof + envelope}
    law = list(range(2, 2 + len(EXCESS_TERMS))) if excess else []
    out = {name: law_induced(cov + prior, law) - prior[1, 1] if law else float(cov[1, 1]) for name, cov in covs.items()}
    out["chi2"] = float(r @ r) / max(n - hat, 1.0)
    return out


def main(count: int, configurations: list[int]) -> None:
    phase_law._covariance = _recording
    phase_law.Model.check_law = _checking
    law = AmplitudeLaw.torsion(ROD)
    rng = np.random.default_rng(1819)  # identify-record-trials' configurations, as trial_width.py draws them
    drawn = [Y.gyro(rng, rate=250.0, cycles=25.0) for _ in range(8)]
    print("configuration  stated  " + "  ".join(f"{e:>6}" for e in ESTIMATORS) + "  chi2/dof  jackknife")
    for k in configurations:
        sub = np.random.default_rng(1000 + k)
        errors, stated, jackknife = [], [], []
        variances = {e: [] for e in ESTIMATORS}
        chi = []
        for _ in range(count):
            traits = replace(drawn[k], amplitude=drawn[k].amplitude * sub.uniform(0.95, 1.05))
            rec = Y.record(ROD, sub, traits)
            _calls.clear()
            _final.clear()
            fit = fit_oscillation(rec.t, rec.y, "rate", law)
            final = _calls[_final[-1] - 1]
            to_period = fit.period**2 / (2.0 * math.pi)
            e = estimates(*final)
            for name in ESTIMATORS:
                variances[name].append(to_period**2 * e[name])
            chi.append(e["chi2"])
            errors.append(fit.period - rec.period)
            stated.append(fit.period_std_statistical)
            jackknife.append(fit.jackknife > 0)
        sd = float(np.std(errors, ddof=1))
        ratio = [sd / math.sqrt(float(np.mean(np.square(stated))))]
        ratio += [sd / math.sqrt(float(np.mean(variances[e]))) for e in ESTIMATORS]
        print(f"{k:<13} " + "  ".join(f"{x:6.2f}" for x in ratio) + f"  {np.mean(chi):8.2f}  {np.mean(jackknife):9.0%}",
              flush=True)


if __name__ == "__main__":
    if len(sys.argv) not in (2, 3):
        sys.exit("usage: python benchmarks/phase_variance.py COUNT [CONFIGURATIONS, e.g. 0,2,5,7]")
    main(int(sys.argv[1]), [int(c) for c in (sys.argv[2] if len(sys.argv) == 3 else "0,2,5,7").split(",")])
