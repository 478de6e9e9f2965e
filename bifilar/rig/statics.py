"""Engine-neutral statics of a rig: its rest pose, static wire tensions and initial state.

A pose is the COM position ``com`` (world frame, m) and the rotation matrix ``rotation`` (body frame to
world frame). Both engines start from :func:`initial_state`, so that they integrate the same motion:

1. the rest pose: the minimum of the potential ``m g z_com`` with every wire at its length (SLSQP from
   the file's orientation, the way the body hangs and more starts, a start that fails again with the
   wires free to slacken: the lowest equilibrium found), polished by Newton's method on the equilibrium
   equations (force and moment balance, wire lengths), whose unknowns include the tensions;
2. the body rotated about its COM by ``rig.initial_rotation`` (rotation vector, world frame);
3. the COM moved by the shortest displacement that makes every wire exactly its length (two wires:
   the nearest point of a circle; three: the nearer of two points; more: minimum-norm Gauss-Newton,
   see :func:`taut_shift`), refused in one line if there is none;
4. angular velocity ``rig.initial_omega`` (world frame) and the smallest COM velocity that keeps every
   wire length constant, refused if no COM velocity does (four or more wires and a spin that would
   stretch one).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from scipy.optimize import least_squares, minimize
from scipy.spatial.transform import Rotation

from bifilar.rig import Rig, RigError, elastic, so3
from bifilar.rig.pose_loops import PK  # the pose kernels, compiled only where they loop (bifilar.jit)

# Newton on the equilibrium equations converges quadratically: 30 iterations is ample from any start
# SLSQP hands it; a residual of 1e-12 (forces / weight, lengths / rig size) is machine precision on
# ordinary rigs and ~1e-13 of the weight where a Jacobian is nearly singular.
NEWTON_ITERATIONS = 30
RESIDUAL = 1e-12
# Constraint rows whose singular value is below this fraction of the largest are dependent.
NULL_RTOL = 1e-9
# A body frame turned more than this (rad) from the way the body hangs gets a second SLSQP start: from
# the file's orientation SLSQP settled 126 deg away in a twisted equilibrium on a trifilar whose
# hanging orientation is only 16 deg off, so any visible difference earns the second start.
_FAR_START = np.radians(1.0)
# A wire this fraction of the rig size short of its length is slack: on 142 random rigs of 3-6 wires SLSQP
# ended active wires within 3e-11 of their lengths and slack ones 5e-5 or more short.
SLACK_GAP = 1e-8
# An omega^2 below -this fraction of the largest is a real instability, not rounding.
NEUTRAL_SLACK = 1e-9


@dataclass(frozen=True)
class State:
    """Rigid-body state: COM position and velocity (world, m and m/s), body->world rotation, and
    angular velocity (world, rad/s)."""

    com: np.ndarray
    rotation: np.ndarray
    velocity: np.ndarray
    omega: np.ndarray


@dataclass(frozen=True)
class Rest:
    """The rest pose and the static tension of each wire (N, positive when pulling)."""

    com: np.ndarray
    rotation: np.ndarray
    tensions: np.ndarray


def attachments(rig: Rig, com: np.ndarray, rotation: np.ndarray) -> np.ndarray:
    """World positions (..., n_wires, 3; m) of the attachment points for a pose, or for a stack of
    poses (com ..., 3 and rotation ..., 3, 3)."""
    arms = np.array([w.attach - rig.com for w in rig.wires])
    return np.asarray(com)[..., None, :] + np.einsum("...ij,wj->...wi", rotation, arms)


def anchors(rig: Rig) -> np.ndarray:
    """World positions (n_wires x 3, m) of the ceiling anchors."""
    return np.array([w.anchor for w in rig.wires])


def lengths(rig: Rig) -> np.ndarray:
    """Wire lengths (m)."""
    return np.array([w.length for w in rig.wires])


def length_errors(rig: Rig, com: np.ndarray, rotation: np.ndarray) -> np.ndarray:
    """Anchor-to-attachment distance minus wire length, per wire (m), for a pose or a stack of poses."""
    return np.linalg.norm(attachments(rig, com, rotation) - anchors(rig), axis=-1) - lengths(rig)


def _equilibrium_residual(x: np.ndarray, rig: Rig, rotation0: np.ndarray, scale: float) -> np.ndarray:
    """Force balance, moment balance about the COM and wire lengths, each made dimensionless."""
    n = len(rig.wires)
    com, rotation = x[:3], Rotation.from_rotvec(x[3:6]).as_matrix() @ rotation0
    tension = x[6 : 6 + n] * rig.mass * rig.gravity
    pts = attachments(rig, com, rotation)
    span = anchors(rig) - pts
    dist = np.linalg.norm(span, axis=1)
    pull = span / dist[:, None] * tension[:, None]
    force = pull.sum(axis=0) - np.array([0.0, 0.0, rig.mass * rig.gravity])
    moment = np.cross(pts - com, pull).sum(axis=0)
    weight = rig.mass * rig.gravity
    return np.concatenate([force / weight, moment / (weight * scale), (dist - lengths(rig)) / scale])


def rig_scale(rig: Rig) -> float:
    """A length (m) that makes the rig's equations dimensionless: its longest wire or anchor span."""
    return float(max(lengths(rig).max(), np.ptp(anchors(rig), axis=0).max(), 1e-3))


