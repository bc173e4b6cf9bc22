"""Compiled world-frame block solve (blocks without a constant frame), one sample.

The block's balances (Eqs. 15-16, 19-20) in base axes about each link's origin, assembled
from the column terms of :mod:`.kernel_terms` for a sign pattern of its t and solved by
Gaussian elimination with partial pivoting (like :func:`~.general.solve_general`, which
calls LAPACK): a singular matrix gives NaN, which no sign pattern accepts.  The solve is
not inlined into the kernel (it is rare and costs far more than a call).
"""
from __future__ import annotations

import numpy as np
from numba import njit

from .kernel_links import INLINE, OPTS, cross, rot


@njit(**INLINE)
def term_wrench(k, L, trec, tflt, sig, R, o):
    """Wrench (6-tuple, base axes, about o_L) of term k per unit of its unknown."""
    X = trec[k, 4]
    coef = tflt[k, 0]
    if trec[k, 5] >= 0:
        coef *= sig[trec[k, 5]]
    d = rot(R, X, tflt[k, 1], tflt[k, 2], tflt[k, 3])
    if trec[k, 3] == 1:
        return 0.0, 0.0, 0.0, coef * d[0], coef * d[1], coef * d[2]
    P = rot(R, X, tflt[k, 4], tflt[k, 5], tflt[k, 6])
    e = cross(o[X, 0] + P[0] - o[L, 0], o[X, 1] + P[1] - o[L, 1], o[X, 2] + P[2] - o[L, 2], d[0], d[1], d[2])
    return coef * d[0], coef * d[1], coef * d[2], coef * e[0], coef * e[1], coef * e[2]


@njit(**OPTS)
def _assemble(k0, nt, trec, tflt, sig, R, o, nr, n, A):
    """A[:nr, :n] = the block matrix for the signs ``sig``."""
    for i in range(nr):
        for j in range(n):
            A[i, j] = 0.0
    for k in range(k0, k0 + nt):
        row = trec[k, 1]
        if row < 0:
            continue
        w = term_wrench(k, trec[k, 0], trec, tflt, sig, R, o)
        c = trec[k, 2]
        for h in range(6):
            A[6 * row + h, c] += w[h]


@njit(**OPTS)
def _eliminate(A, nr, r, x):
    """x = A^-1 r (A square nr x nr, overwritten; partial pivoting); NaN when singular."""
    for i in range(nr):
        x[i] = r[i]
    for c in range(nr):
        p = c
        for i in range(c + 1, nr):
            if abs(A[i, c]) > abs(A[p, c]):
                p = i
        if A[p, c] == 0.0:
            for i in range(nr):
                x[i] = np.nan
            return
        if p != c:
            for j in range(c, nr):
                A[c, j], A[p, j] = A[p, j], A[c, j]
            x[c], x[p] = x[p], x[c]
        for i in range(c + 1, nr):
            f = A[i, c] / A[c, c]
            if f != 0.0:
                for j in range(c + 1, nr):
                    A[i, j] -= f * A[c, j]
                x[i] -= f * x[c]
    for c in range(nr - 1, -1, -1):
        s = x[c]
        for j in range(c + 1, nr):
            s -= A[c, j] * x[j]
        x[c] = s / A[c, c]


@njit(**INLINE)
def world_gather(lk0, B, blinks, rhs, r):
    """r (6B) = the block links' right-hand sides (base axes, about each link's origin)."""
    for i in range(B):
        L = blinks[lk0 + i]
        for h in range(6):
            r[6 * i + h] = rhs[L, h]


@njit(**OPTS)
def world_solve(k0, nt, trec, tflt, sig, R, o, nr, r, x, A):
    """x = the world-frame block solution for the signs ``sig``."""
    _assemble(k0, nt, trec, tflt, sig, R, o, nr, nr, A)
    _eliminate(A, nr, r, x)


@njit(**INLINE)
def world_propagate(k0, nt, trec, tflt, sig, R, o, x, rhs):
    """rhs[L] -= the solved wrenches on the later links (terms with no block row)."""
    for k in range(k0, k0 + nt):
        if trec[k, 1] >= 0:
            continue
        L = trec[k, 0]
        w = term_wrench(k, L, trec, tflt, sig, R, o)
        xc = x[trec[k, 2]]
        for h in range(6):
            rhs[L, h] -= w[h] * xc
