"""The registry of validation cases and the metric outcome type they return.

A case is a function that runs one or more engines on one system and returns :class:`Metric`s, each
a measured value, the tolerance it must meet and the reason for that tolerance. Register it with
:func:`case`; ``python -m validate all`` runs every case tagged ``fast`` (``--slow`` adds ``slow``).
Trajectories a case wants recorded (rerun) and drawn in the HTML report (runs of one rig by several
engines: their traces and differences, :mod:`validate.report.traces`) are handed to ``ctx.keep``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable

from .trajectory import Trajectory


@dataclass(frozen=True)
class Metric:
    """One measured quantity against its tolerance. ``passed`` is False for NaN."""

    name: str
    value: float
    tolerance: float
    reason: str
    passed: bool
    unit: str = ""
    at_least: bool = False

    def __post_init__(self):  # plain Python types, whatever numpy scalars a case passed in
        for name, kind in (("value", float), ("tolerance", float), ("passed", bool), ("at_least", bool)):
            object.__setattr__(self, name, kind(getattr(self, name)))


def check(name: str, value: float, tolerance: float, reason: str, *, unit: str = "", at_least: bool = False) -> Metric:
    """``value <= tolerance`` (or ``>=`` with ``at_least``); a value that is not finite fails."""
    value = float(value)
    ok = math.isfinite(value) and (value >= tolerance if at_least else value <= tolerance)
    return Metric(name, value, float(tolerance), reason, ok, unit, at_least)


@dataclass
class CaseContext:
    """What a running case may hand back besides metrics."""

    trajectories: list[Trajectory] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)

    def keep(self, *trajs: Trajectory) -> None:
        self.trajectories.extend(trajs)


@dataclass(frozen=True)
class Case:
    name: str
    source: str  # the seed section it reproduces, e.g. "000 ch. 6.1"
    engines: tuple[str, ...]
    tags: frozenset[str]
    description: str
    run: Callable[[CaseContext], list[Metric]]


REGISTRY: dict[str, Case] = {}


def case(name: str, source: str, engines: tuple[str, ...], tags=("fast",), description: str = ""):
    """Register the decorated ``run(ctx) -> list[Metric]`` as a validation case."""

    def register(fn: Callable[[CaseContext], list[Metric]]):
        if name in REGISTRY:
            raise ValueError(f"case {name!r} registered twice")
        REGISTRY[name] = Case(name, source, tuple(engines), frozenset(tags), description or (fn.__doc__ or "").strip(), fn)
        return fn

    return register
