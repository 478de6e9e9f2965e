"""Reading measured records: sniffed delimiters and headers, time as frames or ms, units, windows,
lost frames, folded angles, and one-line errors naming file, column and problem."""

import math

import numpy as np
import pytest

from bifilar.identification.records import read as R
from bifilar.rig import RigError

T = np.arange(40) / 60.0
ANGLE = 0.3 * np.cos(2.0 * math.pi * T / 0.5)


def write(tmp_path, text, name="rec.csv"):
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


@pytest.mark.parametrize("sep", [",", "\t", ";", " ", "   "])
def test_delimiters_are_sniffed(tmp_path, sep):
    text = f"t{sep}angle\n" + "".join(f"{a:.9f}{sep}{b:.9f}\n" for a, b in zip(T, ANGLE))
    rec = R.read_record(write(tmp_path, text))
    np.testing.assert_allclose(rec.t, T, atol=1e-9)
    np.testing.assert_allclose(rec.y, ANGLE, atol=1e-9)


def test_byte_order_mark_and_comments(tmp_path):
    text = "\ufeff# tracker v2\nt,angle\n" + "".join(f"{a},{b}\n" for a, b in zip(T, ANGLE))
    rec = R.read_record(write(tmp_path, text))
    assert rec.column == "angle" and len(rec.t) == 40


def test_video_frames_with_gaps_fps_and_degrees(tmp_path):
    frames = np.delete(np.arange(40), [5, 17, 18])
    text = "frame,angle\n" + "".join(f"{f},{math.degrees(ANGLE[f])}\n" for f in frames)
    rec = R.read_record(write(tmp_path, text), fps=60.0, angle_unit="deg")
    np.testing.assert_allclose(rec.t, frames / 60.0, rtol=1e-15)
    np.testing.assert_allclose(rec.y, ANGLE[frames], rtol=1e-12)


def test_gyro_ms_timestamp_and_rate(tmp_path):
    text = "timestamp;gyro_z\n" + "".join(f"{1000 * a:.6f};{math.degrees(b)}\n" for a, b in zip(T, ANGLE))
    rec = R.read_record(write(tmp_path, text), "gyro_z", "rate", time_unit="ms", angle_unit="deg")
    np.testing.assert_allclose(rec.t, T, atol=1e-9)
    np.testing.assert_allclose(rec.y, ANGLE, rtol=1e-12)


def test_headerless_pixels_are_named_by_position(tmp_path):
    text = "".join(f"{320 + 100 * b}\t{240.5}\n" for b in ANGLE)
    rec = R.read_record(write(tmp_path, text), "1", "proportional", fps=240.0)
    np.testing.assert_allclose(rec.t, np.arange(40) / 240.0)
    np.testing.assert_allclose(rec.y, 320 + 100 * ANGLE)


def test_window_and_lost_frames(tmp_path):
    rows = [f"{a},{b}" if k not in (3, 30) else f"{a},nan" if k == 3 else f"{a}," for k, (a, b) in enumerate(zip(T, ANGLE))]
    text = "t,angle\n" + "\n".join(rows) + "\n"
    rec = R.read_record(write(tmp_path, text), start=0.02, end=0.6)
    assert rec.dropped == 2
    assert rec.t[0] >= 0.02 and rec.t[-1] <= 0.6 and len(rec.t) == np.sum((T >= 0.02) & (T <= 0.6)) - 2


def test_folded_angles_are_unfolded():
    # a line near the image vertical at rest: its angle crosses pi/2 twice in every cycle
    theta = 1.45 + 0.6 * np.cos(np.linspace(0.0, 12.0, 600))
    glitched = theta.copy()
    glitched[100] += 0.9  # a single-frame glitch stays a single-frame glitch
    for truth, n_glitch in ((theta, 0), (glitched, 1)):
        folded = truth - math.pi * np.round(truth / math.pi)
        out, jumps = R.unfold(folded)
        assert jumps > 0
        shift = math.pi * np.round((out[0] - theta[0]) / math.pi)  # unfolded up to a whole turn of the line
        assert np.count_nonzero(np.abs(out - shift - theta) > 1e-9) == n_glitch
    same, jumps = R.unfold(theta)  # not folded: untouched
    assert jumps == 0 and same is theta


