"""The whole record fitted at once, the law's shape held: T0 with a plain damped-sine fit's efficiency.

Step 6 of the record fit (:mod:`.fit`). A cycle measured alone (:mod:`.cycles`) spends some of its
information on its own offset, envelope and harmonics, and a record of a few cycles gives only a few
phases; :func:`fit_whole` fits every kept sample with one phase law (:mod:`.phase_law`, its shape held
as the cycles gave it), one envelope and one second mode (:mod:`.second_mode`), and states omega0's
sandwich over cycles, scaled to the Student-t interval of its few blocks (:mod:`.spread`), and the
Cramér-Rao bound of omega0 for the same model and the noise its residual shows (:mod:`.bound`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from .bound import Bound, cramer_rao
from .cycles import Cycles, Samples, highest_harmonic
from .phase_fit import PhaseFit
from .second_mode import SECOND_DECAY_SPANS, Second, outside, peak_apart, swept_band
from .spread import block_length, few_blocks

_SECOND_SHARE = 0.5  # the largest second mode, relative to the first mode's largest swing


@dataclass
class Whole:
    """The whole record fitted at once, the law held (:func:`fit_whole`): omega0 (rad/s) and its
    statistical variance, its white-noise variance, the batch block (cycles), the refined second mode,
    the model at the samples used and their indices, and the Cramér-Rao bound of omega0 (:mod:`.bound`)."""

    omega0: float
    variance: float
    variance_white: float
    block: int
    second: Second | None
    fitted: np.ndarray
    index: np.ndarray
    bound: Bound


def fit_whole(rec: Samples, cyc: Cycles, law_fit: PhaseFit, baseline: np.ndarray, second: Second | None) -> Whole:
    """Every sample of the good cycles fitted at once, with the law's shape held as the cycles gave it (``law_fit``):

        y - baseline = c0 + c1 u + E(t) [cos Phi + sum_{n=3,5} (E / E_mean)^(n-1) (a_n cos n Phi + b_n sin n Phi)]
                       + e^(-a2 tau) (c2 cos w2 tau + s2 sin w2 tau),
        Phi = phi0 + omega0 int dt / (R E D),   E(t) = e^(e0 + e1 u) A_cycles(t),

    u the time from the middle over the span, A_cycles the amplitude the cycles measured (times the
    local frequency for a rate). A cycle measured alone spends some of its information on its own
    offset, envelope and harmonics, and a record of a few cycles gives only a few phases; here one
    phase law, one envelope and one second mode take all of it, the efficiency of a plain damped-sine
    least squares, while the law's chirp (from the cycles) keeps it right at large amplitude. The
    phase law's parameters other than phi0 and omega0 stay as the cycles fitted them; what their
    uncertainty does to omega0 is added after (:meth:`.phase_fit.PhaseFit.law_induced_variance`).

    Its uncertainty: the sandwich with the scores summed over each cycle, then over blocks of
    :data:`.spread.BLOCK_TAUS` integrated autocorrelation times of the omega0 score's cycle series, never
    below the white-noise covariance (residual variance times (J^T J)^-1).

    The samples: those of the good cycles, and the record's usable tail past the last of them (too
    short a cycle to measure alone, not too short to hold phase). A second mode the cycles did not
    show is looked for in this fit's own residual (:func:`peak_apart`), and the fit repeated with it."""
    good = np.flatnonzero(cyc.good & np.isfinite(cyc.phase))
    idx = np.unique(np.concatenate([cyc.index[k] for k in good]))
    tail = np.flatnonzero(cyc.usable & (rec.tau > rec.tau[idx[-1]]))
    idx = np.concatenate([idx, tail])
    tau = rec.tau[idx]
    y = rec.y[idx] - baseline[idx]
    span = max(tau[-1] - tau[0], 1e-300)
    u = (tau - 0.5 * (tau[0] + tau[-1])) / span
    integral = law_fit.integral_at(tau)
    envelope = law_fit.fund_at(tau) * (law_fit.local_omega(tau) if rec.kind == "rate" else 1.0)
    level = float(np.exp(np.mean(np.log(envelope))))
    harmonics = highest_harmonic(float(np.median([len(cyc.index[k]) for k in good])))
    first = [law_fit.phi0, law_fit.omega0, math.log(float(np.median(cyc.fundamental[good])) / level), 0.0]
    largest = _SECOND_SHARE * float(np.max(envelope))
    swept = swept_band(law_fit, cyc.centre[good])

    def plausible(f, near: bool = False) -> bool:
        """Its second mode at most _SECOND_SHARE of the first (a law misfit near the first mode's
        frequency would pass for one of comparable size) and apart from the band the first mode swept
        (:func:`.second_mode.outside`), unless the beat found it there (``near``: :mod:`.near`)."""
        scaled = tuple(w * f[0][1] / law_fit.omega0 for w in swept)
        return (math.hypot(*f[3][-2:]) * math.exp(-f[0][5] * tau[0]) <= largest
                and (near or outside(float(f[0][4]), scaled, span)))

    fit = _whole_fit(tau, y, u, integral, envelope, level, harmonics, first, second)
    if second is not None and not plausible(fit, second.near):
        second = None
        fit = _whole_fit(tau, y, u, integral, envelope, level, harmonics, first, None)
    if second is None:
        peak = peak_apart(tau, fit[2], tuple(w * fit[0][1] / law_fit.omega0 for w in swept))
        if peak is not None:
            with_second = _whole_fit(tau, y, u, integral, envelope, level, harmonics, list(fit[0][:4]),
                                     Second(peak, 0.0, 0.0, 0.0))
            if plausible(with_second):
                fit, second = with_second, Second(peak, 0.0, 0.0, 0.0)
    q, jac, r, beta, model_y = fit
    n, k = jac.shape
    bread = np.linalg.pinv(jac.T @ jac)
    white = bread * float(r @ r) / max(n - k, 1)
    cycle = np.floor((q[1] * (integral - integral[0])) / (2.0 * math.pi)).astype(int)
    scores = np.zeros((cycle.max() + 1, k))
    np.add.at(scores, cycle, jac * r[:, None])
    block = block_length(scores[:, 1]) if len(scores) >= 10 else 1
    blocks = np.add.reduceat(scores, np.arange(0, len(scores), block), axis=0)
    nb = len(blocks)
    sandwich = bread @ (blocks.T @ blocks) @ bread * (nb / max(nb - 1, 1)) * (n / max(n - k, 1))
    sandwich *= few_blocks(nb)
    refined = None
    if second is not None:
        c2, s2 = beta[-2:]
        refined = Second(float(q[4]), float(q[5]), float(c2), float(s2), second.near, second.held)
    # the law's parameters, held here, in the bound with their priors: the fundamental's response to them
    # (the harmonics' and a rate's envelope's, a few % of it, left out)
    law = (np.exp(q[2] + q[3] * u) * envelope * np.sin(q[0] + q[1] * integral))[:, None] * q[1] \
        * law_fit.law_integrals_at(tau)
    bound = cramer_rao(tau, r, jac, rec.step, 1, law, law_fit.law_prior_sd)
    return Whole(float(q[1]), float(max(white[1, 1], sandwich[1, 1])), float(white[1, 1]), int(block), refined,
                 model_y + baseline[idx], idx, bound)


