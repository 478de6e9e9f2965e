"""A second mode near the first one's frequency: found by its beat, fitted beside the first mode, its
trade with the law carried into the sigma; and, where it cannot be fitted, seen in an envelope that one
mode's damping never lifts or bends so.

A sway within ~10 % of the torsion's frequency beats into the record. In the frame turning at omega0
the analytic signal is A(t) + c2 e^(i dw t): the beat moves the complex amplitude round a circle, so
the envelope and the phase wobble together, of the same relative size, in quadrature. The periodogram
search of :mod:`.second_mode` refuses the band the first mode sweeps (its own law misfit stands there),
and where it finds the sway just outside that band it fits it beside the law as the law was fitted, a
law that took part of the beat. To first order in its size a beat is an amplitude law whose frequency
moves with ln A at the beat frequency: a law free to move takes it, and extrapolates it into T0.

:func:`near_mode_of` fits the cycles' complex fundamentals as the first mode (its own damping's decay,
the ideal law's phase with the excess under its prior) plus a damped sinusoid within
:data:`NEAR_BAND`, against one mode with an envelope free to follow the wobble: the law, held to its
prior, cannot follow the phase's. Where the two modes fit better by :data:`NEAR_GAIN` of their own
residual variances, the mode is subtracted from the record and the law refitted without it
(:func:`near_refit` refits one the periodogram found in the band the same way). Mode and law still
trade what the record says of them: :func:`near_doubt` adds to omega0's variance what freeing the mode
adds in that fit. Searching the whole fit's residual instead (a sinusoid at each trial omega2, the rest
linearised) was tried and left out: with the learned law having taken the beat, the residual showed
the beat's mirror image (a sway at 0.963 omega0 turned up at 1.035) and joint fits wandered
(``benchmarks/near_mode.py``).

Half a beat or less over one record is often not told from a law at all: while the beat's phase
dw t + phi sweeps less than pi, the envelope's share of it moves one way, and the frequency the beat
adds, d arg(1 + eps e^(i (dw t + phi))) / dt, is a single-valued function of it, to every order in eps,
so it is an amplitude law (in the beat's part of ln A; the damping moves ln A alone). What tells it
apart then is that damping only shrinks the swing, and only as a damping law does: where the cycles'
envelope rises again (:func:`envelope_rises`) or decays as no one mode's does (two modes decay as two
exponentials of their own rates and wobble at their beat: :func:`decay_misfit`),
:meth:`.phase_law.Model.check_law` holds T0 under the ideal law in the sigma as well, as it does for a
law past its prior. And a rig has one law: records of it, or a record's two halves, each learn the
beat their own sway's phase and size ask for; where the excesses they learned disagree beyond their
sigmas, :func:`.pipeline._own_variances` measures their spread and carries it into each one's T0, in
the halves' test and in pooled trials. Where the sway is one of the rig's own modes the rig file says
where it lies: :func:`near_held` fits a mode there whatever its size, and the pipeline carries how far
that moves T0 into the sigma (:func:`.pipeline._with_rig_mode`). A sway under a beat that no record of
it shows and no rig places stays open (issue 37 item 1; docs/identification.md, "What is left").
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np
from scipy.integrate import cumulative_trapezoid
from scipy.optimize import least_squares
from scipy.stats import f as fisher

from .cycles import Cycles
from .phase_fit import PhaseFit
from .read import MIN_CYCLES
from .second_mode import SECOND_DECAY_SPANS, Second

NEAR_FLOOR = 1e-3  # relative rise below which a "beat" is the first mode's own law misfit
# (:func:`.second_mode.outside`: a noiseless record's misfit fitted as a mode at 2.7e-4 of the swing)

RISE_SIGMAS = 12.0  # a rise of the smoothed envelope this many of its sigmas: a beat. Of 400 flat noisy
# envelopes of 8-100 cycles each, the largest rise reached 7.6 at the 99th percentile, 12 at the most


def envelope_rises(times: np.ndarray, amplitudes: np.ndarray) -> bool:
    """Whether the cycles' amplitudes (at their centre ``times``) rise over the record: damping only
    shrinks a free oscillation's swing, and an amplitude law only ties its phase to it, but a mode
    beating in moves the complex amplitude round a circle and lifts the envelope again. To first order
    in its size the beat is then the same as a law whose frequency moves with ln A at its beat
    frequency, so the law learned from such a record may be the beat's (:meth:`.phase_law.Model.check_law`
    then holds the ideal law's T0 in the sigma too). ln A is smoothed by a polynomial (degree up to 3,
    one per 6 cycles); its largest rise (a later value above an earlier one) is compared with
    :data:`RISE_SIGMAS` sigmas of the smoothed curve (the fit's residual sigma times
    sqrt((degree + 1) / N)) and with :data:`NEAR_FLOOR`. Half a beat or less over the record may only
    steepen the decay, and several beats are more than the polynomial follows: neither is seen here."""
    ok = np.isfinite(amplitudes) & (amplitudes > 0.0)
    t, a = times[ok], np.log(amplitudes[ok])
    n = len(a)
    degree = int(min(3, max(1, n // 6)))
    if n < degree + 4:
        return False
    x = (t - t.mean()) / max(float(np.ptp(t)), 1e-300)
    smooth = np.polyval(np.polyfit(x, a, degree), x)
    sigma = math.sqrt(float(np.sum((a - smooth) ** 2)) / (n - degree - 1) * (degree + 1) / n)
    rise = float(np.max(smooth - np.minimum.accumulate(smooth)))
    return rise > max(RISE_SIGMAS * sigma, NEAR_FLOOR)


DECAY_P = 1e-6  # a decay this unlikely under one mode's damping law: two modes (:func:`decay_misfit`)


def decay_misfit(times: np.ndarray, amplitudes: np.ndarray, sd: np.ndarray, degree: int) -> float:
    """The p-value of the cycles' amplitudes (at their centre ``times``, ``sd`` their sds) decaying as one
    mode's do: ln A fitted by d ln A / dt = -(a + b A + c / A), a, b, c >= 0 (linear, quadratic and dry
    damping), against the most flexible envelope the record fit allows (a Chebyshev series of
    ``degree``, :data:`.phase_law._ENVELOPE_DEGREE`), by the F ratio of the misfit that law adds over
    that envelope's residual variance. A second mode near the torsion's frequency adds to the swing a
    term of its own decay and phase: the sum's envelope wobbles at the beat, or, under half a beat,
    bends as no damping law bends it (two exponentials of different rates)."""
    ok = np.isfinite(amplitudes) & (amplitudes > 0.0) & np.isfinite(sd) & (sd > 0.0)
    t, log_a, w = times[ok] - times[ok][0], np.log(amplitudes[ok]), 1.0 / sd[ok]
    n = len(t)
    top = min(degree, n - 2)
    if top < 5:
        return 1.0
    u = 2.0 * t / max(float(t[-1]), 1e-300) - 1.0
    x = np.polynomial.chebyshev.chebvander(u, top) * w[:, None]
    flexible = log_a * w - x @ np.linalg.lstsq(x, log_a * w, rcond=None)[0]
    chi_top = float(flexible @ flexible)

    def residual(p):  # RK4 at the cycles' spacing: (rate h)^5 ~ 1e-10 of a slow decay
        return (_damping_decay(t, *(float(x) for x in p))[0] - log_a) * w

    # started from the decay's mean rate taken as all linear, all quadratic or all dry, whichever fits
    # best: from it the search reached the best of all three's minima within 3e-7 of chi^2 on 65 decays
    # of one and of two modes (tests/test_near_mode.py's), at a third of the cost
    slope = max(-float(np.polyfit(t, log_a, 1)[0]), 1e-9)
    mean = math.exp(float(np.mean(log_a)))
    starts = [[log_a[0], slope, 0.0, 0.0], [log_a[0], 0.0, slope / mean, 0.0], [log_a[0], 0.0, 0.0, slope * mean]]
    start = min(starts, key=lambda p: float(np.sum(residual(np.array(p)) ** 2)))
    best = 2.0 * least_squares(residual, start, bounds=([-np.inf, 0.0, 0.0, 0.0], np.inf), x_scale="jac").cost
    dof = top + 1 - 4
    ratio = (best - chi_top) / dof / max(chi_top / (n - top - 1), 1e-300)
    return float(fisher.sf(max(ratio, 0.0), dof, n - top - 1))


NEAR_BAND = 0.15  # a near mode is searched within this relative distance of the first mode's frequency
NEAR_GAIN = 25.0  # the two-mode fit's chi^2 below the one-mode fit's, in its own residual variances: a mode
_NEAR_SHARE = 0.5  # the largest near mode, relative to the first mode's swing in the record's middle
_ENVELOPE_ONE = 7  # the one-mode fit's envelope degree (ln A): as many parameters as the two-mode fit's
DAMPING = -1  # the first mode's own envelope beside a near mode: a damping law's decay (:func:`_damping_decay`)
_ENVELOPE_TWO = DAMPING  # Viscous, quadratic and dry damping together bend ln A both ways over a record
# (-ln(1 + c A0 t), ln(1 - k t)), which a quadratic in time (stop 50) cannot follow: the near mode took the
# bend. A gyro record of a tuned bench plate from 0.63 rad (quadratic 0.032, dry 1.7e-3, a sway 1.2 beats off)
# had its sway fitted 0.47 % off and T0 6.9 sigma off; six draws of its traits: rms z 3.9 with the quadratic,
# 0.55 with the damping law. On 24 such records at 1-2.5 beats (benchmarks/near_mode.py 53 24 damped): 21
# inside, rms z 1.157 with the quadratic; 23, 1.055 with a cubic, which also takes a share of a mild record's
# beat (tests/test_near_mode.py's 1.4-beat sway 0.4 % off, z +1.74); 24, 0.822 with the damping law, which
# follows the bend and not the beat (that sway 0.1 % off, z +0.16)
_RATIO_DEGREE = 6  # R(A)'s polynomial in A^2 (_Near)
_SUBSTEPS = 4  # the law's phase integral's steps a cycle (trapezoid: ~1e-4 of the law's ~1e-2 a cycle)


def near_mode_of(cyc: Cycles, law_fit: PhaseFit, rate: bool, prior: float) -> Second | None:
    """A second mode within :data:`NEAR_BAND` of the torsion's frequency, fitted to the cycles' complex
    fundamentals z_k = a_k e^(i phi_k) (:mod:`.cycles`: a window one local period long takes all of a
    near mode into its fundamental, times sinc((omega2 - omega_k) / omega_k)) as the sum of the first
    mode, e^(P(t) + i Phi(t)) with ln A = P the decay of linear, quadratic and dry damping and
    Phi = phi0 + omega0 int dt / (R(A) E(A)) (the ideal law R, its excess E = 1 + ds A^2 + dq A^4 under
    its ``prior``, A in rad: a rate's fundamental over omega0), and a damped sinusoid
    C e^((-decay + i omega2) t). Against it one mode alone with an envelope of degree
    :data:`_ENVELOPE_ONE` (as many parameters): the beat's wobble of the envelope it follows, but the
    phase's, of the same size in quadrature, only a law far past its prior would. None unless the two
    modes' chi^2 is :data:`NEAR_GAIN` of its own residual variances below the one mode's (a mode, not
    noise: the search over omega2 looks in many places), and the near mode is at most
    :data:`_NEAR_SHARE` of the first, at least :data:`NEAR_FLOOR` of it (below, the first mode's own
    law misfit: a noiseless 100-cycle record's fitted as a mode of 1.1e-4 at 1.058 T0), and lasts the
    record. The residuals are each cycle's phase and ln a, over their sigmas."""
    data = _Near.of(cyc, law_fit, rate, prior)
    if data is None:
        return None
    one = data.fit(_ENVELOPE_ONE)
    two = None
    for start in data.starts(data.fit(_ENVELOPE_TWO)):
        sol = data.fit(_ENVELOPE_TWO, start)
        if two is None or sol.cost < two.cost:
            two = sol
    if two is None:
        return None
    gain = (one.cost - two.cost) / max(two.cost / data.dof(two), 1e-300)
    return data.mode_of(two) if gain >= NEAR_GAIN else None


def near_doubt(cyc: Cycles, law_fit: PhaseFit, rate: bool, prior: float, second: Second,
               subtracted: Second | None) -> float:
    """What a second mode within :data:`NEAR_BAND` of the torsion's frequency adds to omega0's variance
    ((rad/s)^2) by trading with the law: to first order in its size a beat is an amplitude law
    (module docstring), so the law the record learns and the mode fitted beside it share what the
    record says of them, which the law's fit, the mode held, does not see. The cycles' two-mode model
    of :func:`near_mode_of` is fitted from ``second``, the cycles measured with ``subtracted`` taken
    from the record (put back here); the difference of omega0's variance with the mode free and held,
    both scaled by that fit's chi^2 / dof where above 1, is the doubt, at most the square of what the
    mode can move omega0 at all (:meth:`_Near.reach`: past it the linearised difference has left its
    range, a fit near degenerate: a 50 Hz quadrotor gyro log of 12 cycles with a mode of 2 % half a beat
    off was given 0.116 s on T0 = 0.84 s). 0 where the mode lies outside the band or the cycles are too
    few."""
    if abs(second.omega / law_fit.omega0 - 1.0) > NEAR_BAND:
        return 0.0
    data = _Near.of(cyc, law_fit, rate, prior, subtracted)
    if data is None:
        return 0.0
    two = data.from_second(second)
    scale = max(2.0 * two.cost / data.dof(two), 1.0)
    jac = np.delete(two.jac, -4, axis=1) if second.held else two.jac  # the rig's frequency: held
    free = np.linalg.pinv(jac.T @ jac)[1, 1]
    held = np.linalg.pinv(jac[:, :-4].T @ jac[:, :-4])[1, 1]
    return min(scale * max(free - held, 0.0), data.reach(two.x) ** 2)


def near_held(cyc: Cycles, law_fit: PhaseFit, rate: bool, prior: float, omegas: tuple[float, ...]) -> Second | None:
    """A mode at one of the rig's frequencies ``omegas`` (rad/s) within :data:`NEAR_BAND` of the
    torsion's, fitted beside the first mode in the cycles' two-mode model of :func:`near_mode_of` with
    its frequency held there: the best of them, whatever its size (the rig says where it is, so no search
    asks the gain of :data:`NEAR_GAIN`, and a size the record cannot tell from 0 carries its doubt,
    :func:`near_doubt`). None where the cycles are too few, no frequency lies within the band, or the
    mode is past :data:`_NEAR_SHARE` of the first."""
    data = _Near.of(cyc, law_fit, rate, prior)
    if data is None:
        return None
    base = data.fit(_ENVELOPE_TWO)
    near = [w for w in omegas if abs(w / base.x[1] - 1.0) <= NEAR_BAND]
    if not near:
        return None
    best = min((data.fit(_ENVELOPE_TWO, start, held=True) for start in data.starts(base, near)),
               key=lambda sol: sol.cost)
    return data.mode_of(best, held=True)


def near_refit(cyc: Cycles, law_fit: PhaseFit, rate: bool, prior: float, second: Second) -> Second | None:
    """A second mode the periodogram found (:func:`.second_mode.second_mode_of`: apart from the band
    the first mode swept, but within :data:`NEAR_BAND` of its frequency), refitted beside the first
    mode in the cycles' two-mode model of :func:`near_mode_of`: the periodogram's fit takes the first
    mode as the law fitted it, and that law has taken part of the beat. ``second`` was subtracted from
    the record the cycles were measured on (put back here). None where the cycles are too few or the
    refitted mode is past :data:`_NEAR_SHARE` of the first or below :data:`NEAR_FLOOR` (``second``
    stays as the periodogram fitted it)."""
    data = _Near.of(cyc, law_fit, rate, prior, second)
    return None if data is None else data.mode_of(data.from_second(second, mirror=True))


class _Near:
    """The cycles' complex fundamentals and the one- and two-mode models of :func:`near_mode_of`:
    p = (phi0, omega0, ln A's terms (:meth:`envelope`), the excess's two terms in prior sigmas[, omega2,
    decay, Re C, Im C]), times from the record's middle."""

    @classmethod
    def of(cls, cyc: Cycles, law_fit: PhaseFit, rate: bool, prior: float, add: Second | None = None) -> _Near | None:
        """The good cycles' (None: fewer than 12), the law's phase unwrapping them; ``add``: a mode
        subtracted from the record before the cycles were measured, put back."""
        good = np.flatnonzero(cyc.good & np.isfinite(cyc.phase) & (cyc.phase_var > 0.0) & (cyc.amplitude_var > 0.0))
        if len(good) < max(MIN_CYCLES, 12):
            return None
        t, omega = cyc.centre[good], cyc.omega[good]
        z = cyc.fundamental[good] * np.exp(1j * cyc.phase[good])
        if add is not None:
            z = z + add.phasor(t) * np.sinc((add.omega - omega) / omega)
        law_phase = law_fit.phase_at(t)
        phase = law_phase + np.angle(z * np.exp(-1j * law_phase))
        # the ideal law's table, where the swing in rad is known; its excess E = 1 + width (e1 A^2 + e2 A^4)
        table = law_fit.table if law_fit.scale_known else None
        width = prior * abs(law_fit.ideal) if table is not None and law_fit.ideal is not None else 0.0
        return cls(t, phase, np.abs(z), np.sqrt(cyc.phase_var[good]),
                   np.sqrt(cyc.amplitude_var[good]) / cyc.fundamental[good], omega, table, width, rate)

    def __init__(self, t, phase, amplitude, sd_phase, sd_log, omega, table, width, rate):
        self.t, self.phase, self.sd_phase, self.sd_log, self.omega = t, phase, sd_phase, sd_log, omega
        self.z = amplitude * np.exp(1j * phase)
        self.log_a = np.log(amplitude)
        self.table, self.width, self.rate = table, width, rate
        if table is not None:  # R(A) as a polynomial in A^2 over the swings the record may reach: a spline's
            # evaluation at every step of every fit cost 3x the rest of the model (within 1e-10 of R to 1.2 rad)
            a2 = np.linspace(0.0, table.largest, 64) ** 2
            self.ratio = np.polynomial.Polynomial.fit(a2, table.ratio_at(np.sqrt(a2)), _RATIO_DEGREE)
            self.ratio_slope = self.ratio.deriv()
        self.middle = 0.5 * (t[0] + t[-1])
        self.half = max(0.5 * (t[-1] - t[0]), 1e-300)
        # the law's phase integral, trapezoid, over _SUBSTEPS steps between neighbouring cycles
        self.grid = np.interp(np.arange((len(t) - 1) * _SUBSTEPS + 1) / _SUBSTEPS, np.arange(len(t)), t)
        self._bases = {}
        self._decay = None

    def basis(self, degree: int) -> tuple[np.ndarray, np.ndarray]:
        """The Chebyshev basis of ln A at the grid and at the cycles."""
        if degree not in self._bases:
            self._bases[degree] = tuple(np.polynomial.chebyshev.chebvander((x - self.middle) / self.half, degree)
                                        for x in (self.grid, self.t))
        return self._bases[degree]

    def dof(self, sol) -> int:
        return max(2 * len(self.t) + 2 - len(sol.x), 1)

    def envelope(self, coef: np.ndarray, degree: int, derivatives: bool = False):
        """The first mode's ln A on the grid and at the cycles (and with ``derivatives`` their derivatives by
        its terms ``coef``, columns): a Chebyshev series of ``degree`` in time, or with :data:`DAMPING` the
        decay d ln A / dt = -(a + b A + c / A) of linear, quadratic and dry damping from ln A at the
        record's start (``coef`` = (ln A0, a, b, c), :func:`_damping_decay`). The cycles lie on the grid,
        every :data:`_SUBSTEPS` steps."""
        if degree == DAMPING:
            key = tuple(float(x) for x in coef)
            if self._decay is None or self._decay[0] != key:  # the model asks twice a step: the law's phase too
                self._decay = key, _damping_decay(self.grid, *key)
            grid, slope = self._decay[1]
            return (grid, grid[::_SUBSTEPS], slope, slope[::_SUBSTEPS]) if derivatives else (grid, grid[::_SUBSTEPS])
        grid_basis, at_cycles = self.basis(degree)
        values = grid_basis @ coef, at_cycles @ coef
        return (*values, grid_basis, at_cycles) if derivatives else values

    def law_phase(self, omega0: float, envelope: np.ndarray, degree: int, excess: np.ndarray,
                  derivatives: bool = False):
        """int_middle^t dt / (R(A) E(A)) (s) at the cycles, and with ``derivatives`` its derivatives by
        omega0, by ln A's terms (columns, :meth:`envelope`) and by the excess's two terms (columns): the ideal
        law R (none where the swing in rad is not known), A the first mode's own peak swing (rad: a
        rate's fundamental over omega0), E = 1 + width (e1 A^2 + e2 A^4)."""
        n, k = len(self.t), len(envelope)
        if self.table is None:
            law = self.t - self.middle
            return (law, np.zeros(n), np.zeros((n, k)), np.zeros((n, 2))) if derivatives else law
        log_a, _, grid_slope, _ = self.envelope(envelope, degree, derivatives=True)
        a = np.exp(log_a) / (omega0 if self.rate else 1.0)
        inside = a < self.table.largest  # past it the table's last value is held: no derivative
        a2 = np.minimum(a, self.table.largest) ** 2
        ratio = self.ratio(a2)
        excess_factor = 1.0 + self.width * (excess[0] * a2 + excess[1] * a2 * a2)
        rate = 1.0 / (ratio * excess_factor)
        if not derivatives:
            return self._integral(rate)
        # d rate / d A^2, and d A^2 / d (omega0, ln A's terms)
        slope = np.where(inside, -rate * (self.ratio_slope(a2) / ratio
                                          + self.width * (excess[0] + 2.0 * excess[1] * a2) / excess_factor), 0.0)
        columns = np.column_stack([slope * -2.0 * a2 / omega0 if self.rate else np.zeros_like(a2),
                                   (slope * 2.0 * a2)[:, None] * grid_slope,
                                   -rate * self.width * a2 / excess_factor,
                                   -rate * self.width * a2 * a2 / excess_factor])
        q = self._integral(np.column_stack([rate, columns]))
        return q[:, 0], q[:, 1], q[:, 2:2 + k], q[:, 2 + k:]

    def _integral(self, f: np.ndarray) -> np.ndarray:
        """int_middle^t f dt at the cycles (trapezoid on the grid), column by column."""
        q = cumulative_trapezoid(f, self.grid, axis=0, initial=0.0)
        j = min(int(np.searchsorted(self.grid, self.middle)), len(self.grid) - 1)
        j = max(j, 1)
        w = (self.middle - self.grid[j - 1]) / max(self.grid[j] - self.grid[j - 1], 1e-300)
        return q[::_SUBSTEPS] - (q[j - 1] + w * (q[j] - q[j - 1]))

    def model(self, p: np.ndarray, degree: int, second: bool, derivatives: bool = False):
        """The complex fundamental at the cycles (and, with ``derivatives``, its derivatives by p, columns)."""
        k = _terms(degree)
        envelope = p[2:2 + k]
        u = self.t - self.middle
        _, log_a, _, at_cycles = self.envelope(envelope, degree, derivatives=True)
        law = self.law_phase(p[1], envelope, degree, p[2 + k:4 + k], derivatives)
        law, by_omega, by_envelope, by_excess = law if derivatives else (law, None, None, None)
        z1 = np.exp(log_a + 1j * (p[0] + p[1] * law))
        z = z1
        if second:
            omega2, decay, cr, ci = p[4 + k:8 + k]
            x = (omega2 - self.omega) / self.omega
            ramp = np.exp((-decay + 1j * omega2) * u)
            shape = ramp * np.sinc(x)
            z = z1 + complex(cr, ci) * shape
        if not derivatives:
            return z
        log_z1 = np.column_stack([np.full(len(u), 1j), 1j * (law + p[1] * by_omega),
                                  at_cycles + 1j * p[1] * by_envelope, 1j * p[1] * by_excess])
        dz = z1[:, None] * log_z1
        if second:
            c = complex(cr, ci)
            safe = np.where(x == 0.0, 1.0, x)
            sinc_slope = np.where(x == 0.0, 0.0, (np.cos(np.pi * safe) - np.sinc(safe)) / safe)
            dz = np.column_stack([dz, c * ramp * (1j * u * np.sinc(x) + sinc_slope / self.omega), -u * c * shape,
                                  shape, 1j * shape])
        return z, dz

    def residual(self, p: np.ndarray, degree: int, second: bool) -> np.ndarray:
        q = self.z / self.model(p, degree, second)
        k = _terms(degree)
        return np.concatenate([np.angle(q) / self.sd_phase, np.log(np.abs(q)) / self.sd_log, p[2 + k:4 + k]])

    def jacobian(self, p: np.ndarray, degree: int, second: bool) -> np.ndarray:
        """d residual / d p: the model's log derivative, its imaginary part the phase's, its real part ln A's."""
        z, dz = self.model(p, degree, second, derivatives=True)
        log_slope = dz / z[:, None]
        prior = np.zeros((2, len(p)))
        prior[0, 2 + _terms(degree)] = prior[1, 3 + _terms(degree)] = 1.0
        return np.vstack([-log_slope.imag / self.sd_phase[:, None], -log_slope.real / self.sd_log[:, None], prior])

    def fit(self, degree: int, start: np.ndarray | None = None, held: bool = False):
        """The least squares of one mode (``start`` None: from the envelope's and the phase's linear
        fits) or of two (from ``start``; ``held``: the second's frequency held at its start)."""
        if held:
            omega2, j = start[-4], len(start) - 4

            def whole(q):
                return np.insert(q, j, omega2)

            lo, hi = self._bounds(np.delete(start, j), degree, True)
            sol = least_squares(lambda q: self.residual(whole(q), degree, True), np.clip(np.delete(start, j), lo, hi),
                                jac=lambda q: np.delete(self.jacobian(whole(q), degree, True), j, axis=1),
                                bounds=(lo, hi), x_scale="jac", ftol=1e-6, xtol=1e-6)
            sol.x, sol.jac = whole(sol.x), self.jacobian(whole(sol.x), degree, True)
            return sol
        second = start is not None
        if start is None:
            u = self.t - self.middle
            if degree == DAMPING:  # all linear damping, at the decay's mean rate
                slope, middle = np.polyfit(u, self.log_a, 1)
                envelope = np.array([middle + slope * (self.t[0] - self.middle), max(-slope, 0.0), 0.0, 0.0])
            else:
                envelope = np.polynomial.chebyshev.chebfit(u / self.half, self.log_a, degree)
            w0 = np.polyfit(u, self.phase, 1)[0]
            omega0, phi0 = np.polyfit(self.law_phase(w0, envelope, degree, np.zeros(2)), self.phase, 1)
            start = np.concatenate([[phi0, omega0], envelope, [0.0, 0.0]])
        lo, hi = self._bounds(start, degree, second)
        start = np.clip(start, lo, hi)
        return least_squares(self.residual, start, jac=self.jacobian, args=(degree, second), bounds=(lo, hi),
                             x_scale="jac", ftol=1e-6, xtol=1e-6)

    def _bounds(self, start: np.ndarray, degree: int, second: bool):
        """Damping only takes the swing (a, b, c >= 0); a mode beating in lasts the record
        (:func:`.second_mode.second_mode_of`): its decay is p[-3]."""
        lo, hi = np.full(len(start), -np.inf), np.full(len(start), np.inf)
        if degree == DAMPING:
            lo[3:6] = 0.0
        if second:
            lo[-3], hi[-3] = 0.0, SECOND_DECAY_SPANS / (2.0 * self.half)
        return lo, hi

    def reach(self, p: np.ndarray) -> float:
        """The most the near mode of the two-mode fit ``p`` can move omega0 (rad/s): the sum's frequency
        strays from the first mode's by at most eps |omega2 - omega0| / (1 - eps), eps the mode's largest
        size over the first mode's at the cycles; and the sum's swing, off by a factor e^(+-eps), moves the
        law's frequency 1 / (R E) by at most 2 |R E - 1| of it at the largest swing (R E - 1 ~ s A^2, so
        twice its log-slope in A), which the law may carry to zero swing."""
        k = _terms(_ENVELOPE_TWO)
        log_a = self.envelope(p[2:2 + k], _ENVELOPE_TWO)[1]
        omega0, omega2, decay, size = p[1], p[4 + k], p[5 + k], abs(complex(p[6 + k], p[7 + k]))
        eps = min(float(np.max(size * np.exp(-decay * (self.t - self.middle) - log_a))), _NEAR_SHARE)
        law = 0.0
        if self.table is not None:
            a2 = min(math.exp(float(np.max(log_a))) / (omega0 if self.rate else 1.0), self.table.largest) ** 2
            law = 2.0 * abs(float(self.ratio(a2)) * (1.0 + self.width * (p[2 + k] * a2 + p[3 + k] * a2 * a2)) - 1.0)
        return abs(omega0) * eps / (1.0 - eps) * (abs(omega2 / omega0 - 1.0) + law)

    def mode_of(self, two, held: bool = False) -> Second | None:
        """The near mode of the two-mode fit ``two`` (its amplitude at tau = 0), None where it is past
        :data:`_NEAR_SHARE` of the first mode's swing in the record's middle, below :data:`NEAR_FLOOR` of
        it (not with ``held``: a mode the rig places has no floor, :func:`near_held`), or outside
        :data:`NEAR_BAND`."""
        log_a = self.envelope(two.x[2:2 + _terms(_ENVELOPE_TWO)], _ENVELOPE_TWO)[0]
        first = math.exp(float(np.interp(self.middle, self.grid, log_a)))
        omega2, decay, c = float(two.x[-4]), float(two.x[-3]), complex(two.x[-2], two.x[-1])
        floor = 0.0 if held else NEAR_FLOOR
        if not floor * first <= abs(c) <= _NEAR_SHARE * first or abs(omega2 / two.x[1] - 1.0) > NEAR_BAND:
            return None
        c = c * np.exp((decay - 1j * omega2) * self.middle)
        return Second(omega2, decay, float(c.real), float(-c.imag), near=True, held=held)

    def from_second(self, second: Second, mirror: bool = False):
        """The two-mode fit started from the one-mode fit and ``second``; with ``mirror``, the better of
        that and one started from its mirror image about the first mode's frequency, 2 omega0 - omega2,
        sized by the projection there (where the law took the beat's phase, what is left of it is the
        envelope's wobble, whose two sidebands are alike: a periodogram may pick either)."""
        base = self.fit(_ENVELOPE_TWO)
        c = second.phasor(self.middle)
        starts = [np.concatenate([base.x, [second.omega, second.decay, c.real, c.imag]])]
        if mirror:
            starts += self.starts(base, [2.0 * base.x[1] - second.omega])
        return min((self.fit(_ENVELOPE_TWO, start, second.held) for start in starts), key=lambda sol: sol.cost)

    def starts(self, base, picked: list[float] | None = None) -> list[np.ndarray]:
        """Two-mode starts from the one-mode fit ``base`` at the frequencies ``picked`` (None: the three
        highest peaks, a resolution apart, of the periodogram of what it leaves (z / z1 - 1) |z1| over
        omega2 within NEAR_BAND), each sized by the projection of that rest there."""
        p = base.x
        z1 = self.model(p, _ENVELOPE_TWO, False)
        rest = (self.z / z1 - 1.0) * np.abs(z1)
        weight = 1.0 / self.sd_phase**2
        u = self.t - self.middle
        if picked is None:
            resolution = math.pi / self.half
            grid = p[1] * (1.0 + np.linspace(-NEAR_BAND, NEAR_BAND, 401))
            shifts = np.exp(-1j * np.outer(grid - p[1], u))
            power = np.abs(shifts @ (weight * rest))
            picked = []
            for j in np.argsort(power)[::-1]:
                if all(abs(grid[j] - g) > resolution for g in picked):
                    picked.append(grid[j])
                if len(picked) == 3:
                    break
        out = []
        for omega2 in picked:
            c = np.sum(weight * rest * np.exp(-1j * (omega2 - p[1]) * u)) / np.sum(weight) * np.exp(1j * p[0])
            out.append(np.concatenate([p, [omega2, 0.1 / (2.0 * self.half), c.real, c.imag]]))
        return out


def _terms(degree: int) -> int:
    """The first mode's envelope's terms of :meth:`_Near.envelope` for ``degree``."""
    return 4 if degree == DAMPING else degree + 1


_LOG_A_SPAN = 10.0  # ln A is held within this of its start in :func:`_damping_decay` (a swing falling
# 2e4-fold over a record: none the fit measures), its derivatives 0 there: a trial step of the search may
# ask for a decay that ends the swing, where dry friction's c / A, and the sensitivities, grow without bound


@nb.njit(cache=True)
def _damping_decay(grid, log_a0, a, b, c):
    """ln A at ``grid`` (s, increasing) from ``log_a0`` at its start under d ln A / dt = -(a + b A + c / A)
    (linear, quadratic and dry damping of the swing A), and its derivatives by (ln A0, a, b, c), columns:
    RK4 between the grid's points with the sensitivities' equations alongside (~1e-4 of a cycle's decay
    a step at :data:`_SUBSTEPS` steps a cycle, as the law's phase integral)."""
    n = len(grid)
    out = np.empty(n)
    slope = np.zeros((n, 4))
    v = log_a0
    s = np.array([1.0, 0.0, 0.0, 0.0])
    out[0] = v
    slope[0] = s
    low, high = log_a0 - _LOG_A_SPAN, log_a0 + _LOG_A_SPAN
    kv = np.empty(4)  # each stage's rate of ln A, and of its four derivatives
    ks = np.empty((4, 4))
    si = np.empty(4)
    for k in range(n - 1):
        h = grid[k + 1] - grid[k]
        vi = v
        si[:] = s
        for stage in range(4):
            e = math.exp(min(max(vi, low), high))
            kv[stage] = -(a + b * e + c / e)
            ks[stage, 0] = 0.0
            ks[stage, 1] = -1.0
            ks[stage, 2] = -e
            ks[stage, 3] = -1.0 / e
            for j in range(4):
                ks[stage, j] += -(b * e - c / e) * si[j]
            if stage < 3:
                step = h if stage == 2 else 0.5 * h
                vi = v + step * kv[stage]
                for j in range(4):
                    si[j] = s[j] + step * ks[stage, j]
        v = v + h * (kv[0] + 2.0 * kv[1] + 2.0 * kv[2] + kv[3]) / 6.0
        for j in range(4):
            s[j] = s[j] + h * (ks[0, j] + 2.0 * ks[1, j] + 2.0 * ks[2, j] + ks[3, j]) / 6.0
        if not low < v < high or not np.all(np.isfinite(s)):  # held at the bound: no derivative there
            v = min(max(v, low), high) if math.isfinite(v) else low
            s[:] = 0.0
        out[k + 1] = v
        slope[k + 1] = s
    return out, slope
