"""MuJoCo's heavy cable: every wire a chain of N ball-jointed rigid segments with the wire's mass.

The third cable model (engine ``mujoco-cable``), for rigs whose wires have a ``linear_density``: it
knows nothing of the first-order heavy-wire model (:mod:`bifilar.rig.heavy`) it checks. Wire i hangs
from a ball joint at its anchor; segment k is a rigid body of mass rho L / N whose inertia is a thin
uniform rod's across it (m l^2 / 12) and, to keep the spin about its own axis decoupled
(nothing turns a segment about its axis; a small axial moment made that spin unstable under tension),
the same along it, on a ball joint at its upper end; the
last segment's lower end is tied to the body's attachment point by a ``connect`` equality (the loop
closes through it). A straight chain therefore has the continuous wire's kinetic and potential
energy exactly; what N limits is the wire's bending (its sag and its own transverse modes), which
enters the body's motion at second order in the wire-to-body mass ratio (docs/heavy-wires.md).

The run starts from the lumped rig's initial state (:func:`bifilar.rig.heavy.lumped`, the rig file's
``[initial]`` semantics) with every wire straight and turning rigidly about its anchor with the
attachment's velocity. The straight wire is not the sagged one at rest: its transverse modes (fast,
~ pi sqrt(t / rho) / L) start with the sag's amplitude, and the joints between segments carry a
damping that takes them out within a few of their periods without touching a straight wire's swing
(the anchor joint is undamped). ``tension`` is the norm of the connect constraint's force, the pull
of the wire on the body at its end (at t = 0 the force rigid rows would carry,
:func:`rigid_connect_forces`); ``length_error`` is the anchor-attachment distance minus the
wire's length (the sag shortens it by O(ratio^2) L, the connect rows' stretch, ~5e-8 m,
lengthens it); ``energy`` is MuJoCo's, body and chains.

Numerics: MuJoCo's implicitfast at :data:`TIMESTEP` (the chain's fastest mode, omega ~ 2 N sqrt(t /
rho) / L, is ~2e3 rad/s for the rigs of tests and cases: omega h ~ 0.2), connect rows with the rig
engine's solref (2 h, 0.5) and solimp d = 0.9999 (:data:`IMPEDANCE`: at the rig engine's 0.99 the
rows, tied to a light segment, stretched 4.5e-7 m on the parallel rig and cost 1.5e-6 in the period).
Velocities are those of the step, not staggered as in
:mod:`validate.engines.mujoco_rig`: a period is insensitive to that half step.
"""

from __future__ import annotations

import time

import mujoco
import numpy as np
from scipy.spatial.transform import Rotation

from bifilar.motion.simulate import BudgetSpent, IntegrationError, output_grid
from bifilar.rig import Rig, RigError
from bifilar.rig.heavy import lumped
from bifilar.rig.statics import State, anchors, initial_state

from ..trajectory import Trajectory
from .errors import EngineInputError
from .mujoco_rig import _check_warnings, _quiet_warnings, jacobian_rate, rig_channels

SEGMENTS = 16  # per wire; the bending it leaves out is second order in the mass ratio
TIMESTEP = 1e-4  # s
BEND_DAMPING = 0.2  # fraction of critical damping of the wire's first transverse mode, at the inner joints
MAX_STEPS = 5_000_000
SOLREF_STEPS = 2  # the connect rows' time constant in steps, damping ratio DAMPRATIO (the rig engine's choice)
DAMPRATIO = 0.5
INTEGRATOR = "implicitfast"
IMPEDANCE = 0.9999  # solimp d of the connect rows


