"""Small fixed-size algebra for the compiled kernel, on tuples (values kept in registers).

A 3-vector is a 3-tuple, a 3x3 matrix a row-major 9-tuple.  Loading an array row into a
tuple once, computing on tuples and storing the result keeps the compiler from re-reading
memory that a store might have changed (numba cannot tell that the arrays do not overlap).
"""
from __future__ import annotations

from numba import njit

# fused multiply-adds allowed ("contract": one rounding instead of two, ~5% faster); no other
# fast-math flag: NaN must reach the sign search (a sample without a consistent pattern)
OPTS = dict(cache=True, nogil=True, fastmath={"contract"}, error_model="numpy", _nrt=False)
# helpers are inlined into their caller at numba's IR level: a call passes every array
# as a struct of ~9 words on the stack, more than the work of most helpers
INLINE = dict(OPTS, inline="always")


@njit(**OPTS)
def load3(A, i):
    """Row i of an (n, 3) array."""
    return A[i, 0], A[i, 1], A[i, 2]


@njit(**OPTS)
def store3(A, i, v):
    A[i, 0], A[i, 1], A[i, 2] = v[0], v[1], v[2]


@njit(**OPTS)
def load9(A, i):
    """Matrix i of an (n, 3, 3) array."""
    return (A[i, 0, 0], A[i, 0, 1], A[i, 0, 2], A[i, 1, 0], A[i, 1, 1], A[i, 1, 2],
            A[i, 2, 0], A[i, 2, 1], A[i, 2, 2])


@njit(**OPTS)
def store9(A, i, m):
    A[i, 0, 0], A[i, 0, 1], A[i, 0, 2] = m[0], m[1], m[2]
    A[i, 1, 0], A[i, 1, 1], A[i, 1, 2] = m[3], m[4], m[5]
    A[i, 2, 0], A[i, 2, 1], A[i, 2, 2] = m[6], m[7], m[8]


@njit(**OPTS)
def row9(F, k, c):
    """F[k, c:c+9] as a matrix."""
    return (F[k, c], F[k, c + 1], F[k, c + 2], F[k, c + 3], F[k, c + 4], F[k, c + 5],
            F[k, c + 6], F[k, c + 7], F[k, c + 8])


@njit(**OPTS)
def row3(F, k, c):
    """F[k, c:c+3] as a vector."""
    return F[k, c], F[k, c + 1], F[k, c + 2]


@njit(**OPTS)
def mm(a, b):
    """a b."""
    return (a[0] * b[0] + a[1] * b[3] + a[2] * b[6], a[0] * b[1] + a[1] * b[4] + a[2] * b[7],
            a[0] * b[2] + a[1] * b[5] + a[2] * b[8],
            a[3] * b[0] + a[4] * b[3] + a[5] * b[6], a[3] * b[1] + a[4] * b[4] + a[5] * b[7],
            a[3] * b[2] + a[4] * b[5] + a[5] * b[8],
            a[6] * b[0] + a[7] * b[3] + a[8] * b[6], a[6] * b[1] + a[7] * b[4] + a[8] * b[7],
            a[6] * b[2] + a[7] * b[5] + a[8] * b[8])


@njit(**OPTS)
def mv(a, v):
    """a v."""
    return (a[0] * v[0] + a[1] * v[1] + a[2] * v[2], a[3] * v[0] + a[4] * v[1] + a[5] * v[2],
            a[6] * v[0] + a[7] * v[1] + a[8] * v[2])


@njit(**OPTS)
def mtv(a, v):
    """a^T v."""
    return (a[0] * v[0] + a[3] * v[1] + a[6] * v[2], a[1] * v[0] + a[4] * v[1] + a[7] * v[2],
            a[2] * v[0] + a[5] * v[1] + a[8] * v[2])


@njit(**OPTS)
def cx(a, b):
    """a x b."""
    return a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]


@njit(**OPTS)
def add(a, b):
    return a[0] + b[0], a[1] + b[1], a[2] + b[2]


@njit(**OPTS)
def sub(a, b):
    return a[0] - b[0], a[1] - b[1], a[2] - b[2]


@njit(**OPTS)
def scale(a, s):
    return a[0] * s, a[1] * s, a[2] * s
