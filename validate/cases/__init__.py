"""Validation cases. Importing :func:`load_all` registers every module in this package."""

from __future__ import annotations

import importlib
import pkgutil


def load_all() -> None:
    """Import every case module (each registers its cases on import)."""
    for info in pkgutil.iter_modules(__path__):
        importlib.import_module(f"{__name__}.{info.name}")
