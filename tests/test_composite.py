"""Composite mass properties: each primitive against its textbook formula and against MuJoCo's
compiler, the composition against the thesis's dumbbell (ch. 3) and MuJoCo, the Solar Boat parts
file against the thesis's ch. 8.1 numbers, and the parts loader's error messages."""

import math
from pathlib import Path

import mujoco
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from bifilar.bodies.composite import (
    SHAPES,
    load_parts,
    mass_properties,
    part_from_dict,
    rig_body,
    rotation_from_axis,
)
from bifilar.rig import RigError, rig_from_dict

BOAT = Path(__file__).parents[1] / "models" / "solar_boat" / "parts.toml"
EXACT = 1e-12  # closed forms evaluated two ways: a few roundings of double precision
MUJOCO = 1e-9  # MuJoCo composes and diagonalizes iteratively in double: ~3e-14 seen, 1e-9 required

# Dimensions (m) of one part per shape, and its textbook principal moments per unit mass (m^2)
# about the centroid along the part axes, and its volume (area for shells) -- written out
# independently of bifilar.bodies.composite.
R, RI, L = 0.3, 0.2, 1.1
TEXTBOOK = {
    "box": ({"length": 0.5, "width": 0.3, "height": 0.2},
            [(0.09 + 0.04) / 12, (0.25 + 0.04) / 12, (0.25 + 0.09) / 12], 0.5 * 0.3 * 0.2),
    "cylinder": ({"radius": R, "length": L},
                 [R**2 / 4 + L**2 / 12] * 2 + [R**2 / 2], math.pi * R**2 * L),
    "hollow_cylinder": ({"radius": R, "inner_radius": RI, "length": L},
                        [(R**2 + RI**2) / 4 + L**2 / 12] * 2 + [(R**2 + RI**2) / 2],
                        math.pi * (R**2 - RI**2) * L),
    "cylindrical_shell": ({"radius": R, "length": L},
                          [R**2 / 2 + L**2 / 12] * 2 + [R**2], 2 * math.pi * R * L),
    "sphere": ({"radius": R}, [2 / 5 * R**2] * 3, 4 / 3 * math.pi * R**3),
    "hollow_sphere": ({"radius": R, "inner_radius": RI},
                      [2 / 5 * (R**5 - RI**5) / (R**3 - RI**3)] * 3, 4 / 3 * math.pi * (R**3 - RI**3)),
    "spherical_shell": ({"radius": R}, [2 / 3 * R**2] * 3, 4 * math.pi * R**2),
}


def part(shape, dims, **kw):
    return part_from_dict({"name": shape, "shape": shape, **dims, **kw})


@pytest.mark.parametrize("shape", sorted(TEXTBOOK))
def test_primitive_matches_textbook(shape):
    dims, gyration, measure = TEXTBOOK[shape]
    p = part(shape, dims, mass=2.5)
    np.testing.assert_allclose(p.principal_moments(), 2.5 * np.array(gyration), rtol=EXACT)
    assert part(shape, dims, density=7.0).mass == pytest.approx(7.0 * measure, rel=EXACT)


def test_every_shape_is_tested():
    assert set(SHAPES) - {"beam", "plate"} == set(TEXTBOOK)
    assert SHAPES["beam"] is SHAPES["box"] and SHAPES["plate"] is SHAPES["box"]


@pytest.mark.parametrize(("hollow", "solid", "shell"), [
    ("hollow_cylinder", "cylinder", "cylindrical_shell"), ("hollow_sphere", "sphere", "spherical_shell")])
def test_hollow_shapes_reach_solid_and_shell_limits(hollow, solid, shell):
    """A hollow part with no hole is the solid one; with the wall thinned to 1e-9 m it is the thin
    shell to O(1e-9), and the factored sphere formula does not cancel catastrophically there."""
    dims = {"radius": R} | ({"length": L} if "length" in SHAPES[hollow].dims else {})
    no_hole = part(hollow, dims | {"inner_radius": 1e-300}, mass=1.0)
    thin = part(hollow, dims | {"inner_radius": R - 1e-9}, mass=1.0)
    np.testing.assert_allclose(no_hole.principal_moments(), part(solid, dims, mass=1.0).principal_moments(),
                               rtol=EXACT)
    np.testing.assert_allclose(thin.principal_moments(), part(shell, dims, mass=1.0).principal_moments(),
                               rtol=1e-8)


