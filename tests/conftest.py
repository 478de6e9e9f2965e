"""Shared fixtures: the shipped rigs and their Kane models; hypothesis profiles; no compile notes inside
the tests.

Hypothesis profiles, registered once here (a test sets only ``max_examples``, the size its assertion
needs): ``ci``, the default, draws the same examples on every run (derandomized, no example database),
so that the suite fails on a change, not on a new draw: a draw that finds a defect becomes an
``@example``; ``fuzz`` draws afresh, for the long profile (``python -m pytest -m fuzz``, or
``HYPOTHESIS_PROFILE=fuzz`` for every property test). Neither has a deadline: an example's time depends on
the machine's load and on whether numba has compiled yet.

On an empty numba cache (a fresh machine running only the test command) the kernels compile at
whichever test first loops over them, and their one-line note on stderr would land in that test's
output, failing any test that asserts a one-line error or an empty stderr, depending on the order the
tests run in. The notes are therefore marked as given for the whole session; tests/test_jit.py checks
them with a fresh record of its own.

The long tiers, ``fuzz`` and ``long``, run only when asked for by name (``-m fuzz``, ``-m long``):
:func:`pytest_collection_modifyitems` deselects them otherwise, so that a tier chosen by another ``-m``
(the quick tier's ``-m "not slow"``, which replaces any ``-m`` of the default options) still leaves them
out.

On an empty numba cache each pytest-xdist worker first compiles its share of the kernels
(:func:`bifilar.kernels.shares`) and loads the others' from the cache as its tests meet them: left to
compile at first use, the two workers met the same kernels at about the same time and both compiled
them. A run without workers compiles at first use, as before.

One BLAS thread per test worker, as ``python -m validate`` sets it (``validate/__main__.py``): set here,
before anything imports numpy, so that pytest's two workers do not each run OpenBLAS's threads on the two
cores.
"""

import os
import re
import sys
from pathlib import Path

for _variable in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_variable, "1")

import pytest  # noqa: E402
from hypothesis import HealthCheck, settings  # noqa: E402

sys.path.insert(0, str(Path(__file__).parent))  # helper modules beside the tests (thesis_appendix)

from bifilar import jit, kernels  # noqa: E402
from bifilar.motion.kane import KaneModel  # noqa: E402
from validate.assets import rig  # noqa: E402

jit._announced.add(jit.EVERYTHING)  # module docstring

# Random rigs are built by filtering draws (a degenerate one is discarded) and some examples take seconds.
_QUIET = [HealthCheck.filter_too_much, HealthCheck.too_slow, HealthCheck.data_too_large]
settings.register_profile("ci", derandomize=True, database=None, deadline=None, suppress_health_check=_QUIET)
settings.register_profile("fuzz", derandomize=False, database=None, deadline=None, suppress_health_check=_QUIET)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))


def pytest_sessionstart(session):
    worker = os.environ.get("PYTEST_XDIST_WORKER", "")  # gw0, gw1, ...: a worker of -n N (module docstring)
    if worker.startswith("gw") and kernels.cold():
        count = int(os.environ.get("PYTEST_XDIST_WORKER_COUNT", "1"))
        kernels.precompile(kernels.shares(count)[int(worker[2:]) % count])


LONG_TIERS = ("fuzz", "long")


def left_out(markexpr: str) -> set[str]:
    """The long tiers a run with ``-m markexpr`` leaves out: those its expression does not name."""
    return {tier for tier in LONG_TIERS if not re.search(rf"\b{tier}\b", markexpr or "")}


def pytest_collection_modifyitems(config, items):
    tiers = left_out(config.getoption("markexpr"))
    kept, dropped = [], []
    for item in items:
        (dropped if any(item.get_closest_marker(t) for t in tiers) else kept).append(item)
    if dropped:
        config.hook.pytest_deselected(items=dropped)
        items[:] = kept


@pytest.fixture(params=["plate", "parallel", "asymmetric", "sidesway"])
def any_rig(request):
    return rig(request.param)


@pytest.fixture
def plate_model():
    return KaneModel.from_rig(rig("plate"))


@pytest.fixture
def asym_model():
    return KaneModel.from_rig(rig("asymmetric"))