def _whole_fit(tau, y, u, integral, envelope, level, harmonics, first, second):
    """The least squares of :func:`fit_whole` from ``first`` (phi0, omega0, e0, e1) and a second mode's
    (omega2, decay2) start if any: (parameters, Jacobian of the residual with the linear terms last,
    residual, linear terms, model)."""
    start = list(first)
    omega0 = start[1]
    held = second is not None and second.held  # the rig's frequency (.near.near_held): not a parameter
    if second is not None:
        start += [second.omega, second.decay]

    def design(q):
        if held:
            q = np.insert(q, 4, second.omega)
        phase = q[0] + q[1] * integral
        env = np.exp(q[2] + q[3] * u) * envelope
        cols = [np.ones_like(u), u]
        for n in range(3, harmonics + 1, 2):
            rel = env * (env / level) ** (n - 1)
            cols += [rel * np.cos(n * phase), rel * np.sin(n * phase)]
        if second is not None:
            decay = np.exp(-q[5] * tau)
            cols += [decay * np.cos(q[4] * tau), decay * np.sin(q[4] * tau)]
        return env * np.cos(phase), np.column_stack(cols)

    def residual(q):
        fixed, x = design(q)
        beta = np.linalg.lstsq(x, y - fixed, rcond=None)[0]
        return y - fixed - x @ beta

    lo = np.full(len(start), -np.inf)
    hi = np.full(len(start), np.inf)
    lo[1], hi[1] = 0.9 * omega0, 1.1 * omega0
    if second is not None:  # a mode beating in lasts the record (:func:`second_mode_of`)
        lo[5], hi[5] = 0.0, SECOND_DECAY_SPANS / max(tau[-1] - tau[0], 1e-300)
    start = np.clip(np.array(start, dtype=float), lo, hi)
    if held:
        start, lo, hi = (np.delete(v, 4) for v in (start, lo, hi))
    sol = least_squares(residual, start, bounds=(lo, hi), x_scale="jac", xtol=1e-12, ftol=1e-12, gtol=1e-12)
    q = sol.x
    fixed, x = design(q)
    if held:
        q = np.insert(q, 4, second.omega)
    beta = np.linalg.lstsq(x, y - fixed, rcond=None)[0]
    model_y = fixed + x @ beta
    return q, np.column_stack([sol.jac, -x]), y - model_y, beta, model_y
