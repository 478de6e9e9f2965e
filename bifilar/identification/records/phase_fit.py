"""One fit of the phases' law (:class:`PhaseFit`): what :meth:`.phase_law.Model.fit` returns, frozen.

A fit is a value: refitting the same cycles under other options (one excess term fewer, the excess held
at the ideal law, a group of cycles left out) gives another :class:`PhaseFit` and leaves this one as it
was, so the doubts measured by refitting (:meth:`.phase_law.Model.check_law`, ``Model.jackknife``) compare
two results rather than one object before and after. The law on the fit's grid is kept as arrays, and what
the later steps ask of it (its phase, local frequency and decay at any time: :mod:`.cycles`' next pass,
:mod:`.whole`, :mod:`.second_mode`) is read off them by interpolation.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .law import Table

# The real law's excess E = 1 + ds A^2 + dq A^4 + d6 A^6: a stronger cubic restoring term alone already
# gives all three (over 0.4..1.25 rad, A^2 and A^4 alone leave 2e-4 of it, enough to bias T0 by 1e-4).
EXCESS_TERMS = ("ds", "dq", "d6")


@dataclass(frozen=True)
class PhaseFit:
    """The phases' law fitted to a pass's good cycles (:mod:`.phase_law`). Times in s, omega in rad/s.

    ``names``: the parameters (phi, omega, then the law's: the excess terms, the scale ``q`` or ``kappa``
    of a proportional record), ``params`` their values (``phi0`` and ``omega0`` the first two). ``cov_stat``, ``cov_law``:
    their covariance, the record's noise (block sandwich plus the envelope's doubt) and the priors' part;
    ``prior_gain``: omega0's response to each excess prior off by one sigma. ``j_phase``, ``bread``: the
    good cycles' weighted phase Jacobian and the inverse normal matrix (priors included), from which
    the jackknife's expected ratio is derived (:func:`.spread.jackknife_inflation`, in
    :meth:`.phase_law.Model.jackknife`). ``envelope_degree``, ``envelope_weights``: the
    envelope's degree and each degree's Akaike weight (:class:`.phase_law._Envelope`). ``residual``, ``var``: each
    good cycle's phase residual (rad) and variance. ``ideal``: the ideal law's coefficient s (1/rad^2;
    None for the linear law). ``conflict``: the largest excess at a swing the record went through, in
    prior sigmas. ``held``: the excess held at the ideal law. ``scale_known``: the swing in rad is known.
    ``damping``: the decay's description (:func:`.damping.damping_of`), ``shift_curve`` its shift of the
    frequency against the amplitude, ``harmonic`` a proportional pendulum's scale (q, sd, rate) from its
    third harmonic. ``table``, ``table_key``: the ideal law's table and the (omega, largest amplitude) it
    was made for, which the next fit reuses while omega stays within 1e-6 (:meth:`.phase_law.Model.fit`).
    On the phase grid ``grid``: the envelope ``amplitude`` (signal units), the swing ``peak`` (rad; None
    for the linear law), the rate 1 / (R E D) ``rate`` and d ln A / dt ``decay``. ``phase_integral``:
    (grid, int dt / (R E D) from the reference time, the end rates); ``law_slopes`` that
    integral's response to each law parameter, ``law_prior_sd`` their priors' sds (for :mod:`.bound`).
    ``order_shift``, ``held_shift``, ``ideal_shift`` (rad/s) and ``rises``: the law's doubts that
    :meth:`.phase_law.Model.check_law` measures (zero before it).
    """

    names: tuple[str, ...]
    params: np.ndarray
    cov_stat: np.ndarray
    cov_law: np.ndarray
    prior_gain: np.ndarray
    j_phase: np.ndarray
    bread: np.ndarray
    envelope_degree: int
    envelope_weights: np.ndarray
    residual: np.ndarray
    var: np.ndarray
    ideal: float | None
    conflict: float
    held: bool
    scale_known: bool
    damping: dict
    shift_curve: tuple[np.ndarray, np.ndarray]
    harmonic: tuple[float, float, bool] | None
    table: Table | None
    table_key: tuple[float, float] | None
    grid: np.ndarray
    amplitude: np.ndarray
    peak: np.ndarray | None
    rate: np.ndarray
    decay: np.ndarray
    phase_integral: tuple
    law_slopes: tuple
    law_prior_sd: np.ndarray
    order_shift: float = 0.0  # omega0 learned less omega0 with one excess term fewer
    held_shift: float = 0.0  # omega0 learned less omega0 under the ideal law, past LAW_CONFLICT or where it rises
    ideal_shift: float = 0.0  # the same, whatever the conflict: what a law shared with other records weighs
    rises: bool = False  # the cycles' envelope rises again or is no damping's (.near): a mode beating in

    @property
    def phi0(self) -> float:
        """The phase (rad) at the reference time."""
        return float(self.params[0])

    @property
    def omega0(self) -> float:
        """The zero-swing frequency (rad/s): 2 pi / T0."""
        return float(self.params[1])

    def fund_at(self, tt: np.ndarray) -> np.ndarray:
        """The cycles' envelope (signal units; the angle's for a rate) at times ``tt``."""
        return np.interp(tt, self.grid, self.amplitude)

    def peak_at(self, tt: np.ndarray) -> np.ndarray | None:
        """The swing (rad) at times ``tt``; None for the linear law, which has no scale to apply."""
        return None if self.peak is None else np.interp(tt, self.grid, self.peak)

    def decay_at(self, tt: np.ndarray) -> np.ndarray:
        """d ln(amplitude) / dt (1/s) at times ``tt``."""
        return np.interp(tt, self.grid, self.decay)

    def integral_at(self, tt: np.ndarray) -> np.ndarray:
        """int dt / (R E D) from the reference time to ``tt`` (s), carried on at the end rates beyond the
        first and last cycle: the phase is phi0 + omega0 times this."""
        return _carried(tt, *self.phase_integral)

    def law_integrals_at(self, tt: np.ndarray) -> np.ndarray:
        """d :meth:`integral_at` / d p for each law parameter p (``names[2:]``), an (n, m) array."""
        return np.column_stack([_carried(tt, *slope) for slope in self.law_slopes] or [np.zeros((len(tt), 0))])

    def phase_at(self, tt: np.ndarray) -> np.ndarray:
        """The fitted law's phase Phi at times ``tt`` (the cycles' fundamental is A cos Phi)."""
        return self.phi0 + self.omega0 * self.integral_at(tt)

    def local_omega(self, tt: np.ndarray) -> np.ndarray:
        """The instantaneous frequency (rad/s) the fitted law gives at times ``tt``."""
        return self.omega0 * np.interp(tt, self.grid, self.rate)

    def local(self, tt: np.ndarray):
        """(instantaneous frequency, d ln(amplitude) / dt) at times ``tt``: what the next pass's windows
        are fitted with."""
        return self.local_omega(tt), self.decay_at(tt)

    def law_induced_variance(self) -> float:
        """The variance of omega0 that the law's parameters carry (their own uncertainty, the record's and
        the priors'): Sigma_wL Sigma_LL^-1 Sigma_Lw of the whole covariance, the part a fit holding the
        law at its estimate does not see."""
        law = [i for i, n in enumerate(self.names) if n in EXCESS_TERMS or n in ("kappa", "q")]
        return law_induced(self.cov_stat + self.cov_law, law)


def law_induced(cov: np.ndarray, law: list[int]) -> float:
    """Sigma_wL Sigma_LL^-1 Sigma_Lw of covariance ``cov`` (omega0 its row 1, ``law`` the law's rows):
    the variance of omega0 that the law's parameters carry (0 without them)."""
    if not law:
        return 0.0
    cross = cov[1, law]
    return float(cross @ np.linalg.pinv(cov[np.ix_(law, law)]) @ cross)


def _carried(tt, grid, cum, g0, g1):
    """The integral ``cum`` on ``grid`` at ``tt``, carried on at the end rates g0, g1 beyond it."""
    inside = np.interp(tt, grid, cum)
    inside = np.where(tt < grid[0], cum[0] + g0 * (tt - grid[0]), inside)
    return np.where(tt > grid[-1], cum[-1] + g1 * (tt - grid[-1]), inside)
