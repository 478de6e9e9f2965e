"""Robustness of the command line: physical ranges, bounded runs, honest outputs, one-line errors.

Each test runs ``validate.cli.main`` in-process (fast) unless the behaviour needs a real process
(signals, pipes). An error is always one line on stderr starting ``error: FILE: FIELD: `` (or
``error: --option: ``) with the documented exit status.
"""

import os
import signal
import subprocess
import sys
import time
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from bifilar.rig import load_rig
from validate.assets import RIGS
from validate.cli import main

ROOT = Path(__file__).resolve().parents[1]
GOOD = (RIGS / "plate.toml").read_text()
INERTIA = "inertia = [216.66666666666666, 60.416666666666664, 260.4166666666667]"


def run_cli(capsys, *args):
    code = main([str(a) for a in args])
    out, err = capsys.readouterr()
    return code, out, err


def one_error(err: str) -> str:
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("error: "), err
    return lines[0]


# ------------------------------------------------------------------------------------- rig ranges


@pytest.mark.parametrize(
    "edit, field, words",
    [
        # A huge integer is not a float: refused, not an OverflowError.
        (lambda s: s.replace("mass = 100.0", "mass = -123456789012345678901234567890" + "0" * 300), "body.mass", "too large"),
        (lambda s: s.replace("mass = 100.0", "mass = 1e-30"), "body.mass", "outside 0.001 .. 1e+06 kg"),
        (lambda s: s.replace("mass = 100.0", "mass = 1e30"), "body.mass", "outside"),
        (lambda s: s.replace("gravity = 9.81", "gravity = 1.7e308"), "gravity", "outside 0.1 .. 100"),
        (lambda s: s.replace("[0.0, -5.0, 4.830127018922193]", "[0.0, -5.0, 1e200]"), "wire[1].anchor[2]", "outside"),
        (lambda s: s.replace("attach = [0.0, 2.5, 0.5]", "attach = [0.0, -2.49999999, 0.5]"), "wire[2].attach",
         "coincides"),
        (lambda s: s.replace(INERTIA, "inertia = [1e-9, 1.0, 1.0]"), "body.inertia", "outside"),
        (lambda s: s.replace("com = [0.0, 0.0, 0.0]", "com = [0.0, 0.0, -1000.0]"), "body.com", "nearest attachment"),
        (lambda s: s.replace("omega = [0.0, 0.0, 0.0]", "omega = [0.0, 0.0, 1e15]"), "initial.omega", "rad/s"),
        (lambda s: s.replace("rotation = [0.0, 0.0, 0.1745]", "rotation = [0.0, 0.0, 7.0]"), "initial.rotation", "pi"),
        (lambda s: s + "\n[uncertainty]\nlength = 5e-324\n", "uncertainty.length", "outside"),
        (lambda s: s + "\n[uncertainty]\nmass = 80.0\n", "uncertainty.mass", "outside"),
        (lambda s: s.replace("mass = 100.0", "mass = " + "[" * 1000 + "]" * 1000), "toml", "nested too deeply"),
        (lambda s: s.replace("mass = 100.0", "mass = " + "9" * 5000), "toml", "4300 digits"),
        # The sign of wire 2's anchor height flipped: a guy wire, not a pendulum.
        (lambda s: s.replace("anchor = [0.0, 5.0, 4.830127018922193]", "anchor = [0.0, 5.0, -4.830127018922193]"),
         "wire[2].anchor", "below"),
    ],
)
def test_out_of_range_rig_fields_are_one_line(tmp_path, capsys, edit, field, words):
    path = tmp_path / "bad.toml"
    path.write_text(edit(GOOD))
    code, out, err = run_cli(capsys, "modes", path)
    assert code == 2 and out == ""
    line = one_error(err)
    assert line.startswith(f"error: {path}: {field}: "), line
    assert words in line, line


