"""Hinge rigs (compound and torsion pendulums, :mod:`bifilar.rig.hinge`) against what does not share their code.

* The compound pendulum's exact period, 4 sqrt(J_p / (m g d)) K(sin^2(A / 2)) (:func:`bifilar.motion.hinge.
  period_at`), against a direct quadrature of the energy integral (which checks scipy's K convention),
  against the hand-derived 1-DOF equation integrated by DOP853 and against MuJoCo's hinge joint, which
  builds the moment about the axis from the full tensor and the pivot's offset itself.
* The torsion pendulum's 2 pi sqrt(J / k) against MuJoCo's hinge spring, at two steps: the measured period
  error must be RK4's own (omega h)^4 / 120, so a wrong J or k shows however small.
* A fork's full tensor (:mod:`bifilar.identification.hinge_tensor`'s linear rows) from MuJoCo's periods of
  it turned six ways on a torsion rod and swung on a knife edge.
* The calibration rod's inertia (:func:`bifilar.rig.hinge.cylinder_inertia`) against the volume integral
  of r^2 dm by Gauss-Legendre quadrature (exact for the polynomial integrand), solid and hollow.

Periods are measured from the interpolated rising zero crossings of the angle (:func:`validate.metrics.
period`), 200 samples a period, good to ~1e-12 relative on these signals (100 samples leave 2e-11 at 2 rad).
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
from scipy.integrate import quad

from bifilar.identification.hinge_tensor import Rod, identify_hinge_tensor, read_hinge_hangings
from bifilar.motion.hinge import linear_period, moment_about_axis, period_at
from bifilar.rig.file import load_rig
from bifilar.rig.hinge import HingeRig, cylinder_inertia

from ..assets import RIGS
from ..engines import hinge as kane_hinge
from ..engines import mujoco_hinge
from ..metrics import period
from ..registry import CaseContext, case, check

RTOL = 1e-10  # DOP853 for the kane runs
KANE_TOL = 1e-9  # DOP853 at rtol 1e-10: measured 3e-11 at 2 rad (3e-9 at 3 rad, near the top, not used here)
SAMPLES = 200  # a period: the degree-5 crossing fit's error falls as its 6th power; 100 leave 2e-11 at 2 rad
FLOOR = 1e-11  # the zero-crossing period measurement at SAMPLES a period, with margin (measured below 1e-12)
AMPLITUDES = (0.3, 2.0)  # rad: a swing where K adds 0.6 %, and one of 115 degrees where it adds 31 %


def hinge_rig(name: str, **changes) -> HingeRig:
    """The shipped hinge rig ``models/rigs/<name>.toml`` with ``changes`` (an unknown moment filled in)."""
    return replace(load_rig(RIGS / f"{name}.toml", hinge=True), **changes)


def wheel_compound() -> HingeRig:
    """The shipped wheel on its rim pivot, its unknown spin moment set to 0.1 kg m^2 (a ring's m r^2)."""
    return hinge_rig("wheel_compound", inertia=np.diag([0.1, 0.05, 0.05]))


def skew_body() -> HingeRig:
    """A body with a full inertia tensor, its COM off the origin and a pivot axis along no body axis, so
    that MuJoCo's composite inertia has every term of e^T I e + m d^2 to get right."""
    inertia = np.array([[0.30, 0.04, -0.02], [0.04, 0.22, 0.05], [-0.02, 0.05, 0.18]])
    axis = np.array([0.8, -0.3, 0.52])
    return HingeRig(name="skew", mass=2.3, inertia=inertia, kind="pivot", axis=axis / np.linalg.norm(axis),
                    point=np.array([0.05, 0.21, 0.33]), com=np.array([0.02, -0.03, 0.01]))


def _period(traj) -> float:
    return period(traj.t, traj["angle"], level=0.0).value


@case("hinge-compound-elliptic", source="issue 38; any mechanics text (simple pendulum, elliptic integral)",
      engines=("kane", "closed form"))
def compound_elliptic(ctx: CaseContext):
    """Compound pendulum: elliptic period = energy-integral quadrature = DOP853 run, to 2 rad."""
    out = []
    for rig in (wheel_compound(), skew_body()):
        omega = 2.0 * math.pi / linear_period(rig)
        for a in AMPLITUDES:
            exact = period_at(rig, a)
            # T = 4 / omega * integral_0^(pi/2) dphi / sqrt(1 - k^2 sin^2 phi), k = sin(A/2): the substitution
            # sin(theta/2) = k sin(phi) in T = 4 integral_0^A dtheta / sqrt(2 omega^2 (cos theta - cos A)).
            k2 = math.sin(0.5 * a) ** 2
            quadrature = 4.0 / omega * quad(lambda p: 1.0 / math.sqrt(1.0 - k2 * math.sin(p) ** 2), 0.0,
                                            0.5 * math.pi, epsabs=0.0, epsrel=1e-13)[0]
            out.append(check(f"{rig.name} {a} rad: elliptic vs quadrature", abs(exact / quadrature - 1.0), 1e-12,
                             "two evaluations of one integral; catches K's parameter convention (m vs k)"))
            traj = kane_hinge.run(rig, a, 5.0 * exact, exact / SAMPLES, RTOL)
            ctx.keep(traj)
            out.append(check(f"{rig.name} {a} rad: DOP853 period vs elliptic", abs(_period(traj) / exact - 1.0),
                             KANE_TOL, "DOP853 at rtol 1e-10 over five periods, plus the crossing floor"))
    return out


@case("hinge-compound-mujoco", source="issue 38", engines=("mujoco", "closed form"))
def compound_mujoco(ctx: CaseContext):
    """Compound pendulum on MuJoCo's hinge joint: its moment about the axis and its period at 2 rad."""
    out = []
    for rig in (wheel_compound(), skew_body()):
        j = moment_about_axis(rig)
        out.append(check(f"{rig.name}: MuJoCo's joint inertia vs e^T I e + m d^2",
                         abs(mujoco_hinge.joint_moment(rig) / j - 1.0), 1e-12,
                         "MuJoCo composes it from the tensor and the offset: rounding only"))
        a = AMPLITUDES[-1]
        exact = period_at(rig, a)
        dt_out = mujoco_hinge.TIMESTEP * max(1, round(exact / SAMPLES / mujoco_hinge.TIMESTEP))
        traj = mujoco_hinge.run(rig, a, 4.0 * exact, dt_out)
        ctx.keep(traj)
        rk4 = (2.0 * math.pi / linear_period(rig) * mujoco_hinge.TIMESTEP) ** 4 / 120.0
        out.append(check(f"{rig.name} {a} rad: MuJoCo period vs elliptic", abs(_period(traj) / exact - 1.0),
                         rk4 + FLOOR, f"RK4's (omega h)^4 / 120 = {rk4:.1e} plus the crossing floor"))
        drift = float(np.ptp(traj["energy"])) / (rig.mass * rig.gravity * rig.arm)
        out.append(check(f"{rig.name}: MuJoCo energy drift / m g d", drift, 1e-10,
                         "RK4 at omega h < 1e-3 conserves energy to ~1e-13 over four periods"))
    return out


@case("hinge-torsion-mujoco", source="issue 38", engines=("mujoco", "closed form"))
def torsion_mujoco(ctx: CaseContext):
    """Torsion pendulum on MuJoCo's hinge spring: 2 pi sqrt(J / k) at any amplitude, RK4's error exactly."""
    rod = hinge_rig("calibration_rod", stiffness=11.71)  # the wheel's rod (wheel_torsion.toml)
    wheel = hinge_rig("wheel_torsion", inertia=np.diag([0.1, 0.05, 0.05]))  # unknown radial moment set
    out = []
    for rig in (rod, wheel):
        exact = 2.0 * math.pi * math.sqrt(float(rig.axis @ rig.inertia @ rig.axis) / rig.stiffness)
        for a, h in ((0.5, mujoco_hinge.TIMESTEP), (3.0, 5.0 * mujoco_hinge.TIMESTEP)):
            dt_out = h * max(1, round(exact / SAMPLES / h))
            traj = mujoco_hinge.run(rig, a, 4.0 * exact, dt_out, timestep=h)
            ctx.keep(traj)
            rk4 = (2.0 * math.pi / exact * h) ** 4 / 120.0  # RK4 runs slow: its period is long by this
            out.append(check(f"{rig.name} {a} rad at h = {h:g} s: MuJoCo period error minus RK4's (omega h)^4/120",
                             abs(_period(traj) / exact - 1.0 - rk4), FLOOR,
                             f"RK4 on a linear oscillator is off by exactly {rk4:.2e}; what remains is J, k or "
                             "the measurement"))
    return out


@case("hinge-rod-inertia", source="issue 38; Meriam & Kraige table D/4", engines=("closed form",))
def rod_inertia(ctx: CaseContext):
    """cylinder_inertia (solid, hollow, the shipped calibration rod) vs the volume integral of r^2 dm."""
    out = []
    for radius, length, inner in ((0.00635, 1.0, 0.0), (0.05, 0.3, 0.04), (0.2, 0.1, 0.0)):
        mass = 1.7
        got = cylinder_inertia(mass, radius, length, inner)
        want = _volume_integral(mass, radius, length, inner)
        out.append(check(f"r {radius} L {length} ri {inner}: tensor vs volume integral",
                         float(np.abs(got - want).max() / want.max()), 1e-13, "Gauss-Legendre exact; rounding"))
    rig = hinge_rig("calibration_rod")
    textbook = rig.mass * (3.0 * 0.00635**2 + 1.0**2) / 12.0  # m (3 r^2 + L^2) / 12 about a transverse axis
    out.append(check("calibration_rod.toml: moment about the rod axis vs m (3 r^2 + L^2) / 12",
                     abs(moment_about_axis(rig) / textbook - 1.0), 1e-15, "the same number two ways: rounding"))
    return out


def _volume_integral(mass: float, radius: float, length: float, inner: float) -> np.ndarray:
    """The inertia tensor about the COM of a uniform (hollow) cylinder along x, as the integral of
    (|r|^2 1 - r r^T) dm over its volume in cylindrical coordinates (x, s, phi): Gauss-Legendre in x and
    s (polynomial integrands, exact with 4 points) and the trapezoid rule in phi (exact for the
    trigonometric degree 2 here with 8 points)."""
    nodes, weights = np.polynomial.legendre.leggauss(4)  # on [-1, 1]
    x, wx = 0.5 * length * nodes, 0.5 * length * weights
    s, ws = 0.5 * (radius + inner) + 0.5 * (radius - inner) * nodes, 0.5 * (radius - inner) * weights
    phi = np.arange(8) * (2.0 * math.pi / 8)
    wphi = np.full(8, 2.0 * math.pi / 8)
    X, S, P = np.meshgrid(x, s, phi, indexing="ij")
    W = np.einsum("i,j,k->ijk", wx, ws * s, wphi)  # the Jacobian s of cylindrical coordinates
    r = np.stack([X, S * np.cos(P), S * np.sin(P)], axis=-1)
    density = mass / (math.pi * (radius**2 - inner**2) * length)
    rr = np.einsum("...i,...j->...ij", r, r)
    tensor = np.tensordot(W, np.einsum("...k,...k->...", r, r)[..., None, None] * np.eye(3) - rr, axes=3)
    return density * tensor


# The generated fork of models/hangings/fork_torsion.toml (its header): tensor about the COM, object axes
FORK = np.array([[0.0912, 0.0031, -0.0204], [0.0031, 0.1106, 0.0057], [-0.0204, 0.0057, 0.0278]])  # kg m^2
FORK_ROD = 5.0  # N m/rad


@case("hinge-tensor-mujoco", source="issue 38 item 4; BicycleParameters' torsion and compound hangings",
      engines=("mujoco", "analytic"))
def tensor_mujoco(ctx: CaseContext):
    """A fork's full tensor from MuJoCo's periods of it on a torsion rod (six orientations) and a knife edge
    (0.25 rad): the linear rows of bifilar.identification.hinge_tensor against MuJoCo's own composite inertia."""
    setup = read_hinge_hangings(RIGS.parent / "hangings" / "fork_torsion.toml")
    hangings, worst = [], 0.0
    for h in setup.hangings:
        q = h.orientation
        truth = replace(h.rig, inertia=q @ FORK @ q.T, stiffness=FORK_ROD if h.rig.kind == "torsion" else None)
        exact = period_at(truth, h.amplitude)
        h_step = mujoco_hinge.TIMESTEP
        dt_out = h_step * max(1, round(exact / SAMPLES / h_step))
        traj = mujoco_hinge.run(truth, h.amplitude or 0.3, 4.0 * exact, dt_out)
        measured = _period(traj)
        if h.rig.kind == "torsion" and not h.amplitude:  # a rod is isochronous: the run's 0.3 rad is any amplitude
            measured /= 1.0 + (2.0 * math.pi / exact * h_step) ** 4 / 120.0  # RK4's known lengthening taken out
        worst = max(worst, abs(measured / exact - 1.0))
        hangings.append(replace(h, period=measured, sigma=0.0))
    fitted = identify_hinge_tensor(hangings, Rod(FORK_ROD, 0.0, "case")).inertia
    return [check("MuJoCo periods vs the exact law, worst of seven", worst, 1e-10,
                  "RK4 at omega h < 2e-3 ((omega h)^4 / 120 < 2e-13) plus the crossing floor 1e-11"),
            check("tensor from MuJoCo's periods vs the fork's, / largest entry",
                  float(np.abs(fitted - FORK).max() / np.abs(FORK).max()), 1e-9,
                  "moments carry 2 x the periods' 1e-11; six rows of condition ~10 and the knife edge's m d^2 "
                  "(~4x the moment) amplify it to ~1e-10")]
