"""The compiled period slopes of the linear propagation (bifilar/identification/slopes_kernel.py:
chord-Newton continuation of the rest pose, a Rayleigh quotient for the perturbed omega^2) against the
general path (a fresh rest_pose and eigen-solution per perturbed input), on shipped rigs of two and
three wires with an uncertainty on every input group.

Both are forward differences with steps of 1e-3 sigma, so each slope carries a truncation error of
~1e-3 sigma x (curvature / slope), ~1e-6 of the slope on these rigs; they differ by how the perturbed
omega^2 is found, both to O(h^2). 2e-5 of the largest slope bounds the difference with room; a wrong
Hessian or mass term (the property tests' 2 % error) moves slopes by far more.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from bifilar.identification import identify as ident
from bifilar.identification import propagation as P
from bifilar.motion.modes import linearize
from bifilar.rig import Uncertainty, load_rig
from bifilar.rig.statics import rest_pose
from validate.assets import MODELS

RIGS = ["asymmetric", "bench_plate", "cylinder", "foam_wing", "plate_unequal", "trifilar_asymmetric",
        "trifilar_offset"]


def _setup(name):
    rig = load_rig(MODELS / "rigs" / f"{name}.toml")
    rig = replace(rig, uncertainty=Uncertainty(length=1e-3, anchor=1e-3, attach=5e-4, mass=1e-3 * rig.mass,
                                               com=1e-3, period=1e-3))
    rest = rest_pose(rig)
    lin = linearize(rig, rest)
    pencils = {a: ident.pencil(rig, a, lin=lin) for a in "xyz"}
    pencils = {a: p for a, p in pencils.items() if p.shares(p.moment0, p.modes(p.moment0)[1]).max() > 1e-12}
    bases = {a: ident.predicted(rig, p) for a, p in pencils.items()}
    return rig, rest, lin, pencils, bases


@pytest.mark.parametrize("name", RIGS)
def test_compiled_slopes_equal_the_general_path(name):
    rig, rest, lin, pencils, bases = _setup(name)
    inp = P.inputs(rig, 0.0, rig.uncertainty.period)
    shapes = np.array([lin.basis @ pencils[a].associated(b.moment)[2][:, pencils[a].associated(b.moment)[0]]
                       for a, b in bases.items()])
    table, ok = P.kernel_slopes(rig, rest, inp, shapes, np.array([rig.inertia] * len(bases)))
    assert ok
    general = P._slopes_resolved(rig, rest, inp, bases)
    for n, axis in enumerate(bases):
        scale = np.abs(general[axis]).max()
        assert scale > 0.0
        np.testing.assert_allclose(table[n], general[axis], rtol=0, atol=2e-5 * scale)


@pytest.mark.parametrize("name", ["sidesway", "parallel_measured"])
def test_a_neutral_rest_pose_takes_the_general_path(name):
    """A rest pose with a neutral tilt (sidesway: wire 1 at the COM; parallel_measured: the COM on the
    attachment line) has a singular equilibrium Jacobian: the kernel declines (linear_axes then
    solves each perturbed rig afresh)."""
    rig, rest, lin, pencils, bases = _setup(name)
    inp = P.inputs(rig, 0.0, rig.uncertainty.period)
    shapes = np.array([lin.basis @ pencils[a].associated(b.moment)[2][:, pencils[a].associated(b.moment)[0]]
                       for a, b in bases.items()])
    _, ok = P.kernel_slopes(rig, rest, inp, shapes, np.array([rig.inertia] * len(bases)))
    assert not ok
