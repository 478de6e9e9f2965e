"""``identify ... --html`` and the sweep's ``DIR/report.html``: each page parses, stands alone, shows
the numbers the command printed (its JSON, its summary.json and CSV), and renders (headless Chromium)
to a page that is not blank with those numbers in its DOM."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest

from page_check import check_not_blank, check_self_contained, page_text, render
from test_identify import BENCH, torsion_csv, write_rig

from bifilar.identification import identify as ident
from bifilar.identification.measurement import sigma_shares
from bifilar.rig import load_rig
from validate.assets import rig
from validate.cli import main
from validate.report.html import number


def _identify(capsys, *args) -> dict:
    assert main(["identify", *map(str, args), "--json"]) == 0
    return json.loads(capsys.readouterr().out)


@pytest.mark.slow
def test_identify_page_of_two_records(tmp_path, capsys):
    records = [torsion_csv(tmp_path, "a.csv", 0.1, 3), torsion_csv(tmp_path, "b.csv", 0.5, 4)]
    path = tmp_path / "identify.html"
    out = _identify(capsys, BENCH, "--axis", "z", "--signal", records[0], "--signal", records[1], "--html", path)
    page = check_self_contained(path.read_text())
    words = page_text(page)
    assert f"I_zz {number(out['inertia'], 9)} ± {number(out['std'], 3)} kg m^2" in words
    for trial in out["trials"]:
        assert trial["source"] in words and f"{number(trial['period'], 9)} ± {number(trial['period_std'], 3)} s" in words
        assert f"{trial['crb_ratio']:.2f}x ({trial['crb_noise']} noise)" in words  # and what makes the sigma
        shares = sigma_shares(trial)
        assert shares and all(f"{what} {100.0 * share:.0f} %" in words for what, share in shares)
    for group, share in out["budget"].items():
        assert f"{group} {100.0 * share:.2f} %" in words
    assert ", ".join(number(x, 6) for x in out["tensor_check"]["principal"]) in words
    assert 'name = "bench_plate"' in words and f"--signal {records[1]} --html" in words  # the inputs
    assert len(page.images) == 1  # the fits

    image, dom = render(path)
    check_not_blank(image)
    assert number(out["inertia"], 9) in dom and "Variance budget" in dom


def test_identify_page_of_a_period_with_a_tare(tmp_path, capsys):
    """bench_plate with a 1 kg object on top (tests/test_identify.py's tare case)."""
    combined = write_rig(tmp_path, "[0.04, 0.13, 0.16]", mass="5.0", com="[0.0, 0.0, 0.01]", name="loaded.toml")
    path = tmp_path / "tare.html"
    out = _identify(capsys, combined, "--axis", "z", "--period", repr(ident.linear_period(load_rig(combined), "z")),
                    "--tare", BENCH, "--tare-period", repr(ident.linear_period(rig("bench_plate"), "z")), "--html", path)
    words = page_text(check_self_contained(path.read_text()))
    assert "A measured period was given: no record was fitted." in words
    assert f"I_zz about its own COM {number(out['object']['inertia'], 9)} ± {number(out['object']['std'], 3)}" in words
    assert "Fixture (tare)" in words and words.count('name = "bench_plate"') == 2
    assert f"rig: {combined}" in words and f"fixture: {BENCH}" in words


@pytest.mark.slow
def test_sweep_writes_a_report_page_of_its_outputs(tmp_path, capsys):
    from test_sweep_rerun import _sweep

    assert _sweep(tmp_path, "--check-mujoco", 1) == 0
    out = tmp_path / "out"
    summary = json.loads((out / "summary.json").read_text())
    with open(out / "sweep.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    page = check_self_contained((out / "report.html").read_text())
    words = page_text(page)
    best = summary["best"]
    (row,) = [r for r in rows if all(float(r[a]) == best[a] for a in ("anchor_span", "wire_length"))]
    assert f"configuration anchor_span = {best['anchor_span']:g} m, wire_length = {best['wire_length']:g} m" in words
    for k in range(1, 5):  # the best's modes: motion and period
        period = f"{number(float(row[f'period_{k}']), 9)} s" if row[f"period_{k}"] else "neutral"
        assert f"{k} {row[f'motion_{k}']} {period}" in words
    assert f"z {100.0 * float(row['sigma_z']):.4g} % {row['dominant_z']}" in words
    for p in summary["pareto"]:
        assert f"{100.0 * p['objective']:.4g} % {number(p['tension_peak'], 5, 'N')}" in words
    (mode,) = summary["mujoco_check"][0]["modes"]
    periods = (number(mode["predicted"], 9, "s"), number(mode["mujoco"], 9, "s"), number(mode["period_rel_error"], 3))
    assert " ".join(periods) in words
    assert "Grid-edge warnings" in words and len(page.images) == 1

    image, dom = render(out / "report.html")
    check_not_blank(image)
    assert f"{100.0 * best['objective']:.4g} %" in dom and "MuJoCo check" in dom


@pytest.mark.slow
def test_the_sweep_page_reads_its_csv_in_bounded_memory(tmp_path):
    """30,000 rows (~5 MB of CSV, ~60 MB as row dicts) reduced with a peak of a few MB: the cells
    (here 300 x 100 values in 200 x 100 cells), the sample of at most 20,000 feasible rows (every
    second here: 12,000 of 24,000) and the best row."""
    import tracemalloc

    from validate.commands.sweep import COLUMNS_AFTER_AXES
    from validate.report.sweep_page import sweep_page

    n, xs = 30_000, np.linspace(0.5, 2.0, 300)
    with open(tmp_path / "sweep.csv", "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["wire_length", "anchor_span"] + COLUMNS_AFTER_AXES)
        for i in range(n):
            sigma = 0.01 + 0.001 * ((i * 7919) % 1000) / 1000
            w.writerow([repr(float(xs[i % 300])), repr(0.1 + 0.01 * (i // 300)), "", "1.9", "1.5", "1.2", "10", "10", "10.5",
                        "", "", repr(sigma), "", "true" if i % 5 else "false", "tilt", "sway x", "sway y", "yaw", "", "",
                        "length", "0.1", "" if i % 5 else "peak tension over the limit", "", "", ""])
    best = {"wire_length": float(xs[1]), "anchor_span": 0.1, "sigma": {"z": 0.01}, "objective": 0.01, "tension_peak": 10.5}
    (tmp_path / "summary.json").write_text(json.dumps({"n": n, "feasible": n - n // 5, "objective": "worst", "best": best,
                                                        "pareto": [best], "seconds": 1.0, "mujoco_check": []}))
    tracemalloc.start()
    page = sweep_page(tmp_path, ["z"], "worst")
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert peak < 8e6, f"{peak / 1e6:.1f} MB"
    words = page_text(check_self_contained(page.html()))
    assert "configuration wire_length = 0.505017 m, anchor_span = 0.1 m" in words
