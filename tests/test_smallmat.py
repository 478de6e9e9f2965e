"""bifilar.smallmat.inverse agrees with numpy's and fails where numba's LAPACK wrapper does (the slopes
kernel switched to it to cut compile time, not to change results); its loop copies into part of an
array (put, add, put2, add2, put_col, add_col) give exactly numpy's slice assignments."""

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


def _data(*shape, seed=0):
    return np.random.default_rng(seed).standard_normal(shape)


def test_put_and_add_match_slicing():
    out, x = _data(8), _data(10, seed=1)[::2][:3]  # a strided source, as ``y[5:]`` or a column
    want = out.copy()
    want[4:7] = x
    got = out.copy()
    smallmat.put(got, 4, x)
    assert np.array_equal(got, want)
    want[1:4] += x
    smallmat.add(got, 1, x)
    assert np.array_equal(got, want)


def test_put_into_a_row_view():
    rows, x = _data(4, 6), _data(3, seed=1)
    want = rows.copy()
    want[2, 3:] = x
    smallmat.put(rows[2], 3, x)
    assert np.array_equal(rows, want)


def test_put2_and_add2_match_slicing():
    out, x = _data(6, 6), _data(3, 3, seed=1)
    want = out.copy()
    want[3:, 2:5] = x
    got = out.copy()
    smallmat.put2(got, 3, 2, x)
    assert np.array_equal(got, want)
    want[:3, :3] += x
    smallmat.add2(got, 0, 0, x)
    assert np.array_equal(got, want)


def test_put2_into_a_matrix_of_a_stack():
    frames, x = _data(5, 3, 3), _data(3, 3, seed=1)
    want = frames.copy()
    want[1] = x
    smallmat.put2(frames[1], 0, 0, x)
    assert np.array_equal(frames, want)


def test_put_col_and_add_col_match_slicing():
    out, x = _data(6, 4), _data(3, seed=1)
    want = out.copy()
    want[3:, 2] = x
    got = out.copy()
    smallmat.put_col(got, 3, 2, x)
    assert np.array_equal(got, want)
    want[:3, 1] += x
    smallmat.add_col(got, 0, 1, x)
    assert np.array_equal(got, want)
