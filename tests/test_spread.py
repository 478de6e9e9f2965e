"""The record fit's covariance estimators (bifilar.identification.records.spread) against Monte Carlo
draws of a straight-line fit, whose true covariance is known in closed form: the phase law's omega0 is
such a slope (phase against time), with the law's terms and priors beside it."""

import numpy as np
import pytest

from bifilar.identification.records.spread import jackknife_inflation, long_run, white_and_blocks

DRAWS = 3000


def _line(n: int):
    """Design [1, t] of ``n`` cycles, t on [-1, 1], and its inverse normal matrix."""
    x = np.column_stack([np.ones(n), np.linspace(-1.0, 1.0, n)])
    return x, np.linalg.inv(x.T @ x)


@pytest.mark.parametrize("n", [25, 60])
def test_the_long_run_covariance_of_alternating_errors_is_the_slope_s(n):
    # AR(1) errors of coefficient -0.4 (neighbouring cycles erring in turn, as a sway beating every few
    # cycles leaves them): the slope's variance is B X^T S X B with S the errors' covariance. The white
    # covariance scaled by chi^2 per dof states 2.3x it (the errors' size, not what reaches a slope);
    # Newey-West over two neighbours measured 1.07 (25 cycles) and 1.22 (60) of it over 3000 draws, whose
    # own Monte Carlo error is ~3 %: within 0.85-1.35, and at least 1.8x closer than the white one
    x, b = _line(n)
    lag = np.abs(np.arange(n)[:, None] - np.arange(n)[None, :])
    s = (-0.4) ** lag / (1.0 - 0.16)
    true = (b @ x.T @ s @ x @ b)[1, 1]
    chol = np.linalg.cholesky(s)
    rng = np.random.default_rng(7)
    long, white = [], []
    for _ in range(DRAWS):
        e = chol @ rng.standard_normal(n)
        r = e - x @ (b @ x.T @ e)
        long.append(long_run(x, r, b)[1, 1])
        white.append(white_and_blocks(x, r, b)[0][1, 1])
    ratio = float(np.mean(long)) / true
    assert 0.85 < ratio < 1.35
    assert float(np.mean(white)) / true > 1.8 * ratio


@pytest.mark.parametrize("prior", [0.0, 2.0])
def test_the_jackknife_s_leverage_ratio_and_degrees_of_freedom_are_the_refits(prior):
    # 25 cycles in 20 groups (the gyro records' jackknife), white errors of unit variance, a quadratic
    # term free or held by a prior row of weight ``prior``: each draw's delete-a-group jackknife of the
    # slope by explicit refits (the prior kept). Its mean over the slope's variance is the ratio the
    # deletion formula predicts, and its variance over the draws 2 mean^2 / dof (a quadratic form in
    # Gaussian errors). Predicted: 1.35 and 5.1 dof free, 1.17 and 6.6 held; Monte Carlo error over 3000
    # draws: the mean ~2 %, the variance ~6 % (its kurtosis makes it more for few dof)
    n, groups = 25, 20
    t = np.linspace(-1.0, 1.0, n)
    x = np.column_stack([np.ones(n), t, t * t])
    p = np.diag([0.0, 0.0, prior])
    b = np.linalg.inv(x.T @ x + p.T @ p)
    ratio, dof = jackknife_inflation(x, b, groups)
    maps = []
    for part in np.array_split(np.arange(n), groups):
        keep = np.setdiff1d(np.arange(n), part)
        xk = x[keep]
        sel = np.zeros((len(keep), n))
        sel[np.arange(len(keep)), keep] = 1.0
        maps.append((np.linalg.inv(xk.T @ xk + p.T @ p) @ xk.T @ sel)[1])  # the refit's slope, linear in y
    maps = np.array(maps)
    e = np.random.default_rng(11).standard_normal((n, DRAWS))
    slopes = maps @ e
    jack = (groups - 1) / groups * np.sum((slopes - slopes.mean(axis=0)) ** 2, axis=0)
    variance = (b @ x.T @ x @ b)[1, 1]
    assert float(np.mean(jack)) / variance == pytest.approx(ratio, rel=0.06)
    assert 2.0 * float(np.mean(jack)) ** 2 / float(np.var(jack)) == pytest.approx(dof, rel=0.2)
    assert ratio > 1.05 and dof < groups - 1  # the ends' leverage: more than the variance, fewer dof
