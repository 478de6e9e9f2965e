"""The rest pose of any rig of 3-8 wires is the lowest one (issue 20, item 5), checked by an independent
search on random rigs built around a known taut equilibrium in a randomly turned body frame.

Construction: a body of mass m with its COM at the origin and a random rotation (body -> world); random
attachments; wire forces f_i = t_i u_i that balance the weight and have no moment about the COM (the
minimum-norm correction of random, mostly upward forces onto the six balance equations); anchors
a_i = p_i + L_i u_i. Inextensible rigs (3-6 wires; more are always indeterminate) are checked against
SLSQP from many random orientations on the physical problem, min z_COM with every wire at most its
length (a wire may go slack); elastic rigs (3-8 wires, L_i shortened by t_i / k_i so the pose is an
equilibrium) against BFGS on the potential energy from many starts. Either the independent lowest pose
has every wire taut and ours is it (not refused, never higher); or it slackens a wire and ours is
refused naming a wire or is a higher stable taut equilibrium. Never a traceback, never another field.
"""

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from scipy.optimize import minimize
from scipy.spatial.transform import Rotation

from bifilar.rig import RigError, rig_from_dict
from bifilar.rig.file import check_hanging
from bifilar.rig.statics import rest_pose

STARTS = 24  # independent search starts; the lowest of them is the reference


def build(seed: int, n: int, elastic: bool):
    """A rig dict (see the module docstring) or None if the draw is degenerate."""
    rng = np.random.default_rng(seed)
    mass, g = float(rng.uniform(1.0, 20.0)), 9.81
    weight = mass * g
    turn = Rotation.random(random_state=rng).as_matrix()
    com_body = rng.uniform(-0.2, 0.2, 3)
    angles = np.sort(rng.uniform(0, 2 * np.pi, n))
    radii = rng.uniform(0.2, 0.6, n)
    arms = np.column_stack([radii * np.cos(angles), radii * np.sin(angles), rng.uniform(0.0, 0.15, n)])
    attach_body = com_body + arms
    s = arms @ turn.T  # world arms from the COM at the origin
    f0 = np.column_stack([rng.normal(0, 0.25, (n, 2)), np.ones(n)]) * rng.uniform(0.5, 1.5, n)[:, None] * weight / n
    A = np.zeros((6, 3 * n))
    for i in range(n):
        A[:3, 3 * i:3 * i + 3] = np.eye(3)
        A[3:, 3 * i:3 * i + 3] = _skew(s[i])
    b = np.array([0, 0, weight, 0, 0, 0.0])
    f = (f0.ravel() + np.linalg.pinv(A) @ (b - A @ f0.ravel())).reshape(n, 3)
    t = np.linalg.norm(f, axis=1)
    if t.min() < 0.05 * weight / n or np.min(f[:, 2] / t) < 0.5:  # a wire nearly slack or nearly level
        return None
    u = f / t[:, None]
    lengths = rng.uniform(0.8, 2.0, n)
    anchors = s + lengths[:, None] * u
    wires = []
    for i in range(n):
        wire = {"anchor": anchors[i].tolist(), "attach": attach_body[i].tolist(), "length": float(lengths[i])}
        if elastic:
            ea = float(rng.uniform(1e3, 1e5))
            # unstretched L0 with (EA / L0) (d - L0) = t: L0 = d EA / (EA + t)
            wire["length"] = float(lengths[i] * ea / (ea + t[i]))
            wire["axial_stiffness"] = ea
        wires.append(wire)
    inertia = np.diag(mass * rng.uniform(0.02, 0.1, 3))
    inertia[2, 2] = inertia[0, 0] + inertia[1, 1] - 1e-3 * mass * 0.02
    return {"body": {"mass": mass, "com": com_body.tolist(), "inertia": np.diag(inertia).tolist()}, "wire": wires}


def _pose(x, r0=np.eye(3)):
    return x[:3], Rotation.from_rotvec(x[3:]).as_matrix() @ r0


def _skew(v):
    """[v]x, the matrix of the cross product v x ."""
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def _left_jacobian(v):
    """SO(3)'s left Jacobian at the rotation vector ``v``: exp([v + dv]x) = exp([J dv]x) exp([v]x) to first
    order, so a turned vector R q moves by -[R q]x J dv."""
    theta = np.linalg.norm(v)
    k = _skew(v)
    if theta < 1e-6:  # the series, to theta^2
        return np.eye(3) + 0.5 * k + k @ k / 6.0
    return np.eye(3) + (1.0 - np.cos(theta)) / theta**2 * k + (theta - np.sin(theta)) / theta**3 * k @ k


