"""Which hangings to make (``validate plan``): from candidate orientations, the K whose yaw periods
determine the object's tensor best under the rig's period sigma.

Each candidate is the object on the rig turned by Q (object axes -> rig body axes); its period's
gradient g = d T / d(I_xx, I_yy, I_zz, I_xy, I_yz, I_xz) on the exact linearisation
(:class:`bifilar.identification.tensor.Linear`) at the expected tensor gives the information
F = sum g g^T / sigma^2 of a set, and its covariance F^-1. Criteria:

* ``worst``: the largest component sigma relative to the largest principal moment (the products of
  inertia may be near zero, so each is judged on the tensor's scale);
* ``det``: ln det F^-1, the volume of the confidence ellipsoid (D-optimal).

The search is greedy (add the candidate that lowers the criterion most, the information regularised
until six are in) followed by exchanges (swap a chosen for an unchosen candidate while that lowers
the criterion), the classical Fedorov exchange: not a proof of the optimum, but never worse than the
greedy set, and the textbook set is itself a start, so the plan never loses to it.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from scipy.spatial.transform import Rotation

from bifilar.rig import Rig, RigError

from .tensor import Hanging, Linear, components_of

CRITERIA = ("worst", "det")
_EXCHANGE_PASSES = 50
_RIDGE = 1e-9  # x the largest information entry: keeps F invertible while fewer than six are chosen


@dataclass(frozen=True, eq=False)  # compared by identity: one candidate is chosen once
class Candidate:
    name: str
    orientation: np.ndarray  # Q, object axes -> rig body axes
    gradient: np.ndarray  # d T / d components, s / (kg m^2)
    period: float  # s, at the expected tensor
    sigma: float  # s


@dataclass(frozen=True)
class Design:
    """A set of candidates with its covariance over the six components."""

    chosen: tuple[Candidate, ...]
    covariance: np.ndarray
    scale: float  # the expected tensor's largest principal moment, kg m^2

    @property
    def std(self) -> np.ndarray:
        return np.sqrt(np.diag(self.covariance))

    @property
    def worst(self) -> float:
        return float(self.std.max() / self.scale)

    @property
    def log_det(self) -> float:
        return float(np.linalg.slogdet(self.covariance)[1])

    def value(self, criterion: str) -> float:
        return self.worst if criterion == "worst" else self.log_det


def vertical_orientation(axis) -> np.ndarray:
    """Q turning the object so that its ``axis`` (object frame) is the rig's body z."""
    e = np.asarray(axis, float) / np.linalg.norm(axis)
    return Rotation.align_vectors([[0.0, 0.0, 1.0]], [e])[0].as_matrix()


TEXTBOOK = tuple((name, vertical_orientation(v)) for name, v in (
    ("x vertical", (1, 0, 0)), ("y vertical", (0, 1, 0)), ("z vertical", (0, 0, 1)),
    ("x+y vertical", (1, 1, 0)), ("y+z vertical", (0, 1, 1)), ("x+z vertical", (1, 0, 1))))


def hemisphere(count: int) -> list[tuple[str, np.ndarray]]:
    """``count`` orientations whose vertical object axes are spread evenly over a hemisphere (a
    Fibonacci lattice: an axis and its opposite give the same yaw period)."""
    golden = np.pi * (3.0 - np.sqrt(5.0))
    out = []
    for k in range(count):
        z = 1.0 - (k + 0.5) / count
        r = np.sqrt(1.0 - z * z)
        axis = np.array([r * np.cos(golden * k), r * np.sin(golden * k), z])
        out.append((f"axis ({axis[0]:+.3f}, {axis[1]:+.3f}, {axis[2]:+.3f}) vertical", vertical_orientation(axis)))
    return out


def mounted(rig: Rig, inertia: np.ndarray, q: np.ndarray, fixture: Rig | None = None) -> Hanging:
    """The hanging of the object (``rig``'s [body] in object axes, tensor ``inertia``) turned by Q:
    alone on ``rig``'s wires (COM at Q com), or on ``fixture`` with its COM on the fixture's."""
    if fixture is None:
        hung = replace(rig, com=q @ rig.com, inertia=q @ inertia @ q.T)
        return Hanging(hung, 0.0, 0.0, q)
    hung = replace(fixture, mass=fixture.mass + rig.mass, inertia=fixture.inertia + q @ inertia @ q.T)
    return Hanging(hung, 0.0, 0.0, q, held=fixture.inertia)


