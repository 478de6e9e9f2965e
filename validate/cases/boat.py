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
"""

from __future__ import annotations

import numpy as np

from bifilar.bodies.boat import load_suspension
from bifilar.rig.statics import State

from ..studies.boat_model import build_spec
from ..studies.boat_study import DT_OUT, SUSPENSION, run_study
from ..engines import mujoco_rig
from ..engines.kane import to_trajectory
from ..metrics import max_abs, period
from ..registry import CaseContext, case, check

IDENTIFY_RTOL = 1e-8
REST_RTOL = 1e-8
MUJOCO_SECONDS = 6.0  # 3.2 torsion periods of configuration 1: three rising crossings
TENSION_RTOL = 1e-6  # of the static tension (module docstring)
STRETCH = 3e-9  # m (module docstring: 1.4e-9 m estimated)


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
    return out


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
