"""The Solar Boat study (seed 000, ch. 8.2-8.4) as a validation case: the study's numbers are checked
where something independent fixes them, and the shipped MuJoCo boat is checked against the Kane model
on the thesis's torsion of Fig. 8.4.1.

Tolerances:

* Identified moments: the period is simulated at the thesis's pi/80 and the amplitude correction
  re-simulates that same release at the identified moment, so at its fixed point the moment is the
  truth; the fixed point stops when a pass moves J by < 1e-9 and contracts by
  (d ln ratio / d ln J) / (d ln T / d ln J) <= 0.15 per pass (pitch in configuration 1: ratio - 1 =
  9e-5 against a sensitivity of 6e-4), leaving < 2e-10. Allowed 1e-8.
* Rest tensions against the symmetric closed form m g / (2 cos alpha), sin alpha = (hook - attachment
  offset) / L: the parts' COM is 3.6e-5 m aft of the deck's middle, which moves each tension by
  2.6e-5 of itself in opposite directions and their mean by the square of that; allowed 1e-8.
* MuJoCo against Kane: the chosen numerics of models/README.md (tension within 1e-6 of the static
  tension, measured 3.1e-7 on the plate's 10 degree torsion). The boat's pi/12 torsion moves its
  attachments at up to 2.4 m/s, so the curvature of the wire's path, c = v^2 / L plus the
  centripetal acceleration along the wire, reaches 1.5 m/s^2 (the plate's: 0.4), and the stretch
  estimate of models/README.md, the static 1.6e-10 m plus h^2 c / 2 = 1.2e-9 m, is 1.4e-9 m. On the
  plate the same estimate fell short of the measurement by a factor 2 (the row's transients): 3e-9 m
  is allowed, so the boat exceeds the 1e-9 m target the numerics were chosen for on the plate.
  The period: the leapfrog's -(omega h)^2 / 24 = -7.5e-10 with the stretch's like-sized lengthening;
  3 (omega h)^2 / 24 is allowed, as for the plate.
* The sweep of models/solar_boat/configurations.toml (issue 10, item 7), run as ``python -m validate
  sweep`` runs it, against the study. Its rigs are suspension.toml's: the attachments moved in by
  ``attach_inset`` from the deck's ends against boat.py's formula, rounding of 3 m coordinates, 1e-12 m
  allowed. Its rows are the study's, the same evaluation reached from the file instead of from the
  suspension, but the sweep continues each rest pose from the previous point's (Newton) where the study
  starts each afresh: the poses agree to the solvers' ~1e-11, which the propagation's forward
  differences (steps of 1e-3 sigma) amplify in the sigmas to ~1e-9 (measured 8e-10); 1e-8 allowed. Its linear period of each measured mode against the study's Kane-timed period at
  pi/80 inverted with the amplitude correction (the linear period at the identified moment): they
  differ by d ln T / d ln I (<= 1/2) times the identified moment's 2e-10 (above), 1e-8 allowed. Its
  sigma against the propagation at the identified moment and its period, the study's earlier path
  (bifilar.identification.propagation.linear, fresh rest pose): forward differences of 1e-3 sigma of
  every input, ~1e-6 relative (as in sweep-parallel-5.2.18), 1e-5 allowed.
* The hall sweep (slow): the best configuration is re-hung in the study and its motions simulated
  (Kane): the torsion at pi/12 and the pitch and roll at pi/80 about their axes, as the sweep times
  them; its wires stay under the hall's tension limit and its parts above the floor.
"""

from __future__ import annotations

import numpy as np

import os
import tempfile
from dataclasses import replace
from pathlib import Path

from bifilar.bodies.boat import Configuration, load_suspension
from bifilar.identification.propagation import linear
from bifilar.rig.statics import State
from bifilar.sweep.axes import configure
from bifilar.sweep.choose import best, objective
from bifilar.sweep.evaluate import evaluate
from bifilar.sweep.run import run as run_sweep
from bifilar.sweep.run import run_chunk
from bifilar.sweep.space import load_space

from ..assets import MODELS
from ..studies.boat_model import build_spec
from ..studies.boat_study import (DT_OUT, PERIODS, SUSPENSION, Motion, load_run, run_study, study_configuration,
                                  sweep_space)
from ..engines import mujoco_rig
from ..engines.kane import to_trajectory
from ..metrics import max_abs, period
from ..registry import CaseContext, case, check

IDENTIFY_RTOL = 1e-8
REST_RTOL = 1e-8
MUJOCO_SECONDS = 6.0  # 3.2 torsion periods of configuration 1: three rising crossings
TENSION_RTOL = 1e-6  # of the static tension (module docstring)
STRETCH = 3e-9  # m (module docstring: 1.4e-9 m estimated)
CONFIGURATIONS = MODELS / "solar_boat" / "configurations.toml"
HALL = MODELS / "solar_boat" / "hall.toml"
ATTACH_ABS = 1e-12  # m, rigs of the sweep file vs the suspension file (module docstring)
ROWS_RTOL = 1e-8  # the same evaluation reached from two files (module docstring)
PERIOD_RTOL = 1e-8  # the sweep's linear period vs the Kane-timed, amplitude-corrected one
SIGMA_RTOL = 1e-5  # forward differences of the propagation