def arms(rig: Rig) -> np.ndarray:
    """Attachment points relative to the COM, body frame (n_wires x 3, m)."""
    return np.array([w.attach - rig.com for w in rig.wires])


def rest_pose(rig: Rig, guess: Rest | None = None) -> Rest:
    """The stable rest pose and static tensions, to machine precision.

    From ``guess`` (a rest pose of a nearby rig: continuation in a sweep) Newton's method alone
    finds it; otherwise, or if that fails, the minimum of the potential with every wire at its
    length (SLSQP) is polished by Newton's method on the equilibrium equations (force and moment
    balance, wire lengths, the tensions as unknowns; compiled, analytic Jacobian). The result is
    checked: every wire pulls and the pose is stable (no direction on the constraint manifold
    lowers the potential).

    Raises :class:`RigError` if no pose holds every wire taut (a wire would have to push) or the
    equilibrium found is not stable.

    Elastic wires (``axial_stiffness``): the lowest minimum of the potential energy, gravity plus the
    wires' strain energy (:mod:`bifilar.rig.elastic`), from ``guess``, the inextensible rest pose of
    the same wires where that is determinate, and the starts of the inextensible search.
    """
    if rig.elastic:
        return _elastic_rest_pose(rig, guess)
    if guess is not None:
        rest = _polish(rig, guess.com, guess.rotation, guess.tensions)
        if rest is not None and _stable(rig, rest):
            # A neutral tilt (COM on the attachment line) leaves Newton anywhere along it: the same
            # representative as without a guess.
            return Rest(rest.com, _nearest_on_neutral_axis(rig, rest.com, rest.rotation), rest.tensions)
    return _remembered_rest_pose(rig)


_MEMO_SIZE = 64  # rest poses remembered per process (a few kB each)
_memo: dict = {}


def _remembered_rest_pose(rig: Rig) -> Rest:
    """:func:`_global_rest_pose`, remembered by what it depends on: the wires, the COM, the mass and
    gravity, not the inertia. A tensor fit or a tare hangs the same few rigs with many trial inertias
    (82 multi-start searches of 8 rigs in the tare case, ~70 ms each). The inertia enters only the
    stability check's neutral threshold, so a remembered pose is checked again for this rig (and
    searched afresh if it fails). Copies are returned: a caller may not change the remembered one."""
    key = (rig.mass, rig.gravity, rig.com.tobytes(),
           tuple((w.anchor.tobytes(), w.attach.tobytes(), w.length, w.linear_density) for w in rig.wires))
    rest = _memo.get(key)
    if rest is None or not _stable(rig, rest):
        rest = _global_rest_pose(rig)
        if len(_memo) >= _MEMO_SIZE:
            _memo.pop(next(iter(_memo)))  # the oldest
        _memo[key] = rest
    return Rest(rest.com.copy(), rest.rotation.copy(), rest.tensions.copy())


