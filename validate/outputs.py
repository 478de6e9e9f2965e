"""Output paths checked before a command's work: a file that can be written, a folder that can hold
files, and no two outputs of one command on the same path.

Each problem is an :class:`OSError` naming the path as given (the command line prints it as one
line, ``PATH: cannot write (REASON)``, exit status 2), raised before the run, so that a bad path
fails at once and not after minutes of work. The reason is the real one: a regular file where a
folder is needed is said to be one (the operating system would say "File exists" of the file, or
"Not a directory" of a path under it).
"""

from __future__ import annotations

import errno
import os
from pathlib import Path


def check_writable(path: str | Path) -> None:
    """Raise :class:`OSError` (naming ``path``) unless a file can be written at ``path``: not a folder,
    its folder exists or can be made, and is writable."""
    path = Path(path)
    if path.is_dir():
        raise IsADirectoryError(errno.EISDIR, "is a directory", str(path))
    _make_folder(path.parent, path)
    if len(path.name.encode()) > 255:
        raise OSError(errno.ENAMETOOLONG, "File name too long", str(path))


def check_folder(path: str | Path) -> None:
    """Raise :class:`OSError` (naming ``path``) unless ``path`` is, or can be made, a writable folder;
    it is made."""
    _make_folder(Path(path), Path(path))


def distinct_outputs(outputs: dict[str, str]) -> tuple[str, str] | None:
    """The first two options (names as keys, paths as values) that name the same path, else None: one
    output would overwrite the other, and the first written would be lost."""
    seen: dict[str, str] = {}
    for name, value in outputs.items():
        key = os.path.realpath(value)
        if key in seen:
            return seen[key], name
        seen[key] = name
    return None


def _make_folder(folder: Path, named: Path) -> None:
    """Make ``folder`` (and its parents), refusing, as ``named``, an existing ancestor that is not a
    folder, a folder that cannot be made, or one that cannot be written."""
    existing = next((p for p in (folder, *folder.parents) if p.exists()), None)
    if existing is not None and not existing.is_dir():
        where = "is" if existing == named else f"is under {existing}, which is"
        raise NotADirectoryError(errno.ENOTDIR, f"{where} a {_kind(existing)}, not a folder", str(named))
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise OSError(exc.errno, exc.strerror or str(exc), str(named)) from None
    if not os.access(folder, os.W_OK | os.X_OK):
        raise PermissionError(errno.EACCES, "Permission denied", str(named))


def _kind(path: Path) -> str:
    return "regular file" if path.is_file() else "special file (a device, pipe or socket)"