def run(rig: Rig, duration: float, dt_out: float = 0.01, rtol: float = 1e-10, state: State | None = None, *,
        segments: int = SEGMENTS, timestep: float = TIMESTEP, max_seconds: float | None = None) -> Trajectory:
    """Simulate the rig on heavy cables for ``duration`` s sampled every ``dt_out`` s (``rtol`` is
    ignored). ``state``: the body's start (default the rig's initial state on the lumped rig); a rig
    whose wires have no ``linear_density`` is refused as a :class:`RigError` on ``wire``."""
    missing = [i for i, w in enumerate(rig.wires, start=1) if w.linear_density <= 0.0]
    if missing:
        raise RigError(rig.source, f"wire[{missing[0]}].linear_density", "missing: the mujoco-cable engine models "
                       "heavy wires; give every wire a linear_density (kg/m), or use --engine mujoco")
    if rig.air is not None:
        raise RigError(rig.source, "air", "the mujoco-cable engine has no fluid model: simulate heavy wires in a "
                       "vacuum (drop [air]), or the air on massless wires with --engine kane or mujoco")
    nstep = round(dt_out / timestep)
    if nstep < 1 or abs(nstep * timestep - dt_out) > 1e-9 * dt_out:
        raise EngineInputError("--dt-out", f"{dt_out:g} s is not a whole number of MuJoCo time steps ({timestep:g} s)")
    times = output_grid(duration, dt_out)
    if (len(times) - 1) * nstep > MAX_STEPS:
        raise EngineInputError("--duration", f"{duration:g} s is more than {MAX_STEPS} steps of {timestep:g} s")
    start = body_state(rig) if state is None else state
    model = compile_model(rig, start, segments, timestep)
    data = mujoco.MjData(model)
    data.qvel[:] = initial_qvel(rig, start, model)
    return _sample(model, data, rig, times, nstep, dt_out, max_seconds)


def body_state(rig: Rig) -> State:
    """The rig's initial state for the body's own COM: the lumped rig's (``[initial]`` applied at its
    rest pose), moved from the lumped COM to the body's."""
    light = lumped(rig)
    s = initial_state(light)
    offset = s.rotation @ (rig.com - light.com)
    return State(s.com + offset, s.rotation, s.velocity + np.cross(s.omega, offset), s.omega)


def chain_points(rig: Rig, state: State, segments: int) -> np.ndarray:
    """(wires, segments + 1, 3): the joints of every straight chain from anchor to attachment, world."""
    ends = state.com + (state.rotation @ (np.array([w.attach for w in rig.wires]) - rig.com).T).T
    f = np.linspace(0.0, 1.0, segments + 1)[None, :, None]
    return anchors(rig)[:, None, :] * (1.0 - f) + ends[:, None, :] * f


def fmt(values) -> str:
    """Numbers as an MJCF attribute, to the last bit."""
    return " ".join(f"{x:.17g}" for x in np.ravel(values))


