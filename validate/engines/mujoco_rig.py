"""MuJoCo as an engine: the rig model of :mod:`validate.engines.mjcf`, stepped in C, sampled on a grid.

``ENGINES`` holds two engines, ``mujoco`` (tendon cables: one-sided, may go slack) and ``mujoco-eq``
(equality cables: two-sided), both with the chosen :data:`~validate.engines.mjcf.CHOSEN` numerics.
Both start from :func:`bifilar.rig.statics.initial_state` unless given another state, like every engine.

Sampling: between samples ``mj_step(nstep=dt_out / timestep)`` advances in C. After ``mj_step`` the
derived quantities in ``mjData`` (``efc_force``, ``ten_length``, ``qacc``) are those computed at the
start of the last step, one step before the sampled ``qpos``; so each sample calls ``mj_forward`` to
recompute them at the sampled state. That costs one forward pass per sample (1/250 of the work at the
chosen step) and changes nothing in the trajectory: the next ``mj_step`` repeats that same forward
pass. How velocities are started and read is explained in :func:`simulate`. :func:`run_batch` steps
many runs at once through ``mujoco.rollout`` on every core, sampled by the same code.

Refused before a step is taken: a rig whose two cable rows are so unequally loaded that MuJoCo's soft
constraint is ill-conditioned there (:func:`row_coupling`; a slender body), and a run of more than
:data:`MAX_STEPS` steps. Every run has a wall-time budget (``max_seconds``).
"""

from __future__ import annotations

import os
import time
from collections.abc import Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from functools import partial

import mujoco
from mujoco import rollout
import numpy as np
from scipy.spatial.transform import Rotation

from bifilar.rig.air import added_mass
from bifilar.rig import Rig, RigError
from bifilar.motion.simulate import BudgetSpent, IntegrationError, output_grid
from bifilar.rig.statics import State, initial_state

from ..trajectory import Trajectory, rig_quaternions
from . import mjcf
from .errors import EngineInputError
from .mjcf import CHOSEN, Numerics


MAX_STEPS = 25_000_000  # 1000 s at 4e-5 s; ~3 min at the ~1.5e5 steps/s measured here (10 s of the plate in 1.6 s)
# The largest row coupling (max diag A / min eig A) at which the cable tensions stay right. Measured on
# a 10 kg body on 2 m wires, I = [Ix, 1, 1], 0.2 s at rest: coupling 13-417 (Ix 0.1-0.003) tensions
# within 2e-8; 1251 (Ix 1e-3) 6e-5; 4167 (Ix 3e-4) 3.5 %; 1.25e5 (Ix 1e-5) 63 % (the shipped rigs: 1.6-2.2).
MAX_ROW_COUPLING = 500.0
# Numbers one mujoco.rollout call of run_batch may record (128 MB): rollout keeps the state (14 numbers
# for one body) after every step, so this holds four runs of 10 s at 4e-5 s whole (see run_batch).
ROLLOUT_FLOATS = 1 << 24


def run(rig: Rig, duration: float, dt_out: float = 0.01, rtol: float = 1e-10, state: State | None = None, *,
        cables: str = "tendon", numerics: Numerics = CHOSEN, max_seconds: float | None = None) -> Trajectory:
    """Simulate from ``state`` (default: the rig's initial state) for ``duration`` s, sampled every
    ``dt_out`` s, within ``max_seconds`` of wall time. ``rtol`` is ignored: MuJoCo's accuracy is set by
    ``numerics``. A rig whose cable rows are ill-conditioned (:func:`row_coupling` above
    :data:`MAX_ROW_COUPLING`) is refused as a :class:`RigError` on ``body.inertia``."""
    model, start = _prepare(rig, duration, state, cables, numerics)
    return simulate(model, rig, start, duration, dt_out, cables, numerics.staggered, max_seconds)


@dataclass(frozen=True)
class BatchRun:
    """One run of :func:`run_batch`: the arguments of :func:`run` that may differ from run to run."""

    rig: Rig
    duration: float  # s
    dt_out: float  # s, a whole number of MuJoCo steps
    state: State | None = None  # None: the rig's initial state


