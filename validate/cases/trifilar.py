"""Trifilar platform cases (issue 11): the N-wire model and the linearised modes against the trifilar's
closed forms and an exact quadrature, against MuJoCo's tendon and equality cables, and an added-mass
identification with tare subtraction.

Closed forms (vertical wires of length L, which is then also the vertical drop; attachments at radius
R from the axis; small-angle limit): omega^2 = M g R^2 / (L I) for the COM on the axis, and
omega^2 = M g (R^2 - d^2) / (L I_cm) for yaw about the vertical through a COM d off the axis (the
wire tensions then satisfy sum t_i = M g, sum t_i r_i = M g d, so the yaw stiffness about the COM is
sum t_i |r_i - d|^2 / L = M g (R^2 - d^2) / L, and yaw about the COM exerts no net sideways force).

Exact large-amplitude torsion of the symmetric platform (docs/nwire-model.md, section 6): by the
three-fold symmetry the platform only turns by phi about the axis and rises; each wire's horizontal
span is 2 R sin(phi/2), so the COM height is z(phi) = -sqrt(L^2 - 4 R^2 sin^2(phi/2)) below the anchors
and energy gives phi'^2 = 2 M g (z(phi0) - z(phi)) / (I + M z'(phi)^2); the period is the quadrature
T = 4 int_0^phi0 dphi / phi'.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from scipy.integrate import quad

from bifilar.motion import lagrange
from bifilar.motion.modes import linearize

from ..assets import rig
from ..engines import engines
from ..metrics import max_abs, period, quat_angle_difference, yaw
from ..registry import CaseContext, case, check
from .rig_engines import AGREEMENT, MUJOCO, agreement_metrics

RTOL = 1e-10
# DOP853 at rtol 1e-10 over ~3 periods, crossings refined from samples 1/100 period apart: 1e-8 relative.
PERIOD_TOL = 1e-8
# The linearisation is an eigenproblem of 3 x 3 matrices assembled in closed form: rounding only.
LINEAR_TOL = 1e-9


def torsion_period(mass: float, inertia: float, radius: float, length: float, gravity: float, amplitude: float) -> float:
    """Exact period (s) of the symmetric trifilar's torsion at amplitude ``amplitude`` (rad); see the
    module docstring. phi = phi0 sin(u) removes the turning point's inverse-square-root singularity."""
    def height(phi):
        return np.sqrt(length**2 - 4.0 * radius**2 * np.sin(phi / 2.0) ** 2)

    h0 = height(amplitude)

    def integrand(u):
        phi = amplitude * np.sin(u)
        gap = 2.0 * amplitude * np.sin((np.pi / 2.0 - u) / 2.0) ** 2  # phi0 - phi without cancellation
        h = height(phi)
        # z(phi0) - z(phi) = h(phi) - h(phi0), written without cancellation.
        rise = 4.0 * radius**2 * np.sin(gap / 2.0) * np.sin((amplitude + phi) / 2.0) / (h + h0)
        slope = radius**2 * np.sin(phi) / h  # dz/dphi
        rate2 = 2.0 * mass * gravity * rise / (inertia + mass * slope**2)
        # d phi = phi0 cos(u) du; rise ~ cos^2(u) near u = pi/2, so the ratio stays finite.
        return amplitude * np.cos(u) / np.sqrt(rate2)  # quad never samples the end u = pi/2
    value, _ = quad(integrand, 0.0, np.pi / 2.0, epsabs=0.0, epsrel=1e-13, limit=200)
    return 4.0 * value


def _yaw_period(name: str, r, amplitude: float, periods: float = 3.0):
    """Period of yaw of an engine run released at ``amplitude`` rad of torsion, and the run."""
    lin = linearize(r)
    t_lin = next(m.period for m in lin.modes if m.motion == "yaw")
    released = r.with_initial(rotation=(0.0, 0.0, amplitude))
    traj = engines()[name](released, periods * t_lin, t_lin / 100.0, RTOL)
    return period(traj.t, yaw(traj)).value, traj


