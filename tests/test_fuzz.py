"""Property-based tests (hypothesis) of the command line: malformed rig files, signal files and command
lines, and valid extreme rigs.

Every example runs ``validate.cli.main`` in-process and asserts the command-line contract:

* exit 0 with finite, physical output (rest tensions positive and holding the weight up), or
* exit 2 (bad input) or 4 (a run that failed, from a numerical exception only, never a programming
  error such as a TypeError) with exactly ONE stderr line ``error: SOURCE: FIELD: problem``;
* never a traceback, and within a bounded time.

Each property runs twice: a fast profile in the default run (a few hundred examples in all, ~20 s), and
a long one (10,000 examples in all) marked ``fuzz``, excluded by default and run with
``python -m pytest -m fuzz``.
"""

from __future__ import annotations

import functools
import json
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from validate.assets import MODELS, RIGS
from validate.cli import main

PROFILES = [pytest.param("fast", id="fast"),
            pytest.param("long", id="long", marks=[pytest.mark.fuzz, pytest.mark.slow])]
# examples per property: (fast, long); the long counts add up to 10,000.
EXAMPLES = {"rig_text": (120, 3500), "extreme": (25, 1500), "simulate": (6, 500), "argv": (150, 3000),
            "signal": (15, 1000), "sweep": (40, 500)}
SECONDS = 60.0  # the most one example may take (a modes call is ~0.1 s, a simulate ~1 s; 60 s is a hang)
# Exceptions that may end a run with exit 4: numerical failures. Anything else is a bug.
NUMERICAL = ("LinAlgError", "RuntimeError", "ValueError", "FloatingPointError", "ZeroDivisionError",
             "OverflowError", "BudgetSpent", "IntegrationError")
SHIPPED = sorted(p.read_text() for p in RIGS.glob("*.toml"))
# sweep files, each with the folder its relative paths start from
SWEEPS = sorted((p.parent.name, p.read_text()) for p in [*MODELS.glob("sweeps/*.toml"),
                                                         MODELS / "solar_boat" / "configurations.toml",
                                                         MODELS / "solar_boat" / "hall.toml"])
SWEEP_RUN_MAX = 64  # configurations: a valid mutated sweep this small is also run; a bigger one is real work


def _run(profile: str, name: str, strategy, check) -> None:
    """Run ``check`` on ``EXAMPLES[name]`` examples of ``strategy`` (fast or long profile)."""
    count = EXAMPLES[name][0 if profile == "fast" else 1]

    @settings(settings.get_profile("ci" if profile == "fast" else "fuzz"), max_examples=count)  # tests/conftest.py
    @given(strategy)
    def prop(example):
        check(example)

    prop()


def _call(capsys, argv: list[str]) -> tuple[int, str, str]:
    start = time.perf_counter()
    code = main(argv)
    seconds = time.perf_counter() - start
    out, err = capsys.readouterr()
    assert seconds < SECONDS, f"{argv}: took {seconds:.0f} s"
    assert "Traceback" not in err and "Traceback" not in out, err
    return code, out, err


def _assert_contract(code: int, out: str, err: str, source: str) -> None:
    """Exit 0, or 2 / 4 with one error line that names ``source`` and a field."""
    lines = [line for line in err.splitlines() if not line.startswith(("note: compiling", "warning: "))]
    if code == 0:
        assert not lines, err
        return
    assert code in (2, 4), (code, err)
    assert len(lines) == 1 and err.strip().count("\n") == 0, err
    line = lines[0]
    assert line.startswith("error: "), line
    if code == 4:
        assert line.startswith(f"error: {source}: "), line
        failed = re.search(r"run failed \((\w+):", line)
        assert failed and failed.group(1) in NUMERICAL, line
    if source and line.startswith(f"error: {source}: "):
        assert re.match(r"[^:]+: .+", line[len(f"error: {source}: "):]), line  # the file, then the field
    else:  # a usage error names the option or command, or another input file (a signal, an output)
        assert re.match(r"error: [^:]+: .+", line), line


# ------------------------------------------------------------------------------------------ values

