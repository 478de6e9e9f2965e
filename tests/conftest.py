"""Shared fixtures: the shipped rigs and their Kane models."""

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent))  # helper modules beside the tests (thesis_appendix)

from bifilar.motion.kane import KaneModel  # noqa: E402
from validate.assets import rig  # noqa: E402


@pytest.fixture(params=["plate", "parallel", "asymmetric", "sidesway"])
def any_rig(request):
    return rig(request.param)


@pytest.fixture
def plate_model():
    return KaneModel.from_rig(rig("plate"))


@pytest.fixture
def asym_model():
    return KaneModel.from_rig(rig("asymmetric"))
