"""The N-wire model: a rigid body on any number of inextensible wires, integrated in pose coordinates.

The equations (Newton-Euler, wire tensions as Lagrange multipliers; derived in docs/nwire-model.md)
are compiled in :mod:`bifilar.motion.nwire_kernel`. They hold every wire length's second derivative
at zero, so lengths drift only by the integration error; every :data:`PROJECT_EVERY` seconds the
state is projected back onto the constraint manifold (positions by minimum-norm Newton steps,
velocities by the mass-weighted projection onto the null space of the constraint Jacobian, which
removes only the constraint-violating kinetic energy) and integration restarts there.

Integration is scipy's DOP853 (rtol 1e-10 by default); outputs come from its dense output on a
uniform grid. A wire whose tension reaches zero stops the run (``slack = (wire, time)``), as in the
two-wire Kane-Tseng model (:mod:`bifilar.motion.simulate`): the taut-wire model ends there.

Elastic wires (``axial_stiffness``): the body is free in six directions and each wire a force element
pulling with k_i max(0, rho_i - L_i) (:mod:`bifilar.motion.elastic_kernel`, docs/elastic-wires.md): no
constraint to project onto, and a slack wire is simply one that pulls nothing, so the run goes on.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp
from scipy.spatial.transform import Rotation

from bifilar.motion import elastic_kernel as EK
from bifilar.motion import nwire_kernel as NK
from bifilar.motion.kane import air_vector
from bifilar.motion.simulate import Budget, IntegrationError, Meter, output_grid
from bifilar.rig import Rig
from bifilar.rig.statics import State, check_determinate, length_errors

# Projection interval (s): the drift of a wire length between projections is the integrator's error
# over that time, ~1e-12 m per second at rtol 1e-10 on the shipped rigs (measured, docs/nwire-model.md).
PROJECT_EVERY = 1.0
_PROJECT_TOL = 1e-14  # length residual / rig size at which a position projection stops


@dataclass(frozen=True)
class NWireModel:
    """Arrays the compiled kernel needs, taken from a rig."""

    rig: Rig
    arms: np.ndarray  # attachment minus COM, body frame (N x 3, m)
    anchors: np.ndarray  # world (N x 3, m)
    lengths: np.ndarray  # m
    inertia: np.ndarray  # about the COM, body axes (3 x 3, kg m^2)
    mass: float
    gravity: float
    air: np.ndarray  # the air's added mass, ellipsoid and drag (bifilar.motion.kane.air_vector); zeros in a vacuum
    springs: np.ndarray | None = None  # EA / L per wire (N/m) for elastic wires; None: inextensible

    @classmethod
    def from_rig(cls, rig: Rig) -> "NWireModel":
        return cls(
            rig=rig,
            arms=np.array([w.attach - rig.com for w in rig.wires]),
            anchors=np.array([w.anchor for w in rig.wires]),
            lengths=np.array([w.length for w in rig.wires]),
            inertia=np.ascontiguousarray(rig.inertia, dtype=float),
            mass=float(rig.mass),
            gravity=float(rig.gravity),
            air=air_vector(rig),
            springs=np.array([w.spring for w in rig.wires]) if rig.elastic else None,
        )

    @property
    def args(self):
        return self.arms, self.anchors, self.inertia, self.mass, self.gravity, self.air

    @property
    def elastic_args(self):
        return self.arms, self.anchors, self.lengths, self.springs, self.inertia, self.mass, self.gravity, self.air

    @property
    def scale(self) -> float:
        return float(max(self.lengths.max(), 1e-3))

    def tensions(self, y: np.ndarray) -> np.ndarray:
        return NK.dynamics(np.ascontiguousarray(y, dtype=float), *self.args)[1]


@dataclass(frozen=True)
class NWireRun:
    """A sampled N-wire trajectory; every vector in the world frame."""

    t: np.ndarray  # s, (n,)
    com: np.ndarray  # m, (n, 3)
    rotation: np.ndarray  # body -> world, (n, 3, 3)
    velocity: np.ndarray  # m/s, (n, 3)
    omega: np.ndarray  # rad/s, (n, 3)
    tension: np.ndarray  # N, (n, N)
    length_error: np.ndarray  # m, (n, N)
    energy: np.ndarray  # J, (n,)
    nfev: int
    slack: tuple[int, float] | None  # (wire number, time) where a wire went slack, else None


def state_vector(state: State) -> np.ndarray:
    quat = Rotation.from_matrix(state.rotation).as_quat(scalar_first=True)
    return np.concatenate([state.com, quat, state.velocity, state.omega])


def project(model: NWireModel, y: np.ndarray) -> np.ndarray:
    """The nearest state on the constraint manifold: every wire at its length, every length rate zero."""
    y = y.copy()
    y[3:7] /= np.linalg.norm(y[3:7])
    for _ in range(10):
        rot = NK.quat_matrix(y[3:7])
        err = length_errors(model.rig, y[:3], rot)
        if np.abs(err).max() <= _PROJECT_TOL * model.scale:
            break
        jac = NK.dynamics_jacobian(y, model.arms, model.anchors)
        jac[:, 3:] /= model.scale
        step = -np.linalg.pinv(jac) @ err
        y[:3] += step[:3]
        turn = Rotation.from_rotvec(step[3:] / model.scale) * Rotation.from_quat(y[3:7], scalar_first=True)
        y[3:7] = turn.as_quat(scalar_first=True)
    rot = NK.quat_matrix(y[3:7])
    jac = NK.dynamics_jacobian(y, model.arms, model.anchors)
    minv = np.zeros((6, 6))
    minv[:3, :3] = np.eye(3) / model.mass
    minv[3:, 3:] = rot @ np.linalg.inv(model.inertia) @ rot.T
    nu = y[7:13]
    y[7:13] = nu - minv @ jac.T @ np.linalg.solve(jac @ minv @ jac.T, jac @ nu)
    return y


def simulate(model: NWireModel, state: State, duration: float, dt_out: float = 0.01, rtol: float = 1e-10,
             atol: float | None = None, budget: Budget = Budget()) -> NWireRun:
    """Integrate from ``state`` for ``duration`` s, sampled every ``dt_out`` s (see the module docstring),
    within ``budget`` (else :class:`~bifilar.motion.simulate.BudgetSpent`), as the two-wire model."""
    meter = Meter(budget, duration, "nwire")
    atol = 1e-2 * rtol if atol is None else atol
    grid = output_grid(duration, dt_out)
    y = state_vector(state)
    if model.springs is not None:
        return _simulate_elastic(model, y, grid, rtol, atol, meter)
    rot = NK.quat_matrix(y[3:7])
    check_determinate(model.rig, y[:3], rot)  # dependent wires: tensions undetermined
    args = model.args
    n = len(model.lengths)
    tension0 = model.tensions(y)
    if tension0.min() < 0.0:  # a wire would already have to push: stop at t = 0
        return _sampled_run(model, [y[None, :]], grid, 0, (int(np.argmin(tension0)) + 1, 0.0))
    samples, nfev, slack = [y[None, :]], 0, None
    t0, t_end = 0.0, float(grid[-1])
    events = [_slack_event(args, i) for i in range(n)]
    while t0 < t_end:
        t1 = min(t0 + PROJECT_EVERY, t_end)
        todo = grid[(grid > t0) & (grid <= t1)]
        def rhs(t, yy):
            meter.tick(t)
            return NK.rhs(yy, *args)

        sol = solve_ivp(rhs, (t0, t1), y, method="DOP853", t_eval=todo,
                        rtol=rtol, atol=atol, events=events, dense_output=True)
        nfev += sol.nfev
        if sol.status == -1:
            raise IntegrationError(f"nwire integration failed at t = {sol.t[-1] if sol.t.size else t0:.6g} s: {sol.message}")
        if sol.y.shape[1]:
            samples.append(sol.y.T)
        if sol.status == 1:
            wire = next(i for i in range(n) if sol.t_events[i].size)
            slack = (wire + 1, float(sol.t_events[wire][0]))
            break
        y = project(model, sol.sol(t1))
        t0 = t1
    return _sampled_run(model, samples, grid, nfev, slack)


def _simulate_elastic(model: NWireModel, y: np.ndarray, grid: np.ndarray, rtol: float, atol: float,
                      meter: Meter) -> NWireRun:
    """Elastic wires: one DOP853 integration of the free body under the wire forces."""
    args = model.elastic_args

    def rhs(t, yy):
        meter.tick(t)
        return EK.rhs(yy, *args)

    samples = [y[None, :]]
    nfev = 0
    if grid[-1] > 0.0:
        sol = solve_ivp(rhs, (0.0, float(grid[-1])), y, method="DOP853", t_eval=grid[1:], rtol=rtol, atol=atol)
        nfev = sol.nfev
        if sol.status == -1:
            raise IntegrationError(f"nwire integration failed at t = {sol.t[-1] if sol.t.size else 0.0:.6g} s: {sol.message}")
        samples.append(sol.y.T)
    Y = np.ascontiguousarray(np.concatenate(samples), dtype=float)
    frames, tension, stretch, energy = EK.observe(Y, *args)
    return NWireRun(t=grid[: len(Y)], com=Y[:, :3].copy(), rotation=frames, velocity=Y[:, 7:10].copy(),
                    omega=Y[:, 10:13].copy(), tension=tension, length_error=stretch, energy=energy, nfev=nfev,
                    slack=None)


def _slack_event(args, wire: int):
    def event(t, y):
        return NK.dynamics(y, *args)[1][wire]
    event.terminal, event.direction = True, -1
    return event


def _sampled_run(model: NWireModel, samples, grid, nfev, slack) -> NWireRun:
    Y = np.ascontiguousarray(np.concatenate(samples), dtype=float)
    frames, tension, energy = NK.observe(Y, *model.args)
    return NWireRun(
        t=grid[: len(Y)],
        com=Y[:, :3].copy(),
        rotation=frames,
        velocity=Y[:, 7:10].copy(),
        omega=Y[:, 10:13].copy(),
        tension=tension,
        length_error=length_errors(model.rig, Y[:, :3], frames),
        energy=energy,
        nfev=nfev,
        slack=slack,
    )
