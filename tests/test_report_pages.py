"""``identify ... --html`` and the sweep's ``DIR/report.html``: each page parses, stands alone, shows
the numbers the command printed (its JSON, its summary.json and CSV), and renders (headless Chromium)
to a page that is not blank with those numbers in its DOM."""

from __future__ import annotations

import json

from page_check import check_not_blank, check_self_contained, page_text, render
from test_identify import BENCH, torsion_csv, write_rig

from bifilar.identification import identify as ident
from bifilar.rig import load_rig
from validate.assets import rig
from validate.cli import main
from validate.report.html import number


def _identify(capsys, *args) -> dict:
    assert main(["identify", *map(str, args), "--json"]) == 0
    return json.loads(capsys.readouterr().out)


def test_identify_page_of_two_records(tmp_path, capsys):
    records = [torsion_csv(tmp_path, "a.csv", 0.1, 3), torsion_csv(tmp_path, "b.csv", 0.5, 4)]
    path = tmp_path / "identify.html"
    out = _identify(capsys, BENCH, "--axis", "z", "--signal", records[0], "--signal", records[1], "--html", path)
    page = check_self_contained(path.read_text())
    words = page_text(page)
    assert f"I_zz {number(out['inertia'], 9)} ± {number(out['std'], 3)} kg m^2" in words
    for trial in out["trials"]:
        assert trial["source"] in words and f"{number(trial['period'], 9)} ± {number(trial['period_std'], 3)} s" in words
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
