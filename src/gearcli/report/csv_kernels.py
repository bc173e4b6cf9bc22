"""Compiled loops (numba, cached on disk) of :mod:`gearcli.report.csv_text`: the decimal
decomposition of each value and the CSV characters."""
from __future__ import annotations

import math

import numpy as np
from numba import njit

NORMAL, ZERO, SPECIAL = 0, 1, 2
"""``kind`` of a value: written from (mantissa, exponent); ``0``; copied from Python's text."""

_LOW, _HIGH = 1e-280, 1e280     # beyond: 10**(P-1-e) would leave the normal float64 range
_P10 = np.array([float(f"1e{k}") for k in range(-300, 301)])   # correctly rounded powers of ten
_U10 = np.uint64(10)
_LOG10_2 = math.log10(2.0)
_U48 = np.uint64(48)
_U0 = np.uint64(0)
_ZEROS = np.frombuffer(b"0.000", np.uint8).copy()


@njit(cache=True, nogil=True)
def decompose(tab, digits, band, mant, expo, kind):
    """Fill ``mant`` (rounded mantissa, ``10**(digits-1) <= m < 10**digits``), ``expo``
    (decimal exponent of the rounded value) and ``kind`` (all (n, ncol), C order) for every
    value of ``tab`` (n, ncol), any memory layout."""
    lo = 10.0 ** (digits - 1) - 0.5
    hi = 10.0 ** digits - 0.5
    p10 = _P10
    for i in range(tab.shape[0]):
        for j in range(tab.shape[1]):
            a = abs(tab[i, j])
            if a == 0.0:
                kind[i, j] = ZERO
                continue
            if not (_LOW <= a <= _HIGH):      # also NaN
                kind[i, j] = SPECIAL
                continue
            e2 = math.frexp(a)[1] - 1                   # a in [2**e2, 2**(e2 + 1))
            e = int(math.floor(e2 * _LOG10_2))          # the exponent of a, or one less
            s = a * p10[digits - 1 - e + 300]
            while s >= hi:
                e += 1
                s = a * p10[digits - 1 - e + 300]
            f = s - math.floor(s)
            if abs(f - 0.5) < band or not (lo <= s < hi):
                kind[i, j] = SPECIAL
                continue
            kind[i, j] = NORMAL
            mant[i, j] = np.uint64(s + 0.5)
            expo[i, j] = e


@njit(cache=True, nogil=True)
def emit(tab, mant, expo, kind, extra, offsets, digits, out):
    """Write the CSV characters of ``tab`` (n, ncol) row by row into ``out``; return the
    number of bytes written.  A normal value's digits are all written, then the position
    advances past the kept ones only (trailing zeros dropped).  Special values take their
    text from ``extra`` (``offsets``), in row-major order."""
    pos = 0
    js = 0
    ncol = tab.shape[1]
    for i in range(tab.shape[0]):
        for j in range(ncol):
            k = kind[i, j]
            if k == ZERO:
                out[pos] = 48
                pos += 1
            elif k == SPECIAL:
                for b in range(offsets[js], offsets[js + 1]):
                    out[pos] = extra[b]
                    pos += 1
                js += 1
            else:
                if tab[i, j] < 0.0:
                    out[pos] = 45
                    pos += 1
                pos = _normal(mant[i, j], expo[i, j], digits, out, pos)
            out[pos] = 44 if j + 1 < ncol else 10
            pos += 1
    return pos


@njit(cache=True, nogil=True, inline="always")
def _normal(m, e, digits, out, pos):
    """Write m * 10**(e - digits + 1) > 0 as ``%g`` does; return the new position."""
    fixed = -4 <= e < digits
    if e < 0 and fixed:               # 0.000ddd: no point among the digits
        for p in range(5):
            out[pos + p] = _ZEROS[p]
        pos += 1 - e
        dot = digits
    else:                             # ddd[.ddd] (point after digit e), d[.ddd]e+XX (after 0)
        dot = e if fixed else 0
        out[pos + dot + 1] = 46
    nz = digits                       # significant digits left after removing trailing zeros
    for p in range(digits - 1, -1, -1):
        q = m // _U10
        d = m - q * _U10
        m = q
        out[pos + p + (1 if p > dot else 0)] = np.uint8(d + _U48)
        if nz == p + 1 and d == _U0 and p > 0:
            nz = p
    if dot == digits:
        return pos + nz
    end = pos + (nz + 1 if nz > dot + 1 else dot + 1)
    return end if fixed else _exponent(e, out, end)


@njit(cache=True, nogil=True, inline="always")
def _exponent(e, out, pos):
    """Write e+XX (at least two exponent digits); return the new position."""
    out[pos] = 101
    out[pos + 1] = 45 if e < 0 else 43
    pos += 2
    ae = np.uint64(-e if e < 0 else e)
    if ae >= 100:
        out[pos] = np.uint8(_U48 + ae // np.uint64(100))
        pos += 1
    out[pos] = np.uint8(_U48 + (ae // _U10) % _U10)
    out[pos + 1] = np.uint8(_U48 + ae % _U10)
    return pos + 2
