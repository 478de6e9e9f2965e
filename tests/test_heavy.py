"""Heavy wires (issue 20, item 4): the rig file's linear_density, the first-order correction of
docs/heavy-wires.md in modes and identify, and MuJoCo's chain cable (validate/engines/mujoco_cable.py)."""

import json
from dataclasses import replace

import numpy as np
import pytest
from scipy.linalg import eigh

from bifilar.identification.identify import invert_period
from bifilar.motion.modes import linearize
from bifilar.rig import heavy
from bifilar.rig.heavy import massless, with_mass_ratio
from validate.assets import RIGS, rig
from validate.cli import main
from validate.engines import mujoco_cable
from validate.metrics import period, yaw

PARALLEL = (RIGS / "parallel.toml").read_text()


def periods(r) -> dict:
    return {m.motion: m.period for m in linearize(r).modes}


def run_cli(capsys, *args):
    code = main(list(args))
    out, err = capsys.readouterr()
    return code, out, err


def _heavy_file(tmp_path, density="0.01", extra=""):
    text = PARALLEL.replace("length = 1.5\n", f"length = 1.5\nlinear_density = {density}\n{extra}", 1)
    path = tmp_path / "heavy.toml"
    path.write_text(text)
    return path


@pytest.mark.parametrize("density, extra, words", [
    ("-0.01", "", "must be positive"),
    ("0.0", "", "must be positive"),
    ("20.0", "", "outside 0 .. 10 kg/m"),
    ("1.0", "", "the wire's mass, at most 0.5 x the body's"),  # 1.5 kg on a 2 kg body
    ('"heavy"', "", "number"),
    ("0.01", "axial_stiffness = 1e5\n", "not with axial_stiffness"),
])
def test_bad_linear_density_is_one_line_naming_the_field(tmp_path, capsys, density, extra, words):
    path = _heavy_file(tmp_path, density, extra)
    code, out, err = run_cli(capsys, "modes", str(path))
    assert code == 2 and out == ""
    assert err.count("\n") == 1 and err.startswith(f"error: {path}: wire[1].linear_density: "), err
    assert words in err, err


def test_engines_refuse_what_they_do_not_model(tmp_path, capsys):
    heavy_path = _heavy_file(tmp_path)
    code, _, err = run_cli(capsys, "simulate", str(heavy_path), "--engine", "kane", "--duration", "0.1",
                           "--out", str(tmp_path / "k.csv"))
    assert code == 2 and "wire[1].linear_density" in err and "--engine mujoco-cable" in err and err.count("\n") == 1
    light = tmp_path / "light.toml"
    light.write_text(PARALLEL)
    code, _, err = run_cli(capsys, "simulate", str(light), "--engine", "mujoco-cable", "--duration", "0.1",
                           "--out", str(tmp_path / "c.csv"))
    assert code == 2 and "wire[1].linear_density: missing" in err and err.count("\n") == 1
    assert not (tmp_path / "k.csv").exists() and not (tmp_path / "c.csv").exists()


def test_simulate_mujoco_cable_writes_body_end_tensions(tmp_path, capsys):
    """Both wires heavy, at rest: on vertical wires the body end carries the body's share m g / 2
    exactly (docs/heavy-wires.md step 7), not the lumped rig's m g / 2 + mu g / 2."""
    text = PARALLEL.replace("length = 1.5\n", "length = 1.5\nlinear_density = 0.02\n")
    text = text.replace("rotation = [0.0, 0.0, 0.1]", "rotation = [0.0, 0.0, 0.0]")
    path = tmp_path / "rest.toml"
    path.write_text(text)
    out_csv = tmp_path / "rest.csv"
    code, out, _ = run_cli(capsys, "simulate", str(path), "--engine", "mujoco-cable", "--duration", "0.2",
                           "--out", str(out_csv))
    assert code == 0 and "mujoco-cable" in out
    data = np.genfromtxt(out_csv, delimiter=",", names=True)
    body_share = 2.0 * 9.81 / 2.0
    # The first sample is the rigid rows' force (the soft rows start unstretched), the others the soft
    # rows' own at solimp 0.9999: within 1e-5 of the load; the wire's weight would add 0.0147 N (1.5e-3).
    for col in ("tension_1", "tension_2"):
        assert np.abs(data[col] - body_share).max() < 1e-5 * body_share


def test_massless_limit_is_todays_model():
    """No key: the massless code path, bit for bit the rig as it was. linear_density -> 0: the first-order
    path converges to it (c1 eps ~ 1e-13 here), and with zero densities forced through it, it is the
    massless linearisation to rounding (the coordinate change and the lumped rig vanish)."""
    r = rig("plate")
    assert all(w.linear_density == 0.0 for w in r.wires)
    base = periods(r)
    tiny = periods(replace(r, wires=tuple(replace(w, linear_density=1e-12) for w in r.wires)))
    assert all(abs(tiny[k] / base[k] - 1.0) < 1e-11 for k in base)  # rounding of eigh ~1e-13
    rest, z, m6, kr = heavy.system(r)  # every density 0
    w2 = np.sort(eigh(kr, z.T @ m6 @ z, eigvals_only=True))
    assert np.allclose(np.sort([2 * np.pi / p for p in base.values()]) ** 2, w2, rtol=1e-12, atol=0)
    assert np.allclose(rest.tensions, linearize(r).rest.tensions, rtol=1e-13, atol=0)