def _mjcf(rig: Rig, state: State, segments: int, timestep: float) -> str:
    """The model as MJCF text: the body (free joint, first, so qpos[:7] and qvel[:6] are its own) and one
    chain per wire, every body frame world-aligned at ``state``."""
    origin = state.com - state.rotation @ rig.com
    quat = Rotation.from_matrix(state.rotation).as_quat(scalar_first=True)
    inertia = rig.inertia
    body = (f'<body name="body" pos="{fmt(origin)}" quat="{fmt(quat)}"><freejoint name="body"/>'
            f'<inertial pos="{fmt(rig.com)}" mass="{rig.mass:.17g}" fullinertia="{fmt(inertia[[0, 1, 2, 0, 0, 1], [0, 1, 2, 1, 2, 2]])}"/>'
            f'<geom type="sphere" size="{0.02 * _size(rig):.6g}" pos="{fmt(rig.com)}"/></body>')
    chains, equalities = [], []
    points = chain_points(rig, state, segments)
    for i, w in enumerate(rig.wires):
        pts = points[i]
        seg = pts[1] - pts[0]
        l = float(np.linalg.norm(seg))
        m = w.linear_density * w.length / segments
        across = m * l * l / 12.0
        inertial = f'<inertial pos="{fmt(seg / 2)}" mass="{m:.17g}" diaginertia="{fmt([across] * 3)}"/>'
        damping = bend_damping(rig, i, segments)
        xml, close = "", ""
        for k in range(segments):
            pos = pts[0] if k == 0 else seg
            xml += (f'<body name="w{i + 1}s{k}" pos="{fmt(pos)}">'
                    f'<joint type="ball" damping="{0.0 if k == 0 else damping:.17g}"/>{inertial}'
                    f'<geom type="capsule" fromto="0 0 0 {fmt(seg)}" size="{0.004 * _size(rig):.6g}"/>')
            close += "</body>"
        chains.append(xml + close)
        equalities.append(f'<connect body1="w{i + 1}s{segments - 1}" body2="body" anchor="{fmt(seg)}" '
                          f'solref="{SOLREF_STEPS * timestep:.17g} {DAMPRATIO:g}" solimp="{IMPEDANCE:g} {IMPEDANCE:g} 0.001 0.5 2"/>')
    return (f'<mujoco model="{rig.name}_cable"><compiler angle="radian" inertiafromgeom="false"/>'
            f'<option timestep="{timestep:.17g}" integrator="{INTEGRATOR}" gravity="0 0 {-rig.gravity:.17g}" tolerance="1e-10">'
            f'<flag energy="enable" contact="disable"/></option>'
            f'<default><geom contype="0" conaffinity="0"/></default>'
            f'<worldbody>{body}{"".join(chains)}</worldbody><equality>{"".join(equalities)}</equality></mujoco>')


def _size(rig: Rig) -> float:
    return max(w.length for w in rig.wires)


def bend_damping(rig: Rig, wire: int, segments: int) -> float:
    """Damping (N m s/rad) of the joints between segments: each damps its segment's turning relative
    to the one above at the rate 2 :data:`BEND_DAMPING` omega_1, omega_1 = pi sqrt(t / rho) / L the
    wire's first transverse mode (a string under t ~ m g / n_wires), i.e. 2 zeta omega_1 m_s l^2 / 3
    with the segment's mass m_s and length l (its inertia about its joint)."""
    w = rig.wires[wire]
    segment = w.length / segments
    return 2.0 * BEND_DAMPING * first_mode(rig, wire) * (w.linear_density * segment) * segment**2 / 3.0


def first_mode(rig: Rig, wire: int) -> float:
    """omega_1 (rad/s) of a wire's first transverse mode, pi sqrt(t / rho) / L, with t ~ m g / n_wires."""
    w = rig.wires[wire]
    return float(np.pi * np.sqrt(rig.mass * rig.gravity / len(rig.wires) / w.linear_density) / w.length)


def compile_model(rig: Rig, state: State, segments: int = SEGMENTS, timestep: float = TIMESTEP) -> mujoco.MjModel:
    """The compiled chain model with the body at ``state`` and every wire straight."""
    return mujoco.MjModel.from_xml_string(_mjcf(rig, state, segments, timestep))


def initial_qvel(rig: Rig, state: State, model: mujoco.MjModel) -> np.ndarray:
    """Velocities: the body's free joint (origin velocity, world; angular velocity, body axes) and each
    wire's anchor joint turning the straight chain rigidly about its anchor with the attachment's
    velocity, omega = span x v_p / |span|^2 (the inner joints at rest relative to it; every body frame
    is world-aligned at the start)."""
    qvel = np.zeros(model.nv)
    arm = state.rotation @ rig.com
    qvel[:3] = state.velocity - np.cross(state.omega, arm)
    qvel[3:6] = state.rotation.T @ state.omega
    for i, w in enumerate(rig.wires):
        s = state.rotation @ (w.attach - rig.com)
        v_p = state.velocity + np.cross(state.omega, s)
        span = state.com + s - w.anchor
        dof = model.jnt_dofadr[model.body_jntadr[model.body(f"w{i + 1}s0").id]]
        qvel[dof:dof + 3] = np.cross(span, v_p) / (span @ span)
    return qvel