def _elastic_rest_pose(rig: Rig, guess: Rest | None) -> Rest:
    if guess is not None:  # continuation: Newton from the nearby rig's pose, else the full search
        try:
            com, rotation, tensions = _lowest_elastic(rig, [(guess.com, guess.rotation)])
            if tensions.min() > 0.0:
                return Rest(com=com, rotation=rotation, tensions=tensions)
        except RigError:
            pass
    starts = []
    if len(rig.wires) <= 3:
        # The inextensible pose, a stretch away from the elastic one: two or three wires only, where it is
        # determinate (three take the multi-start search too; on four parallel wires it fails on every
        # start: measured ~6 s per quadrifilar MuJoCo run, where its elastic rest pose is 8 ms).
        rigid = replace(rig, wires=tuple(replace(w, axial_stiffness=None) for w in rig.wires))
        try:
            rest = _remembered_rest_pose(rigid)
            starts.append((rest.com, rest.rotation))
        except (RigError, np.linalg.LinAlgError):
            pass
    hanging = _hanging_orientation(rig)
    for start in (np.eye(3), hanging):
        starts.append((_start_com(rig, start), start))
    try:
        com, rotation, tensions = _lowest_elastic(rig, starts)
    except RigError:  # no start converged: for four or more wires the turned starts below, else refused
        if len(rig.wires) < 4:
            raise
        tensions = np.zeros(len(rig.wires))
    if len(rig.wires) >= 4 and tensions.min() <= 0.0:
        # Four or more wires: these starts can end in a minimum with a wire slack while a taut one lies
        # elsewhere (issue 20's fuzzing); before refusing, the turned starts of _global_rest_pose. Only
        # then: each costs ~0.1 s (100-250 trust-region steps from a far orientation), and a rig whose
        # first starts hang taut keeps its 8 ms.
        turns = Rotation.random(MULTI_STARTS, random_state=_START_SEED).as_matrix()
        starts += [(_start_com(rig, turn @ hanging), turn @ hanging) for turn in turns]
        com, rotation, tensions = _lowest_elastic(rig, starts)
    slack = np.flatnonzero(tensions <= 0.0)
    if slack.size:
        i = int(slack[0])
        raise RigError(rig.source, f"wire[{i + 1}]", "would be slack at rest (shorter than its unstretched length): "
                       "the body cannot hang taut on every wire")
    return Rest(com=com, rotation=rotation, tensions=tensions)


def _lowest_elastic(rig: Rig, starts: list) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The lowest stable minimum on the elastic wires from ``starts``: (com, rotation, tensions)."""
    return elastic.rest_pose(rig, starts, arms(rig), anchors(rig), rig_scale(rig))


def _start_com(rig: Rig, rotation: np.ndarray) -> np.ndarray:
    """A COM for the body turned by ``rotation``: under the anchors' centroid by the mean wire length,
    then the shortest shift putting every wire at its length where there is one."""
    guess = anchors(rig).mean(axis=0) - np.array([0.0, 0.0, lengths(rig).mean()])
    guess = guess - rotation @ (np.array([w.attach for w in rig.wires]).mean(axis=0) - rig.com)
    try:
        return guess + taut_shift(rig, guess, rotation)
    except (RigError, np.linalg.LinAlgError):  # no taut pose at this orientation: the minimiser finds one
        return guess


def _polish(rig: Rig, com: np.ndarray, rotation: np.ndarray, tensions: np.ndarray) -> Rest | None:
    """Newton's method on the equilibrium equations from a pose and tensions; None if it fails."""
    weight = rig.mass * rig.gravity
    try:
        com, rotation, tensions, residual, _ = PK.newton_equilibrium(
            np.asarray(com, float), np.asarray(rotation, float), np.asarray(tensions, float),
            arms(rig), anchors(rig), lengths(rig), weight, rig_scale(rig), NEWTON_ITERATIONS,
        )
    except np.linalg.LinAlgError:  # a singular Jacobian: a neutral direction (see _global_rest_pose)
        return None
    if not residual <= RESIDUAL:
        return None
    return Rest(com=com, rotation=rotation, tensions=tensions)


