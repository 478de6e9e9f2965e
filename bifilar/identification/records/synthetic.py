"""Synthetic records with the traits real rigs and trackers show, whose truth is known (tests, cases, docs).

The motion is the exact 1-DOF torsion of :mod:`bifilar.motion.lagrange` (integrated independently of
the fit, by scipy's DOP853 at rtol 1e-11: a period error ~1e-11, far below any fit's sigma), with what
real rigs add to it:

* a real amplitude law up to 40 % stronger than the ideal rig's (hook pivots, wire bending, air): an
  extra restoring term -omega^2 kappa theta^3 (1 + q theta^2), kappa = -8/3 ``excess`` s_ideal, so that
  its A^2 coefficient is (1 + excess) times the ideal one and its shape is not a pure cubic (``shape`` q);
* viscous, quadratic and dry (hook) damping;
* a second mode beating in (``second``: period ratio to T0, amplitude relative to the swing, decay
  rate 1/s), seen by the tracker or the gyro as an apparent rotation.

and what trackers and gyros add:

* white noise and noise correlated over many frames (AR(1) of correlation time ``colour_time``);
* an offset and its slow wander (a few sinusoids of 10-40 periods, ``drift`` rad peak to peak), for a
  gyro also a bias random walk;
* frames lost in bursts (a two-state chain: ``lost`` of them, runs of ``burst`` frames on average);
* a tracker locking on at the start (``lockon`` s of jumps, values stuck at exactly -pi/4, and noise),
  a tracker repeating its last value (``holds`` per frame) and single-frame glitches;
* a line tracker folding the angle into (-pi/2, pi/2] (``fold``); a pixel signal of unknown scale
  (``kind="proportional"``, ``scale`` units per rad).

:func:`video`, :func:`gyro` and :func:`laser` draw the traits of the three kinds of record over the
ranges real records show (issue 18: 60 fps video, 100-500 Hz gyros, 240 fps laser spots).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, replace

import numpy as np
from scipy.integrate import solve_ivp
from scipy.signal import lfilter

from bifilar.motion import lagrange as L


@dataclass(frozen=True)
class Traits:
    """What a synthetic record holds (module docstring); angles in rad, times in s."""

    kind: str = "angle"
    rate: float = 60.0  # samples per second
    amplitude: float = 0.5  # release, rad
    cycles: float = 40.0
    excess: float = 0.0  # the real law's A^2 coefficient over the ideal one, minus 1
    shape: float = 0.0  # q of the excess's theta^3 (1 + q theta^2)
    zeta: float = 5e-4
    quadratic: float = 0.0
    dry: float = 0.0  # rad/s^2
    white: float = 0.003
    coloured: float = 0.0
    colour_time: float = 0.3
    offset: float = 0.0
    drift: float = 0.0
    bias_walk: float = 0.0  # rate records: rad/s per sqrt(s)
    lost: float = 0.0
    burst: float = 1.0
    lockon: float = 0.0
    holds: float = 0.0
    glitches: float = 0.0
    glitch: float = 0.3
    second: tuple[float, float, float] | None = None
    fold: bool = False
    scale: float = 1.0


@dataclass(frozen=True)
class Synthetic:
    """Sample times (s; frame numbers / rate), values, the true zero-amplitude period T0 (s), the
    traits, and the frame numbers."""

    t: np.ndarray
    y: np.ndarray
    period: float
    traits: Traits
    frames: np.ndarray


def record(rig: L.TorsionRig, rng: np.random.Generator, traits: Traits) -> Synthetic:
    """A record of ``traits.cycles`` cycles of the rig's torsion released from rest (module docstring)."""
    tr = traits
    t0 = L.linear_period(rig)
    omega = 2.0 * math.pi / t0
    span = tr.cycles * t0 * (1.0 + 0.2 * tr.amplitude**2)
    rate_out = tr.kind == "rate"
    clean = _clean(rig, span, tr.amplitude, tr.excess, tr.shape, tr.zeta, tr.quadratic, tr.dry, tr.rate, rate_out)
    n = len(clean)
    frames = np.arange(n)
    t = frames / tr.rate
    if tr.second is not None:
        ratio, rel, decay = tr.second
        w2, phase, a2 = omega / ratio, rng.uniform(0.0, 2.0 * math.pi), rel * tr.amplitude
        envelope = a2 * np.exp(-decay * t)
        clean = clean + envelope * (w2 * np.cos(w2 * t + phase) if rate_out else np.sin(w2 * t + phase))
    pole = math.exp(-1.0 / (tr.rate * tr.colour_time)) if tr.colour_time > 0.0 else 0.0
    coloured = lfilter([math.sqrt(1.0 - pole**2)], [1.0, -pole], rng.standard_normal(n))  # unit variance
    wander = np.zeros(n)
    for _ in range(3):
        wander += rng.normal() * np.sin(2.0 * math.pi * t / (rng.uniform(10.0, 40.0) * t0) + rng.uniform(0, 2 * math.pi))
    wander *= tr.drift / max(float(np.ptp(wander)), 1e-300)
    if rate_out and tr.bias_walk > 0.0:
        wander += np.cumsum(rng.standard_normal(n)) * tr.bias_walk / math.sqrt(tr.rate)
    y = clean + tr.offset + wander + tr.white * rng.standard_normal(n) + tr.coloured * coloured
    hit = rng.uniform(size=n) < tr.glitches
    y[hit] += tr.glitch * rng.choice([-1.0, 1.0], size=int(hit.sum()))
    i = 0
    while i < n:  # a tracker repeating its last value for 2-6 frames
        if rng.uniform() < tr.holds:
            k = int(rng.integers(2, 7))
            y[i + 1:i + k] = y[i]
            i += k
        i += 1
    y = _lockon(y, rng, int(tr.lockon * tr.rate))
    if tr.fold:  # the tracked line is near the image's vertical at rest: its angle wraps every cycle
        y = y + 0.5 * math.pi
        y = y - math.pi * np.round(y / math.pi)
        y[y <= -0.5 * math.pi] += math.pi
    keep = _kept(rng, n, tr.lost, tr.burst)
    return Synthetic(t[keep], tr.scale * y[keep], t0, tr, frames[keep])


