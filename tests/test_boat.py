"""The Solar Boat hung in a hall (bifilar/bodies/boat.py), its MuJoCo model (validate/studies/boat_model.py), the study
(validate/studies/boat_study.py) and its command (validate/commands/boat.py), on models/solar_boat/suspension.toml."""

from __future__ import annotations

import dataclasses
import io
import json
import math
from contextlib import redirect_stdout
from pathlib import Path

import mujoco
import numpy as np
import pytest
from PIL import Image
from scipy.spatial.transform import Rotation

from bifilar.identification import identify as ident
from bifilar.bodies.boat import attachment_forces, load_suspension, lowest_point
from bifilar.bodies.composite import mass_properties
from bifilar.rig import RigError
from bifilar.rig.statics import rest_pose
from validate import cli
from validate.commands import boat as boat_cli
from validate.studies import boat_model, boat_study
from validate.studies.boat_study import TIMED, axis_amplitude, run_study, summary
from validate.lineplot import nice_ticks

ROOT = Path(__file__).resolve().parents[1]
BOAT = ROOT / "models" / "solar_boat"
SUSPENSION = load_suspension(BOAT / "suspension.toml")
PROPS = mass_properties(list(SUSPENSION.parts))
HALF_DECK = 5.432 / 2.0  # parts.toml: deck length 5.432 m, centred, top face at z = 0


def test_configurations_hang_from_the_same_hooks_at_the_deck_ends():
    assert [(c.name, c.inset) for c in SUSPENSION.configurations] == [("1", 0.0), ("2", 0.5), ("3", 1.0)]
    for c in SUSPENSION.configurations:
        rig = SUSPENSION.rig(c)
        x = HALF_DECK - c.inset
        np.testing.assert_allclose([w.attach for w in rig.wires], [[x, 0, 0], [-x, 0, 0]], atol=1e-15)
        np.testing.assert_allclose([w.anchor for w in rig.wires], [[3.0, 0, 0], [-3.0, 0, 0]], atol=0)
        assert [w.length for w in rig.wires] == [4.0, 4.0]
        assert rig.mass == PROPS.mass and np.array_equal(rig.com, PROPS.com)
        np.testing.assert_array_equal(rig.inertia, PROPS.inertia)
        assert rig.uncertainty.period == 5e-3 and rig.uncertainty.com == 5e-3


def _write(tmp_path, text: str) -> Path:
    path = tmp_path / "suspension.toml"
    path.write_text(f'parts = "{BOAT / "parts.toml"}"\n' + text)
    return path


HALL = '[hall]\nhooks = [[3.0, 0.0, 0.0], [-3.0, 0.0, 0.0]]\nwire_length = 4.0\nhook_height = 6.5\n'
ONE = '[[configuration]]\nname = "1"\ninset = 0.0\n'


@pytest.mark.parametrize(("text", "field", "problem"), [
    ('deck = "keel"\n' + HALL + ONE, "deck", "no part named 'keel'"),
    ('deck = "battery"\n' + HALL + ONE, "deck", "it must be a box, plate or beam"),
    ('deck = "deck"\n' + ONE, "hall", "missing"),
    ('deck = "deck"\n' + HALL.replace("[-3.0, 0.0, 0.0]]", "]") + ONE, "hall.hooks", "must be two hooks"),
    ('deck = "deck"\n' + HALL + ONE.replace("0.0", "2.8"), "configuration[1].inset", "less than half the deck"),
    ('deck = "deck"\n' + HALL + ONE + ONE, "configuration[2].name", "unique"),
    ('deck = "deck"\n' + HALL.replace("4.0", "0.1") + ONE, "wire", "no taut pose"),
    ('deck = "deck"\n' + HALL + ONE + "[uncertainty]\nperiod = -1.0\n", "uncertainty.period", "non-negative"),
])
def test_bad_suspension_is_a_one_line_rig_error(tmp_path, text, field, problem):
    path = _write(tmp_path, text)
    with pytest.raises(RigError) as err:
        load_suspension(path)
    assert err.value.source == str(path) and err.value.field == field and problem in err.value.problem
    assert "\n" not in str(err.value)