_floats = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([0.0, -0.0, 5e-324, 1e-308, 1e-30, 1e-9, 1e-5, 1.0, 1e5, 1e30, 1e200, 1e308, -1.0, -1e308]),
)
_ints = st.one_of(st.integers(-10, 10), st.integers(-(10**400), 10**400), st.just(10**4000))


def _float_text(x: float) -> str:
    if np.isnan(x):
        return "nan"
    if np.isinf(x):
        return "inf" if x > 0 else "-inf"
    return repr(float(x))


_scalar = st.one_of(_floats.map(_float_text), _ints.map(str), st.sampled_from(['"heavy"', "true", "''", "1979-05-27"]))
_value = st.recursive(
    _scalar,
    lambda inner: st.one_of(
        st.lists(inner, max_size=4).map(lambda xs: "[" + ", ".join(xs) + "]"),
        st.lists(_floats.map(_float_text), min_size=3, max_size=3).map(lambda xs: "[" + ", ".join(xs) + "]"),
        st.dictionaries(st.sampled_from(["mass", "x", "anchor"]), inner, max_size=2).map(
            lambda d: "{" + ", ".join(f"{k} = {v}" for k, v in d.items()) + "}"),
    ),
    max_leaves=8,
)
_deep = st.integers(1, 1200).map(lambda n: "[" * n + "]" * n)


@st.composite
def _mutated(draw, texts, keys, headers) -> str:
    """One of ``texts`` with one to three mutations: a value replaced, a line dropped or repeated,
    a key (one of ``keys``) added, a table header (one of ``headers``) inserted, or bytes inserted."""
    lines = draw(st.sampled_from(texts)).splitlines()
    for _ in range(draw(st.integers(1, 3))):
        i = draw(st.integers(0, len(lines) - 1))
        op = draw(st.sampled_from(["value", "value", "value", "deep", "drop", "repeat", "key", "header", "junk"]))
        key = lines[i].split("=")[0].strip() if "=" in lines[i] else None
        if op in ("value", "deep") and key:
            lines[i] = f"{key} = {draw(_deep if op == 'deep' else _value)}"
        elif op == "drop":
            del lines[i]
        elif op == "repeat":
            lines.insert(i, lines[i])
        elif op == "key":
            lines.insert(i, f"{draw(st.sampled_from(keys))} = {draw(_value)}")
        elif op == "header":
            lines.insert(i, draw(st.sampled_from(headers)))
        elif op == "junk":
            lines.insert(i, draw(st.text(max_size=20)))
        if not lines:
            lines = [""]
    return "\n".join(lines) + "\n"


_mutated_rig = functools.partial(_mutated, SHIPPED, ["colour", "mass", "wire", "length", "omega"],
                                 ["[[wire]]", "[body]", "[initial]", "[uncertainty]", "[[body]]", "["])


@pytest.mark.parametrize("profile", PROFILES)
def test_malformed_rig_files(profile, tmp_path, capsys):
    path = tmp_path / "rig.toml"

    def check(text: str) -> None:
        path.write_text(text, encoding="utf-8", errors="surrogatepass") if _encodable(text) else path.write_bytes(
            text.encode("utf-8", "replace"))
        code, out, err = _call(capsys, ["modes", str(path), "--json"])
        _assert_contract(code, out, err, str(path))
        if code == 2:
            assert err.startswith(f"error: {path}: "), err  # a rig problem names the file
        if code == 0:
            _assert_physical_modes(out)

    _run(profile, "rig_text", _mutated_rig(), check)


def _encodable(text: str) -> bool:
    try:
        text.encode("utf-8")
        return True
    except UnicodeEncodeError:
        return False


def _assert_physical_modes(out: str) -> dict:
    data = json.loads(out)  # strict JSON: no NaN
    if data.get("kind") in ("pivot", "torsion"):  # a mutation that made a hinge rig: its one mode
        assert data["moment"] is None or data["moment"] > 0.0
        assert data["restoring"] is None or data["restoring"] > 0.0
        assert all(m["period"] is None or (np.isfinite(m["period"]) and m["period"] > 0.0) for m in data["modes"])
        return data
    tensions = np.array(data["equilibrium"]["tensions"])
    assert np.all(np.isfinite(tensions)) and np.all(tensions > 0.0)
    for mode in data["modes"]:
        assert mode["period"] is None or (np.isfinite(mode["period"]) and mode["period"] > 0.0)
        assert np.all(np.isfinite(mode["com_shape"])) and np.all(np.isfinite(mode["rotation_shape"]))
    return data