def test_a_wire_that_carries_nothing_at_rest_is_refused_every_time(tmp_path, capsys):
    """The asymmetric rig with its COM at wire 1's attachment: wire 2 carries ~6e-31 N at rest, taut or
    slack by the sign of a rounding error (eight runs once exited 2 2 2 2 2 2 0 0); refused, always."""
    path = tmp_path / "com_at_attach.toml"
    path.write_text((RIGS / "asymmetric.toml").read_text().replace("com = [0.03, -0.02, -0.08]",
                                                                    "com = [-0.42, -0.18, 0.1]"))
    for engine in ("kane", "mujoco"):
        code, _, err = run_cli(capsys, "simulate", path, "--engine", engine, "--duration", "0.1", "--out",
                               tmp_path / "x.csv")
        assert code == 2 and one_error(err).startswith(f"error: {path}: wire[2]: "), err
        assert "the body hangs from the other wire alone" in err or "slack at rest" in err


def test_every_shipped_rig_is_inside_the_ranges():
    for path in sorted(RIGS.glob("*.toml")):
        load_rig(path, hinge=True)  # raises RigError otherwise


def test_the_ranges_are_documented():
    from bifilar.rig import ranges

    doc = (ROOT / "docs" / "rig-file.md").read_text()
    for field, (low, high, unit, _) in ranges.RANGES.items():
        assert f"`{field}`" in doc and f"{low:g}" in doc and f"{high:g}" in doc, field
    for name in ("MIN_ATTACH_SPAN", "MAX_COM_OFFSET", "MIN_INERTIA", "MAX_INERTIA", "MAX_OMEGA"):
        assert f"{getattr(ranges, name):g}" in doc, name
    assert all(f"{x:g}" in doc for x in ranges.AIR_SIZE)


def test_a_hundred_thousand_wires_are_refused_before_any_physics(tmp_path, capsys):
    """100,000 wires crashed MuJoCo's compiler; they are refused by size (a 7.5 MB file), and any number
    of wires but two by count, before a model is built."""
    wire = "[[wire]]\nanchor = [0.0, -5.0, 4.83]\nattach = [0.0, -2.5, 0.5]\nlength = 5.0\n"
    head = GOOD.split("[[wire]]")[0]
    for count, words in ((100_000, "more than the 1048576"), (1000, "found 1000")):
        path = tmp_path / "many.toml"
        path.write_text(head + wire * count)
        code, _, err = run_cli(capsys, "simulate", path, "--engine", "mujoco", "--duration", "0.1", "--out",
                               tmp_path / "x.csv")
        assert code == 2 and words in one_error(err)


def test_a_named_pipe_is_refused_not_waited_on(tmp_path, capsys):
    fifo = tmp_path / "rig.toml"
    os.mkfifo(fifo)
    code, _, err = run_cli(capsys, "modes", fifo)
    assert code == 2 and one_error(err) == f"error: {fifo}: file: is not a regular file (a pipe, device or folder " \
                                           "cannot be read as input)"


def test_an_oversized_file_is_refused(tmp_path, capsys):
    path = tmp_path / "big.toml"
    path.write_text(GOOD + "#" * (1 << 20))
    code, _, err = run_cli(capsys, "modes", path)
    assert code == 2 and "file: is " in one_error(err) and "bytes" in err


def test_a_byte_order_mark_and_a_250_character_name_are_accepted(tmp_path, capsys):
    path = tmp_path / ("r" * 245 + ".toml")
    path.write_bytes(b"\xef\xbb\xbf" + GOOD.encode())
    out = tmp_path / ("r" * 246 + ".csv")  # 250 characters
    code, _, err = run_cli(capsys, "simulate", path, "--duration", "0.02", "--out", out)
    assert code == 0, err
    assert out.read_text().startswith("t,com_x")


# ------------------------------------------------------------------------------------ bounded runs


