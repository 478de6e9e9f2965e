"""bifilar.jit: the plain-Python twin of a kernel module runs the same code as the compiled one (equal
to rounding), LoopKernels runs one-shot work in Python until it loops (then compiles),
a compile note is printed once per process, and on an empty cache the suite runs the cases that compile
first."""

import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from bifilar import jit
from bifilar.rig import pose_kernel
from bifilar.rig.statics import anchors, arms, lengths, rig_scale
from validate.assets import rig


def _equilibrium_inputs():
    r = rig("asymmetric")  # products of inertia, unequal wires, hooks at different heights
    guess_rot = np.eye(3)
    weight = r.mass * r.gravity
    return (np.zeros(3), guess_rot, np.full(2, weight / 2), arms(r), anchors(r), lengths(r), weight, rig_scale(r), 30)


def test_the_twin_is_python_and_agrees_with_the_compiled_kernels():
    twin = jit.interpreted(pose_kernel)
    assert not hasattr(twin.newton_equilibrium, "py_func")  # a plain function, nothing to compile
    assert twin.wire_geometry.__globals__ is vars(twin)  # its calls go to the twin's functions
    args = _equilibrium_inputs()
    com_p, rot_p, t_p, res_p, it_p = twin.newton_equilibrium(*args)
    com_c, rot_c, t_c, res_c, it_c = pose_kernel.newton_equilibrium(*args)
    assert res_p < 1e-14 and res_c < 1e-14 and it_p == it_c  # both converge, in the same steps
    # The same arithmetic in a different order (BLAS, loops): rounding of ~1e-16 per operation, a few
    # hundred operations per Newton step; the converged pose is the same to 1e-12 of the rig size.
    scale = args[7]
    np.testing.assert_allclose(com_p, com_c, rtol=0, atol=1e-12 * scale)
    np.testing.assert_allclose(rot_p, rot_c, rtol=0, atol=1e-12)
    np.testing.assert_allclose(t_p, t_c, rtol=1e-12)


def test_loop_kernels_interpret_until_they_loop(monkeypatch, capsys):
    kernels = jit.LoopKernels(pose_kernel, "the test's kernels", seconds="1")
    monkeypatch.setattr(jit, "cached", lambda kernel: False)  # as on a fresh machine
    monkeypatch.setattr(jit, "_announced", set())
    monkeypatch.setattr(jit, "LOOP_CALLS", 3)
    seen = [kernels.cross_matrix for _ in range(5)]
    assert [hasattr(f, "py_func") for f in seen] == [False, False, False, True, True]
    err = capsys.readouterr().err
    assert err.count("note: compiling the test's kernels") == 1 and "~1 s" in err


def test_cached_kernels_are_used_compiled(monkeypatch):
    monkeypatch.setattr(jit, "cached", lambda kernel: True)
    assert jit.LoopKernels(pose_kernel, "x", "1").cross_matrix is pose_kernel.cross_matrix


def test_one_note_for_everything(monkeypatch, capsys):
    monkeypatch.setattr(jit, "cached", lambda kernel: False)
    monkeypatch.setattr(jit, "_announced", set())
    jit.announce_modules("all the kernels", [pose_kernel], seconds="5-10")
    jit.announce_compile("the Kane kernels", pose_kernel.cross_matrix)
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and err[0].startswith("note: compiling all the kernels with numba") and "~5-10 s" in err[0]


@pytest.mark.parametrize("name", ["plate", "trifilar_asymmetric"])
def test_modes_from_the_twin_match_the_compiled_kernels(name, monkeypatch):
    """The modes command's numbers do not depend on whether the kernels were compiled."""
    from bifilar.motion.modes import linearize
    from bifilar.rig import statics

    r = rig(name)
    both = []
    for cached in (False, True):
        monkeypatch.setattr(statics, "_memo", {})  # the rest pose searched afresh by each
        monkeypatch.setattr(statics, "PK", jit.LoopKernels(pose_kernel, "x", "1"))
        monkeypatch.setattr("bifilar.motion.modes.PK", statics.PK)
        monkeypatch.setattr(jit, "cached", lambda kernel, c=cached: c)
        both.append(sorted(m.omega2 for m in linearize(r).modes))
    np.testing.assert_allclose(both[0], both[1], rtol=1e-10)  # eigenvalues of the same matrices to rounding


def _logged_case(name, keep, traces):
    """A stand-in for suite.run_case (inherited by the forked workers): when each case starts and ends."""
    from validate.suite import CaseResult

    with open(_ORDER_LOG, "a") as out:
        out.write(f"start {name}\n")
    time.sleep(0.02)
    with open(_ORDER_LOG, "a") as out:
        out.write(f"end {name}\n")
    return CaseResult(name, "", True, 0.0, [])


_ORDER_LOG = ""


def _logged_share(groups):
    """A stand-in for kernels.precompile (inherited by the forked workers): when each share starts and ends."""
    with open(_ORDER_LOG, "a") as out:
        out.write(f"start share:{','.join(groups)}\n")
    time.sleep(0.05)
    with open(_ORDER_LOG, "a") as out:
        out.write(f"end share:{','.join(groups)}\n")


