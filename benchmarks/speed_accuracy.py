"""Speed against accuracy of the cross-validation's engines, side by side in one run.

For the thesis plate (models/rigs/plate.toml, 10 deg of torsion) and the trifilar platform
(models/rigs/trifilar.toml, 0.1 rad of torsion), from each rig's [initial] state:

* MuJoCo at several time steps h, with the Euler, implicitfast and RK4 integrators and both cable
  models (tendon limits, equality rows), every other setting as chosen in models/README.md (cable
  solref (2h, 0.5), impedance 0.99);
* the hand-derived model (Kane-Tseng for the plate, the N-wire model for the trifilar) at several
  integrator tolerances rtol.

Each run reports its torsion period's relative error against the exact large-amplitude period by
quadrature that the cases use (the 1-DOF torsion model of bifilar.motion.lagrange for the plate;
validate.cases.trifilar.torsion_period, docs/nwire-model.md section 6, for the trifilar), the
constraint drift (largest |wire length error|, m) and its cost (wall and CPU seconds per simulated
second). Every engine runs once on a short span first, so that compilation is not timed; then every
setting runs once, one after the other in this process, so the timings are side by side on one
machine in one run. On a shared machine wall times move with its load: the CPU times are steadier.

    python benchmarks/speed_accuracy.py [--duration 8] [--json docs/speed_accuracy.json] [--png docs/speed_accuracy.png]

The JSON is the stored result that ``validate all --slow --html`` shows (validate/report/speed_accuracy.py
draws the figure from it, here and there).
"""

from __future__ import annotations

import argparse
import datetime
import json
import time
from pathlib import Path

import mujoco
import numpy as np

from bifilar.motion import lagrange
from bifilar.rig import load_rig
from validate.cases.trifilar import torsion_period
from validate.engines import kane, mujoco_rig
from validate.engines.mjcf import CHOSEN
from validate.metrics import max_abs, period, yaw
from validate.report.environment import machine, versions
from validate.report.speed_accuracy import figure_png
from validate.trajectory import atomic_write_bytes, atomic_write_text

ROOT = Path(__file__).resolve().parent.parent
TIMESTEPS = (1e-3, 2e-4, 4e-5, 1e-5)  # s; 4e-5 is the chosen one; each divides the 0.01 s sampling
INTEGRATORS = ("Euler", "implicitfast", "RK4")
CABLES = ("tendon", "equality")
RTOLS = (1e-6, 1e-8, 1e-10, 1e-12)
DT_OUT = 0.01  # s: ~200 samples per period, crossing times refined to ~1e-10 of a period


def exact_period(rig) -> float:
    """The exact period (s) of the rig's [initial] torsion, by quadrature (see the module docstring)."""
    amplitude = float(rig.initial_rotation[2])
    if len(rig.wires) == 2:
        return lagrange.period(lagrange.from_rig(rig), amplitude)
    radius = float(np.hypot(*rig.wires[0].attach[:2]))
    return torsion_period(rig.mass, float(rig.inertia[2, 2]), radius, rig.wires[0].length, rig.gravity, amplitude)


def measure(run, rig, duration: float, reference: float) -> dict:
    wall, cpu = time.perf_counter(), time.process_time()
    try:
        traj = run(rig, duration)
        wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
        measured = period(traj.t, yaw(traj)).value
    except Exception as exc:  # an unstable setting (or a motion with no period): reported, not plotted
        return {"failed": f"{type(exc).__name__}: {str(exc).splitlines()[0] if str(exc) else ''}"}
    return {"period_error": abs(measured / reference - 1.0), "length_error": max_abs(traj["length_error"]),
            "wall_per_second": wall / duration, "cpu_per_second": cpu / duration}


def settings():
    """(engine, label, setting, run(rig, duration)) for every point of the figure."""
    for rtol in RTOLS:
        yield "kane", f"rtol {rtol:g}", {"rtol": rtol}, lambda rig, d, rtol=rtol: kane.run(rig, d, DT_OUT, rtol)
    for cables in CABLES:
        for integrator in INTEGRATORS:
            for h in TIMESTEPS:
                numerics = CHOSEN.with_(timestep=h, integrator=integrator)
                yield (f"mujoco {cables}", f"{integrator} h {h:g}", {"cables": cables, "integrator": integrator,
                                                                      "timestep": h},
                       lambda rig, d, c=cables, n=numerics: mujoco_rig.run(rig, d, DT_OUT, cables=c, numerics=n))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--duration", type=float, default=8.0, help="simulated seconds per run (default 8: 4 periods)")
    parser.add_argument("--json", default=str(ROOT / "docs" / "speed_accuracy.json"), help="the result (JSON)")
    parser.add_argument("--png", default=str(ROOT / "docs" / "speed_accuracy.png"), help="the figure (PNG)")
    args = parser.parse_args()
    mujoco.set_mju_user_warning(lambda message: None)  # an unstable setting is reported, not printed
    rigs = {name: load_rig(ROOT / "models" / "rigs" / f"{name}.toml") for name in ("plate", "trifilar")}
    for rig in rigs.values():  # compile and warm up every engine
        kane.run(rig, 0.05, DT_OUT, 1e-10)
        mujoco_rig.run(rig, 0.05, DT_OUT)
    points = []
    print(f"{args.duration:g} s of torsion per run; period error against the exact period by quadrature")
    print("| rig | engine | setting | period rel. err | max length error (m) | wall s / sim s | CPU s / sim s |")
    print("|---|---|---|---|---|---|---|")
    for name, rig in rigs.items():
        reference = exact_period(rig)
        for engine, label, setting, run in settings():
            result = measure(run, rig, args.duration, reference)
            points.append({"rig": name, "engine": engine, "label": label, **setting, **result})
            if "failed" in result:
                print(f"| {name} | {engine} | {label} | failed: {result['failed']} ||||")
            else:
                print(f"| {name} | {engine} | {label} | {result['period_error']:.1e} | {result['length_error']:.1e} "
                      f"| {result['wall_per_second']:.3g} | {result['cpu_per_second']:.3g} |")
    options = f" --duration {args.duration:g}" if args.duration != 8.0 else ""
    data = {"command": "python benchmarks/speed_accuracy.py" + options,
            "date": datetime.date.today().isoformat(), "duration": args.duration, "dt_out": DT_OUT,
            "machine": machine(), "versions": versions(),
            "note": "one run of each setting, side by side in one process on a machine shared with other jobs: "
                    "wall times move with its load (CPU times are steadier)",
            "points": points}
    atomic_write_text(args.json, json.dumps(data, indent=1) + "\n")
    atomic_write_bytes(args.png, figure_png(data))
    print(f"wrote {args.json}, {args.png}")


if __name__ == "__main__":
    main()
