"""Synthetic measured records with the traits of real ones, whose truth is known (tests, cases, docs).

The motion is the exact 1-DOF torsion of :mod:`bifilar.motion.lagrange` (integrated independently of
the fit, by scipy's DOP853 at rtol 1e-10: a period error ~1e-10, far below any fit's sigma), optionally with a stronger amplitude dependence than the
ideal rig's (an extra cubic restoring term, ``excess`` times the law's own period-amplitude
coefficient), viscous and quadratic damping. The record then gets what trackers and gyros add:

* video: frames at ``fps`` (60-240) with a fraction ``missing`` dropped, time as frame numbers;
* noise of ``noise`` (rad, or rad/s for a rate) coloured by a first-order filter of pole ``colour``
  (a smoothing tracker; 0: white), an ``offset``, a fraction ``glitches`` of single-frame glitches of
  ``glitch`` rad, folding into (-pi/2, pi/2] (a line tracker whose line is near the image vertical
  at rest, so that its angle, offset by pi/2, wraps twice in every cycle, ``fold``);
* ``kind="proportional"``: pixels, ``scale`` pixels per rad, plus a superposed ``second`` mode
  (period s, amplitude px) such as the pendulum swing.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp
from scipy.signal import lfilter

from bifilar.motion import lagrange as L


@dataclass(frozen=True)
class Synthetic:
    """Frame numbers (or times) and values of a record, the true zero-amplitude period T0 (s) and
    the true amplitude at the start (rad)."""

    frames: np.ndarray
    values: np.ndarray
    period: float
    amplitude: float
    fps: float


def torsion_record(rig: L.TorsionRig, rng: np.random.Generator, *, amplitude: float = 0.5, cycles: float = 40.0,
                   fps: float = 60.0, kind: str = "angle", noise: float = 0.007, colour: float = 0.7,
                   offset: float = 0.03, glitches: float = 0.003, glitch: float = 0.4, missing: float = 0.02,
                   fold: bool = False, zeta: float = 2e-3, quadratic: float = 0.02, excess: float = 0.0,
                   scale: float = 300.0, second: tuple[float, float] | None = None) -> Synthetic:
    """A record of ``cycles`` cycles of the rig's torsion released from rest at ``amplitude`` rad."""
    t0 = L.linear_period(rig)
    omega = 2.0 * math.pi / t0
    kappa = -8.0 / 3.0 * excess * L.period_amplitude_coefficient(rig)

    def rhs(_, y):
        th, w = y
        acc = L.exact_acceleration(rig, th, w) - omega**2 * kappa * th**3 - 2 * zeta * omega * w - quadratic * abs(w) * w
        return [w, acc]

    span = cycles * t0 * (1.0 + 0.2 * amplitude**2)
    sol = solve_ivp(rhs, (0.0, span), [amplitude, 0.0], method="DOP853", rtol=1e-10, atol=1e-12, dense_output=True)
    frames = np.arange(int(span * fps))
    frames = frames[rng.uniform(size=len(frames)) >= missing]
    t = frames / fps
    state = sol.sol(t)
    clean = state[1] if kind == "rate" else state[0]
    coloured = lfilter([math.sqrt(1.0 - colour**2)], [1.0, -colour], rng.standard_normal(len(t)))  # AR(1), unit variance
    y = clean + offset + noise * coloured
    hit = rng.uniform(size=len(t)) < glitches
    y[hit] += glitch * rng.choice([-1.0, 1.0], size=int(hit.sum()))
    if kind == "proportional":
        y = scale * y
        if second is not None:
            y += second[1] * np.cos(2.0 * math.pi * t / second[0] + 0.3) * np.exp(-0.01 * t)
    if fold:  # the tracked line is near the image's vertical at rest: its angle wraps every cycle
        y = y + 0.5 * math.pi
        y = y - math.pi * np.round(y / math.pi)
        y[y <= -0.5 * math.pi] += math.pi
    return Synthetic(frames, y, t0, amplitude, fps)


def write_tracker_csv(path, record: Synthetic, column: str = "angle", delimiter: str = ",") -> None:
    """The record as a video tracker writes it: a ``frame`` column and the value column, no time."""
    rows = "".join(f"{f}{delimiter}{v:.6f}\n" for f, v in zip(record.frames, record.values))
    with open(path, "w") as out:
        out.write(f"frame{delimiter}{column}\n" + rows)


def random_traits(rng: np.random.Generator, max_cycles: float = 150.0) -> dict:
    """Keyword arguments of :func:`torsion_record` drawn over the ranges real records show: start
    0.3-1.4 rad, 60-240 fps, noise 0.005-0.01 rad white to strongly coloured, offsets of a few
    hundredths, glitches, 0-5 % lost frames, a real amplitude law 0-40 % stronger than the ideal
    one, damping that leaves 0.15-0.4 rad of a large start, a folding line tracker one time in three."""
    cycles = rng.uniform(10.0, max_cycles)
    amplitude = rng.uniform(0.3, 1.4)
    return dict(amplitude=amplitude, cycles=cycles, fps=float(rng.choice([60.0, 120.0, 240.0]) if cycles < 40 else 60.0),
                noise=rng.uniform(0.005, 0.01), colour=rng.uniform(0.0, 0.85), offset=rng.uniform(-0.05, 0.05),
                glitches=rng.uniform(0.0, 0.005), missing=rng.uniform(0.0, 0.05), excess=rng.uniform(0.0, 0.4),
                zeta=rng.uniform(1e-4, 1e-3) * 20.0 / cycles, quadratic=rng.uniform(0.0, 0.02) * 20.0 / cycles,
                fold=bool(rng.uniform() < 1.0 / 3.0))
