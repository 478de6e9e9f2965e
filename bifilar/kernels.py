"""Every numba kernel of the project with the signatures the project calls it with, in groups, and
:func:`precompile`: a first run's compiling shared out between processes so that no kernel is compiled
twice.

Left to compile at first use, the two workers of ``validate all`` or of the test suite (pytest-xdist)
meet the same kernels at about the same time and each compiles them: on an empty cache most of the
cold run's extra time was the same kernels compiled in both processes. Instead, each worker first
compiles one share of the groups (:func:`shares`, balanced by :data:`GROUPS`' measured costs) into the
common on-disk cache, and loads the other shares from there when its work first calls them.

The signatures are those a cold ``validate all`` and the test suite compiled (read from the cache's
index files: ``python benchmarks/compile_cpu.py --read CACHE``); a signature the project no longer
calls would only cost its compile, one it calls but the table misses is compiled at first use as
before. ``tests/test_jit.py`` checks that the table names every module of cached kernels.
Codes: ``a1``/``a2``/``a3`` C-contiguous float64 arrays of 1-3 dimensions, ``i1`` a C-contiguous int64
array, ``f`` float64, ``i`` int64.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass

from bifilar.jit import cached


@dataclass(frozen=True)
class Group:
    """A module's kernels (``name: signature``, compiled in this order) and ``cost``, the CPU seconds
    compiling them took in its share (``python benchmarks/compile_cpu.py shares 2``; a process's first
    group also pays for numba's own functions it compiles once per process). The shares are balanced
    by it, so only its proportions matter."""

    module: str
    kernels: dict[str, str]
    cost: float


GROUPS = {
    "kane": Group("bifilar.motion.kane_kernel", {
        "air_terms": "a2 a1 a1 a1", "rhs": "a1 a1 i", "observe": "a2 a1 i", "loads": "a1 a1 a1 i",
        "eom": "a1 a1 a1 i", "pose": "a1 a1 i"}, 15.9),
    "pose": Group("bifilar.rig.pose_kernel", {
        "newton_equilibrium": "a1 a2 a1 a2 a2 a1 f f i", "reduced_matrices": "a1 a2 a1 a2 a2 a2 f f f",
        "equilibrium_balance": "a1 a2 a1 a2 a2 a1 f f", "equilibrium_residual": "a1 a2 a1 a2 a2 a1 f f",
        "constraint_jacobian": "a2 a2", "constraint_hessian": "a2 a2 a1 i", "cross_matrix": "a1",
        "rotation_vector_matrix": "a1", "wire_geometry": "a1 a2 a2 a2"}, 9.5),
    "nwire": Group("bifilar.motion.nwire_kernel", {
        "rhs": "a1 a2 a2 a2 f f a1", "observe": "a2 a2 a2 a2 f f a1", "dynamics": "a1 a2 a2 a2 f f a1",
        "dynamics_jacobian": "a1 a2 a2", "quat_matrix": "a1", "matrix_quat": "a2", "state_rate": "a1 a1",
        "compatible_tensions": "a1 a2 a2 a2 f f a1 a1 a1"}, 10.7),
    "elastic": Group("bifilar.motion.elastic_kernel", {
        "rhs": "a1 a2 a2 a1 a1 a2 f f a1", "observe": "a2 a2 a2 a1 a1 a2 f f a1"}, 6.7),
    "slopes": Group("bifilar.identification.slopes_kernel", {
        "period_slopes": "a1 a1 i f f a1 a2 a1 a3 a2 a2 a3"}, 4.0),
    "sweep": Group("bifilar.sweep.kernel", {
        "continued_modes": "a2 a2 a1 f f a2 f a1 a2 a1 f f f f",
        "peak_tension": "a1 a2 a2 a1 a1 a1 a2 a2 a2 f f a1"}, 4.6),
    "tmt": Group("bifilar.seeds.tmt", {"_kinematics": "a1 a1 a2 a2 i1 a1 i1 i"}, 3.3),
    "damping": Group("bifilar.identification.records.damping", {"_cycle_from": "f f f f f"}, 0.7),
    "near": Group("bifilar.identification.records.near", {"_damping_decay": "a1 f f f f"}, 4.4),
    "modes": Group("bifilar.motion.modes", {"resolution": "f f f"}, 0.1),
}


def numba_types(signature: str) -> tuple:
    """The numba argument types of a signature written in the module docstring's codes."""
    from numba import types

    codes = {"a1": types.float64[::1], "a2": types.float64[:, ::1], "a3": types.float64[:, :, ::1],
             "i1": types.int64[::1], "f": types.float64, "i": types.int64}
    return tuple(codes[code] for code in signature.split())


def dispatcher(group: Group, name: str):
    return getattr(importlib.import_module(group.module), name)


def cold(names=tuple(GROUPS)) -> bool:
    """Whether any kernel of the named groups has no entry in the on-disk cache (it would compile)."""
    return not all(cached(dispatcher(GROUPS[g], k)) for g in names for k in GROUPS[g].kernels)


def shares(n: int) -> list[list[str]]:
    """The groups dealt to ``n`` processes in the table's order, each to the share with the least cost
    so far (the shares end within about the last group's cost of each other). The order puts a group's
    callees in other groups early (the Kane group's ``air_terms`` first, the pose group second), so that
    by the time another share needs them they are in the cache."""
    out: list[list[str]] = [[] for _ in range(max(n, 1))]
    load = [0.0] * len(out)
    for name, group in GROUPS.items():
        i = load.index(min(load))
        out[i].append(name)
        load[i] += group.cost
    return out


def precompile(names) -> None:
    """Compile the named groups' kernels for their signatures into the cache (a kernel already cached
    is loaded, not compiled)."""
    for name in names:
        group = GROUPS[name]
        for kernel, signature in group.kernels.items():
            dispatcher(group, kernel).compile(numba_types(signature))
