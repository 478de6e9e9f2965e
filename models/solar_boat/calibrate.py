"""Calibrate six dimensions of parts.toml so that the parts reproduce the thesis's Solar Boat.

Targets (thesis ch. 8.1, seed 000_452bb3442a9ae1d4.txt): principal moments I1 = 317.278 (yaw),
I2 = 317.154 (pitch), I3 = 83.143 kg m^2 (roll), the centre of mass 0.205 m below the solar deck,
principal axes along the boat's yaw, pitch and roll axes (body z, y, x), which the thesis takes for
granted, and the centre of mass under the middle of the deck, where the thesis's symmetric
suspensions (ch. 8.2) put it. Masses stay as budgeted in the file; each free dimension mainly sets
one target (deck width: sum(m y^2); wing depth: sum(m z^2); deck length: sum(m x^2); pilot height
and fore-aft position: the COM; rear wing position: the xz product of inertia).

Run ``python models/solar_boat/calibrate.py``. It prints the match of the file as it stands, then
solves from the file's values (scipy least_squares, bounded to plausible ranges), rounds to 1 mm,
and prints those values and their match. The values belong in parts.toml, never in this script.
"""

from __future__ import annotations

import copy
import tomllib
from pathlib import Path

import numpy as np
from scipy.optimize import least_squares

from bifilar.bodies.composite import MassProperties, mass_properties, parts_from_dict

PARTS = Path(__file__).with_name("parts.toml")

THESIS_MOMENTS = {"yaw": 317.278, "pitch": 317.154, "roll": 83.143}  # kg m^2, thesis ch. 8.1
THESIS_COM_BELOW_DECK = 0.205  # m
THESIS_PILOT_SHARE = 0.44
BODY_AXIS = {"roll": 0, "pitch": 1, "yaw": 2}  # body x forward, y port, z up

# label -> (entries it sets as (part name, key, vector index or None), plausible bounds in m)
FREE = {
    "deck width": ([("deck", "width", None)], (1.8, 3.2)),
    "deck length": ([("deck", "length", None)], (3.0, 5.9)),
    "wing depth z": ([("front_wing", "position", 2), ("rear_wing", "position", 2)], (-1.8, -0.9)),
    "pilot centre z": ([("pilot", "position", 2)], (-0.45, 0.1)),
    "pilot centre x": ([("pilot", "position", 0), ("cockpit", "position", 0)], (-1.0, 1.5)),
    "rear wing x": ([("rear_wing", "position", 0)], (-2.95, -1.5)),
}


def get(data: dict, entry) -> float:
    name, key, index = entry
    table = next(p for p in data["part"] if p["name"] == name)
    return table[key] if index is None else table[key][index]


def with_values(data: dict, values) -> dict:
    """A copy of the parsed file with the free dimensions set to ``values`` (order of FREE)."""
    out = copy.deepcopy(data)
    for (entries, _), value in zip(FREE.values(), values):
        for name, key, index in entries:
            table = next(p for p in out["part"] if p["name"] == name)
            if index is None:
                table[key] = float(value)
            else:
                table[key][index] = float(value)
    return out


def principal_by_body_axis(props: MassProperties) -> tuple[dict, float]:
    """Principal moments named by the body axis each principal axis lies nearest to, and the
    largest angle (rad) between a principal axis and its body axis."""
    moments, axes = props.principal()
    named, tilt = {}, 0.0
    for label, i in BODY_AXIS.items():
        j = int(np.argmax(np.abs(axes[i])))
        named[label] = moments[j]
        tilt = max(tilt, float(np.arccos(min(1.0, abs(axes[i, j])))))
    return named, tilt


def residuals(values, data: dict) -> np.ndarray:
    props = mass_properties(parts_from_dict(with_values(data, values)))
    scale = THESIS_MOMENTS["roll"]
    return np.array(
        [props.inertia[i, i] / THESIS_MOMENTS[label] - 1.0 for label, i in BODY_AXIS.items()]
        + [props.inertia[0, 2] / scale, props.com[0], props.com[2] + THESIS_COM_BELOW_DECK]
    )


def report(data: dict, title: str) -> None:
    parts = parts_from_dict(data)
    props = mass_properties(parts)
    named, tilt = principal_by_body_axis(props)
    pilot = next(p for p in parts if p.name == "pilot").mass / props.mass
    print(f"\n{title}: mass {props.mass:.2f} kg, COM {np.array2string(props.com, precision=4)} m")
    print(f"  {'quantity':<24}{'thesis':>10}{'model':>10}{'error':>10}")
    for label in ("yaw", "pitch", "roll"):
        thesis, model = THESIS_MOMENTS[label], named[label]
        print(f"  {'I ' + label + ' (kg m^2)':<24}{thesis:>10.3f}{model:>10.3f}{model / thesis - 1:>+10.3%}")
    depth = -props.com[2]
    print(f"  {'COM below deck (m)':<24}{THESIS_COM_BELOW_DECK:>10.3f}{depth:>10.4f}"
          f"{depth - THESIS_COM_BELOW_DECK:>+10.4f}")
    share = THESIS_PILOT_SHARE
    print(f"  {'pilot share':<24}{share:>10.3f}{pilot:>10.4f}{pilot - share:>+10.4f}")
    print(f"  principal axes within {np.degrees(tilt):.3f} deg of the body axes")


def main() -> None:
    data = tomllib.loads(PARTS.read_text())
    report(data, f"{PARTS.name} as it stands")
    start = [get(data, entries[0]) for entries, _ in FREE.values()]
    lower, upper = zip(*(bounds for _, bounds in FREE.values()))
    start = np.clip(start, lower, upper)
    fit = least_squares(residuals, start, bounds=(lower, upper), args=(data,), xtol=1e-12, ftol=1e-12)
    rounded = np.round(fit.x, 3)
    held = np.array_equal(rounded, np.round(start, 3))
    print("\ncalibrated values, rounded to 1 mm"
          + (" (parts.toml holds them):" if held else " (write these into parts.toml):"))
    for label, value in zip(FREE, rounded):
        print(f"  {label:<16}{value:>8.3f} m")
    report(with_values(data, rounded), "with these values")


if __name__ == "__main__":
    main()
