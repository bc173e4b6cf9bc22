"""Sign resolution of the separating tooth force |t| (paper Eq. 14).

The separating force |t| tan(phi) makes the equations piecewise linear in the tangential
tooth forces t: for each sign pattern sigma of the geared meshes of a block the equations
are linear, and the solution of a sample is the one whose t agree with the pattern that
produced them.  :func:`resolve_signs` is the one algorithm that finds it, used by the
block schedule (constant-frame and general blocks) and by the full simultaneous solve.
"""
from __future__ import annotations

import itertools
from typing import Callable

import numpy as np

from ..errors import GearcliError

TOL_SIGN = 1e-12   # a t of the wrong sign up to TOL_SIGN * (1 + largest load) counts as zero


class SignError(GearcliError):
    """No sign pattern of the tangential tooth forces is consistent with its own solution.

    ``sample`` is the 0-based index of the first such sample within the solve call.
    """

    def __init__(self, sample: int, meshes: list[str]):
        super().__init__()
        self.sample = sample
        self.meshes = meshes

    def lines(self) -> list[str]:
        """The one-line message of this error."""
        return [f"sample {self.sample}: no sign pattern of the tangential tooth forces of "
                f"{', '.join(self.meshes)} agrees with its own solution (paper Eq. 14); "
                "the equations have no consistent solution there"]


def sign_patterns(m: int) -> list[tuple[float, ...]]:
    """The 2^m sign patterns of m meshes, all positive first (the search order)."""
    return list(itertools.product((1.0, -1.0), repeat=m))


MAX_EXHAUSTIVE = 16   # meshes in one block up to which every sign pattern may be tried


def pattern_index(signs) -> int:
    """Position of the sign vector ``signs`` (m,) in :func:`sign_patterns`."""
    return int(sum(1 << (len(signs) - 1 - i) for i, s in enumerate(signs) if s < 0))


def resolve_signs(solve_pattern: Callable[[np.ndarray, np.ndarray], np.ndarray], m: int,
                  t_cols: list[int], N: int, scale: np.ndarray,
                  mesh_names: list[str]) -> tuple[np.ndarray, np.ndarray]:
    """Solution of every sample with a sign pattern consistent with it.

    The search: start every sample with all t positive; a sample whose solution disagrees
    with its pattern retries with the signs of that solution (m + 1 rounds at most, which
    settles almost every sample at once); the samples left try every pattern in the order
    of :func:`sign_patterns` (up to ``MAX_EXHAUSTIVE`` meshes).  A sample is accepted by the
    first pattern whose solution's t agree with it (t of the wrong sign up to
    ``TOL_SIGN * scale`` counts as zero).

    Parameters
    ----------
    solve_pattern : callable(signs, idx) -> (len(idx), n)
        Solution of the samples ``idx`` (index array) with the signs ``signs`` (m,) of t.
    m : number of geared meshes (signed unknowns).
    t_cols : the column of each signed t in the solution.
    N : number of samples.
    scale : (N,) load scale of each sample (for the zero tolerance of t).
    mesh_names : names of the m meshes, for the error message.

    Returns
    -------
    x : (N, n) solution; signs : (N, m) sign of each t used.

    Raises
    ------
    SignError
        naming the first sample for which no pattern is consistent.
    """
    search = OwnSigns(solve_pattern, m, t_cols, N, scale)
    todo = search.settle()
    if todo.size and m <= MAX_EXHAUSTIVE:             # the rest: every pattern in order
        for signs in sign_patterns(m):
            if todo.size == 0:
                break
            todo, _ = search.attempt(todo, np.array(signs))
    if todo.size:
        raise SignError(int(todo.min()), mesh_names)   # the first such sample
    return search.x, search.used


class OwnSigns:
    """The first m + 1 trials of :func:`resolve_signs` (every t positive, then each sample's
    own signs); ``x`` (N, n) and ``used`` (N, m) hold the samples settled so far."""

    def __init__(self, solve_pattern, m: int, t_cols: list[int], N: int, scale: np.ndarray):
        self.solve_pattern, self.m, self.t_cols, self.N, self.scale = solve_pattern, m, t_cols, N, scale
        self.x, self.used = None, np.ones((N, m))

    def attempt(self, idx: np.ndarray, signs: np.ndarray):
        """Solve the samples ``idx`` with the signs ``signs`` (m,) of t and keep those it
        settles; returns the others and the signs of their own t."""
        xs = self.solve_pattern(signs, idx)
        t = xs[:, self.t_cols]
        ok = np.all(-signs * t <= (TOL_SIGN * self.scale[idx])[:, None], axis=1)
        if self.x is None:
            if ok.all():                              # the usual case: done in one solve
                self.x = xs
                return idx[:0], t[:0]
            self.x = np.empty((self.N, xs.shape[1]))
        self.x[idx[ok]] = xs[ok]
        self.used[idx[ok]] = signs
        return idx[~ok], np.where(t[~ok] < 0, -1.0, 1.0)

    def settle(self) -> np.ndarray:
        """Every sample with all t positive, then the unsettled with their own signs (m
        rounds at most); returns the samples still unsettled."""
        todo, trial = self.attempt(np.arange(self.N), np.ones(self.m))
        for _ in range(self.m):                       # retry with the solution's own signs
            if todo.size == 0:
                break
            left, nxt = [], []
            for rows in _same_rows(trial):
                bad, own = self.attempt(todo[rows], trial[rows[0]])
                left.append(bad)
                nxt.append(own)
            todo, trial = np.concatenate(left), np.concatenate(nxt)
        return todo


def rows_by_pattern(signs: np.ndarray) -> list[np.ndarray]:
    """Indices of the rows of ``signs`` (N, m) of -1/0/+1 grouped by equal rows (a motion
    meets few patterns: a loop over patterns, not samples)."""
    _, which = np.unique(signs, axis=0, return_inverse=True)
    which = which.reshape(-1)
    return [np.flatnonzero(which == u) for u in range(which.max() + 1)]


def _same_rows(signs: np.ndarray) -> list[np.ndarray]:
    """Indices of the rows of ``signs`` (n, m) of +-1 grouped by equal rows."""
    m = signs.shape[1]
    if m > 60:                                       # too many bits for an integer key
        return rows_by_pattern(signs)
    key = (signs < 0) @ (1 << np.arange(m, dtype=np.int64))
    order = np.argsort(key, kind="stable")
    cuts = np.flatnonzero(np.diff(key[order])) + 1
    return np.split(order, cuts)


def sign_violation(t: np.ndarray, signs: np.ndarray, scale: np.ndarray) -> float:
    """Worst relative disagreement between solved t (N, m) and the signs used (N, m)."""
    if t.size == 0:
        return 0.0
    return float(np.max(np.maximum(-signs * t, 0.0).max(axis=1) / scale))
