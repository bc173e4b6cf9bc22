"""Derivatives of the quintic interpolating spline at its data points, without
:mod:`scipy.interpolate`.

:func:`spline_derivatives` computes what ``make_interp_spline(t, y, k=5)`` (not-a-knot
ends) followed by ``.derivative(1)`` and evaluation at ``t`` gives, by the same
arithmetic: the not-a-knot knots, the collocation matrix by the Cox-de Boor recursion
(scipy's ``_deBoor_D``), LAPACK ``gbsv`` on the banded system, the derivative
coefficients of ``splder`` and the evaluation sum of ``evaluate_spline``.  It is
vectorised over the samples (Python loops over the degree only) and knows the knot
interval of every data point (no search).  Importing :mod:`scipy.interpolate` costs ~0.2 s
(scipy.sparse, scipy.special, ...), the ``scipy.linalg`` package as much: this module loads
only scipy's LAPACK extension (:func:`dgbsv`).  ``tests/test_spline.py`` checks it against
``make_interp_spline`` (to 1e-12 of each column's largest derivative) and against
polynomials of degree 5, which the spline reproduces exactly.
"""
from __future__ import annotations

import sys
from functools import lru_cache

import numpy as np

from ..errors import counted

K = 5          # spline degree
MIN_SAMPLES = K + 1


def _knots(x: np.ndarray) -> np.ndarray:
    """Not-a-knot knots of degree ``K`` (odd) on the data sites ``x`` (n,): (n + K + 1,)."""
    h = (K + 1) // 2
    return np.concatenate([np.full(K + 1, x[0]), x[h:-h], np.full(K + 1, x[-1])])


def _shift(shift: int) -> int:
    """Knot interval of data site x_i on ``_knots(x)[shift:len - shift]``: i + this, except
    in the first and last intervals (:func:`_intervals`)."""
    return (K + 1) // 2 - shift


def _intervals(n: int, shift: int, k: int) -> np.ndarray:
    """Knot interval l (t[l] <= x_i < t[l + 1], the last one closed) of every data site
    x_i, i < n, on the knots ``_knots(x)[shift:len - shift]`` of degree ``k``: the site
    x_i is the knot of index i + 3 - shift, clipped to the first and last interval."""
    return np.clip(np.arange(n) + _shift(shift), k, n - 1 - shift)


def _basis(t: np.ndarray, x: np.ndarray, k: int, knot) -> list[np.ndarray]:
    """The k + 1 non-zero B-splines of degree ``k`` on knots ``t`` at the points ``x`` (n,):
    [B_{l-k}(x), ..., B_{l}(x)] for x in knot interval l, ``knot(d)`` being the knots
    t[l + d] (n,) (scipy's ``_deBoor_D``, its operations in its order; the intervals are
    never empty for strictly increasing sites, so no division by zero)."""
    h = [np.ones_like(x)] + [None] * k
    for j in range(1, k + 1):
        hh = h[:j]
        for m in range(1, j + 1):
            xb, xa = knot(m), knot(m - j)
            w = hh[m - 1] / (xb - xa)
            h[m - 1] = h[m - 1] + w * (xb - x) if m > 1 else w * (xb - x)
            h[m] = w * (x - xa)
    return h


def _all_bases(t: np.ndarray, x: np.ndarray, k: int, shift: int) -> tuple[list[np.ndarray], np.ndarray]:
    """(:func:`_basis` at every site x_i in its interval l_i, the intervals (n,)): by
    slices for the sites inside (l_i = i + s), by index for the few at either end."""
    n, s = len(x), _shift(shift)
    ell = _intervals(n, shift, k)
    ends = np.flatnonzero(ell != np.arange(n) + s)
    pad = np.concatenate([np.full(k + 1, t[0]), t, np.full(k + 1, t[-1])])   # any finite knots
    with np.errstate(divide="ignore", invalid="ignore"):      # the end rows, replaced below
        h = _basis(t, x, k, lambda d: pad[k + 1 + s + d:k + 1 + s + d + n])
    he = _basis(t, x[ends], k, lambda d: t[ell[ends] + d])
    for a in range(k + 1):
        h[a][ends] = he[a]
    return h, ell


def _evaluate(t: np.ndarray, c: np.ndarray, k: int, x: np.ndarray, shift: int) -> np.ndarray:
    """Values (n, m) at the sites ``x`` (n,) of the spline of degree ``k``, knots ``t``
    (``_knots(x)[shift:len - shift]``) and coefficients ``c`` (>= n, m) (scipy's
    ``evaluate_spline``: sum in the order of the basis)."""
    n, s = len(x), _shift(shift)
    h, ell = _all_bases(t, x, k, shift)
    p = 2 * k + 2                                          # cp[j + p] = c[j]
    cp = np.concatenate([np.zeros((p, c.shape[1])), c, np.zeros((p, c.shape[1]))])
    out = np.zeros((n, c.shape[1]))
    for a in range(k + 1):
        out += cp[p + s - k + a:p + s - k + a + n] * h[a][:, None]      # c[i + s - k + a]
    ends = np.flatnonzero(ell != np.arange(n) + s)
    oe = np.zeros((len(ends), c.shape[1]))
    for a in range(k + 1):
        oe += c[ell[ends] - k + a] * h[a][ends][:, None]
    out[ends] = oe
    return out


