"""The identification library (:mod:`bifilar.identification.measurement`): the typed result every face of
the tool reads, the one ``identify --json`` prints, and the tare's transfer with an off-axis object."""

from __future__ import annotations

import dataclasses
import json
import math

import numpy as np
import pytest

from test_identify import BENCH, write_rig

from bifilar.identification import identify as ident
from bifilar.identification.measurement import measure, said_once, start_moment, subtract_tare, tensor_check
from bifilar.rig import load_rig
from validate.assets import rig
from validate.cli import main


def test_the_moment_of_the_rig_s_own_period_is_the_rig_s_moment():
    """Inverting the period the rig predicts gives its own I_zz back: the eigenproblem's rounding, ~1e-12."""
    r = rig("bench_plate")
    result = measure(r, "z", period=ident.linear_period(r, "z"))
    assert result.inertia == pytest.approx(0.15, rel=1e-10)
    assert result.tensor_check.body and result.flags == ()
    assert result.inertia_per_mass == pytest.approx(0.15 / 4.0, rel=1e-10)
    # the interval is the propagated sigma's (linear: symmetric, 1.96 sigma)
    low, high = result.interval95
    assert 0.5 * (high - low) == pytest.approx(1.959963984540054 * result.std, rel=1e-9)
    with pytest.raises(dataclasses.FrozenInstanceError):
        result.inertia = 1.0


def test_the_cli_prints_the_library_s_result(capsys):
    """``identify --json`` is the library's ``as_dict`` (non-finite numbers as null), nothing added."""
    r = rig("bench_plate")
    period = 1.01 * ident.linear_period(r, "z")
    assert main(["identify", BENCH, "--axis", "z", "--period", repr(period), "--amplitude", "0.2", "--json"]) == 0
    printed = json.loads(capsys.readouterr().out)
    result = measure(load_rig(BENCH), "z", period=period, amplitude=0.2)
    assert printed == json.loads(json.dumps(result.as_dict()))
    assert printed["timed_period"] == period and printed["amplitude"] == [0.2, 0.2]
    assert printed["period"] < period  # taken to zero amplitude: a torsion's period grows with the swing


def test_a_tare_moves_an_off_axis_object_by_the_parallel_axis_theorem(tmp_path):
    """bench_plate (4 kg, COM at the origin) with a 1 kg object whose own I_zz is 0.01 kg m^2 at
    (0.1, 0, 0.05) m: the assembly's I_zz about its COM (0.02, 0, 0.01) is 0.15 + 4 x 0.02^2 + 0.01 +
    1 x 0.08^2 = 0.1680 kg m^2. From the two predicted periods the object's own moment is 0.01 again
    (both inversions good to ~1e-12; the transfer is exact)."""
    assembly_izz = 0.15 + 4.0 * 0.02**2 + 0.01 + 1.0 * 0.08**2
    path = write_rig(tmp_path, f"[0.04, 0.13, {assembly_izz!r}]", mass="5.0", com="[0.02, 0.0, 0.01]")
    assembly, fixture = load_rig(path), rig("bench_plate")
    whole = measure(assembly, "z", period=ident.linear_period(assembly, "z"))
    alone = measure(fixture, "z", period=ident.linear_period(fixture, "z"))
    tared = subtract_tare(whole, alone)
    part = tared.object_part
    assert part.mass == pytest.approx(1.0, rel=1e-12)
    assert part.com == pytest.approx((0.1, 0.0, 0.05), abs=1e-12)
    assert part.inertia == pytest.approx(0.01, rel=1e-8)
    assert part.std == pytest.approx(math.hypot(whole.std, alone.std), rel=1e-12)
    assert tared.as_dict()["object"]["inertia"] == part.inertia and tared.as_dict()["tare"] == alone.as_dict()


def test_a_fixture_as_heavy_as_the_assembly_leaves_no_object():
    r = rig("bench_plate")
    result = measure(r, "z", period=ident.linear_period(r, "z"))
    with pytest.raises(Exception, match="body.mass.*no object is left"):
        subtract_tare(result, result)


def test_a_flag_of_many_records_is_said_once_naming_them_all():
    said = [("a.csv", "T0 is known to 2 % only"), ("b.csv", "a swing of 2 rad is more than pi/2"),
            ("b.csv", "T0 is known to 2 % only"), ("c.csv", "T0 is known to 2 % only"), ("c.csv", "T0 is known to 2 % only")]
    assert said_once(said) == ["a.csv, b.csv, c.csv: T0 is known to 2 % only",
                               "b.csv: a swing of 2 rad is more than pi/2"]


def test_an_unknown_moment_starts_at_the_mean_of_the_known_ones():
    """One rule for identify's nan moment and a tare's: inside the triangle inequality of a diagonal tensor."""
    assert start_moment(np.diag([0.1, 0.3, math.nan]), 2) == pytest.approx(0.2)
    assert start_moment(np.diag([math.nan, 0.3, math.nan]), 2) == pytest.approx(0.3)
    assert start_moment(np.diag([math.nan, math.nan, math.nan]), 2) is None


def test_the_tensor_check_finds_what_no_body_has():
    assert tensor_check(np.diag([1.0, 2.0, 3.0])).body
    assert not tensor_check(np.diag([1.0, 1.0, 3.0])).triangle
    assert not tensor_check(np.diag([-1.0, 2.0, 2.0])).positive_definite
