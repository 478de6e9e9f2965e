"""The Solar Boat as a MuJoCo model: a configuration's rig (:mod:`validate.engines.mjcf`) drawn as its
parts, written as ``models/solar_boat/boat.xml`` and ``scene.xml``.

The physics is the rig's, built by :func:`validate.engines.mjcf.build_spec`: one free body ``body``
with the parts' mass, COM and full inertia tensor as an explicit inertial, and two tendon wires from
the hall's hooks. To it this module adds one visual geom per part (class ``visual``: no contact, no
mass; named as the part), so the model looks like the boat. MuJoCo has no hollow cylinder or hollow
sphere: hollow parts are drawn as their outer surface, translucent so that what they hold shows.
The inertia-equivalent box of ``build_spec`` moves to geom group 3, hidden until toggled in the
viewer. Keyframe ``initial`` is the thesis's torsion release, pi/12 about the vertical (Fig. 8.4.1).
The scene puts the floor at the hall's floor, ``hook_height`` under the highest hook.

Regenerate after changing the parts or the hall:
``python -m validate.studies.boat_model models/solar_boat/suspension.toml models/solar_boat``.
"""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
from scipy.spatial.transform import Rotation

from bifilar.bodies.boat import Suspension, load_suspension
from bifilar.rig.statics import Rest, rest_pose

from ..engines import mjcf

CONFIGURATION = "1"  # the thesis's recommendation, hung in the shipped model
TORSION = np.pi / 12  # rad, keyframe 'initial': the release of the thesis's Fig. 8.4.1
HIDDEN_GROUP = 3  # MuJoCo's viewer shows geom groups 0-2 by default

# Drawing only: colour by shape (solar cells, carbon, translucent shells).
_RGBA = {
    "plate": (0.08, 0.12, 0.35, 1.0),
    "box": (0.25, 0.25, 0.28, 1.0),
    "beam": (0.15, 0.15, 0.15, 1.0),
    "cylinder": (0.85, 0.55, 0.35, 1.0),
    "sphere": (0.75, 0.2, 0.15, 1.0),
    "hollow_cylinder": (0.95, 0.95, 0.95, 0.45),
    "cylindrical_shell": (0.95, 0.95, 0.95, 0.45),
    "hollow_sphere": (0.7, 0.85, 1.0, 0.35),
    "spherical_shell": (0.7, 0.85, 1.0, 0.35),
}


def part_geom(part) -> dict:
    """MjSpec geom attributes drawing one part (bifilar.bodies.composite.Part): type, size, pose, colour."""
    d = part.dims
    if "width" in d:
        kind, size = mujoco.mjtGeom.mjGEOM_BOX, [0.5 * d["length"], 0.5 * d["width"], 0.5 * d["height"]]
    elif "length" in d:
        kind, size = mujoco.mjtGeom.mjGEOM_CYLINDER, [d["radius"], 0.5 * d["length"], 0.0]
    else:
        kind, size = mujoco.mjtGeom.mjGEOM_SPHERE, [d["radius"], 0.0, 0.0]
    quat = Rotation.from_matrix(part.rotation).as_quat(scalar_first=True)
    return {"name": part.name, "type": kind, "size": size, "pos": part.position, "quat": quat,
            "rgba": _RGBA[part.shape]}


def build_spec(s: Suspension, configuration: str = CONFIGURATION, scene: bool = False,
               rest: Rest | None = None) -> mujoco.MjSpec:
    """The boat hung in ``configuration`` (see the module docstring); ``scene`` adds the hall."""
    rig = s.rig(s.configuration(configuration)).with_initial(rotation=(0.0, 0.0, TORSION))
    rest = rest_pose(rig) if rest is None else rest
    spec = mjcf.build_spec(rig, rest=rest)
    spec.modelname = "solar_boat"
    spec.comment += (f"  Drawn as the {len(s.parts)} parts of {s.source} (validate/studies/boat_model.py); the box above\n"
                     f"  is geom group {HIDDEN_GROUP}, hidden. Keyframe 'initial': {TORSION:.6g} rad of torsion.\n")
    spec.geom("body").group = HIDDEN_GROUP
    body, visual = spec.body("body"), spec.find_default("visual")
    for part in s.parts:
        body.add_geom(visual, **part_geom(part))
    if scene:
        add_hall(spec, s, rig, rest)
    return spec


def add_hall(spec: mujoco.MjSpec, s: Suspension, rig, rest: Rest) -> None:
    """:func:`validate.engines.mjcf.add_scene`, with the floor moved to the hall's floor."""
    mjcf.add_scene(spec, rig, rest)
    floor = spec.geom("floor")
    floor.pos = [floor.pos[0], floor.pos[1], float(s.hooks[:, 2].max()) - s.hook_height]


def write_model_files(s: Suspension, directory: str | Path) -> tuple[Path, Path]:
    """Write ``boat.xml`` and ``scene.xml`` (which includes it and adds the hall) into ``directory``."""
    rig = s.rig(s.configuration(CONFIGURATION))
    rest = rest_pose(rig)
    return mjcf.write_xml_pair(build_spec(s, rest=rest), "boat.xml", lambda spec: add_hall(spec, s, rig, rest),
                               directory)


def main(argv: list[str] | None = None) -> int:
    """``python -m validate.studies.boat_model SUSPENSION.toml DIR``: write DIR/boat.xml and DIR/scene.xml."""
    return mjcf.xml_main(argv, main.__doc__, "suspension file (TOML), e.g. models/solar_boat/suspension.toml",
                         lambda path, out: write_model_files(load_suspension(path), out))


if __name__ == "__main__":
    raise SystemExit(main())
