"""bifilar.smallmat's loop products and factorisations agree with numpy's and fail where numba's
LAPACK wrappers do (the kernels switched to them to cut compile time, not to change results)."""

import numpy as np
import pytest

from bifilar import smallmat


@pytest.mark.parametrize("n", [1, 3, 6, 10])
def test_inverse_and_cholesky_match_numpy(n):
    rng = np.random.default_rng(n)
    a = rng.standard_normal((n, n))
    spd = a @ a.T + n * np.eye(n)
    assert np.allclose(smallmat.inverse(a), np.linalg.inv(a), rtol=1e-10, atol=1e-12)
    assert np.allclose(smallmat.cholesky(spd), np.linalg.cholesky(spd), rtol=1e-12, atol=1e-14)
    assert smallmat.dot(a[0], a[-1]) == pytest.approx(a[0] @ a[-1], rel=1e-14, abs=1e-14)


def test_they_raise_where_lapack_does():
    with pytest.raises(np.linalg.LinAlgError):
        smallmat.inverse(np.array([[1.0, 2.0], [2.0, 4.0]]))
    with pytest.raises(np.linalg.LinAlgError):
        smallmat.inverse(np.array([[1.0, np.nan], [0.0, 1.0]]))
    with pytest.raises(np.linalg.LinAlgError):
        smallmat.cholesky(np.array([[1.0, 2.0], [2.0, 1.0]]))
