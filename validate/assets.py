"""Where the shipped models live, and loading the shipped rig files by name.

In a checkout (or an editable install) the models are the source tree's ``models/`` folder beside the
packages; in an installed wheel they are the package data ``validate/_models`` (``setup.py`` maps the
folder in). :data:`MODELS` is whichever exists, the checkout first.
"""

from __future__ import annotations

from pathlib import Path

from bifilar.rig import Rig, load_rig


def _models() -> Path:
    here = Path(__file__).resolve().parent
    for folder in (here.parent / "models", here / "_models"):
        if (folder / "rigs").is_dir():
            return folder
    raise FileNotFoundError(f"the shipped models are missing: neither {here.parent / 'models'} nor {here / '_models'}")


MODELS = _models()
RIGS = MODELS / "rigs"


def rig(name: str) -> Rig:
    """The rig file ``models/rigs/<name>.toml``."""
    return load_rig(RIGS / f"{name}.toml")