def _wires(data):
    """Each wire's anchor-to-attachment distance (m) and its derivatives in x = (COM, rotation vector),
    the rotation exp([v]x) r0 (body -> world), as a function of x and r0: (distances, n x 6 Jacobian).
    The searches call it tens of thousands of times; analytic derivatives (central differences agree to
    1e-8: the test below) spare the searches' finite differences, ~2.5x their time."""
    anchors = np.array([w["anchor"] for w in data["wire"]])
    arms = np.array([w["attach"] for w in data["wire"]]) - np.array(data["body"]["com"])

    def wires(x, r0):
        com, rot = _pose(x, r0)
        turned = arms @ rot.T
        gap = anchors - com - turned
        d = np.linalg.norm(gap, axis=1)
        e = gap / d[:, None]  # from the attachment towards the anchor
        # d d_i / d com = -e_i; d d_i / d v = -e_i . (d p_i / d v) = e_i . [R q_i]x J = (e_i x R q_i) . J
        return d, np.hstack([-e, np.cross(e, turned) @ _left_jacobian(x[3:])])

    return wires


def independent_lowest_rigid(data, rng):
    """Lowest COM height (m) over SLSQP runs with |a_i - p_i| <= L_i, and whether every wire is taut
    there (distance within 1e-7 m of its length)."""
    lengths = np.array([w["length"] for w in data["wire"]])
    anchors = np.array([w["anchor"] for w in data["wire"]])
    wires = _wires(data)
    height = np.array([0.0, 0.0, 1.0, 0.0, 0.0, 0.0])
    best = None
    for k in range(STARTS):
        r0 = Rotation.random(random_state=rng).as_matrix()
        c0 = anchors.mean(axis=0) - [0, 0, lengths.mean() + 0.5]
        res = minimize(lambda x: x[2], np.concatenate([c0, np.zeros(3)]), jac=lambda x: height, method="SLSQP",
                       constraints=[{"type": "ineq", "fun": lambda x: lengths - wires(x, r0)[0],
                                     "jac": lambda x: -wires(x, r0)[1]}],
                       options={"ftol": 1e-14, "maxiter": 500})
        d = wires(res.x, r0)[0]
        if np.max(d - lengths) > 1e-8:
            continue
        if best is None or res.x[2] < best[0]:
            best = (res.x[2], bool(np.all(lengths - d < 1e-7)))
    return best


def independent_lowest_elastic(data, rng):
    """Lowest potential energy (J) over BFGS runs from random orientations (with its gradient)."""
    lengths = np.array([w["length"] for w in data["wire"]])
    k = np.array([w["axial_stiffness"] for w in data["wire"]]) / lengths
    anchors = np.array([w["anchor"] for w in data["wire"]])
    weight = data["body"]["mass"] * 9.81
    wires = _wires(data)

    def energy(x, r0):
        d, jac = wires(x, r0)
        stretch = np.maximum(d - lengths, 0.0)
        return weight * x[2] + 0.5 * k @ stretch**2, weight * np.eye(6)[2] + (k * stretch) @ jac

    best, slack = np.inf, False
    for _ in range(STARTS):
        r0 = Rotation.random(random_state=rng).as_matrix()
        c0 = anchors.mean(axis=0) - [0, 0, lengths.mean()]
        res = minimize(energy, np.concatenate([c0, np.zeros(3)]), args=(r0,), jac=True, method="BFGS",
                       options={"gtol": 1e-10})
        if res.fun < best:
            best, slack = res.fun, bool(np.any(wires(res.x, r0)[0] <= lengths))
    return best, slack, lambda x, r0: energy(x, r0)[0]


def test_the_reference_searches_derivatives_are_the_distances():
    # central differences (h 1e-6: truncation ~h^2 x curvature ~1e-12, rounding ~1e-16 / h ~1e-10 m)
    data = build(371995, 5, elastic=True)
    wires = _wires(data)
    rng = np.random.default_rng(0)
    for _ in range(5):
        r0 = Rotation.random(random_state=rng).as_matrix()
        x = np.concatenate([rng.normal(0.0, 0.3, 3), rng.normal(0.0, 1.0, 3)])
        h = 1e-6
        numeric = np.column_stack([(wires(x + h * e, r0)[0] - wires(x - h * e, r0)[0]) / (2.0 * h) for e in np.eye(6)])
        assert np.max(np.abs(wires(x, r0)[1] - numeric)) < 1e-8


