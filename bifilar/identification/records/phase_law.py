"""The phases' law: every measured cycle's phase on one curve, Phi(t) = phi0 + omega0 int dt / (R E D).

Steps 4 and 5 of the record fit (:mod:`.fit`). The cycles (:mod:`.cycles`) each give a phase and an
amplitude; :class:`Model` asks one thing of all of them together, the rig's amplitude law, and returns
it fitted, a frozen :class:`.phase_fit.PhaseFit`: A(t) the peak amplitude (the cycles' amplitudes through
the waveform the record shows, ln A a Chebyshev series of the degree Akaike's criterion allows:
:class:`_Envelope`), R the ideal law (:mod:`.law`), E = 1 + ds A^2 + dq A^4 + d6 A^6 the real rig's
excess with Gaussian priors, D the damping's shift of the frequency
(:mod:`.damping`). Weighted least squares gives omega0 = 2 pi / T0 and the excess; the covariance is
the long-run covariance of the cycles' scores (:mod:`.spread`) plus what the envelope's own
uncertainty and the choice of its degree add (:meth:`Model.envelope_doubt`), the priors' part apart,
and a delete-a-group jackknife (:meth:`Model.jackknife`) checks it. A proportional record of a
compound pendulum has its scale q = kappa^2 from its own third harmonic (:func:`harmonic_scale`), a prior
of the fit whose doubt is the law's part of T0's sigma. The learned law's own doubts
(its extrapolation to zero swing, a law no rig has) are measured by refitting (:meth:`Model.check_law`).
Every refit is a new fit of the same :class:`Model` under other options, never the fit changed in place.
The law's local frequency and decay are what the next pass's windows are fitted with
(:meth:`.phase_fit.PhaseFit.local`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from .cycles import Cycles
from .damping import damping_of, damping_shift
from .law import AmplitudeLaw, Table
from .near import DECAY_P, decay_misfit, envelope_rises
from .phase_fit import EXCESS_TERMS, PhaseFit
from .read import MIN_CYCLES
from .spread import jackknife_inflation, long_run, sandwich

JACKKNIFE_GROUPS = 20  # groups of cycles of the jackknife (Model.jackknife): its variance has ~19 dof
_PHASE_Z = 6.0  # a cycle's phase this many robust sigmas off the law: a slip (left out)
# ... and this far in rad: a tracker's jump moves a window's phase by a good part of a radian, where
# what the law's few terms leave at the largest swings of a clean record is ~1e-3 rad
_SLIP_FLOOR = 0.02
_GRID_PER_CYCLE = 8  # integration points of the law's phase integral per cycle (trapezoid, smooth)
_ENVELOPE_DEGREE = 8  # at most: ln A of a decay to a third of the start over the record needs ~5
# One more term of the envelope must lower chi^2 by this times the residual variance (Akaike's 2: a term
# worth more than it costs). The envelope is the law's regressor: a term left out biases every record
# alike (ln A of a light viscous decay is curved, the law's frequency shift changes the decay rate by
# 2 % over 100 cycles from 0.8 rad; a straight line put the ends' amplitudes 3e-4 low and T0 +0.40 sigma
# long on average over 40 white-noise records), one too many only adds variance, which the covariance
# carries (Murphy-Topel). At 9 (an F test at ~3 sigma) it was that bias; at 2, z -0.02 +- 0.10.
_ENVELOPE_F = 2.0
# A record whose T(A) asks for an excess this many prior sigmas from the ideal law at some amplitude it
# swung through follows no rig's law (real ones differ by up to 30-40 %, about one prior sigma): a mode
# close to the torsion's frequency beating in (its slow phase wobble reads as a chirp), or a rig file
# whose law is wrong. Either T0, the one learned or the one under the ideal law, may then be the right
# one: their difference enters T0's sigma (:meth:`Model.check_law`) and the fit says so (``Law.conflict``).
# Learned alone from a gyro record with a mode 3 % from the torsion's, T0 came out 1.4 % off at 5 sigma.
LAW_CONFLICT = 3.0
_WEIGHT_FLOOR = 1e-3  # an envelope degree of less Akaike weight is not refitted (Model.envelope_doubt)
_HELD = 1e-6  # a held excess's prior sd, relative to the prior's own: the data cannot move it
# Gauss-Newton's last step: omega0's relative step (the excess terms' 100x that, relative to 1 + |d|). It
# converges quadratically (omega0's steps 3e-2, 3e-6, 8e-9, 1e-12 on a 100-cycle record), so after a step
# this small the next is at the rounding floor (~1e-13 of omega0 on 100 cycles: a test at 1e-14 was never
# met there, and ran every solve to the 40-step cap), ~1e-8 of a sigma
_CONVERGED = 1e-10


@dataclass(frozen=True)
class Model:
    """The phases' law (module docstring; :mod:`.fit`, step 4): its configuration, the ideal law ``law``,
    the record's ``kind``, the excess's ``prior`` (relative sd) and a proportional record's
    ``max_amplitude`` (rad). :meth:`fit` fits it to the good cycles of a pass and returns a frozen
    :class:`.phase_fit.PhaseFit`; the refits that measure the fit's doubts (:meth:`check_law`,
    :meth:`jackknife`) are the same solve under other options, each a new fit.

    The amplitude the law is evaluated at is measured with noise too: it is a smooth envelope fitted to
    the cycles' amplitudes alone (:class:`_Envelope`), and what its uncertainty does to T0 is added to
    the covariance (:func:`_covariance`).
    """

    law: AmplitudeLaw
    kind: str
    prior: float
    max_amplitude: float | None

    def _table(self, previous: PhaseFit | None, omega: float, largest: float) -> tuple[tuple[float, float], Table]:
        """(key, table): the law's table at ``omega`` up to ``largest`` rad, the ``previous`` fit's unless
        omega moved by over 1e-6 of it or the table is too short: the exact law's R depends on omega through
        lam omega^2 (d R / d ln omega = eps A^2 / 2 < 0.1 for any rig's eps and A < 1.4 rad), so R stays
        right to 1e-7."""
        key = None if previous is None else previous.table_key
        if key is None or abs(key[0] / omega - 1.0) > 1e-6 or key[1] < largest:
            return (omega, largest), self.law.table(omega, largest)
        return key, previous.table

    def fit(self, cyc: Cycles, previous: PhaseFit | None = None, slips: bool = False) -> PhaseFit:
        """The law fitted to the good cycles, from the ``previous`` pass's omega0 (and its table; the
        cycles' median frequency on the first pass); with ``slips``, cycles whose phase is far off the law
        are marked bad in ``cyc`` (the tracker jumped) and the rest refitted."""
        good = cyc.good & np.isfinite(cyc.phase)
        for _ in range(3):
            if good.sum() < MIN_CYCLES:
                raise ValueError(f"{int(good.sum())} cycles could be measured on their own; at least "
                                 f"{MIN_CYCLES} are needed")
            previous = self._solve(cyc, good, previous)
            if not slips:
                break
            z = previous.residual / np.sqrt(previous.var)
            robust = 1.4826 * float(np.median(np.abs(z))) or 1.0
            slip = (np.abs(z) > _PHASE_Z * max(robust, 1.0)) & (np.abs(previous.residual) > _SLIP_FLOOR)
            if not slip.any():
                break
            for k in np.flatnonzero(good)[slip]:
                cyc.good[k] = False
                cyc.reason[k] = "phase slips off the law (the tracker jumped)"
            good = cyc.good & np.isfinite(cyc.phase)
        return previous

    def _solve(self, cyc: Cycles, good: np.ndarray, previous: PhaseFit | None, free: int = len(EXCESS_TERMS),
               held: bool = False, parent: PhaseFit | None = None, degree: int | None = None) -> PhaseFit:
        """One fit of the cycles ``good``, started from ``previous`` (:meth:`fit`), with the first ``free``
        excess terms free and the rest held at zero, or all ``held`` at the ideal law (:meth:`check_law`);
        a jackknife refit (:meth:`jackknife`) takes its ``parent``'s scale, damping shift and start;
        ``degree``: the envelope's, where not Akaike's choice (:meth:`envelope_doubt`)."""
        centre, var = cyc.centre[good], cyc.phase_var[good]
        n = len(centre)
        # the cycles' peak amplitudes (signal units; of the angle for a rate) and their ln variances
        a1 = cyc.fundamental[good] / (cyc.omega[good] if self.kind == "rate" else 1.0)
        shape = _waveform(a1, cyc.peak_ratio[good])
        peak_data = a1 * (1.0 + shape[0] * a1**2 + shape[1] * a1**4)
        log_sd = np.sqrt(cyc.amplitude_var[good]) / cyc.fundamental[good]
        grid = _phase_grid(centre)
        envelope = _Envelope(centre, np.log(peak_data), log_sd, degree)
        b_grid = envelope.basis(grid)
        amp_grid = np.exp(b_grid @ envelope.beta)
        omega = float(np.median(cyc.omega[good])) if previous is None else previous.omega0
        largest = float(amp_grid.max())
        law_on = self.law.kind != "linear"
        kappa_max = None
        harmonic = None  # (q centre, q sd, rate): the swing's scale from the third harmonic (:func:`harmonic_scale`)
        if self.kind == "proportional":
            kappa_max = self.max_amplitude / largest if self.max_amplitude is not None else None
            largest_rad = self.max_amplitude or 0.0
            if kappa_max is None and law_on and pendulum(self.law):
                if parent is not None and parent.harmonic is not None:
                    harmonic = parent.harmonic  # a jackknife refit: the scale's doubt is the law's part
                else:
                    harmonic = harmonic_scale(np.exp(envelope.basis(centre) @ envelope.beta),
                                              cyc.third[good], cyc.third_var[good])
                q_top = harmonic[0] + 6.0 * harmonic[1]
                largest_rad = swing_of(math.sqrt(max(q_top, 0.0)) * largest, harmonic[2])
        else:
            largest_rad = largest
        s = self.law.coefficient(omega)
        table_key, table = self._table(previous, omega, 1.05 * largest_rad) if law_on else (None, None)
        phase = unwrap(cyc, good)
        names = ["phi", "omega"]
        start = [0.0, omega]
        priors = []  # (index, centre, sd)
        if law_on and self.prior > 0.0:
            names += list(EXCESS_TERMS)
            start += [0.0] * len(EXCESS_TERMS)
            priors += [(2 + j, 0.0, (_HELD if held or j >= free else 1.0) * self.prior * abs(s))
                       for j in range(len(EXCESS_TERMS))]
        if harmonic is not None:
            names.append("q")
            start.append(max(harmonic[0], 0.0))
            priors.append((len(names) - 1, harmonic[0], harmonic[1]))
        if law_on and kappa_max is not None:
            names.append("kappa")
            start.append(0.5 * kappa_max)
            priors.append((len(names) - 1, 0.5 * kappa_max, kappa_max / math.sqrt(12.0)))
        ref = float(np.average(centre, weights=1.0 / var))
        at = np.searchsorted(grid, centre)
        at_ref = float(np.interp(ref, grid, np.arange(len(grid))))
        weights = 1.0 / np.sqrt(var)
        # the damping's own lengthening of the period, second order in it (:func:`damping_shift`)
        if parent is None:
            damping = damping_of(grid, amp_grid, omega)
            shift = damping_shift(damping, amp_grid)
        else:  # a ~1e-5 effect that leaving out a group of cycles moves by a few % of itself
            damping = parent.damping
            shift = np.interp(amp_grid, *parent.shift_curve)
        order = np.argsort(amp_grid)
        shift_curve = (amp_grid[order], shift[order])
        slow = 1.0 / (1.0 + shift)

        def terms(p):
            """(amplitude A(t) in rad on the grid, 1 / (R E D), d(1 / (R E D)) / d ln a, and its
            derivatives in the law's parameters)."""
            amp = amp_grid
            if not law_on:
                return amp, slow, np.zeros_like(amp), []
            kappa = p[names.index("kappa")] if "kappa" in names else 1.0
            if "q" in names:  # q = kappa^2; a rate's peak is 2 sin(A / 2) of the angle's (the energy)
                x = math.sqrt(max(p[names.index("q")], 0.0)) * amp
                a = np.minimum(swing_of(x, harmonic[2]), table.largest)
                da_dx = 1.0 / np.sqrt(np.maximum(1.0 - 0.25 * x * x, 1e-12)) if harmonic[2] else np.ones_like(x)
            else:
                a = np.minimum(kappa * amp, table.largest)
            a2 = a * a
            d = p[2:2 + len(EXCESS_TERMS)] if "ds" in names else np.zeros(len(EXCESS_TERMS))
            powers = [a2 ** (j + 1) for j in range(len(EXCESS_TERMS))]
            excess = 1.0 + sum(dj * pw for dj, pw in zip(d, powers))
            growth = sum(2.0 * (j + 1) * dj * a2**j for j, dj in enumerate(d))  # dE/da / a
            ratio = table.ratio_at(a)
            g = slow / (ratio * excess)
            # d g / d a over a, finite at a = 0 (R is even in A)
            floor = np.maximum(a, 1e-6)
            dg_da_a = -g * (table.ratio_slope(floor) / floor / ratio + growth / excess)
            dg_da = dg_da_a * a
            dg_dlna = a * dg_da if "q" not in names else dg_da_a * a * x * da_dx
            slopes = [-g * pw / excess for pw in powers] if "ds" in names else []
            if "kappa" in names:  # d g / d kappa = A d g / d a: finite at kappa = 0, where a is 0
                slopes.append(amp * dg_da)
            if "q" in names:  # d g / d q = (d g / d a) (d a / d x) amp^2 / (2 x): finite at q = 0
                slopes.append(dg_da_a * np.where(x > 1e-9, a / np.maximum(x, 1e-300), 1.0) * da_dx * amp * amp / 2.0)
            return a, g, dg_dlna, slopes

        def integral(f):
            cum = np.concatenate([np.zeros((1,) + f.shape[1:]),
                                  np.cumsum(0.5 * (f[1:] + f[:-1]) * np.diff(grid).reshape((-1,) + (1,) * (f.ndim - 1)),
                                           axis=0)])
            return cum[at] - _interp_rows(at_ref, cum)

        def evaluate(p):
            _, g, dg, slopes = terms(p)
            big = integral(g)
            r_phase = (phase - p[0] - p[1] * big) * weights
            cols = [-np.ones(n), -big] + [-p[1] * integral(d) for d in slopes]
            j_phase = np.column_stack(cols) * weights[:, None]
            j_envelope = -p[1] * integral(dg[:, None] * b_grid) * weights[:, None]
            rp = np.array([(p[i] - c) / sd for i, c, sd in priors])
            jp = np.zeros((len(priors), len(p)))
            for row, (i, _, sd) in enumerate(priors):
                jp[row, i] = 1.0 / sd
            return r_phase, j_phase, j_envelope, rp, jp

        # Gauss-Newton with the analytic Jacobian: phi0 and omega0 enter linearly, the rest nearly so; a
        # record at one amplitude leaves a direction to the priors alone, which finite differences of a
        # residual weighted by 1 / sigma_phase would drown in rounding.
        p = np.array(start, dtype=float)
        if parent is not None:
            p = parent.params.copy()
        p[0] = float(np.average(phase - p[1] * integral(terms(p)[1]), weights=weights**2))
        for _ in range(40):
            r_phase, j_phase, _, rp, jp = evaluate(p)
            jac = np.vstack([j_phase, jp])
            res = np.concatenate([r_phase, rp])
            col = np.maximum(np.linalg.norm(jac, axis=0), 1e-300)
            step = -np.linalg.lstsq(jac / col, res, rcond=None)[0] / col
            new = p + step
            new[1] = min(max(new[1], 0.5 * omega), 2.0 * omega)
            if "kappa" in names:
                new[names.index("kappa")] = max(new[names.index("kappa")], 0.0)
            if "q" in names:
                new[names.index("q")] = max(new[names.index("q")], 0.0)
            done = abs(new[1] - p[1]) <= _CONVERGED * p[1] and \
                np.all(np.abs(step[2:]) <= 100.0 * _CONVERGED * (1.0 + np.abs(p[2:])))
            p = new
            if done:
                break
        r_phase, j_phase, j_envelope, rp, jp = evaluate(p)
        a_fit, g_fit, _, _ = terms(p)
        conflict = 0.0
        if "ds" in names and not held:  # the excess at each amplitude swung through, in prior sigmas
            powers = np.array([(a_fit * a_fit) ** (j + 1) for j in range(len(EXCESS_TERMS))])
            sd = self.prior * abs(s) * np.sqrt(np.sum(powers**2, axis=0))
            conflict = float(np.max(np.abs(p[2:2 + len(EXCESS_TERMS)] @ powers) / np.maximum(sd, 1e-300)))
        bread_inv = bread(j_phase, jp)
        cov_stat, cov_law, prior_gain = _covariance(j_phase, jp, r_phase, j_envelope, envelope.cov, "ds" in names,
                                                    bread_inv)
        return PhaseFit(
            names=tuple(names), params=p, cov_stat=cov_stat, cov_law=cov_law,
            prior_gain=prior_gain, j_phase=j_phase, bread=bread_inv, envelope_degree=envelope.degree,
            envelope_weights=envelope.weights, residual=r_phase / weights, var=var, ideal=s if law_on else None,
            conflict=conflict, held=held, scale_known=self.kind != "proportional" or "kappa" in names or "q" in names,
            damping=damping, shift_curve=shift_curve, harmonic=harmonic, table=table, table_key=table_key,
            grid=grid, amplitude=amp_grid, peak=a_fit if law_on else None, rate=g_fit,
            decay=envelope.basis(grid, derivative=1) @ envelope.beta,
            phase_integral=(grid, _from_reference(grid, g_fit, at_ref), float(g_fit[0]), float(g_fit[-1])),
            # the integral's response to each law parameter (names[2:]) and their priors' sds, for the
            # Cramér-Rao bound of a whole fit with the law free (:mod:`.bound`)
            law_slopes=tuple((grid, _from_reference(grid, d, at_ref), float(d[0]), float(d[-1])) for d in terms(p)[3]),
            law_prior_sd=np.array([sd for _, _, sd in sorted(priors)]))

    def check_law(self, fit: PhaseFit, cyc: Cycles) -> PhaseFit:
        """``fit`` with two doubts of the learned law that T0's sigma carries (:func:`.fit._result`: the
        first where it is more than the sigma already holds), each the same cycles refitted:
        ``order_shift``, omega0 as fitted less omega0 with the excess's last term held at zero, and past
        :data:`LAW_CONFLICT` ``held_shift``, omega0 less omega0 with the whole excess held at the ideal law;
        the same where the cycles' envelope rises (:func:`.near.envelope_rises`) or decays as no damping
        law does (:func:`.near.decay_misfit` below :data:`.near.DECAY_P`): a mode beating in, which the law
        learns as a frequency moving with the swing, within its prior. That difference is kept
        whatever the conflict (``ideal_shift``): fits of one rig whose learned laws disagree hold it
        (:func:`.pipeline._own_variances`).

        The first is the extrapolation's: a record whose swing spans a narrow range (a lightly damped
        rig from 1.2 rad to 1.05) gives the law's value, slope and curvature there so precisely that
        the three terms seem determined, and their extrapolation to zero swing turns a 1e-5 misfit of
        the law's shape into 1.5e-3 of T0 (6-8 sigma of the covariance's, which only counts the
        noise); with one term fewer, where the record does determine the law, the two agree to a
        fraction of their sigma."""
        good = cyc.good & np.isfinite(cyc.phase)
        learned = "ds" in fit.names and not fit.held
        centre, amplitude = cyc.centre[good], cyc.fundamental[good]
        rises = "ds" in fit.names and (envelope_rises(centre, amplitude) or decay_misfit(
            centre, amplitude, np.sqrt(cyc.amplitude_var[good]), _ENVELOPE_DEGREE) < DECAY_P)
        if not learned:
            return replace(fit, order_shift=0.0, held_shift=0.0, ideal_shift=0.0, rises=rises)
        fewer = self._solve(cyc, good, fit, free=len(EXCESS_TERMS) - 1)
        ideal_shift = fit.omega0 - self._solve(cyc, good, fit, held=True).omega0
        return replace(fit, order_shift=fit.omega0 - fewer.omega0, ideal_shift=ideal_shift, rises=rises,
                       held_shift=ideal_shift if fit.conflict > LAW_CONFLICT or rises else 0.0)

    def jackknife(self, fit: PhaseFit, cyc: Cycles) -> tuple[float, int, float, float]:
        """(variance of omega0, groups, ratio, dof): the delete-a-group jackknife of ``fit`` over up to
        :data:`JACKKNIFE_GROUPS` contiguous groups of the good cycles, each refitted whole (waveform,
        envelope and phases) with the envelope's degree held (the doubt of that choice is
        :meth:`envelope_doubt`'s). It sees the paths by which a record's noise reaches omega0 that the
        covariance does not model (the law's shape misfit, what moves a cycle's phase and amplitude
        together); of an honest covariance it gives ``ratio`` times omega0's variance, a variance of
        ``dof`` degrees of freedom (:func:`.spread.jackknife_inflation`: the groups at the ends move
        omega0 more than their share), which :mod:`.fit` tests it against."""
        good = np.flatnonzero(cyc.good & np.isfinite(cyc.phase))
        groups = min(JACKKNIFE_GROUPS, len(good))
        if groups < 5:
            return 0.0, 0, 1.0, 1.0
        start = fit
        if self.law.kind != "linear":  # the refits' table: at their starting omega0, and room for
            key, table = self._table(fit, fit.omega0, 1.2 * fit.table_key[1])  # an envelope a little higher
            start = replace(fit, table_key=key, table=table)  # without a group
        omegas = []
        for part in np.array_split(good, groups):
            keep = cyc.good & np.isfinite(cyc.phase)
            keep[part] = False
            omegas.append(self._solve(cyc, keep, start, parent=fit, degree=fit.envelope_degree).omega0)
        omegas = np.array(omegas)
        ratio, dof = jackknife_inflation(fit.j_phase, fit.bread, groups)
        return float((groups - 1) / groups * np.sum((omegas - omegas.mean()) ** 2)), groups, ratio, dof

    def envelope_doubt(self, fit: PhaseFit, cyc: Cycles) -> float:
        """The variance of omega0 (rad^2/s^2) that choosing the envelope's degree adds (Buckland, Burnham
        and Augustin 1997): the cycles refitted at every degree of Akaike weight w_k above
        :data:`_WEIGHT_FLOOR`, sum w_k (omega_k - sum w_j omega_j)^2. The law reads the swing off the
        envelope, and where noise correlated within a cycle leaves Akaike's criterion unsure (weights of
        0.04-0.27 over degrees 2-8 on one 100-cycle video record of 0.8 rad), the degrees' T0 differ by
        up to ~1e-3 s, as much as the rest of the sigma: a spread the covariance, which holds the degree
        chosen, does not see. On such records it left the phase fit's covariance 1.5x short of the
        scatter, which the jackknife, reselecting the degree in every refit, took up in jumps (its sd
        1.7x the scatter in rms)."""
        w = fit.envelope_weights
        kept = np.flatnonzero(w > _WEIGHT_FLOOR)
        if len(kept) < 2:
            return 0.0
        good = cyc.good & np.isfinite(cyc.phase)
        omegas = np.array([fit.omega0 if k == fit.envelope_degree else self._solve(cyc, good, fit, degree=int(k)).omega0
                           for k in kept])
        weights = w[kept] / w[kept].sum()
        mean = float(weights @ omegas)
        return float(weights @ (omegas - mean) ** 2)


def unwrap(cyc: Cycles, good: np.ndarray) -> np.ndarray:
    """The good cycles' phases made continuous: each one within pi of its predecessor advanced by
    the local frequency over the time between them."""
    centre, phase, omega = cyc.centre[good], cyc.phase[good], cyc.omega[good]
    out = np.empty(len(phase))
    out[0] = phase[0]
    for k in range(1, len(phase)):
        advance = 0.5 * (omega[k] + omega[k - 1]) * (centre[k] - centre[k - 1])
        predicted = out[k - 1] + advance
        out[k] = phase[k] + 2.0 * math.pi * round((predicted - phase[k]) / (2.0 * math.pi))
    return out


def _covariance(jd, jp, r, j_envelope, cov_envelope, excess: bool, bread_inv: np.ndarray):
    """(statistical, priors', T0's gain on the excess's priors): :mod:`.fit`, step 5. The statistical
    part is the scores' long-run covariance (:func:`.spread.long_run`; at least the white one, unscaled)
    and what the envelope's own uncertainty adds (a two-step estimate's correction, Murphy and Topel:
    H^-1 (J^T J_A) V_A (J_A^T J) H^-1, J_A the phases' response to the envelope's coefficients);
    ``excess``: the law's excess terms are fitted (the first rows after phi and omega); ``bread_inv``:
    :func:`bread` of ``jd`` and ``jp``."""
    white = bread_inv @ (jd.T @ jd) @ bread_inv
    scores = long_run(jd, r, bread_inv)
    cross = jd.T @ j_envelope
    envelope = bread_inv @ cross @ cov_envelope @ cross.T @ bread_inv
    cov_stat = (scores if scores[1, 1] > white[1, 1] else white) + envelope
    cov_law = bread_inv @ (jp.T @ jp) @ bread_inv
    # T0's response to the law's prior being off by one sigma in each of its excess terms (their rows
    # come first): records of one rig share that error, while a proportional record's scale is its own
    law_rows = len(EXCESS_TERMS) if excess else 0
    return cov_stat, cov_law, (bread_inv @ jp.T)[1, :law_rows]


def bread(jd, jp) -> np.ndarray:
    """(J^T J + P^T P)^-1 of the phase fit (``jd`` its weighted phases' Jacobian, ``jp`` its priors'),
    equilibrated before the inverse: the columns differ by ~1e3 in scale (phase, omega0 times the
    record's span, the excess times A^2), and at a nearly constant swing the direction only the priors
    fix has ~1e-10 of the largest curvature, which pinv's cut would otherwise round away."""
    hessian = jd.T @ jd + jp.T @ jp
    scale = 1.0 / np.sqrt(np.maximum(np.diag(hessian), 1e-300))
    return scale[:, None] * np.linalg.pinv(scale[:, None] * hessian * scale[None, :]) * scale[None, :]


class _Envelope:
    """ln A(t) of the cycles' amplitudes as a Chebyshev series in the time scaled to [-1, 1], of the
    lowest degree past which one more term does not lower chi^2 by :data:`_ENVELOPE_F` times the
    residual variance (Akaike's criterion), at most :data:`_ENVELOPE_DEGREE`: as smooth as the decay
    the record shows and no smoother; or of the ``degree`` given (the refits that weigh that choice,
    :meth:`Model.envelope_doubt`). Fitted to the amplitudes alone: let the phases move it and their
    noise would pass for a law through it (an error in the regressor attenuates what it regresses).
    ``cov``: the coefficients' covariance, scaled by chi^2 per degree of freedom where that is above 1.
    ``weights``: each degree's Akaike weight, exp(-QAIC / 2) normalised, QAIC = chi^2 / c + 2 (degree + 1)
    with c the residual variance at the highest degree (the amplitudes' own variances understate
    noise correlated within a cycle ~10x, which the quasi-likelihood's c takes out)."""

    def __init__(self, t: np.ndarray, log_a: np.ndarray, sd: np.ndarray, degree: int | None = None):
        self.t0, self.t1 = float(t[0]), float(t[-1])
        n = len(t)
        top = min(_ENVELOPE_DEGREE, n - 2)
        fits = []
        for k in range(0, top + 1) if degree is None else [min(degree, top)]:
            x = self.basis(t, degree=k) / sd[:, None]
            beta, *_ = np.linalg.lstsq(x, log_a / sd, rcond=None)
            r = log_a / sd - x @ beta
            fits.append((k, beta, float(r @ r), max(n - k - 1, 1), x))
        best = fits[0]
        for fit in fits[1:]:
            if best[2] - fit[2] < _ENVELOPE_F * fit[2] / fit[3]:
                break
            best = fit
        self.degree, self.beta, _, _, x = best
        self.cov = sandwich(x, log_a / sd - x @ self.beta)
        self.weights = np.zeros(top + 1)
        if degree is not None:  # a refit at a degree given: its weight is the record's (envelope_doubt)
            self.weights[self.degree] = 1.0
            return
        c = max(fits[-1][2] / fits[-1][3], 1e-300)
        qaic = np.array([chi / c + 2.0 * (k + 1) for k, _, chi, _, _ in fits])
        w = np.exp(-0.5 * (qaic - qaic.min()))
        self.weights = w / w.sum()

    def basis(self, t: np.ndarray, derivative: int = 0, degree: int | None = None) -> np.ndarray:
        from numpy.polynomial import chebyshev as C

        degree = self.degree if degree is None else degree
        half = max(0.5 * (self.t1 - self.t0), 1e-300)
        u = np.clip((np.asarray(t) - 0.5 * (self.t0 + self.t1)) / half, -1.0, 1.0)
        cols = []
        for k in range(degree + 1):
            c = np.zeros(k + 1)
            c[k] = 1.0
            cols.append(C.chebval(u, C.chebder(c, derivative) if derivative else c) / half**derivative)
        return np.column_stack(cols)


# A compound pendulum's (theta'' = -omega^2 sin theta) waveform: theta = A cos(phi) + a3 cos(3 phi) + ..,
# a3 / A = -(A^2 / 192) H(A) (Lindstedt: the Duffing eps A^2 / 32 with eps = -1/6), and a rate's third
# harmonic over its fundamental, in its own phase, -3 a3 / A = +(A^2 / 64) H(A), with
# H = 1 + 0.0573 A^2 + 0.0039 A^4 fitted to the exact solution's Fourier coefficients (DOP853, rtol 1e-12)
# over 0.1..0.8 rad, right to 2e-4 of the ratio there (tests/test_gyro_scale.py).
_THIRD_H = (0.0573, 0.0039)
_THIRD_Z = 3.0  # the third harmonic this many sigmas from zero: its sign says rate (+) or angle (-)


def pendulum(law) -> bool:
    """Whether ``law`` is a compound pendulum's, theta'' = -omega^2 sin(theta) (:func:`..hinge.law_for_hinge`),
    whose waveform :func:`harmonic_scale` knows."""
    return law.kind == "exact" and law.rho == 0.0 and law.lam == 0.0


def swing_of(x, rate: bool):
    """The angle's amplitude (rad) of a peak ``x`` (the signal's peak times kappa): a rate's peak is
    2 sin(A / 2) omega0 (the energy), an angle's is A."""
    return 2.0 * np.arcsin(np.minimum(0.5 * np.asarray(x), 1.0)) if rate else np.asarray(x)


def third_ratio(a, rate: bool):
    """The third harmonic over the fundamental of a pendulum swinging at ``a`` rad: + for a rate, - for an
    angle (the constants above)."""
    a2 = np.asarray(a) ** 2
    h = 1.0 + _THIRD_H[0] * a2 + _THIRD_H[1] * a2 * a2
    return a2 * h / 64.0 if rate else -a2 * h / 192.0


def harmonic_scale(amp: np.ndarray, third: np.ndarray, third_var: np.ndarray) -> tuple[float, float, bool]:
    """(q, its sd, rate) of a proportional record of a compound pendulum: q = kappa^2, kappa the scale
    (rad of swing per signal unit of peak), from each cycle's third harmonic over its fundamental
    (``third``, variances ``third_var``) at its peak ``amp`` (signal units): weighted least squares of
    :func:`third_ratio`, the sd scaled by the misfit where chi^2 / dof is above 1. Its sign says
    whether the record is a rate (+) or an angle (-) where it is :data:`_THIRD_Z` sigmas from zero;
    where it is not (a swing of ~0.1 rad in 1 % noise), q is taken uniform on [0, the larger of the two
    readings' estimate + 2 sd] (centre and sd of that), so that its doubt is honest in T0's sigma."""
    ok = np.isfinite(third) & np.isfinite(third_var) & (third_var > 0.0)
    if ok.sum() < 2:
        return 0.0, 0.0, True
    amp, r, w = amp[ok], third[ok], 1.0 / third_var[ok]
    x2 = amp * amp

    def model(q, rate):
        return third_ratio(swing_of(math.sqrt(q) * amp, rate), rate)

    def solve(rate):
        c = 64.0 if rate else -192.0
        sxx = float(np.sum(w * x2 * x2))
        q = c * float(np.sum(w * r * x2)) / sxx
        if q > 0.0:  # Gauss-Newton on q (a numeric slope), from the leading order
            for _ in range(20):
                d = (model(q * 1.000001, rate) - model(q * 0.999999, rate)) / (2e-6 * q)
                step = float(np.sum(w * d * (r - model(q, rate))) / np.sum(w * d * d))
                q = max(q + step, 1e-3 * q)
                if abs(step) <= 1e-10 * q:
                    break
            d = (model(q * 1.000001, rate) - model(q * 0.999999, rate)) / (2e-6 * q)
            info = float(np.sum(w * d * d))
        else:
            info = sxx / (c * c)
        chi = float(np.sum(w * (r - model(max(q, 0.0), rate)) ** 2)) / max(len(r) - 1, 1)
        return q, math.sqrt(max(chi, 1.0) / info)

    beta = float(np.sum(w * r * x2) / np.sum(w * x2 * x2))  # the leading order, r = beta amp^2
    misfit = float(np.sum(w * (r - beta * x2) ** 2)) / max(len(r) - 1, 1)
    lead = beta * math.sqrt(float(np.sum(w * x2 * x2)) / max(misfit, 1.0))  # in its sigmas
    if abs(lead) >= _THIRD_Z:
        q, sd = solve(lead > 0.0)
        return q, sd, lead > 0.0
    top = max(max(q, 0.0) + 2.0 * sd for q, sd in (solve(True), solve(False)))
    return 0.5 * top, top / math.sqrt(12.0), lead > 0.0


def _from_reference(grid: np.ndarray, rate: np.ndarray, at_ref: float) -> np.ndarray:
    """The trapezoidal integral of ``rate`` over ``grid``, zero at grid index ``at_ref`` (fractional)."""
    cum = np.concatenate([[0.0], np.cumsum(0.5 * (rate[1:] + rate[:-1]) * np.diff(grid))])
    return cum - float(np.interp(at_ref, np.arange(len(grid)), cum))


def _waveform(a1: np.ndarray, peak_ratio: np.ndarray) -> np.ndarray:
    """(c1, c2) of peak / fundamental = 1 + c1 a1^2 + c2 a1^4, least squares over the cycles: the real
    rig's waveform, measured on the record (its harmonics are its law's, not the ideal law's: at 1.2 rad
    they differ by ~excess x 1 %, which moves A by 1e-4 and T0 with it)."""
    if len(a1) < 3:
        return np.zeros(2)
    return np.linalg.lstsq(np.column_stack([a1**2, a1**4]), peak_ratio - 1.0, rcond=None)[0]


def _interp_rows(at: float, cum: np.ndarray):
    """``cum`` (rows on a grid index) interpolated at fractional row ``at``."""
    i = min(int(at), len(cum) - 2)
    f = at - i
    return (1.0 - f) * cum[i] + f * cum[i + 1]


def _phase_grid(centre: np.ndarray) -> np.ndarray:
    """The cycles' centres with :data:`_GRID_PER_CYCLE` - 1 points between neighbours."""
    step = np.diff(centre) / _GRID_PER_CYCLE  # numpy's linspace(a, b, n, endpoint=False) for every pair at once
    inner = np.arange(_GRID_PER_CYCLE)[None, :] * step[:, None] + centre[:-1, None]
    return np.concatenate([inner.ravel(), centre[-1:]])
