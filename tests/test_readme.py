"""The README holds exactly the two set-up commands, and CI runs them as the README prints them, in a
fresh venv with the newest allowed versions and an empty numba cache, the tests first (.ci/run,
.ci/readme_commands.py)."""

import runpy
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
READER = runpy.run_path(str(ROOT / ".ci" / "readme_commands.py"))


def test_the_readme_holds_the_two_set_up_commands():
    printed = subprocess.run([sys.executable, str(ROOT / ".ci" / "readme_commands.py")], capture_output=True,
                             text=True, check=True).stdout.splitlines()
    assert printed == ["pip install -e . && python -m validate all",
                       "pip install -e '.[test]' && python -m pytest -n auto"]


@pytest.mark.parametrize("text", ["# x\n", "## Set up and run\n\n```bash\na\n```\n",
                                  "## Set up and run\n\n```bash\na\nb\n```\n\n```bash\nc\n```\n"])
def test_a_readme_without_exactly_two_one_line_blocks_is_refused(text):
    with pytest.raises(ValueError):
        READER["commands"](text)


def test_ci_runs_them_in_a_fresh_venv_with_the_newest_versions():
    ci = (ROOT / ".ci" / "run").read_text()
    for step in ("python3 .ci/readme_commands.py", 'python3 -m venv "$work/venv"', 'source "$work/venv/bin/activate"',
                 "pip install -q --upgrade --upgrade-strategy eager -e '.[test]'", 'bash -euo pipefail -c "${commands[i]}"',
                 'export NUMBA_CACHE_DIR="$work/numba"',
                 "bash .ci/chromium", "bash .ci/wheel"):
        assert step in ci, step
    assert "--system-site-packages" not in ci