def test_rotations():
    rng = np.random.default_rng(3)
    for _ in range(20):
        v = rng.normal(size=3)
        Q = _rot(v)
        np.testing.assert_allclose(Q.T @ Q, np.eye(3), atol=1e-15)
        np.testing.assert_allclose(Q @ v, v, atol=1e-14)  # the axis is fixed
        a = rng.normal(size=3)
        np.testing.assert_allclose(rotation_from_axis(a)[:, 2], a / np.linalg.norm(a), atol=1e-15)
    np.testing.assert_allclose(_rot([0, 0, math.pi / 2]) @ [1, 0, 0], [0, 1, 0], atol=1e-15)
    for a in ([0, 0, 2.0], [0, 0, -1.0]):  # parallel and antiparallel to the part z axis
        Q = rotation_from_axis(a)
        np.testing.assert_allclose(Q[:, 2], np.sign(a[2]) * np.array([0, 0, 1.0]), atol=0)
        assert np.linalg.det(Q) == pytest.approx(1.0, abs=1e-15)


def test_orientation_moves_the_moments_to_the_body_axes():
    box = {"length": 0.5, "width": 0.3, "height": 0.2}
    moments = part("box", box, mass=3.0).principal_moments()
    quarter = part("box", box, mass=3.0, rotation=[0, 0, math.pi / 2]).inertia()
    np.testing.assert_allclose(quarter, np.diag(moments[[1, 0, 2]]), atol=1e-15)
    along_x = part("cylinder", {"radius": R, "length": L}, mass=1.0, axis=[1, 0, 0]).inertia()
    np.testing.assert_allclose(np.diag(along_x), [R**2 / 2] + [R**2 / 4 + L**2 / 12] * 2, rtol=EXACT)


def test_thesis_dumbbell():
    """Thesis ch. 3: two 10 kg discs (r = 0.10 m, width 0.05 m) with centres d = 0.06 m either side
    of the middle of a massless handle. About the handle's perpendicular bisector the thesis gets
    I_p* = 13/480 for one disc about its own centre, I* = 757/12000 with d, and I = 1514/12000 kg m^2."""
    disc = {"radius": 0.10, "length": 0.05}
    plates = [part_from_dict({"name": f"plate{s}", "shape": "cylinder", **disc, "mass": 10.0,
                              "position": [s * 0.06, 0.0, 0.0], "axis": [1.0, 0.0, 0.0]}) for s in (-1, 1)]
    assert plates[0].principal_moments()[0] == pytest.approx(13 / 480, rel=EXACT)
    one = mass_properties(plates[1:])  # I* needs the axis through the handle's middle, not the disc
    shifted = one.inertia[2, 2] + one.mass * 0.06**2
    assert shifted == pytest.approx(757 / 12000, rel=EXACT)
    both = mass_properties(plates)
    np.testing.assert_allclose(both.com, 0.0, atol=1e-17)
    assert both.inertia[2, 2] == pytest.approx(1514 / 12000, rel=EXACT)
    assert both.inertia[1, 1] == pytest.approx(1514 / 12000, rel=EXACT)  # axisymmetric about the handle
    assert both.inertia[0, 0] == pytest.approx(2 * 10.0 * 0.10**2 / 2, rel=EXACT)


