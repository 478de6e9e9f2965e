"""Build a MuJoCo model of a rig with :class:`mujoco.MjSpec`, and write it as plain MJCF.

The model is one free body hung from two cables; every vector is in the world frame (z up, gravity
along -z) unless it says body frame. The body frame is the rig file's own body frame, so the sites
``attach1``/``attach2`` sit at the rig's ``attach`` points and the inertial at ``rig.com``. The model
is built at the rest pose (``qpos0`` and keyframe ``rest`` are :func:`bifilar.rig.statics.rest_pose`), so
that MuJoCo's reference quantities computed at ``qpos0`` (tendon lengths, the constraint-space inertia
used by the soft-constraint regularizer) are those of the pendulum at rest; keyframe ``initial`` is
:func:`bifilar.rig.statics.initial_state`.

Two cable models (``CABLES``):

``tendon``
    Each wire is a spatial tendon from the world site ``anchor<i>`` to the body site ``attach<i>``,
    limited to ``[0, length]``: a one-sided constraint that pulls when the tendon would be longer
    than the wire and lets the wire go slack otherwise.
``equality``
    The same tendons, unlimited, each held at its length by a tendon equality constraint (two-sided:
    it can push). MuJoCo 4.0 has no distance equality (``mjEQ_DISTANCE`` raises "unsupported"), and a
    ``connect`` pins a point rather than a distance, so a single-tendon equality is the one built-in
    equality that keeps a point-to-point length.

Elastic wires (``axial_stiffness`` EA): with ``tendon`` cables each tendon is a spring of stiffness
EA / L with the dead band ``springlength = [0, L]``: MuJoCo's tendon spring pulls with k (l - L) above
the band and pushes below it, so a band from 0 to L gives exactly "k (l - L) when longer than L, else
nothing" (measured: no force at l < L). The tendon is unlimited: no constraint row, the spring is a
passive force. ``equality`` cables cannot go slack or stretch by EA and refuse elastic wires.

Air (``[air]``, docs/air.md): the option's ``density`` and ``viscosity`` and one ellipsoid geom with
``fluidshape="ellipsoid"`` at the air's ellipsoid. MuJoCo's ellipsoid model has the same drag terms as
ours (the ``fluidcoef`` blunt, slender and angular coefficients are the rig's) and no Kutta or Magnus
lift here (``fluidcoef`` 3, 4 = 0: our model has neither). Of the added mass it applies only the
velocity products of the fluid's impulse (Kirchhoff's terms); the acceleration term is left out
(measured: a fluid body at rest accelerates as in a vacuum). :func:`compile_model` supplies it as the
free joint's ``dof_armature``: the diagonal of the added-mass tensor, translational in world axes at
rest, rotational in body axes about the body origin. Armature adds inertia without weight and without
velocity terms, which is what the missing term is. What it cannot hold: the off-diagonal entries
(zero when the ellipsoid's axes are the body axes and its centre the body origin, as in
``models/rigs/foam_wing.toml``) and the turning of the translational block with the body (second order
in the rotation). MJCF has one armature per joint, so the written XML lacks it (its header says so).

Building is stateless and costs about a millisecond, so sweeps may build thousands of models.
"""

from __future__ import annotations

import errno
import sys
from dataclasses import dataclass, replace
from pathlib import Path

import mujoco
import numpy as np
from scipy.spatial.transform import Rotation

from bifilar.rig.air import added_mass
from bifilar.bodies.composite import equivalent_box
from bifilar.rig import Rig, RigError, load_rig
from bifilar.rig.statics import Rest, State, attachments, initial_state, rest_pose

from ..trajectory import atomic_write_text

CABLES = ("tendon", "equality")

_INTEGRATORS = {
    "Euler": mujoco.mjtIntegrator.mjINT_EULER,
    "RK4": mujoco.mjtIntegrator.mjINT_RK4,
    "implicit": mujoco.mjtIntegrator.mjINT_IMPLICIT,
    "implicitfast": mujoco.mjtIntegrator.mjINT_IMPLICITFAST,
    "discrete": mujoco.mjtIntegrator.mjINT_DISCRETE,
}