@pytest.mark.parametrize("ratio", [0.001, 0.05, 0.3])
def test_parallel_rig_closed_forms(ratio):
    """docs/heavy-wires.md section 2: yaw and sway of the parallel-wire rig, exact for the lumped model
    (vertical wires: rounding only, 1e-12). Sway along y, across the wires' plane, also turns the body
    about its attachment line: no closed form of this kind."""
    r = with_mass_ratio(rig("parallel"), ratio)
    m, g, length, radius, inertia = r.mass, r.gravity, 1.5, 0.2, r.inertia[2, 2]
    mu = ratio * m / 2.0  # each wire
    p = periods(r)
    yaw_closed = 2 * np.pi * np.sqrt(length * (inertia + 2 * mu * radius**2 / 3) / ((m + mu) * g * radius**2))
    sway_closed = 2 * np.pi * np.sqrt(length * (m + 2 * mu / 3) / (g * (m + mu)))
    assert abs(p["yaw"] / yaw_closed - 1.0) < 1e-12
    assert abs(p["sway x"] / sway_closed - 1.0) < 1e-12  # in the wires' plane: a parallelogram, pure translation
    rest = linearize(r).rest
    assert np.allclose(rest.tensions, m * g / 2.0, rtol=1e-12)  # the body end of a vertical wire


def _chain_error(name, ratio, segments):
    r = with_mass_ratio(rig(name), ratio)
    t_first = periods(r)["yaw"]
    traj = mujoco_cable.run(r.with_initial(rotation=(0.0, 0.0, 1e-4)), 3.0 * t_first, 0.01, segments=segments)
    t_chain = period(traj.t, yaw(traj)).value
    return t_first / t_chain - 1.0, periods(massless(r))["yaw"] / t_chain - 1.0


def test_rigid_rod_chain_is_the_first_order_model_exactly():
    """One segment a wire is a rigid rod with ball joints at both ends: its kinetic energy is mu / 3 at
    the attachment and its weight mu g / 2 there at any ratio, so the first-order model is exact for it
    (measured 3.8e-9). Tolerance 1e-7: the connect rows' stretch (~5e-8 m on 1.5 m) and the
    amplitude's own shift at 1e-4 rad (~1e-9)."""
    first, massless_error = _chain_error("parallel", 0.05, 1)
    assert abs(first) < 1e-7
    assert abs(massless_error) > 1e-3  # the wires' share is visible: 1.3e-3


@pytest.mark.slow
def test_first_order_correction_against_the_chain_at_small_ratio():
    """Parallel rig, wires 1 % of the body, 8 segments a wire. The first-order model leaves the second
    order (sag and lag of the flexible wire, measured 4e-3 eps^2 = 4e-7 here, 3.4e-7 with 16 segments:
    the chain's bending converges as N^-2 and its first-order part is exact for any N, rod-like
    segments). Tolerance 2e-6 = 0.02 eps^2, against the massless model's 2.6e-4; a kinetic share
    mu / 2 instead of mu / 3 would be 1.4e-3 off."""
    first, massless_error = _chain_error("parallel", 0.01, 8)
    assert abs(first) < 2e-6
    assert abs(massless_error) > 100 * abs(first)


def test_identify_follows_the_correction():
    """identify's inversion goes through modes: the heavy rig's own corrected period gives back its
    moment; read as massless, the same period gives the moment the closed form predicts,
    (I + 2 mu r^2 / 3) m / (m + mu)."""
    r = with_mass_ratio(rig("parallel"), 0.02)
    t = periods(r)["yaw"]
    inertia = r.inertia[2, 2]
    assert abs(invert_period(r, "z", t).moment / inertia - 1.0) < 1e-9
    mu, m = 0.02 * r.mass / 2.0, r.mass
    wrong = (inertia + 2 * mu * 0.2**2 / 3) * m / (m + mu)
    assert abs(invert_period(massless(r), "z", t).moment / wrong - 1.0) < 1e-9


def test_modes_names_the_massless_periods(tmp_path, capsys):
    path = tmp_path / "heavy.toml"
    path.write_text(PARALLEL.replace("length = 1.5\n", "length = 1.5\nlinear_density = 0.02\n"))  # both wires
    code, out, _ = run_cli(capsys, "modes", str(path), "--json")
    report = json.loads(out)
    assert code == 0 and "heavy wires" in report["model"]
    light = periods(rig("parallel"))
    for mode in report["modes"]:
        assert mode["massless_period"] == pytest.approx(light[mode["motion"]], rel=1e-12)
        assert mode["period"] != mode["massless_period"]
    code, out, _ = run_cli(capsys, "modes", str(path))
    assert code == 0 and out.count("[massless wires: ") == 4