def test_parallel_axis_theorem_reassembles_a_split_box():
    """A tilted box cut into two halves along its length is the same body: the halves' inertias
    moved to the common COM must add up to the whole's."""
    rng = np.random.default_rng(7)
    v, centre = rng.normal(size=3), rng.normal(size=3)
    Q = _rot(v)
    whole = part("box", {"length": 2.0, "width": 0.4, "height": 0.3}, mass=6.0, rotation=list(v),
                 position=list(centre))
    halves = [part("box", {"length": 1.0, "width": 0.4, "height": 0.3}, mass=3.0, rotation=list(v),
                   position=list(centre + s * 0.5 * Q[:, 0])) for s in (-1, 1)]
    props = mass_properties(halves)
    assert props.mass == pytest.approx(6.0, rel=EXACT)
    np.testing.assert_allclose(props.com, centre, rtol=EXACT)
    np.testing.assert_allclose(props.inertia, whole.inertia(), rtol=EXACT, atol=EXACT * 6.0)
    moments, axes = props.principal()
    np.testing.assert_allclose(moments, np.sort(whole.principal_moments()), rtol=EXACT)
    np.testing.assert_allclose(axes @ np.diag(moments) @ axes.T, props.inertia, atol=EXACT * 6.0)
    assert np.linalg.det(axes) == pytest.approx(1.0, abs=1e-14)


# --- MuJoCo's compiler as the independent reference -------------------------------------------

GEOM_TYPE = {"box": mujoco.mjtGeom.mjGEOM_BOX, "beam": mujoco.mjtGeom.mjGEOM_BOX,
             "plate": mujoco.mjtGeom.mjGEOM_BOX, "cylinder": mujoco.mjtGeom.mjGEOM_CYLINDER,
             "sphere": mujoco.mjtGeom.mjGEOM_SPHERE, "spherical_shell": mujoco.mjtGeom.mjGEOM_SPHERE}
SHELL = mujoco.mjtGeomInertia.mjINERTIA_SHELL


def compiled(geoms=(), inertials=()):
    """Mass, COM and inertia tensor about the COM (body frame) that MuJoCo's compiler gives one free
    body made of these geoms (MjSpec geom attributes) and of jointless child bodies with explicit
    inertials (``fusestatic`` merges them into the body)."""
    spec = mujoco.MjSpec()
    spec.compiler.fusestatic = True
    body = spec.worldbody.add_body(name="composite")
    body.add_freejoint()
    for kw in geoms:
        body.add_geom(**kw)
    for kw in inertials:
        # ipos must be set: MjSpec's default (NaN) means "no inertial", and fusestatic drops the body.
        body.add_body(ipos=[0.0, 0.0, 0.0], explicitinertial=True, **kw)
    model = spec.compile()
    assert model.nbody == 2, "fusestatic should leave the world and one body"
    Q = np.empty(9)
    mujoco.mju_quat2Mat(Q, model.body_iquat[1])
    Q = Q.reshape(3, 3)
    return model.body_mass[1], model.body_ipos[1].copy(), Q @ np.diag(model.body_inertia[1]) @ Q.T


def mujoco_mass_properties(parts):
    """The parts as geoms where MuJoCo has the shape (shellinertia for the spherical shell), and as
    explicit inertials where it has not: thick-walled hollow shapes, and the open tube, since
    MuJoCo's cylinder shell has end caps."""
    geoms, inertials = [], []
    for p in parts:
        if p.shape in GEOM_TYPE:
            d = p.dims
            size = ([d["length"] / 2, d["width"] / 2, d["height"] / 2] if "width" in d
                    else [d["radius"], d.get("length", 0.0) / 2, 0.0])
            quat = np.empty(4)
            mujoco.mju_mat2Quat(quat, np.ascontiguousarray(p.rotation).ravel())
            geoms.append({"type": GEOM_TYPE[p.shape], "size": size, "pos": p.position, "quat": quat,
                          "mass": p.mass} | ({"typeinertia": SHELL} if p.shape == "spherical_shell" else {}))
        else:
            I = p.inertia()
            inertials.append({"name": p.name, "pos": p.position, "mass": p.mass,
                              "fullinertia": [I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[0, 2], I[1, 2]]})
    return compiled(geoms, inertials)


def assert_matches_mujoco(parts):
    props = mass_properties(parts)
    mass, com, inertia = mujoco_mass_properties(parts)
    assert mass == pytest.approx(props.mass, rel=MUJOCO)
    np.testing.assert_allclose(com, props.com, rtol=0, atol=MUJOCO * max(1.0, np.abs(props.com).max()))
    np.testing.assert_allclose(inertia, props.inertia, rtol=0, atol=MUJOCO * np.linalg.norm(props.inertia, 2))