def _connect_rows(data: mujoco.MjData) -> np.ndarray:
    return np.flatnonzero(data.efc_type[:data.nefc] == mujoco.mjtConstraint.mjCNSTR_EQUALITY)


def _connect_jacobian(model: mujoco.MjModel, data: mujoco.MjData) -> np.ndarray:
    if not mujoco.mj_isSparse(model):
        return np.asarray(data.efc_J, dtype=float)[:data.nefc * model.nv].reshape(-1, model.nv)[_connect_rows(data)]
    dense = np.zeros((data.nefc, model.nv))  # MuJoCo keeps J sparse from 60 dofs on
    mujoco.mju_sparse2dense(dense, data.efc_J, data.efc_J_rownnz[:data.nefc], data.efc_J_rowadr[:data.nefc],
                            data.efc_J_colind)
    return dense[_connect_rows(data)]


def rigid_connect_forces(model: mujoco.MjModel, data: mujoco.MjData) -> np.ndarray:
    """The connect rows' forces (N, 3 per wire) if they were rigid, at the current state (after
    ``mj_forward``): J qacc + J' qvel = 0 with qacc = a0 - M^-1 J^T f, so (J M^-1 J^T) f = J a0 + J' qvel
    (a0 MuJoCo's unconstrained acceleration, J' qvel by a central difference), as
    :func:`validate.engines.mujoco_rig.settled_tensions` does for the rig's cables. The first sample
    reads these: the soft rows start unstretched and carry only part of the load at t = 0."""
    J = _connect_jacobian(model, data)
    X = np.empty_like(J)
    mujoco.mj_solveM(model, data, X, J)
    return np.linalg.solve(J @ X.T, J @ data.qacc_smooth + jacobian_rate(model, data, _connect_jacobian))


def _sample(model, data, rig: Rig, times: np.ndarray, nstep: int, dt_out: float,
            max_seconds: float | None) -> Trajectory:
    n = len(times)
    nw = len(rig.wires)
    qpos, qvel = np.empty((n, 7)), np.empty((n, 6))
    tension, distance, energy = np.empty((n, nw)), np.empty((n, nw)), np.empty(n)
    attach_site = np.array([w.attach for w in rig.wires])
    started = time.monotonic()
    with _quiet_warnings():
        for k in range(n):
            if k:
                mujoco.mj_step(model, data, nstep)
            mujoco.mj_forward(model, data)
            _check_warnings(data, k * dt_out)
            if not np.all(np.isfinite(data.qpos)):
                raise IntegrationError(f"mujoco-cable: non-finite state by t = {k * dt_out:g} s")
            qpos[k], qvel[k] = data.qpos[:7], data.qvel[:6]
            force = data.efc_force[_connect_rows(data)] if k else rigid_connect_forces(model, data)
            tension[k] = np.linalg.norm(force.reshape(-1, 3), axis=1)  # one connect (3 world rows) a wire
            points = data.xpos[1] + (data.xmat[1].reshape(3, 3) @ attach_site.T).T
            distance[k] = np.linalg.norm(points - anchors(rig), axis=1)
            energy[k] = data.energy.sum()
            if max_seconds is not None and time.monotonic() - started > max_seconds:
                raise BudgetSpent(f"mujoco-cable: wall-time budget of {max_seconds:g} s spent at t = {times[k]:.6g} s")
    channels = rig_channels(rig, qpos, qvel)
    channels["tension"] = tension
    channels["length_error"] = distance - np.array([w.length for w in rig.wires])
    channels["energy"] = energy
    meta = {"rig": rig.name, "rig_spec": rig, "cables": "chain", "timestep": model.opt.timestep,
            "integrator": "RK4", "segments": (model.nbody - 2) // nw, "model": "mujoco-cable"}
    return Trajectory("mujoco-cable", times, channels, meta)