@dataclass(frozen=True)
class Numerics:
    """Time step, integrator and cable-constraint softness. The defaults are the settings chosen in
    ``models/README.md`` from measurements (``benchmarks/mujoco_settings.py``); the reasoning:

    * ``timeconst, dampratio`` are the cable rows' ``solref`` (s, -); ``None`` means ``2 timestep``,
      the stiffest spring MuJoCo's ``refsafe`` allows the explicit integrators. With ``dampratio``
      0.5 the row's discrete error dynamics are deadbeat (both eigenvalues zero); 1.5 steps with
      0.5 was measured unstable.
    * At rest a row with impedance d stretches by ``(1 - d) a timeconst^2 dampratio^2`` (MuJoCo
      modeling guide; a ~ g the unconstrained acceleration along the wire). In motion it settles
      about ``h^2 c / 2`` from that, c being the kinematic curvature of the wire length (v_perp^2 / L
      plus the centripetal acceleration of the attachment along the wire), of either sign.
    * A limit row exists only while stretched, so when ``-c`` exceeds about ``2 (1 - d) a`` a taut
      wire drops out for a step and snaps back (false slack, chatter). d = 0.9999 (MuJoCo's ceiling)
      tolerates |c| < 2e-3 m/s^2 and chatters on models/rigs/asymmetric.toml; d = 0.99 tolerates
      0.2 m/s^2 and stretches the plate by 1.8e-10 m at rest.
    """

    timestep: float = 4e-5  # s
    integrator: str = "implicitfast"
    timeconst: float | None = None  # s; None -> 2 * timestep
    dampratio: float = 0.5
    # Constant impedance d (width, midpoint and power are MuJoCo's defaults and unused when d0 = dw).
    solimp: tuple[float, float, float, float, float] = (0.99, 0.99, 0.001, 0.5, 2.0)
    refsafe: bool = True  # MuJoCo's clamp timeconst >= 2 * timestep (see its XML reference)
    # Newton solver: stop when the cost improves by less (relative). MuJoCo's 1e-8 lets RK4 gain
    # 0.04 J in 10 s on the plate (measured); 1e-10 removes that and costs nothing (one iteration).
    tolerance: float = 1e-10
    staggered: bool = True  # start and read velocities at half steps (see validate.engines.mujoco_rig)

    @property
    def solref(self) -> tuple[float, float]:
        return (2.0 * self.timestep if self.timeconst is None else self.timeconst, self.dampratio)

    def with_(self, **changes) -> Numerics:
        return replace(self, **changes)


CHOSEN = Numerics()

# A tendon limit row exists while ``range_max - length < margin`` and pulls towards
# ``length = range_max - margin``. Exactly at the wire's length (the initial state) a zero margin leaves
# the row out, so the body would fall freely for a step; this margin, far above the rounding of a
# tendon length (~1e-15 m) and far below the 1e-9 m length target, keeps a taut wire's row in.
TAUT_MARGIN = 1e-12  # m

# Visual constants (no physics): colours, and sizes relative to the rig's own scale.
_WIRE_RGBA = (0.85, 0.75, 0.2, 1.0)
_BODY_RGBA = (0.3, 0.45, 0.7, 1.0)
_BEAM_RGBA = (0.45, 0.35, 0.3, 1.0)
_AIR_RGBA = (0.7, 0.85, 1.0, 0.25)
_WIRE_WIDTH = 0.004  # tendon drawing radius per metre of wire
_BEAM_SECTION = 0.02  # beam cross-section per metre of the larger of anchor span and wire length
_MIN_BOX = 0.02  # thinnest edge of the body's drawing box, per metre of its longest edge