def _stable(rig: Rig, rest: Rest) -> bool:
    """Every wire pulls and the stiffness on the constraint manifold has no negative direction."""
    if np.any(rest.tensions <= 0.0):
        return False
    z, mr, kr, _ = PK.reduced_matrices(
        rest.com, rest.rotation, rest.tensions, arms(rig), anchors(rig), rig.inertia, rig.mass,
        rig_scale(rig), NULL_RTOL,
    )
    if z.shape[1] == 0:
        return True
    chol = np.linalg.cholesky(mr)  # omega^2 are the eigenvalues of L^-1 K L^-T, M = L L^T
    w2 = np.linalg.eigvalsh(np.linalg.solve(chol, np.linalg.solve(chol, kr).T))
    return bool(w2.min() >= -NEUTRAL_SLACK * max(abs(w2).max(), 1e-300))


def _global_rest_pose(rig: Rig) -> Rest:
    """The rest pose without a guess: SLSQP on the potential from the file's orientation, then
    :func:`_polish`; and, where the body frame is turned from the way the body hangs (the
    orientation that best lays the attachments under their anchors, :func:`_hanging_orientation`),
    from that orientation too. Of the stable equilibria found the lowest (least potential) is the rest
    pose: from a far start SLSQP can settle in a higher, twisted equilibrium (wires crossed) that is
    stable too. Ties keep the file's orientation's.

    Three or more wires can have several taut equilibria far apart (a 3-wire body has three directions
    of freedom, a 4-wire one two, a 6-wire one none: its poses are isolated points), and one start
    stopped in a local minimum or failed (issue 20; a random trifilar of the property test sat 17 mm
    above its lowest pose). They get :data:`MULTI_STARTS` more starts: the hanging
    orientation without the COM's row, and that orientation turned by fixed rotations spread over the
    sphere; a start that fails in any way (no taut pose there, a singular matrix) is skipped, and the
    error of the first start is raised only if no start succeeds."""
    starts = [np.eye(3)]
    hanging = _hanging_orientation(rig)
    if Rotation.from_matrix(hanging).magnitude() > _FAR_START:
        starts.append(hanging)
    if len(rig.wires) >= 3:
        starts.append(_hanging_orientation(rig, with_com=False))
        turns = Rotation.random(MULTI_STARTS, random_state=_START_SEED).as_matrix()
        starts += [turn @ hanging for turn in turns]
    found, first_error, indeterminate, numerical = [], None, None, None
    retry = []  # the starts whose search with every wire at its length failed
    for start in starts:
        try:
            found.append(_search(rig, start))
        except Indeterminate as exc:  # the lowest of these, if below every pose found, is the answer
            if indeterminate is None or exc.height < indeterminate.height:
                indeterminate = exc
            first_error = first_error or exc
        except RigError as exc:
            first_error = first_error or exc
            retry.append(start)
        except (np.linalg.LinAlgError, ValueError, FloatingPointError) as exc:  # a start gone numerically wrong
            numerical = numerical or exc
            retry.append(start)
    # Wires held at their lengths can leave no room to descend (six: the poses are isolated points, SLSQP
    # only solves the length equations, to a solution near the start; on the random rig of seed 837 every
    # start ended with wire 1 pushing, the lowest pose taut). From a failed start the physical problem (wires
    # at most their lengths, tensions its multipliers, never negative) descends; the first search's reasons stand.
    for start in retry:
        try:
            found.append(_search(rig, start, may_slacken=True))
        except (RigError, np.linalg.LinAlgError, ValueError, FloatingPointError):
            pass
    if not found:
        # Every start failed: a stated reason (a slack wire, no taut pose) if one gave it, else the
        # numerical failure itself (exit 4, as any failure inside the physics).
        raise first_error or numerical
    lowest = min(r.com[2] for r in found)
    if indeterminate is not None and indeterminate.height < lowest - 1e-9 * rig_scale(rig):
        raise indeterminate  # e.g. four parallel wires: a higher, twisted pose is not the rest pose
    return next(r for r in found if r.com[2] <= lowest + 1e-9 * rig_scale(rig))


# Extra rest-pose starts for three or more wires, and the seed of their fixed, reproducible rotations.
MULTI_STARTS = 12
_START_SEED = 20


