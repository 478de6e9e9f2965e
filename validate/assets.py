"""Where the shipped models live, and loading the shipped rig files by name."""

from __future__ import annotations

from pathlib import Path

from bifilar.rig import Rig, load_rig

MODELS = Path(__file__).resolve().parents[1] / "models"
RIGS = MODELS / "rigs"


def rig(name: str) -> Rig:
    """The rig file ``models/rigs/<name>.toml``."""
    return load_rig(RIGS / f"{name}.toml")
