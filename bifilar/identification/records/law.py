"""The amplitude law of a rig: how its period grows with the swing, ideal and as a real rig shows it.

A free oscillation of amplitude A (the peak rotation, rad) has the period T(A) = T0 R(A), T0 the
small-amplitude period that the inversion needs. The fit of a record (:mod:`.fit`) measures the period
at the record's amplitudes; this module says how to take it to A = 0.

The ideal law R(A) is the rig's own (:class:`AmplitudeLaw`; which one a rig has about an axis is chosen
from its models of motion by :func:`.pipeline.law_for`, so this module needs none of them):

* ``exact``: the exact 1-DOF torsion of :mod:`bifilar.motion.lagrange` (wires of any spacing, the vertical
  kinetic energy kept), (I + m z'^2) theta'' + m z' z'' theta'^2 + m g z' = 0, divided by I: with
  z' = (bD / 4H) u(theta), u = sin(theta) / r, r = sqrt(1 - rho sin^2(theta/2)), rho = bD / H^2,

      theta'' = -omega^2 u (1 + lam v theta'^2) / (1 + lam omega^2 u^2),   v = cos(theta) / r + rho u^2 / (4 r),

  lam = bD / (4 H g): m z'^2 / I = lam omega^2 u^2, so the law needs the geometry only, not the mass or
  the moment; omega is the small-amplitude frequency.
* ``series``: theta'' = -omega^2 theta (1 + kappa theta^2 + q theta^4), kappa = -8 s / 3 reproducing the
  Kane model's T(A) = T0 (1 + s A^2) (:func:`bifilar.identification.identify.amplitude_coefficient`), for
  modes that are not a symmetric torsion; the quintic q (:meth:`AmplitudeLaw.matched`) makes it equal
  the Kane model's T(A) / T0 at the record's largest amplitude too.
* ``linear``: R = 1.

A real rig's law is not the ideal one: hook pivots, wire bending and stretch, the air change it by tens
of percent (up to 30-40 % in the A^2 coefficient on published records). The fit therefore learns the
excess from the record's own cycle-by-cycle T(A):

    T(A) = T0 R(A) (1 + ds A^2 + dq A^4),

ds and dq with Gaussian priors of standard deviation :data:`EXCESS_PRIOR` times the ideal s (dq per
rad^2): a record that decays over a wide range of amplitudes determines them, a record at one amplitude
leaves them at the prior, whose width then enters T0's sigma as the law's doubt (never hidden: the
report gives it apart, ``period_std_law``).

R comes from the energy integral on a grid of amplitudes (:meth:`AmplitudeLaw.table`): each law is the
Lagrange equation of T = M(theta) theta'^2 / 2, V(theta) per unit moment (exact: M = 1 + lam omega^2
u^2 and V' = omega^2 u, since v = du/dtheta; series and linear: M = 1), so a swing of amplitude A takes
the quarter period

    T / 4 = integral_0^A sqrt(M(theta) / (2 (V(A) - V(theta)))) dtheta,

which with theta = A sin(phi) has a smooth integrand on [0, pi / 2]: Gauss-Legendre quadrature, exact to
rounding where an RK4 quarter cycle at 1024 steps per period was right to ~1e-10 and ~100 times slower.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
from scipy.interpolate import CubicSpline

from bifilar.rig import RigError

EXCESS_PRIOR = 0.35  # prior std of ds / s (and of dq / s, per rad^2): real rigs differ by up to 30-40 %
# Gauss-Legendre nodes of the quarter period's integral on [0, pi / 2]: 48 gave R to 4e-14 of an RK4 at
# 8192 steps per period for exact laws at 0.98 of their limit (the hardest: r near zero), series alike.
_NODES = 64
_X, _W = np.polynomial.legendre.leggauss(_NODES)
_PHI = 0.25 * math.pi * (_X + 1.0)  # theta = A sin(phi), phi on [0, pi / 2]
_WEIGHTS = 0.25 * math.pi * _W
_SIN, _COS2 = np.sin(_PHI), np.cos(_PHI) ** 2
_HALF_GAP = np.sin(0.25 * math.pi - 0.5 * _PHI) ** 2  # (1 - sin(phi)) / 2
_GRID = 24  # amplitudes of a table on (0, A_max], dense near both ends: a cubic spline in A^2 to ~1e-9
# Matching a series law's quintic to the Kane model's T(A) / T0: the ratio itself is exact to
# ~1e-13, the Kane ratio is timed to ~1e-9; 1e-9 and a few secant steps.
_MATCH_TOL = 1e-9
_MATCH_STEPS = 6
_LAW_RTOL = 1e-3  # a series law this close to the one fitted with does not change the fit


class Table:
    """R(A) = T(A) / T0 on an amplitude grid (rad), interpolated by a cubic spline in A^2 (R is an even,
    analytic function of A; R(0) = 1 is the first knot)."""

    def __init__(self, amplitude: np.ndarray, ratio: np.ndarray):
        self.amplitude, self.ratio = amplitude, ratio
        self._ratio = CubicSpline(np.concatenate([[0.0], amplitude**2]), np.concatenate([[1.0], ratio]))

    @property
    def largest(self) -> float:
        return float(self.amplitude[-1])

    def ratio_at(self, a):
        """R at peak amplitudes ``a`` (rad), at most :attr:`largest`."""
        return self._ratio(np.asarray(a) ** 2)

    def ratio_slope(self, a):
        """dR / dA at peak amplitudes ``a`` (rad): 2 A S'(A^2) of the spline S."""
        a = np.asarray(a)
        return 2.0 * a * self._ratio(a**2, 1)