def run_batch(runs: Sequence[BatchRun], *, cables: str = "tendon", numerics: Numerics = CHOSEN,
              nthread: int | None = None, max_seconds: float | None = None) -> list[Trajectory]:
    """:func:`run` for every run of ``runs``, stepped together by :func:`mujoco.rollout` on ``nthread``
    threads (default: every core), one ``MjData`` per thread; each run has its own model, duration and
    sampling. rollout records the state after every step; the sampled ones get a forward pass here,
    like in :func:`simulate`. A run that raises a MuJoCo warning stops in rollout (its time stops),
    which fails the batch as :class:`IntegrationError`.

    The same model, start, steps and samples as :func:`run`, so the same numbers (bit for bit in the
    positions, measured in ``tests/test_sweep_check.py``), with one proviso: rollout takes the solver's
    warm start (the previous step's acceleration) as an input and does not return it. A run is
    therefore rolled out in one call whenever it fits :data:`ROLLOUT_FLOATS`: the runs go longest
    first, one per thread to a call (a call steps all its runs as far as its longest, so runs of like
    length go together), as many as fit; a longer run goes in pieces, each started from the
    acceleration of its latest sample. The Newton solver converges in one iteration from either warm
    start, to rounding, but an occasional last bit of a velocity differs, and the soft cable rows turn
    a last bit of position (~1e-16 m) into ~1e-7 N of tension."""
    prepared = [_prepare(r.rig, r.duration, r.state, cables, numerics) for r in runs]
    started = time.monotonic()
    samplers = [_Sampler(model, r.rig, start, r.duration, r.dt_out, cables, numerics.staggered)
                for (model, start), r in zip(prepared, runs)]
    if not samplers:
        return []
    sizes = {(s.model.nq, s.model.nv, s.model.nbody, s.model.ntendon, s.model.neq) for s in samplers}
    if len(sizes) > 1:  # one MjData per thread serves every model: their sizes must agree
        raise ValueError(f"run_batch: the runs' models differ in size {sorted(sizes)}; batch rigs of one shape")
    nstate = mujoco.mj_stateSize(samplers[0].model, _STATE)
    nthread = (os.cpu_count() or 1) if nthread is None else nthread
    threads = [mujoco.MjData(samplers[0].model) for _ in range(nthread)]
    with _quiet_warnings(), rollout.Rollout(nthread=nthread if nthread > 1 else 0) as pool:
        for s in samplers:
            s.sample(0)
        group: list[_Sampler] = []
        for s in sorted((s for s in samplers if s.n_out > 1), key=lambda s: -s.steps):
            if group and (len(group) == nthread or (len(group) + 1) * group[0].steps * nstate > ROLLOUT_FLOATS):
                _roll(pool, threads, group, nstate, started, max_seconds)
                group = []
            group.append(s)
        _roll(pool, threads, group, nstate, started, max_seconds)
    return [s.trajectory() for s in samplers]


_STATE = mujoco.mjtState.mjSTATE_FULLPHYSICS  # what rollout takes and records