def _hanging_orientation(rig: Rig, with_com: bool = True) -> np.ndarray:
    """The rotation (body -> world) that best maps the attachments to points hanging straight under
    their anchors, each by its wire's length, and (``with_com``) the COM under their centroid by its
    body-frame distance from the attachments' centroid (Kabsch: the SVD of the points' cross-covariance)."""
    body = np.array([w.attach for w in rig.wires] + [rig.com])
    under = anchors(rig) - np.outer(lengths(rig), [0.0, 0.0, 1.0])
    drop = np.linalg.norm(rig.com - body[:-1].mean(axis=0))
    world = np.vstack([under, under.mean(axis=0) - [0.0, 0.0, drop]])
    if not with_com:
        body, world = body[:-1], world[:-1]
    u, _, vt = np.linalg.svd((world - world.mean(axis=0)).T @ (body - body.mean(axis=0)))
    d = np.sign(np.linalg.det(u @ vt)) or 1.0
    return u @ np.diag([1.0, 1.0, d]) @ vt


def _search(rig: Rig, start: np.ndarray, may_slacken: bool = False) -> Rest:
    """SLSQP on the potential from the body turned by ``start`` (body -> world), every wire at its length
    or (``may_slacken``) at most it, refused if one ends slack; then :func:`_polish` and the checks of
    :func:`rest_pose`."""
    scale = rig_scale(rig)
    # Start slightly turned: a symmetric start can be a stationary point that is not a minimum
    # (a body balanced upside down); the minimiser must see a gradient to roll off it.
    rotation0 = Rotation.from_rotvec([0.03, 0.02, 0.01]).as_matrix() @ start
    guess = anchors(rig).mean(axis=0) - np.array([0.0, 0.0, lengths(rig).mean()])
    guess = guess - (np.array([w.attach for w in rig.wires]).mean(axis=0) - rig.com)
    try:
        com0 = guess + taut_shift(rig, guess, rotation0)
    except RigError:  # no taut pose at this orientation: let the minimiser find a feasible one
        com0 = guess

    turned = np.einsum("ij,wj->wi", rotation0, arms(rig))  # the arms at rotvec 0 (world frame)
    ends, wire_length = anchors(rig), lengths(rig)
    height = np.array([0.0, 0.0, 1.0 / scale, 0.0, 0.0, 0.0])
    last: dict = {}  # SLSQP asks for the lengths and their slopes at the same x: one evaluation serves both

    def spans(x):
        """The arms turned by rotvec x[3:6] and the anchor-to-attachment vectors (world, m)."""
        key = x.tobytes()
        if last.get("x") != key:
            r = turned @ so3.rotation(x[3:6]).T
            last.update(x=key, spans=(r, x[:3] + r - ends))
        return last["spans"]

    def wire_lengths(x):
        s = spans(x)[1]
        return (np.sqrt(np.einsum("wi,wi->w", s, s)) - wire_length) / scale

    def wire_slopes(x):
        # d|s_i|/dx: the unit span u_i for the COM, and u_i . d(R r_i)/dv = u_i . (-[R r_i]x J_l(v))
        # = (R r_i x u_i) . J_l(v) for the rotation vector v (J_l its left Jacobian on SO(3)); the cross
        # products written out (np.cross's axis handling was a tenth of the search's time)
        r, s = spans(x)
        u = s / np.sqrt(np.einsum("wi,wi->w", s, s))[:, None]
        (rx, ry, rz), (ux, uy, uz) = r.T, u.T
        turn = np.column_stack((ry * uz - rz * uy, rz * ux - rx * uz, rx * uy - ry * ux))
        return np.hstack([u, turn @ so3.left_jacobian(x[3:6])]) / scale

    coarse = minimize(
        lambda x: x[2] / scale,
        np.concatenate([com0, np.zeros(3)]),
        jac=lambda x: height,
        method="SLSQP",
        constraints=[{"type": "ineq", "fun": lambda x: -wire_lengths(x), "jac": lambda x: -wire_slopes(x)}
                     if may_slacken else {"type": "eq", "fun": wire_lengths, "jac": wire_slopes}],
        options={"ftol": 1e-12, "maxiter": 500},
    )
    x = coarse.x
    if not np.all(np.isfinite(x)):  # SLSQP diverged from this start: nothing to polish (LAPACK prints on NaN)
        raise FloatingPointError("SLSQP diverged")
    if may_slacken and wire_lengths(x).min() < -SLACK_GAP:
        raise RigError(rig.source, "wire", "a wire is slack at the lowest pose reached from this start")
    rotation0 = Rotation.from_rotvec(x[3:6]).as_matrix() @ rotation0
    com = x[:3]
    # Tension guess from force balance alone, then Newton on the full equilibrium equations.
    span = anchors(rig) - attachments(rig, com, rotation0)
    dirs = span / np.linalg.norm(span, axis=1)[:, None]
    t0 = np.linalg.lstsq(dirs.T, np.array([0.0, 0.0, 1.0]), rcond=None)[0] * rig.mass * rig.gravity
    rest = _polish(rig, com, rotation0, t0)
    if rest is None:
        # A singular equilibrium Jacobian (a COM on the line of two attachments: a neutral tilt)
        # defeats plain Newton; Levenberg-Marquardt still converges there.
        sol = least_squares(_equilibrium_residual, np.concatenate([com, np.zeros(3), t0 / (rig.mass * rig.gravity)]),
                            args=(rig, rotation0, scale), method="lm", xtol=1e-15, ftol=1e-15, gtol=1e-15)
        residual = float(np.abs(sol.fun).max())
        # Dimensionless (forces / weight, lengths / rig size); 1e-16 on ordinary rigs, ~1e-9 where
        # the Jacobian is singular (a COM on CD between vertical wires: two neutral directions).
        if residual > 1e-7:
            raise RigError(rig.source, "wire", f"no equilibrium with every wire taut (residual {residual:.2e})")
        rotation = Rotation.from_rotvec(sol.x[3:6]).as_matrix() @ rotation0
        rest = Rest(com=sol.x[:3].copy(), rotation=rotation, tensions=sol.x[6:] * rig.mass * rig.gravity)
    check_determinate(rig, rest.com, rest.rotation)
    if (slack := np.flatnonzero(rest.tensions <= 0.0)).size:
        raise RigError(rig.source, f"wire[{slack[0] + 1}]", f"would be slack at rest (tension "
                       f"{rest.tensions[slack[0]]:.6g} N): the body cannot hang taut on every wire")
    rest = Rest(rest.com, _nearest_on_neutral_axis(rig, rest.com, rest.rotation), rest.tensions)
    if not _stable(rig, rest):
        raise RigError(rig.source, "wire", "the only equilibrium with every wire taut found is unstable: no rest pose")
    return rest


