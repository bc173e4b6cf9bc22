"""CSV text of the output table, fast: the same bytes as ``"%.<P>g" % x`` for every value.

:func:`format_rows` gives the rows of a table ``(N, ncol)`` as CSV text, each value written
like C's ``printf("%.Pg")`` (``P`` significant digits, trailing zeros removed, exponent
form below 1e-4 and from 10**P on) with negative zero written ``0``.  Python's own
``%`` formatting costs ~400 ns a value; for large tables (and ``P <= FAST_DIGITS``) a
compiled two-pass writer (numba, GIL-free, ~60-100 ns a value) does the same:

1. per value, the decimal exponent ``e`` and the rounded mantissa ``m``
   (``10**(P-1) <= m < 10**P``) from ``|x| * 10**(P-1-e)`` in float64.  That product is
   within a few units in the last place of the exact one; when its fraction lies within
   :data:`_TIE_BAND` of one half, rounding to the nearest integer could go either way, so
   the value is *special* and formatted by Python instead (exactly: correctly rounded,
   half to even); so are magnitudes below 1e-280 or above 1e280 (where 10**(P-1-e)
   leaves the normal float64 range) and non-finite values (NaN, inf: never written by
   ``gearcli solve``, which refuses them first);
2. the characters, from ``m`` and ``e`` (or a copy of Python's text for a special value).

The result is byte-identical to Python's formatting for every float64 (the tests check
random tables with ties, negative zeros, subnormals and huge values against ``"%.9g"``).
"""
from __future__ import annotations

import io
import os
from concurrent.futures import ThreadPoolExecutor

import numpy as np

FAST_DIGITS = 10
"""Largest number of significant digits of the compiled path (rounding errors of the
float64 product stay far below :data:`_TIE_BAND` of a unit up to 10 digits)."""


_TIE_BAND = 1e-4
"""Fractions within this of one half (units of the last kept digit) go to Python: the
float64 product's error is below 10**P * 3 * 2**-53 <= 3.4e-6 units for P <= 10."""


def format_rows(tab: np.ndarray, digits: int = 9, compiled: bool = True) -> str:
    """CSV text of the rows of ``tab`` (N, ncol): values ``"%.<digits>g"``, no negative
    zeros, ``,`` between values and ``\\n`` after each row.  ``compiled``: use the
    compiled writer when ``digits <= FAST_DIGITS`` (the same text; worth its ~1 s import
    and cached compilation from ~2 million values on)."""
    tab = np.asarray(tab, dtype=float)
    if not compiled or digits > FAST_DIGITS:
        return python_rows(tab, digits)
    return compiled_rows(tab, digits)


def write_rows(f, tab: np.ndarray, digits: int = 9, compiled: bool = True, jobs: int = 1) -> None:
    """Write :func:`format_rows` to the text file ``f``; the compiled bytes go straight
    to the binary buffer of a plain :class:`io.TextIOWrapper` (no decoding, re-encoding).
    ``jobs`` > 1 formats that many blocks of rows in threads (the compiled loops release
    the GIL); the text is the same."""
    tab = np.asarray(tab, dtype=float)
    if not compiled or digits > FAST_DIGITS:
        f.write(python_rows(tab, digits))
        return
    direct = type(f) is io.TextIOWrapper and os.linesep == "\n" and _ascii_safe(f)
    if direct:
        f.flush()
    for part in compiled_parts(tab, digits, jobs):
        if direct:
            f.buffer.write(part)
        else:
            f.write(str(part, "ascii"))


def compiled_parts(tab: np.ndarray, digits: int, jobs: int) -> list[memoryview]:
    """:func:`compiled_bytes` of ``jobs`` blocks of rows of ``tab``, formatted in threads."""
    n = tab.shape[0]
    jobs = max(1, min(int(jobs), n // 1000))
    if jobs == 1:
        return [compiled_bytes(tab, digits)]
    blocks = np.array_split(tab, jobs)
    with ThreadPoolExecutor(jobs) as pool:
        return list(pool.map(lambda b: compiled_bytes(b, digits), blocks))


def _ascii_safe(f) -> bool:
    """True when the text file encodes ASCII as itself (UTF-8, ASCII, Latin-1, ...)."""
    try:
        return "x,-.e+0123456789\n".encode(f.encoding) == b"x,-.e+0123456789\n"
    except (LookupError, TypeError):
        return False


def python_rows(tab: np.ndarray, digits: int = 9) -> str:
    """CSV text by Python's ``%`` formatting (the reference behaviour)."""
    n, m = tab.shape
    line = ",".join([f"%.{digits}g"] * m) + "\n"
    return (line * n) % tuple((tab + 0.0).ravel().tolist())   # + 0.0: no negative zeros


def compiled_rows(tab: np.ndarray, digits: int = 9) -> str:
    """CSV text by the compiled two-pass writer (see the module docstring)."""
    return str(compiled_bytes(tab, digits), "ascii")


def compiled_bytes(tab: np.ndarray, digits: int = 9) -> memoryview:
    """ASCII bytes of :func:`compiled_rows` (no copy to a ``str``)."""
    from . import csv_kernels as k  # noqa: PLC0415 (numba: imported only for large tables)

    if not 1 <= digits <= FAST_DIGITS:
        raise ValueError(f"compiled_rows: digits must be 1..{FAST_DIGITS}, got {digits}")
    tab = np.asarray(tab, dtype=np.float64)
    mant = np.empty(tab.shape, np.uint64)
    expo = np.empty(tab.shape, np.int64)
    kind = np.empty(tab.shape, np.uint8)
    k.decompose(tab, digits, _TIE_BAND, mant, expo, kind)
    special = np.nonzero(kind == k.SPECIAL)       # row-major order, as they are written
    fmt = f"%.{digits}g"
    texts = [fmt % (x + 0.0) for x in tab[special].tolist()]
    extra = np.frombuffer("".join(texts).encode("ascii"), np.uint8)
    lengths = np.fromiter(map(len, texts), np.int64, len(texts))
    offsets = np.zeros(len(texts) + 1, np.int64)
    np.cumsum(lengths, out=offsets[1:])
    out = np.empty(tab.size * (digits + 8) + extra.size, np.uint8)
    used = k.emit(tab, mant, expo, kind, extra, offsets, digits, out)
    return memoryview(out[:used])
