"""The full inertia tensor of one object from its yaw periods in several hangings (issues 11 and 21).

Each hanging is a rig (e.g. a trifilar platform) holding the object mounted in a known orientation Q
(object axes -> the rig's body axes), so that at rest a different object axis is vertical, with the
measured period of the mode that turns about the vertical (yaw: the largest angular velocity about
world z per unit kinetic energy). The rig's inertia about its COM, in its body axes, is

    I_rig = H + Q X Q^T,

X the object's own tensor (about its COM, object axes: the unknown) and H the part held fixed: zero
for an object hung alone; for an object on a fixture, the fixture's tensor and both parallel-axis
terms, moved to the assembly's COM (:mod:`bifilar.identification.hangings` builds it exactly). The
six components x = (I_xx, I_yy, I_zz, I_xy, I_yz, I_xz) of X follow by Gauss-Newton on the exact
linearisation.

Exact and cheap: the rest pose and the stiffness K of :func:`bifilar.motion.modes.linearize` do not
depend on the inertia, and the reduced mass matrix is linear in it, M(X) = M_H + A X A^T, A = G^T R Q
(G the angular velocity per independent speed, R the rest rotation). For K v = w2 M v with v^T M v = 1,
Hellmann-Feynman gives d w2 = -w2 v^T dM v, so with the mode's object-frame rotation shape
W = A^T v = Q^T R^T G v,

    d T / dI_ab = (T/2) W_a W_b   (each product of inertia counts twice).

Errors: each period has its own sigma, and a fixture's moment measured once (a tare) moves every
hanging on that fixture together. With D_hk = d T_h / d s_k (s_k the moment a tare measured, about the
vertical of its fixture) the periods' covariance is C = diag(sigma^2) + D Sigma_s D^T; the fit is the
generalised least squares in C and the components' covariance is (J^T C^-1 J)^-1, J the Jacobian of
the periods: the linearisation of the exact inversion.

Refused (one line) when the orientations cannot determine all six components (naming those left
undetermined), when a hanging's yaw cannot be told from another mode, and when the result is not a
physical tensor (not positive definite, or breaking the triangle inequality).
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass, field

import numpy as np
from scipy.linalg import eigh

from bifilar.motion.modes import linearize, oscillating
from bifilar.rig import Rig, RigError
from bifilar.rig.heavy import has_wire_mass
from bifilar.rig.statics import rest_pose

COMPONENTS = ("I_xx", "I_yy", "I_zz", "I_xy", "I_yz", "I_xz")
_PAIRS = ((0, 0), (1, 1), (2, 2), (0, 1), (1, 2), (0, 2))
_RANK_RTOL = 1e-8  # singular values of the relative Jacobian below this fraction are undetermined
_TOL = 1e-11  # relative step at convergence: eigh rounding moves a small object on a heavy fixture ~4e-14
# from exact periods; from noisy ones its steps stall higher (below). So, with the periods' sigmas given, a
# last step that moves the tensor by less than this many of its standard deviations (its chi^2 decrement
# below the square) has converged too: past it the steps are the periods' rounding.
# A 0.25 kg object on the 2 kg trifilar disc (validate's tensor-tare) converged in two steps to a relative
# step of 4e-10 and then stalled at 4e-11..2e-10, each step lowering chi^2 by 7e-14..1.4e-12 (1e-6 of a
# sigma), in 0-4 of the case's 200 fits as rounding moved its periods by 1e-13 (tests/test_tensor.py)
_SIGMA_STEP = 1e-5
_ITERATIONS = 50
_HALVINGS = 40  # a Gauss-Newton step is halved at most this often to find a trial the objective accepts
# A yaw is told from the other modes when no other mode turns about the vertical with more than this
# share of the yaw's own angular velocity there (per unit kinetic energy, squared): above it a record
# of "the yaw" may be either mode, and the period does not say which moment it measures.
_DISTINCT_SHARE = 0.25


@dataclass(frozen=True)
class Hanging:
    """One rig as hung (its wires, the mass and COM of what hangs), the object in it turned by
    ``orientation`` Q (object axes -> rig body axes), its fixed part ``held`` (3x3 about the rig's COM,
    rig body axes, kg m^2; zero for an object hung alone), the measured small-amplitude yaw period (s)
    and its standard deviation (s; 0: not stated), and ``tare``, the index of the fixture moment
    (:class:`Tare`) it shares with other hangings, or None."""

    rig: Rig
    period: float
    sigma: float = 0.0
    orientation: np.ndarray = field(default_factory=lambda: np.eye(3))
    held: np.ndarray = field(default_factory=lambda: np.zeros((3, 3)))
    tare: int | None = None
    name: str = ""

    @property
    def label(self) -> str:
        return self.name or self.rig.source


@dataclass(frozen=True)
class Tare:
    """A fixture's moment measured once: about body ``axis`` (unit, the fixture's vertical at rest,
    rig body frame) with standard deviation ``std`` (kg m^2), held in every hanging that names it."""

    axis: np.ndarray
    std: float


@dataclass(frozen=True)
class Tensor:
    inertia: np.ndarray  # 3 x 3, about the object's COM, object axes, kg m^2
    covariance: np.ndarray | None  # 6 x 6 over COMPONENTS, (kg m^2)^2; None if no period sigma is stated
    model: np.ndarray  # the model's yaw period per hanging at the solution, s
    residual_sigmas: np.ndarray | None  # (measured - model) / its sigma (tares included), per hanging
    chi2_per_dof: float | None  # with more than six hangings and stated sigmas

    @property
    def std(self) -> np.ndarray | None:
        """3 x 3 standard deviations of the components (kg m^2)."""
        return None if self.covariance is None else tensor_of(np.sqrt(np.diag(self.covariance)))

    def principal(self):
        """(moments ascending, axes as columns in object axes, moments' std or None): the std to
        first order, d lambda_k = u_k^T dX u_k."""
        moments, axes = np.linalg.eigh(self.inertia)
        if self.covariance is None:
            return moments, axes, None
        g = np.array([moment_row(u) for u in axes.T])
        return moments, axes, np.sqrt(np.einsum("ki,ij,kj->k", g, self.covariance, g))


def tensor_of(x: np.ndarray) -> np.ndarray:
    """The symmetric 3x3 tensor of the six components (COMPONENTS order)."""
    return np.array([[x[0], x[3], x[5]], [x[3], x[1], x[4]], [x[5], x[4], x[2]]])


def moment_row(u: np.ndarray) -> np.ndarray:
    """a with a . x = u^T X u for the six components x of X (COMPONENTS order; products count twice):
    the moment about ``u`` (a unit vector, object axes) is linear in the components."""
    return np.array([(1.0 if a == b else 2.0) * u[a] * u[b] for a, b in _PAIRS])


def components_of(t: np.ndarray) -> np.ndarray:
    """The six components (COMPONENTS order) of a symmetric 3x3 tensor."""
    return np.array([t[a, b] for a, b in _PAIRS])


_LINEARISED: dict[int, tuple[weakref.ref, object]] = {}


def _linearised(rig: Rig, guess=None):
    """:func:`linearize` of ``rig``, once per rig object (its entry goes with the object): a Monte Carlo
    over the periods, or a tare's draws, refits the same hangings' rigs many times, and a trifilar's
    rest pose alone takes 14 starts (the tensor-tare case: 1475 rest poses, 362 of its 367 s). With
    ``guess`` (the rest pose of a nearby rig) the rest pose is continued from it (:func:`rest_pose`)."""
    hit = _LINEARISED.get(id(rig))
    if hit is not None and hit[0]() is rig:
        return hit[1]
    lin = linearize(rig, None if guess is None or has_wire_mass(rig) else rest_pose(rig, guess))
    _LINEARISED[id(rig)] = (weakref.ref(rig, lambda _, key=id(rig): _LINEARISED.pop(key, None)), lin)
    return lin


class Linear:
    """One hanging linearised once: its yaw period, d T / d components and d T / d (held moment
    about a rig axis) at any object tensor.

    ``like``: a rig that differs from the hanging's in its body's inertia alone, whose linearisation
    (rest pose and all) is used: the rest pose and the stiffness do not depend on the inertia, and the
    mass matrix depends on it linearly (its part is taken out below), so hangings that differ only by
    the object's turn about its COM share one rest-pose search (:func:`bifilar.identification.plan.candidates`).
    ``guess``: a nearby rig's rest pose to continue from (:func:`_linearised`); ``rest``: the pose found.
    """

    def __init__(self, hanging: Hanging, like: Rig | None = None, guess=None):
        q = np.asarray(hanging.orientation, float)
        rig = hanging.rig if like is None else like
        lin = _linearised(rig, guess)
        self.label, self.rest = hanging.label, lin.rest
        self.k = lin.stiffness
        self.body = lin.partial_omega.T @ lin.rest.rotation  # (n x 3): rig-body angular velocity, transposed
        self.arm = self.body @ q  # (n x 3): object-frame angular velocity per speed, transposed
        self.m_held = lin.mass - self.body @ (rig.inertia - np.asarray(hanging.held, float)) @ self.body.T
        self.vertical = lin.partial_omega.T @ np.array([0.0, 0.0, 1.0])
        self.pendulum = lin.pendulum

    def solve(self, x: np.ndarray):
        """(T, v, index) of the yaw at components ``x``: v the M-normalised shapes of the oscillating
        modes; raises RigError when another mode turns about the vertical nearly as much."""
        w2, v = eigh(self.k, self.m_held + self.arm @ tensor_of(x) @ self.arm.T)
        keep = oscillating(w2, self.pendulum)
        w2, v = w2[keep], v[:, keep]
        share = (self.vertical @ v) ** 2
        order = np.argsort(share)[::-1]
        j = int(order[0])
        if len(order) > 1 and share[order[1]] > _DISTINCT_SHARE * share[j]:
            periods = 2.0 * np.pi / np.sqrt(w2[order[:2]])
            raise RigError(self.label, "orientation", f"the yaw cannot be told from another mode: the modes of "
                           f"{periods[0]:.6g} s and {periods[1]:.6g} s both turn about the vertical (shares "
                           f"1 : {share[order[1]] / share[j]:.2f}); hang the object so that one mode is the yaw")
        return 2.0 * np.pi / np.sqrt(w2[j]), v[:, j]

    def period(self, x: np.ndarray):
        """(T, d T / d components) of the yaw at components ``x``."""
        t, v = self.solve(x)
        shape = self.arm.T @ v  # object frame
        grad = moment_row(shape) * 0.5 * t
        return t, grad

    def held_slope(self, x: np.ndarray, axis: np.ndarray) -> float:
        """d T / d s for the held tensor changed by s e e^T (e ``axis``, rig body frame)."""
        t, v = self.solve(x)
        return 0.5 * t * float(axis @ (self.body.T @ v)) ** 2


def _undetermined(rel: np.ndarray) -> list[str]:
    """The components that the rows of ``rel`` leave (mostly) undetermined: the largest entries of the
    right singular vectors whose singular values are below the rank tolerance."""
    _, sv, vt = np.linalg.svd(rel)  # rel has at least 6 rows: six singular values
    null = vt[sv <= _RANK_RTOL * sv[0]]
    weight = np.sqrt((null ** 2).sum(axis=0))
    return [COMPONENTS[i] for i in range(6) if weight[i] > 0.3]


def identify_tensor(hangings: list[Hanging], start: np.ndarray, tares: tuple[Tare, ...] = (),
                    source: str = "hangings") -> Tensor:
    """The six components (object frame) from the hangings' periods, from the tensor ``start``
    (3x3, object axes). ``tares``: the fixture moments the hangings' ``tare`` indices name."""
    if len(hangings) < 6:
        raise RigError(source, "hanging", f"{len(hangings)} hangings cannot determine the 6 tensor components: "
                                          "give at least 6 orientations")
    models = [Linear(h) for h in hangings]
    measured = np.array([h.period for h in hangings])
    sigma = np.array([h.sigma for h in hangings])
    weighted = bool(np.all(sigma > 0.0))
    x = components_of(np.asarray(start, float))
    scale = float(np.trace(start) / 3.0)
    t, jac = _periods(models, x, source)
    for _ in range(_ITERATIONS):
        rel = jac * scale / measured[:, None]  # d ln T / d (X / scale)
        sv = np.linalg.svd(rel, compute_uv=False)
        if np.sum(sv > _RANK_RTOL * sv[0]) < 6:
            missing = ", ".join(_undetermined(rel))
            raise RigError(source, "hanging", f"the {len(hangings)} orientations leave {missing} undetermined (make "
                           "more distinct object axes vertical, some between the principal axes)")
        root = _whitener(models, hangings, tares, x, measured, sigma) if weighted else np.eye(len(hangings))
        step = np.linalg.lstsq(root @ rel, root @ ((measured - t) / measured), rcond=None)[0] * scale
        moved = root @ rel @ (step / scale)  # the step in the periods, in their sigmas where they are given
        if np.abs(step).max() < _TOL * scale or (weighted and moved @ moved < _SIGMA_STEP**2):  # converged
            x = x + step
            t, jac = _periods(models, x, source, final=True)
            break
        x, t, jac = _damped(models, x, t, step, root, measured, source)
    else:
        raise RigError(source, "hanging", "the tensor did not converge: the periods are not consistent with one body")
    inertia = tensor_of(x)
    moments = np.linalg.eigvalsh(inertia)
    if moments[0] <= 0.0:
        raise RigError(source, "hanging", f"the periods give a tensor that is not positive definite (principal "
                                          f"{moments})")
    if moments[0] + moments[1] < moments[2] * (1.0 - 1e-9):
        raise RigError(source, "hanging", f"the periods give a tensor breaking I1 + I2 >= I3 (principal {moments})")
    if not weighted:
        return Tensor(inertia, None, t, None, None)
    c = period_covariance(models, hangings, tares, x, sigma)
    ci = np.linalg.inv(c)
    covariance = np.linalg.inv(jac.T @ ci @ jac)
    r = measured - t
    dof = len(hangings) - 6
    chi2 = float(r @ ci @ r) / dof if dof > 0 else None
    return Tensor(inertia, covariance, t, r / np.sqrt(np.diag(c)), chi2)


def _periods(models: list[Linear], x: np.ndarray, source: str, final: bool = False):
    """(T, d T / d components) of every hanging at components ``x``. A yaw that cannot be told from another
    mode at the start or at the result (``final``) is the hangings file's problem: named there."""
    try:
        return _evaluate(models, x)
    except RigError as exc:
        where = "the result" if final else "the start"
        raise RigError(source, f"{exc.source}.{exc.field}", f"at {where}: {exc.problem}") from None


def _evaluate(models: list[Linear], x: np.ndarray):
    """(T, d T / d components) of every hanging at components ``x``, as :meth:`Linear.period` raises."""
    out = [m.period(x) for m in models]
    return np.array([o[0] for o in out]), np.array([o[1] for o in out])


def _damped(models: list[Linear], x: np.ndarray, t: np.ndarray, step: np.ndarray, root: np.ndarray,
            measured: np.ndarray, source: str):
    """(x, T, d T / d x) after the Gauss-Newton ``step``, halved until the trial is a tensor that holds every
    hanging's mass matrix positive definite, its yaw told from the other modes, and the weighted residual
    no larger (to rounding). Why: from a rough start (an isotropic guess 4x the true moments) the full step
    left the tensors a rig can have: the trial's eigen-solve failed, or its yaw mixed with a sway, a fault
    of the iterate and not of the data (issue 35 item 7). Refused if no trial in :data:`_HALVINGS` halvings."""
    def objective(periods):
        r = root @ ((measured - periods) / measured)
        return float(r @ r)

    current = objective(t)
    for _ in range(_HALVINGS):
        trial = x + step
        try:
            if np.linalg.eigvalsh(tensor_of(trial))[0] > 0.0:
                periods, jac = _evaluate(models, trial)
                if objective(periods) <= current * (1.0 + 1e-9):
                    return trial, periods, jac
        except (RigError, np.linalg.LinAlgError):
            pass
        step = 0.5 * step
    raise RigError(source, "hanging", "the tensor did not converge: no step from the last estimate lowers the "
                   "periods' misfit (the periods are not consistent with one body, or the start is too far)")


def period_covariance(models: list[Linear], hangings: list[Hanging], tares: tuple[Tare, ...], x: np.ndarray,
                      sigma: np.ndarray) -> np.ndarray:
    """C = diag(sigma^2) + D Sigma_s D^T (s^2): each period's own variance and the shared tares'."""
    c = np.diag(sigma ** 2)
    for k, tare in enumerate(tares):
        d = np.array([m.held_slope(x, tare.axis) if h.tare == k else 0.0 for m, h in zip(models, hangings)])
        c += tare.std ** 2 * np.outer(d, d)
    return c


def _whitener(models, hangings, tares, x, measured, sigma) -> np.ndarray:
    """L^-1 with L L^T the relative periods' covariance: the GLS weighting of the relative residuals."""
    c = period_covariance(models, hangings, tares, x, sigma) / np.outer(measured, measured)
    return np.linalg.inv(np.linalg.cholesky(c))