class Indeterminate(RigError):
    """Dependent wire constraints at a pose whose COM is ``height`` (m, world z) high."""

    def __init__(self, source: str, field_name: str, problem: str, height: float):
        super().__init__(source, field_name, problem)
        self.height = height


def check_determinate(rig: Rig, com: np.ndarray, rotation: np.ndarray) -> None:
    """Refuse wires whose constraints are dependent at this pose (four parallel wires, or more than
    six): the tensions of inextensible wires are then not fixed by rigid-body statics or dynamics
    (any self-balanced set can be added), and only the wires' stretch would share the load."""
    s, u, _ = PK.wire_geometry(np.asarray(com, float), np.asarray(rotation, float), arms(rig), anchors(rig))
    jac = PK.constraint_jacobian(s, u)
    jac[:, 3:] /= rig_scale(rig)
    sv = np.linalg.svd(jac, compute_uv=False)
    rank = int(np.sum(sv > NULL_RTOL * sv[0]))
    n = len(rig.wires)
    if rank < n:
        raise Indeterminate(
            rig.source, "wire",
            f"{n} wires but only {rank} independent wire constraints at rest: the tensions of inextensible "
            "wires are statically indeterminate (redundant wires share the load by their stretch, which "
            "this rig file has no stiffness for: give every wire an axial_stiffness)", float(com[2]),
        )


