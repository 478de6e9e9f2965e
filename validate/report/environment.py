"""What a run ran on: the machine and the versions of the packages the numbers depend on."""

from __future__ import annotations

import os
import platform
from importlib import metadata

PACKAGES = ("mujoco", "numpy", "scipy", "numba", "rerun-sdk")


def versions() -> dict[str, str]:
    """python and each of :data:`PACKAGES` -> its version ("not installed" when absent)."""
    out = {"python": platform.python_version()}
    for name in PACKAGES:
        try:
            out[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            out[name] = "not installed"
    return out


def machine() -> dict[str, str]:
    """Host name, operating system, processor and its number of cores."""
    return {"host": platform.node() or "unknown", "system": platform.platform(), "processor": _cpu(),
            "cores": str(os.cpu_count() or "unknown")}


def _cpu() -> str:
    """The processor's model name (Linux: /proc/cpuinfo), else what ``platform`` says."""
    try:
        with open("/proc/cpuinfo") as fh:
            for line in fh:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine() or "unknown"
