"""Package layout that pyproject.toml cannot say: the shipped models/ folder travels inside the wheel
as the package data ``validate/_models`` (validate/assets.py finds it there when the source tree's
models/ is not beside the package), so that ``pip install .`` carries the rigs and MJCF models.

Each folder of models/ is named as a package of its own (``validate._models.rigs``, ...): setuptools
warns of, and plans to ignore, a folder that Python can import but ``packages`` does not list."""

from pathlib import Path

from setuptools import find_packages, setup

MODEL_FOLDERS = sorted(p.name for p in (Path(__file__).parent / "models").iterdir()
                       if p.is_dir() and p.name.isidentifier() and not p.name.startswith("_"))
MODEL_PACKAGES = ["validate._models"] + [f"validate._models.{name}" for name in MODEL_FOLDERS]
MODEL_FILES = ["*.md", "*.toml", "*.xml", "*.py"]

setup(
    packages=find_packages(include=["bifilar", "bifilar.*", "validate", "validate.*"]) + MODEL_PACKAGES,
    package_dir={"validate._models": "models"},
    package_data={name: MODEL_FILES for name in MODEL_PACKAGES},
)