def build_spec(rig: Rig, cables: str = "tendon", numerics: Numerics = CHOSEN, scene: bool = False,
               rest: Rest | None = None, *, gyro: bool = False) -> mujoco.MjSpec:
    """The rig as an :class:`mujoco.MjSpec` (not compiled); ``scene`` adds floor, light and beam;
    ``gyro`` adds a site ``imu`` at the COM (body axes) and a sensor ``gyro`` there: the body's angular
    velocity in body axes (rad/s), what a rate gyro strapped to the body reads (for mujoco.sysid)."""
    if cables not in CABLES:
        raise RigError(rig.source, "cables", f"unknown cable model {cables!r} (known: {', '.join(CABLES)})")
    if numerics.integrator not in _INTEGRATORS:
        raise RigError(rig.source, "integrator", f"unknown {numerics.integrator!r} (known: {', '.join(_INTEGRATORS)})")
    if rig.elastic and cables != "tendon":
        raise RigError(rig.source, "wire[1].axial_stiffness", f"the {cables} cables hold each wire at its length and "
                       "cannot model elastic wires: use --engine mujoco (tendon springs) or kane")
    rest = rest_pose(rig) if rest is None else rest
    spec = mujoco.MjSpec()
    spec.modelname = rig.name
    spec.comment = _header(rig, cables, numerics)
    spec.compiler.degree = False  # angle="radian"
    spec.compiler.autolimits = True
    # Save the spec as written (full precision, fullinertia): the compiled form rounds to 6 digits.
    spec.compiler.savecompiled = False
    spec.compiler.savecanonical = False
    _set_options(spec, rig, numerics)
    _add_defaults(spec, rig, cables, numerics)

    origin, quat = pose_qpos(rig, rest.com, rest.rotation)
    body = spec.worldbody.add_body(name="body", pos=origin, quat=quat)
    body.explicitinertial = True
    body.mass = rig.mass
    body.ipos = rig.com
    inertia = rig.inertia
    body.fullinertia = [inertia[0, 0], inertia[1, 1], inertia[2, 2], inertia[0, 1], inertia[0, 2], inertia[1, 2]]
    body.add_freejoint(name="free")
    if gyro:
        body.add_site(name="imu", pos=rig.com)
        spec.add_sensor(name="gyro", type=mujoco.mjtSensor.mjSENS_GYRO, objtype=mujoco.mjtObj.mjOBJ_SITE, objname="imu")
    size, box_quat = _inertia_box(rig)
    body.add_geom(spec.find_default("visual"), name="body", type=mujoco.mjtGeom.mjGEOM_BOX, size=size,
                  pos=rig.com, quat=box_quat, rgba=_BODY_RGBA)
    if rig.air is not None:
        _add_air(spec, body, rig)

    wire_class = spec.find_default("wire")
    for i, wire in enumerate(rig.wires, start=1):
        spec.worldbody.add_site(name=f"anchor{i}", pos=wire.anchor)
        body.add_site(name=f"attach{i}", pos=wire.attach)
        tendon = spec.add_tendon(wire_class, name=f"wire{i}")
        tendon.wrap_site(f"anchor{i}")
        tendon.wrap_site(f"attach{i}")
        if wire.axial_stiffness is not None:  # a spring that pulls above L only (module docstring)
            tendon.stiffness[0] = wire.spring
            tendon.springlength = [0.0, wire.length]
        elif cables == "tendon":
            tendon.range = [0.0, wire.length]
            tendon.margin = TAUT_MARGIN
    if cables == "equality":
        # Single-tendon equality: length - length(qpos0) = polycoef[0]; qpos0 is the rest pose, where
        # each wire is at its length to rounding, and polycoef[0] absorbs that rounding.
        length0 = np.linalg.norm(attachments(rig, rest.com, rest.rotation) - [w.anchor for w in rig.wires], axis=1)
        for i, wire in enumerate(rig.wires, start=1):
            eq = spec.add_equality(spec.find_default("wire"), name=f"wire{i}", type=mujoco.mjtEq.mjEQ_TENDON,
                                   objtype=mujoco.mjtObj.mjOBJ_TENDON, name1=f"wire{i}")
            eq.data[:5] = [wire.length - length0[i - 1], 0.0, 0.0, 0.0, 0.0]

    spec.add_key(name="rest", qpos=np.concatenate([origin, quat]), qvel=np.zeros(6))
    qpos, qvel = state_qpos_qvel(rig, initial_state(rig, rest))
    spec.add_key(name="initial", qpos=qpos, qvel=qvel)  # the rig file's [initial] disturbance
    if scene:
        add_scene(spec, rig, rest)
    return spec


