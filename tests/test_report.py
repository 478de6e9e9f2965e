"""``validate all --junit`` and ``--html``: the JUnit file CI servers read and the self-contained page.

The JUnit file must parse, hold one testcase per case run with the failed metrics in its failure,
and differ between two identical runs only in its times. The page must parse, name every case and
metric, reference nothing outside itself, and render (headless Chromium) to a page that is not blank
and shows the verdict and the metric values.
"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET

import numpy as np
import pytest
from page_check import check_not_blank, check_self_contained, page_text, render

from validate import registry
from validate.cli import main
from validate.registry import Case, check
from validate.report.junit import junit_xml
from validate.report.suite_page import margin, suite_page
from validate.report.traces import comparisons
from validate.suite import CaseResult
from validate.trajectory import Trajectory

CASES = "pendulum-*"  # two MuJoCo cases of a few seconds (the spherical one compares two engines) and:
FAILING = "pendulum-demo-failing"  # registered by these tests only


def _failing(ctx):
    """A case that fails one of its two metrics (registered by the tests only)."""
    t = np.linspace(0.0, 1.0, 101)
    ctx.keep(Trajectory("a", t, {"q": np.sin(t)}), Trajectory("b", t, {"q": np.sin(t) + 1e-3 * t}))
    return [check("agrees", 1e-3, 1e-6, "a demonstration that must fail"),
            check("holds", 0.5, 0.1, "a demonstration lower bound", at_least=True)]


@pytest.fixture
def failing_case(monkeypatch):
    from validate.cases import load_all

    load_all()
    monkeypatch.setitem(registry.REGISTRY, FAILING, Case(FAILING, "tests", ("a", "b"), frozenset({"fast"}),
                                                         "fails on purpose", _failing))


def _mask_times(text: str) -> str:
    return re.sub(r'(time|timestamp)="[^"]*"', r'\1="*"', text)


@pytest.mark.slow
def test_junit_of_two_identical_runs_differs_only_in_times_and_lists_failed_metrics(tmp_path, capsys, failing_case):
    texts = []
    for k in range(2):
        path = tmp_path / f"j{k}.xml"
        code = main(["all", "-k", CASES, "--jobs", "1", "--junit", str(path)])
        capsys.readouterr()
        assert code == 1  # the failing case fails the run
        texts.append(path.read_text())
    assert texts[0] != _mask_times(texts[0]) and _mask_times(texts[0]) == _mask_times(texts[1])
    suite = ET.fromstring(texts[0]).find("testsuite")
    cases = {c.get("name"): c for c in suite.iter("testcase")}
    assert set(cases) == {"pendulum-planar-A", "pendulum-spherical-4.5", FAILING}
    assert (suite.get("tests"), suite.get("failures"), suite.get("errors")) == ("3", "1", "0")
    assert cases["pendulum-planar-A"].get("classname") == "validate.cases.pendulum"
    assert float(cases["pendulum-planar-A"].get("time")) > 0.0
    assert cases["pendulum-planar-A"].find("failure") is None
    failure = cases[FAILING].find("failure")
    assert failure.get("message") == "1 of 2 metrics failed: agrees"
    assert failure.text == "agrees: 1.000000e-03 (<= 1.000e-06: FAIL) a demonstration that must fail"
    props = {p.get("name"): p.get("value") for p in suite.find("properties")}
    assert set(props) >= {"python", "mujoco", "numpy", "scipy", "numba"}


def _results() -> list[CaseResult]:
    t = np.linspace(0.0, 4.0, 4001)
    runs = [Trajectory("kane", t, {"q": np.cos(3 * t)}), Trajectory("mujoco", t, {"q": np.cos(3 * t) + 1e-9 * t})]
    ok = CaseResult("good-case", "000 ch. 6", True, 1.25, [check("period vs exact", 3e-11, 1e-8, "rtol 1e-10")],
                    group="demo", traces=comparisons(runs))
    bad = CaseResult("bad-case", "000 ch. 7", False, 0.5, [check("tension & <stretch>", 2.0, 1.0, "softness", unit="N")],
                     group="demo")
    broken = CaseResult("broken-case", "issue 1", False, 0.1, [], "ZeroDivisionError: division by zero\nTraceback ...")
    return [ok, bad, broken]


def test_junit_counts_failures_and_errors_apart():
    root = ET.fromstring(junit_xml(_results(), 2.0))
    suite = root.find("testsuite")
    assert (suite.get("tests"), suite.get("failures"), suite.get("errors"), suite.get("time")) == ("3", "1", "1", "2.000")
    broken = [c for c in suite.iter("testcase") if c.get("name") == "broken-case"][0]
    assert broken.find("error").get("type") == "ZeroDivisionError" and broken.find("failure") is None
    bad = [c for c in suite.iter("testcase") if c.get("name") == "bad-case"][0]
    assert "tension & <stretch>: 2.000000e+00 N (<= 1.000e+00: FAIL) softness" == bad.find("failure").text


def test_margin_is_the_share_of_the_tolerance_used():
    assert margin(check("a", 2e-9, 1e-8, "")) == pytest.approx(0.2)
    assert margin(check("b", 8.0, 4.0, "", at_least=True)) == pytest.approx(0.5)
    assert np.isnan(margin(check("c", float("nan"), 1.0, "")))


def test_comparisons_keep_the_peaks_of_the_difference():
    """4001 samples thinned to 400 buckets keep the largest difference (4e-9 at the end) exactly."""
    c = _results()[0].traces[0]
    assert (c.signal, c.reference, [line.label for line in c.traces]) == ("q", "kane", ["kane", "mujoco"])
    assert len(c.differences[0].t) <= 800 and c.differences[0].y.max() == pytest.approx(4e-9, rel=1e-6)


def test_page_orders_failed_cases_first_and_escapes_text():
    text = suite_page(_results(), 2.0, {"good-case": "a <b> description"}, command="python -m validate all").html()
    page = check_self_contained(text)
    words = page_text(page)
    assert words.index("bad-case: FAIL") < words.index("good-case: PASS")
    assert "tension & <stretch>" in words and "a <b> description" in words
    assert "1 passed, 2 failed" in words and "ZeroDivisionError: division by zero" in words
    assert len(page.images) == 1  # the good case's comparison


@pytest.mark.slow
def test_html_names_every_case_and_metric_and_renders(tmp_path, capsys, failing_case):
    path = tmp_path / "report.html"
    code = main(["all", "-k", CASES, "--jobs", "1", "--html", str(path)])
    capsys.readouterr()
    assert code == 1
    text = path.read_text()
    page = check_self_contained(text)
    words = page_text(page)
    from validate.suite import run_case  # the same cases, run again for their metric names

    names = ["pendulum-planar-A", "pendulum-spherical-4.5", FAILING]
    for name in names:
        assert name in words
    for m in run_case("pendulum-spherical-4.5").metrics + run_case(FAILING).metrics:
        assert m.name in words and m.reason in words and f"{m.value:.3e}" in words
    assert words.index(f"{FAILING}: FAIL") < words.index("pendulum-planar-A: PASS")
    assert len(page.images) == 2  # the spherical pendulum (MuJoCo vs the thesis's 4.5.7) and the demo
    assert f"python -m validate all -k '{CASES}' --jobs 1 --html {path}" in words
    for version in ("mujoco", "numpy", "scipy", "numba", "python"):
        assert f"{version} " in words

    image, dom = render(path)
    check_not_blank(image)
    dom_words = " ".join(dom.split())
    assert "2 passed, 1 failed" in dom_words and "1.000e-03" in dom_words


def test_case_writes_junit_and_html_of_its_one_case(tmp_path, capsys):
    junit, page = tmp_path / "case.xml", tmp_path / "case.html"
    assert main(["case", "pendulum-spherical-4.5", "--junit", str(junit), "--html", str(page)]) == 0
    capsys.readouterr()
    suite = ET.parse(junit).getroot().find("testsuite")
    assert [c.get("name") for c in suite.iter("testcase")] == ["pendulum-spherical-4.5"]
    assert (suite.get("tests"), suite.get("failures"), suite.get("errors")) == ("1", "0", "0")
    words = page_text(check_self_contained(page.read_text()))
    assert "1 passed, 0 failed" in words and "pendulum-spherical-4.5: PASS" in words


def test_an_unwritable_report_path_is_exit_2_before_any_case_runs(tmp_path, capsys):
    (tmp_path / "r.html").mkdir()
    assert main(["all", "-k", "pendulum-*", "--html", str(tmp_path / "r.html")]) == 2
    assert main(["all", "-k", "pendulum-*", "--junit", "/proc/nope/j.xml"]) == 2
    _, err = capsys.readouterr()
    assert err.splitlines() == [f"error: {tmp_path / 'r.html'}: cannot write (is a directory)",
                                "error: /proc/nope/j.xml: cannot write (No such file or directory)"]


@pytest.mark.slow
def test_slow_html_ends_with_the_stored_speed_accuracy_result(tmp_path, capsys):
    from validate.report.speed_accuracy import SpeedAccuracySection, load

    stored = load()
    assert stored is not None, "docs/speed_accuracy.json: python benchmarks/speed_accuracy.py writes it"
    path = tmp_path / "slow.html"
    assert main(["all", "--slow", "-k", "pendulum-planar-A", "--html", str(path)]) == 0
    capsys.readouterr()
    page = check_self_contained(path.read_text())
    words = page_text(page)
    assert words.index("pendulum-planar-A: PASS") < words.index("Speed and accuracy")
    assert f"measured {stored['date']}" in words and len(page.images) == 1  # the figure; planar-A compares nothing
    for p in stored["points"]:
        assert f"{p['rig']} {p['engine']} {p['label']}" in words
    assert "No stored result at /nowhere.json" in page_text(parse_section(SpeedAccuracySection(None, "/nowhere.json")))
    assert main(["all", "-k", "pendulum-planar-A", "--html", str(path)]) == 0  # without --slow: no such section
    capsys.readouterr()
    assert "Speed and accuracy" not in path.read_text()


def parse_section(section):
    from page_check import parse

    return parse(section.html())
