"""The sign resolution of Eq. 14 (:func:`gearcli.dynamics.signs.resolve_signs`) against the
exhaustive rule, on many random piecewise-linear systems A_mid x + H |t| = r.

The exhaustive rule solves every one of the 2^m sign patterns and keeps the solutions whose
t agree with their pattern.  The search (every t positive, then the trial's own signs m
times, then every pattern in order) must give: a SignError naming the first such sample
exactly where no pattern is consistent, one of the consistent solutions elsewhere, and the
consistent solution where it is unique.  Random matrices with large separating terms H
make all three cases frequent.  The Woodbury form the generated kernel solves for blocks
with many patterns (:class:`~gearcli.dynamics.pattern_maps.LowRank`) is checked against
the direct pattern maps on the same systems (square and redundant).
"""
from __future__ import annotations

import itertools

import numpy as np
import pytest

from gearcli.dynamics.pattern_maps import PatternMaps, low_rank
from gearcli.dynamics.signs import TOL_SIGN, SignError, pattern_index, resolve_signs


def _system(rng, n, m, h):
    A = rng.normal(size=(n, n)) + 2.0 * np.eye(n)
    H = rng.normal(size=(n, m)) * h
    return A, H, sorted(rng.choice(n, m, replace=False).tolist())


def _matrix(A, H, cols, signs):
    M = A.copy()
    for i, c in enumerate(cols):
        M[:, c] += signs[i] * H[:, i]
    return M


def _exhaustive(A, H, cols, r):
    """Per sample the list of (signs, x) whose t agree with their pattern."""
    m = len(cols)
    scale = 1.0 + np.abs(r).max(axis=1)
    out = [[] for _ in range(r.shape[0])]
    for signs in itertools.product((1.0, -1.0), repeat=m):
        x = np.linalg.solve(_matrix(A, H, cols, signs), r.T).T
        ok = np.all(-np.array(signs) * x[:, cols] <= TOL_SIGN * scale[:, None], axis=1)
        for s in np.flatnonzero(ok):
            out[s].append((signs, x[s]))
    return out


@pytest.mark.parametrize("seed", range(40))
def test_search_equals_the_exhaustive_rule(seed):
    rng = np.random.default_rng(seed)
    n, m = int(rng.integers(2, 7)), 0
    m = int(rng.integers(1, n + 1))
    A, H, cols = _system(rng, n, m, h=float(rng.choice([0.3, 1.0, 3.0])))
    r = rng.normal(size=(64, n))
    every = _exhaustive(A, H, cols, r)

    def solve_pattern(signs, idx):
        return np.linalg.solve(_matrix(A, H, cols, signs), r[idx].T).T

    scale = 1.0 + np.abs(r).max(axis=1)
    none = [s for s, sols in enumerate(every) if not sols]
    if none:                                     # the search must fail at the first such sample
        with pytest.raises(SignError) as info:
            resolve_signs(solve_pattern, m, cols, 64, scale, ["'g'"] * m)
        assert info.value.sample == none[0]
        keep = np.array([s for s in range(64) if every[s]])
        if keep.size == 0:
            return
        r, every, scale = r[keep], [every[s] for s in keep], scale[keep]
    x, used = resolve_signs(solve_pattern, m, cols, r.shape[0], scale, ["'g'"] * m)
    for s, sols in enumerate(every):
        found = [xs for signs, xs in sols if pattern_index(signs) == pattern_index(used[s])]
        assert found, "the search accepted a pattern the exhaustive rule rejects"
        np.testing.assert_allclose(x[s], found[0], rtol=0, atol=1e-9 * (1 + np.abs(found[0]).max()))
        if len(sols) == 1:
            assert pattern_index(used[s]) == pattern_index(sols[0][0])


def test_the_random_systems_cover_every_case():
    """Among the systems above: samples with no, one and several consistent patterns."""
    kinds = set()
    for seed in range(40):
        rng = np.random.default_rng(seed)
        n = int(rng.integers(2, 7))
        m = int(rng.integers(1, n + 1))
        A, H, cols = _system(rng, n, m, h=float(rng.choice([0.3, 1.0, 3.0])))
        kinds |= {min(len(s), 2) for s in _exhaustive(A, H, cols, rng.normal(size=(64, n)))}
    assert kinds == {0, 1, 2}


@pytest.mark.parametrize("redundant", [False, True])
@pytest.mark.parametrize("seed", range(10))
def test_low_rank_equals_the_pattern_maps(seed, redundant):
    """LowRank.solve (one base matrix, a k x k solve a pattern) against PatternMaps' own
    inverse (or least-load map) of every pattern."""
    rng = np.random.default_rng(100 + seed)
    rows, m = 6, int(rng.integers(1, 5))
    n = rows + (2 if redundant else 0)
    A_mid = rng.normal(size=(rows, n)) + np.eye(rows, n) * 2.0
    halves = rng.normal(size=(m, rows)) * 0.5
    cols = sorted(rng.choice(n, m, replace=False).tolist())
    w = np.where(np.isin(np.arange(n), cols), 1.0, 0.0) + (np.arange(n) >= rows) if redundant else None
    maps = PatternMaps(A_mid, halves, cols, w)
    lr = low_rank(maps)
    r = rng.normal(size=(5, rows))
    for k, signs in enumerate(itertools.product((1.0, -1.0), repeat=m)):
        direct = r @ maps[k].T
        np.testing.assert_allclose(lr.solve(signs, r), direct, rtol=0, atol=1e-11 * (1 + np.abs(direct).max()))
