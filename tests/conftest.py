"""Shared fixtures: the shipped rigs and their Kane models; no compile notes inside the tests.

On an empty numba cache (a fresh machine running only the test command) the kernels compile at
whichever test first loops over them, and their one-line note on stderr would land in that test's
output, failing any test that asserts a one-line error or an empty stderr, depending on the order the
tests run in. The notes are therefore marked as given for the whole session; tests/test_jit.py checks
them with a fresh record of its own.
"""

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent))  # helper modules beside the tests (thesis_appendix)

from bifilar import jit  # noqa: E402
from bifilar.motion.kane import KaneModel  # noqa: E402
from validate.assets import rig  # noqa: E402

jit._announced.add(jit.EVERYTHING)  # module docstring


@pytest.fixture(params=["plate", "parallel", "asymmetric", "sidesway"])
def any_rig(request):
    return rig(request.param)


@pytest.fixture
def plate_model():
    return KaneModel.from_rig(rig("plate"))


@pytest.fixture
def asym_model():
    return KaneModel.from_rig(rig("asymmetric"))
