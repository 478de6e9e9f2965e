"""The page of a suite run (``validate all --html``, ``validate case NAME --html``): a summary (the
verdict, wall time, machine, package versions), an overview of the cases, then every case with its
metrics (value, tolerance, why that tolerance) and, where it compares motions, a figure of the
engines' traces and their difference (:mod:`.traces`). Failed cases come first and open; passed
cases are folded.
"""

from __future__ import annotations

import datetime
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from .environment import machine, versions
from .html import Raw, join, number, slug, table, tag
from .page import Page, Section
from .sections import Facts, Table, figure, verdict
from .traces import figure as trace_figure

if TYPE_CHECKING:
    from ..suite import CaseResult


def margin(m) -> float:
    """How much of its tolerance a metric uses: value / tolerance (tolerance / value for ``>=``);
    above 1 it fails, and NaN fails too."""
    a, b = (m.tolerance, m.value) if m.at_least else (m.value, m.tolerance)
    if b == 0.0:
        return 0.0 if a == 0.0 else math.inf
    return abs(a / b) if math.isfinite(a) and math.isfinite(b) else math.nan


def in_report_order(results: Sequence[CaseResult]) -> list[CaseResult]:
    """Failed cases first, each group in the order the cases ran."""
    return [r for r in results if not r.passed] + [r for r in results if r.passed]


@dataclass
class CaseSection(Section):
    """One case: what it checks, its error if it raised, its metrics and its comparison figures."""

    result: CaseResult
    description: str = ""

    @property
    def title(self) -> str:
        return f"{self.result.name}: {'PASS' if self.result.passed else 'FAIL'}"

    @property
    def open(self) -> bool:
        return not self.result.passed

    @property
    def anchor(self) -> str:
        return case_anchor(self.result.name)

    def body(self) -> str:
        r = self.result
        lead = tag("p", join([verdict(r.passed), f" {r.source}; group {r.group or '-'}; {r.seconds:.2f} s. ",
                              self.description]))
        parts = [lead]
        if r.error:
            parts.append(tag("pre", r.error))
        if r.metrics:
            parts.append(metrics_table(r.metrics))
        elif not r.error:
            parts.append(tag("p", "The case returned no metrics.", cls="fail"))
        for note in r.notes:
            parts.append(tag("p", f"note: {note}"))
        for c in r.traces:
            engines = ", ".join(line.label for line in c.traces)
            parts.append(figure(trace_figure(c), f"{c.system}: {c.signal} of each engine ({engines}) and the "
                                                 f"difference of each from {c.reference}"))
        return join(parts)


def case_anchor(name: str) -> str:
    return f"case-{slug(name)}"


def metrics_table(metrics) -> Raw:
    rows, classes = [], []
    for m in metrics:
        unit = f" {m.unit}" if m.unit else ""
        rows.append((m.name, f"{m.value:.3e}{unit}", f"{'>=' if m.at_least else '<='} {m.tolerance:.1e}{unit}",
                     verdict(m.passed), m.reason))
        classes.append(None if m.passed else "fail")
    return table(("metric", "value", "tolerance", "", "why that tolerance"), rows, classes)


def summary_section(results: Sequence[CaseResult], seconds: float, command: str) -> Facts:
    n_fail = sum(not r.passed for r in results)
    n_metrics = sum(len(r.metrics) for r in results)
    n_failed_metrics = sum(not m.passed for r in results for m in r.metrics)
    v = versions()
    host = machine()
    items = [
        ("verdict", tag("span", f"{len(results) - n_fail} passed, {n_fail} failed", cls="verdict " +
                        ("pass" if n_fail == 0 else "fail"))),
        ("cases, metrics", f"{len(results)} cases, {n_metrics} metrics ({n_failed_metrics} failed)"),
        ("wall time", f"{seconds:.1f} s (the cases' own times add up to {sum(r.seconds for r in results):.1f} s)"),
        ("command", command or "-"),
        ("finished", datetime.datetime.now().astimezone().replace(microsecond=0).isoformat()),
        ("machine", f"{host['host']}: {host['processor']}, {host['cores']} cores; {host['system']}"),
        ("versions", ", ".join(f"{k} {val}" for k, val in v.items())),
    ]
    return Facts("Summary", items)


def overview_section(results: Sequence[CaseResult]) -> Table:
    rows, classes = [], []
    for r in in_report_order(results):
        worst = max(r.metrics, key=lambda m: (math.isnan(margin(m)), margin(m)), default=None)
        rows.append((tag("a", r.name, href=f"#{case_anchor(r.name)}"), r.group or "-", verdict(r.passed),
                     f"{r.seconds:.2f}", f"{sum(m.passed for m in r.metrics)} / {len(r.metrics)}",
                     "-" if worst is None else f"{worst.name} ({number(margin(worst), 2)} of its tolerance)", r.source))
        classes.append(None if r.passed else "fail")
    return Table("Cases", ("case", "group", "", "time (s)", "metrics passed", "closest to its tolerance", "source"),
                 rows, note="Failed cases first. A metric's share of its tolerance: value / tolerance (tolerance / "
                            "value for a lower bound); it fails above 1.", row_classes=classes)


def suite_page(results: Sequence[CaseResult], seconds: float, descriptions: dict[str, str] | None = None,
               extra: Sequence[Section] = (), command: str = "") -> Page:
    """The page of ``results`` (see the module docstring): ``descriptions`` case name -> what it checks,
    ``extra`` sections after the cases, ``command`` the command line that ran them."""
    descriptions = descriptions or {}
    page = Page("bifilar-validate: validation report", "Every case's metrics against tolerances that come from "
                "reasoning (integrator tolerance, constraint softness), the reason stated beside each.")
    page.add(summary_section(results, seconds, command), overview_section(results))
    page.add(*(CaseSection(r, descriptions.get(r.name, "")) for r in in_report_order(results)))
    page.add(*extra)
    return page


def write_suite_html(path: str | Path, results: Sequence[CaseResult], seconds: float,
                     descriptions: dict[str, str] | None = None, extra: Sequence[Section] = (),
                     command: str = "") -> Path:
    """Write :func:`suite_page` to ``path`` whole or not at all."""
    return suite_page(results, seconds, descriptions, extra, command).write(path)
