"""The full inertia tensor of one body from its periods in several hangings (issue 11, item 5).

Each hanging is a rig (e.g. a trifilar platform) holding the object mounted in a known orientation Q
(object axes -> the rig's body axes), so that at rest a different object axis is vertical, with the
measured period of the mode that turns about the vertical (yaw, the largest kinetic share of rotation
about world z). The rig's inertia is that of the object turned, Q I Q^T (a platform's own tare is
subtracted beforehand, or included in the rig and held fixed: only the object's part is unknown). The six components
I = (I_xx, I_yy, I_zz, I_xy, I_yz, I_xz) follow by Gauss-Newton on the exact linearisation.

Exact and cheap: the rest pose and the stiffness K of :func:`bifilar.motion.modes.linearize` do not
depend on the inertia, and the reduced mass matrix is linear in it, M(I) = M_0 + A I A^T, A = G^T R Q (G
the angular velocity per independent speed, R the rest rotation). For K v = w2 M v with v^T M v = 1,
Hellmann-Feynman gives d w2 = -w2 v^T dM v, so with the mode's body-frame rotation shape
W = A^T v = Q^T R^T G v,

    d ln T / dI_ab = (1/2) W_a W_b   (each product of inertia counts twice).

The covariance of the six components is (A^T S^-1 A)^-1, A the Jacobian of the periods and S the
period variances: the linearisation of the exact inversion. Refused (one line) when the orientations
cannot determine all six components (the Jacobian's rank is below 6), and when the result is not a
physical tensor (not positive definite, or breaking the triangle inequality).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.linalg import eigh

from bifilar.motion.modes import NEUTRAL_RTOL, linearize
from bifilar.rig import Rig, RigError

COMPONENTS = ("I_xx", "I_yy", "I_zz", "I_xy", "I_yz", "I_xz")
_PAIRS = ((0, 0), (1, 1), (2, 2), (0, 1), (1, 2), (0, 2))
_RANK_RTOL = 1e-8  # singular values of the relative Jacobian below this fraction are undetermined
_TOL = 1e-14  # relative step at convergence
_ITERATIONS = 50


@dataclass(frozen=True)
class Hanging:
    """One rig holding the object in orientation ``orientation`` (object axes -> rig body axes), with
    the measured yaw period (s) and its standard deviation (s)."""

    rig: Rig
    period: float
    sigma: float = 0.0
    orientation: np.ndarray = field(default_factory=lambda: np.eye(3))


@dataclass(frozen=True)
class Tensor:
    inertia: np.ndarray  # 3 x 3, about the COM, body axes, kg m^2
    covariance: np.ndarray  # 6 x 6 over COMPONENTS, (kg m^2)^2 (zero if every sigma is zero)
    residuals: np.ndarray  # model minus measured period per hanging, s


def _tensor(x: np.ndarray) -> np.ndarray:
    return np.array([[x[0], x[3], x[5]], [x[3], x[1], x[4]], [x[5], x[4], x[2]]])


class _Linear:
    """One hanging linearised once: period and d T / d components at any tensor."""

    def __init__(self, hanging: Hanging):
        rig, q = hanging.rig, np.asarray(hanging.orientation, float)
        lin = linearize(rig)
        self.k, self.g, self.rot = lin.stiffness, lin.partial_omega, lin.rest.rotation
        arm = self.g.T @ self.rot @ q  # (n x 3): object-frame angular velocity per speed, transposed
        self.arm = arm
        self.m0 = lin.mass - arm @ (q.T @ rig.inertia @ q) @ arm.T
        self.vertical = self.g.T @ np.array([0.0, 0.0, 1.0])

    def period(self, x: np.ndarray):
        w2, v = eigh(self.k, self.m0 + self.arm @ _tensor(x) @ self.arm.T)
        keep = w2 > NEUTRAL_RTOL * max(abs(w2).max(), 1e-300)
        w2, v = w2[keep], v[:, keep]
        j = int(np.argmax((self.vertical @ v) ** 2))
        t = 2.0 * np.pi / np.sqrt(w2[j])
        shape = self.arm.T @ v[:, j]  # object frame
        grad = np.array([(1.0 if a == b else 2.0) * shape[a] * shape[b] for a, b in _PAIRS]) * 0.5 * t
        return t, grad


def identify_tensor(hangings: list[Hanging], source: str = "hangings") -> Tensor:
    """The six components (object frame) from the hangings' periods, starting from the first rig's
    tensor turned back to the object frame."""
    if len(hangings) < 6:
        raise RigError(source, "hangings", f"{len(hangings)} hangings cannot determine 6 tensor components")
    first = hangings[0].rig
    for h in hangings[1:]:
        if h.rig.mass != first.mass:
            raise RigError(h.rig.source, "body.mass", "is not the mass of the other hangings: not the same object")
    models = [_Linear(h) for h in hangings]
    measured = np.array([h.period for h in hangings])
    q0 = np.asarray(hangings[0].orientation, float)
    x = np.array([(q0.T @ first.inertia @ q0)[a, b] for a, b in _PAIRS])
    scale = float(np.trace(first.inertia) / 3.0)
    for _ in range(_ITERATIONS):
        out = [m.period(x) for m in models]
        t = np.array([o[0] for o in out])
        jac = np.array([o[1] for o in out])
        rel = jac * scale / measured[:, None]  # d ln T / d (I / scale)
        sv = np.linalg.svd(rel, compute_uv=False)
        rank = int(np.sum(sv > _RANK_RTOL * sv[0]))
        if rank < 6:
            raise RigError(source, "hangings", f"the {len(hangings)} orientations determine only {rank} of the 6 "
                           "tensor components (make more distinct body axes vertical, some between the principal axes)")
        step = np.linalg.lstsq(rel, (measured - t) / measured, rcond=None)[0] * scale
        x = x + step
        if np.abs(step).max() < _TOL * scale:
            break
    else:
        raise RigError(source, "hangings", "the tensor did not converge: the periods are not consistent with one body")
    inertia = _tensor(x)
    moments = np.linalg.eigvalsh(inertia)
    if moments[0] <= 0.0:
        raise RigError(source, "hangings", f"the periods give a tensor that is not positive definite (principal {moments})")
    if moments[0] + moments[1] < moments[2] * (1.0 - 1e-9):
        raise RigError(source, "hangings", f"the periods give a tensor breaking I1 + I2 >= I3 (principal {moments})")
    out = [m.period(x) for m in models]
    jac = np.array([o[1] for o in out])
    sigma = np.array([h.sigma for h in hangings])
    if np.all(sigma > 0.0):
        covariance = np.linalg.inv(jac.T @ (jac / sigma[:, None] ** 2))
    else:
        covariance = np.zeros((6, 6))
    return Tensor(inertia, covariance, np.array([o[0] for o in out]) - measured)
