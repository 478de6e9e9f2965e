"""Elastic wires (issue 20): the elastic statics, modes and engines against closed forms, an independent
elastic model, the inextensible limit and each other.

The independent elastic model (:func:`independent_rest`, :func:`independent_periods`) shares no code
with :mod:`bifilar.rig.elastic`: the net wrench on the body (force and moment about the COM, world
frame) written from its definition with scipy's rotations, its root found by MINPACK's hybrid method
(``scipy.optimize.root``), and the stiffness as the central-difference Jacobian of the wrench (step 1e-6
of the rig's size: truncation ~1e-12 relative, rounding ~1e-14 N / 1e-6 m against stiffnesses of
>= m g / L ~ 30 N/m, ~1e-9 relative), the periods from the generalised eigenproblem with the rigid
body's mass matrix. At an equilibrium the wrench's Jacobian in (COM shift, world rotation vector)
coordinates is the potential's Hessian: the chart's correction multiplies the vanishing wrench.

Closed forms of a symmetric four-wire platform with vertical wires (docs/elastic-wires.md): each wire
carries m g / 4 and stretches by m g L / (4 EA); bounce 2 pi sqrt(m L / (4 EA)) (L unstretched: the
spring constant is EA / L), yaw 2 pi sqrt(I L' / (m g R^2)) and sway 2 pi sqrt(L' / g) with L' the
stretched length (the tension's geometric stiffness t / L').
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from scipy.linalg import eigh
from scipy.optimize import root
from scipy.spatial.transform import Rotation

from bifilar.motion.modes import linearize
from bifilar.rig import Rig
from bifilar.rig.statics import rest_pose, rig_scale

from ..assets import rig
from ..engines import engines, mujoco_rig
from ..engines.mjcf import CHOSEN
from ..metrics import max_abs, period, yaw
from ..registry import CaseContext, case, check

RTOL = 1e-10
LINEAR_TOL = 1e-9  # closed-form linear periods: eigenproblems of 6 x 6 matrices, rounding only
INDEPENDENT_TOL = 1e-6  # the bar; the FD stiffness is good to ~1e-9 (module docstring)
# kane (elastic N-wire, DOP853 at rtol 1e-10) vs MuJoCo (tendon springs, semi-implicit Euler at 4e-5 s,
# second order with the staggered velocities): the bars; measured ~1e-10 m and ~1e-6.
POSE_TOL = 1e-5  # m
TENSION_TOL = 1e-3  # of the largest static tension
# MuJoCo's step for the elastic runs. Its leapfrog is second order in h omega_fast: on the asymmetric
# platform, whose release rings the 44-68 Hz bounce and tilts at ~100 % of the static tension, the
# tensions differ from kane by 1.6e-3 at the chosen 4e-5 s, 3.9e-4 at 2e-5 s, 1.0e-4 at 1e-5 s (the
# COM by 1.3e-7, 3.3e-8, 8.6e-9 m): half the step, a quarter of the error.
ELASTIC_TIMESTEP = 2e-5


def wrench(r: Rig, com: np.ndarray, rotation: np.ndarray) -> np.ndarray:
    """Net force (N) and moment about the COM (N m) on the body, world frame: gravity plus every wire's
    k (rho - L) pull towards its anchor while stretched."""
    force = np.array([0.0, 0.0, -r.mass * r.gravity])
    moment = np.zeros(3)
    for w in r.wires:
        arm = rotation @ (w.attach - r.com)
        span = w.anchor - com - arm
        rho = np.linalg.norm(span)
        pull = w.axial_stiffness / w.length * max(rho - w.length, 0.0) * span / rho
        force += pull
        moment += np.cross(arm, pull)
    return np.concatenate([force, moment])


def _wrench_at(r: Rig, com0, rot0, q: np.ndarray) -> np.ndarray:
    return wrench(r, com0 + q[:3], Rotation.from_rotvec(q[3:]).as_matrix() @ rot0)


def independent_rest(r: Rig, com0: np.ndarray, rot0: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The equilibrium near the pose (com0, rot0): the root of :func:`wrench`; (com, rotation, tensions)."""
    scale = rig_scale(r)
    weight = r.mass * r.gravity
    unit = np.array([1.0, 1.0, 1.0, scale, scale, scale])
    sol = root(lambda y: _wrench_at(r, com0, rot0, y / unit) / weight * unit / scale * np.array([scale] * 3 + [1.0] * 3),
               np.zeros(6), method="hybr", options={"xtol": 1e-15})
    q = sol.x / unit
    com, rot = com0 + q[:3], Rotation.from_rotvec(q[3:]).as_matrix() @ rot0
    tensions = np.array([w.axial_stiffness / w.length * max(np.linalg.norm(w.anchor - com - rot @ (w.attach - r.com)) - w.length, 0.0)
                         for w in r.wires])
    return com, rot, tensions


