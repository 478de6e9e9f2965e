"""Normal modes from the exact linearisation against closed forms and the nonlinear model."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from bifilar.motion.kane import KaneModel
from bifilar.motion.modes import excite, linearize
from bifilar.motion.simulate import simulate
from validate.assets import rig
from validate.metrics import period


def test_parallel_torsion_matches_5_2_17():
    """Parallel wires: omega^2 = m g D^2 / (4 h I) exactly in the linear limit (thesis 5.2.15)."""
    r = rig("parallel")
    lin = linearize(r)
    torsion = [m for m in lin.modes if abs(m.rotation[2]) > 0.99]
    assert len(torsion) == 1
    closed = 2 * np.pi * np.sqrt(4 * 1.5 * r.inertia[2, 2] / (r.mass * r.gravity * 0.4**2))
    assert torsion[0].period == pytest.approx(closed, rel=1e-12)  # closed-form stiffness: rounding only
    # The swing along the wires' plane is a pendulum of the wire length: 2 pi sqrt(h / g).
    assert any(m.period == pytest.approx(2 * np.pi * np.sqrt(1.5 / 9.81), rel=1e-10) for m in lin.modes)


def test_mass_and_stiffness_are_symmetric_positive_definite():
    lin = linearize(rig("asymmetric"))
    np.testing.assert_allclose(lin.mass, lin.mass.T, rtol=1e-12)
    assert np.all(np.linalg.eigvalsh(lin.mass) > 0) and np.all(np.linalg.eigvalsh(lin.stiffness) > 0)


def test_each_mode_oscillates_at_its_period_in_the_nonlinear_model():
    model = KaneModel.from_rig(rig("asymmetric"))
    lin = linearize(model.rig)
    for i, mode in enumerate(lin.modes):
        run = simulate(model, excite(lin, i, 1e-4), 6 * mode.period, dt_out=mode.period / 100)
        motion = np.column_stack([run.com - run.com[0], Rotation.from_matrix(run.rotation).as_rotvec()])
        measured = period(run.t, motion[:, np.argmax(motion.std(axis=0))])
        # Amplitude 1e-4 rad shifts the period by ~1e-8; integration at rtol 1e-10.
        assert measured.value == pytest.approx(mode.period, rel=5e-8)
