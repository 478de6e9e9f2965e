"""The N-wire model (bifilar.motion.nwire) against the two-wire Kane-Tseng model and the trifilar
closed form, the initial state for three wires, and the refusal of statically indeterminate wires."""

import numpy as np
import pytest

from bifilar.motion.kane import KaneModel
from bifilar.motion.nwire import NWireModel, simulate
from bifilar.motion.simulate import simulate as kane_simulate
from bifilar.rig import RigError, load_rig, rig_from_dict
from bifilar.rig.statics import initial_state, length_errors
from validate.assets import RIGS


def test_two_wires_agree_with_kane_tseng():
    # Two independent derivations integrated at rtol 1e-10 over 2 s: they agree to the integrator's
    # error (measured 7e-11 m over 10 s on this rig); 1e-8 m leaves a margin of 100.
    rig = load_rig(RIGS / "plate.toml")
    state = initial_state(rig)
    a = simulate(NWireModel.from_rig(rig), state, 2.0, 0.01)
    b = kane_simulate(KaneModel.from_rig(rig), state, 2.0, 0.01)
    assert np.abs(a.com - b.com).max() < 1e-8
    assert np.abs(a.rotation - b.rotation).max() < 1e-8
    assert np.abs(a.tension - b.tension).max() < 1e-8 * np.abs(b.tension).max()


def test_trifilar_initial_state_holds_every_wire():
    # Trilateration puts the turned platform on all three spheres: lengths exact to rounding (1e-13 m).
    rig = load_rig(RIGS / "trifilar.toml")
    s = initial_state(rig)
    assert np.abs(length_errors(rig, s.com, s.rotation)).max() < 1e-13
    # A pure turn about the axis: the platform rises, R^2 (1 - cos phi) / L to first order (1e-6 m).
    assert s.com[2] == pytest.approx(0.09 * (1 - np.cos(0.1)) / 1.5, abs=1e-6)


def test_trifilar_static_tensions_and_lengths_in_motion():
    # Symmetric platform: each wire carries M g / 3 at rest; in motion the projection keeps every
    # length within 1e-10 m (the brief's target).
    rig = load_rig(RIGS / "trifilar.toml").with_initial()
    run = simulate(NWireModel.from_rig(rig), initial_state(rig), 1.0, 0.01)
    np.testing.assert_allclose(run.tension[0], 2.0 * 9.81 / 3, rtol=1e-12)
    rig = load_rig(RIGS / "trifilar.toml")
    run = simulate(NWireModel.from_rig(rig), initial_state(rig), 3.0, 0.01)
    assert np.abs(run.length_error).max() < 1e-10


def test_four_parallel_wires_are_refused():
    data = {"body": {"mass": 2.0, "inertia": [0.06, 0.06, 0.12]}, "wire": [
        {"anchor": [x, y, 1.5], "attach": [x, y, 0.0], "length": 1.5}
        for x, y in ((0.3, 0.0), (0.0, 0.3), (-0.3, 0.0), (0.0, -0.3))]}
    rig = rig_from_dict(data, source="four.toml")
    with pytest.raises(RigError, match="statically indeterminate"):
        simulate(NWireModel.from_rig(rig), initial_state(rig), 0.1, 0.01)


def test_tensor_from_closed_form_periods():
    # Independent of the linearisation: on the trifilar (vertical wires, COM in the attachment plane)
    # the yaw period with object axis e vertical is 2 pi sqrt(L e.I.e / (M g R^2)) exactly in the
    # linear limit, so six hangings recover the tensor to rounding (1e-10 relative).
    from bifilar.identification.tensor import Hanging, identify_tensor
    from validate.cases.tensor import TRUE_INERTIA, mounted

    axes = [np.array(v, float) / np.linalg.norm(v) for v in ((1, 0, 0), (0, 1, 0), (0, 0, 1), (1, 1, 0), (0, 1, 1), (1, 0, 1))]
    hangings = []
    for e in axes:
        carrier, q = mounted(e, np.eye(3) * 0.1)
        period = 2 * np.pi * np.sqrt(1.5 * (e @ TRUE_INERTIA @ e) / (2.0 * 9.81 * 0.09))
        hangings.append(Hanging(carrier, period, 0.0, q))
    result = identify_tensor(hangings, np.eye(3) * 0.1)
    np.testing.assert_allclose(result.inertia, TRUE_INERTIA, rtol=0, atol=1e-10 * 0.12)
    with pytest.raises(RigError, match="cannot determine"):
        identify_tensor(hangings[:5], np.eye(3) * 0.1)


def test_slack_stops_the_run_with_status_3(tmp_path, capsys):
    # Spun at 20 rad/s the platform rises steeply as it turns and must then decelerate faster than g: the
    # tensions reach zero (all three at once, by symmetry) near t = 0.107 s; the run stops there.
    from validate.cli import main

    text = (RIGS / "trifilar.toml").read_text().replace("omega = [0.0, 0.0, 0.0]", "omega = [0.0, 0.0, 20.0]")
    text = text.replace("rotation = [0.0, 0.0, 0.1]", "rotation = [0.0, 0.0, 0.0]")
    path = tmp_path / "spun.toml"
    path.write_text(text)
    out = tmp_path / "spun.csv"
    code = main(["simulate", str(path), "--duration", "1", "--out", str(out)])
    err = capsys.readouterr().err
    assert code == 3 and "went slack at t = 0.1065" in err and err.count("\n") == 1
    rows = out.read_text().splitlines()
    assert 10 <= len(rows) - 1 <= 12  # samples up to the slack time, 0.01 s apart


def test_every_engine_is_a_simulate_choice(tmp_path):
    """The CLI's --engine choices are the registry's engines, nwire included."""
    from validate.engines import NAMES, engines

    assert set(NAMES) == set(engines())
