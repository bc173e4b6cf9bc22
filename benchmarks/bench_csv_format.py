"""Does numba earn its place in the CSV writer?  The CSV text of a loads table, four ways; prints figures.

    python benchmarks/bench_csv_format.py [--rows 20000] [--cols 60] [--repeat 5]

A realistic table (``--rows`` x ``--cols`` loads, magnitudes 1e-3..1e4 with exact zeros, as
``gearcli solve`` writes), 9 significant digits, one thread, the four writers interleaved
round by round, medians:

* ``numba``: gearcli's compiled two-pass writer (:func:`gearcli.report.csv_text.compiled_rows`);
* ``numpy``: the same two passes vectorised with numpy (below: the decimal decomposition as
  array operations, then every value's characters in fixed slots and the used slots kept);
  checked byte-identical to ``"%.9g"`` first;
* ``pyarrow``: ``pyarrow.csv.write_csv`` of the table (shortest round-trip text of each
  float64, *not* ``%.9g``: rounding the values to 9 digits first would add to its time);
* ``python``: ``"%.9g" % x`` (:func:`gearcli.report.csv_text.python_rows`, the reference).

Only the byte-identical writers (numba, numpy, python) keep the output contract.  Load
average at the start and the end.
"""
from __future__ import annotations

import argparse
import io
import math
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from timing import load_line  # noqa: E402 (benchmarks/timing.py)

from gearcli.report.csv_text import compiled_rows, python_rows  # noqa: E402

_LOW, _HIGH = 1e-280, 1e280
_P10 = np.array([float(f"1e{k}") for k in range(-300, 301)])
_LOG10_2 = math.log10(2.0)


def decompose(x: np.ndarray, digits: int, band: float):
    """(mant uint64, expo int64, normal bool, zero bool) of the flat float64 values x."""
    a = np.abs(x)
    zero = a == 0.0
    ok = (a >= _LOW) & (a <= _HIGH)                 # False for NaN
    aa = np.where(ok, a, 1.0)
    e = np.floor((np.frexp(aa)[1] - 1) * _LOG10_2).astype(np.int64)
    s = aa * _P10[digits - 1 - e + 300]
    hi = 10.0 ** digits - 0.5
    lo = 10.0 ** (digits - 1) - 0.5
    while True:
        up = s >= hi
        if not up.any():
            break
        e = e + up
        s = np.where(up, aa * _P10[digits - 1 - e + 300], s)
    f = s - np.floor(s)
    normal = ok & ~(np.abs(f - 0.5) < band) & (lo <= s) & (s < hi)
    mant = (s + 0.5).astype(np.uint64)
    return mant, e, normal, zero