@pytest.mark.parametrize("shape", sorted(set(GEOM_TYPE) - {"beam", "plate"}))
def test_primitive_matches_mujoco_geom(shape):
    rng = np.random.default_rng(11)
    p = part(shape, TEXTBOOK[shape][0], mass=4.0, rotation=list(rng.normal(size=3)),
             position=list(rng.normal(size=3)))
    assert_matches_mujoco([p])


@pytest.mark.parametrize("shape", ["hollow_cylinder", "hollow_sphere"])
def test_thick_hollow_shapes_are_mujoco_solids_subtracted(shape):
    """MuJoCo has no thick-walled hollow geom, but the outer solid minus the inner solid at the same
    density is one, in mass and in inertia (both centred at the origin)."""
    rho = 900.0
    kind = mujoco.mjtGeom.mjGEOM_CYLINDER if "cylinder" in shape else mujoco.mjtGeom.mjGEOM_SPHERE
    (m_out, _, i_out), (m_in, _, i_in) = (
        compiled([{"type": kind, "size": [r, L / 2, 0], "density": rho}]) for r in (R, RI))
    p = part(shape, TEXTBOOK[shape][0], density=rho)
    assert p.mass == pytest.approx(m_out - m_in, rel=MUJOCO)
    np.testing.assert_allclose(np.diag(p.principal_moments()), i_out - i_in, rtol=0,
                               atol=MUJOCO * i_out.max())


def test_open_tube_is_mujoco_closed_shell_without_caps():
    """MuJoCo's shell cylinder has end caps; without two discs of the same areal density at its ends
    it is the open cylindrical shell. The discs are MuJoCo cylinders 1e-9 m thick (their thickness
    adds m h^2/12 ~ 1e-19 kg m^2). Both bodies are centred at the origin."""
    sigma, h = 3.0, 1e-9
    cylinder = mujoco.mjtGeom.mjGEOM_CYLINDER
    m_closed, _, i_closed = compiled([{"type": cylinder, "size": [R, L / 2, 0], "density": sigma,
                                       "typeinertia": SHELL}])
    m_caps, _, i_caps = compiled([{"type": cylinder, "size": [R, h / 2, 0], "mass": sigma * math.pi * R**2,
                                   "pos": [0, 0, s * L / 2]} for s in (-1, 1)])
    p = part("cylindrical_shell", {"radius": R, "length": L}, density=sigma)
    assert p.mass == pytest.approx(m_closed - m_caps, rel=MUJOCO)
    np.testing.assert_allclose(np.diag(p.principal_moments()), i_closed - i_caps, rtol=0,
                               atol=MUJOCO * i_closed.max())


def test_all_shapes_composed_match_mujoco():
    rng = np.random.default_rng(5)
    parts = [part_from_dict({"name": f"{shape}{i}", "shape": shape, **TEXTBOOK[shape][0],
                             "mass": float(rng.uniform(0.5, 5.0)), "rotation": list(rng.normal(size=3)),
                             "position": list(rng.normal(size=3))})
             for i, shape in enumerate(sorted(TEXTBOOK))]
    assert_matches_mujoco(parts)


def test_solar_boat_matches_mujoco():
    assert_matches_mujoco(load_parts(BOAT))


# --- The Solar Boat parts file -------------------------------------------------------------------

