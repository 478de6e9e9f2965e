"""numba's on-disk cache kept out of the source tree, one line on stderr when kernels compile, and
kernels that compile only when they loop.

The Kane, TMT and signal kernels are compiled by numba with ``cache=True``. Left to itself numba writes
its cache into ``__pycache__`` beside the sources (which fails silently in a read-only install, and
litters a checkout); :func:`use_user_cache` points it at the user's cache folder instead (one
subfolder per state of the kernels' sources: :func:`kernels_key`), unless ``NUMBA_CACHE_DIR`` is already set, and compiles at LLVM's level 1 (:data:`OPT_LEVEL`). The first run
after an install or a change of a kernel compiles for 30-80 s; :func:`announce_compile` says so in one
line instead of leaving the user in silence, and a run on several processes shares the compiling out
between them, none compiling a kernel twice (:mod:`bifilar.kernels`).

One-shot work (one rig's rest pose and modes) need not wait for a compiler: :class:`LoopKernels`
runs a kernel module's functions as plain Python (numpy) until they are either cached on disk or
called often enough to be a loop (:data:`LOOP_CALLS`), and compiles them only then.
"""

from __future__ import annotations

import hashlib
import inspect
import os
import sys
import types
from pathlib import Path


def user_cache_dir() -> Path:
    """``$XDG_CACHE_HOME/bifilar-validate/numba/<kernels>`` (default ``~/.cache/...``), ``<kernels>``
    the :func:`kernels_key` of the installed sources."""
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "bifilar-validate" / "numba" / kernels_key()


def kernels_key(root: Path = Path(__file__).parent) -> str:
    """12 hex digits of a hash of every module under ``root`` (the package) that uses numba: its path
    and its text.

    numba checks a cached kernel against its own source file only: a kernel whose jitted callee in
    another module changed, or moved to another module, is loaded stale (a ModuleNotFoundError, or
    silently the old callee). A folder per state of the kernels' sources makes any such change a
    fresh cache (everything compiles once, as after an install); hashing ~15 files takes ~1 ms."""
    digest = hashlib.sha1()
    for path in sorted(root.rglob("*.py")):
        text = path.read_bytes()
        if b"numba" in text:
            digest.update(str(path.relative_to(root)).encode() + b"\0" + text)
    return digest.hexdigest()[:12]


# LLVM's optimisation level for the kernels. numba's default, 3, compiled the suite's kernels in 153 s
# on 2 busy cores, 2 in 99 s, with the kernels as fast (benchmarks/kane.py, benchmarks/sweep.py side by
# side: rhs evaluations and sweep configurations per second within their run-to-run scatter). Level 1
# compiles boat-study's kernels (Kane, pose, slopes, sweep) in 60 s of CPU against 72 s at level 2 (two
# runs each, empty caches, /usr/bin/time), `validate all` cold in 78 s against 101 s at level 3; the
# Kane rhs runs 3-5 % slower (benchmarks/kane.py: 2.33-2.40e5 against 2.41-2.50e5 evaluations/s, two
# interleaved rounds) and the sweep as fast (1.82-1.85e3 configurations/s/core against 1.83-1.86e3). A
# first run compiles every kernel; the warm ones spend most of their time in MuJoCo and scipy. What each
# group of kernels costs to compile: benchmarks/compile_cpu.py (CPU s in a fresh cache; the Kane group
# 21.7 s, 25.8 before its cross products were written out and its accelerations kernel dropped; pose
# 10.5-12.5, slopes 11.2-15.5, sweep 27.2-27.4, elastic 13.4-13.5, all 54.2-56.3, against 15.7-18.1,
# 16.3-18.3, 29.6-33.5, 14.0-14.2 and 59.5-60.2 before their small products were written as loops).
OPT_LEVEL = "1"


def use_user_cache() -> None:
    """Set ``NUMBA_CACHE_DIR`` to :func:`user_cache_dir` and ``NUMBA_OPT`` to :data:`OPT_LEVEL`, each
    unless it is set (or numba is already imported, which has read them)."""
    if "numba" not in sys.modules:
        os.environ.setdefault("NUMBA_CACHE_DIR", str(user_cache_dir()))
        os.environ.setdefault("NUMBA_OPT", OPT_LEVEL)


_announced: set[str] = set()
EVERYTHING = "*"  # announced as ``what``: one note has covered every kernel (announce_modules)