def independent_periods(r: Rig, com: np.ndarray, rot: np.ndarray) -> np.ndarray:
    """The six periods (s, ascending) about the equilibrium (com, rot): K = -d wrench / d q by central
    differences, M = diag(m I, R I R^T)."""
    h = 1e-6 * rig_scale(r)
    steps = np.array([h, h, h, h / rig_scale(r), h / rig_scale(r), h / rig_scale(r)])
    k = np.empty((6, 6))
    for j in range(6):
        dq = np.zeros(6)
        dq[j] = steps[j]
        k[:, j] = -(_wrench_at(r, com, rot, dq) - _wrench_at(r, com, rot, -dq)) / (2.0 * steps[j])
    m = np.zeros((6, 6))
    m[:3, :3] = r.mass * np.eye(3)
    m[3:, 3:] = rot @ r.inertia @ rot.T
    w2 = eigh(0.5 * (k + k.T), m, eigvals_only=True)
    return np.sort(2.0 * np.pi / np.sqrt(w2))


def against_independent(r: Rig) -> tuple[float, float]:
    """(max tension difference / max tension, max relative period difference) of the statics and modes
    against the independent model, started 3e-5 m and 1e-4 rad away from the rest pose (less than the
    stiff quadrifilar's 7e-5 m stretch: further up, every wire would be slack and the wrench flat)."""
    lin = linearize(r)
    nudge = Rotation.from_rotvec([1e-5, -7e-6, 1e-4]).as_matrix()
    com, rot, tensions = independent_rest(r, lin.rest.com + [2e-5, -2e-5, -2e-5], nudge @ lin.rest.rotation)
    ours = np.sort([m.period for m in lin.modes])
    theirs = independent_periods(r, com, rot)
    return (float(np.abs(tensions - lin.rest.tensions).max() / tensions.max()),
            float(np.abs(ours / theirs - 1.0).max()))


def with_stiffness(r: Rig, factor: float) -> Rig:
    """The rig with every wire's axial stiffness times ``factor``."""
    return replace(r, wires=tuple(replace(w, axial_stiffness=w.axial_stiffness * factor) for w in r.wires))


def with_ea(r: Rig, ea: float) -> Rig:
    """The rig with every wire elastic of axial stiffness ``ea`` (N)."""
    return replace(r, wires=tuple(replace(w, axial_stiffness=ea) for w in r.wires))


@case("elastic-quadrifilar-closed-form", source="issue 20 (symmetric four-wire platform)", engines=("kane", "analytic"))
def quadrifilar_closed_form(ctx: CaseContext):
    """Symmetric quadrifilar on vertical elastic wires: load shares, the six linear periods against the
    closed forms, and the elastic N-wire yaw period at 1e-3 rad against the linear one."""
    r = rig("quadrifilar")
    m, g, L, R, ea, inertia = r.mass, r.gravity, 1.5, 0.3, 2.0e5, r.inertia
    stretched = L + m * g * L / (4.0 * ea)
    lin = linearize(r)
    by = {mode.motion: mode.period for mode in lin.modes}
    out = [check("rest tensions vs m g / 4", np.abs(lin.rest.tensions / (m * g / 4.0) - 1.0).max(), 1e-12,
                 "four equal vertical springs: symmetry; the minimum is found to rounding"),
           check("rest drop vs m g L / (4 EA)", abs(-lin.rest.com[2] / (m * g * L / (4.0 * ea)) - 1.0), 1e-8,
                 "the stretch, 7.4e-5 m, against coordinates ~1 m: rounding 1e-16 m / 7e-5 m ~ 1e-12, plus the tolerance "
                 "of the minimum")]
    closed = {
        "bounce": 2.0 * np.pi * np.sqrt(m * L / (4.0 * ea)),
        "yaw": 2.0 * np.pi * np.sqrt(inertia[2, 2] * stretched / (m * g * R**2)),
        "sway x": 2.0 * np.pi * np.sqrt(stretched / g),
        "sway y": 2.0 * np.pi * np.sqrt(stretched / g),
        # a tilt about x stretches the two wires on the y axis by +-R theta: 2 (EA / L) R^2 over I_xx
        "roll": 2.0 * np.pi * np.sqrt(inertia[0, 0] * L / (2.0 * ea * R**2)),
    }
    # Roll's geometric stiffness: the tensions' t_i (u . s) term vanishes (u vertical, s horizontal) and
    # the lateral ones (t / L') move no attachment sideways under a tilt about a horizontal axis through
    # the attachment plane, so roll is the two springs alone.
    for motion, value in closed.items():
        out.append(check(f"linear {motion} period vs closed form", abs(by[motion] / value - 1.0), LINEAR_TOL,
                         "closed form of the linearisation; rounding only"))
    start = r.with_initial(rotation=(0.0, 0.0, 1e-3))
    traj = engines()["kane"](start, 3.0 * by["yaw"], by["yaw"] / 100.0, RTOL)
    ctx.keep(traj)
    out.append(check("kane (elastic N-wire) yaw period at 1e-3 rad vs linear", abs(period(traj.t, yaw(traj)).value / by["yaw"] - 1.0),
                     1e-6, "amplitude correction ~ phi0^2 / 16 = 6e-8 plus integrator and crossing error"))
    return out


