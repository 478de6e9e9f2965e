"""A part's full inertia tensor from hangings on hinge rigs: a torsion rod in several orientations and,
for a moment the rod cannot reach, a compound pendulum (issue 38 item 4; docs/identification.md section 9).

BicycleParameters measures a fork or a frame this way: clamped to a torsion rod in three or four
orientations, and swung as a compound pendulum for the moment about an axis it cannot be clamped along.
Each hanging is a hinge rig (:mod:`bifilar.rig.hinge`) whose ``[body]`` is the part in its own axes
(mass; ``com`` in object axes; its ``inertia`` is not used), turned by the orientation Q (object axes ->
rig body axes): its COM at Q com, its tensor Q X Q^T. With e the rig's hinge axis (rig body frame), the
period measures the moment about the COM axis along it, which is one linear equation in the six
components x = (I_xx, I_yy, I_zz, I_xy, I_yz, I_xz) of X (about the COM, object axes):

    J_h = u^T X u = a_h . x,   u = Q^T e (object frame),   a_h = (u_x^2, u_y^2, u_z^2, 2 u_x u_y, 2 u_y u_z, 2 u_x u_z),

with J_h from the period by the exact 1-DOF law (:func:`bifilar.identification.hinge.moment_from_period`):
k T0^2 / (4 pi^2) on a rod, m g d T0^2 / (4 pi^2) - m d^2 on a pivot, T0 the period taken to zero
amplitude (a pivot's elliptic-integral law depends on the amplitude alone). The fit is linear; there is
nothing to iterate.

Errors: J = G p to first order in the inputs p: each hanging's period (its own), the rod's stiffness
(one value for every torsion hanging: a 1 % error in k moves every rod moment by 1 %, correlated), and
each pivot rig file's mass, COM (object axes) and pivot point (one measurement per file, shared by the
hangings naming it). The moments' covariance is C = G Sigma G^T, Sigma the inputs' variances. With every
period's sigma stated, C is positive definite and the fit is generalised least squares in C,
Cov x = (A^T C^-1 A)^-1 (six hangings: A^-1 C A^-T, the plain propagation); otherwise ordinary least
squares, its covariance P C P^T (P the pseudo-inverse), or none when no sigma is stated at all.

Known entries (``known = { I_xy = 0.0, ... }`` in the hangings file: a part symmetric about its x-z
plane, as BicycleParameters takes a frame) are held at their value (sigma 0) and the rest fitted, so
four hangings can give a symmetric part's four entries.

Refused in one line: orientations that leave entries undetermined (named), torsion hangings without a
rod stiffness, rig files that describe different objects, a wire rig among hinge rigs, records (give
the period: ``validate identify`` fits a hinge rig's records), and a result that is not a physical
tensor.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
from scipy.linalg import solve_triangular

from bifilar.motion.hinge import linear_period, moment_about_axis, period_ratio
from bifilar.rig import RigError
from bifilar.rig.checks import no_unknown, number, positive, read_toml, required, within
from bifilar.rig.hinge import HINGE_TABLES, HingeRig, hinge_from_dict
from bifilar.rig.ranges import RANGES

from .hangings import PERIOD_RANGE, Measured, orientation, period_sigma
from .hinge import moment_from_period, stiffness_from_period
from .plan import Candidate
from .tensor import COMPONENTS, Tensor, moment_row, tensor_of

__all__ = ["HingeHanging", "HingeSetup", "Rod", "fit_hinge_hangings", "hinge_candidates", "hinge_file",
           "identify_hinge_tensor", "read_hinge_hangings", "row"]

_KEYS = {"hanging", "name", "rod", "known"}
_HANGING_KEYS = {"rig", "orientation", "period", "period_std", "amplitude", "name"}
_ROD_KEYS = {"stiffness", "stiffness_std", "calibration", "period", "period_std", "amplitude"}
_RANK_RTOL = 1e-8  # singular values of the (dimensionless) rows below this fraction: undetermined
_SAME_MASS = 1e-3  # relative: rig files whose masses differ by more are not the same part
_SAME_COM = 1e-3  # x the pivots' largest arm: COMs (object axes) further apart are not the same part's
_PLACEHOLDER = 1e-2  # x mass, kg m^2: an isotropic stand-in for the rig file's inertia, which is not used


@dataclass(frozen=True)
class Rod:
    """The torsion rod's stiffness (N m/rad) and its sigma, shared by every torsion hanging, and where
    they came from (the ``[rod]`` table, a calibration, or the rig files)."""

    stiffness: float
    std: float
    source: str


@dataclass(frozen=True)
class HingeHanging:
    """One hinge rig as hung: the part turned by ``orientation`` Q (object axes -> rig body axes) in
    ``rig`` (COM at Q com, its stiffness the rod's), the period (s) timed at ``amplitude`` (rad), its
    sigma (s; 0: not stated) and ``group``, the rig file whose mass, COM and point sigmas it shares."""

    rig: HingeRig
    period: float
    sigma: float = 0.0
    orientation: np.ndarray = field(default_factory=lambda: np.eye(3))
    amplitude: float = 0.0
    name: str = ""
    group: str = ""
    tare = None  # as a wire hanging's: no fixture (the report's schema)

    @property
    def label(self) -> str:
        return self.name or self.rig.source


def row(axis: np.ndarray, q: np.ndarray) -> np.ndarray:
    """a with a . x = u^T X u, u = Q^T ``axis`` (rig body frame -> object frame); products count twice."""
    return moment_row(np.asarray(q, float).T @ axis)


def identify_hinge_tensor(hangings: list[HingeHanging], rod: Rod | None = None, known: dict | None = None,
                          source: str = "hangings") -> Tensor:
    """The six components (about the COM, object axes) from the hinge hangings' periods, with
    ``known`` (component index -> value, kg m^2) held; the module docstring gives the model and errors."""
    known = dict(known or {})
    free = [i for i in range(6) if i not in known]
    rows = np.array([row(h.rig.axis, h.orientation) for h in hangings])
    _check_rank(rows[:, free], free, len(hangings), source)
    moments, grads, sigma = _moments(hangings, rod, source)
    cov = grads @ np.diag(sigma ** 2) @ grads.T  # the moments' covariance, (kg m^2)^2
    fixed = np.array([known.get(i, 0.0) for i in range(6)])
    a, b = rows[:, free], moments - rows @ fixed
    weighted = all(h.sigma > 0.0 for h in hangings)
    if weighted:  # whitened by the Cholesky factor: C can be near rank one when the rod's sigma dominates
        lower = np.linalg.cholesky(cov)
        pinv = np.linalg.pinv(solve_triangular(lower, a, lower=True))
        solution = pinv @ solve_triangular(lower, b, lower=True)
        part = pinv @ pinv.T
    else:
        pinv = np.linalg.pinv(a)
        solution = pinv @ b
        part = pinv @ cov @ pinv.T if np.any(sigma > 0.0) else None
    x = fixed.copy()
    x[free] = solution
    inertia = tensor_of(x)
    principal = np.linalg.eigvalsh(inertia)
    if principal[0] <= 0.0:
        raise RigError(source, "hanging", f"the periods give a tensor that is not positive definite (principal {principal})")
    if principal[0] + principal[1] < principal[2] * (1.0 - 1e-9):
        raise RigError(source, "hanging", f"the periods give a tensor breaking I1 + I2 >= I3 (principal {principal})")
    model = np.array([_model_period(h, rod, float(r @ x)) for h, r in zip(hangings, rows)])
    if part is None:
        return Tensor(inertia, None, model, None, None)
    covariance = np.zeros((6, 6))
    covariance[np.ix_(free, free)] = part
    resid = moments - rows @ x
    dof = len(hangings) - len(free)
    chi2 = None
    if weighted and dof > 0:
        white = solve_triangular(lower, resid, lower=True)
        chi2 = float(white @ white) / dof
    spread = np.sqrt(np.diag(cov))
    return Tensor(inertia, covariance, model, resid / spread if np.all(spread > 0.0) else None, chi2)


def hinge_candidates(rig: HingeRig, inertia: np.ndarray, sigma: float, orientations):
    """(candidates, names skipped with the reason: none) for ``validate plan`` on a torsion rod: the part
    (``rig``'s [body] in object axes, expected tensor ``inertia``) turned by each Q, its period
    T = 2 pi sqrt(J / k) and d T / d x = T a / (2 J) (a the hanging's :func:`row`, J = a . x), for
    :func:`bifilar.identification.plan.plan`. The rod's stiffness error scales every moment alike whatever
    the orientations: no plan lowers it, so the plan weighs the periods' sigma alone."""
    usable = []
    for name, q in orientations:
        turned = replace(rig, com=q @ rig.com, inertia=q @ inertia @ q.T)
        t = linear_period(turned)
        usable.append(Candidate(name, q, t * row(rig.axis, q) / (2.0 * moment_about_axis(turned)), t, sigma))
    return usable, []


def _check_rank(a: np.ndarray, free: list[int], n: int, source: str) -> None:
    """Refuse rows that leave a free component undetermined, naming those (the largest entries of the
    null space's right singular vectors)."""
    _, sv, vt = np.linalg.svd(a)
    rank = int(np.sum(sv > _RANK_RTOL * sv[0])) if sv.size else 0
    if rank == len(free):
        return
    null = vt[rank:]
    weight = np.sqrt((null ** 2).sum(axis=0))
    missing = ", ".join(COMPONENTS[free[i]] for i in range(len(free)) if weight[i] > 0.3)
    raise RigError(source, "hanging", f"the {n} orientations leave {missing} undetermined (turn the part so that "
                   "more distinct axes, some between its principal axes, lie along the rod or hinge, or give known "
                   "entries)")


def _moments(hangings: list[HingeHanging], rod: Rod | None, source: str):
    """(J per hanging, d J / d inputs (n x p), the inputs' sigmas (p)): the inputs are each period, the
    rod's stiffness, and each rig file's mass, COM (3, object axes) and pivot point (3, rig body frame)."""
    groups = sorted({h.group for h in hangings if h.rig.kind == "pivot"})
    n, width = len(hangings), len(hangings) + 1 + 7 * len(groups)
    moments, grads, sigma = np.zeros(n), np.zeros((n, width)), np.zeros(width)
    if rod is not None:
        sigma[n] = rod.std
    for k, h in enumerate(hangings):
        rig = replace(h.rig, uncertainty=replace(h.rig.uncertainty, period=h.sigma))
        if rig.kind == "torsion":
            if rod is None:
                raise RigError(source, "rod", f"missing: {h.label} is on a torsion rod, whose stiffness is not given "
                               "([rod] stiffness and stiffness_std, or calibration, or torsion.stiffness in the rig)")
            rig = replace(rig, stiffness=rod.stiffness)
        m = moment_from_period(rig, h.period, h.amplitude)
        moments[k] = m.moment
        grads[k, k] = m.gradient["period"]
        sigma[k] = h.sigma
        grads[k, n] = m.gradient["stiffness"]
        if rig.kind == "pivot":
            at = n + 1 + 7 * groups.index(h.group)
            grads[k, at] = m.gradient["mass"]
            grads[k, at + 1:at + 4] = h.orientation.T @ m.gradient["com"]  # d J / d com, object axes
            grads[k, at + 4:at + 7] = m.gradient["point"]
            unc = rig.uncertainty
            sigma[at], sigma[at + 1:at + 4], sigma[at + 4:at + 7] = unc.mass, unc.com, unc.point
    return moments, grads, sigma


def _model_period(h: HingeHanging, rod: Rod | None, moment: float) -> float:
    """The period (s) at the hanging's amplitude of the fitted moment ``moment`` about its axis."""
    ratio = period_ratio(h.rig.kind, h.amplitude, h.rig.source)
    if h.rig.kind == "torsion":
        return 2.0 * math.pi * math.sqrt(moment / rod.stiffness) * ratio
    m, d = h.rig.mass, h.rig.arm
    return 2.0 * math.pi * math.sqrt((moment + m * d * d) / (m * h.rig.gravity * d)) * ratio


@dataclass
class HingeSetup:
    """A hinge hangings file as read: what the fit needs and what the report says (the fields of
    :class:`bifilar.identification.hangings.Setup` the report reads, and the rod and known entries)."""

    hangings: list[HingeHanging]
    measured: list[Measured]
    rod: Rod | None
    known: dict
    mass: float
    com: np.ndarray
    fixtures: list = field(default_factory=list)
    flags: list[str] = field(default_factory=list)

    @property
    def unknowns(self) -> int:
        return 6 - len(self.known)


def hinge_file(path: str | Path) -> bool:
    """Whether any hanging's rig in the hangings file is a hinge rig (``[pivot]`` or ``[torsion]``): such a
    file is read by :func:`read_hinge_hangings`, which refuses a wire rig among them. A file or rig that
    cannot be read says so when read as a wire hangings file."""
    data = read_toml(path)
    raw = data.get("hanging")
    if not isinstance(raw, list):
        return False
    rigs = [Path(path).parent / h["rig"] for h in raw if isinstance(h, dict) and isinstance(h.get("rig"), str)]
    return any(r.is_file() and any(t in read_toml(r) for t in HINGE_TABLES) for r in rigs)


def read_hinge_hangings(path: str | Path) -> HingeSetup:
    """Read a hinge hangings file (module docstring; docs/identification.md section 9); every problem is
    a one-line :class:`RigError` naming the file and the field."""
    src, folder = str(path), Path(path).parent
    data = read_toml(path)
    no_unknown(data, _KEYS, src, "")
    raw = data.get("hanging")
    if not isinstance(raw, list) or not raw or not all(isinstance(h, dict) for h in raw):
        raise RigError(src, "hanging", "missing: give the hangings as [[hanging]] tables")
    known = _known(data.get("known", {}), src)
    hangings = [_hanging(h, i, src, folder) for i, h in enumerate(raw, start=1)]
    mass, com = _same_part(hangings, src)
    rod = _rod(data.get("rod"), hangings, src, folder)
    measured = [Measured(h.period, h.sigma, "period" if h.amplitude == 0.0 else f"period at {h.amplitude:g} rad")
                for h in hangings]
    flags = [] if rod is None or rod.std > 0.0 else ["the rod's stiffness has no sigma: the tensor's leaves it out"]
    return HingeSetup(hangings, measured, rod, known, mass, com, flags=flags)


def fit_hinge_hangings(setup: HingeSetup, source: str) -> Tensor:
    """The part's tensor from a read :class:`HingeSetup`."""
    return identify_hinge_tensor(setup.hangings, setup.rod, setup.known, source)


def _known(value, src: str) -> dict:
    """``known = { I_xy = 0.0, ... }``: component index -> value (kg m^2)."""
    if not isinstance(value, dict):
        raise RigError(src, "known", "must be a table of components, e.g. { I_xy = 0.0, I_yz = 0.0 }")
    no_unknown(value, set(COMPONENTS), src, "known.")
    return {COMPONENTS.index(k): number(v, src, f"known.{k}") for k, v in value.items()}


def _hanging(h: dict, i: int, src: str, folder: Path) -> HingeHanging:
    prefix = f"hanging[{i}]."
    if "signal" in h:
        raise RigError(src, prefix + "signal", "records are not taken on hinge hangings: give period (s); "
                       "`validate identify RIG --signal ...` fits a hinge rig's records into one")
    no_unknown(h, _HANGING_KEYS, src, prefix)
    name = required(h, "rig", src, prefix)
    if not isinstance(name, str) or not name:
        raise RigError(src, prefix + "rig", "must be a file name (a string, relative to the hangings file)")
    rig_path = folder / name
    rig_data = read_toml(rig_path)
    if not any(t in rig_data for t in HINGE_TABLES):
        raise RigError(src, prefix + "rig", f"{rig_path} is not a hinge rig ([pivot] or [torsion]): a hangings file "
                       "takes wire rigs or hinge rigs, not both")
    q = orientation(h.get("orientation"), src, prefix + "orientation")
    body = dict(rig_data.get("body") or {}) if isinstance(rig_data.get("body"), dict) else {}
    if isinstance(body.get("mass"), (int, float)):  # the file's inertia is not used: a stand-in checks nothing
        body.pop("cylinder", None)
        body["inertia"] = [_PLACEHOLDER * float(body["mass"])] * 3
    rig = hinge_from_dict({**rig_data, "body": body}, str(rig_path), rig_path.stem)
    rig = replace(rig, com=q @ rig.com)  # the part turned: its COM in the rig's body frame
    period = within(positive(required(h, "period", src, prefix), src, prefix + "period"), *PERIOD_RANGE, src,
                    prefix + "period", "s", "a measured period, from a millisecond to a day")
    sigma = (period_sigma(h["period_std"], src, prefix + "period_std", period) if "period_std" in h
             else rig.uncertainty.period)
    amplitude = positive(h["amplitude"], src, prefix + "amplitude") if "amplitude" in h else 0.0
    if amplitude > 0.5 * math.pi:
        raise RigError(src, prefix + "amplitude", f"{amplitude:g} rad is past pi/2: is it in degrees?")
    label = h.get("name", f"hanging[{i}]")
    if not isinstance(label, str):
        raise RigError(src, prefix + "name", "must be a string")
    return HingeHanging(rig, period, sigma, q, amplitude, label, str(rig_path.resolve()))


def _same_part(hangings: list[HingeHanging], src: str) -> tuple[float, np.ndarray]:
    """The part's mass and COM (object axes), the same in every rig file."""
    first = hangings[0]
    com0 = first.orientation.T @ first.rig.com
    size = max([h.rig.arm for h in hangings if h.rig.kind == "pivot"], default=0.0)  # m: the COM matters there
    for k, h in enumerate(hangings[1:], start=2):
        if abs(h.rig.mass - first.rig.mass) > _SAME_MASS * first.rig.mass:
            raise RigError(src, f"hanging[{k}].rig", f"{h.rig.source} holds {h.rig.mass:g} kg, {first.rig.source} "
                           f"{first.rig.mass:g} kg: the hangings must hold the same part")
        com = h.orientation.T @ h.rig.com
        if h.rig.kind == "pivot" and first.rig.kind == "pivot" and np.abs(com - com0).max() > _SAME_COM * size:
            raise RigError(src, f"hanging[{k}].rig", f"the part's COM (object axes) is {com.tolist()} m there and "
                           f"{com0.tolist()} m in {first.rig.source}: the same part has one COM")
    return first.rig.mass, com0


def _rod(value, hangings: list[HingeHanging], src: str, folder: Path) -> Rod | None:
    """The rod's stiffness and sigma: the ``[rod]`` table (``stiffness`` and ``stiffness_std``, or
    ``calibration`` = a calibration rod's rig file with its ``period``), else the torsion rigs' own
    ``torsion.stiffness`` and ``[uncertainty].stiffness`` (one rod: every file must state the same)."""
    if value is not None:
        if not isinstance(value, dict):
            raise RigError(src, "rod", "must be a table: stiffness and stiffness_std, or calibration and period")
        no_unknown(value, _ROD_KEYS, src, "rod.")
        if "calibration" in value:
            return _calibrated(value, src, folder)
        for key in ("period", "period_std", "amplitude"):
            if key in value:
                raise RigError(src, f"rod.{key}", "goes with rod.calibration (a calibration rod's period)")
        k = positive(required(value, "stiffness", src, "rod."), src, "rod.stiffness")
        low, high, unit, why = RANGES["torsion.stiffness"]
        within(k, low, high, src, "rod.stiffness", unit, why)
        std = float(value.get("stiffness_std", 0.0))
        if not 0.0 <= std <= 0.5 * k:
            raise RigError(src, "rod.stiffness_std", f"{std:g} N m/rad must be between 0 and half the stiffness")
        return Rod(k, std, f"{src} [rod]")
    rods = [h for h in hangings if h.rig.kind == "torsion"]
    if not rods:
        return None
    stated = {(h.rig.stiffness, h.rig.uncertainty.stiffness) for h in rods}
    if any(k is None for k, _ in stated):
        bare = next(h for h in rods if h.rig.stiffness is None)
        raise RigError(src, "rod", f"missing: {bare.rig.source} has no torsion.stiffness; give the rod's stiffness "
                       "once as [rod] stiffness and stiffness_std (or calibration and period)")
    if len(stated) > 1:
        raise RigError(src, "rod", "the torsion rigs state different stiffnesses or sigmas: one rod has one; give "
                       "it once as [rod] stiffness and stiffness_std")
    k, std = stated.pop()
    return Rod(k, std, f"torsion.stiffness of {rods[0].rig.source}")


def _calibrated(value: dict, src: str, folder: Path) -> Rod:
    """The rod's stiffness from a calibration rod's rig file and its timed period (``validate calibrate``)."""
    name = value["calibration"]
    if not isinstance(name, str) or not name:
        raise RigError(src, "rod.calibration", "must be a calibration rod's rig file (relative to this file)")
    path = folder / name
    rig = hinge_from_dict(read_toml(path), str(path), path.stem)
    period = within(positive(required(value, "period", src, "rod."), src, "rod.period"), *PERIOD_RANGE, src,
                    "rod.period", "s", "a measured period, from a millisecond to a day")
    if "period_std" in value:
        sigma = period_sigma(value["period_std"], src, "rod.period_std", period)
        rig = replace(rig, uncertainty=replace(rig.uncertainty, period=sigma))
    amplitude = positive(value["amplitude"], src, "rod.amplitude") if "amplitude" in value else 0.0
    found = stiffness_from_period(rig, period, amplitude)
    return Rod(found.stiffness, found.std, f"calibration {path}")
