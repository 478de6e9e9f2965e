"""Elastic wires (issue 20): the rig-file field, the statics and modes against closed forms and an
independent model, the inextensible limit, and kane against MuJoCo."""

import json

import numpy as np
import pytest

from bifilar.motion.modes import linearize
from bifilar.rig import load_rig
from bifilar.rig.statics import initial_state, rest_pose
from validate.assets import RIGS, rig
from validate.cases import elastic as E
from validate.cli import main
from validate.registry import CaseContext

QUAD = (RIGS / "quadrifilar.toml").read_text()


def _cli(capsys, *args):
    code = main(list(args))
    out, err = capsys.readouterr()
    return code, out, err


@pytest.mark.parametrize("edit, field, words", [
    (lambda s: s.replace("axial_stiffness = 2.0e5", "axial_stiffness = -1.0", 1), "wire[1].axial_stiffness", "positive"),
    (lambda s: s.replace("axial_stiffness = 2.0e5", "axial_stiffness = 1e12", 1), "wire[1].axial_stiffness", "outside"),
    (lambda s: s.replace("axial_stiffness = 2.0e5\n", "", 1), "wire[2].axial_stiffness", "every wire"),
    (lambda s: s.replace("axial_stiffness = 2.0e5", "axial_stiffness = 'stiff'", 1), "wire[1].axial_stiffness", "number"),
    # Without any axial_stiffness, four parallel wires are indeterminate: still refused in one line.
    (lambda s: s.replace("axial_stiffness = 2.0e5", "").replace("axial_stiffness = 2.0e5", ""), "wire", "indeterminate"),
])
def test_bad_elastic_field_is_one_line(tmp_path, capsys, edit, field, words):
    path = tmp_path / "bad.toml"
    path.write_text(edit(QUAD))
    code, out, err = _cli(capsys, "modes", str(path), "--json")
    assert code == 2 and out == ""
    assert len(err.strip().splitlines()) == 1, err
    assert err.startswith(f"error: {path}: {field}: ") and words in err, err


def test_mujoco_eq_refuses_elastic_wires_in_one_line(tmp_path, capsys):
    code, out, err = _cli(capsys, "simulate", str(RIGS / "quadrifilar.toml"), "--engine", "mujoco-eq",
                          "--duration", "0.1", "--out", str(tmp_path / "x.csv"))
    assert code == 2 and len(err.strip().splitlines()) == 1
    assert "wire[1].axial_stiffness" in err and "--engine mujoco" in err
    assert not (tmp_path / "x.csv").exists()


def test_modes_json_names_six_modes_fast_and_slow(capsys):
    code, out, _ = _cli(capsys, "modes", str(RIGS / "quadrifilar.toml"), "--json")
    assert code == 0
    modes = json.loads(out)["modes"]
    kinds = {m["motion"]: m["kind"] for m in modes}
    assert kinds == {"sway x": "slow", "sway y": "slow", "yaw": "slow", "bounce": "fast", "roll": "fast", "pitch": "fast"}


def test_inextensible_rig_is_unchanged_by_the_new_field():
    # The key's absence is today's model: the plate's rest tensions m g / (2 cos 30 deg), to rounding.
    r = rig("plate")
    assert not r.elastic and all(w.axial_stiffness is None for w in r.wires)
    assert np.allclose(rest_pose(r).tensions, 100.0 * 9.81 / (2.0 * np.cos(np.radians(30.0))), rtol=1e-12)


def _metrics(case_fn):
    return case_fn(CaseContext())


@pytest.mark.parametrize("case_fn", [E.quadrifilar_closed_form, E.independent, E.stiff_limit])
def test_elastic_statics_and_modes_cases_pass(case_fn):
    # Each metric carries its own tolerance and reason (validate/cases/elastic.py).
    failed = [(m.name, m.value, m.tolerance) for m in _metrics(case_fn) if not m.passed]
    assert not failed