@case("boat-study", source="000 ch. 8.2-8.4", engines=("kane", "mujoco"))
def boat_study(ctx: CaseContext):
    """Solar Boat, configurations 1-3 of models/solar_boat/suspension.toml: every moment identified
    from its timed motion recovers the truth, the rest tensions match the closed form, the boat clears
    the hall's floor, and the shipped MuJoCo boat repeats the Kane torsion of Fig. 8.4.1."""
    s = load_suspension(SUSPENSION)
    study = run_study(s)
    out = []
    for c in study.configurations:
        for m in c.moments:
            quoted = "" if m.thesis is None else f" (thesis {100 * (m.thesis / m.truth - 1):+.2f} %)"
            out.append(check(f"configuration {c.config.name}, {m.name}: identified vs true{quoted}",
                             abs(m.found.moment / m.truth - 1.0), IDENTIFY_RTOL,
                             "a round trip: Kane's nonlinear period at pi/80, inverted through the linearisation and "
                             "the amplitude correction; checks the method, not the thesis (module docstring)"))
        offset = abs(s.hooks[0, 0] - c.rig.wires[0].attach[0])
        closed = c.rig.mass * c.rig.gravity / (2.0 * np.sqrt(1.0 - (offset / s.wire_length) ** 2))
        out.append(check(f"configuration {c.config.name}: mean rest tension vs m g / (2 cos alpha) = {closed:.2f} N",
                         abs(c.rest.tensions.mean() / closed - 1.0), REST_RTOL,
                         "symmetric but for the COM's 3.6e-5 m, a second-order change (module docstring)"))
        out.append(check(f"configuration {c.config.name}: floor margin under the lowest part in motion",
                         s.hook_height - c.depth, 0.0, "the hall's floor is hook_height under the hooks",
                         unit="m", at_least=True))
    out += _mujoco_torsion(ctx, s, study.configurations[0])
    out += _sweep_configurations(s, study)
    return out


def _sweep_configurations(s, study) -> list:
    """The sweep of configurations.toml reproduces the study (module docstring)."""
    space = load_space(CONFIGURATIONS)
    rows = run_chunk(str(CONFIGURATIONS), 0, space.size)
    out = [check("configurations.toml: its points are suspension.toml's configurations, by name",
                 float(space.names != tuple(c.config.name for c in study.configurations)), 0.0,
                 "the same three configurations (thesis Table 8.2.1) in both files")]
    for c, values, row in zip(study.configurations, space.points(), rows):
        rig = configure(space.rig, values)
        out.append(check(f"configuration {c.config.name}: sweep's attachments vs suspension.toml's",
                         max(float(abs(a.attach - b.attach).max()) for a, b in zip(rig.wires, s.rig(c.config).wires)),
                         ATTACH_ABS, "attach_inset from the deck's ends vs boat.py's formula; rounding", unit="m"))
        mine = list(c.row.periods) + list(c.row.tensions) + [c.row.sigma[a] for a in ("z", "y", "x")]
        theirs = list(row["periods"]) + list(row["tensions"]) + [row["sigma"][a] for a in ("z", "y", "x")]
        out.append(check(f"configuration {c.config.name}: sweep file's periods, tensions, sigmas vs the study's",
                         max(abs(x / y - 1.0) for x, y in zip(theirs, mine)), ROWS_RTOL,
                         "one evaluation from two files; rest poses continued or afresh (module docstring)"))
        for m in c.moments:
            # The sweep's period of the mode that measures the axis: of its four, the one nearest (the
            # others are >= 4 % away).
            near = min((p for p in row["periods"] if p is not None), key=lambda p: abs(p / m.found.period - 1.0))
            out.append(check(f"configuration {c.config.name}, {m.name}: sweep's linear period {near:.6f} s vs "
                             f"Kane's at pi/80 ({m.period:.6f} s) without its amplitude shift",
                             abs(near / m.found.period - 1.0), PERIOD_RTOL,
                             "d ln T / d ln I times the identified moment's error (module docstring)"))
            old = linear(m.found.rig, m.axis, m.found.period, rig.uncertainty.period)
            out.append(check(f"configuration {c.config.name}, {m.name}: sweep's sigma {100 * row['sigma'][m.axis]:.3g} % "
                             "vs the propagation at the identified moment",
                             abs(row["sigma"][m.axis] / (old.std / old.moment) - 1.0), SIGMA_RTOL,
                             "forward differences of 1e-3 sigma (module docstring)"))
    return out


