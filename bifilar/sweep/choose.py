"""Choosing among the configurations: the objective, the best feasible row and the Pareto front.

Objective (the sweep file's ``measure.objective``): ``worst``, the largest relative standard deviation
of the moments in ``measure.axes`` (a rig is as good as its worst-measured moment; the default), or
``mean``, their mean. Only feasible rows (every limit held, every measured axis identifiable) count.
The Pareto front trades the objective against the peak tension: a feasible row is on it when no other
feasible row is at least as good in both and better in one (of equal ones, the first in grid order).
The rows are reduced as they pass (:class:`Choice`), so a sweep's choice needs no more memory for
10^7 rows than for 10.
"""

from __future__ import annotations

import bisect
import heapq
import math


def objective(row: dict, measured, kind: str) -> float:
    values = [row["sigma"][a] for a in measured]
    if not row["feasible"] or any(v is None for v in values):
        return math.inf
    return max(values) if kind == "worst" else sum(values) / len(values)


class Front:
    """The Pareto front of points offered one at a time in grid order, in memory of the front alone.

    A point (objective v, peak tension t, grid index i) is off the front when another point has a
    lexicographically smaller (v, t, i) and a peak tension t' <= t. That relation is transitive, so the
    points not beaten so far, kept sorted by (v, t, i), have strictly decreasing tensions, and each new
    point (the largest i yet) is beaten iff the member just before its place has t' <= t; if not, it
    beats the members after it whose tension is >= t. The result is the front the sorted list of every
    point gives (the least tension so far, by increasing (v, t, i))."""

    def __init__(self):
        self._keys: list[tuple[float, float, int]] = []
        self._rows: list[dict] = []

    def add(self, value: float, tension: float, index: int, row: dict) -> None:
        key = (value, tension, index)
        at = bisect.bisect(self._keys, key)
        if at > 0 and self._keys[at - 1][1] <= tension:
            return
        beaten = at
        while beaten < len(self._keys) and self._keys[beaten][1] >= tension:
            beaten += 1
        self._keys[at:beaten] = [key]
        self._rows[at:beaten] = [row]

    @property
    def rows(self) -> list[dict]:
        """The front's rows by increasing objective."""
        return list(self._rows)


class Ranking:
    """The ``keep`` points of least objective among those offered in grid order (a tie to the first
    in grid order), in memory of ``keep``: a bounded heap whose root is the worst kept."""

    def __init__(self, keep: int):
        self.keep = keep
        self._heap: list[tuple[float, int, dict]] = []  # (-objective, -index, row)

    def add(self, value: float, index: int, row: dict) -> None:
        item = (-value, -index, row)  # the indices differ: the rows are never compared
        if len(self._heap) < self.keep:
            heapq.heappush(self._heap, item)
        elif item > self._heap[0]:
            heapq.heapreplace(self._heap, item)

    def ranked(self) -> list[tuple[int, dict]]:
        """(grid index, row) of the kept points, best first."""
        return [(-i, row) for _, i, row in sorted(self._heap, reverse=True)]


class Choice:
    """A sweep's rows reduced as they pass in grid order, in memory independent of their number: the
    count ``n``, the ``feasible`` count, the Pareto ``front`` and the ``keep`` best ranked (the first
    of them the best row)."""

    def __init__(self, measured, kind: str, keep: int = 1):
        self.measured, self.kind = list(measured), kind
        self.n = self.feasible = 0
        self.front = Front()
        self.ranking = Ranking(max(1, keep))

    def add(self, row: dict) -> float:
        """Take the next row in grid order; returns its objective."""
        value = objective(row, self.measured, self.kind)
        if math.isfinite(value):
            self.front.add(value, row["tension_peak"], self.n, row)
            self.ranking.add(value, self.n, row)
        self.feasible += bool(row["feasible"])
        self.n += 1
        return value

    @property
    def best(self) -> tuple[int, dict] | None:
        """(grid index, row) of the feasible row of least objective (the first in grid order on a
        tie), or None."""
        ranked = self.ranking.ranked()
        return ranked[0] if ranked else None


def best(rows, measured, kind: str) -> dict | None:
    """The feasible row of least objective among ``rows`` (any iterable; the first on a tie), or None."""
    choice = Choice(measured, kind)
    for row in rows:
        choice.add(row)
    return choice.best[1] if choice.best else None


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