def _nearest_on_neutral_axis(rig: Rig, com: np.ndarray, rotation: np.ndarray) -> np.ndarray:
    """With the COM on the line through two attachments, the body tilts about that line at no cost
    and every tilt is a rest pose: take the one nearest the file's orientation (the identity).

    Turning by a about the unit axis n, tr(Rot(n, a) R) = tr R + a' sin a + c' (1 - cos a) with
    a' = tr(K R), c' = tr(K^2 R), K = [n]x; its maximum (the smallest turn from the identity) is at
    a = atan2(a', -c'). Other rigs are returned unchanged.
    """
    if len(rig.wires) != 2:
        return rotation
    pts = attachments(rig, com, rotation)
    axis = pts[1] - pts[0]
    axis /= np.linalg.norm(axis)
    offset = (com - pts[0]) - ((com - pts[0]) @ axis) * axis
    if np.linalg.norm(offset) > 1e-12 * max(lengths(rig).max(), 1.0):
        return rotation
    K = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    angle = np.arctan2(np.trace(K @ rotation), -np.trace(K @ K @ rotation))
    return Rotation.from_rotvec(angle * axis).as_matrix() @ rotation


def taut_shift(rig: Rig, com: np.ndarray, rotation: np.ndarray) -> np.ndarray:
    """The shortest COM displacement (world, m) that puts every wire at its length.

    Each wire confines the displaced COM to a sphere. Two spheres meet in a circle: the answer is
    its point nearest the current COM. Three spheres meet in two points (trilateration): the nearer.
    Otherwise (four or more wires, or three whose sphere centres are nearly collinear, e.g. parallel
    equal wires at rest, where the spheres coincide) Gauss-Newton with minimum-norm steps from zero
    finds the nearest common point, which must hold every length to 1e-12 of the rig size.
    """
    centres = anchors(rig) - attachments(rig, com, rotation)  # sphere i: |d - centres_i| = L_i
    radii = lengths(rig)
    if len(rig.wires) == 2:
        return _two_sphere_point(rig, centres, radii)
    if len(rig.wires) == 3:
        point = _three_sphere_point(centres, radii)
        if point is not None:
            return point
    return _common_point(rig, centres, radii)


def _no_taut_pose(rig: Rig) -> RigError:
    return RigError(rig.source, "wire", "no taut pose for this orientation: the wires cannot all reach")


def _two_sphere_point(rig: Rig, centres: np.ndarray, radii: np.ndarray) -> np.ndarray:
    """The point nearest the origin of the circle where two spheres meet."""
    axis = centres[1] - centres[0]
    dist = float(np.linalg.norm(axis))
    if dist < 1e-12 * radii.max():
        # Parallel, equal wires: the spheres coincide; take the nearest point of the one sphere.
        if abs(radii[0] - radii[1]) > 1e-12 * radii.max():
            raise _no_taut_pose(rig)
        norm = float(np.linalg.norm(centres[0]))
        return centres[0] - radii[0] * centres[0] / norm if norm > 0.0 else np.array([0.0, 0.0, -radii[0]])
    axis /= dist
    along = (dist**2 + radii[0] ** 2 - radii[1] ** 2) / (2.0 * dist)
    radius2 = radii[0] ** 2 - along**2
    if radius2 < 0.0:
        raise _no_taut_pose(rig)
    centre = centres[0] + along * axis
    off = -centre - np.dot(-centre, axis) * axis
    norm = float(np.linalg.norm(off))
    if norm < 1e-12:  # every point of the circle is equally near: take any
        off = np.cross(axis, [1.0, 0.0, 0.0] if abs(axis[0]) < 0.9 else [0.0, 1.0, 0.0])
        norm = float(np.linalg.norm(off))
    return centre + np.sqrt(radius2) * off / norm


def _three_sphere_point(centres: np.ndarray, radii: np.ndarray) -> np.ndarray | None:
    """The nearer to the origin of the two points where three spheres meet; None when the centres
    are too nearly collinear for trilateration to be accurate (then :func:`_common_point` decides).

    In the frame e_x = (c2 - c1)/d, e_y in the plane of the centres, the points are
    c1 + x e_x + y e_y +- z e_z with x = (r1^2 - r2^2 + d^2)/(2 d),
    y = (r1^2 - r3^2 + i^2 + j^2)/(2 j) - (i/j) x, z^2 = r1^2 - x^2 - y^2 (i, j: c3 - c1 in e_x, e_y).
    """
    ex = centres[1] - centres[0]
    d = float(np.linalg.norm(ex))
    if d < 1e-6 * radii.max():
        return None
    ex /= d
    rel = centres[2] - centres[0]
    i = float(ex @ rel)
    ey = rel - i * ex
    j = float(np.linalg.norm(ey))
    if j < 1e-6 * radii.max():
        return None
    ey /= j
    ez = np.cross(ex, ey)
    x = (radii[0] ** 2 - radii[1] ** 2 + d**2) / (2.0 * d)
    y = (radii[0] ** 2 - radii[2] ** 2 + i**2 + j**2) / (2.0 * j) - i * x / j
    z2 = radii[0] ** 2 - x**2 - y**2
    if z2 < 0.0:
        return None
    base = centres[0] + x * ex + y * ey
    points = [base + np.sqrt(z2) * ez, base - np.sqrt(z2) * ez]
    return min(points, key=lambda p: float(p @ p))