@case("trifilar-closed-form", source="issue 11 (trifilar torsion)", engines=("kane", "analytic"))
def closed_form(ctx: CaseContext):
    """Symmetric trifilar: linear yaw period against M g R^2 / (L I); N-wire runs at 0.01 and 0.5 rad
    against the exact quadrature."""
    r = rig("trifilar")
    R, L, I = 0.3, 1.5, r.inertia[2, 2]
    closed = 2.0 * np.pi / np.sqrt(r.mass * r.gravity * R**2 / (L * I))
    lin = {m.motion: m.period for m in linearize(r).modes}
    out = [check("linearised yaw period vs M g R^2 / (L I)", abs(lin["yaw"] / closed - 1.0), LINEAR_TOL,
                 "closed form, small-angle limit, L = vertical drop (vertical wires)")]
    sway = 2.0 * np.pi * np.sqrt(L / r.gravity)
    out.append(check("linearised sway periods vs 2 pi sqrt(L / g)",
                     max(abs(lin["sway x"] / sway - 1.0), abs(lin["sway y"] / sway - 1.0)), LINEAR_TOL,
                     "vertical wires: the platform translates as a pendulum of length L"))
    for amplitude in (0.01, 0.5):
        measured, traj = _yaw_period("kane", r, amplitude)
        ctx.keep(traj)
        exact = torsion_period(r.mass, I, R, L, r.gravity, amplitude)
        out.append(check(f"kane (N-wire) period at {amplitude} rad vs exact quadrature", abs(measured / exact - 1.0),
                         PERIOD_TOL, "integrator rtol 1e-10 and crossing refinement"))
    torsion = lagrange.from_rig(r)  # the bifilar's 1-DOF law with b, D twice the radii (the fit's exact law)
    out.append(check("lagrange exact period at 0.5 rad (from_rig, b = D = 2R) vs this quadrature",
                     abs(lagrange.period(torsion, 0.5, vertical_ke=True) / torsion_period(r.mass, I, R, L, r.gravity, 0.5)
                         - 1.0), 1e-12, "two quadratures of one energy integral, each to 1e-13"))
    out.append(check("quadrature at 1e-6 rad vs closed form", abs(torsion_period(r.mass, I, R, L, r.gravity, 1e-6) / closed - 1.0),
                     1e-10, "the quadrature's small-amplitude limit (amplitude correction ~1e-13)"))
    return out


@case("trifilar-offset", source="issue 11 (trifilar, COM off the axis)", engines=("kane", "analytic"))
def offset(ctx: CaseContext):
    """COM 0.05 m off the axis: linear yaw period against M g (R^2 - d^2) / (L I_cm), and the N-wire run
    at 1e-3 rad against it."""
    r = rig("trifilar_offset")
    R, L, d, I = 0.3, 1.5, 0.05, r.inertia[2, 2]
    closed = 2.0 * np.pi / np.sqrt(r.mass * r.gravity * (R**2 - d**2) / (L * I))
    lin = {m.motion: m.period for m in linearize(r).modes}
    measured, traj = _yaw_period("kane", r, 1e-3)
    ctx.keep(traj)
    return [
        check("linearised yaw period vs M g (R^2 - d^2) / (L I_cm)", abs(lin["yaw"] / closed - 1.0), LINEAR_TOL,
              "closed form, small-angle limit, L = vertical drop"),
        check("kane (N-wire) period at 1e-3 rad vs closed form", abs(measured / closed - 1.0), 1e-6,
              "amplitude correction ~ phi0^2 / 16 = 6e-8 plus integrator error"),
    ]


@case("trifilar-engines", source="issue 11 (N-wire model vs MuJoCo)", engines=("kane",) + MUJOCO)
def trifilar_engines(ctx: CaseContext):
    """Symmetric trifilar at 0.1 rad: N-wire model and MuJoCo (tendon, equality) periods against the
    exact quadrature; wire lengths, tensions and poses against the N-wire model."""
    r = rig("trifilar")
    exact = torsion_period(r.mass, r.inertia[2, 2], 0.3, 1.5, r.gravity, 0.1)
    dt = 0.02  # a whole number of MuJoCo steps, ~1/100 of the period
    runs = {name: engines()[name](r, 3.0 * exact, dt, RTOL) for name in ("kane",) + MUJOCO}
    ctx.keep(*runs.values())
    out = []
    for name, traj in runs.items():
        tol = PERIOD_TOL if name == "kane" else AGREEMENT[name].period
        out.append(check(f"{name}: period vs exact quadrature", abs(period(traj.t, yaw(traj)).value / exact - 1.0),
                         tol, "integrator rtol 1e-10" if name == "kane" else AGREEMENT[name].reason))
    out.append(check("kane: max wire length error", max_abs(runs["kane"]["length_error"]), 1e-10,
                     "projection onto the wire lengths every second", unit="m"))
    out += agreement_metrics(runs, r.mass * r.gravity / 3.0)
    return out