# ---------------------------------------------------------------------------------- extreme rigs


def _log_uniform(low: float, high: float):
    return st.floats(np.log10(low), np.log10(high)).map(lambda e: float(10.0**e))


@st.composite
def _extreme_rig(draw) -> dict:
    """A valid rig at the edges of the ranges: scale from 1 mm to 1 km, mass from 1 g to 1000 t, any
    splay, tilted hook line, unequal wires, a COM off the attachment line, a body from slender to flat."""
    scale = draw(_log_uniform(1e-2, 1e2))
    mass = draw(_log_uniform(1e-3, 1e6))
    half_span = scale * draw(st.floats(0.02, 1.0))  # attachment half-span
    splay = draw(st.floats(-0.6, 1.2))  # rad: wires leaning out (> 0) or in (< 0)
    length = scale * draw(st.floats(0.3, 3.0))
    ratio = draw(st.floats(0.7, 1.4))  # wire 2 / wire 1
    rise = [length * np.cos(splay), ratio * length * np.cos(splay)]
    out = [length * np.sin(splay), ratio * length * np.sin(splay)]
    com = [draw(st.floats(-0.3, 0.3)) * half_span, draw(st.floats(-0.5, 0.5)) * half_span,
           -draw(st.floats(0.0, 1.0)) * half_span]
    k = [draw(_log_uniform(1e-3, 1.0)) for _ in range(3)]
    a, b, c = sorted(k)
    if a + b < c:  # keep the triangle inequality of principal moments
        c = a + b
    moments = [mass * half_span**2 * m for m in draw(st.permutations([a, b, c]))]
    return {
        "mass": mass, "com": com, "inertia": moments,
        "wires": [([0.0, -half_span - out[0], rise[0]], [0.0, -half_span, 0.0], length),
                  ([0.0, half_span + out[1], rise[1]], [0.0, half_span, 0.0], ratio * length)],
    }


def _rig_toml(rig: dict) -> str:
    def vec(v):
        return "[" + ", ".join(repr(float(x)) for x in v) + "]"

    text = f"name = \"extreme\"\n[body]\nmass = {rig['mass']!r}\ncom = {vec(rig['com'])}\ninertia = {vec(rig['inertia'])}\n"
    for anchor, attach, length in rig["wires"]:
        text += f"[[wire]]\nanchor = {vec(anchor)}\nattach = {vec(attach)}\nlength = {length!r}\n"
    return text


@pytest.mark.parametrize("profile", PROFILES)
def test_valid_extreme_rigs_give_physical_modes_or_one_line(profile, tmp_path, capsys):
    path = tmp_path / "extreme.toml"

    def check(rig: dict) -> None:
        path.write_text(_rig_toml(rig))
        code, out, err = _call(capsys, ["modes", str(path), "--json"])
        _assert_contract(code, out, err, str(path))
        if code == 0:
            data = _assert_physical_modes(out)
            # Vertical force balance at rest, from the file's own numbers: sum T_i (anchor_z - attach_z) / L_i
            # = m g (the tensions are solved to ~1e-15 of the weight; 1e-6 allows the rest pose's residual).
            com = np.array(data["equilibrium"]["com"])
            rotation = np.array(data["equilibrium"]["rotation"])
            lift = 0.0
            for tension, (anchor, attach, length) in zip(data["equilibrium"]["tensions"], rig["wires"]):
                point = com + rotation @ (np.array(attach) - np.array(rig["com"]))
                lift += tension * (anchor[2] - point[2]) / length
            assert lift == pytest.approx(rig["mass"] * 9.81, rel=1e-6)

    _run(profile, "extreme", _extreme_rig(), check)