def test_the_command_reports_a_bad_file_as_a_rig_error(tmp_path):
    """cli.main prints a RigError as one line and exits 2; the command must raise it, not print."""
    path = _write(tmp_path, 'deck = "keel"\n' + HALL + ONE)
    with pytest.raises(RigError, match=f"^{path}: deck: "):
        boat_cli.run(_parse(["boat", "--suspension", str(path)]))


def _parse(argv):
    return cli.build_parser().parse_args(argv)


def test_lowest_point_is_the_lowest_corner_or_rim_point():
    """Against brute force: a box's lowest point is a corner, a cylinder's on a rim circle (sampled at
    0.05 degree: within r (1 - cos 0.025 deg) = 3e-8 m for r = 0.3 m), a sphere's straight down."""
    rng = np.random.default_rng(11)
    origin = rng.normal(size=(20, 3))
    rotation = Rotation.random(20, random_state=rng).as_matrix()
    low, index = lowest_point(SUSPENSION.parts, origin, rotation)
    angles = np.linspace(0.0, 2.0 * np.pi, 7200, endpoint=False)
    for n in range(20):
        heights = []
        for p in SUSPENSION.parts:
            d = p.dims
            if "width" in d:
                local = np.array(np.meshgrid(*[[-0.5 * d[k], 0.5 * d[k]] for k in ("length", "width", "height")])).reshape(3, -1).T
            elif "length" in d:
                rim = np.column_stack([d["radius"] * np.cos(angles), d["radius"] * np.sin(angles), np.zeros_like(angles)])
                local = np.concatenate([rim + [0, 0, 0.5 * d["length"]], rim - [0, 0, 0.5 * d["length"]]])
            else:
                local = np.zeros((1, 3))
            points = origin[n] + (p.position + local @ p.rotation.T) @ rotation[n].T
            heights.append(points[:, 2].min() - (0.0 if "width" in d or "length" in d else d["radius"]))
        assert low[n] == pytest.approx(min(heights), abs=3e-8)
        assert index[n] == int(np.argmin(heights))


def test_lowest_point_at_rest_is_the_foils_bottom():
    """With the COM moved onto the middle of the deck (it is 3.6e-5 m aft, which pitches the rest
    pose by up to 3e-6 rad), the boat hangs level: the foils' undersides, 1.574 + 0.025 / 2 m below
    the deck (parts.toml), are that far under the attachments, L cos(alpha) under the hooks."""
    for c in SUSPENSION.configurations:
        rig = SUSPENSION.rig(c)
        rig = dataclasses.replace(rig, com=rig.com * [0.0, 1.0, 1.0])
        rest = rest_pose(rig)
        low, _ = lowest_point(SUSPENSION.parts, rest.com - rest.rotation @ rig.com, rest.rotation)
        offset = 3.0 - (HALF_DECK - c.inset)
        assert -low[0] == pytest.approx(math.sqrt(4.0**2 - offset**2) + 1.574 + 0.0125, abs=1e-12)


def test_attachment_forces_hold_the_boat_at_rest():
    """Forces and moments about the COM of the two wires (body frame) balance the weight to the
    rest pose's residual (< 1e-9 of m g)."""
    weight = PROPS.mass * 9.81
    for c in SUSPENSION.configurations:
        rig = SUSPENSION.rig(c)
        rest = rest_pose(rig)
        forces = attachment_forces(rig, rest.com, rest.rotation, rest.tensions)[0]
        world = forces @ rest.rotation.T
        np.testing.assert_allclose(world.sum(axis=0), [0.0, 0.0, weight], atol=1e-9 * weight)
        arms = np.array([w.attach - rig.com for w in rig.wires])
        np.testing.assert_allclose(np.cross(arms, forces).sum(axis=0), 0.0, atol=1e-9 * weight)
        np.testing.assert_allclose(np.linalg.norm(forces, axis=1), rest.tensions, rtol=1e-15)


