"""Running registered cases: in parallel worker processes, into a table and a JSON report.

A case that raises is reported as failed with the exception as its one metric, so one broken case
never hides the others' results.
"""

from __future__ import annotations

import fnmatch
import json
import sys
import time
import traceback
from concurrent.futures import ProcessPoolExecutor, as_completed, wait
from dataclasses import asdict, dataclass, field
from typing import Callable, Sequence

from bifilar import kernels

from .registry import REGISTRY, Case, CaseContext, Metric

# The compile time of every kernel the cases use, empty cache, 2 cores: each worker compiles its share
# in ~28 s of CPU (python benchmarks/compile_cpu.py shares 2), and the first run took 64.5 s against
# 33.8 s warm on a quiet machine (python benchmarks/first_run.py all); a busy machine takes longer.
COMPILE_SECONDS = "30-60"


@dataclass
class CaseResult:
    """One case's outcome. ``group`` is the module the case is defined in (``trifilar``); the runs the
    case kept are in ``trajectories`` (for a recording) or ``traces`` (for a report:
    :func:`validate.report.traces.comparisons`), only when asked for."""

    name: str
    source: str
    passed: bool
    seconds: float
    metrics: list[Metric]
    error: str | None = None
    trajectories: list = field(default_factory=list)
    group: str = ""
    notes: list[str] = field(default_factory=list)
    traces: list = field(default_factory=list)


# What a suite run hands its results to, besides the table: e.g. a JUnit or an HTML writer; called
# with the results in the order of the cases and the run's wall time (s).
Report = Callable[[list[CaseResult], float], object]


def registered(slow: bool = False) -> list[Case]:
    """Every registered case, fast ones only unless ``slow``."""
    from .cases import load_all

    load_all()
    return [c for c in REGISTRY.values() if slow or "slow" not in c.tags]


def select(cases: list[Case], pattern: str | None = None, tags: list[str] | None = None) -> list[Case]:
    """The cases whose name contains ``pattern`` (or matches it as a glob when it has ``* ? [``) and
    that carry one of ``tags``; none selected is a usage error."""
    from .argtypes import UsageError

    chosen = cases
    if pattern:
        glob = any(ch in pattern for ch in "*?[")
        chosen = [c for c in chosen if (fnmatch.fnmatchcase(c.name, pattern) if glob else pattern in c.name)]
    if tags:
        chosen = [c for c in chosen if c.tags & set(tags)]
    if not chosen:
        known = sorted({t for c in cases for t in c.tags})
        asked = " ".join(([f"-k {pattern}"] if pattern else []) + [f"--tag {t}" for t in tags or []])
        raise UsageError(f"all: no case matches {asked} (tags: {', '.join(known)}; see python -m validate list)")
    return chosen


def find(name: str) -> Case:
    from .argtypes import UsageError

    cases = {c.name: c for c in registered(slow=True)}
    if name not in cases:
        raise UsageError(f"case: unknown case {name!r} (see python -m validate list)")
    return cases[name]


def run_case(name: str, keep_trajectories: bool = False, keep_traces: bool = False) -> CaseResult:
    """Run one case by name (in this process); with ``keep_trajectories`` its kept runs come back
    whole, with ``keep_traces`` as the report's comparisons."""
    c = find(name)
    ctx = CaseContext()
    start = time.perf_counter()
    try:
        metrics = list(c.run(ctx))
        error = None
    except Exception as exc:  # reported, not raised: see the module docstring
        metrics, error = [], f"{type(exc).__name__}: {exc}\n{traceback.format_exc()}"
    seconds = time.perf_counter() - start
    passed = error is None and bool(metrics) and all(m.passed for m in metrics)
    traces = []
    if keep_traces:
        from .report.traces import comparisons

        try:
            traces = comparisons(ctx.trajectories)
        except Exception as exc:  # the case's verdict stands; the report says why it has no figure
            ctx.notes.append(f"the report could not draw this case's runs ({type(exc).__name__}: {exc})")
    return CaseResult(c.name, c.source, passed, seconds, metrics, error, ctx.trajectories if keep_trajectories else [],
                      c.run.__module__.rsplit(".", 1)[-1], list(ctx.notes), traces)


