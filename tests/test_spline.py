"""io/spline.py: the quintic spline derivatives against scipy's make_interp_spline (the
implementation before, kept here as the reference) and against polynomials."""
import numpy as np
import pytest
from scipy.interpolate import make_interp_spline

from gearcli.io.spline import spline_derivatives


def scipy_derivatives(t, y, order):
    """The reference: scipy's interpolating spline, differentiated one step at a time."""
    spl = make_interp_spline(t, y, k=5)
    out = []
    for _ in range(order):
        spl = spl.derivative(1)
        out.append(spl(t))
    return out


def relative(a, b) -> float:
    """Largest difference relative to each column's largest magnitude."""
    return float(np.max(np.abs(a - b) / np.maximum(np.abs(b).max(axis=0), 1e-300)))


@pytest.mark.parametrize("n", [6, 7, 8, 9, 10, 11, 13, 64, 1000, 20_128])
def test_equals_scipy_interpolating_spline(n):
    rng = np.random.default_rng(n)
    t = 3.0 + np.cumsum(rng.uniform(0.3e-3, 1.7e-3, n))       # uneven steps, offset start
    y = np.column_stack([np.sin(7 * t), np.exp(t / 4) * np.cos(3 * t), rng.standard_normal(n)])
    mine, ref = spline_derivatives(t, y, 5), scipy_derivatives(t, y, 5)
    for d, (a, b) in enumerate(zip(mine, ref), 1):
        assert a.shape == b.shape == (n, 3)
        assert relative(a, b) <= 1e-12, f"derivative {d}"


def test_reproduces_quintic_polynomials():
    rng = np.random.default_rng(5)
    t = np.sort(rng.uniform(-1.0, 2.0, 300))
    coef = rng.standard_normal((6, 2))              # y = sum c_p t^p, degree 5 (a quintic spline's own)
    y = np.polynomial.polynomial.polyval(t, coef).T
    d1 = np.polynomial.polynomial.polyval(t, np.polynomial.polynomial.polyder(coef, 1)).T
    d2 = np.polynomial.polynomial.polyval(t, np.polynomial.polynomial.polyder(coef, 2)).T
    got1, got2 = spline_derivatives(t, y, 2)
    assert relative(got1, d1) < 1e-9 and relative(got2, d2) < 1e-7


def test_refuses_too_few_or_unordered_sites():
    with pytest.raises(ValueError, match="at least 6"):
        spline_derivatives(np.arange(5.0), np.zeros((5, 1)))
    with pytest.raises(ValueError, match="increase strictly"):
        spline_derivatives(np.array([0.0, 1, 2, 2, 3, 4, 5]), np.zeros((7, 1)))


PROBE = """
import sys
import numpy as np
from gearcli.io.spline import derivatives
t = np.cumsum(np.random.default_rng(4).uniform(0.5, 1.5, 3000))
y = np.column_stack([np.sin(t / 40), np.cos(t / 25)])
d1, d2 = derivatives(t, y, 2)
print("scipy.linalg" in sys.modules)
sys.stdout.flush()
from scipy.linalg import get_lapack_funcs
import gearcli.io.spline as S
S.dgbsv = lambda: get_lapack_funcs(("gbsv",), (np.zeros((1, 1)),))[0]    # the scipy.linalg path
e1, e2 = derivatives(t, y, 2)
print(d1.tobytes() == e1.tobytes() and d2.tobytes() == e2.tobytes())
"""


def test_spline_loads_lapack_without_the_scipy_linalg_package_same_bits():
    # a fresh process: the spline's dgbsv comes from scipy's LAPACK extension alone (the
    # scipy.linalg package costs 0.2-0.4 s to import), and gives what get_lapack_funcs' does
    import subprocess
    import sys

    out = subprocess.run([sys.executable, "-c", PROBE], capture_output=True, text=True, check=True).stdout.split()
    assert out == ["False", "True"]


@pytest.mark.parametrize("n", [4, 50])
def test_a_column_that_holds_still_has_exactly_zero_rates(n):
    """A joint held at a constant angle (0.3, not a binary fraction) has rate and acceleration
    exactly 0, not ~1e-14 of rounding that turns its bearings (issue 34: a rest trajectory
    gave bearing lives of 1e+64 h); the moving column beside it is unchanged."""
    from gearcli.io.spline import derivatives
    t = np.linspace(0.0, 1.0, n)
    y = np.column_stack([np.full(n, 0.3), np.sin(t), np.full(n, -1e5 / 3)])
    d1, d2 = derivatives(t, y, 2)
    assert not d1[:, [0, 2]].any() and not d2[:, [0, 2]].any()
    if n > 6:
        assert np.abs(d1[:, 1] - np.cos(t)).max() < 1e-6
