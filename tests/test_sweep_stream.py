"""Sweeps in constant memory (issue 19, item 9): the rows reduced as they pass (bifilar/sweep/choose.py)
choose exactly what the whole list gives.

Tolerances: none; the same arithmetic on the same numbers, so equality."""

import math

from hypothesis import given, settings
from hypothesis import strategies as st

from bifilar.sweep.choose import Choice, objective


MEASURED, KIND = ("x", "z"), "worst"


def _brute(rows: list[dict], keep: int):
    """The reference: every row scored, then the front by its definition (a point is off it when another
    has a lexicographically smaller (objective, peak tension, index) and a peak tension <= its own),
    and the ``keep`` best by (objective, index), all by quadratic or sorted search over the whole list."""
    points = [(objective(r, MEASURED, KIND), r["tension_peak"], i) for i, r in enumerate(rows)]
    points = [p for p in points if math.isfinite(p[0])]
    front = sorted(p for p in points if not any(q < p and q[1] <= p[1] for q in points))
    ranked = sorted((v, i) for v, _, i in points)[:keep]
    return [i for _, _, i in front], [i for _, i in ranked], sum(r["feasible"] for r in rows)


# Few distinct values, so that objectives, tensions and both together tie often.
_SIGMA = st.sampled_from([None, 0.01, 0.02, 0.03])
_ROW = st.fixed_dictionaries({
    "feasible": st.booleans(),
    "sigma": st.fixed_dictionaries({"x": _SIGMA, "y": _SIGMA, "z": _SIGMA}),
    "tension_peak": st.sampled_from([5.0, 6.0, 7.0, 8.0]),
})


@settings(max_examples=300, deadline=None, database=None)
@given(rows=st.lists(_ROW, max_size=40), keep=st.integers(1, 6))
def test_the_reduction_as_rows_pass_is_the_whole_lists(rows, keep):
    choice = Choice(MEASURED, KIND, keep=keep)
    for r in rows:
        choice.add(r)
    front, ranked, feasible = _brute(rows, keep)
    assert [id(r) for r in choice.front.rows] == [id(rows[i]) for i in front]
    assert [i for i, _ in choice.ranking.ranked()] == ranked
    assert choice.best == ((ranked[0], rows[ranked[0]]) if ranked else None)
    assert (choice.n, choice.feasible) == (len(rows), feasible)
