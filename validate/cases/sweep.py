"""Sweeps (issue 10) against independent physics: the closed-form propagation of (5.2.18) for
parallel wires, and the recommendation of a plate sweep rerun in MuJoCo."""

from __future__ import annotations

import math

from bifilar.sweep.choose import best
from bifilar.sweep.run import run_chunk
from bifilar.sweep.space import load_space

from ..assets import MODELS
from ..registry import CaseContext, case, check
from ..studies.sweep_check import TOLERANCE
from ..studies.sweep_check import check as mujoco_check


@case("sweep-parallel-5.2.18", source="000 ch. 5.2 (5.2.18); issue 10", engines=("sweep", "analytic"))
def parallel_closed_form(ctx: CaseContext):
    """For vertical parallel wires the sweep's yaw sigma is the closed-form propagation through (5.2.18),
    I = m g D^2 T^2 / (16 pi^2 h): (s_I/I)^2 = (s_m/m)^2 + (2 s_T/T)^2 + (s_L/(sqrt 2 h))^2 (h the mean
    of the two lengths). The rows whose anchors are as far apart as the attachments are the vertical ones."""
    path = MODELS / "sweeps" / "parallel.toml"
    space = load_space(path)
    rows = run_chunk(str(path), 0, space.size)
    unc, m = space.rig.uncertainty, space.rig.mass
    worst, n = 0.0, 0
    for r in rows:
        v = r["values"]
        if abs(v["anchor_span"] - v["attach_span"]) > 1e-12:
            continue
        h, D, I = v["wire_length"], v["attach_span"], space.rig.inertia[2, 2]
        T = 2.0 * math.pi * math.sqrt(4.0 * h * I / (m * space.rig.gravity * D**2))
        closed = math.sqrt((unc.mass / m) ** 2 + (2.0 * unc.period / T) ** 2 + (unc.length / (math.sqrt(2.0) * h)) ** 2)
        worst = max(worst, abs(r["sigma"]["z"] / closed - 1.0))
        n += 1
    return [check(f"yaw sigma vs closed form, {n} vertical-wire rows", worst, 1e-5,
                  "forward differences of 1e-3 sigma: ~1e-6 relative")]


@case("sweep-mujoco-check", source="issue 10 (cross-validation of the recommendation)", engines=("sweep", "mujoco"))
def mujoco_recommendation(ctx: CaseContext):
    """The best configuration of a small bench-plate sweep, every measured mode rerun in MuJoCo at
    1e-3 rad: periods and mean tensions agree with the sweep's prediction to 1e-6."""
    path = MODELS / "sweeps" / "bench_plate_small.toml"
    space = load_space(path)
    rows = run_chunk(str(path), 0, space.size)
    top = best(rows, space.measure, space.objective)
    result = mujoco_check(space, [top["values"]])[0].entry
    out = []
    for m in result["modes"]:
        out.append(check(f"{m['axis']} ({m['motion']}, {m['predicted']:.6f} s): MuJoCo period vs sweep",
                         abs(m["period_rel_error"]), TOLERANCE,
                         "MuJoCo ~3e-10 at the chosen step; amplitude shift ~6e-8 at 1e-3 rad"))
        out.append(check(f"{m['axis']}: MuJoCo mean tension vs static", m["tension_rel_error"], TOLERANCE,
                         "soft cables 1e-7; the motion adds ~A^2"))
    return out
