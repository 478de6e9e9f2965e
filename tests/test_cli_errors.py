"""Errors that blamed the wrong thing (issue 35, items 8-14): each is one line on stderr naming the
file (or option, or stdout), the field and what is wrong, exit status 2, and nothing is written.

Each test runs ``validate.cli.main`` in-process, as ``tests/test_robust.py`` does, unless it needs a
real process (a full stdout).
"""

import subprocess
import sys
from pathlib import Path

import pytest

from test_robust import one_error, run_cli

from validate.cli import main

ROOT = Path(__file__).resolve().parents[1]


# ------------------------------------------------------------------------- 8: a folder as a rig


def test_a_folder_given_as_a_rig_is_not_a_regular_file(tmp_path, capsys):
    code, out, err = run_cli(capsys, "modes", tmp_path)
    assert code == 2 and out == ""
    assert one_error(err) == (f"error: {tmp_path}: file: is not a regular file (a pipe, device or folder cannot be "
                              "read as input)")


@pytest.mark.parametrize("verb, text", [
    ("tensor", '[[hanging]]\nrig = "."\nperiod = 1.0\n' * 6),
    ("plan", 'rig = "."\ngenerate = 10\n'),
])
def test_a_folder_named_as_rig_inside_a_file_is_not_a_regular_file(tmp_path, capsys, verb, text):
    path = tmp_path / "in.toml"
    path.write_text(text)
    code, out, err = run_cli(capsys, verb, path, *(["--count", "6"] if verb == "plan" else []))
    assert code == 2 and out == ""
    assert one_error(err).startswith(f"error: {tmp_path}: file: is not a regular file"), err


# ------------------------------------------------------------- 13: the axial_stiffness axis's unit


def test_a_sweep_s_axial_stiffness_below_zero_is_refused_in_its_own_unit(tmp_path, capsys):
    space = tmp_path / "space.toml"
    space.write_text(f'rig = "{ROOT / "models/rigs/bench_plate.toml"}"\n[vary]\naxial_stiffness = [-1.0, 1e6]\n')
    code, out, err = run_cli(capsys, "sweep", space, "--out", tmp_path / "out")
    assert code == 2 and out == ""
    assert one_error(err) == f"error: {space}: vary.axial_stiffness: must be above zero (a wire's E A, N); found -1"


# ----------------------------------------------------- 12: an output folder that cannot be one


@pytest.mark.parametrize("out, reason", [
    ("afile", "is a regular file, not a folder"),
    ("afile/sub", "is under {tmp}/afile, which is a regular file, not a folder"),
    ("afile/sub/deeper", "is under {tmp}/afile, which is a regular file, not a folder"),
])
def test_sweep_out_that_cannot_be_a_folder_names_the_path_given(tmp_path, capsys, out, reason):
    (tmp_path / "afile").write_text("kept\n")
    code, stdout, err = run_cli(capsys, "sweep", "bench_plate", "--out", tmp_path / out)
    assert code == 2 and stdout == ""
    assert one_error(err) == f"error: {tmp_path / out}: cannot write ({reason.format(tmp=tmp_path)})"
    assert "probe" not in err and (tmp_path / "afile").read_text() == "kept\n"


def test_a_file_output_under_a_regular_file_says_so(tmp_path, capsys):
    (tmp_path / "afile").write_text("kept\n")
    code, out, err = run_cli(capsys, "case", "no-such-case", "--json", tmp_path / "afile/report.json")
    assert code == 2
    assert one_error(err) == (f"error: {tmp_path}/afile/report.json: cannot write (is under {tmp_path}/afile, which "
                              "is a regular file, not a folder)")


# ------------------------------------------------------------- 14: one path for two outputs


@pytest.mark.parametrize("argv, first, second", [
    (["all", "-k", "no-such-case", "--json", "{p}", "--junit", "{p}"], "json", "junit"),
    (["case", "no-such-case", "--html", "{p}", "--junit", "./{p}"], "junit", "html"),
    (["simulate", "plate", "--duration", "0.1", "--out", "{p}", "--rerun", "{p}"], "out", "rerun"),
])
def test_one_path_for_two_outputs_is_refused_before_anything_is_written(tmp_path, capsys, monkeypatch, argv,
                                                                         first, second):
    monkeypatch.chdir(tmp_path)
    code, out, err = run_cli(capsys, *[a.format(p="report.out") for a in argv])
    assert code == 2 and out == ""
    line = one_error(err)
    assert line.startswith(f"error: --{second}: ") and f"is also the --{first} output" in line, line
    assert not (tmp_path / "report.out").exists()


# ------------------------------------------------------------- 11: a tare in some hangings only


@pytest.mark.parametrize("bare", [4, 1])
def test_a_tare_in_some_hangings_only_names_the_hanging_without_one(tmp_path, capsys, bare):
    import re

    from validate.cases.tensor import write_tare_hangings

    path = Path(write_tare_hangings(tmp_path, [2.0] * 7, 2.0, 1e-6, 1e-6))  # refused before any period is used
    tables = path.read_text().split("[[hanging]]")
    tables[bare] = re.sub(r"tare = .*\n", "", tables[bare])
    path.write_text("[[hanging]]".join(tables))
    code, out, err = run_cli(capsys, "tensor", path)
    assert code == 2 and out == ""
    other = 2 if bare == 1 else 1
    assert one_error(err) == (f"error: {path}: hanging[{bare}].tare: missing in hanging[{bare}], given in "
                              f"hanging[{other}]: give a tare in every hanging or in none (with one, each rig's body "
                              "is the whole assembly)")


