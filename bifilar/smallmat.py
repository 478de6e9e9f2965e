"""Products and solves of small dense matrices inside numba-compiled kernels.

numba hands ``@`` and ``np.linalg.solve`` to BLAS/LAPACK, whose call overhead (~1 us) dwarfs the
arithmetic of a 3x5 or 5x5 problem; plain loops compile to a few nanoseconds. Likewise numba's
``np.cross`` is generic (any shapes, broadcast along an axis) and costs more to compile than the three
products it computes for two 3-vectors: :func:`cross` writes them out, with the same arithmetic.
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