@pytest.mark.parametrize("cold", [True, False])
def test_on_an_empty_cache_each_worker_compiles_a_share_before_the_cases(cold, monkeypatch, tmp_path):
    # started together on the cases, both workers compiled the same kernels (the first validate all 2.7x
    # a warm one); on an empty cache each worker compiles one share of the kernels, then the cases run
    from bifilar import kernels
    from validate import suite

    monkeypatch.setattr(sys.modules[__name__], "_ORDER_LOG", str(tmp_path / "order"))
    monkeypatch.setattr(suite, "run_case", _logged_case)
    monkeypatch.setattr(kernels, "precompile", _logged_share)
    monkeypatch.setattr(suite, "_announce_compile", lambda: cold)
    cases = suite.registered()
    assert suite.run_cases(cases, jobs=2) == 0
    lines = [line.split() for line in (tmp_path / "order").read_text().splitlines()]
    assert sorted(n for what, n in lines if what == "end" and not n.startswith("share:")) == sorted(c.name for c in cases)
    shares = [n for what, n in lines if what == "end" and n.startswith("share:")]
    if not cold:
        assert shares == []  # warm: the cases in their order, two at a time
        return
    assert sorted(shares) == sorted("share:" + ",".join(s) for s in kernels.shares(2))
    starts = [i for i, (what, n) in enumerate(lines) if what == "start" and n.startswith("share:")]
    assert lines[starts[1]][0] == "start" and starts[1] < min(i for i, (w, n) in enumerate(lines) if w == "end")
    last_share = max(i for i, (what, n) in enumerate(lines) if what == "end" and n.startswith("share:"))
    first_case = min(i for i, (what, n) in enumerate(lines) if what == "start" and not n.startswith("share:"))
    assert last_share < first_case


def test_the_shares_cover_every_group_once_and_balance():
    from bifilar import kernels

    for n in (1, 2, 3, 5):
        dealt = kernels.shares(n)
        assert sorted(g for share in dealt for g in share) == sorted(kernels.GROUPS)
        costs = [sum(kernels.GROUPS[g].cost for g in share) for share in dealt]
        # greedy to the least loaded: no share exceeds another by more than the costliest group
        assert max(costs) - min(costs) <= max(g.cost for g in kernels.GROUPS.values())


def test_the_table_names_every_cached_kernel_of_the_project():
    """A kernel the table leaves out compiles at first use in every worker that meets it: each module
    with cached kernels is a group, and each of its kernels is listed or only ever a callee."""
    import importlib

    from bifilar import kernels

    project = Path(__file__).resolve().parents[1] / "bifilar"
    modules = {".".join(p.relative_to(project.parent).with_suffix("").parts) for p in project.rglob("*.py")
               if "cache=True" in p.read_text()} - {"bifilar.jit", "bifilar.smallmat", "bifilar.rig.air"}
    assert modules == {g.module for g in kernels.GROUPS.values()}
    for group in kernels.GROUPS.values():
        module = importlib.import_module(group.module)
        for name in group.kernels:
            assert hasattr(getattr(module, name), "compile"), f"{group.module}.{name} is no numba kernel"


@pytest.mark.slow
@pytest.mark.parametrize("name", ["plate", "quadrifilar"])
def test_one_rigs_modes_compile_nothing(name, tmp_path):
    """The README's promise: one rig's rest pose and modes run as plain Python on an empty numba cache
    (nothing is written to it); a kernel called from Python outside LoopKernels would compile there
    (modes.resolution did, called by linearize's neutral test)."""
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path))
    proc = subprocess.run([sys.executable, "-m", "validate", "modes", name], cwd=Path(__file__).resolve().parents[1],
                          env=env, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert not list(tmp_path.rglob("*.nbi")) and "compiling" not in proc.stderr, proc.stderr


def test_the_cache_folder_follows_the_kernels_sources(tmp_path):
    """numba checks a cached kernel against its own file only; the folder key catches a jitted callee
    changed or moved to another module (a kernel loaded stale), and ignores modules without numba."""
    from bifilar.jit import kernels_key

    (tmp_path / "kernel.py").write_text("from numba import njit\n@njit(cache=True)\ndef f(x):\n    return g(x)\n")
    (tmp_path / "callee.py").write_text("from numba import njit\n@njit(cache=True)\ndef g(x):\n    return x\n")
    first = kernels_key(tmp_path)
    (tmp_path / "plain.py").write_text("def h():\n    return 1\n")
    assert kernels_key(tmp_path) == first
    (tmp_path / "callee.py").write_text("from numba import njit\n@njit(cache=True)\ndef g(x):\n    return 2 * x\n")
    changed = kernels_key(tmp_path)
    assert changed != first
    (tmp_path / "callee.py").rename(tmp_path / "moved.py")
    assert kernels_key(tmp_path) not in (first, changed)
