"""gearcli.solve refuses a non-finite motion value (library callers; the CLI checks its files
itself): a ValueError naming the array, the first bad sample and its joint, on every backend;
``check_finite=False`` lets the value through (NaN loads, or a SignError at a geared block)."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from gearcli import analyse, load_mechanism, solve
from gearcli.dynamics.signs import SignError

MECH_DIR = Path(__file__).resolve().parents[1] / "mechanisms"


@pytest.fixture(scope="module")
def bendix():
    return analyse(load_mechanism(MECH_DIR / "bendix_wrist.yaml"))


def _motion(an, n=50):
    rng = np.random.default_rng(3)
    return [rng.uniform(-1, 1, (n, an.dof)) for _ in range(3)]


@pytest.mark.parametrize("backend", ["numpy", "llvm"])
@pytest.mark.parametrize("which, value", [(0, np.nan), (1, np.inf), (2, -np.inf)])
def test_non_finite_motion_is_named(bendix, backend, which, value):
    arrays = _motion(bendix)
    arrays[which][17, 2] = value
    arrays[which][30, 0] = np.nan          # a later one: the first is named
    name, joint = ("q", "qd", "qdd")[which], bendix.independent_names[2]
    with pytest.raises(ValueError) as info:
        solve(bendix, *arrays, backend=backend)
    assert str(info.value) == (f"{name} is not finite at sample 17, joint '{joint}': {value} "
                               "(check_finite=False lets it through)")


def test_a_single_sample_and_lists_are_checked(bendix):
    q = [0.1, float("nan"), 0.3]
    with pytest.raises(ValueError, match=r"^q is not finite at sample 0, joint '"):
        solve(bendix, q, [0, 0, 0], [0, 0, 0])


def test_check_finite_false_lets_the_value_reach_the_solver(bendix):
    q, qd, qdd = _motion(bendix)
    qdd[5, 1] = np.nan
    with pytest.raises(SignError) as info, np.errstate(all="ignore"):
        solve(bendix, q, qd, qdd, backend="numpy", check_finite=False)
    assert info.value.sample == 5


def test_finite_motion_is_solved_the_same_with_or_without_the_check(bendix):
    q, qd, qdd = _motion(bendix)
    a = solve(bendix, q, qd, qdd, backend="numpy")
    b = solve(bendix, q, qd, qdd, backend="numpy", check_finite=False)
    assert np.array_equal(a.motor, b.motor) and np.array_equal(a.joint, b.joint)
