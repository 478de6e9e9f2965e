"""Reading TOML input files field by field, with one-line errors that name file, field and problem.

Every problem is raised as :class:`RigError` (``source: field: problem``), which the command line
prints as one line before exiting with status 2.
"""

from __future__ import annotations

import math
import os
import re
import stat
import tomllib
from pathlib import Path

import numpy as np


class RigError(ValueError):
    """An input that cannot be used: ``source: field: problem``."""

    def __init__(self, source: str, field_name: str, problem: str):
        self.source, self.field, self.problem = source, field_name, problem
        super().__init__(f"{source}: {field_name}: {problem}")


MAX_FILE_BYTES = 1 << 20  # an input file larger than 1 MiB is not a rig (the shipped ones are ~1 kB)


def read_text_file(path: str | Path, max_bytes: int = MAX_FILE_BYTES) -> str:
    """The UTF-8 text of a regular file (a leading byte-order mark dropped), refusing what is not a
    regular file (a named pipe would block forever, a device never end) and files over ``max_bytes``;
    every problem is a :class:`RigError` on field ``file``. Opened non-blocking, so that a pipe is
    refused without waiting for a writer."""
    src = str(path)
    if not src:
        raise RigError("''", "file", "no file name given (an empty argument)")
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
    except OSError as exc:
        raise RigError(src, "file", f"cannot read ({exc.strerror})") from None
    info = os.fstat(fd)
    if not stat.S_ISREG(info.st_mode):  # checked before fdopen, which refuses a folder naming the descriptor
        os.close(fd)
        raise RigError(src, "file", "is not a regular file (a pipe, device or folder cannot be read as input)")
    with os.fdopen(fd, "rb") as fh:
        if info.st_size > max_bytes:
            raise RigError(src, "file", f"is {info.st_size} bytes, more than the {max_bytes} an input file may have")
        try:
            data = fh.read(max_bytes + 1)
        except OSError as exc:
            raise RigError(src, "file", f"cannot read ({exc.strerror})") from None
    if len(data) > max_bytes:  # grew while read
        raise RigError(src, "file", f"is more than the {max_bytes} bytes an input file may have")
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise RigError(src, "file", f"not UTF-8 text (byte {exc.start})") from None


def read_toml(path: str | Path) -> dict:
    """Parse a TOML file; an unreadable, oversized or malformed file is a :class:`RigError`."""
    src = str(path)
    text = read_text_file(path)
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise RigError(src, "toml", f"not valid TOML ({exc})") from None
    except RecursionError:
        raise RigError(src, "toml", "nested too deeply (arrays or tables within each other)") from None
    except ValueError as exc:  # e.g. an integer of more than 4300 digits (Python's conversion limit)
        raise RigError(src, "toml", f"not usable ({exc})") from None


def rig_name(data: dict, source: str, default_name: str) -> str:
    """The file's ``name`` (it names output files: letters, digits, '_', '-', '.'), else ``default_name``."""
    name = data.get("name", default_name)
    if not isinstance(name, str) or not re.fullmatch(r"[A-Za-z0-9_.-]+", name) or name.startswith("."):
        raise RigError(source, "name", "must be letters, digits, '_', '-' or '.' (it names output files)")
    return name


def required(table: dict, key: str, source: str, prefix: str):
    if key not in table:
        raise RigError(source, prefix + key, "missing")
    return table[key]


def table(data: dict, key: str, source: str, mandatory: bool) -> dict:
    value = data.get(key)
    if value is None:
        if mandatory:
            raise RigError(source, key, "missing: give a [" + key + "] table")
        return {}
    if not isinstance(value, dict):
        raise RigError(source, key, "must be a table")
    return value


def no_unknown(table: dict, allowed: set, source: str, prefix: str) -> None:
    unknown = sorted(set(table) - allowed)
    if unknown:
        raise RigError(source, prefix + unknown[0], f"unknown key (allowed: {', '.join(sorted(allowed))})")