@functools.lru_cache(maxsize=4)
def _motion(rig: L.TorsionRig, span: float, amplitude: float, excess: float, shape: float, zeta: float,
            quadratic: float, dry: float):
    """The clean torsion released from ``amplitude`` (rad) at rest, over ``span`` (s): DOP853's dense
    solution of (theta, theta'). Kept for the last few motions: records drawn again with the same motion
    and new noise (a study over many seeds) integrate it once, ~0.9 s of a 100-cycle record."""
    t0 = L.linear_period(rig)
    omega = 2.0 * math.pi / t0
    kappa = -8.0 / 3.0 * excess * L.period_amplitude_coefficient(rig)

    def rhs(_, state):
        th, w = state
        acc = (L.exact_acceleration(rig, th, w) - omega**2 * kappa * th**3 * (1.0 + shape * th * th)
               - 2.0 * zeta * omega * w - quadratic * abs(w) * w - dry * math.tanh(w / 1e-3))
        return [w, acc]

    return solve_ivp(rhs, (0.0, span), [amplitude, 0.0], method="DOP853", rtol=1e-11, atol=1e-13, dense_output=True).sol


@functools.lru_cache(maxsize=4)
def _clean(rig: L.TorsionRig, span: float, amplitude: float, excess: float, shape: float, zeta: float,
           quadratic: float, dry: float, rate: float, rate_out: bool) -> np.ndarray:
    """The clean motion's angle (rate: its rate) at every frame of ``rate`` frames/s over ``span``
    (read-only; frame k at k / rate s: its length is the record's frame count). Kept for the last few: a study drawing many records of one motion (new noise each)
    evaluates the dense solution's ~37 pieces a cycle once, ~0.1 s of a 100-cycle record."""
    sol = _motion(rig, span, amplitude, excess, shape, zeta, quadratic, dry)
    clean = sol(np.arange(int(span * rate)) / rate)[1 if rate_out else 0]
    clean.flags.writeable = False
    return clean