@dataclass(frozen=True)
class AmplitudeLaw:
    """The restoring law of the module docstring: ``kind`` ``exact``, ``series`` or ``linear``.

    ``rho`` = bD / H^2 and ``lam`` = bD / (4 H g) (s^2) for ``exact``; ``s`` (1/rad^2) and ``quintic``
    (the theta^5 coefficient of the restoring term, 1/rad^4) for ``series``.
    """

    kind: str = "linear"
    rho: float = 0.0
    lam: float = 0.0
    s: float = 0.0
    quintic: float = 0.0

    @classmethod
    def torsion(cls, torsion_rig) -> "AmplitudeLaw":
        """The exact law of a :class:`bifilar.motion.lagrange.TorsionRig`."""
        bd, h = torsion_rig.hook_span * torsion_rig.attach_span, torsion_rig.height
        return cls("exact", rho=bd / h**2, lam=bd / (4.0 * h * torsion_rig.gravity))

    @property
    def limit(self) -> float:
        """The largest amplitude (rad) the law holds to: where the exact torsion's wires turn
        horizontal (or pi, where they would cross), pi / 2 for a swing (the body at the hooks' height)."""
        if self.kind == "exact":
            return math.pi if self.rho <= 1.0 else 2.0 * math.asin(math.sqrt(1.0 / self.rho))
        return 0.5 * math.pi

    def coefficient(self, omega: float) -> float:
        """s in T(A) = T0 (1 + s A^2 + O(A^4)) (1/rad^2) at zero-amplitude frequency ``omega``.

        Exact law: s = eps / 4 - 3 beta / 8 with eps = lam omega^2 and beta = -1/6 + rho / 8, the series
        of :func:`bifilar.motion.lagrange.period_amplitude_coefficient`."""
        if self.kind == "exact":
            return 0.25 * self.lam * omega**2 - 0.375 * (-1.0 / 6.0 + 0.125 * self.rho)
        return self.s

    def acceleration(self, theta, rate, omega: float):
        """theta'' of the undamped law (numpy, elementwise)."""
        w2 = omega * omega
        if self.kind == "exact":
            half, co = np.sin(0.5 * theta), np.cos(0.5 * theta)
            r = self._r(theta)
            u = 2.0 * half * co / r  # sin(theta) / r
            v = (1.0 - 2.0 * half * half) / r + 0.25 * self.rho * u * u / r  # cos(theta) / r + ...
            return -w2 * u * (1.0 + self.lam * v * rate * rate) / (1.0 + self.lam * w2 * u * u)
        if self.kind == "series":
            t2 = theta * theta
            return -w2 * theta * (1.0 + (-8.0 / 3.0) * self.s * t2 + self.quintic * t2 * t2)
        return -w2 * theta

    def table(self, omega: float, largest: float) -> Table:
        """R(A) on :data:`_GRID` amplitudes up to ``largest`` (rad, clipped to 0.98 of :attr:`limit`),
        by the quarter period's energy integral (module docstring) at :data:`_NODES` nodes."""
        top = min(max(largest, 1e-3), 0.98 * self.limit)
        k = np.arange(_GRID)
        amps = top * np.sin(0.5 * math.pi * (k + 1) / _GRID)  # dense near both ends
        if self.kind == "linear":
            return Table(amps, np.ones(_GRID))
        a, theta = amps[:, None], amps[:, None] * _SIN
        if self.kind == "exact":
            r_a, r = self._r(a), self._r(theta)
            # V(A) - V(theta) = 4 omega^2 (r(theta) - r(A)) / rho, without the cancellation: A - theta =
            # 2 A sin^2(pi / 4 - phi / 2)
            below = 2.0 * a * _HALF_GAP
            drop = 4.0 * np.sin(0.5 * below) * np.sin(0.5 * (a + theta)) / (r + r_a)
            u = np.sin(theta) / r
            mass = 1.0 + self.lam * omega**2 * u * u
        else:  # series: V(A) - V(theta) = (A^2 - theta^2) (1/2 - 2 s (A^2 + theta^2) / 3 + q (...) / 6)
            a2, t2 = a * a, theta * theta
            drop = a2 * _COS2 * (0.5 - (2.0 / 3.0) * self.s * (a2 + t2) + self.quintic * (a2 * a2 + a2 * t2 + t2 * t2) / 6.0)
            mass = 1.0
        scaled = drop / (a * a * _COS2)  # (V(A) - V(theta)) / (omega^2 A^2 cos^2 phi): smooth, > 0 if it returns
        if not np.all(scaled > 0.0):
            raise RigError("<law>", "amplitude", f"the {self.kind} law does not return from {top:.3g} rad")
        quarter = np.sqrt(mass / (2.0 * scaled)) @ _WEIGHTS  # omega T / 4
        return Table(amps, 2.0 * quarter / math.pi)

    def _r(self, theta):
        """r = sqrt(1 - rho sin^2(theta / 2)) of the exact law, floored at 1e-6 (the wires horizontal)."""
        return np.sqrt(np.maximum(1.0 - self.rho * np.sin(0.5 * theta) ** 2, 1e-12))

    def ratio(self, amplitude: float, omega: float) -> float:
        """T(A) / T0 of the undamped law at ``amplitude`` (rad)."""
        if self.kind == "linear" or amplitude == 0.0:
            return 1.0
        return float(self.table(omega, amplitude).ratio[-1])  # the table's last knot is the amplitude

    def matched(self, amplitude: float, ratio: float, omega: float) -> "AmplitudeLaw":
        """This series law with the quintic coefficient that makes its T(A) / T0 at ``amplitude``
        equal ``ratio`` (the Kane model's, :func:`bifilar.identification.identify.amplitude_ratio`):
        right at O(A^2) by s and at the record's largest amplitude by the quintic. T(A) / T0 falls by
        ~(5 / 16) q A^4 as q grows, nearly linearly: secant steps from that estimate."""
        if self.kind != "series":
            raise ValueError("only a series law takes a quintic term")
        law = replace(self, quintic=0.0)
        step = 16.0 / (5.0 * amplitude**4)
        q0, r0 = 0.0, law.ratio(amplitude, omega)
        q1 = q0 + (r0 - ratio) * step
        for _ in range(_MATCH_STEPS):
            r1 = replace(law, quintic=q1).ratio(amplitude, omega)
            if abs(r1 - ratio) < _MATCH_TOL or r1 == r0:
                break
            q0, r0, q1 = q1, r1, q1 - (r1 - ratio) * (q1 - q0) / (r1 - r0)
        return replace(law, quintic=float(q1))

    def same_as(self, other: "AmplitudeLaw") -> bool:
        """Whether a fit with ``other`` would be this fit (a series law moved by under 1e-3)."""
        if self.kind != "series" or other.kind != "series":
            return self == other
        return abs(other.s - self.s) <= _LAW_RTOL * abs(self.s) and other.quintic == self.quintic


LINEAR = AmplitudeLaw()