def test_a_record_never_folded_is_left_as_it_is_whatever_its_big_steps():
    # Issue 37 item 3: a 1.2 rad swing with a sway at twice its frequency, 60 fps, a run of 16 lost frames
    # at full speed (a 2.6 rad step over the gap) and a tracker locking on (a jump of 2 rad): steps over
    # pi/2, but no fold. Reducing them modulo pi put the pieces between them pi apart (refused records).
    t = np.arange(1200) / 60.0
    theta = 1.2 * np.cos(6.0 * t) + 0.25 * np.sin(12.0 * t)
    keep = np.ones(len(t), dtype=bool)
    keep[300:316] = False
    t, theta = t[keep], theta[keep].copy()
    theta[:5] = -0.25 * math.pi
    assert np.abs(np.diff(theta)).max() > 0.5 * math.pi
    same, jumps = R.unfold(theta, t)
    assert jumps == 0 and same is theta


def test_a_folded_record_is_unfolded_across_lost_frames():
    # the folded line of test_folded_angles_are_unfolded swinging 1.2 rad, with runs of lost frames over
    # which it turns by more than pi/2: each piece comes back by the multiple of pi that puts it on the swing
    t = np.arange(1500) / 60.0
    theta = 0.5 * math.pi + 1.2 * np.cos(6.0 * t) + 0.2 * np.sin(12.0 * t)
    keep = np.ones(len(t), dtype=bool)
    for start in (200, 455, 830, 1111):
        keep[start:start + 20] = False
    t, theta = t[keep], theta[keep]
    folded = theta - math.pi * np.round(theta / math.pi)
    out, jumps = R.unfold(folded, t)
    assert jumps > 20
    shift = math.pi * np.round((out[0] - theta[0]) / math.pi)
    assert np.abs(out - shift - theta).max() < 1e-12


GOOD = "".join(f"{0.05 * k},{math.cos(k / 3):.6f}\n" for k in range(30))


@pytest.mark.parametrize("text, kwargs, field, problem", [
    ("", {}, "file", "empty: expected rows of numbers, optionally under a header row"),
    ("t,roll,pitch\n" + GOOD.replace("\n", ",1\n"), {}, "angle", "missing column (columns: t, roll, pitch): choose one with --column"),
    ("t,angle\n" + GOOD + "1.6,abc\n", {}, "angle", "line 32: not a number: 'abc'"),
    ("t,angle\n" + GOOD + "1.6,inf\n", {}, "angle", "line 32: not finite: 'inf'"),
    ("t,angle\n" + GOOD + "1.4,0.1\n", {}, "t", "line 32: time 1.4 does not increase (previous 1.45)"),
    ("t,angle\n" + GOOD + "1.6\n", {}, "line 32", "has 1 fields, the header has 2"),
    ("t,angle\n0,1\n0.1,0.5\n0.2,0\n", {}, "angle", "3 samples; at least 20 are needed"),
    ("x,angle\n" + GOOD, {}, "t", "no time column (looked for t, time, timestamp; columns: x, angle): name it with "
                                  "--time-column, or give --fps for frame numbers"),
    ("t,angle\n" + GOOD, {"time_column": "clock"}, "clock", "missing time column (columns: t, angle)"),
    ("t,angle\n" + GOOD, {"start": 5.0}, "angle", "0 samples between --from and --to (the record spans 0 .. 1.45 s); "
                                                  "at least 20 are needed"),
    ("t,angle,angle\n" + GOOD.replace("\n", ",1\n"), {}, "header", "column 'angle' appears more than once"),
    ("t,angle\n" + "".join(f"{k},0.5\n" for k in range(30)), {}, "angle", "constant (0.5) over the whole record: nothing oscillates"),
])
def test_errors_name_file_column_and_problem(tmp_path, text, kwargs, field, problem):
    path = write(tmp_path, text)
    with pytest.raises(RigError) as err:
        R.read_record(path, **kwargs)
    assert (err.value.source, err.value.field, err.value.problem) == (str(path), field, problem)
    assert "\n" not in str(err.value)


def test_unreadable_files(tmp_path):
    for path, problem in ((tmp_path / "absent.csv", "cannot read"), (tmp_path, "is a directory")):
        with pytest.raises(RigError, match=problem):
            R.read_record(path)
    binary = tmp_path / "b.csv"
    binary.write_bytes(b"t,angle\n\xff\xfe\n")
    with pytest.raises(RigError, match="not UTF-8"):
        R.read_record(binary)
