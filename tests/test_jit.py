"""bifilar.jit: the plain-Python twin of a kernel module runs the same code as the compiled one (equal
to rounding), LoopKernels runs one-shot work in Python until it loops (then compiles),
and a compile note is printed once per process."""

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
    monkeypatch.setattr(jit, "_cached", lambda kernel: False)  # as on a fresh machine
    monkeypatch.setattr(jit, "_announced", set())
    monkeypatch.setattr(jit, "LOOP_CALLS", 3)
    seen = [kernels.cross_matrix for _ in range(5)]
    assert [hasattr(f, "py_func") for f in seen] == [False, False, False, True, True]
    err = capsys.readouterr().err
    assert err.count("note: compiling the test's kernels") == 1 and "~1 s" in err


def test_cached_kernels_are_used_compiled(monkeypatch):
    monkeypatch.setattr(jit, "_cached", lambda kernel: True)
    assert jit.LoopKernels(pose_kernel, "x", "1").cross_matrix is pose_kernel.cross_matrix


def test_one_note_for_everything(monkeypatch, capsys):
    monkeypatch.setattr(jit, "_cached", lambda kernel: False)
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
        monkeypatch.setattr(statics, "PK", jit.LoopKernels(pose_kernel, "x", "1"))
        monkeypatch.setattr("bifilar.motion.modes.PK", statics.PK)
        monkeypatch.setattr(jit, "_cached", lambda kernel, c=cached: c)
        both.append(sorted(m.omega2 for m in linearize(r).modes))
    np.testing.assert_allclose(both[0], both[1], rtol=1e-10)  # eigenvalues of the same matrices to rounding