def compile_model(rig: Rig, cables: str = "tendon", numerics: Numerics = CHOSEN, scene: bool = False,
                  rest: Rest | None = None) -> mujoco.MjModel:
    """The compiled model of :func:`build_spec`, with the air's added mass as armature (see above)."""
    rest = rest_pose(rig) if rest is None else rest
    model = build_spec(rig, cables, numerics, scene, rest).compile()
    if rig.air is not None:
        model.dof_armature[:6] = air_armature(rig, rest)
    return model


def air_armature(rig: Rig, rest: Rest) -> np.ndarray:
    """The free joint's armature for the air: the diagonal of the added-mass tensor about the body
    origin, translation in world axes at ``rest``, rotation in body axes (kg, kg m^2)."""
    ma = added_mass(rig.air, np.zeros(3))
    return np.concatenate([np.diag(rest.rotation @ ma[:3, :3] @ rest.rotation.T), np.diag(ma[3:, 3:])])


def pose_qpos(rig: Rig, com: np.ndarray, rotation: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Free-joint position (body-frame origin, world, m) and quaternion (body->world, wxyz)."""
    origin = com - rotation @ rig.com
    return origin, Rotation.from_matrix(rotation).as_quat(scalar_first=True)


def state_qpos_qvel(rig: Rig, state: State) -> tuple[np.ndarray, np.ndarray]:
    """MuJoCo ``qpos`` (7) and ``qvel`` (6) of a rigid-body state.

    A free joint's ``qvel`` is the velocity of the body-frame origin in the world frame followed by
    the angular velocity in the body (local) frame (MuJoCo overview, "floating objects"); the state
    gives the COM velocity and the angular velocity in the world frame.
    """
    origin, quat = pose_qpos(rig, state.com, state.rotation)
    arm = state.rotation @ rig.com  # COM relative to the body origin, world frame
    v_origin = state.velocity - np.cross(state.omega, arm)
    return np.concatenate([origin, quat]), np.concatenate([v_origin, state.rotation.T @ state.omega])


def add_scene(spec: mujoco.MjSpec, rig: Rig, rest: Rest | None = None) -> None:
    """Floor, light, ceiling beam and camera framing: drawing only, nothing here touches the body.

    The floor lies at the lowest height the body can reach with taut wires (lowest anchor, minus the
    longest wire, minus the farthest the body's drawing box reaches from an attachment), so that
    nothing ever meets it; the body's geoms and the beam do not collide anyway.
    """
    rest = rest_pose(rig) if rest is None else rest
    anchors = np.array([w.anchor for w in rig.wires])
    longest = max(w.length for w in rig.wires)
    size, _ = _inertia_box(rig)
    reach = max(np.linalg.norm(w.attach - rig.com) for w in rig.wires) + float(np.linalg.norm(size))
    floor_z = anchors[:, 2].min() - longest - reach
    span = float(np.ptp(anchors, axis=0).max())
    section = _BEAM_SECTION * max(span, longest)
    top = anchors[:, 2].max()
    centre = anchors.mean(axis=0)

    spec.add_texture(name="grid", type=mujoco.mjtTexture.mjTEXTURE_2D, builtin=mujoco.mjtBuiltin.mjBUILTIN_CHECKER,
                     rgb1=[0.2, 0.3, 0.4], rgb2=[0.1, 0.2, 0.3], width=300, height=300)
    spec.add_material(name="grid", textures=["", "grid"], texrepeat=[1.0, 1.0], texuniform=True, reflectance=0.2)
    spec.worldbody.add_geom(name="floor", type=mujoco.mjtGeom.mjGEOM_PLANE, pos=[centre[0], centre[1], floor_z],
                            size=[0.0, 0.0, 0.05], material="grid")
    spec.worldbody.add_geom(name="beam", type=mujoco.mjtGeom.mjGEOM_BOX, contype=0, conaffinity=0,
                            fromto=np.concatenate([anchors[0], anchors[-1]]) + [0, 0, section, 0, 0, section],
                            size=[section, 0.0, 0.0], rgba=_BEAM_RGBA)
    spec.worldbody.add_light(name="top", pos=[centre[0], centre[1], top + longest], dir=[0.0, 0.0, -1.0],
                             type=mujoco.mjtLightType.mjLIGHT_DIRECTIONAL)
    spec.stat.center = 0.5 * (centre + rest.com)
    spec.stat.extent = float(max(longest, span))


def write_model_files(rig: Rig, directory: str | Path) -> tuple[Path, Path]:
    """Write ``<rig.name>.xml`` (tendon cables, chosen numerics) and ``scene.xml``, which includes it
    and adds the scene, so that ``python -m mujoco.viewer --mjcf <directory>/scene.xml`` opens it."""
    rest = rest_pose(rig)
    return write_xml_pair(build_spec(rig, rest=rest), f"{rig.name}.xml", lambda spec: add_scene(spec, rig, rest),
                          directory)


def write_xml_pair(model: mujoco.MjSpec, model_file: str, scene, directory: str | Path) -> tuple[Path, Path]:
    """Write ``model`` to ``directory/model_file`` and ``scene.xml``, an MJCF that includes it and holds
    what ``scene(spec)`` adds to an empty spec (floor, light, ceiling). Full precision, as written."""
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    model_path = directory / model_file
    scene_path = directory / "scene.xml"
    include = f'<include file="{model_path.name}"/>'
    if scene_path.is_file() and include not in scene_path.read_text(errors="replace"):  # before any write
        raise FileExistsError(errno.EEXIST, "is the scene of another model; write each model to its own folder",
                              str(scene_path))
    atomic_write_text(model_path, model.to_xml())
    scene_spec = mujoco.MjSpec()
    scene_spec.modelname = f"{Path(model_file).stem} scene"
    scene_spec.compiler.savecompiled = False
    scene_spec.compiler.savecanonical = False
    scene(scene_spec)
    head, sep, tail = scene_spec.to_xml().partition(">\n")
    atomic_write_text(scene_path, f'{head}{sep}  <include file="{model_path.name}"/>\n\n{tail}')
    return model_path, scene_path


def _set_options(spec: mujoco.MjSpec, rig: Rig, numerics: Numerics) -> None:
    opt = spec.option
    opt.timestep = numerics.timestep
    opt.integrator = _INTEGRATORS[numerics.integrator]
    opt.gravity = [0.0, 0.0, -rig.gravity]
    opt.solver = mujoco.mjtSolver.mjSOL_NEWTON
    opt.tolerance = numerics.tolerance
    # No contacts: the body meets nothing, and skipping collision keeps each step to the cables. No
    # island discovery: one body is one island; finding it cost ~10 % of a step (3.59 -> 3.25 us on the
    # plate, the trajectory bitwise the same: python benchmarks/mujoco_step.py).
    opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONTACT | mujoco.mjtDisableBit.mjDSBL_ISLAND
    if not numerics.refsafe:
        opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_REFSAFE


def _add_defaults(spec: mujoco.MjSpec, rig: Rig, cables: str, numerics: Numerics) -> None:
    visual = spec.add_default("visual", spec.default)
    visual.geom.contype = 0
    visual.geom.conaffinity = 0
    visual.geom.group = 2
    wire = spec.add_default("wire", spec.default)
    wire.tendon.width = _WIRE_WIDTH * max(w.length for w in rig.wires)
    wire.tendon.rgba = _WIRE_RGBA
    if cables == "tendon":
        wire.tendon.solref_limit = numerics.solref
        wire.tendon.solimp_limit = numerics.solimp
    else:
        wire.equality.solref = numerics.solref
        wire.equality.solimp = numerics.solimp


def _add_air(spec: mujoco.MjSpec, body: mujoco.MjsBody, rig: Rig) -> None:
    """The fluid on the option and the air's ellipsoid as a massless, non-colliding fluid geom."""
    air = rig.air
    spec.option.density = air.density
    spec.option.viscosity = air.viscosity
    body.add_geom(spec.find_default("visual"), name="air", type=mujoco.mjtGeom.mjGEOM_ELLIPSOID,
                  size=air.semi_axes, pos=air.center, quat=Rotation.from_matrix(air.axes).as_quat(scalar_first=True),
                  fluid_ellipsoid=1, fluid_coefs=[*map(float, air.drag), 0.0, 0.0], rgba=_AIR_RGBA)


def _inertia_box(rig: Rig) -> tuple[np.ndarray, np.ndarray]:
    """:func:`bifilar.bodies.composite.equivalent_box` as half sizes, no edge thinner than ``_MIN_BOX`` of the
    longest (a flat body stays visible), and a wxyz quaternion (MuJoCo's order)."""
    half, axes = equivalent_box(rig.mass, rig.inertia)
    return np.maximum(half, _MIN_BOX * half.max()), Rotation.from_matrix(axes).as_quat(scalar_first=True)


def _header(rig: Rig, cables: str, numerics: Numerics) -> str:
    """The file's opening comment: where every number comes from."""
    def vec(x) -> str:
        return "[" + ", ".join(repr(float(v)) for v in x) + "]"

    timeconst, dampratio = numerics.solref
    lines = [
        f"Rig '{rig.name}' from {rig.source}, written by validate/engines/mjcf.py; see models/README.md.",
        f"Units SI, angles radian; world z up, gravity {rig.gravity:g} m/s^2 along -z. Cables: {cables}.",
        f"body: {rig.mass:g} kg, COM {vec(rig.com)} m (body frame), fullinertia about the COM (body axes).",
        *(f"wire{i}: anchor {vec(w.anchor)} m (world), attach {vec(w.attach)} m (body), length {w.length!r} m"
          + ("." if w.axial_stiffness is None else f" unstretched, EA {w.axial_stiffness!r} N: tendon stiffness EA / L, "
             "springlength [0, L] (pulls only when longer than L).")
          for i, w in enumerate(rig.wires, start=1)),
        "qpos0 and keyframe 'rest': bifilar.rig.statics.rest_pose; keyframe 'initial': the rig's [initial] state.",
        (f"Numerics (models/README.md): timestep {numerics.timestep:g} s, {numerics.integrator}; cable solref "
         f"{timeconst:g} s{' (2 timesteps)' if numerics.timeconst is None else ''} {dampratio:g},"),
        f"  solimp {' '.join(f'{x:g}' for x in numerics.solimp)} (constant impedance);",
        f"  tendon margin {TAUT_MARGIN:g} m: a wire exactly at its length is taut.",
        "Body geom: the uniform box with the body's mass and inertia, for drawing only (no contact).",
    ]
    if rig.air is not None:
        lines.append("Air: fluid geom 'air' (ellipsoid model, no Kutta/Magnus lift). The added mass is NOT in this "
                     "file: validate.engines.mjcf.compile_model sets it as dof_armature.")
    return "\n" + "\n".join("  " + line for line in lines) + "\n"


def main(argv: list[str] | None = None) -> int:
    """``python -m validate.engines.mjcf RIG.toml DIR``: write the rig's model and scene XML."""
    return xml_main(argv, main.__doc__, "rig file (TOML)", lambda path, out: write_model_files(load_rig(path), out))


def xml_main(argv, description: str, input_help: str, write) -> int:
    """A command line ``INPUT DIR`` that calls ``write(INPUT, DIR)`` and prints the files written; a
    bad input is one line on stderr and exit status 2."""
    from ..argtypes import OneLineParser, UsageError

    parser = OneLineParser(description=description)
    parser.add_argument("input", help=input_help)
    parser.add_argument("directory", help="output folder")
    try:
        args = parser.parse_args(argv)
        paths = write(args.input, args.directory)
    except (RigError, UsageError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except OSError as exc:
        print(f"error: {exc.filename}: cannot write ({exc.strerror})", file=sys.stderr)
        return 2
    except Exception as exc:  # a numerical failure while building: one line, exit 4 (as python -m validate)
        print(f"error: {args.input}: rig: the model could not be built ({type(exc).__name__}: {exc})", file=sys.stderr)
        return 4
    for path in paths:
        print(path)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
