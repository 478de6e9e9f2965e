"""The spread of least-squares estimates from records whose errors are not white: the covariances the
record fit (:mod:`.fit`) states.

Tracker noise correlated over many frames, a wandering offset, a left-over beat all make neighbouring
cycles err together, and a covariance that assumes white errors then states too small a sigma. The
scores are summed over blocks of :data:`BLOCK_TAUS` integrated autocorrelation times (a batch-means
sandwich, :func:`white_and_blocks`), never below the white-noise covariance; a sandwich over few blocks
is itself uncertain and is scaled to its Student-t interval (:func:`few_blocks`). Where neighbours err
in turn instead (residuals that alternate), the phase law's coefficients take the long-run variance of
the scores (:func:`long_run`). The phase law's own jackknife (:meth:`.phase_law.Model.jackknife`)
checks these.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.stats import norm
from scipy.stats import t as student_t

BLOCK_TAUS = 4.0  # batch-means block, in integrated autocorrelation times of the phase residuals


def white_and_blocks(x: np.ndarray, r: np.ndarray, bread_inv: np.ndarray):
    """(white, block sandwich, block length) covariances of least-squares coefficients of weighted
    design ``x`` with residuals ``r`` (``bread_inv`` the inverse normal matrix, priors included): the
    white one scaled by chi^2 per degree of freedom where that is above 1, the sandwich's scores summed
    over blocks of :func:`block_length` neighbours (errors correlated over several cycles)."""
    n, k = x.shape
    white = bread_inv @ (x.T @ x) @ bread_inv * max(1.0, float(r @ r) / max(n - k, 1))
    block = block_length(r)
    sand = bread_inv @ _block_meat(x * r[:, None], block) @ bread_inv * (n / max(n - k, 1))
    return white, sand, block


def _block_meat(scores: np.ndarray, block: int) -> np.ndarray:
    """The batch-means meat of a sandwich: the ``scores`` (a row per cycle) summed over blocks of
    ``block`` neighbours, the sums' outer product over the blocks times nb / (nb - 1)."""
    sums = np.add.reduceat(scores, np.arange(0, len(scores), block), axis=0)
    nb = len(sums)
    return sums.T @ sums * (nb / max(nb - 1, 1))


def long_run(x: np.ndarray, r: np.ndarray, bread_inv: np.ndarray) -> np.ndarray:
    """The covariance of least-squares coefficients of weighted design ``x`` with residuals ``r``
    (``bread_inv`` the inverse normal matrix, priors included) from the long-run variance of the scores
    x_i r_i, unscaled by any white noise's: where neighbours err together over several cycles
    (:func:`block_length` above one: a bias's random walk, noise correlated over cycles) the scores
    summed over such blocks (batch means, as :func:`white_and_blocks`); otherwise Newey-West over two
    neighbours (Bartlett's weights 2/3 and 1/3). A sway beating in every few cycles, the law's misfit,
    noise correlated within a cycle leave phase residuals 2-25x their white variance whose neighbours
    alternate (lag-1 correlation to -0.4): a slow coefficient such as omega0 sums them over many cycles
    and feels them less than their size, which the white covariance scaled by chi^2 per degree of
    freedom does not see (it stated 1.3-1.9x the scatter of repeated gyro trials, Newey-West
    0.93-1.18: ``python benchmarks/phase_variance.py 30``)."""
    n, k = x.shape
    scores = x * r[:, None]
    block = block_length(r)
    if block > 1:
        meat = _block_meat(scores, block)
    else:
        meat = scores.T @ scores
        for lag in (1, 2):
            c = scores[lag:].T @ scores[:-lag]
            meat += (1.0 - lag / 3.0) * (c + c.T)
    return bread_inv @ meat @ bread_inv * (n / max(n - k, 1))


def sandwich(x: np.ndarray, r: np.ndarray) -> np.ndarray:
    """The covariance of plain weighted least squares (design ``x``, residuals ``r``): the block
    sandwich of :func:`white_and_blocks` where it is the larger in total (``tr(W^-1 S) > k``), never
    below the white one."""
    bread_inv = np.linalg.pinv(x.T @ x)
    white, sand, _ = white_and_blocks(x, r, bread_inv)
    return sand if float(np.trace(np.linalg.pinv(white) @ sand)) > x.shape[1] else white


def few_blocks(nb: int) -> float:
    """The variance factor that makes a normal 95 % interval from a sandwich over ``nb`` blocks the
    Student-t interval it is ((t_0.975(nb - 1) / z_0.975)^2): such a variance is itself estimated from
    nb - 1 degrees of freedom, and a short record (a 6-cycle laser record: 6 blocks, a factor 1.56)
    would otherwise state intervals that hold the truth in ~85 % of records, not 95 %."""
    return (float(student_t.ppf(0.975, max(nb - 1, 1))) / float(norm.ppf(0.975))) ** 2


def block_length(r: np.ndarray) -> int:
    """:data:`BLOCK_TAUS` integrated autocorrelation times of ``r`` (initial positive sequence), at most
    a fifth of the cycles (fewer blocks and their variance is itself too uncertain)."""
    n = len(r)
    if n < 10:
        return 1
    x = r - r.mean()
    f = np.fft.rfft(x, 2 * n)
    acf = np.fft.irfft(f * np.conj(f))[:n]
    acf = acf / acf[0]
    below = np.flatnonzero(acf < 0.0)
    stop = int(below[0]) if len(below) else n
    tau_int = 1.0 + 2.0 * float(acf[1:stop].sum())
    return int(min(max(1, math.ceil(BLOCK_TAUS * tau_int)) if tau_int > 1.5 else 1, max(1, n // 5)))


def jackknife_inflation(x: np.ndarray, bread_inv: np.ndarray, groups: int, row: int = 1) -> tuple[float, float]:
    """(ratio, degrees of freedom): what a delete-a-group jackknife over ``groups`` contiguous groups of
    the rows of weighted design ``x`` gives for coefficient ``row`` over that coefficient's variance, to
    first order where the errors are white, and Satterthwaite's degrees of freedom of that quadratic
    form. Leaving out group g moves the coefficient by -w_g^T (I - H_gg)^-1 r_g (w = X H^-1 e_row,
    H = X H^-1 X^T the hat matrix, r = (I - H) e): the groups at a record's ends, where H_gg reaches
    ~0.6, move it more than their share, and their few large terms leave the jackknife fewer degrees of
    freedom than its groups (5-9 of 19 on 25-cycle gyro records). A plain jackknife of an honest
    covariance exceeds it by that ratio: tested against the covariance alone it set the sigma of
    20-60 % of ordinary gyro records, 1.3-1.6x their trials' scatter."""
    n = x.shape[0]
    w = x @ bread_inv[:, row]
    resid = np.eye(n) - x @ bread_inv @ x.T
    moves = np.zeros((groups, n))
    for g, part in enumerate(np.array_split(np.arange(n), groups)):
        moves[g, part] = -np.linalg.solve(resid[np.ix_(part, part)], w[part])
    effect = moves @ resid
    centred = effect - effect.mean(axis=0)  # the jackknife is (groups - 1) / groups e^T C^T C e
    gram = centred @ centred.T
    trace = float(np.trace(gram))
    expected = (groups - 1) / groups * trace
    dof = trace**2 / max(float(np.sum(gram * gram)), 1e-300)
    return expected / max(float(w @ w), 1e-300), dof