def test_swing_is_released_with_the_wire_turned_by_the_thesis_angle():
    """The swing of ch. 8.3 turns wire 1 by pi/80: the released state does so to first order in the
    amplitude (the mode is linear, the release lies on the taut-wire poses): allowed A = pi/80
    relative, measured up to 0.33 A."""
    swing = TIMED[1]
    for c in SUSPENSION.configurations:
        rig = SUSPENSION.rig(c)
        rest = rest_pose(rig)
        start = ident.released(rig, swing.axis, axis_amplitude(rig, swing, rest), rest).state
        wire = rig.wires[0]
        ends = [com + rotation @ (wire.attach - rig.com) for com, rotation in
                ((rest.com, rest.rotation), (start.com, start.rotation))]
        u = [(e - wire.anchor) / wire.length for e in ends]
        assert math.acos(u[0] @ u[1]) == pytest.approx(swing.amplitude, rel=swing.amplitude)


def test_a_parallelogram_hides_the_pitch_moment():
    """Hooks exactly as far apart as the attachments: wires and deck form a parallelogram, which
    swings without turning, so no period depends on I_yy (why suspension.toml spreads the hooks)."""
    parallel = dataclasses.replace(SUSPENSION, hooks=np.array([[HALF_DECK, 0, 0], [-HALF_DECK, 0, 0]]))
    rig = parallel.rig(parallel.configuration("1"))
    with pytest.raises(RigError, match="axis: no oscillating mode turns about body axis y"):
        ident.invert_period(rig, "y", 4.0)


# --- the MuJoCo model ------------------------------------------------------------------------

def test_shipped_xml_matches_the_generated_model():
    """models/solar_boat/{boat,scene}.xml as committed = boat_model.build_spec now; if this fails,
    regenerate: python -m validate.studies.boat_model models/solar_boat/suspension.toml models/solar_boat."""
    fresh = boat_model.build_spec(SUSPENSION, scene=True).compile()
    saved = mujoco.MjModel.from_xml_path(str(BOAT / "scene.xml"))
    body_s, body_f = saved.body("body"), fresh.body("body")
    for name in ("mass", "inertia", "ipos", "iquat", "pos", "quat"):
        assert getattr(body_s, name) == pytest.approx(getattr(body_f, name), abs=1e-12), name
    for part in SUSPENSION.parts:
        geom_s, geom_f = saved.geom(part.name), fresh.geom(part.name)
        for name in ("type", "size", "pos", "quat", "rgba", "contype", "conaffinity"):
            assert getattr(geom_s, name) == pytest.approx(getattr(geom_f, name), abs=1e-12), (part.name, name)
    for i in (1, 2):
        for site in (f"anchor{i}", f"attach{i}"):
            assert saved.site(site).pos == pytest.approx(fresh.site(site).pos, abs=1e-12), site
        id_s, id_f = saved.tendon(f"wire{i}").id, fresh.tendon(f"wire{i}").id
        assert saved.tendon_range[id_s] == pytest.approx(fresh.tendon_range[id_f], abs=0.0)
    for key in ("rest", "initial"):
        assert saved.key(key).qpos == pytest.approx(fresh.key(key).qpos, abs=1e-12), key
    assert saved.geom("floor").pos[2] == -SUSPENSION.hook_height


def test_shipped_model_has_the_parts_mass_properties():
    """MuJoCo's compiled body (mass, COM, principal moments and axes) rebuilds the parts' composite
    tensor to rounding (1e-12 of its largest moment)."""
    saved = mujoco.MjModel.from_xml_path(str(BOAT / "boat.xml"))
    body = saved.body("body")
    assert body.mass[0] == pytest.approx(PROPS.mass, rel=1e-15)
    np.testing.assert_allclose(body.ipos, PROPS.com, atol=1e-15)
    axes = Rotation.from_quat(body.iquat, scalar_first=True).as_matrix()
    np.testing.assert_allclose(axes @ np.diag(body.inertia) @ axes.T, PROPS.inertia, atol=1e-12 * 317.3)
    assert [saved.geom(p.name).group[0] for p in SUSPENSION.parts] == [2] * len(SUSPENSION.parts)
    assert saved.geom("body").group[0] == boat_model.HIDDEN_GROUP