@pytest.mark.parametrize("profile", PROFILES)
def test_valid_extreme_rigs_simulate_or_refuse_in_one_line(profile, tmp_path, capsys):
    path, out_csv = tmp_path / "extreme.toml", tmp_path / "run.csv"

    def check(example) -> None:
        rig, engine = example
        path.write_text(_rig_toml(rig) + "[initial]\nrotation = [0.0, 0.0, 0.05]\n")
        out_csv.unlink(missing_ok=True)
        code, out, err = _call(capsys, ["simulate", str(path), "--engine", engine, "--duration", "0.04",
                                        "--dt-out", "0.01", "--max-seconds", "20", "--out", str(out_csv)])
        if code == 3:  # a wire went slack: the Kane CSV ends there, with no pushing wire
            assert err.count("\n") == 1 and "went slack" in err
        else:
            _assert_contract(code, "", err, str(path))
        if code in (0, 3):
            table = np.loadtxt(out_csv, delimiter=",", skiprows=1, ndmin=2)
            assert np.all(np.isfinite(table)) and np.all(table[:, 8:10] >= 0.0)
        else:
            assert not out_csv.exists()

    _run(profile, "simulate", st.tuples(_extreme_rig(), st.sampled_from(["kane", "mujoco"])), check)


# --------------------------------------------------------------------------------- command lines

_numberish = st.one_of(_floats.map(_float_text), _ints.map(str), st.sampled_from(["", "x", "1e400", "-", "0x10"]))
_option = st.one_of(
    st.tuples(st.sampled_from(["--duration", "--dt-out", "--rtol", "--max-seconds", "--jobs"]), _numberish),
    st.tuples(st.sampled_from(["--engine"]), st.sampled_from(["kane", "mujoco", "mujoco-eq", "bogus", ""])),
    st.tuples(st.sampled_from(["--out", "--json", "--rerun"]),
              st.sampled_from(["/proc/nope/x.csv", "", "/", "OUT/x.csv", "OUT/" + "n" * 300 + ".csv"])),
    st.tuples(st.sampled_from(["--json", "--slow", "-k", "--tag", "--bogus", "-h"]), st.just(None)),
)


@st.composite
def _argv(draw) -> list[str]:
    verb = draw(st.sampled_from(["modes", "simulate", "mjcf", "list", "case", "all", "nonsense", ""]))
    argv = [verb] if verb else []
    if verb in ("modes", "simulate", "mjcf"):
        argv.append(draw(st.sampled_from([str(RIGS / "plate.toml"), str(RIGS / "asymmetric.toml"), "/no/rig.toml",
                                          "/dev/null", str(RIGS), ""])))
    if verb == "case":
        argv.append(draw(st.sampled_from(["no-such-case", ""])))
    for flag, value in draw(st.lists(_option, max_size=5)):
        argv.append(flag)
        if value is not None:
            argv.append(value)
    if verb == "simulate" and draw(st.booleans()):
        argv += ["--duration", "0.02"]  # often runnable, so that the run itself is fuzzed too
    return argv


@pytest.mark.parametrize("profile", PROFILES)
def test_command_lines(profile, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)

    def check(argv: list[str]) -> None:
        argv = [a.replace("OUT/", f"{tmp_path}/out/") for a in argv]
        if argv[:1] == ["all"]:
            argv += ["-k", "no-such-case"]  # never the whole suite: the last -k wins
        if argv[:1] == ["simulate"]:
            argv += ["--max-seconds", "5"]  # a fuzzed long run stops at its wall-time budget (exit 4)
        code, out, err = _call(capsys, argv)
        if "-h" in argv and code == 0:
            assert "usage:" in out
            return
        if argv and argv[0] == "simulate" and code == 3:
            assert err.count("\n") == 1
            return
        _assert_contract(code, out, err, argv[1] if len(argv) > 1 else "")

    _run(profile, "argv", _argv(), check)


# --------------------------------------------------------------------------------------- signals