def _announce_compile() -> bool:
    """One note, here in the main process, if the cases' kernels will compile (the workers keep quiet);
    whether they will."""
    import importlib

    from bifilar import jit, kernels

    modules = [importlib.import_module(g.module) for g in kernels.GROUPS.values()]
    return jit.announce_modules("the Kane, N-wire, TMT and pose kernels", modules, seconds=COMPILE_SECONDS)


def run_cases(cases: list[Case], jobs: int = 2, json_path: str | None = None,
              on_result: Callable[[CaseResult], object] | None = None, progress: bool = False,
              reports: Sequence[Report] = (), traces: bool = False) -> int:
    """Run the cases, print the table (and write the JSON report); 0 if all passed, else 1.
    ``on_result`` is called on every result in this process (e.g. to record it); only then are the
    trajectories carried back from the workers. ``reports`` are then handed every result and the
    wall time; with ``traces`` the results carry the comparisons a report draws. With ``progress``,
    each case is announced on stderr as it finishes, with its verdict and wall time."""
    names = [c.name for c in cases]
    keep = on_result is not None
    cold = _announce_compile()
    start = time.perf_counter()
    done: dict[str, CaseResult] = {}

    def finished(result: CaseResult) -> None:
        done[result.name] = result
        if progress:
            verdict = "pass" if result.passed else "FAIL"
            print(f"[{len(done)}/{len(names)}] {result.name}: {verdict} in {result.seconds:.1f} s "
                  f"({time.perf_counter() - start:.0f} s elapsed)", file=sys.stderr, flush=True)

    if jobs > 1 and len(names) > 1:
        with ProcessPoolExecutor(max_workers=jobs) as pool:
            if cold:  # each worker compiles one share of the kernels, none twice (bifilar.kernels)
                for done_share in wait([pool.submit(kernels.precompile, share) for share in kernels.shares(jobs)]).done:
                    done_share.result()
            for future in as_completed([pool.submit(run_case, n, keep, traces) for n in names]):
                finished(future.result())
    else:
        for n in names:
            finished(run_case(n, keep, traces))
    results = [done[n] for n in names]
    seconds = time.perf_counter() - start
    print(format_table(results))
    if on_result is not None:
        for r in results:
            on_result(r)
    passed = all(r.passed for r in results)
    if json_path:
        from .trajectory import atomic_write_text

        atomic_write_text(json_path, json.dumps(report(results), indent=1) + "\n")
    for write in reports:
        write(results, seconds)
    return 0 if passed else 1


def report(results: list[CaseResult]) -> dict:
    """The JSON report: ``{"passed", "cases": [{"name", "source", "passed", "metrics": [...]}]}``."""
    return {
        "passed": all(r.passed for r in results),
        "cases": [
            {
                "name": r.name,
                "source": r.source,
                "passed": r.passed,
                "seconds": round(r.seconds, 3),
                "error": r.error.splitlines()[0] if r.error else None,
                "metrics": [asdict(m) for m in r.metrics],
            }
            for r in results
        ],
    }


def format_table(results: list[CaseResult]) -> str:
    """One row per metric: case, metric, measured value, tolerance, verdict; then a summary."""
    rows = [("case", "metric", "value", "tolerance", "", "reason")]
    for r in results:
        if r.error:
            rows.append((r.name, "error", r.error.splitlines()[0][:60], "", "FAIL", ""))
            print(r.error, file=sys.stderr)
        for m in r.metrics:
            cmp = ">=" if m.at_least else "<="
            unit = f" {m.unit}" if m.unit else ""
            rows.append((r.name, m.name, f"{m.value:.3e}{unit}", f"{cmp} {m.tolerance:.1e}", "pass" if m.passed else "FAIL", m.reason))
    widths = [max(len(row[i]) for row in rows) for i in range(5)]
    lines = ["  ".join(cell.ljust(w) for cell, w in zip(row[:5], widths)) + "  " + row[5] for row in rows]
    n_fail = sum(not r.passed for r in results)
    n_metrics = sum(len(r.metrics) for r in results)
    lines.append(f"{len(results) - n_fail} passed, {n_fail} failed ({len(results)} cases, {n_metrics} metrics)")
    return "\n".join(lines)