@pytest.mark.parametrize(
    "args, option, words",
    [
        (("--duration", "1", "--rtol", "0.5"), "--rtol", "[1e-13, 0.0001]"),
        (("--duration", "1", "--rtol", "1"), "--rtol", "[1e-13, 0.0001]"),
        (("--duration", "0.005"), "--duration", "shorter than --dt-out"),
        (("--duration", "1e5"), "--duration", "10000001 samples"),
        (("--duration", "1e6"), "--duration", "(0, 100000] s"),
        (("--duration", "2000", "--engine", "mujoco", "--dt-out", "1"), "--duration", "MuJoCo steps"),
        (("--duration", "1", "--engine", "mujoco", "--dt-out", "0.0123457"), "--dt-out", "whole number"),
    ],
)
def test_run_options_have_ranges(tmp_path, capsys, args, option, words):
    out = tmp_path / "x.csv"
    code, _, err = run_cli(capsys, "simulate", RIGS / "plate.toml", *args, "--out", out)
    line = one_error(err)
    assert code == 2 and option in line and words in line, line
    assert not out.exists()


def test_a_duration_that_is_not_a_multiple_of_dt_out_says_where_it_ends(tmp_path, capsys):
    out = tmp_path / "x.csv"
    code, stdout, err = run_cli(capsys, "simulate", RIGS / "plate.toml", "--duration", "1", "--dt-out", "0.7",
                                "--out", out)
    assert code == 0 and err == ""
    assert stdout.count("\n") == 1 and "ends at 0.7 s" in stdout and "last 0.3 s are not sampled" in stdout
    assert [line.split(",")[0] for line in out.read_text().splitlines()[1:]] == ["0.0", "0.7"]


def test_simulate_prints_a_one_line_summary(tmp_path, capsys):
    out = tmp_path / "x.csv"
    code, stdout, _ = run_cli(capsys, "simulate", RIGS / "plate.toml", "--duration", "0.5", "--out", out)
    assert code == 0
    assert stdout == f"kane on plate: t = 0 .. 0.5 s, 51 samples every 0.01 s; tensions " \
                     f"{_tension_range(out)} N; wrote {out}\n"


def _tension_range(csv) -> str:
    table = np.loadtxt(csv, delimiter=",", skiprows=1)
    return f"{table[:, 8:10].min():.6g} .. {table[:, 8:10].max():.6g}"


def test_the_kane_work_budget_stops_a_run():
    from bifilar.motion.kane import KaneModel
    from bifilar.motion.simulate import Budget, BudgetSpent, simulate
    from bifilar.rig.statics import initial_state

    rig = load_rig(RIGS / "plate.toml")
    model = KaneModel.from_rig(rig)
    # 10 s need ~2700 evaluations at rtol 1e-10 (~270 per simulated second): 1000 cannot do it.
    with pytest.raises(BudgetSpent, match="work budget spent"):
        simulate(model, initial_state(rig), 10.0, budget=Budget(rhs_per_second=0.0, rhs_floor=1000))
    run = simulate(model, initial_state(rig), 1.0)  # the default budget does not bind an ordinary run
    assert run.t[-1] == 1.0 and 100 < run.nfev < Budget().rhs_limit(1.0) / 1000


@pytest.mark.parametrize("engine", ["kane", "mujoco"])
def test_a_spent_wall_time_budget_is_exit_4(tmp_path, capsys, engine):
    out = tmp_path / "x.csv"
    start = time.perf_counter()
    code, _, err = run_cli(capsys, "simulate", RIGS / "plate.toml", "--engine", engine, "--duration", "900",
                           "--max-seconds", "0.5", "--out", out)
    line = one_error(err)
    assert code == 4 and line.startswith(f"error: {RIGS / 'plate.toml'}: initial: ") and "budget" in line, line
    assert time.perf_counter() - start < 30.0  # 0.5 s of budget, checked every ~15 ms of work
    assert not out.exists()


