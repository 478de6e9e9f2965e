"""CPU seconds numba spends compiling the project's kernels (:data:`bifilar.kernels.GROUPS`), in fresh,
empty caches: the figures the table's costs and the first run's sharing of the compiling come from.

A first run's extra time (``validate all`` cold against warm) is mostly numba compiling. Three views:

    python benchmarks/compile_cpu.py               # each group in the table's order, in one process:
                                                   # what it costs once the groups before it are cached
    python benchmarks/compile_cpu.py shares 2      # 2 processes side by side on one cache, each its share
                                                   # (bifilar.kernels.shares): each one's CPU and wall time
    python benchmarks/compile_cpu.py --read CACHE  # the kernels and signatures a cache folder holds (a
                                                   # cold run's NUMBA_CACHE_DIR): what the table must list

CPU time of the compiling process (numba compiles on one thread) is steadier than wall time on a busy
machine. The code measured is this checkout's (the subprocesses' PYTHONPATH is the script's repository,
not an installed copy), at :data:`bifilar.jit.OPT_LEVEL`.
"""

from __future__ import annotations

import os
import pickle
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def in_process(names: list[str]) -> None:
    """Compile the named groups here, one after the other; print each group's CPU seconds, then the
    process's wall seconds."""
    from bifilar import kernels

    start = time.perf_counter()
    for name in names:
        before = os.times()
        kernels.precompile([name])
        after = os.times()
        print(f"{name} {after.user - before.user + after.system - before.system:.2f}", flush=True)
    print(f"wall {time.perf_counter() - start:.2f}")


def _start(names: list[str], cache: str) -> subprocess.Popen:
    env = dict(os.environ, NUMBA_CACHE_DIR=cache, PYTHONPATH=str(ROOT))
    return subprocess.Popen([sys.executable, __file__, "--in-process", *names], env=env, stdout=subprocess.PIPE,
                            text=True)


def _figures(out: str) -> dict[str, float]:
    return {name: float(value) for name, value in (line.split() for line in out.splitlines())}


def in_order() -> None:
    from bifilar.kernels import GROUPS

    with tempfile.TemporaryDirectory(prefix="numba-compile-cpu-") as cache:
        figures = _figures(_start(list(GROUPS), cache).communicate()[0])
    print("group     cpu s  (table's cost)")
    for name, group in GROUPS.items():
        print(f"{name:<8} {figures[name]:6.1f}  ({group.cost:g})")
    print(f"{'all':<8} {sum(v for k, v in figures.items() if k != 'wall'):6.1f}  ({figures['wall']:.1f} s wall)")


def side_by_side(n: int) -> None:
    from bifilar.kernels import shares

    with tempfile.TemporaryDirectory(prefix="numba-compile-cpu-") as cache:
        runs = [(share, _start(share, cache)) for share in shares(n)]
        results = [(share, _figures(proc.communicate()[0])) for share, proc in runs]
    print("share  cpu s  wall s  groups")
    for i, (share, figures) in enumerate(results):
        cpu = sum(figures[g] for g in share)
        print(f"{i:<5} {cpu:6.1f}  {figures['wall']:6.1f}  {' '.join(f'{g} {figures[g]:.1f}' for g in share)}")


def read(cache: str) -> None:
    """Every kernel and signature in ``cache``'s index files (numba's own format: a pickled version,
    then the pickled (stamp, overloads) whose keys start with the signature)."""
    for index in sorted(Path(cache).rglob("*.nbi")):
        with open(index, "rb") as f:
            pickle.load(f)
            _, overloads = pickle.loads(f.read())
        for key in overloads:
            print(index.name.split(".py")[0], ", ".join(str(t) for t in key[0]))


if __name__ == "__main__":
    args = sys.argv[1:]
    if args[:1] == ["--in-process"]:
        in_process(args[1:])
    elif args[:1] == ["--read"] and len(args) == 2:
        read(args[1])
    elif args[:1] == ["shares"] and len(args) == 2 and args[1].isdigit():
        side_by_side(int(args[1]))
    elif not args:
        in_order()
    else:
        sys.exit("usage: python benchmarks/compile_cpu.py [shares N | --read CACHE]")
