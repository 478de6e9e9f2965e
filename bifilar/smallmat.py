"""Products and solves of small dense matrices inside numba-compiled kernels, and copies into parts of
arrays (:func:`put` and its kin, for compile time: see the note above them).

numba hands ``@`` and ``np.linalg.solve`` to BLAS/LAPACK, whose call overhead (~1 us) dwarfs the
arithmetic of a 3x5 or 5x5 problem; plain loops compile to a few nanoseconds. Likewise numba's
``np.cross`` is generic (any shapes, broadcast along an axis) and costs more to compile than the three
products it computes for two 3-vectors: :func:`cross` writes them out, with the same arithmetic.

:func:`inverse` is there for compile time: numba's ``np.linalg.inv`` and its ``solve`` with a matrix
right-hand side each compile their own LAPACK wrapper into the kernel that calls them. In
``slopes_kernel.period_slopes`` the loop version cut that kernel's compile from 5.8 to 4.5 CPU s
(``benchmarks/compile_cpu.py``); where a kernel keeps other LAPACK calls (SVD, least squares,
eigen-solves: rank handling LAPACK does and these loops do not) the process's LAPACK set-up is paid
anyway, and swapping a lone ``solve`` or ``@`` for loops measured no gain.
"""

import numpy as np
from numba import njit


@njit(cache=True)
def cross(a, b):
    """a x b of two 3-vectors, written out (the same products and order as ``np.cross``)."""
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


@njit(cache=True)
def mv(A, x):
    """A @ x with loops: numba sends small `@` to BLAS, whose call overhead dominates at this size."""
    out = np.zeros(A.shape[0])
    for i in range(A.shape[0]):
        for j in range(A.shape[1]):
            out[i] += A[i, j] * x[j]
    return out


@njit(cache=True)
def mm(A, B):
    """A @ B with loops (see :func:`mv`)."""
    out = np.zeros((A.shape[0], B.shape[1]))
    for i in range(A.shape[0]):
        for k in range(A.shape[1]):
            a = A[i, k]
            for j in range(B.shape[1]):
                out[i, j] += a * B[k, j]
    return out


@njit(cache=True)
def solve(A, b):
    """Solve A x = b by Gaussian elimination with partial pivoting (A, b are copied)."""
    n = b.shape[0]
    M = A.copy()
    x = b.copy()
    for k in range(n):
        piv = k
        for i in range(k + 1, n):
            if abs(M[i, k]) > abs(M[piv, k]):
                piv = i
        if piv != k:
            for j in range(n):
                M[k, j], M[piv, j] = M[piv, j], M[k, j]
            x[k], x[piv] = x[piv], x[k]
        for i in range(k + 1, n):
            f = M[i, k] / M[k, k]
            for j in range(k, n):
                M[i, j] -= f * M[k, j]
            x[i] -= f * x[k]
    for i in range(n - 1, -1, -1):
        acc = x[i]
        for j in range(i + 1, n):
            acc -= M[i, j] * x[j]
        x[i] = acc / M[i, i]
    return x


@njit(cache=True)
def inverse(A):
    """A^-1 by Gauss-Jordan elimination with partial pivoting, failing as numba's ``np.linalg.inv``
    does (LAPACK getrf/getri): LinAlgError on an input not finite or an exactly zero pivot."""
    n = A.shape[0]
    M = A.copy()
    X = np.eye(n)
    for k in range(n):
        for j in range(n):
            if not np.isfinite(M[k, j]):
                raise np.linalg.LinAlgError("Array must not contain infs or NaNs.")
    for k in range(n):
        piv = k
        for i in range(k + 1, n):
            if abs(M[i, k]) > abs(M[piv, k]):
                piv = i
        if M[piv, k] == 0.0:
            raise np.linalg.LinAlgError("Matrix is singular to machine precision.")
        if piv != k:
            for j in range(n):
                M[k, j], M[piv, j] = M[piv, j], M[k, j]
                X[k, j], X[piv, j] = X[piv, j], X[k, j]
        d = 1.0 / M[k, k]
        for j in range(n):
            M[k, j] *= d
            X[k, j] *= d
        for i in range(n):
            f = M[i, k]
            if i == k or f == 0.0:
                continue
            for j in range(n):
                M[i, j] -= f * M[k, j]
                X[i, j] -= f * X[k, j]
    return X


# Copies into part of an array. numba compiles an array assigned into a slice (``out[:3] = x``,
# ``m[3:, 3:] = R``, ``b[:3] += v``, ``rows[i] = vec``) through its generic ``fancy_setslice``, with a
# shape-mismatch error message built by an f-string: ~2 CPU s the first time in a process and ~0.2 s
# more per later kernel (6 such assignments compiled in 3.3-3.5 s, against 1.4-1.6 s through these
# loops). The first-time part is saved only where no kernel of a process does it, so the kernels copy
# with these instead (a row of a 2-D or 3-D array is passed as its view, ``put(rows[i], 0, x)``): the
# project's groups compiled in 53.9 CPU s against 59.5 in one process, each of two shares in 27-28 s
# against 33-34 (``benchmarks/compile_cpu.py``, run back to back). numba's own ``np.linalg.solve`` and
# ``lstsq`` with a 1-D right-hand side still copy into a slice inside. A copy by loop gives the same
# numbers, and ``out[k] = out[k] + x[k]`` is the same rounding as ``+=`` on a slice.


@njit(cache=True)
def put(out, i, x):
    """out[i:i + len(x)] = x, as a loop (see the note above)."""
    for k in range(x.shape[0]):
        out[i + k] = x[k]


@njit(cache=True)
def add(out, i, x):
    """out[i:i + len(x)] += x, as a loop (see the note above)."""
    for k in range(x.shape[0]):
        out[i + k] = out[i + k] + x[k]


@njit(cache=True)
def put2(out, i, j, x):
    """out[i:i + rows, j:j + columns] = x (x 2-D), as a loop (see the note above)."""
    for r in range(x.shape[0]):
        for c in range(x.shape[1]):
            out[i + r, j + c] = x[r, c]


@njit(cache=True)
def add2(out, i, j, x):
    """out[i:i + rows, j:j + columns] += x (x 2-D), as a loop (see the note above)."""
    for r in range(x.shape[0]):
        for c in range(x.shape[1]):
            out[i + r, j + c] = out[i + r, j + c] + x[r, c]


@njit(cache=True)
def put_col(out, i, j, x):
    """out[i:i + len(x), j] = x: x into column j from row i, as a loop (see the note above)."""
    for k in range(x.shape[0]):
        out[i + k, j] = x[k]


@njit(cache=True)
def add_col(out, i, j, x):
    """out[i:i + len(x), j] += x, as a loop (see the note above)."""
    for k in range(x.shape[0]):
        out[i + k, j] = out[i + k, j] + x[k]