def _common_point(rig: Rig, centres: np.ndarray, radii: np.ndarray) -> np.ndarray:
    """Gauss-Newton with minimum-norm steps from the origin on |d - c_i| = L_i; refuses if the
    spheres have no common point (residual above 1e-12 of the rig size)."""
    scale = rig_scale(rig)
    d = np.zeros(3)
    for _ in range(60):
        span = d - centres
        dist = np.linalg.norm(span, axis=1)
        err = dist - radii
        if np.abs(err).max() <= 1e-13 * scale:
            return d
        jac = span / dist[:, None]
        d = d - np.linalg.pinv(jac) @ err
    if np.abs(np.linalg.norm(d - centres, axis=1) - radii).max() <= 1e-12 * scale:
        return d
    raise _no_taut_pose(rig)


def initial_state(rig: Rig, rest: Rest | None = None) -> State:
    """The rig's initial state, exactly as the rig file's ``[initial]`` table defines it."""
    rest = rest_pose(rig) if rest is None else rest
    rotation = Rotation.from_rotvec(rig.initial_rotation).as_matrix() @ rest.rotation
    if rig.elastic:
        return _elastic_initial_state(rig, rest, rotation)
    try:
        com = rest.com + taut_shift(rig, rest.com, rotation)
    except RigError as exc:
        # Only a rotation can make the wires unreachable: the rest pose holds every wire taut.
        field = "initial.rotation" if np.any(rig.initial_rotation != 0.0) else "wire"
        raise RigError(rig.source, field, exc.problem) from None
    omega = np.asarray(rig.initial_omega, dtype=float)
    pts = attachments(rig, com, rotation)
    span = pts - anchors(rig)
    dirs = span / np.linalg.norm(span, axis=1)[:, None]
    # Wire i keeps its length iff dirs_i . (v + omega x arm_i) = 0; take the least-norm v.
    rate = np.einsum("ij,ij->i", dirs, np.cross(omega, pts - com))
    velocity = -np.linalg.pinv(dirs) @ rate
    miss = np.abs(dirs @ velocity + rate).max()
    # More wires than the COM velocity can satisfy; 1e-9 of the attachments' speed is rounding.
    if miss > 1e-9 * np.linalg.norm(omega) * np.linalg.norm(pts - com, axis=1).max():
        raise RigError(rig.source, "initial.omega", f"no COM velocity keeps every wire at its length "
                       f"(mismatch {miss:.3g} m/s): this spin stretches a wire")
    return State(com=com, rotation=rotation, velocity=velocity, omega=omega)


def _elastic_initial_state(rig: Rig, rest: Rest, rotation: np.ndarray) -> State:
    """Elastic wires: the body turned about its COM by ``initial.rotation`` and held at that orientation
    while its COM settles (the minimum of the potential over the COM position, :mod:`bifilar.rig.elastic`),
    then released with ``initial.omega`` and no COM velocity. A wire may be slack there: it pushes
    nothing. For stiff wires this tends to the inextensible rig's taut shift where the lowest COM on the
    wire spheres is also the nearest (a turn about the vertical: a pure rise)."""
    com, _, _, ok = elastic.settle(rig, rest.com, rotation, arms(rig), anchors(rig), rig_scale(rig),
                                   fixed_rotation=True)
    if not ok:
        raise RigError(rig.source, "initial.rotation", "the body turned this far finds no rest for its COM on the "
                       "elastic wires")
    return State(com=com, rotation=rotation, velocity=np.zeros(3), omega=np.asarray(rig.initial_omega, dtype=float))
