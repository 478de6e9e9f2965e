"""The speed-accuracy figure of ``benchmarks/speed_accuracy.py`` and its section in the suite's page.

The benchmark stores its result (``docs/speed_accuracy.json``): per rig and setting, the torsion
period's relative error against the exact period by quadrature, the largest wire length error (m)
and the wall and CPU seconds per simulated second. ``validate all --slow --html`` shows that stored
result (timing is never done in a test or a case: the machine is shared), with the date, machine and
versions it was measured on. The figure: for each rig, the period error and the length error against
the wall time per simulated second, log-log; MuJoCo as one line per integrator and cable model through
its time steps, the hand-derived model as points at its tolerances.
"""

from __future__ import annotations

import json
from pathlib import Path

from .figures import png_bytes, pyplot
from .html import join, number, table, tag
from .page import Section
from .sections import figure

STORED = Path(__file__).resolve().parents[2] / "docs" / "speed_accuracy.json"
FLOOR = 1e-16  # errors below (a constraint exact by construction) are drawn at this floor
COLOURS = {"Euler": "tab:red", "implicitfast": "tab:blue", "RK4": "tab:green"}
STYLES = {"mujoco tendon": ("o", "-"), "mujoco equality": ("s", "--")}
QUANTITIES = (("period_error", "period rel. error vs exact quadrature"), ("length_error", "max |wire length error| (m)"))


def load(path: str | Path = STORED) -> dict | None:
    """The stored result, or None when there is none (e.g. an installed wheel has no docs/)."""
    try:
        return json.loads(Path(path).read_text())
    except FileNotFoundError:
        return None


def figure_png(data: dict) -> bytes:
    """The figure (see the module docstring) as PNG bytes."""
    plt = pyplot()

    rigs = list(dict.fromkeys(p["rig"] for p in data["points"]))
    fig, axes = plt.subplots(len(rigs), 2, figsize=(12, 4.6 * len(rigs)), squeeze=False)
    for row, rig in zip(axes, rigs):
        points = [p for p in data["points"] if p["rig"] == rig and "failed" not in p]
        for ax, (key, label) in zip(row, QUANTITIES):
            for engine, (marker, line) in STYLES.items():
                for integrator, colour in COLOURS.items():
                    series = sorted((p for p in points if p["engine"] == engine and p["integrator"] == integrator),
                                    key=lambda p: -p["timestep"])
                    if series:
                        ax.plot([p["wall_per_second"] for p in series], [max(p[key], FLOOR) for p in series],
                                marker=marker, linestyle=line, color=colour, mfc="none" if line == "--" else colour,
                                label=f"{engine.split()[1]} {integrator}")
            chosen = [p for p in points if p["engine"] == "mujoco tendon" and p["integrator"] == "implicitfast"]
            for p in chosen:
                ax.annotate(f"h {p['timestep']:g}", (p["wall_per_second"], max(p[key], FLOOR)), fontsize=7,
                            xytext=(4, 4), textcoords="offset points")
            kane = [p for p in points if p["engine"] == "kane"]
            ax.plot([p["wall_per_second"] for p in kane], [max(p[key], FLOOR) for p in kane], "*", ms=11,
                    color="black", label="Kane / N-wire model")
            for p in kane:
                ax.annotate(f"rtol {p['rtol']:g}", (p["wall_per_second"], max(p[key], FLOOR)), fontsize=7,
                            xytext=(4, -10), textcoords="offset points")
            ax.set(xscale="log", yscale="log", xlabel="wall seconds per simulated second", ylabel=label,
                   title=f"{rig}: {label.split(' (')[0]}")
            ax.grid(True, which="major", alpha=0.3)
        row[0].legend(fontsize=7, ncol=2, loc="best")
    fig.suptitle(f"speed against accuracy, {data['duration']:g} s of torsion per run ({data['date']}; one run each, "
                 "side by side, on a shared machine)", fontsize=10)
    return png_bytes(fig)


class SpeedAccuracySection(Section):
    """The stored result: its figure, where and when it was measured, and every point as a table."""

    title = "Speed and accuracy"
    open = True

    def __init__(self, data: dict | None, source: str | Path = STORED):
        self.data, self.source = data, source

    def body(self) -> str:
        if self.data is None:
            return tag("p", f"No stored result at {self.source}: python benchmarks/speed_accuracy.py measures it.")
        d = self.data
        lead = tag("p", f"The stored result of {d['command']} (measured {d['date']} on {d['machine']['processor']}, "
                        f"{d['machine']['cores']} cores; {', '.join(f'{k} {v}' for k, v in d['versions'].items())}); "
                        f"{d['note']}. Not measured in this run: timing has no place in a test.")
        rows = []
        for p in d["points"]:
            if "failed" in p:
                rows.append((p["rig"], p["engine"], p["label"], "failed: " + p["failed"], "", "", ""))
                continue
            rows.append((p["rig"], p["engine"], p["label"], number(p["period_error"], 2), number(p["length_error"], 2),
                         number(p["wall_per_second"], 3), number(p["cpu_per_second"], 3)))
        return join([lead, figure(figure_png(d), "period error and wire length error against wall time per "
                                               "simulated second"),
                     table(("rig", "engine", "setting", "period rel. error", "max length error (m)", "wall s / sim s",
                            "CPU s / sim s"), rows)])
