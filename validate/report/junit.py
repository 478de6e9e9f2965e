"""JUnit XML of a suite run, the layout that CI servers read (Jenkins, GitLab, GitHub actions'
JUnit readers): ``<testsuites>`` holding one ``<testsuite>`` with its counts, the machine's name and
the package versions as properties, and one ``<testcase>`` per case.

A case is ``<testcase name=CASE classname=validate.cases.GROUP time=SECONDS>`` (GROUP: the module
the case is defined in, e.g. ``trifilar``); a failed metric is listed in its ``<failure>`` (value,
tolerance, reason), a case that raised has an ``<error>`` with the traceback, and every metric is in
its ``<system-out>``. Cases are in the order they ran in, so two identical runs give files that differ
only in their times (``time``, ``timestamp``).
"""

from __future__ import annotations

import datetime
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from ..trajectory import atomic_write_text
from .environment import machine, versions

if TYPE_CHECKING:
    from ..suite import CaseResult


def metric_line(m) -> str:
    """``name: value unit (<= tolerance: pass) reason``, one metric on one line."""
    unit = f" {m.unit}" if m.unit else ""
    cmp = ">=" if m.at_least else "<="
    return f"{m.name}: {m.value:.6e}{unit} ({cmp} {m.tolerance:.3e}: {'pass' if m.passed else 'FAIL'}) {m.reason}"


def junit_xml(results: Sequence[CaseResult], seconds: float, name: str = "validate") -> str:
    """The XML text (see the module docstring); ``seconds`` is the run's wall time."""
    failures = sum(1 for r in results if not r.passed and r.error is None)
    errors = sum(1 for r in results if r.error is not None)
    counts = {"tests": str(len(results)), "failures": str(failures), "errors": str(errors), "skipped": "0",
              "time": f"{seconds:.3f}"}
    root = ET.Element("testsuites", {"name": name, **counts})
    stamp = datetime.datetime.now(datetime.timezone.utc).replace(microsecond=0).isoformat()
    suite = ET.SubElement(root, "testsuite", {"name": name, **counts, "timestamp": stamp,
                                              "hostname": machine()["host"]})
    props = ET.SubElement(suite, "properties")
    for key, value in versions().items():
        ET.SubElement(props, "property", {"name": key, "value": value})
    for r in results:
        case = ET.SubElement(suite, "testcase", {"name": r.name, "classname": f"validate.cases.{r.group or 'case'}",
                                                 "time": f"{r.seconds:.3f}"})
        failed = [m for m in r.metrics if not m.passed]
        if r.error is not None:
            first = r.error.splitlines()[0]
            ET.SubElement(case, "error", {"message": first, "type": first.split(":", 1)[0]}).text = r.error
        elif not r.passed:
            message = (f"{len(failed)} of {len(r.metrics)} metrics failed: " + "; ".join(m.name for m in failed)
                       if failed else "the case returned no metrics")
            ET.SubElement(case, "failure", {"message": message, "type": "MetricFailed"}).text = \
                "\n".join(metric_line(m) for m in failed)
        if r.metrics:
            ET.SubElement(case, "system-out").text = f"{r.source}\n" + "\n".join(metric_line(m) for m in r.metrics)
    ET.indent(root)
    return ET.tostring(root, encoding="unicode", xml_declaration=True) + "\n"


def write_junit(path: str | Path, results: Sequence[CaseResult], seconds: float) -> Path:
    """Write :func:`junit_xml` to ``path`` whole or not at all."""
    atomic_write_text(path, junit_xml(results, seconds))
    return Path(path)