# ------------------------------------------------------------------------- 9: a full stdout


@pytest.mark.skipif(not Path("/dev/full").exists(), reason="needs /dev/full")
def test_a_full_stdout_is_named_not_the_rig():
    with open("/dev/full", "w") as full:
        proc = subprocess.run([sys.executable, "-m", "validate", "modes", "plate", "--json"], stdout=full,
                              stderr=subprocess.PIPE, text=True, cwd=ROOT, timeout=60)
    assert proc.returncode == 2
    assert one_error(proc.stderr) == "error: stdout: cannot write (No space left on device)"


class _FullStream:
    """A stdout whose every write fails as a full device's does (a report larger than the buffer)."""

    def write(self, text):
        raise OSError(28, "No space left on device")

    def flush(self):
        pass

    def fileno(self):
        raise OSError(9, "no descriptor")


def test_a_write_that_fails_inside_a_command_is_stdout_s(capsys, monkeypatch):
    monkeypatch.setattr(sys, "stdout", _FullStream())
    code = main(["list", "--rigs"])
    assert code == 2
    assert one_error(capsys.readouterr().err) == "error: stdout: cannot write (No space left on device)"


# -------------------------------------------------- 10: absurd values in hangings and candidates


HANGING = f'[[hanging]]\nrig = "{ROOT / "models/rigs/trifilar.toml"}"\norientation = [0.0, 0.0, 0.0]\nperiod = 2.0\n'


@pytest.mark.parametrize("old, new, field, words", [
    ("orientation = [0.0, 0.0, 0.0]", "orientation = [1e300, 0, 0]", "orientation", "at most a turn"),
    ("orientation = [0.0, 0.0, 0.0]", "orientation = [0.0, 0.0, 90.0]", "orientation", "is it in degrees?"),
    ("period = 2.0", "period = 1e300", "period", "1e+300 s is outside 0.001 .. 100000 s"),
    ("period = 2.0", "period = 1e-300", "period", "1e-300 s is outside"),
    ("period = 2.0", "period = 2.0\nperiod_std = 1e300", "period_std", "1e+300 s is outside 0 .. 100 s"),
    ("period = 2.0", "period = 2.0\nperiod_std = 50.0", "period_std", "more than 0.5 of the period 2 s"),
    ("period = 2.0", 'period = 2.0\ntare = { rig = "t.toml", period = 1e300 }', "tare.period", "outside"),
])
def test_absurd_values_in_a_hangings_file_name_the_file_and_field(tmp_path, capsys, old, new, field, words):
    path = tmp_path / "hangings.toml"
    path.write_text(HANGING.replace(old, new) + "\n" + HANGING * 6)
    code, out, err = run_cli(capsys, "tensor", path)
    assert code == 2 and out == ""
    line = one_error(err)
    assert line.startswith(f"error: {path}: hanging[1].{field}: ") and words in line, line


@pytest.mark.parametrize("text, field", [
    ("generate = 10\nperiod_std = 1e300\n", "period_std"),
    ("period_std = 1e-4\n[[candidate]]\norientation = [1e300, 0, 0]\n", "candidate[1].orientation"),
])
def test_absurd_values_in_a_candidates_file_name_the_file_and_field(tmp_path, capsys, text, field):
    path = tmp_path / "candidates.toml"
    path.write_text(f'rig = "{ROOT / "models/rigs/trifilar.toml"}"\n' + text)
    code, out, err = run_cli(capsys, "plan", path, "--count", "6")
    assert code == 2 and out == ""
    assert one_error(err).startswith(f"error: {path}: {field}: "), err


# ------------------------------------------------------- exit 4: the field blamed, keyed by module


def _defines(module, name: str) -> bool:
    """Whether ``module`` itself defines a function, or a method of one of its classes, whose frames are
    called ``name`` (what ``validate.cli._likely_field`` matches)."""
    import inspect

    owners = [module] + [c for c in vars(module).values() if inspect.isclass(c) and c.__module__ == module.__name__]
    codes = [getattr(getattr(owner, name, None), "__code__", None) for owner in owners]
    return any(code is not None and code.co_name == name and code.co_filename == module.__file__ for code in codes)


def test_every_module_and_function_named_in_the_exit_4_table_exists():
    """The table cannot go stale unnoticed: a module moved or renamed, or a function renamed, fails here
    instead of silently changing which field an exit-4 message names."""
    import importlib

    from validate.cli import _LIKELY_FIELD

    for key in _LIKELY_FIELD:
        module_name, function = key if isinstance(key, tuple) else (key, None)
        module = importlib.import_module(module_name)
        assert function is None or _defines(module, function), f"{module_name} defines no {function}"


def test_a_failure_in_a_command_module_itself_names_the_rig(capsys, monkeypatch):
    """``modes``'s own module (validate/commands/modes.py) is not bifilar/motion/modes.py: a failure whose
    innermost frames are not in the table names the whole rig, not the field of a namesake file."""
    import numpy as np

    def singular(*args, **kwargs):
        raise np.linalg.LinAlgError("Singular matrix")

    monkeypatch.setattr("bifilar.motion.modes.linearize", singular)
    code, out, err = run_cli(capsys, "modes", ROOT / "models/rigs/plate.toml")
    assert code == 4 and out == ""
    assert one_error(err).startswith(f"error: {ROOT / 'models/rigs/plate.toml'}: rig: the modes run failed "
                                     "(LinAlgError: Singular matrix)"), err
