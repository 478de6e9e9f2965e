"""Choosing among the configurations: the objective, the best feasible row and the Pareto front.

Objective (the sweep file's ``measure.objective``): ``worst``, the largest relative standard deviation
of the moments in ``measure.axes`` (a rig is as good as its worst-measured moment; the default), or
``mean``, their mean. Only feasible rows (every limit held, every measured axis identifiable) count.
The Pareto front trades the objective against the peak tension: a feasible row is on it when no other
feasible row is at least as good in both and better in one.
"""

from __future__ import annotations

import math


def objective(row: dict, measured, kind: str) -> float:
    values = [row["sigma"][a] for a in measured]
    if not row["feasible"] or any(v is None for v in values):
        return math.inf
    return max(values) if kind == "worst" else sum(values) / len(values)


def best(rows: list[dict], measured, kind: str) -> dict | None:
    """The feasible row of least objective (the first in grid order on a tie), or None."""
    scored = [(objective(r, measured, kind), i) for i, r in enumerate(rows)]
    value, i = min(scored, default=(math.inf, -1))
    return rows[i] if math.isfinite(value) else None


def pareto(rows: list[dict], measured, kind: str) -> list[dict]:
    """Feasible rows not dominated in (objective, peak tension), by increasing objective."""
    points = sorted(
        ((objective(r, measured, kind), r["tension_peak"], i) for i, r in enumerate(rows)
         if math.isfinite(objective(r, measured, kind))),
    )
    front, lowest = [], math.inf
    for value, tension, i in points:
        if tension < lowest:
            front.append(rows[i])
            lowest = tension
    return front


def edges(axes: dict, top: dict | None, explicit: bool = False) -> list[dict]:
    """Where the best row sits on the grid's edge: one entry per axis of three or more values whose
    smallest or largest value the best takes (``axis``, ``side`` low/high, ``widen`` the direction to
    extend the grid, ``text``). A best on an edge may only be the best inside the grid: widening it
    there may move it. Explicit point lists have no grid, so no edges."""
    if top is None or explicit:
        return []
    out = []
    for name, values in axes.items():
        if len(values) < 3:
            continue
        value = top["values"][name]
        for side, end, widen in (("low", min(values), "below"), ("high", max(values), "above")):
            if value == end:
                out.append({"axis": name, "side": side, "widen": widen,
                            "text": f"the best {name} = {value:g} is the grid's {'smallest' if side == 'low' else 'largest'}"
                                    f" value: widen {name} {widen} {value:g} to see whether it is the best beyond the grid"})
    return out