def announce_compile(what: str, *kernels, seconds: str = "30-80") -> None:
    """One line on stderr (once per process and ``what``, and only in the main process: a worker's
    note would repeat it per worker) if any of ``kernels`` (numba dispatchers with ``cache=True``) has
    no fresh cache entry, i.e. will be compiled at its first call. Call it just before the kernels'
    first use (it reads a small index file per kernel). ``seconds``: the estimate, on 2 cores."""
    if _first(what) and any(not cached(k) for k in kernels):
        _note(what, seconds)


def announce_modules(what: str, modules, seconds: str) -> bool:
    """One note for every kernel of ``modules`` (see :func:`announce_compile`), after which no other
    note is printed in this process: for a command that will use them all (``validate all``). Whether
    any of them will compile."""
    cold = not all(cached(k) for m in modules for k in _dispatchers(m).values())
    if _first(what) and cold:
        _note(what, seconds)
    _announced.add(EVERYTHING)
    return cold


def _first(what: str) -> bool:
    """Whether nothing has announced ``what`` (nor everything) in this process yet; marks it."""
    if what in _announced or EVERYTHING in _announced:
        return False
    _announced.add(what)
    return True


def _note(what: str, seconds: str) -> None:
    if _main_process():
        where = os.environ.get("NUMBA_CACHE_DIR", "__pycache__ beside the sources")
        print(f"note: compiling {what} with numba (first run after an install or a change, ~{seconds} s; "
              f"cached afterwards in {where})", file=sys.stderr, flush=True)


def _main_process() -> bool:
    import multiprocessing

    return multiprocessing.parent_process() is None


LOOP_CALLS = 200  # interpreted calls into one kernel module, per process, after which it is compiled


class LoopKernels:
    """A module of numba kernels, seen through the compile-only-what-loops policy: attribute access
    gives the compiled function when the module's kernels are cached on disk (loading is quick), else
    the module's plain-Python twin (:func:`interpreted`, the same code run by numpy) until
    :data:`LOOP_CALLS` calls have been made through it in this process; then it compiles (announced
    once, with ``seconds`` as the estimate) and gives the compiled functions from there on. Both run
    the same source, so they agree to rounding."""

    def __init__(self, module: types.ModuleType, what: str, seconds: str):
        self._module, self._what, self._seconds = module, what, seconds
        self._twin: types.ModuleType | None = None
        self._compiled: bool | None = None  # None: the cache not looked at yet
        self._calls = 0

    def __getattr__(self, name: str):
        if self._compiled is None:
            self._compiled = all(cached(k) for k in _dispatchers(self._module).values())
        if not self._compiled:
            self._calls += 1
            if self._calls <= LOOP_CALLS:
                if self._twin is None:
                    self._twin = interpreted(self._module)
                return getattr(self._twin, name)
            announce_compile(self._what, *_dispatchers(self._module).values(), seconds=self._seconds)
            self._compiled = True
        return getattr(self._module, name)


def _dispatchers(module: types.ModuleType) -> dict:
    from numba.core.registry import CPUDispatcher

    return {k: v for k, v in vars(module).items() if isinstance(v, CPUDispatcher) and v.__module__ == module.__name__}


def interpreted(module: types.ModuleType) -> types.ModuleType:
    """``module``'s plain-Python twin: its source run again in a new namespace, every kernel there
    replaced by its Python function, so that kernels calling each other call the Python ones: those it
    defines and those it imports (:mod:`bifilar.smallmat`'s products, which call no other kernel).
    Nothing is compiled (defining a numba dispatcher is cheap; its first call compiles)."""
    from numba.core.registry import CPUDispatcher

    twin = types.ModuleType(f"{module.__name__}[interpreted]", module.__doc__)
    twin.__file__ = module.__file__
    exec(compile(inspect.getsource(module), module.__file__, "exec"), vars(twin))
    for name, value in list(vars(twin).items()):
        if isinstance(value, CPUDispatcher):
            setattr(twin, name, value.py_func)
    return twin


def cached(kernel) -> bool:
    """Whether numba dispatcher ``kernel`` (``cache=True``) has an entry in the on-disk cache."""
    try:
        return bool(kernel._cache._cache_file._load_index())
    except Exception:  # numba internals moved: assume cached rather than print a wrong note
        return True
