"""CPU seconds numba spends compiling each group of kernels, each group in a fresh, empty cache.

A first run's extra time (``validate all`` cold against warm) is mostly numba compiling; this script
puts a figure on each group so a change to the kernels can be judged by what it saves. Each group's
entry kernels (the ones Python calls) are compiled for the signatures the suite uses, in a subprocess
with a new temporary NUMBA_CACHE_DIR, at :data:`bifilar.jit.OPT_LEVEL`; the figure is that process's CPU
time spent in ``compile`` (numba compiles on one thread), so it is steadier than wall time on a busy
machine. The code measured is this checkout's (the subprocess's PYTHONPATH is the script's repository, not
an installed copy). A group's figure includes the callees it compiles (the sweep compiles pose and N-wire
kernels), so the groups overlap; ``all`` compiles every group in one process, as a first run does, and
compiles a callee or a numpy implementation (``@`` for one pair of layouts, a LAPACK call) once for all
groups: a saving in one group shows in ``all`` only where no other group still compiles the same thing.

    python benchmarks/compile_cpu.py              # every group, then all
    python benchmarks/compile_cpu.py kane pose    # the named groups only
"""

from __future__ import annotations

import importlib
import os
import subprocess
import sys
import tempfile
from pathlib import Path

# Signatures as the suite calls them: a1/a2/a3 C-contiguous float64 arrays, f float64, i int64.
GROUPS = {
    "kane": [("bifilar.motion.kane_kernel", name, sig) for name, sig in [
        ("rhs", "a1 a1 i"), ("observe", "a2 a1 i"), ("loads", "a1 a1 a1 i"), ("eom", "a1 a1 a1 i"),
        ("pose", "a1 a1 i")]],
    "nwire": [("bifilar.motion.nwire_kernel", name, sig) for name, sig in [
        ("rhs", "a1 a2 a2 a2 f f a1"), ("observe", "a2 a2 a2 a2 f f a1"), ("dynamics", "a1 a2 a2 a2 f f a1"),
        ("quat_matrix", "a1"), ("dynamics_jacobian", "a1 a2 a2")]],
    "elastic": [("bifilar.motion.elastic_kernel", name, sig) for name, sig in [
        ("rhs", "a1 a2 a2 a1 a1 a2 f f a1"), ("observe", "a2 a2 a2 a1 a1 a2 f f a1")]],
    "pose": [("bifilar.rig.pose_kernel", name, sig) for name, sig in [
        ("newton_equilibrium", "a1 a2 a1 a2 a2 a1 f f i"), ("reduced_matrices", "a1 a2 a1 a2 a2 a2 f f f"),
        ("equilibrium_balance", "a1 a2 a1 a2 a2 a1 f f")]],
    "slopes": [("bifilar.identification.slopes_kernel", "period_slopes", "a1 a1 i f f a1 a2 a1 a3 a2 a2 a3")],
    "sweep": [("bifilar.sweep.kernel", "continued_modes", "a2 a2 a1 f f a2 f a1 a2 a1 f f f f"),
              ("bifilar.sweep.kernel", "peak_tension", "a1 a2 a2 a1 a1 a1 a2 a2 a2 f f a1")],
}


def _types(sig: str) -> tuple:
    from numba import types

    names = {"a1": types.float64[::1], "a2": types.float64[:, ::1], "a3": types.float64[:, :, ::1],
             "f": types.float64, "i": types.int64}
    return tuple(names[s] for s in sig.split())


def compile_groups(names: list[str]) -> float:
    """CPU seconds to compile the named groups' kernels in this process."""
    import bifilar  # noqa: F401  (sets NUMBA_OPT before numba is imported)

    start = os.times()
    for name in names:
        for module, kernel, sig in GROUPS[name]:
            getattr(importlib.import_module(module), kernel).compile(_types(sig))
    end = os.times()
    return (end.user - start.user) + (end.system - start.system)


def measure(names: list[str]) -> float:
    """:func:`compile_groups` in a subprocess with an empty cache of its own."""
    with tempfile.TemporaryDirectory(prefix="numba-compile-cpu-") as cache:
        env = dict(os.environ, NUMBA_CACHE_DIR=cache, PYTHONPATH=str(Path(__file__).resolve().parents[1]))
        run = subprocess.run([sys.executable, __file__, "--in-process", *names], env=env,
                             capture_output=True, text=True, check=True)
    return float(run.stdout.split()[-1])


def main(names: list[str]) -> None:
    for name in names or list(GROUPS):
        print(f"{name:<8} {measure([name]):6.1f} s cpu", flush=True)
    if not names:
        print(f"{'all':<8} {measure(list(GROUPS)):6.1f} s cpu")


if __name__ == "__main__":
    if sys.argv[1:2] == ["--in-process"]:
        print(f"{compile_groups(sys.argv[2:]):.2f}")
    else:
        unknown = [n for n in sys.argv[1:] if n not in GROUPS]
        if unknown:
            sys.exit(f"usage: python benchmarks/compile_cpu.py [{' | '.join(GROUPS)}]...; unknown {unknown}")
        main(sys.argv[1:])
