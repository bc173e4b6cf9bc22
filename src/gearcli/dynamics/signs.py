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
        return [f"sample {self.sample}: no sign pattern of the tangential tooth forces of "
                f"{', '.join(self.meshes)} agrees with its own solution (paper Eq. 14); "
                "the equations have no consistent solution there"]


def sign_patterns(m: int) -> list[tuple[float, ...]]:
    """The 2^m sign patterns of m meshes, all positive first (the search order)."""
    return list(itertools.product((1.0, -1.0), repeat=m))


def resolve_signs(solve_pattern: Callable[[int, np.ndarray], np.ndarray], m: int,
                  t_cols: list[int], N: int, scale: np.ndarray,
                  mesh_names: list[str]) -> tuple[np.ndarray, np.ndarray]:
    """Solution of every sample with a sign pattern consistent with it.

    The search: start every sample with all t positive; a sample whose solution disagrees
    with its pattern retries with the signs of that solution (m + 1 rounds at most, which
    settles almost every sample at once); the samples left try every pattern in the order
    of :func:`sign_patterns`.  A sample is accepted by the first pattern whose solution's t
    agree with it (t of the wrong sign up to ``TOL_SIGN * scale`` counts as zero).

    Parameters
    ----------
    solve_pattern : callable(k, idx) -> (len(idx), n)
        Solution of the samples ``idx`` (index array) with sign pattern ``k`` of
        :func:`sign_patterns`.
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
    patterns = np.array(sign_patterns(m)).reshape(2 ** m, m)
    weights = 2 ** np.arange(m - 1, -1, -1)          # pattern index from its minus signs
    x = None
    pick = np.full(N, -1)
    todo, k_of = np.arange(N), np.zeros(N, int)

    def attempt(idx, k):
        nonlocal x
        xs = solve_pattern(k, idx)
        if x is None:
            x = np.empty((N, xs.shape[1]))
        t = xs[:, t_cols]
        ok = np.all(-patterns[k] * t <= (TOL_SIGN * scale[idx])[:, None], axis=1)
        x[idx[ok]] = xs[ok]
        pick[idx[ok]] = k
        return idx[~ok], ((t[~ok] < 0) * weights).sum(axis=1)

    for _ in range(m + 1):                            # retry with the solution's own signs
        if todo.size == 0:
            break
        left, nxt = [], []
        for k in np.unique(k_of[todo]):
            bad, kk = attempt(todo[k_of[todo] == k], int(k))
            left.append(bad)
            nxt.append(kk)
        todo = np.concatenate(left)
        k_of[todo] = np.concatenate(nxt)
    for k in range(len(patterns)):                    # the rest: every pattern in order
        if todo.size == 0:
            break
        todo, _ = attempt(todo, k)
    if todo.size:
        raise SignError(int(todo[0]), mesh_names)
    return x, patterns[pick]


def sign_violation(t: np.ndarray, signs: np.ndarray, scale: np.ndarray) -> float:
    """Worst relative disagreement between solved t (N, m) and the signs used (N, m)."""
    if t.size == 0:
        return 0.0
    return float(np.max(np.maximum(-signs * t, 0.0).max(axis=1) / scale))
