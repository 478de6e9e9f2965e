"""bifilar.smallmat.inverse agrees with numpy's and fails where numba's LAPACK wrapper does (the slopes
kernel switched to it to cut compile time, not to change results)."""

import numpy as np
import pytest

from bifilar import smallmat


@pytest.mark.parametrize("n", [1, 3, 6, 10])
def test_inverse_matches_numpy(n):
    rng = np.random.default_rng(n)
    a = rng.standard_normal((n, n))
    assert np.allclose(smallmat.inverse(a), np.linalg.inv(a), rtol=1e-10, atol=1e-12)


def test_it_raises_where_lapack_does():
    with pytest.raises(np.linalg.LinAlgError):
        smallmat.inverse(np.array([[1.0, 2.0], [2.0, 4.0]]))
    with pytest.raises(np.linalg.LinAlgError):
        smallmat.inverse(np.array([[1.0, np.nan], [0.0, 1.0]]))
