"""The thesis's warm-up examples (seed 000, ch. 4.5 and appendix A): the planar and the spherical
pendulum in MuJoCo against closed forms, and against the thesis's equations (4.5.1)/(4.5.7).

MuJoCo model: a point mass m on a massless rod of length l from a fixed pivot (hinge for the planar
pendulum, ball joint for the spherical one). A taut wire and a rod move alike; the rod makes the
constraint exact in MuJoCo (joint coordinates, no soft constraint), so what is measured is the
integrator. The mass is a tiny solid sphere (radius 1e-4 m): its own inertia changes the period by
(2/5)(r/l)^2 ~ 2e-10. Integrator RK4, dt = 1e-3 s: global error ~ (w dt)^4 ~ 1e-12.
"""

from __future__ import annotations

import mujoco
import numpy as np
from scipy.integrate import quad, solve_ivp
from scipy.spatial.transform import Rotation
from scipy.special import ellipk

from ..metrics import channel_difference, max_abs, period
from ..registry import CaseContext, case, check
from ..trajectory import Trajectory

LENGTH, MASS, G = 5.0, 1.0, 9.81  # thesis 4.5: l = 5 m; the mass drops out
DT = 1e-3
BALL_RADIUS = 1e-4


def pendulum_model(joint: str) -> mujoco.MjModel:
    """A point mass on a rigid massless rod hanging from the origin (world z up)."""
    spec = mujoco.MjSpec()
    spec.option.timestep = DT
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_RK4
    spec.option.gravity = [0.0, 0.0, -G]
    inertia = 0.4 * MASS * BALL_RADIUS**2  # solid sphere about its centre
    body = spec.worldbody.add_body(name="bob", pos=[0.0, 0.0, 0.0], mass=MASS, ipos=[0.0, 0.0, -LENGTH],
                                   inertia=[inertia] * 3, explicitinertial=True)
    kind = mujoco.mjtJoint.mjJNT_HINGE if joint == "hinge" else mujoco.mjtJoint.mjJNT_BALL
    body.add_joint(name="pivot", type=kind, axis=[0.0, 1.0, 0.0])
    body.add_geom(type=mujoco.mjtGeom.mjGEOM_SPHERE, size=[0.1, 0, 0], pos=[0.0, 0.0, -LENGTH], mass=0.0,
                  contype=0, conaffinity=0)  # drawn only
    return spec.compile()


def run_mujoco(model: mujoco.MjModel, qpos, qvel, duration: float, dt_out: float) -> Trajectory:
    """Sample the bob's position (world, m) and energy (J) every dt_out (rounded to whole steps)."""
    data = mujoco.MjData(model)
    data.qpos[:], data.qvel[:] = qpos, qvel
    nstep = max(1, int(round(dt_out / model.opt.timestep)))
    dt_out = nstep * model.opt.timestep
    n = int(duration / dt_out) + 1
    pos, energy = np.empty((n, 3)), np.empty(n)
    for k in range(n):
        if k:
            mujoco.mj_step(model, data, nstep)
        mujoco.mj_forward(model, data)
        pos[k] = data.geom_xpos[0]
        vel = np.empty(6)
        mujoco.mj_objectVelocity(model, data, mujoco.mjtObj.mjOBJ_GEOM, 0, vel, 0)
        energy[k] = 0.5 * MASS * vel[3:] @ vel[3:] + MASS * G * pos[k, 2]
    return Trajectory("mujoco", np.arange(n) * dt_out, {"bob": pos, "energy": energy})


def planar_period(amplitude: float) -> float:
    """4 sqrt(l/g) K(sin^2(amplitude/2))."""
    return float(4.0 * np.sqrt(LENGTH / G) * ellipk(np.sin(amplitude / 2.0) ** 2))


@case("pendulum-planar-A", source="000 appendix A", engines=("mujoco", "analytic"))
def planar(ctx: CaseContext):
    """Planar pendulum released from rest: period against the elliptic-integral closed form."""
    model = pendulum_model("hinge")
    out = []
    for amplitude in (0.1, 1.0, 2.5):
        exact = planar_period(amplitude)
        traj = run_mujoco(model, [amplitude], [0.0], 8.0 * exact, exact / 200.0)
        ctx.keep(traj)
        measured = period(traj.t, traj["bob"][:, 0], level=0.0)
        out.append(check(f"period at {amplitude} rad vs 4 sqrt(l/g) K", abs(measured.value / exact - 1.0), 1e-8,
                         "RK4 at dt 1e-3 (~1e-12) and crossing refinement (~1e-10)"))
        out.append(check(f"energy drift at {amplitude} rad / (m g l)", max_abs(traj["energy"] - traj["energy"][0])
                         / (MASS * G * LENGTH), 1e-9, "RK4 is not symplectic: drift ~ (w dt)^4 per period"))
    return out


