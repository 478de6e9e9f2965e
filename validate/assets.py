"""Where the shipped models live, and the shipped rig, sweep and suspension files by name.

In a checkout (or an editable install) the models are the source tree's ``models/`` folder beside the
packages; in an installed wheel they are the package data ``validate/_models`` (``setup.py`` maps the
folder in). :data:`MODELS` is whichever exists, the checkout first.

:func:`resolve` is the one place where a command's input file argument becomes a path: a path that
exists always wins; otherwise a shipped file by name (``plate`` is ``models/rigs/plate.toml``,
``bench_plate`` given to ``sweep`` is ``models/sweeps/bench_plate.toml``) or by its path inside
``models/`` (``models/rigs/plate.toml`` from any folder, also from an installed wheel).
"""

from __future__ import annotations

import re
from pathlib import Path

from bifilar.rig import Rig, RigError, load_rig


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


# The folders (inside MODELS) whose TOML files each kind of input names, searched in this order.
KINDS = {
    "rig": ("rigs",),
    "sweep": ("sweeps", "solar_boat"),
    "suspension": ("solar_boat",),
}
# Which solar_boat/ files are of which kind (the folder also holds the boat's parts).
_SOLAR_BOAT = {"sweep": ("hall", "configurations"), "suspension": ("suspension",)}


def shipped(kind: str) -> dict[str, Path]:
    """The shipped files of ``kind`` (a key of :data:`KINDS`): name -> path, in listing order. The name
    is the file's stem; a stem that an earlier folder already holds is not repeated."""
    found: dict[str, Path] = {}
    for folder in KINDS[kind]:
        paths = sorted((MODELS / folder).glob("*.toml"))
        if folder == "solar_boat":
            paths = [p for p in paths if p.stem in _SOLAR_BOAT[kind]]
        for path in paths:
            found.setdefault(path.stem, path)
    return found


def resolve(text: str, kind: str) -> str:
    """The file a command argument means (see the module docstring): ``text`` itself when it exists
    (or cannot be a name), else the shipped file it names. A bare name that names nothing is a
    :class:`RigError` on ``file`` listing where names come from."""
    if not text or Path(text).exists():
        return text
    inside = re.sub(r"^(\./)?models/", "", text)
    for candidate in (MODELS / inside, MODELS / f"{inside}.toml"):
        if inside != text or "/" in text:
            if candidate.is_file():
                return str(candidate)
    if "/" not in text and not text.endswith(".toml"):
        path = shipped(kind).get(text)
        if path is not None:
            return str(path)
        raise RigError(text, "file", f"no such file, and no shipped {kind} of that name "
                                     f"('python -m validate list --rigs' lists them)")
    return text


def description(path: Path, width: int = 72) -> str:
    """A shipped file's leading comment up to its first sentence end (or a colon after the first 30
    characters) outside parentheses, at most ``width`` characters (cut at a word, with '...'): one line for ``list --rigs``."""
    words = []
    for line in path.read_text(encoding="utf-8").splitlines():
        if not line.startswith("#"):
            break
        words.append(line.lstrip("#").strip())
    text = re.sub(r"\s*\(seed [^)]*\)", "", " ".join(" ".join(words).split()))  # the seeds are cited elsewhere
    depth = 0
    for i, char in enumerate(text):
        depth += {"(": 1, ")": -1}.get(char, 0)
        if depth == 0 and char in ".:" and (i + 1 == len(text) or (text[i + 1] == " " and (char == ":" and i > 30 or text[i + 2 : i + 3].isupper()))):
            text = text[:i]
            break
    if len(text) > width:
        text = text[: text.rfind(" ", 0, width - 3)].rstrip(",;") + " ..."
    return text