@case("trifilar-asymmetric", source="issue 11 (unequal wires, COM offset, products of inertia)",
      engines=("kane",) + MUJOCO)
def asymmetric(ctx: CaseContext):
    """Unequal wires, COM off the axis and below the attachments, products of inertia, released with a
    tilt, a turn and a spin: the N-wire model against MuJoCo, and its energy conservation."""
    r = rig("trifilar_asymmetric")
    runs = {name: engines()[name](r, 3.0, 0.02, RTOL) for name in ("kane",) + MUJOCO}
    ctx.keep(*runs.values())
    kane = runs["kane"]
    energy = kane["energy"]
    out = [check("kane: energy drift / kinetic energy scale", max_abs(energy - energy[0]) / (r.mass * r.gravity * 1e-3),
                 1e-8, "conservative model integrated at rtol 1e-10 (drift relative to ~mg x 1 mm)"),
           check("kane: max wire length error", max_abs(kane["length_error"]), 1e-10,
                 "projection onto the wire lengths every second", unit="m")]
    out += agreement_metrics(runs, float(np.max(kane["tension"][0])))
    return out


@case("trifilar-added-mass", source="issue 11 (added mass, tare subtraction)", engines=("kane", "analytic"))
def added_mass(ctx: CaseContext):
    """Two masses m/2 at +-r on the platform (COM stays on the axis): Delta I identified from the
    N-wire yaw periods of the loaded and the empty (tare) platform, by I = M g R^2 T^2 / (4 pi^2 L)
    with each run's own mass, against m r^2 plus the masses' own inertia."""
    tare = rig("trifilar")
    R, L, m, a = 0.3, 1.5, 0.2, 0.02  # each mass a cylinder of radius a: own I_zz = (m/2) a^2 / 2
    out = []
    t_tare, traj = _yaw_period("kane", tare, 1e-3)
    ctx.keep(traj)
    i_tare = tare.mass * tare.gravity * R**2 * t_tare**2 / (4.0 * np.pi**2 * L)
    out.append(check("tare: identified I_zz vs the rig file", abs(i_tare / tare.inertia[2, 2] - 1.0), 1e-6,
                     "amplitude 1e-3 rad: T^2 carries 2 x phi0^2 / 16 = 1.3e-7, plus integrator error"))
    for r_mass in (0.1, 0.2):
        own = m * a**2 / 2.0  # both masses' own I_zz
        # Masses on the x axis; their own tilt inertia (taken as own / 2, a short cylinder) does not enter yaw.
        added = np.diag([own / 2.0, m * r_mass**2 + own / 2.0, m * r_mass**2 + own])
        loaded = replace(tare, mass=tare.mass + m, inertia=tare.inertia + added)
        t_loaded, traj = _yaw_period("kane", loaded, 1e-3)
        i_loaded = loaded.mass * loaded.gravity * R**2 * t_loaded**2 / (4.0 * np.pi**2 * L)
        expected = m * r_mass**2 + own
        out.append(check(f"Delta I_zz at r = {r_mass} m vs m r^2 + own", abs((i_loaded - i_tare) / expected - 1.0), 2e-5,
                         "each I carries ~1e-7 relative amplitude bias; Delta I is ~1/20 of I, so x20"))
    return out


@case("nwire-vs-kane-tseng", source="issue 11 (two wires: two derivations)", engines=("nwire", "kane"))
def nwire_vs_kane_tseng(ctx: CaseContext):
    """On two-wire rigs the N-wire model (Newton-Euler, tensions as multipliers) and the Kane-Tseng
    model (five thesis angles) are independent derivations: over 10 s they agree to integrator error."""
    out = []
    for name in ("plate", "asymmetric"):
        r = rig(name)
        a = engines()["nwire"](r, 10.0, 0.01, RTOL)
        b = engines()["kane"](r, 10.0, 0.01, RTOL)
        ctx.keep(a, b)
        reason = "two integrations at rtol 1e-10 over 10 s (~1e3 steps)"
        out += [check(f"{name}: COM, nwire vs kane", max_abs(a["com"] - b["com"]), 1e-8, reason, unit="m"),
                check(f"{name}: orientation, nwire vs kane", quat_angle_difference(a, b), 1e-8, reason, unit="rad"),
                check(f"{name}: tensions, nwire vs kane / static", max_abs(a["tension"] - b["tension"]) / max_abs(b["tension"][0]),
                      1e-8, reason)]
    return out