# the ci profile draws the same rigs on every run (tests/conftest.py); a draw that finds a defect
# becomes an @example or a test of its own below (seed 837's six-wire rig)
@pytest.mark.slow
@settings(max_examples=20)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(3, 6))
@example(seed=101471, n=3)  # a trifilar whose two first starts stopped 17 mm above its lowest taut pose
def test_rigid_rest_pose_is_the_lowest(seed, n):
    data = build(seed, n, elastic=False)
    if data is None:
        return
    rng = np.random.default_rng(seed + 1)
    reference = independent_lowest_rigid(data, rng)
    try:
        rig = rig_from_dict(data, source="fuzz.toml")
        rest = rest_pose(rig)
        check_hanging(rig, rest)
    except RigError as exc:
        # Refused: only if the lowest pose leaves a wire slack (then a wire is blamed), never a field
        # that is fine.
        assert exc.field.startswith("wire"), str(exc)
        assert reference is not None and not reference[1], f"refused a rig whose lowest pose is taut: {exc}"
        return
    assert rest.tensions.min() > 0.0
    if reference is not None and reference[1]:
        # The lowest pose is taut: ours is it, never higher (1e-7 m: SLSQP's feasibility tolerance).
        assert rest.com[2] <= reference[0] + 1e-7
    # Else the lowest pose slackens a wire and ours is a higher, stable taut equilibrium (a local
    # minimum of the potential: the body can hang there), which rest_pose checked.


@pytest.mark.slow
@settings(max_examples=10)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(3, 8))
@example(seed=371995, n=5)  # the two first starts ended slack, a taut minimum lies lower (was refused)
@example(seed=109851, n=5)  # the lowest minimum is slack, a taut one 0.5 J above it
def test_elastic_rest_pose_is_the_lowest(seed, n):
    data = build(seed, n, elastic=True)
    if data is None:
        return
    rig = rig_from_dict(data, source="fuzz.toml")
    best, slack, energy = independent_lowest_elastic(data, np.random.default_rng(seed + 1))
    try:
        rest = rest_pose(rig)
    except RigError as exc:
        # Refused only where the lowest minimum leaves a wire slack, and then a wire is named.
        assert exc.field.startswith("wire[") and slack, str(exc)
        return
    assert rest.tensions.min() > 0.0
    ours = energy(np.concatenate([rest.com, np.zeros(3)]), rest.rotation)
    if not slack:
        # BFGS stops at gtol 1e-10 on an energy whose curvature is <= sum k ~ 1e5 N/m: its energy is high
        # by at most ~1e-15 J; ours must be no higher than the independent lowest, to 1e-9 of m g x 1 m.
        assert ours <= best + 1e-9 * data["body"]["mass"] * 9.81
    # Else the lowest minimum slackens a wire and ours is a higher, stable taut one (as for rigid wires).
    assert ours >= best - 1e-9 * data["body"]["mass"] * 9.81  # never below the lowest: a true minimum


@pytest.mark.slow
def test_six_wire_rig_837_hangs_at_its_lowest_taut_pose():
    data = build(837, 6, elastic=False)
    reference = independent_lowest_rigid(data, np.random.default_rng(838))
    assert reference is not None and reference[1]  # the lowest pose is taut
    rest = rest_pose(rig_from_dict(data, source="fuzz.toml"))
    assert rest.com[2] <= reference[0] + 1e-7


def test_a_start_that_diverges_is_dropped_before_lapack_sees_it(capfd):
    """A random five-wire rig (seed 7) on which SLSQP diverges from some starts: its NaN pose went on to
    a least squares whose LAPACK printed 'On entry to DLASCL parameter number 4 had an illegal value'
    on the process's standard output (six times: into a --json document), then failed. The start is
    dropped where SLSQP ends; the rig hangs as before (z of its COM the same as the other starts')."""
    rest = rest_pose(rig_from_dict(build(7, 5, elastic=False), source="fuzz.toml"))
    out, err = capfd.readouterr()
    assert "DLASCL" not in out + err and rest.tensions.min() > 0.0


def test_a_trifilar_rests_at_its_lowest_taut_pose():
    """The quick tier's case of the rigid property (one rig, not twenty): the trifilar whose two first
    starts stopped 17 mm above its lowest taut pose."""
    test_rigid_rest_pose_is_the_lowest.hypothesis.inner_test(seed=101471, n=3)