def numpy_rows(tab: np.ndarray, digits: int, band: float = 1e-4) -> bytes:
    """CSV bytes of ``tab`` as ``"%.<digits>g"`` writes each value (negative zero ``0``),
    vectorised: per value 1 + 5 + 2 digits + 5 + 1 character slots (sign, "0.000",
    digit/point pairs, exponent, separator), the used ones kept in order."""
    n, m = tab.shape
    x = np.ascontiguousarray(tab, dtype=np.float64).reshape(-1)
    K = x.size
    mant, e, normal, zero = decompose(x, digits, band)
    # digit characters D[k] (most significant first)
    D = np.empty((K, digits), np.uint8)
    mm = mant.copy()
    for p in range(digits - 1, -1, -1):
        q = mm // np.uint64(10)
        D[:, p] = (mm - q * np.uint64(10)).astype(np.uint8) + 48
        mm = q
    # significant digits after trailing zeros removed
    nzmask = D != 48
    nz = digits - np.argmax(nzmask[:, ::-1], axis=1)
    fixed = (e >= -4) & (e < digits)
    small = fixed & (e < 0)
    big = fixed & (e >= 0)
    expo = ~fixed
    dot = np.where(big, e, 0)                         # '.' after digit `dot` (not for small)
    keepd = np.where(big, np.maximum(nz, e + 1), nz)  # digits written
    # slots: sign | "0.000" (5) | D0 P0 D1 P1 ... | e s d d d | sep
    W = 1 + 5 + 2 * digits + 5 + 1
    M = np.empty((K, W), np.uint8)
    keep = np.zeros((K, W), bool)
    M[:, 0] = 45
    keep[:, 0] = (x < 0) & ~zero & normal
    M[:, 1:6] = np.frombuffer(b"0.000", np.uint8)
    nlead = np.where(small, 1 - e, 0)                 # "0." + (-e-1) zeros = 1 - e chars
    cols = np.arange(5)
    keep[:, 1:6] = cols[None, :] < nlead[:, None]
    M[:, 6:6 + 2 * digits:2] = D
    kk = np.arange(digits)
    keep[:, 6:6 + 2 * digits:2] = kk[None, :] < keepd[:, None]
    M[:, 7:7 + 2 * digits:2] = 46
    keep[:, 7:7 + 2 * digits:2] = (kk[None, :] == dot[:, None]) & (keepd[:, None] > dot[:, None] + 1) & ~small[:, None]
    b = 6 + 2 * digits
    M[:, b] = 101
    M[:, b + 1] = np.where(e < 0, 45, 43)
    ae = np.abs(e)
    M[:, b + 2] = 48 + (ae // 100) % 10
    M[:, b + 3] = 48 + (ae // 10) % 10
    M[:, b + 4] = 48 + ae % 10
    keep[:, b:b + 2] = expo[:, None]
    keep[:, b + 2] = expo & (ae >= 100)
    keep[:, b + 3:b + 5] = expo[:, None]
    keep &= normal[:, None]
    # zero: a single '0' in slot D0
    M[zero, 6] = 48
    keep[zero, 6] = True
    M[:, W - 1] = 44
    M[m - 1::m, W - 1] = 10
    keep[:, W - 1] = True
    out = M[keep]
    special = ~normal & ~zero
    if special.any():
        idx = np.flatnonzero(special)
        fmt = f"%.{digits}g"
        texts = [(fmt % (v + 0.0)).encode("ascii") for v in x[idx].tolist()]
        lengths = keep.sum(axis=1)
        starts = np.concatenate([[0], np.cumsum(lengths)[:-1]])[idx]
        ins = np.repeat(starts, [len(t) for t in texts])
        out = np.insert(out, ins, np.frombuffer(b"".join(texts), np.uint8))
    return out.tobytes()


def table(rows: int, cols: int) -> np.ndarray:
    rng = np.random.default_rng(0)
    tab = rng.normal(size=(rows, cols)) * 10.0 ** rng.uniform(-3, 4, cols)
    tab[:, ::7] = 0.0                    # e.g. the axial component of a spur mesh
    return tab


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--rows", type=int, default=20_000)
    ap.add_argument("--cols", type=int, default=60)
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args()
    import pyarrow as pa  # noqa: PLC0415
    import pyarrow.csv as pc  # noqa: PLC0415

    print(f"# CSV text of a {args.rows:,} x {args.cols} table, 9 digits, one thread; {load_line()} at start")
    tab = table(args.rows, args.cols)
    check = np.concatenate([tab[:200], np.random.default_rng(1).normal(size=(200, args.cols))
                            * 10.0 ** np.random.default_rng(2).integers(-300, 300, (200, args.cols))])
    assert numpy_rows(check, 9) == python_rows(check, 9).encode() == compiled_rows(check, 9).encode()
    arrow = pa.table({f"c{i}": tab[:, i] for i in range(args.cols)})
    opts = pc.WriteOptions(include_header=False)
    writers = {"numba": lambda: compiled_rows(tab, 9), "numpy": lambda: numpy_rows(tab, 9),
               "pyarrow": lambda: pc.write_csv(arrow, io.BytesIO(), opts), "python": lambda: python_rows(tab, 9)}
    for w in writers.values():
        w()                              # compiled / warmed once
    times = {k: [] for k in writers}
    for _ in range(args.repeat):
        for k, w in writers.items():
            t0 = time.perf_counter()
            w()
            times[k].append(time.perf_counter() - t0)
    med = {k: float(np.median(v)) for k, v in times.items()}
    print("\n| writer | median | ns a value | / numba | contract |\n|---|---:|---:|---:|---|")
    for k, t in med.items():
        print(f"| {k} | {t * 1e3:.0f} ms | {t / tab.size * 1e9:.0f} | {t / med['numba']:.1f}x | "
              f"{'%.9g bytes' if k != 'pyarrow' else 'shortest round-trip, not %.9g'} |")
    print(f"\n{load_line()} at end")


if __name__ == "__main__":
    main()