def test_a_numerical_failure_inside_the_physics_is_exit_4_naming_a_field(tmp_path, capsys, monkeypatch):
    """A singular matrix in the rest pose (forced here: the ranges keep real files away from one)."""
    import scipy.optimize

    def singular(*args, **kwargs):
        raise np.linalg.LinAlgError("Singular matrix")

    monkeypatch.setattr("bifilar.rig.statics._memo", {})  # no rest pose remembered from an earlier test
    monkeypatch.setattr("bifilar.rig.statics.minimize", singular)
    code, out, err = run_cli(capsys, "modes", RIGS / "plate.toml")
    line = one_error(err)
    assert code == 4 and out == ""
    assert line.startswith(f"error: {RIGS / 'plate.toml'}: wire: the modes run failed (LinAlgError: Singular matrix)")
    assert scipy.optimize.minimize is not singular


def test_warnings_before_an_error_are_dropped(tmp_path, capsys, monkeypatch):
    import warnings

    def noisy(*args, **kwargs):
        warnings.warn("overflow encountered in multiply", RuntimeWarning)
        raise ValueError("array must not contain infs or NaNs")

    monkeypatch.setattr("bifilar.rig.statics._memo", {})  # no rest pose remembered from an earlier test
    monkeypatch.setattr("bifilar.rig.statics.minimize", noisy)
    code, _, err = run_cli(capsys, "modes", RIGS / "plate.toml")
    assert code == 4 and "ValueError" in one_error(err)


def test_outputs_are_checked_before_the_work(capsys):
    start = time.perf_counter()
    code, _, err = run_cli(capsys, "boat", "--png", "/proc/nope/x.png")
    assert code == 2 and one_error(err) == "error: /proc/nope/x.png: cannot write (No such file or directory)"
    assert time.perf_counter() - start < 2.0  # the study takes ~10 s: it never started


def test_an_unwritable_output_is_reported_under_the_users_path(tmp_path, monkeypatch):
    """A failure while writing the hidden temporary file or renaming it names the user's file, and
    leaves nothing behind."""
    import errno

    from validate import trajectory

    target = tmp_path / "x.csv"

    def failing_replace(src, dst):
        raise OSError(errno.EROFS, "Read-only file system", str(src))

    monkeypatch.setattr(trajectory.os, "replace", failing_replace)
    with pytest.raises(OSError) as info:
        trajectory.atomic_write_text(target, "data")
    assert info.value.filename == str(target) and info.value.strerror == "Read-only file system"
    assert list(tmp_path.iterdir()) == []


# ---------------------------------------------------------------------------------- processes


def _cli(*args, **kwargs):
    return subprocess.run([sys.executable, "-m", "validate", *map(str, args)], cwd=ROOT, capture_output=True,
                          text=True, timeout=120, **kwargs)