def test_shipped_scene_steps_without_warnings():
    """The viewer's model: from keyframe 'initial' (pi/12 of torsion) 0.5 s, no MuJoCo warning, and
    the boat turns back towards rest (a quarter torsion period is 0.47 s)."""
    model = mujoco.MjModel.from_xml_path(str(BOAT / "scene.xml"))
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("initial").id)
    mujoco.mj_step(model, data, round(0.5 / model.opt.timestep))
    assert data.warning.number.sum() == 0
    turned = Rotation.from_quat(data.qpos[3:7], scalar_first=True).as_rotvec()[2]
    assert abs(turned) < 0.1 * np.pi / 12


# --- the study ---------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def study():
    return run_study(SUSPENSION)


@pytest.mark.slow
def test_summary_has_the_brief_fields(study):
    data = json.loads(json.dumps(summary(study)))
    # models/solar_boat/README.md: 178.6 kg, COM 0.2051 m below the deck, pilot 44.0 %, moments
    # within 0.01 % of the thesis's.
    assert data["mass"] == pytest.approx(178.6, rel=1e-15)
    assert data["com_below_deck"] == pytest.approx(0.2051, abs=1e-4)
    assert data["pilot_fraction"] == pytest.approx(78.6 / 178.6, rel=1e-15)
    np.testing.assert_allclose(data["principal_inertia"], [317.278, 317.154, 83.143], rtol=1e-4)
    assert [c["name"] for c in data["configurations"]] == ["1", "2", "3"]
    for c in data["configurations"]:
        # The exact inversion recovers the truth: validate/cases/boat.py explains 1e-8.
        np.testing.assert_allclose(c["estimates"], c["truth"], rtol=1e-8)
        assert len(c["tension_rest"]) == len(c["tension_max"]) == 2
        assert min(c["tension_max"]) > max(c["tension_rest"])  # every motion pulls harder somewhere
        assert c["clearance"] > c["clearance_rest"] > 5.3  # foils 1.59 m under ~4 m of wire
        assert c["floor_margin"] == pytest.approx(6.5 - c["clearance"], abs=1e-12)
        assert [m["name"] for m in c["motions"]] == ["torsion", "swing", "roll"]
        assert c["motions"][0]["amplitude"] == pytest.approx(np.pi / 12, rel=1e-15)
    assert data["recommendation"]["configuration"] in {"1", "2", "3"}


def test_report_and_figure(study, tmp_path):
    text = boat_cli.report(summary(study))
    assert "recommendation: configuration" in text and text.count("\n") > 15
    path = boat_cli.tension_figure(study, tmp_path / "tensions.png")
    with Image.open(path) as image:
        assert image.format == "PNG" and image.width == 960
    assert path.stat().st_size < 200_000


def test_json_command_prints_one_object(study, monkeypatch):
    """``boat --json``: one JSON object on stdout (the study itself is replaced by the fixture's)."""
    monkeypatch.setattr(boat_study, "run_study", lambda s: study)
    out = io.StringIO()
    with redirect_stdout(out):
        assert boat_cli.run(_parse(["boat", "--json"])) == 0
    assert json.loads(out.getvalue())["configurations"][0]["tension_rest"] == study.configurations[0].rest.tensions.tolist()


def test_nice_ticks():
    """The smallest step of 1, 2 or 5 times a power of ten that is at least a fifth of the range."""
    np.testing.assert_allclose(nice_ticks(768.7, 1020.0), [700, 800, 900, 1000, 1100])  # 50.3 -> 100
    np.testing.assert_allclose(nice_ticks(0.0, 10.0), [0, 2, 4, 6, 8, 10])


def test_a_hall_too_low_recommends_nothing(study):
    """Every configuration hangs ~5.4-5.6 m below the hooks: with the floor 5.5 m down, configurations
    1 and 2 reach it and only 3 may be recommended; with it 1 m down, none."""
    from dataclasses import replace

    from validate.studies.boat_study import recommend

    low = replace(study, suspension=replace(study.suspension, hook_height=5.5))
    choice = recommend(low)
    assert choice["configuration"] == "3"
    assert sum("is excluded" in r for r in choice["reasons"]) == 2
    assert recommend(replace(study, suspension=replace(study.suspension, hook_height=1.0)))["configuration"] is None
