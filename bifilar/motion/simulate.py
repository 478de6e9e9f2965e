"""Integrate the Kane-Tseng equations from a rigid-body state, switching wire charts as needed.

The state vector is (theta, theta') in the current chart of wire 1's direction. Integration uses
scipy's DOP853 (8th order, dense output of order 7), which reaches the 1e-10 relative tolerances the
cross-checks need in few steps. Three terminal events stop a segment:

* the chart degenerates (POLAR: sin(theta2) < 0.1, TILT: |u . n1| > 0.95); the state is converted
  through the pose to the other chart and integration resumes, so hysteresis prevents chattering;
* a wire's tension reaches zero: the taut-wire model no longer holds, and the run ends there with
  ``slack`` saying which wire went slack and when (the model never integrates a pushing wire).

Outputs are sampled on a uniform grid from the dense output, never from the integrator's own steps.

Every run has a work budget (:class:`Budget`: right-hand-side evaluations and wall time) and raises
:class:`BudgetSpent` when it is spent, so that no input makes a run go on for ever: a motion so
violent that the steps shrink without end is stopped, with how far it got.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp

from bifilar.motion import kane_kernel as K
from bifilar.motion.kane import POLAR, TILT, KaneModel, wire_angles
from bifilar.rig.statics import State, length_errors

_ENTER_TILT = 0.1  # leave POLAR when sin(theta2) falls below this
_ENTER_POLAR = 0.95  # leave TILT when |u . n1| rises above this
_START_POLAR = 0.2  # start in POLAR when sin(theta2) is at least this


@dataclass(frozen=True)
class KaneRun:
    """A sampled Kane trajectory; every vector is in the world frame, every angle in the thesis's
    POLAR chart (theta3 is arbitrary where theta2 = 0)."""

    t: np.ndarray  # s, (n,)
    theta: np.ndarray  # rad, (n, 5)
    com: np.ndarray  # m, (n, 3)
    rotation: np.ndarray  # body -> world, (n, 3, 3)
    velocity: np.ndarray  # m/s, (n, 3)
    omega: np.ndarray  # rad/s, (n, 3)
    tension: np.ndarray  # N, (n, 2)
    length_error: np.ndarray  # m, (n, 2)
    energy: np.ndarray  # J, (n,)
    chart: np.ndarray  # chart used at each sample, (n,)
    nfev: int  # right-hand-side evaluations
    slack: tuple[int, float] | None  # (wire number, time) where a wire went slack, else None


class IntegrationError(RuntimeError):
    """The integrator could not continue (step size underflow: the motion is too violent)."""


class BudgetSpent(IntegrationError):
    """A run spent its work budget (:class:`Budget`) before reaching its end."""


@dataclass(frozen=True)
class Budget:
    """The most work one run may do: right-hand-side evaluations per simulated second (plus a floor)
    and wall-clock seconds (None: unbounded). The plate in torsion needs ~270 evaluations per simulated
    second at rtol 1e-10 (tests/test_robust.py), and the evaluations run at ~1.5e5 per wall second
    (benchmarks/kane.py); the default allows 1e6 per simulated second, some 4000 times an ordinary
    run, i.e. about 7 wall seconds per simulated second before it stops a run whose steps shrink
    without end."""

    rhs_per_second: float = 1e6
    rhs_floor: int = 1_000_000
    seconds: float | None = None

    def rhs_limit(self, duration: float) -> int:
        return int(self.rhs_floor + self.rhs_per_second * duration)


_CHECK_EVERY = 2000  # RHS calls between two looks at the clock (~15 ms of work)


class Meter:
    """Counts RHS evaluations across segments and raises :class:`BudgetSpent` when the budget is gone."""

    def __init__(self, budget: Budget, duration: float, model: str = "kane"):
        self.limit, self.seconds, self.model = budget.rhs_limit(duration), budget.seconds, model
        self.start, self.calls, self.t = time.monotonic(), 0, 0.0

    def tick(self, t: float) -> None:
        self.calls += 1
        self.t = t
        if self.calls % _CHECK_EVERY:
            return
        if self.calls >= self.limit:
            raise BudgetSpent(f"{self.model}: work budget spent ({self.calls} right-hand-side evaluations) at t = {t:.6g} s")
        if self.seconds is not None and time.monotonic() - self.start > self.seconds:
            raise BudgetSpent(f"{self.model}: wall-time budget of {self.seconds:g} s spent at t = {t:.6g} s")


MAX_SAMPLES = 10_000_000  # an output grid larger than this is a mistake, not a request


def output_grid(duration: float, dt_out: float) -> np.ndarray:
    """Sample times 0, dt_out, 2 dt_out, ... up to ``duration`` (s); the last one is clipped to
    ``duration`` so that rounding (3 x 0.1 > 0.3) never drops it."""
    n_out = int(np.floor(duration / dt_out + 1e-9)) + 1
    if n_out > MAX_SAMPLES:
        raise ValueError(f"{n_out} output samples (duration / dt_out): at most {MAX_SAMPLES}")
    return np.minimum(np.arange(n_out) * dt_out, duration)


def _pushing_wire(y: np.ndarray, p: np.ndarray, chart: int) -> tuple[int, float] | None:
    """(wire, 0.0) if a wire's tension is already negative in state ``y``, else None."""
    tension = K.loads(y[:5], y[5:], p, chart)[0]
    return (int(np.argmin(tension)) + 1, 0.0) if tension.min() < 0.0 else None