def peaks(rig: L.TorsionRig, traits: Traits, times: np.ndarray) -> np.ndarray:
    """The true peak swing (rad) at ``times`` of the record :func:`record` draws with ``traits`` (its
    clean motion, the same for any noise): the turning points sampled at 4 kHz, each refined by a
    parabola (1e-8 of the swing), ln of them interpolated (1e-7 under a light decay). The truth a fit's
    amplitudes are checked against (a record's own samples miss the turning point by ~1e-3 at 60 fps)."""
    clean = record(rig, np.random.default_rng(0), replace(traits, rate=4000.0, white=0.0, coloured=0.0, second=None,
                                                          lost=0.0, glitches=0.0, holds=0.0, lockon=0.0, drift=0.0,
                                                          offset=0.0, fold=False, scale=1.0, kind="angle"))
    a = np.abs(clean.y)
    k = np.flatnonzero((a[1:-1] >= a[:-2]) & (a[1:-1] >= a[2:])) + 1
    d = 0.5 * (a[k - 1] - a[k + 1]) / (a[k - 1] - 2.0 * a[k] + a[k + 1])
    t, peak = clean.t[k] + d / 4000.0, a[k] - 0.25 * (a[k - 1] - a[k + 1]) * d
    return np.exp(np.interp(times, t, np.log(peak)))


def _lockon(y: np.ndarray, rng: np.random.Generator, m: int) -> np.ndarray:
    """The first ``m`` samples as a tracker locking on writes them: runs of random values, of exactly
    -pi/4 (a tracker's default) and of noisy motion."""
    y = y.copy()
    j = 0
    while j < min(m, len(y)):
        k = min(int(rng.integers(2, 12)), m - j)
        kind = int(rng.integers(3))
        if kind == 0:
            y[j:j + k] = rng.uniform(-1.0, 1.0)
        elif kind == 1:
            y[j:j + k] = -0.25 * math.pi
        else:
            y[j:j + k] += rng.uniform(-0.8, 0.8)
        j += k
    return y


def _kept(rng: np.random.Generator, n: int, lost: float, burst: float) -> np.ndarray:
    """Frames kept when a fraction ``lost`` goes missing in runs of ``burst`` frames on average."""
    keep = np.ones(n, dtype=bool)
    if lost <= 0.0:
        return keep
    p_end = 1.0 / max(burst, 1.0)
    p_start = lost * p_end / (1.0 - lost)
    u = rng.uniform(size=n)
    missing = False
    for k in range(n):
        missing = (u[k] >= p_end) if missing else (u[k] < p_start)
        keep[k] = not missing
    return keep


def video(rng: np.random.Generator, **overrides) -> Traits:
    """A 60 fps tracker record of a torsion released at 0.3-1.2 rad, 12-120 cycles, with every trait
    of the module docstring drawn over the ranges real video records show."""
    cycles = rng.uniform(12.0, 120.0)
    traits = Traits(
        kind="angle", rate=60.0, amplitude=rng.uniform(0.3, 1.2), cycles=cycles,
        excess=rng.uniform(0.0, 0.4), shape=rng.uniform(-0.5, 0.5),
        zeta=rng.uniform(1e-4, 1e-3) * 40.0 / cycles, quadratic=rng.uniform(0.0, 0.02) * 40.0 / cycles,
        dry=rng.uniform(0.0, 2e-3), white=rng.uniform(0.001, 0.004), coloured=rng.uniform(0.002, 0.008),
        colour_time=rng.uniform(0.05, 1.0), offset=rng.uniform(-0.05, 0.05), drift=rng.uniform(0.0, 0.04),
        lost=rng.uniform(0.10, 0.15), burst=rng.uniform(3.0, 30.0), lockon=rng.uniform(0.0, 1.5),
        holds=rng.uniform(0.0, 0.004), glitches=rng.uniform(0.0, 0.003),
        second=(float(rng.choice([rng.uniform(1.3, 2.5), rng.uniform(0.4, 0.75)])), rng.uniform(0.0, 0.06),
                rng.uniform(0.0, 0.01)),
        fold=bool(rng.uniform() < 0.25))
    return replace(traits, **overrides)