def candidates(rig: Rig, inertia: np.ndarray, sigma: float, orientations, fixture: Rig | None = None):
    """(usable candidates, names skipped with the reason): a candidate whose yaw cannot be told from
    another mode is skipped.

    The candidates' hangings differ only in the body's inertia and (alone on the wires) its COM
    (:func:`mounted`): those with one COM share one rest-pose search and linearisation (:class:`Linear`'s
    ``like``): a trifilar's takes 14 starts, 0.1 s, and 5000 generated candidates took 10 minutes. A
    COM not met before continues the rest pose of the nearest one solved (Newton from it, checked
    stable; the full search where that fails: :func:`bifilar.rig.statics.rest_pose`), as a sweep does."""
    x = components_of(inertia)
    usable, skipped = [], []
    like: dict[bytes, Rig] = {}  # COM -> the first hanging's rig with it
    coms, rests = [], []  # the COMs solved and their rest poses
    for name, q in orientations:
        hanging = mounted(rig, inertia, q, fixture)
        com = np.asarray(hanging.rig.com, float)
        base = like.setdefault(com.tobytes(), hanging.rig)
        guess = rests[int(np.argmin(np.sum((np.array(coms) - com) ** 2, axis=1)))] if rests else None
        try:
            model = Linear(hanging, base, guess if base is hanging.rig else None)
            if base is hanging.rig:
                coms.append(com)
                rests.append(model.rest)
            t, g = model.period(x)
        except RigError as exc:
            skipped.append((name, exc.problem))
            continue
        usable.append(Candidate(name, q, g, t, sigma))
    return usable, skipped


def design(chosen, scale: float, ridge: float = 0.0) -> Design:
    info = sum(np.outer(c.gradient, c.gradient) / c.sigma ** 2 for c in chosen)
    return Design(tuple(chosen), np.linalg.inv(info + ridge * np.eye(6)), scale)


def plan(pool: list[Candidate], count: int, criterion: str, scale: float, starts=()) -> Design:
    """The K = ``count`` candidates of ``pool`` minimising ``criterion`` (greedy, then exchanges from
    the greedy set and from each of ``starts``, lists of candidates of the pool)."""
    if count < 6:
        raise ValueError("six components need at least six hangings")
    if len(pool) < count:
        raise ValueError(f"only {len(pool)} usable candidates for {count} hangings")
    outer = _Outer(pool)
    ridge = _RIDGE * float(outer.each.max())
    chosen: list[Candidate] = []
    while len(chosen) < count:
        rest = [k for k, c in enumerate(pool) if c not in chosen]
        values = outer.values(chosen, len(chosen), rest, criterion, scale, ridge)
        best = 0
        for j, v in enumerate(values):  # min(rest, key=value): the first of the least
            if v < values[best]:
                best = j
        chosen.append(pool[rest[best]])
    best = _exchange(outer, chosen, criterion, scale)
    for start in starts:
        if len(start) == count:
            other = _exchange(outer, list(start), criterion, scale)
            if other.value(criterion) < best.value(criterion):
                best = other
    return best


class _Outer:
    """The pool's information terms g g^T / sigma^2, and the criterion of a set with one place filled
    by each of many candidates at once (batched inverses): the greedy step and the exchanges evaluate
    every candidate of the pool for every place, 3e5 designs for 5000 candidates, one at a time ~13 s.
    Summed in the order :func:`design` sums them, so the values and the choices are the same."""

    def __init__(self, pool: list[Candidate]):
        self.pool = pool
        self.each = np.array([np.outer(c.gradient, c.gradient) / c.sigma ** 2 for c in pool])
        self.index = {id(c): k for k, c in enumerate(pool)}

    def term(self, c: Candidate) -> np.ndarray:
        k = self.index.get(id(c))
        return self.each[k] if k is not None else np.outer(c.gradient, c.gradient) / c.sigma ** 2

    def values(self, chosen: list[Candidate], i: int, among: list[int], criterion: str, scale: float,
               ridge: float = 0.0) -> list[float]:
        """The criterion of ``chosen`` with place ``i`` (``len(chosen)``: one more) held by each of the
        pool's candidates ``among`` (indices)."""
        info = sum(self.term(c) for c in chosen[:i]) + self.each[among]
        for c in chosen[i + 1:]:
            info = info + self.term(c)
        cov = np.linalg.inv(info + ridge * np.eye(6))
        if criterion == "worst":
            with np.errstate(invalid="ignore"):
                return (np.sqrt(np.diagonal(cov, axis1=1, axis2=2)).max(axis=1) / scale).tolist()
        return np.linalg.slogdet(cov)[1].tolist()


def _exchange(outer: _Outer, chosen: list[Candidate], criterion: str, scale: float) -> Design:
    """Fedorov's exchange (module docstring): for each place in turn, every candidate of the pool not
    chosen is tried there, in the pool's order, and taken where it lowers the criterion."""
    current = design(chosen, scale)
    now = current.value(criterion)
    for _ in range(_EXCHANGE_PASSES):
        improved = False
        for i in range(len(chosen)):
            among = [k for k, c in enumerate(outer.pool) if c not in chosen]
            taken = None
            for k, v in zip(among, outer.values(chosen, i, among, criterion, scale)):
                if v < now - 1e-12 * abs(now):
                    taken, now = k, v
            if taken is not None:
                chosen = chosen[:i] + [outer.pool[taken]] + chosen[i + 1:]
                current, improved = design(chosen, scale), True
                now = current.value(criterion)
        if not improved:
            break
    return current
