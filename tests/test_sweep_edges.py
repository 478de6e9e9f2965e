"""A best configuration on the grid's edge is flagged (issue 19, item 5): in the summary's ``edges``,
the text and the figure; the summary names every file written."""

import json

import numpy as np
import pytest

from bifilar.sweep.choose import edges
from validate.cli import main


def test_edges_name_the_axis_side_and_direction():
    axes = {"a": np.array([1.0, 2.0, 3.0]), "b": np.array([0.1, 0.2, 0.3]), "c": np.array([5.0, 6.0])}
    top = {"values": {"a": 3.0, "b": 0.2, "c": 5.0}}
    (edge,) = edges(axes, top)  # c has two values: both are edges, and saying so tells nothing
    assert (edge["axis"], edge["side"], edge["widen"]) == ("a", "high", "above")
    assert "widen a above 3" in edge["text"]
    assert edges(axes, {"values": {"a": 1.0, "b": 0.1, "c": 6.0}})[1]["side"] == "low"
    assert edges(axes, None) == [] and edges(axes, top, explicit=True) == []


@pytest.mark.slow
def test_the_shipped_sweep_warns_of_its_edges(tmp_path, capsys):
    # bench_plate's best (anchor span 0.9 m, attachment span 0.2 m) sits on two edges of its grid
    assert main(["sweep", "bench_plate", "--out", str(tmp_path), "--png", "--jobs", "1"]) == 0
    out = capsys.readouterr().out
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert {(e["axis"], e["side"]) for e in summary["edges"]} == {("anchor_span", "high"), ("attach_span", "low")}
    assert out.count("warning: the best") == 2 and all(len(line) <= 100 for line in out.splitlines())
    assert summary["files"] == ["sweep.csv", "summary.json", "sweep.png", "report.html"]
    assert all((tmp_path / f).is_file() for f in summary["files"])