@st.composite
def _signal_csv(draw) -> str:
    """A recorded angle: sometimes a good damped oscillation, then damaged (headers, NaN, repeated or
    decreasing times, a byte-order mark, too few rows, text in a cell)."""
    n = draw(st.integers(0, 400))
    t = np.arange(n) * 0.02
    y = 0.05 * np.exp(-0.01 * t) * np.cos(2 * np.pi * t / 1.5)
    rows = [f"{a!r},{b!r}" for a, b in zip(t, y)]
    header = draw(st.sampled_from(["t,angle", "\ufefft,angle", "time,angle", "t,rate", "t;angle", ""]))
    for _ in range(draw(st.integers(0, 3))):
        if rows:
            i = draw(st.integers(0, len(rows) - 1))
            rows[i] = draw(st.sampled_from(["nan,0.1", "0,0", "x,y", "1e400,1", "", "1,2,3", rows[i - 1]]))
    return "\n".join([header] + rows) + "\n"


@pytest.mark.parametrize("profile", PROFILES)
def test_signal_files(profile, tmp_path, capsys):
    path = tmp_path / "signal.csv"

    def check(text: str) -> None:
        path.write_text(text)
        code, out, err = _call(capsys, ["identify", str(RIGS / "bench_plate.toml"), "--axis", "z", "--signal",
                                        str(path), "--json"])
        _assert_contract(code, out, err, str(RIGS / "bench_plate.toml"))
        if code == 0:
            data = json.loads(out)
            assert np.isfinite(data["inertia"]) and data["inertia"] > 0.0

    _run(profile, "signal", _signal_csv(), check)


@pytest.mark.slow
@pytest.mark.parametrize("profile", PROFILES)
def test_malformed_sweep_files(profile, tmp_path, capsys):
    """A mutated shipped sweep file (next to a copy of the models its paths name): the loader gives a
    space or one line naming the file; a valid space of at most SWEEP_RUN_MAX configurations is run,
    and the run keeps the contract (exit 1 only from a failed MuJoCo check, which is not asked here)."""
    from bifilar.rig import RigError
    from bifilar.sweep.space import load_space

    models = tmp_path / "models"
    shutil.copytree(MODELS, models)
    folders = {folder for folder, _ in SWEEPS}
    strategy = st.tuples(st.sampled_from(sorted(folders)), _mutated([text for _, text in SWEEPS],
                         ["wire_length", "steps", "from", "to", "axes", "tension", "floor", "rig", "objective", "name"],
                         ["[vary]", "[limits]", "[measure]", "[[point]]", "[", "[[vary]]"]))

    def check(example) -> None:
        folder, text = example
        path = models / folder / "fuzz.toml"
        path.write_text(text, encoding="utf-8", errors="surrogatepass") if _encodable(text) else path.write_bytes(
            text.encode("utf-8", "replace"))
        try:
            size = load_space(path).size
        except RigError as exc:
            assert str(exc).startswith(f"{path}: ") or str(exc).startswith(str(models)), exc
            size = 0
        if size > SWEEP_RUN_MAX:
            return
        code, out, err = _call(capsys, ["sweep", str(path), "--out", str(tmp_path / "out"), "--jobs", "1"])
        _assert_contract(code, out, err, str(path))

    _run(profile, "sweep", strategy, check)


def test_the_long_profile_holds_ten_thousand_examples():
    assert sum(long for _, long in EXAMPLES.values()) >= 10_000


def test_the_long_tiers_run_only_when_named():
    # -m on the command line replaces the default options' -m, so the tiers are left out by the conftest's
    # hook, whatever other expression chooses the run (the quick tier's "not slow" ran the 5-minute study)
    from conftest import left_out

    assert left_out("") == left_out("not slow") == {"fuzz", "long"}
    assert left_out("long") == {"fuzz"} and left_out("fuzz and not slow") == {"long"}
    assert left_out("longer") == {"fuzz", "long"}  # a word, not a substring


def test_the_quick_tier_collects_no_long_study():
    root = Path(__file__).resolve().parents[1]
    run = subprocess.run([sys.executable, "-m", "pytest", "tests/test_record_sigma.py", "-m", "not slow", "--collect-only",
                          "-q", "-p", "no:cacheprovider"], cwd=root, capture_output=True, text=True)
    assert run.returncode == 0, run.stdout[-500:]
    assert "unbiased[200" not in run.stdout and "deselected" in run.stdout.splitlines()[-1]