@pytest.mark.slow
def test_a_closed_pipe_is_quiet():
    proc = subprocess.run(f"{sys.executable} -m validate list | head -c 10", shell=True, cwd=ROOT,
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0 and "Error" not in proc.stderr and "error" not in proc.stderr, proc.stderr


@pytest.mark.slow
def test_ctrl_c_is_one_line_and_exit_130(tmp_path):
    proc = subprocess.Popen([sys.executable, "-m", "validate", "simulate", str(RIGS / "plate.toml"), "--duration",
                             "3600", "--out", str(tmp_path / "x.csv")], cwd=ROOT, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    # into the integration (imports take ~1.5 s; an interrupt during them is handled too), which runs
    # ~20 s warm for 3600 s of motion (900 s took 6.2 s in all, and the signal met the exit)
    time.sleep(6.0)
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    lines = [line for line in err.splitlines() if not line.startswith("note: compiling")]
    assert proc.returncode == 130 and lines == ["error: interrupted"], err
    assert not (tmp_path / "x.csv").exists() and list(tmp_path.iterdir()) == []


def _help(capsys, monkeypatch, *verb) -> str:
    """``python -m validate [VERB] --help`` as a process with its output piped prints it (in-process: the
    same parser, without a second interpreter's ~2 s of imports); argparse wraps at COLUMNS, 80 in a pipe."""
    monkeypatch.setenv("COLUMNS", "80")
    code, out, err = run_cli(capsys, *verb, "--help")
    assert code == 0 and not err, err
    return out


def test_help_lists_exit_codes_an_example_and_option_units(capsys, monkeypatch):
    top = _help(capsys, monkeypatch)
    for text in ("exit status:", "  4    a run that failed", "  130  interrupted", "examples:",
                 "python -m validate modes models/rigs/plate.toml"):
        assert text in top, text
    sim = _help(capsys, monkeypatch, "simulate")
    for text in ("{kane,nwire,mujoco,mujoco-eq,mujoco-cable}", "simulated time, s", "(default: 0.01)", "(default: 1e-10",
                 "wall-time budget of the run, s"):
        assert text in " ".join(sim.split()), text


# ------------------------------------------------------------------------------ first run that talks


def test_list_shows_whole_descriptions(capsys):
    from validate.suite import registered

    code, out, _ = run_cli(capsys, "list")
    assert code == 0
    flat = " ".join(out.split())
    for c in registered(slow=True):
        assert f"{c.name} [" in flat and " ".join(c.description.split()) in flat, c.name


def test_all_selects_by_pattern_and_tag_and_reports_each_case(capsys):
    code, out, err = run_cli(capsys, "all", "-k", "seed002-mass", "--jobs", "1")
    assert code == 0
    progress = [line for line in err.splitlines() if line.startswith("[")]
    assert len(progress) == 1 and progress[0].startswith("[1/1] seed002-mass-bias: pass in ")
    assert "1 passed, 0 failed (1 cases" in out
    code, _, err = run_cli(capsys, "all", "--tag", "no-such-tag")
    assert code == 2 and "no case matches --tag no-such-tag" in one_error(err)


def test_select_globs_and_tags():
    from validate.suite import registered, select

    cases = registered(slow=True)
    assert {c.name for c in select(cases, "seed00?-*")} == {c.name for c in cases if c.name.startswith("seed00")}
    assert all("slow" in c.tags for c in select(cases, tags=["slow"]))


def test_mjcf_writes_one_folder_per_rig_and_refuses_clashing_names(tmp_path, capsys):
    code, out, err = run_cli(capsys, "mjcf", RIGS / "plate.toml", RIGS / "asymmetric.toml", "--out", tmp_path)
    assert code == 0, err
    assert out.split() == [str(tmp_path / n / f) for n in ("plate", "asymmetric") for f in (f"{n}.xml", "scene.xml")]
    for name in ("plate", "asymmetric"):
        assert f'<include file="{name}.xml"/>' in (tmp_path / name / "scene.xml").read_text()
    twin = tmp_path / "twin.toml"
    twin.write_text(GOOD)  # also named "plate"
    code, _, err = run_cli(capsys, "mjcf", RIGS / "plate.toml", twin, "--out", tmp_path / "again")
    assert code == 2 and one_error(err).startswith(f"error: {twin}: name: 'plate' is also the name of ")
    assert not (tmp_path / "again" / "plate").exists()


def test_the_module_writer_does_not_overwrite_another_models_scene(tmp_path, capsys):
    from validate.engines.mjcf import main as mjcf_main

    assert mjcf_main([str(RIGS / "plate.toml"), str(tmp_path)]) == 0
    capsys.readouterr()
    assert mjcf_main([str(RIGS / "asymmetric.toml"), str(tmp_path)]) == 2
    line = one_error(capsys.readouterr().err)
    assert line.startswith(f"error: {tmp_path / 'scene.xml'}: cannot write (is the scene of another model")
    assert '<include file="plate.xml"/>' in (tmp_path / "scene.xml").read_text()
    assert not (tmp_path / "asymmetric.xml").exists()


def test_numba_cache_is_outside_the_source_tree_and_a_first_compile_is_announced(tmp_path, monkeypatch):
    """A fresh cache folder: the first Kane run says, in one line, that it compiles; the second is quiet."""
    env = {**os.environ, "XDG_CACHE_HOME": str(tmp_path)}
    env.pop("NUMBA_CACHE_DIR", None)
    code = "import bifilar.motion.kane_kernel, numba; print(numba.config.CACHE_DIR)"
    proc = subprocess.run([sys.executable, "-c", code], cwd=ROOT, env=env, capture_output=True, text=True, timeout=60)
    from bifilar.jit import kernels_key

    assert proc.stdout.strip() == str(tmp_path / "bifilar-validate" / "numba" / kernels_key())
    from bifilar import jit
    from bifilar.jit import announce_compile

    monkeypatch.setattr(jit, "_announced", set())  # as in a new process (an earlier test may have announced all)

    def kernel(index):  # a numba dispatcher as announce_compile sees it: its cache's index of entries
        return SimpleNamespace(_cache=SimpleNamespace(_cache_file=SimpleNamespace(_load_index=lambda: index)))

    # Fresh: no cache entry, as numba sees a first run; Cached: an entry (not K.rhs itself, whose cache
    # is empty on a fresh machine when no earlier test in this worker has run the Kane model)
    Fresh, Cached = kernel({}), kernel({"signature": "entry"})

    import contextlib
    import io

    buffer = io.StringIO()
    with contextlib.redirect_stderr(buffer):
        announce_compile("test kernels", Cached, Fresh)
        announce_compile("test kernels", Cached, Fresh)  # once per process
        announce_compile("the cached kernels", Cached)
    assert buffer.getvalue().count("\n") == 1 and buffer.getvalue().startswith("note: compiling test kernels with numba")


def test_a_kane_csv_that_stops_at_a_slack_wire_ends_with_no_pushing_wire(tmp_path, capsys):
    """The plate (turned 0.1745 rad) spun at 4 rad/s about x: wire 1 goes slack at 0.0912 s (exit 3). Every row, the last
    included, has tensions >= 0 (the README: 0 when slack, never pushing); the last row is the last
    sample before the slack time."""
    path = tmp_path / "spin.toml"
    path.write_text(GOOD.replace("omega = [0.0, 0.0, 0.0]", "omega = [4.0, 0.0, 0.0]"))
    out = tmp_path / "spin.csv"
    code, _, err = run_cli(capsys, "simulate", path, "--duration", "1", "--out", out)
    assert code == 3 and one_error(err).startswith(f"error: {path}: wire[1]: went slack at t = 0.0912")
    table = np.loadtxt(out, delimiter=",", skiprows=1)
    assert table[-1, 0] == pytest.approx(0.09) and table[:, 8:10].min() >= 0.0


def test_the_rig_file_doc_states_the_wire_count_the_reader_accepts():
    """The wire count of docs/rig-file.md is the reader's (2 .. MAX_WIRES), not "exactly two"."""
    from bifilar.rig import ranges

    doc = (ROOT / "docs" / "rig-file.md").read_text()
    assert "exactly two [[wire]]" not in doc
    assert f"2 to {ranges.MAX_WIRES} of them" in doc and f"| 2 .. {ranges.MAX_WIRES} (`MAX_WIRES`)" in doc


@pytest.mark.parametrize("verb", ["all", "list", "case", "modes", "simulate", "mjcf", "identify", "calibrate", "boat", "sweep",
                                  "tensor", "plan"])
def test_every_verbs_help_lists_exactly_its_exit_statuses(verb, capsys, monkeypatch):
    """One source (validate/statuses.py): each verb's --help lists the statuses it can return, no
    others, within 100 columns."""
    from validate.statuses import COMMANDS

    out = _help(capsys, monkeypatch, verb)
    block = out.split("exit status:\n")[1].split("\n\n")[0].splitlines()
    listed = [int(line.split()[0]) for line in block if not line.startswith("       ")]
    assert listed == sorted(COMMANDS[verb])
    assert all(len(line) <= 100 for line in out.splitlines())