def number(value, source: str, name: str) -> float:
    """A finite int or float as a float (an integer too large for a float is refused, not raised)."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise RigError(source, name, f"must be a number, got {type(value).__name__}")
    try:
        x = float(value)
    except OverflowError:
        raise RigError(source, name, "must be finite, got an integer too large for a float") from None
    if not math.isfinite(x):
        raise RigError(source, name, f"must be finite, got {value}")
    return x


def within(value: float, low: float, high: float, source: str, name: str, unit: str, why: str = "") -> float:
    """``value`` if ``low <= value <= high``, else a :class:`RigError` quoting the range (and why)."""
    if not low <= value <= high:
        reason = f" ({why})" if why else ""
        raise RigError(source, name, f"{value:.6g} {unit} is outside {low:g} .. {high:g} {unit}{reason}".replace("  ", " "))
    return value


def positive(value, source: str, name: str) -> float:
    x = number(value, source, name)
    if x <= 0.0:
        raise RigError(source, name, f"must be positive, got {x:g}")
    return x


def non_negative(value, source: str, name: str) -> float:
    x = number(value, source, name)
    if x < 0.0:
        raise RigError(source, name, f"must be non-negative, got {x:g}")
    return x


def vector3(value, source: str, name: str) -> np.ndarray:
    if not isinstance(value, list) or len(value) != 3:
        raise RigError(source, name, "must be a list of three numbers")
    return np.array([number(v, source, f"{name}[{i}]") for i, v in enumerate(value)])


def inertia_tensor(value, source: str, free: int | None = None) -> np.ndarray:
    """The 3x3 tensor of ``body.inertia`` (three principal moments or a symmetric matrix), checked
    positive definite and for the triangle inequality of its principal moments.

    ``free`` (0, 1, 2): the diagonal entry that is being identified. It may be ``nan`` (unknown) or
    any positive value (a starting point only); the checks then apply to the rest of the tensor,
    and the identified tensor is checked by the caller once the entry is known.
    """
    name = "body.inertia"
    entry = (lambda v, n: _free_number(v, source, n)) if free is not None else (lambda v, n: number(v, source, n))
    if isinstance(value, list) and len(value) == 3 and all(isinstance(r, list) for r in value):
        rows = []
        for i, r in enumerate(value):
            if not isinstance(r, list) or len(r) != 3:
                raise RigError(source, f"{name}[{i}]", "must be a list of three numbers")
            rows.append([entry(v, f"{name}[{i}][{k}]") if (i, k) == (free, free) else number(v, source, f"{name}[{i}][{k}]")
                         for k, v in enumerate(r)])
        tensor = np.array(rows)
        known = np.where(np.isnan(tensor), 0.0, tensor)
        if not np.allclose(known, known.T, rtol=1e-12, atol=1e-12 * np.abs(known).max()):
            raise RigError(source, name, "is not symmetric")
    elif isinstance(value, list) and len(value) == 3:
        tensor = np.diag([entry(v, f"{name}[{i}]") if i == free else number(v, source, f"{name}[{i}]")
                          for i, v in enumerate(value)])
    else:
        raise RigError(source, name, "must be three principal moments or a symmetric 3x3 matrix")
    if free is not None:
        rest = [i for i in range(3) if i != free]
        sub = tensor[np.ix_(rest, rest)]
        if np.linalg.eigvalsh(sub)[0] <= 0.0:
            raise RigError(source, name, "the entries other than the identified moment are not positive definite")
        return 0.5 * (tensor + tensor.T)
    moments = np.linalg.eigvalsh(tensor)
    if moments[0] <= 0.0:
        raise RigError(source, name, f"is not positive definite (eigenvalues {fmt_values(moments)})")
    # A real body has I_a + I_b >= I_c for its principal moments; allow rounding in the last digit.
    if moments[0] + moments[1] < moments[2] * (1.0 - 1e-9):
        raise RigError(
            source, name, f"breaks the triangle inequality I1 + I2 >= I3 (principal moments {fmt_values(moments)})"
        )
    return 0.5 * (tensor + tensor.T)


def _free_number(value, source: str, name: str) -> float:
    """The identified moment: nan (unknown) or a positive start value."""
    if isinstance(value, float) and math.isnan(value):
        return value
    return positive(value, source, name)


def fmt_values(values) -> str:
    return "[" + ", ".join(f"{v:.6g}" for v in values) + "]"