@lru_cache(maxsize=1)
def dgbsv():
    """LAPACK ``dgbsv`` as scipy wraps it (``scipy.linalg.get_lapack_funcs`` gives the same
    function for float64 arrays), loaded from scipy's ``scipy.linalg._flapack`` extension
    alone: importing the ``scipy.linalg`` package costs 0.2-0.4 s of a fresh process
    (``gearcli verify`` and ``solve`` of a positions-only file need nothing else of scipy),
    the extension ~0.01 s.  Falls back to ``get_lapack_funcs`` where scipy keeps it elsewhere."""
    import glob  # noqa: PLC0415
    import importlib.machinery  # noqa: PLC0415
    import importlib.util  # noqa: PLC0415
    import os  # noqa: PLC0415

    name = "scipy.linalg._flapack"
    try:
        if name in sys.modules or "scipy.linalg" in sys.modules:
            raise ImportError("loaded already")
        spec = importlib.util.find_spec("scipy")
        found = sorted(glob.glob(os.path.join(os.path.dirname(spec.origin), "linalg",
                                              "_flapack" + importlib.machinery.EXTENSION_SUFFIXES[0])))
        loader = importlib.machinery.ExtensionFileLoader(name, found[0])
        module = importlib.util.module_from_spec(importlib.util.spec_from_file_location(name, found[0], loader=loader))
        loader.exec_module(module)
        return module.dgbsv
    except (ImportError, AttributeError, IndexError, TypeError, OSError):
        from scipy.linalg import get_lapack_funcs  # noqa: PLC0415

        return get_lapack_funcs(("gbsv",), (np.zeros((1, 1)),))[0]


def _coefficients(t: np.ndarray, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """B-spline coefficients (n, m) of the interpolant of ``y`` (n, m) at ``x`` on knots ``t``
    (the banded collocation system of scipy's ``make_interp_spline``, LAPACK ``gbsv``)."""
    n = len(x)
    h, ell = _all_bases(t, x, K, 0)
    kl = ku = K
    ab = np.zeros((2 * kl + ku + 1, n), order="F")
    s = _shift(0)
    lo, hi = K - s, n - s          # rows i in [lo, hi) lie in interval i + s; the others at the ends
    ends = np.r_[0:lo, hi:n]
    for a, b in enumerate(h):      # B_{ell-K+a}(x_i) is A[i, ell-K+a], band row kl+ku+i-(ell-K+a)
        ab[kl + ku + K - s - a, lo + s - K + a:hi + s - K + a] = b[lo:hi]
        col = ell[ends] - K + a
        ab[kl + ku + ends - col, col] = b[ends]
    rhs = np.array(y, dtype=float).reshape(n, -1)
    _, _, c, info = dgbsv()(kl, ku, ab, rhs, overwrite_ab=True, overwrite_b=True)
    if info > 0:
        raise np.linalg.LinAlgError("Colocation matrix is singular.")
    if info < 0:   # pragma: no cover
        raise ValueError(f"illegal value in {-info}-th argument of internal gbsv")
    return c


def spline_derivatives(x: np.ndarray, y: np.ndarray, order: int = 2) -> list[np.ndarray]:
    """First ``order`` (1..5) derivatives (each (n, m)) at the sites ``x`` (n,), strictly
    increasing, n >= 6, of the quintic not-a-knot interpolating spline of ``y`` (n, m)."""
    x = np.asarray(x, dtype=float)
    n = len(x)
    if n < MIN_SAMPLES:
        raise ValueError(f"{counted(n, 'sample')}: the quintic spline needs at least {MIN_SAMPLES}")
    if not np.all(x[1:] > x[:-1]):
        raise ValueError("the sites must increase strictly")
    t = _knots(x)
    c = np.concatenate([_coefficients(t, x, y), np.zeros((K + 1, np.shape(y)[1]))])  # FITPACK's padding
    out = []
    k = K
    for d in range(1, order + 1):
        dt = t[k + 1:-1] - t[1:-k - 1]
        c = np.concatenate([(c[1:-1 - k] - c[:-2 - k]) * k / dt[:, None], np.zeros((k, c.shape[1]))])
        t, k = t[1:-1], k - 1
        out.append(_evaluate(t, c, k, x, d))
    return out


def derivatives(t: np.ndarray, y: np.ndarray, order: int = 2) -> list[np.ndarray]:
    """First ``order`` derivatives of samples ``y`` (N, m) at times ``t`` (N,) by the
    interpolating spline of degree k = min(5, N - 1) (not-a-knot ends).

    Raises ValueError when N - 1 < ``order`` (too few samples for the derivatives).
    """
    n = len(t)
    k = min(5, n - 1)
    if k < order:
        raise ValueError(f"{counted(n, 'sample')} allow{'s' if n == 1 else ''} a spline of degree {k} < {order}")
    # the spline of y - y[0]: the same derivatives, but a column that holds still (a joint at
    # rest) gives exact zeros, not ~1e-14 of rounding (rates that turn bearings and friction)
    y = np.asarray(y, float)
    y = y - y[:1]
    if k == 5:
        return spline_derivatives(t, y, order)     # the same values as scipy's, without importing it
    from scipy.interpolate import make_interp_spline  # noqa: PLC0415  (2 to 5 samples only)

    spl = make_interp_spline(t, y, k=k, check_finite=False)   # the reader checked every value finite
    out = []
    for _ in range(order):
        spl = spl.derivative(1)      # the same coefficients as derivative(i) of the fit, one step each
        out.append(spl(t))
    return out