def state_to_chart(model: KaneModel, state: State, chart: int) -> np.ndarray:
    """(theta, theta') of a rigid-body state in the given chart."""
    theta = model.angles(state.com, state.rotation, chart)
    return np.concatenate([theta, model.rates(theta, state.velocity, state.omega, chart)])


def preferred_chart(model: KaneModel, state: State) -> int:
    """POLAR unless wire 1 hangs within ~11.5 degrees of the vertical."""
    theta = model.angles(state.com, state.rotation, POLAR)
    return POLAR if np.sin(theta[1]) >= _START_POLAR else TILT


def simulate(
    model: KaneModel,
    state: State,
    duration: float,
    dt_out: float = 0.01,
    rtol: float = 1e-10,
    atol: float | None = None,
    budget: Budget = Budget(),
) -> KaneRun:
    """Integrate from ``state`` for ``duration`` seconds, sampling every ``dt_out`` seconds, within
    ``budget`` (else :class:`BudgetSpent`)."""
    atol = 1e-2 * rtol if atol is None else atol
    meter = Meter(budget, duration)

    def rhs(t, yy, c):
        meter.tick(t)
        return K.rhs(yy, p, c)

    grid = output_grid(duration, dt_out)
    p = model.p
    chart = preferred_chart(model, state)
    y = state_to_chart(model, state, chart)
    samples = []
    nfev = 0
    slack = _pushing_wire(y, p, chart)  # a wire that would already have to push: stop at t = 0
    if slack is not None:
        return _sampled_run(model, [(y[None, :], chart)], grid, nfev, slack)
    t0, t_end = 0.0, float(grid[-1])
    if t_end == 0.0:  # a duration shorter than dt_out: the one sample at t = 0
        return _sampled_run(model, [(y[None, :], chart)], grid, nfev, None)
    while True:
        events = [_chart_event(chart), _slack_event(p, chart, 0), _slack_event(p, chart, 1)]
        todo = grid[grid > t0] if samples else grid
        sol = solve_ivp(
            lambda t, yy, c=chart: rhs(t, yy, c),
            (t0, t_end),
            y,
            method="DOP853",
            t_eval=todo,
            rtol=rtol,
            atol=atol,
            events=events,
        )
        nfev += sol.nfev
        if sol.status == -1:
            raise IntegrationError(f"kane integration failed at t = {sol.t[-1] if sol.t.size else t0:.6g} s: {sol.message}")
        if sol.y.shape[1]:
            samples.append((sol.y.T, chart))
        if sol.status == 0:
            break
        t_event = sol.t_events
        if t_event[1].size or t_event[2].size:
            wire = 1 if t_event[1].size else 2
            slack = (wire, float(t_event[wire][0]))
            break
        # Chart boundary: go through the pose to the other chart and carry on.
        t0 = float(t_event[0][0])
        y_event = sol.y_events[0][0]
        pose_state = model.state(y_event[:5], y_event[5:], chart)
        chart = TILT if chart == POLAR else POLAR
        y = state_to_chart(model, pose_state, chart)
    return _sampled_run(model, samples, grid, nfev, slack)


def _chart_event(chart: int):
    if chart == POLAR:
        def event(t, y):
            return np.sin(y[1]) - _ENTER_TILT
    else:
        def event(t, y):
            return _ENTER_POLAR - abs(np.sin(y[2]))
    event.terminal, event.direction = True, -1
    return event


def _slack_event(p: np.ndarray, chart: int, wire: int):
    def event(t, y):
        return K.loads(y[:5], y[5:], p, chart)[0][wire]
    event.terminal, event.direction = True, -1
    return event


def _sampled_run(model, samples, grid, nfev, slack) -> KaneRun:
    parts = {k: [] for k in ("theta", "com", "rotation", "velocity", "omega", "tension", "energy", "chart")}
    for Y, chart in samples:
        Y = np.ascontiguousarray(Y, dtype=float)
        com, frames, vel, omg, tension, _, energy = K.observe(Y, model.p, chart)
        theta = Y[:, :5].copy()
        if chart == TILT:
            for i in range(len(theta)):
                u = K.wire_direction(theta[i, 1], theta[i, 2], TILT)[0]
                theta[i, 1:3] = wire_angles(u, POLAR)
        parts["theta"].append(theta)
        parts["com"].append(com)
        parts["rotation"].append(frames @ model.frame_in_body.T)
        parts["velocity"].append(vel)
        parts["omega"].append(omg)
        parts["tension"].append(tension)
        parts["energy"].append(energy)
        parts["chart"].append(np.full(len(Y), chart))
    cat = {k: np.concatenate(v) for k, v in parts.items()}
    n = len(cat["energy"])
    length_error = length_errors(model.rig, cat["com"], cat["rotation"])
    return KaneRun(
        t=grid[:n],
        theta=cat["theta"],
        com=cat["com"],
        rotation=cat["rotation"],
        velocity=cat["velocity"],
        omega=cat["omega"],
        tension=cat["tension"],
        length_error=length_error,
        energy=cat["energy"],
        chart=cat["chart"],
        nfev=nfev,
        slack=slack,
    )