@case("boat-hall-sweep", source="000 ch. 8; issue 10 item 6", engines=("sweep", "kane"))
def boat_hall_sweep(ctx: CaseContext):
    """The dense sweep of models/solar_boat/hall.toml (2332 configurations, a few seconds on 2 cores): its best
    configuration is feasible, no worse in the objective than the thesis's configuration 3 hung in the
    same hall, and holds in the study's Kane motions: tensions under the hall's limit, the parts above
    the floor, the motions' extra depth within the clearance margin the sweep keeps at rest."""
    space = load_space(HALL)
    with tempfile.TemporaryDirectory() as tmp:
        chunks = run_sweep(str(HALL), space, Path(tmp), jobs=os.cpu_count() or 1)
        top = best(chunks.rows(), space.measure, space.objective)
    if top is None:
        return [check("hall sweep: a feasible configuration exists", 0.0, 1.0, "the hall holds the thesis's own", at_least=True)]
    s = load_suspension(SUSPENSION)
    third = evaluate(space, {"attach_inset": s.configuration("3").inset, "wire_length": s.wire_length})
    worst3 = objective({"feasible": third.feasible, "sigma": third.sigma}, space.measure, space.objective)
    mine = objective(top, space.measure, space.objective)
    inset, length = top["values"]["attach_inset"], top["values"]["wire_length"]
    hung = replace(s, wire_length=length, configurations=(Configuration("best", inset),))
    kane = study_configuration(hung, hung.configurations[0], sweep_space(hung))
    # The motions as the sweep times them: pi/80 about each axis (the study's swing turns the wire by
    # pi/80 instead, which here pitches the boat by more), besides the study's pi/12 torsion.
    slowest = max(p for p in kane.row.periods if p is not None)
    timed = [load_run(hung, kane.rig, Motion(name, axis, space.amplitude), kane.rest, PERIODS * slowest)
             for name, axis in (("pitch", "y"), ("roll", "x"))]
    depth = max([kane.loads[0].depth.max()] + [run.depth.max() for run in timed])
    tension = max([kane.loads[0].run.tension.max()] + [run.run.tension.max() for run in timed])
    where = f"best (inset {inset:.3g} m, wires {length:.3g} m)"
    limits = space.limits
    return [
        check(f"{where}: worst sigma {100 * mine:.3g} % over configuration 3's {100 * worst3:.3g} %",
              mine / worst3, 1.0, "the sweep's hall contains configuration 3's neighbours: no worse"),
        check(f"{where}: sweep's peak tension in the timed motions", top["tension_peak"], limits.tension,
              "the hall's limit (hall.toml)", unit="N"),
        check(f"{where}: Kane's peak tension over the torsion at pi/12, pitch and roll at pi/80",
              float(tension), limits.tension, "the same limit on the thesis's torsion too", unit="N"),
        check(f"{where}: floor margin under the lowest part in those Kane motions", s.hook_height - depth, 0.0,
              "the hall's floor", unit="m", at_least=True),
        check(f"{where}: the motions' extra depth over rest", depth - kane.rest_depth, limits.clearance,
              "the clearance the sweep keeps at rest must cover the motions (hall.toml)", unit="m"),
        check(f"{where}: sweep's clearance at rest vs the study's", abs(top["clearance"] - (s.hook_height - kane.rest_depth)),
              1e-9, "the parts' lowest point at the same rest pose (SLSQP vs continued Newton: 1e-12)", unit="m"),
    ]



def _mujoco_torsion(ctx: CaseContext, s, c) -> list:
    """The shipped model (boat_model.build_spec) started from the Kane run's initial state."""
    torsion = c.loads[0].run
    start = State(torsion.com[0], torsion.rotation[0], torsion.velocity[0], torsion.omega[0])
    model = build_spec(s, c.config.name, rest=c.rest).compile()
    mj = mujoco_rig.simulate(model, c.rig, start, MUJOCO_SECONDS, DT_OUT, "tendon")
    n = len(mj.t)
    kane = to_trajectory(torsion, c.rig, rtol=1e-10).window(MUJOCO_SECONDS)
    ctx.keep(kane, mj)
    # The turn about the vertical, 2 atan2(qz, qw): the torsion turns the boat about z alone.
    yaw_mj = np.unwrap(2.0 * np.arctan2(mj["quat"][:, 3], mj["quat"][:, 0]))
    yaw_kane = np.unwrap(2.0 * np.arctan2(kane["quat"][:, 3], kane["quat"][:, 0]))
    static = c.rest.tensions.mean()
    p_mj, p_kane = period(mj.t, yaw_mj).value, period(kane.t, yaw_kane).value
    leapfrog = (2.0 * np.pi / p_kane * model.opt.timestep) ** 2 / 24.0
    return [
        check(f"configuration {c.config.name} torsion pi/12: MuJoCo vs Kane tension / static tension",
              max_abs(mj["tension"][1:] - kane["tension"][1:n]) / static, TENSION_RTOL,
              "chosen numerics (models/README.md); t = 0 excluded, as there"),
        check(f"configuration {c.config.name} torsion pi/12: MuJoCo wire stretch", max_abs(mj["length_error"]), STRETCH,
              "estimated 1.4e-9 m, twice that allowed as measured on the plate (module docstring)", unit="m"),
        check(f"configuration {c.config.name} torsion pi/12: MuJoCo vs Kane period, relative", abs(p_mj / p_kane - 1.0),
              3.0 * leapfrog, f"3 (omega h)^2 / 24: the leapfrog's {leapfrog:.1e} and the stretch's like share"),
    ]
