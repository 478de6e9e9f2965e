"""Seed 002's three-body pendulum: its frames as a TMT chain (the MuJoCo model of the same chain is
:mod:`validate.engines.seed002_mujoco`).

The seed (/work/shared/seeds/002_83c2d3773759b45a.txt) builds the pendulum from relative frames,
each a product of translations and one rotation about e1:

* ``E^1   = T(0, 0, l1) Rx(theta) T(l2, l3, 0)``: body 1, the arm, from the inertial frame;
* ``E^2_1 = T(0, l4, 0) Rx(phi) T(l5, l6, 0)``: body 2, the rod, from the arm;
* ``E^3_2 = T(0, l7, 0)``: body 3, the ball, fixed to the rod.

Every body frame sits at the body's COM with the body's axes. Inertial e3 is up and gravity acts
along -e3; ``theta`` is the arm's angle from the horizontal e2 axis, ``phi`` the rod's angle relative
to the arm. The numbers the seed leaves open are in ``models/seed002/params.toml`` and
docs/seed002.md says where each comes from.
"""

from __future__ import annotations

import tomllib
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from bifilar.seeds.tmt import Body, Chain, Frame

MODEL_DIR = Path(__file__).resolve().parents[2] / "models" / "seed002"
PARAMS = MODEL_DIR / "params.toml"
XML = MODEL_DIR / "seed002.xml"
JOINTS = ("theta", "phi")  # q[0], q[1]: MuJoCo hinge names
BODIES = ("arm", "rod", "ball")  # bodies 1, 2, 3 of the seed
E1 = (1.0, 0.0, 0.0)  # both rotations are about e1


@dataclass(frozen=True)
class Params:
    """The contents of params.toml (SI units, radians)."""

    gravity: float
    lengths: dict[str, float]  # l1 ... l7
    bodies: tuple[Body, ...]  # arm, rod, ball
    q0: np.ndarray  # (theta, phi) at release
    qd0: np.ndarray
    visual: dict[str, float]
    timestep: float  # MuJoCo's, s


def load(path: str | Path = PARAMS) -> Params:
    """Read the parameter file."""
    data = tomllib.loads(Path(path).read_text())
    lengths = {f"l{i}": float(data["lengths"][f"l{i}"]) for i in range(1, 8)}
    bodies = tuple(
        Body(name, float(data["body"][name]["mass"]), np.array(data["body"][name]["inertia"], dtype=float))
        for name in BODIES
    )
    ini = data["initial"]
    return Params(
        gravity=float(data["gravity"]),
        lengths=lengths,
        bodies=bodies,
        q0=np.array([ini["theta"], ini["phi"]], dtype=float),
        qd0=np.array([ini["theta_dot"], ini["phi_dot"]], dtype=float),
        visual={k: float(v) for k, v in data["visual"].items()},
        timestep=float(data["mujoco"]["timestep"]),
    )


def chain(p: Params) -> Chain:
    """The seed's frames as a TMT chain: q = (theta, phi)."""
    L = p.lengths
    arm, rod, ball = p.bodies
    frames = [
        Frame(s=(0.0, 0.0, L["l1"]), axis=E1, coordinate=0),  # E'_1 E'_2: up l1, turn by theta
        Frame(s=(L["l2"], L["l3"], 0.0), body=arm),  # E'_3: out to the arm's COM
        Frame(s=(0.0, L["l4"], 0.0), axis=E1, coordinate=1),  # to the elbow, turn by phi
        Frame(s=(L["l5"], L["l6"], 0.0), body=rod),  # out to the rod's COM
        Frame(s=(0.0, L["l7"], 0.0), body=ball),  # E^3_2: the ball, fixed to the rod
    ]
    return Chain(frames, (0.0, 0.0, -p.gravity))
