"""Package layout that pyproject.toml cannot say: the shipped models/ folder travels inside the wheel
as the package data ``validate/_models`` (validate/assets.py finds it there when the source tree's
models/ is not beside the package), so that ``pip install .`` carries the rigs and MJCF models."""

from setuptools import find_packages, setup

MODEL_FILES = ["*.md", "*/*.toml", "*/*.xml", "*/*.md", "*/*.py"]

setup(
    packages=find_packages(include=["bifilar", "bifilar.*", "validate", "validate.*"]) + ["validate._models"],
    package_dir={"validate._models": "models"},
    package_data={"validate._models": MODEL_FILES},
)
