"""The compiled continuation of a sweep (bifilar/sweep/kernel.py with the compiled period slopes)
against the general path from a global rest-pose search (SLSQP, linearize, pencils) on every
configuration of a bench-plate sweep's first 40 configurations and a
sweep of the asymmetric trifilar platform (made here, with a stated uncertainty).

Tolerances: periods and static tensions come from the same equations solved to machine precision by
Newton in both paths (a residual of 1e-12 of the weight): 1e-10. The slopes are forward differences
with steps of 1e-3 sigma whose truncation error is ~1e-6 of each slope in both paths; the two differ
in how the perturbed omega^2 is found (Rayleigh quotient vs eigen-solution, both O(h^2)): 1e-4 of sigma
is far above that and far below anything a sweep decides on. Peak tensions use the same formula at
states that agree to rounding: 1e-9.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from bifilar.sweep import evaluate as E
from bifilar.sweep.space import load_space
from validate.assets import MODELS


def _pairs(space, count, monkeypatch):
    """(continued row, general row) per configuration, and how many rows the continuation made."""
    made = []
    original = E._continued
    monkeypatch.setattr(E, "_continued", lambda *args: made.append(original(*args)) or made[-1])
    points = list(space.points())[:count]
    guess, out = None, []
    for values in points:
        fast = E.evaluate(space, values, guess)
        rig = E.configure(space.rig, values)
        general = E.Row(values=values)
        E._general(space, rig, general, None)  # the global search: no continuation at all
        E._limits(space, rig, general)
        out.append((fast, general))
        guess = fast.rest or guess
    return out, sum(made)


TRIFILAR = """
rig = "tri_rig.toml"
[vary]
wire_length = {from = 0.8, to = 2.0, steps = 5}
platform_radius = {from = 0.2, to = 0.4, steps = 6}
[measure]
axes = ["x", "y", "z"]
"""


@pytest.mark.parametrize("name", ["bench_plate.toml", pytest.param("trifilar", marks=pytest.mark.slow),
                                  "parallel.toml"])
def test_continued_rows_equal_general_path(name, monkeypatch, tmp_path):
    if name == "trifilar":
        rig = (MODELS / "rigs" / "trifilar_asymmetric.toml").read_text()
        rig += "\n[uncertainty]\nlength = 1e-3\nanchor = 1e-3\nattach = 5e-4\nmass = 1e-3\ncom = 1e-3\nperiod = 1e-3\n"
        (tmp_path / "tri_rig.toml").write_text(rig)
        (tmp_path / "tri.toml").write_text(TRIFILAR)
        space = load_space(tmp_path / "tri.toml")
    else:
        space = load_space(MODELS / "sweeps" / name)
    pairs, continued = _pairs(space, 40, monkeypatch)
    for fast, general in pairs:
        assert fast.feasible == general.feasible and fast.motions == general.motions
        for a, b in zip(fast.periods, general.periods):
            assert (a is None) == (b is None) and (a is None or abs(a / b - 1) < 1e-10)
        np.testing.assert_allclose(fast.tensions, general.tensions, rtol=1e-10)
        assert fast.tension_peak == pytest.approx(general.tension_peak, rel=1e-9)
        for axis, s in general.sigma.items():
            if s is None:
                assert fast.sigma[axis] is None
            else:
                assert fast.sigma[axis] == pytest.approx(s, rel=1e-4)
                assert fast.dominant[axis] == general.dominant[axis]
        assert math.isnan(general.separation) or fast.separation == pytest.approx(general.separation, rel=1e-9)
        assert fast.near.keys() == general.near.keys()
        for axis, gap in general.near.items():  # gaps of ~1e-2 from periods equal to 1e-10
            assert (gap is None and fast.near[axis] is None) or fast.near[axis] == pytest.approx(gap, rel=1e-7, nan_ok=True)
    # the comparison is of the continued path, not of the general one twice: every configuration
    # after the first that has a rest pose (unreachable ones have none) was continued, except on the
    # parallel rig, whose rows are neutral (its COM on the attachment line) and go the general way
    # from the neighbour's pose, which must not matter either (a yaw there shares a sway's period)
    expected = 0 if name == "parallel.toml" else sum(f.rest is not None for f, _ in pairs[1:])
    assert continued == expected and (continued >= 5 or name == "parallel.toml")


def test_continuation_hands_back_a_neutral_rig():
    """A configuration whose rest pose is neutral (parallel equal wires, COM on the attachment line)
    is not continued by the kernel: the general path's representative pose is kept."""
    from bifilar.motion.modes import DEGENERATE_RTOL, NEUTRAL_RTOL
    from bifilar.rig import load_rig
    from bifilar.rig.statics import NEUTRAL_SLACK, NULL_RTOL, anchors, arms, lengths, rest_pose, rig_scale
    from bifilar.sweep import kernel as SK

    rig = load_rig(MODELS / "rigs" / "parallel_measured.toml")
    rest = rest_pose(rig)
    status = SK.continued_modes(arms(rig), anchors(rig), lengths(rig), rig.mass, rig.gravity, rig.inertia,
                                rig_scale(rig), rest.com, rest.rotation, rest.tensions, NULL_RTOL, NEUTRAL_RTOL,
                                DEGENERATE_RTOL, NEUTRAL_SLACK)[0]
    assert status == SK.NEUTRAL