@case("elastic-independent", source="issue 20 (an independent elastic model)", engines=("analytic",))
def independent(ctx: CaseContext):
    """Rest tensions and all six periods of the elastic rigs against the independent elastic model."""
    out = []
    for name in ("quadrifilar", "quadrifilar_asymmetric", "soft_cords"):
        tension, periods = against_independent(rig(name))
        out += [check(f"{name}: rest tensions vs independent / max tension", tension, INDEPENDENT_TOL,
                      "two solutions of the equilibrium, each to ~1e-12"),
                check(f"{name}: six periods vs independent (relative)", periods, INDEPENDENT_TOL,
                      "analytic Hessian vs central differences of the wrench (~1e-9)")]
    return out


@case("elastic-stiff-limit", source="issue 20 (EA -> infinity)", engines=("analytic",))
def stiff_limit(ctx: CaseContext):
    """EA -> infinity recovers the inextensible rig: periods and rest tensions of the asymmetric trifilar
    differ from the inextensible ones by the order of the stretch eps = max t / EA (first order: ten
    times the stiffness, a tenth of the difference)."""
    base = rig("trifilar_asymmetric")
    rigid = linearize(base)
    weight = base.mass * base.gravity
    out, diffs = [], []
    for ea in (1e6, 1e7):
        lin = linearize(with_ea(base, ea))
        eps = float(lin.rest.tensions.max() / ea)
        slow = sorted(m.period for m in lin.modes if m.stretch_share < 0.5)
        d_period = float(np.max(np.abs(np.array(slow[::-1]) / np.array([m.period for m in rigid.modes]) - 1.0)))
        d_tension = float(np.abs(lin.rest.tensions - rigid.rest.tensions).max() / weight)
        diffs.append((d_period, d_tension))
        out += [check(f"EA = {ea:g} N: slow periods vs inextensible / eps", d_period / eps, 1.0,
                      "a stretch eps lengthens a pendulum of length L by eps L: its period by eps / 2"),
                check(f"EA = {ea:g} N: rest tensions vs inextensible / (W eps)", d_tension / eps, 1.0,
                      "O(eps): the stretch turns the wires by ~eps rad, shifting the shares by ~eps W (measured 0.11)")]
    for k, label in enumerate(("periods", "tensions")):
        out.append(check(f"first order: {label} difference ratio at 10 x EA", abs(diffs[1][k] / diffs[0][k] * 10.0 - 1.0), 0.05,
                         "a first-order effect: the ratio is 1/10 up to O(eps) = 1e-5", ))
    return out


def _engine_runs(ctx: CaseContext, name: str, duration: float):
    r = rig(name)
    runs = {"kane": engines()["kane"](r, duration, 0.01, RTOL),
            "mujoco": mujoco_rig.run(r, duration, 0.01, numerics=CHOSEN.with_(timestep=ELASTIC_TIMESTEP))}
    ctx.keep(*runs.values())
    kane, mj = runs["kane"], runs["mujoco"]
    static = float(kane["tension"][0].max())
    return [check(f"{name}: COM, mujoco vs kane", max_abs(kane["com"] - mj["com"]), POSE_TOL,
                  f"the issue's bar; MuJoCo's leapfrog at {ELASTIC_TIMESTEP:g} s against DOP853 at rtol 1e-10", unit="m"),
            check(f"{name}: tensions, mujoco vs kane / static", max_abs(kane["tension"] - mj["tension"]) / static,
                  TENSION_TOL, f"the issue's bar; MuJoCo's second-order error at {ELASTIC_TIMESTEP:g} s in the ringing fast modes"),
            check(f"{name}: kane energy drift / (m g x 1 mm)", max_abs(kane["energy"] - kane["energy"][0])
                  / (r.mass * r.gravity * 1e-3), 1e-7, "conservative model at rtol 1e-10")]


@case("elastic-engines", source="issue 20 (kane vs mujoco on elastic wires)", engines=("kane", "mujoco"))
def elastic_engines(ctx: CaseContext):
    """Yaw releases on the asymmetric four-wire platform (unequal stiffnesses, offset COM) and on the
    soft cords (2.5 % stretch): the elastic N-wire model against MuJoCo's tendon springs over 3 s."""
    return _engine_runs(ctx, "quadrifilar_asymmetric", 3.0) + _engine_runs(ctx, "soft_cords", 3.0)
