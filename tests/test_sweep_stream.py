"""Sweeps in constant memory (issue 19, item 9): the rows reduced as they pass (bifilar/sweep/choose.py)
choose exactly what the whole list gives, and a sweep's outputs are the same whatever its chunk size,
i.e. however many chunk files its rows stream from.

Tolerances: none; the same arithmetic on the same numbers, so equality."""

import json
import math
import types

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from bifilar.sweep import run as sweep_run
from bifilar.sweep.choose import Choice, objective
from validate.cli import main

from test_sweep import PARALLEL
from test_sweep_rerun import _read

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


@settings(max_examples=300)
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


# Wires of 0.1 m cannot reach attachments 0.4 m apart from the wider anchor spans: infeasible rows.
SPACE = ('rig = "rig.toml"\n[vary]\nanchor_span = [0.4, 0.7, 1.0]\nwire_length = [0.1, 0.8, 1.2]\n'
         '[measure]\naxes = ["z"]\n')


@pytest.mark.slow
def test_the_outputs_are_the_same_whatever_the_chunk_size(tmp_path, capsys, monkeypatch):
    """Nine configurations in one chunk, in three (4, 4, 1) and in nine: sweep.csv, summary.json,
    sweep.png, report.html, the recording's table and map, and what is printed, all equal. Each row is
    evaluated from scratch here (no rest pose continued from the chunk's previous one), so that the
    rows themselves do not depend on where the chunks begin; the evaluation time is held at zero."""
    (tmp_path / "rig.toml").write_text(PARALLEL)
    (tmp_path / "space.toml").write_text(SPACE)

    def from_scratch(path, start, stop):
        return [row for k in range(start, stop) for row in sweep_run._evaluate_range(path, k, k + 1)]

    monkeypatch.setattr(sweep_run, "run_chunk", from_scratch)
    import validate.commands.sweep as command

    monkeypatch.setattr(command, "time", types.SimpleNamespace(perf_counter=lambda: 0.0))
    outputs = []
    for size in (64, 4, 1):
        monkeypatch.setattr(sweep_run, "chunk_size", lambda n, size=size: size)
        out = tmp_path / f"chunk{size}"
        assert main([str(a) for a in ("sweep", tmp_path / "space.toml", "--out", out, "--jobs", 1,
                                      "--png", "--rerun", "--check-mujoco", 2)]) == 0
        printed = capsys.readouterr().out.replace(str(out), "OUT")
        files = {f: (out / f).read_bytes() for f in ("sweep.csv", "summary.json", "sweep.png", "report.html")}
        recording = {e: v for e, v in _read(out / "sweep.rrd").items() if e.startswith("sweep/")}
        outputs.append((printed, files, recording))
    assert 0 < json.loads(outputs[0][1]["summary.json"])["feasible"] < 9  # infeasible rows too
    assert outputs[1] == outputs[0] and outputs[2] == outputs[0]
