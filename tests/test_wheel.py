"""The wheel carries the models: setup.py's package-data globs cover every shipped model file, and CI
builds, installs and runs the wheel (.ci/wheel: a fresh venv, another folder, the wheel's own code)."""

import fnmatch
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_every_model_file_is_package_data():
    """Every tracked file under models/ lies in a folder setup.py names as a package and matches its
    package-data globs (a file that does not is left out of the wheel without a word)."""
    namespace: dict = {"__file__": str(ROOT / "setup.py")}
    source = (ROOT / "setup.py").read_text().split("setup(")[0]  # the constants, without building
    exec(source.replace("from setuptools import find_packages, setup", ""), namespace)
    globs, packages = namespace["MODEL_FILES"], set(namespace["MODEL_PACKAGES"])
    tracked = subprocess.run(["git", "ls-files", "models"], cwd=ROOT, capture_output=True, text=True).stdout.split()
    assert tracked, "models/ is not tracked"
    missing = [p for p in tracked
               if ".".join(("validate._models",) + Path(p).relative_to("models").parent.parts) not in packages
               or not any(fnmatch.fnmatch(Path(p).name, g) for g in globs)]
    assert missing == [], missing


def test_ci_builds_installs_and_runs_the_wheel_elsewhere():
    run = (ROOT / ".ci" / "run").read_text()
    wheel = (ROOT / ".ci" / "wheel").read_text()
    assert "bash .ci/wheel" in run
    for step in ('python3 -m venv "$work/venv"', 'pip" wheel . --no-deps', 'pip" install -q "$work"/dist/*.whl',
                 'cd "$work"', "-m validate list --rigs", "-m validate modes plate", "-m validate case seed001-terms",
                 "startswith(sys.prefix)"):
        assert step in wheel, step
    # The wheel brings its dependencies: no reuse of the machine's packages, no install without them.
    assert "--system-site-packages" not in wheel and "--no-deps --force-reinstall" not in wheel


def test_assets_find_the_checkouts_models():
    from validate import assets

    assert assets.MODELS == ROOT / "models" and (assets.RIGS / "plate.toml").is_file()