def test_solar_boat_reproduces_thesis():
    """Thesis ch. 8.1: I1 = 317.278 (yaw, body z), I2 = 317.154 (pitch, y), I3 = 83.143 kg m^2
    (roll, x); COM 0.205 m below the solar deck (z = 0); pilot nearly 44 % of the mass."""
    parts = load_parts(BOAT)
    props = mass_properties(parts)
    assert [p.name for p in parts] == ["hull", "deck", "battery", "electronics", "cockpit",
                                       "front_wing", "rear_wing", "pilot"]
    moments, axes = props.principal()
    np.testing.assert_allclose(np.abs(axes), np.eye(3), atol=1e-3)  # roll x, pitch y, yaw z
    np.testing.assert_allclose(moments, [83.143, 317.154, 317.278], rtol=5e-3)
    assert props.com[2] == pytest.approx(-0.205, abs=0.01)
    assert abs(props.com[0]) < 0.01 and props.com[1] == 0.0  # under the deck's middle
    pilot = next(p for p in parts if p.name == "pilot")
    assert pilot.mass / props.mass == pytest.approx(0.44, abs=0.02)


def test_solar_boat_hangs_as_a_rig():
    """The composite as a rig body, from wires at the deck's two ends (configuration 1, ch. 8.2)."""
    parts = load_parts(BOAT)
    props = mass_properties(parts)
    body = rig_body(props)
    half = next(p for p in parts if p.name == "deck").dims["length"] / 2
    rig = rig_from_dict({"body": body, "wire": [
        {"anchor": [s * half, 0.0, 3.0], "attach": [s * half, 0.0, 0.0], "length": 3.0} for s in (-1, 1)]})
    assert rig.mass == pytest.approx(178.6, rel=EXACT)
    np.testing.assert_allclose(rig.com, props.com, rtol=0, atol=0)
    np.testing.assert_allclose(rig.inertia, props.inertia, rtol=0, atol=0)


# --- Loader errors --------------------------------------------------------------------------------

GOOD = {"name": "p", "shape": "hollow_sphere", "radius": 0.3, "inner_radius": 0.2, "mass": 1.0}


@pytest.mark.parametrize(("change", "field", "problem"), [
    ({"shape": "cone"}, "part[1].shape", "unknown shape 'cone'"),
    ({"radius": None}, "part[1].radius", "missing"),
    ({"radius": -0.3}, "part[1].radius", "must be positive"),
    ({"inner_radius": 0.3}, "part[1].inner_radius", "must be less than radius"),
    ({"density": 5.0}, "part[1].mass", "exactly one of mass and density"),
    ({"mass": None}, "part[1].mass", "exactly one of mass and density"),
    ({"axis": [0, 0, 0]}, "part[1].axis", "must not be zero"),
    ({"axis": [1, 0, 0], "rotation": [0, 0, 1]}, "part[1].axis", "at most one of rotation and axis"),
    ({"position": [0, 0]}, "part[1].position", "three numbers"),
    ({"length": 1.0}, "part[1].length", "unknown key"),
    ({"name": ""}, "part[1].name", "non-empty string"),
])
def test_loader_errors_name_field_and_problem(tmp_path, change, field, problem):
    table = {k: v for k, v in (GOOD | change).items() if v is not None}
    path = tmp_path / "parts.toml"
    path.write_text("[[part]]\n" + "\n".join(f"{k} = {_toml(v)}" for k, v in table.items()) + "\n")
    with pytest.raises(RigError) as err:
        load_parts(path)
    assert (err.value.source, err.value.field) == (str(path), field)
    assert problem in err.value.problem and "\n" not in str(err.value)


@pytest.mark.parametrize(("text", "field", "problem"), [
    ("", "part", "missing"),
    ("title = 'x'\n", "title", "unknown key"),
    ("[[part]\n", "toml", "not valid TOML"),
    ("[[part]]\nname='a'\nshape='sphere'\nradius=1\nmass=1\n" * 2, "part[2].name", "duplicate name 'a'"),
])
def test_loader_file_errors(tmp_path, text, field, problem):
    path = tmp_path / "parts.toml"
    path.write_text(text)
    with pytest.raises(RigError) as err:
        load_parts(path)
    assert err.value.field == field and problem in err.value.problem


def test_loader_missing_file(tmp_path):
    with pytest.raises(RigError, match="file: cannot read"):
        load_parts(tmp_path / "none.toml")


def _toml(v):
    return repr(v) if not isinstance(v, str) else f'"{v}"'


def _rot(rotvec):
    return Rotation.from_rotvec(rotvec).as_matrix()