def test_quadrifilar_closed_forms_directly():
    # Symmetric platform, EA = 2e5 N, L = 1.5 m, m = 4 kg, R = 0.3 m, I_zz = 0.24 kg m^2 (rig file).
    r = rig("quadrifilar")
    lin = linearize(r)
    by = {m.motion: m.period for m in lin.modes}
    stretched = 1.5 + 4.0 * 9.81 * 1.5 / (4.0 * 2e5)
    # rounding of 6x6 eigenproblems: 1e-9
    assert by["bounce"] == pytest.approx(2 * np.pi * np.sqrt(4.0 * 1.5 / (4 * 2e5)), rel=1e-9)
    assert by["yaw"] == pytest.approx(2 * np.pi * np.sqrt(0.24 * stretched / (4.0 * 9.81 * 0.09)), rel=1e-9)
    assert by["sway x"] == pytest.approx(2 * np.pi * np.sqrt(stretched / 9.81), rel=1e-9)
    # the stretch eps = 4.9e-5 shifts the yaw period by sqrt(1 + eps) - 1 ~ eps / 2 from the
    # inextensible one; the difference of two periods equal to 1e-13 leaves ~1e-8 of it
    assert by["yaw"] / (2 * np.pi * np.sqrt(0.24 * 1.5 / (4.0 * 9.81 * 0.09))) - 1 == pytest.approx(
        np.sqrt(stretched / 1.5) - 1, rel=1e-6)


def test_asymmetric_platform_load_shares_follow_stiffness():
    # Statically indeterminate when rigid: the elastic shares must balance the weight and moments.
    r = rig("quadrifilar_asymmetric")
    rest = rest_pose(r)
    assert np.abs(E.wrench(r, rest.com, rest.rotation)).max() < 1e-9 * r.mass * r.gravity
    assert rest.tensions.min() > 0.0 and np.ptp(rest.tensions) > 0.3 * rest.tensions.mean()


def test_initial_state_holds_the_turn_and_settles_the_com():
    r = rig("quadrifilar_asymmetric")
    state = initial_state(r)
    wrench = E.wrench(r, state.com, state.rotation)
    assert np.abs(wrench[:3]).max() < 1e-9 * r.mass * r.gravity  # force balanced, moment not (held turned)
    assert np.abs(wrench[3:]).max() > 1e-3
    assert np.all(state.velocity == 0.0)


def test_kane_and_mujoco_agree_on_elastic_rigs():
    # The bars: COM to 1e-5 m, tensions to 1e-3 of the static one (MuJoCo at 2e-5 s).
    failed = [(m.name, m.value, m.tolerance) for m in _metrics(E.elastic_engines) if not m.passed]
    assert not failed


def test_axial_stiffness_sweep_axis_and_continuation(tmp_path):
    # The sweep's axis makes every wire elastic; its rows continue from the neighbour's pose but are
    # the elastic rig's own modes (the compiled continuation is the inextensible one's: bypassed).
    from bifilar.sweep.evaluate import evaluate
    from bifilar.sweep.space import load_space

    path = tmp_path / "ea.toml"
    path.write_text(f'rig = "{RIGS / "soft_cords.toml"}"\n\n[vary]\naxial_stiffness = [4000.0, 40000.0]\n\n'
                    '[measure]\naxes = ["z"]\n')
    space = load_space(path)
    first = evaluate(space, {"axial_stiffness": 4000.0})
    second = evaluate(space, {"axial_stiffness": 40000.0}, guess=first.rest)
    for row, ea in ((first, 4000.0), (second, 40000.0)):
        direct = sorted((m.period for m in linearize(E.with_ea(rig("soft_cords"), ea)).modes), reverse=True)[:4]
        assert np.allclose(row.periods, direct, rtol=1e-9)  # the same linearisation: rounding only
    # ten times stiffer: the sway period shifts by ~ (eps_1 - eps_2) / 2 ~ 1e-3 (eps_1 = 2.5e-3)
    assert 5e-4 < first.periods[0] / second.periods[0] - 1 < 2e-3