def _roll(pool: rollout.Rollout, threads: list[mujoco.MjData], group: list[_Sampler], nstate: int,
          started: float, max_seconds: float | None) -> None:
    """Step the runs of ``group`` (sample 0 taken) to their ends, sampling them on the way: in one
    rollout call if it fits :data:`ROLLOUT_FLOATS`, else in pieces (see :func:`run_batch`)."""
    done = 0  # steps every unfinished run has taken
    active = group
    while active:
        nstep = min(max(ROLLOUT_FLOATS // (nstate * len(active)), 1), max(s.steps for s in active) - done)
        start = np.empty((len(active), nstate))
        warm = np.empty((len(active), active[0].model.nv))
        for i, s in enumerate(active):
            mujoco.mj_getState(s.model, s.data, start[i], _STATE)
            warm[i] = s.data.qacc_warmstart  # zero at the start, as in simulate
        states, _ = pool.rollout([s.model for s in active], threads, start, nstep=nstep, initial_warmstart=warm)
        for i, s in enumerate(active):
            h = s.model.opt.timestep
            for k in range(done // s.nstep + 1, min((done + nstep) // s.nstep, s.n_out - 1) + 1):
                state = states[i, k * s.nstep - done - 1]
                if abs(state[0] - k * s.nstep * h) > 0.5 * h:
                    raise IntegrationError(f"mujoco: a warning stopped the run of {s.rig.name} before t = "
                                           f"{k * s.dt_out:g} s; the run is not valid (numerics too coarse?)")
                mujoco.mj_setState(s.model, s.data, state, _STATE)
                s.sample(k)
            s.data.qacc_warmstart[:] = s.data.qacc  # the next piece's: see run_batch
            mujoco.mj_setState(s.model, s.data, states[i, -1], _STATE)
        done += nstep
        _check_budget(started, max_seconds, done * active[0].model.opt.timestep)
        active = [s for s in active if s.steps > done]


def _prepare(rig: Rig, duration: float, state: State | None, cables: str,
             numerics: Numerics) -> tuple[mujoco.MjModel, State]:
    """The compiled model and the start of a run, refused before a step as :func:`run` says."""
    steps = duration / numerics.timestep
    if steps > MAX_STEPS:
        raise EngineInputError("--duration", f"{duration:g} s is {steps:.3g} MuJoCo steps of {numerics.timestep:g} s, "
                               f"more than the {MAX_STEPS:.3g} one run may take")
    model = mjcf.compile_model(rig, cables, numerics)
    start = initial_state(rig) if state is None else state
    if rig.elastic:  # springs, no constraint rows: nothing to be ill-conditioned
        return model, start
    coupling = row_coupling(model, rig, start)
    if coupling > MAX_ROW_COUPLING:
        raise RigError(rig.source, "body.inertia", f"MuJoCo's soft cables are ill-conditioned for this body (row "
                       f"coupling {coupling:.3g} > {MAX_ROW_COUPLING:g}: one wire's pull turns the body far more than "
                       "the other's); its tensions would be wrong by percent: use --engine kane")
    return model, start


def row_coupling(model: mujoco.MjModel, rig: Rig, state: State) -> float:
    """How ill-conditioned the cable rows are at ``state``: max diag(A) / min eig(A) of the cables'
    inverse inertia A = J M^-1 J^T (J: tendon Jacobian). MuJoCo regularises each soft row by about
    (1 - d) / d times its own diagonal of A, so a direction of A much weaker than its diagonal (a body
    that turns easily under one wire's pull, e.g. a slender rod) is softened far more than (1 - d) and
    its tension swings."""
    data = mujoco.MjData(model)
    data.qpos[:], data.qvel[:] = mjcf.state_qpos_qvel(rig, state)
    mujoco.mj_forward(model, data)
    A = _cable_inverse_inertia(model, data)
    return float(np.diag(A).max() / max(np.linalg.eigvalsh(A)[0], np.finfo(float).tiny))


def jacobian_rate(model: mujoco.MjModel, data: mujoco.MjData, jacobian) -> np.ndarray:
    """J' qvel at the current state, J = ``jacobian(model, data)`` (constraint rows by dof): a central
    difference of J qvel along qvel, the curvature term of a constraint held at zero acceleration."""
    v = data.qvel.copy()
    eps = 1e-6 / max(float(np.abs(v).max()), 1.0)  # s; central difference, error ~ (|v| eps)^2
    probe = mujoco.MjData(model)
    rates = []
    for sign in (1.0, -1.0):
        probe.qpos[:] = data.qpos
        mujoco.mj_integratePos(model, probe.qpos, v, sign * eps)
        mujoco.mj_fwdPosition(model, probe)
        rates.append(jacobian(model, probe) @ v)
    return (rates[0] - rates[1]) / (2.0 * eps)


def _tendon_jacobian(model: mujoco.MjModel, data: mujoco.MjData) -> np.ndarray:
    return np.asarray(data.ten_J, dtype=float).reshape(model.ntendon, model.nv)


def _cable_inverse_inertia(model: mujoco.MjModel, data: mujoco.MjData) -> np.ndarray:
    """A = J M^-1 J^T (ntendon x ntendon) at the current forward pass."""
    J = _tendon_jacobian(model, data)
    X = np.empty_like(J)
    mujoco.mj_solveM(model, data, X, J)  # rows: M^-1 J_i^T (M is symmetric)
    return J @ X.T


def settled_tensions(model: mujoco.MjModel, data: mujoco.MjData, cables: str) -> np.ndarray:
    """The tensions (N) a rigid cable would carry at the current state (after ``mj_forward``): each taut
    wire's length has zero second derivative, J qacc + J' qvel = 0 with qacc = a0 - M^-1 J^T T, so
    A T = J a0 + J' qvel (a0: MuJoCo's unconstrained acceleration ``qacc_smooth``; J' qvel by a central
    difference of J qvel along qvel). A tendon cable that would have to push is slack (0) and the
    others are solved without it; an equality cable keeps its sign."""
    J = _tendon_jacobian(model, data)
    rhs = J @ data.qacc_smooth + jacobian_rate(model, data, _tendon_jacobian)
    A = _cable_inverse_inertia(model, data)
    taut = np.ones(len(rhs), dtype=bool)
    tension = np.zeros(len(rhs))
    while taut.any():
        sub = np.linalg.solve(A[np.ix_(taut, taut)], rhs[taut])
        if cables != "tendon" or sub.min() >= 0.0:
            tension[taut] = sub
            break
        taut[np.flatnonzero(taut)[np.argmin(sub)]] = False
    return tension


def simulate(model: mujoco.MjModel, rig: Rig, state: State, duration: float, dt_out: float, cables: str,
             staggered: bool = True, max_seconds: float | None = None) -> Trajectory:
    """Step a compiled rig model from ``state`` and sample the rig channels every ``dt_out`` s.

    With ``staggered`` (single-step integrators), the velocities are those of a leapfrog: MuJoCo's
    semi-implicit Euler (``v += h a(q, v); q += h v``) is the Stoermer-Verlet scheme with ``qvel``
    at half steps. Started from v(0) and read as v(t), the positions come out shifted by h/2 in time,
    a first-order error (measured on the plate: 2.8e-6 m of COM height, 3 mJ of energy, 1.2e-5 of the
    tension). So the run starts from ``v(0) - h/2 a(0)`` and reads ``v(t) = qvel + h/2 qacc``, which
    makes the state second order. Tensions are read from the forward pass at the stepped state
    ``(q, v(t - h/2))``, the one that produced the step: the constraint's damping term ``-b J v``
    there carries the correction that keeps the leapfrog on the wire's sphere; a pass at ``v(t)``
    misses it, about m v^2 / (2 L) (measured 27 N of 566 N on the plate at h = 1e-4 s).

    At t = 0 the soft rows have zero stretch and zero stretch rate: they carry about d of the static
    load and none of the velocity-dependent part (MuJoCo's reference acceleration has no term for the
    curvature of the wire's path; the stretch and stretch rate that supply it build up within two
    steps), so the plate at rest would read 1.8 % low, the side-sway at 1 rad/s 15 % low. The first
    sample's tension is therefore the settled one, :func:`settled_tensions` (what a rigid cable carries
    at that state, from MuJoCo's own J, M and unconstrained acceleration); from the second sample on
    the soft rows' own forces agree with Kane to 2e-7.
    """
    started = time.monotonic()
    run = _Sampler(model, rig, state, duration, dt_out, cables, staggered)
    with _quiet_warnings():  # reported by _check_warnings as one error, not printed by MuJoCo
        for k in range(run.n_out):
            if k:
                mujoco.mj_step(model, run.data, run.nstep)
            run.sample(k)
            _check_budget(started, max_seconds, k * dt_out)
    return run.trajectory()


class _Sampler:
    """The samples of one run, taken from its ``data`` when it holds the stepped state of sample ``k``
    (:meth:`sample`): the forward pass, the tensions and the velocities that :func:`simulate`
    describes. Shared by :func:`simulate` and :func:`run_batch`."""

    def __init__(self, model: mujoco.MjModel, rig: Rig, state: State, duration: float, dt_out: float, cables: str,
                 staggered: bool):
        self.nstep = round(dt_out / model.opt.timestep)
        if self.nstep < 1 or abs(self.nstep * model.opt.timestep - dt_out) > 1e-9 * dt_out:
            raise EngineInputError("--dt-out", f"{dt_out:g} s is not a whole number of MuJoCo time steps "
                                   f"({model.opt.timestep:g} s)")
        self.model, self.rig, self.cables, self.dt_out = model, rig, cables, dt_out
        self.times = output_grid(duration, dt_out)
        self.n_out = len(self.times)
        self.steps = (self.n_out - 1) * self.nstep  # MuJoCo steps to the last sample
        self.data = mujoco.MjData(model)
        self.data.qpos[:], self.data.qvel[:] = mjcf.state_qpos_qvel(rig, state)
        integrator = model.opt.integrator
        self.half = 0.5 * model.opt.timestep if staggered and integrator != mujoco.mjtIntegrator.mjINT_RK4 else 0.0
        self.rows = _cable_rows(model, cables)
        self.lengths = np.array([w.length for w in rig.wires])
        self.springs = np.array([w.spring for w in rig.wires])
        self.qpos = np.empty((self.n_out, model.nq))
        self.qvel = np.empty((self.n_out, model.nv))
        self.tension = np.empty((self.n_out, len(rig.wires)))
        self.length = np.empty((self.n_out, len(rig.wires)))

    def sample(self, k: int) -> None:
        model, data = self.model, self.data
        mujoco.mj_forward(model, data)
        _check_warnings(data, k * self.dt_out)
        self.qpos[k] = data.qpos
        if self.rig.elastic:  # the tendon springs: k (l - L) above L, else 0, as MuJoCo applies them
            self.tension[k] = self.springs * np.maximum(data.ten_length - self.lengths, 0.0)
        else:
            self.tension[k] = cable_tensions(data, self.rows) if k else settled_tensions(model, data, self.cables)
        self.length[k] = data.ten_length
        if k:
            self.qvel[k] = data.qvel + self.half * data.qacc
        else:
            self.qvel[k] = data.qvel
            data.qvel -= self.half * data.qacc

    def trajectory(self) -> Trajectory:
        rig, model, tension = self.rig, self.model, self.tension
        channels = rig_channels(rig, self.qpos, self.qvel)
        if rig.elastic:  # plus the strain energy, as in the N-wire model
            stretch = np.maximum(self.length - self.lengths, 0.0)
            channels["energy"] = channels["energy"] + 0.5 * (stretch**2) @ self.springs
        channels["tension"] = tension
        channels["length_error"] = self.length - np.array([w.length for w in rig.wires])
        slack = np.argwhere(tension <= 0.0)
        meta = {
            "rig": rig.name,
            "rig_spec": rig,
            "cables": self.cables,
            "timestep": model.opt.timestep,
            "integrator": mujoco.mjtIntegrator(model.opt.integrator).name,
            # (wire, time) of the first sample with a slack wire; the run goes on through slack spells.
            "first_slack": None if not slack.size else (int(slack[0, 1]) + 1, float(slack[0, 0] * self.dt_out)),
        }
        engine = "mujoco" if self.cables == "tendon" else "mujoco-eq"
        return Trajectory(engine, self.times, channels, meta)


def _check_budget(started: float, max_seconds: float | None, t: float) -> None:
    if max_seconds is not None and time.monotonic() - started > max_seconds:
        raise BudgetSpent(f"mujoco: wall-time budget of {max_seconds:g} s spent at t = {t:.6g} s")


def _cable_rows(model: mujoco.MjModel, cables: str) -> tuple[int, int]:
    """(constraint type, sign) whose rows carry the cable forces; the row's ``efc_id`` is the tendon id
    (limits) or the equality id, both numbered like the wires."""
    if cables == "tendon":
        return mujoco.mjtConstraint.mjCNSTR_LIMIT_TENDON, 1
    return mujoco.mjtConstraint.mjCNSTR_EQUALITY, -1


def cable_tensions(data: mujoco.MjData, rows: tuple[int, int]) -> np.ndarray:
    """Wire tensions (N, positive pulling) from the constraint forces of the current ``mj_forward``.

    A tendon limit row has Jacobian ``-J_tendon`` (its distance is ``length_max - length``) and a force
    ``efc_force >= 0``, so the generalized force ``-J_tendon^T f`` shortens the wire: tension ``f``.
    A tendon equality row has Jacobian ``+J_tendon`` (residual ``length - length0``) and a signed
    force, so the tension is ``-f`` (negative would mean the wire pushes). A wire without a row (limit
    inactive: slack) has tension exactly 0.
    """
    kind, sign = rows
    out = np.zeros(data.ten_length.shape[0])
    nefc = data.nefc
    mine = np.flatnonzero(data.efc_type[:nefc] == kind)
    out[data.efc_id[mine]] = sign * data.efc_force[mine]
    return out


def rig_channels(rig: Rig, qpos: np.ndarray, qvel: np.ndarray) -> dict[str, np.ndarray]:
    """COM, quaternion (qw >= 0), COM velocity, angular velocity (world) and energy (J) from sampled
    free-joint states: qvel is (origin velocity in world, angular velocity in body axes)."""
    rot = Rotation.from_quat(qpos[:, 3:7], scalar_first=True)
    matrices = rot.as_matrix()
    arm = matrices @ rig.com  # COM relative to the body origin, world
    com = qpos[:, :3] + arm
    omega = rot.apply(qvel[:, 3:6])
    velocity = qvel[:, :3] + np.cross(omega, arm)
    quat = rig_quaternions(rot)
    spin = np.einsum("ij,ij->i", qvel[:, 3:6], qvel[:, 3:6] @ rig.inertia)  # w.Iw in body axes
    energy = 0.5 * rig.mass * np.einsum("ij,ij->i", velocity, velocity) + 0.5 * spin + rig.mass * rig.gravity * com[:, 2]
    if rig.air is not None:  # plus the fluid's kinetic energy, as in the Kane engine (docs/air.md)
        x = np.concatenate([np.einsum("nji,nj->ni", matrices, velocity), qvel[:, 3:6]], axis=1)  # body axes
        energy = energy + 0.5 * np.einsum("ni,ij,nj->n", x, added_mass(rig.air, rig.com), x)
    return {"com": com, "quat": quat, "velocity": velocity, "omega": omega, "energy": energy}


@contextmanager
def _quiet_warnings():
    """Silence MuJoCo's own warning printer (and its MUJOCO_LOG.TXT) for the run, restoring the previous
    handler after: the run still fails on any warning, through :func:`_check_warnings`."""
    previous = mujoco.get_mju_user_warning()
    mujoco.set_mju_user_warning(lambda message: None)
    try:
        yield
    finally:
        mujoco.set_mju_user_warning(previous)


def _check_warnings(data: mujoco.MjData, t: float) -> None:
    counts = data.warning.number  # one count per mjtWarning, read at once (called at every sample)
    if counts.any():
        name = mujoco.mjtWarning(int(np.flatnonzero(counts)[0])).name
        raise IntegrationError(f"mujoco: {name} by t = {t:g} s; the run is not valid (numerics too coarse?)")


ENGINES = {
    "mujoco": partial(run, cables="tendon"),
    "mujoco-eq": partial(run, cables="equality"),
}
