"""numba's on-disk cache kept out of the source tree, and one line on stderr when kernels compile.

The Kane, TMT and signal kernels are compiled by numba with ``cache=True``. Left to itself numba writes
its cache into ``__pycache__`` beside the sources (which fails silently in a read-only install, and
litters a checkout); :func:`use_user_cache` points it at the user's cache folder instead, unless
``NUMBA_CACHE_DIR`` is already set. The first run after an install or a change of a kernel compiles for
30-80 s; :func:`announce_compile` says so in one line instead of leaving the user in silence.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path


def user_cache_dir() -> Path:
    """``$XDG_CACHE_HOME/bifilar-validate/numba`` (default ``~/.cache/...``)."""
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "bifilar-validate" / "numba"


def use_user_cache() -> None:
    """Set ``NUMBA_CACHE_DIR`` to :func:`user_cache_dir` unless it is set (or numba is already
    imported, which has read it)."""
    if "NUMBA_CACHE_DIR" not in os.environ and "numba" not in sys.modules:
        os.environ["NUMBA_CACHE_DIR"] = str(user_cache_dir())


_announced: set[str] = set()


def announce_compile(what: str, *kernels) -> None:
    """One line on stderr (once per process and ``what``) if any of ``kernels`` (numba dispatchers with
    ``cache=True``) has no fresh cache entry, i.e. will be compiled at its first call. Call it just
    before the kernels' first use (it reads a small index file per kernel)."""
    if what in _announced:
        return
    _announced.add(what)
    if any(not _cached(k) for k in kernels):
        where = os.environ.get("NUMBA_CACHE_DIR", "__pycache__ beside the sources")
        print(f"note: compiling {what} with numba (first run after an install or a change: ~30-80 s; "
              f"cached in {where})", file=sys.stderr, flush=True)


def _cached(kernel) -> bool:
    try:
        return bool(kernel._cache._cache_file._load_index())
    except Exception:  # numba internals moved: assume cached rather than print a wrong note
        return True