def gyro(rng: np.random.Generator, **overrides) -> Traits:
    """A 100-500 Hz rate-gyro record (rad/s) of 10-40 cycles from 0.2-0.8 rad: bias, its random walk,
    noise, the other mode beating in, few lost samples, no tracker."""
    cycles = rng.uniform(10.0, 40.0)
    traits = Traits(
        kind="rate", rate=float(rng.choice([100.0, 250.0, 500.0])), amplitude=rng.uniform(0.2, 0.8), cycles=cycles,
        excess=rng.uniform(0.0, 0.4), shape=rng.uniform(-0.5, 0.5),
        zeta=rng.uniform(1e-4, 2e-3) * 20.0 / cycles, quadratic=rng.uniform(0.0, 0.03) * 20.0 / cycles,
        dry=rng.uniform(0.0, 3e-3), white=rng.uniform(0.01, 0.05), coloured=rng.uniform(0.0, 0.02),
        colour_time=rng.uniform(0.02, 0.3), offset=rng.uniform(-0.05, 0.05), drift=rng.uniform(0.0, 0.02),
        bias_walk=rng.uniform(0.0, 0.003), lost=rng.uniform(0.0, 0.02), burst=2.0,
        second=(rng.uniform(0.4, 2.5), rng.uniform(0.0, 0.1), rng.uniform(0.0, 0.05)))
    return replace(traits, **overrides)


def laser(rng: np.random.Generator, **overrides) -> Traits:
    """A 240 fps laser-spot record in pixels (scale 200-600 px/rad, unknown to the fit) of a small
    swing (0.02-0.1 rad) over 5-10 cycles that hardly decays, a sway beating in at ~1.9 T0."""
    traits = Traits(
        kind="proportional", rate=240.0, amplitude=rng.uniform(0.02, 0.1), cycles=rng.uniform(5.0, 10.0),
        excess=rng.uniform(0.0, 0.4), zeta=rng.uniform(0.0, 2e-4), white=rng.uniform(2e-4, 1e-3),
        coloured=rng.uniform(0.0, 5e-4), colour_time=rng.uniform(0.01, 0.1), offset=rng.uniform(-0.5, 0.5),
        drift=rng.uniform(0.0, 2e-3), second=(rng.uniform(1.8, 2.0), rng.uniform(0.05, 0.3), rng.uniform(0.0, 0.02)),
        scale=rng.uniform(200.0, 600.0))
    return replace(traits, **overrides)


def write_tracker_csv(path, rec: Synthetic, column: str = "angle", delimiter: str = ",") -> None:
    """The record as a video tracker writes it: a ``frame`` column and the value column, no time."""
    rows = "".join(f"{f}{delimiter}{v:.6f}\n" for f, v in zip(rec.frames, rec.y))
    with open(path, "w") as out:
        out.write(f"frame{delimiter}{column}\n" + rows)


def write_gyro_csv(path, rec: Synthetic, column: str = "gyro_z") -> None:
    """The record as a flight controller logs it: ``timestamp`` in ms and the rate in deg/s."""
    rows = "".join(f"{1000.0 * t:.3f},{math.degrees(v):.5f}\n" for t, v in zip(rec.t, rec.y))
    with open(path, "w") as out:
        out.write(f"timestamp,{column}\n" + rows)