def spherical_theta_period(theta0: float, dtheta0: float, dphi0: float) -> float:
    """Period of the polar angle of a spherical pendulum from the energy and L_z integrals.

    With u = cos(theta), theta from the downward vertical, u'^2 = (1 - u^2)(a + 2 (g/l) u) - b^2 is a
    cubic with roots u1 < -1 <= u2 < u3 <= 1, equal to 2 (g/l)(u - u1)(u - u2)(u3 - u) on the motion's
    range [u2, u3]; T = 2 int_{u2}^{u3} du / sqrt(cubic), by Gauss-Jacobi quadrature (exact for the
    endpoint square-root singularities).
    """
    w2 = G / LENGTH
    s, c = np.sin(theta0), np.cos(theta0)
    a = dtheta0**2 + dphi0**2 * s**2 - 2.0 * w2 * c  # 2E / (m l^2) with u = cos(theta)
    b = dphi0 * s**2  # L_z / (m l^2)
    # u'^2 = -2 w2 u^3 - a u^2 + 2 w2 u + (a - b^2)
    u1, u2, u3 = np.sort(np.roots([-2.0 * w2, -a, 2.0 * w2, a - b**2]).real)
    integral, _ = quad(lambda u: 1.0 / np.sqrt(2.0 * w2 * (u - u1)), u2, u3, weight="alg", wvar=(-0.5, -0.5),
                       epsabs=0.0, epsrel=1e-13)
    return 2.0 * integral


def thesis_spherical(t_end: float, dt_out: float, theta0: float, dtheta0: float, dphi0: float) -> Trajectory:
    """The thesis's (4.5.7) integrated with DOP853 at rtol 1e-12 (theta from the downward vertical)."""

    def rhs(t, y):
        th, dth, ph, dph = y
        return [dth, (LENGTH * dph**2 * np.sin(th) * np.cos(th) - G * np.sin(th)) / LENGTH, dph,
                -2.0 * dph * np.cos(th) * dth / np.sin(th)]

    t = np.arange(int(round(t_end / dt_out)) + 1) * dt_out
    sol = solve_ivp(rhs, (0.0, t[-1]), [theta0, dtheta0, 0.0, dphi0], method="DOP853", t_eval=t,
                    rtol=1e-12, atol=1e-12)
    th, ph = sol.y[0], sol.y[2]
    bob = LENGTH * np.column_stack([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), -np.cos(th)])
    return Trajectory("thesis-4.5.7", t, {"bob": bob})


@case("pendulum-spherical-4.5", source="000 ch. 4.5", engines=("mujoco", "thesis-4.5.7", "analytic"))
def spherical(ctx: CaseContext):
    """Spherical pendulum with theta'(0) = 1 and phi'(0) = 2 rad/s (thesis fig. 4.5.2), from 0.5 rad."""
    theta0, dtheta0, dphi0 = 0.5, 1.0, 2.0
    model = pendulum_model("ball")
    # Orientation taking the rod (-z) to the bob's direction: R = Rz(phi) Ry(-theta), phi = 0.
    rot = Rotation.from_euler("zy", [0.0, -theta0])
    omega_world = np.array([0.0, -dtheta0, dphi0])  # theta' about -y (at phi = 0), phi' about z
    qpos = rot.as_quat(scalar_first=True)
    qvel = rot.inv().apply(omega_world)  # a ball joint's velocity is in the body frame
    exact = spherical_theta_period(theta0, dtheta0, dphi0)
    dt_out = DT * round(exact / 200.0 / DT)
    traj = run_mujoco(model, qpos, qvel, 10.0 * exact, dt_out)
    thesis = thesis_spherical(traj.t[-1], dt_out, theta0, dtheta0, dphi0)
    ctx.keep(traj, thesis)
    measured = period(traj.t, traj["bob"][:, 2])
    return [
        check("theta period vs energy/L_z quadrature", abs(measured.value / exact - 1.0), 1e-8,
              "RK4 at dt 1e-3 and crossing refinement"),
        check("bob position: MuJoCo vs (4.5.7) over 10 theta periods", channel_difference(traj, thesis, "bob"), 1e-7,
              "both integrate the same smooth, non-chaotic motion: RK4 (1e-12/step) vs DOP853 rtol 1e-12", unit="m"),
        check("energy drift / (m g l)", max_abs(traj["energy"] - traj["energy"][0]) / (MASS * G * LENGTH), 1e-9,
              "RK4 at dt 1e-3"),
    ]

