"""The constant map of a block's solution for each sign pattern of Eq. 14, made on first use.

A block written in a constant frame has the matrix A_sigma = A_mid + sum_i sigma_i H_i e_i^T
for the sign pattern sigma of its m tangential tooth forces (the separating force |t| tan phi
adds +-H_i to column i).  Its solution map X_sigma (n, 6B) is A_sigma^-1 for a square block
and the least-t^2/k map of :func:`.sharing.least_load_map` for a redundant one.  There are
2^m patterns (m = 2N for N planets) but a motion meets few of them, so each map is computed
when first asked for and kept: :class:`PatternMaps` is read-only, indexed like
:func:`~.signs.sign_patterns` (:func:`~.signs.pattern_index`); iterating it computes all.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .sharing import kkt, least_load_map


class PatternMaps:
    """(n, 6B) solution map of every sign pattern of one constant block, lazily.

    ``A_mid`` (6B, n): the block matrix with each signed column at its mean over the two
    signs; ``halves`` (m, 6B): half the difference of each signed column (sign + minus
    sign -); ``cols`` (m,): the signed columns; ``w`` (n,): load-sharing weights of a
    redundant block (n > 6B), None for a square one.
    """

    def __init__(self, A_mid: np.ndarray, halves: np.ndarray, cols: list[int], w: np.ndarray | None):
        self.A_mid, self.halves, self.cols, self.w = A_mid, halves, list(cols), w
        self._maps: dict[int, np.ndarray] = {}
        self.count = 1 << len(self.cols)     # number of patterns (may exceed sys.maxsize)

    def __len__(self) -> int:
        return self.count

    def matrix(self, index: int) -> np.ndarray:
        """The block matrix A_sigma (6B, n) of pattern ``index``."""
        m = len(self.cols)
        A = self.A_mid.copy()
        for i, c in enumerate(self.cols):
            A[:, c] += (-1.0 if index >> (m - 1 - i) & 1 else 1.0) * self.halves[i]
        return A

    def __getitem__(self, index: int) -> np.ndarray:
        if not 0 <= index < self.count:
            raise IndexError(index)
        X = self._maps.get(index)
        if X is None:
            A = self.matrix(index)
            X = self._maps[index] = np.linalg.inv(A) if self.w is None else least_load_map(A, self.w)
        return X

    def __iter__(self):
        return (self[i] for i in range(len(self)))


@dataclass(frozen=True, eq=False)
class LowRank:
    """Every sign pattern's solution of one constant block from one base matrix (Woodbury).

    The block matrix of pattern sigma differs from A_mid (every signed column at its mean
    over the two signs: the separating-force-free matrix) by a term of rank m, or 2m for a
    redundant block (the KKT matrix K of :mod:`.sharing` holds A twice):

        K_sigma = K + P C_sigma P^T,   C_sigma = diag(sigma)  (square, K = A_mid, P = H),
        C_sigma = [[0, diag sigma], [diag sigma, 0]]  (redundant, P = [[E, 0], [0, H]]),

    with H (6B, m) the halves of the signed columns and E their unit columns; C_sigma^-1 =
    C_sigma.  By the Woodbury identity the solution x = X_sigma r is

        y = Y r,  g = G r,  (C_sigma + W) c = g,  x = y - Z c,  t = g[:m] - W[:m] c,

    with the constant maps Y (n, 6B) = the first n rows of K^-1 [0; I] (K^-1 for a square
    block), G = V^T K^-1 [0; I] (k, 6B), Z (n, k) the first n rows of K^-1 U and W = V^T
    K^-1 U (k, k), where U = H, V = E (square) or U = V = P (redundant), k = m or 2m: a pattern costs one k x k solve instead of a stored map
    (2^m of them: 1,024 for 5 planets).  ``redundant``: which C_sigma.
    """

    Y: np.ndarray
    G: np.ndarray
    Z: np.ndarray
    W: np.ndarray
    redundant: bool

    @property
    def k(self) -> int:
        return self.W.shape[0]

    def C(self, signs) -> np.ndarray:
        """C_sigma (k, k) of the sign vector ``signs`` (m,)."""
        m = len(signs)
        if not self.redundant:
            return np.diag(np.asarray(signs, float))
        C = np.zeros((2 * m, 2 * m))
        C[:m, m:] = C[m:, :m] = np.diag(np.asarray(signs, float))
        return C

    def solve(self, signs, r: np.ndarray) -> np.ndarray:
        """x (N, n) of the rows r (N, 6B) for the sign vector ``signs`` (the kernel's twin)."""
        c = np.linalg.solve(self.C(signs) + self.W, (r @ self.G.T).T).T
        return r @ self.Y.T - c @ self.Z.T


def low_rank(maps: PatternMaps) -> LowRank:
    """The :class:`LowRank` form of a block's :class:`PatternMaps` (its A_mid, halves,
    signed columns and sharing weights).  Raises :class:`~.sharing.SharingError` (or
    numpy's LinAlgError for a square block) when the base matrix is singular."""
    A, H = maps.A_mid, maps.halves.T               # (6B, n), (6B, m)
    nr, n = A.shape
    m = len(maps.cols)
    E = np.zeros((n, m))
    E[maps.cols, range(m)] = 1.0
    if maps.w is None:                             # K + H C E^T
        Y = np.linalg.inv(A)
        V, Z = E, Y @ H
    else:                                          # K + P C P^T
        Kinv = np.linalg.inv(kkt(A, maps.w))
        V = np.zeros((n + nr, 2 * m))
        V[:n, :m], V[n:, m:] = E, H
        Y, Z = Kinv[:, n:], Kinv @ V               # K^-1 P (Y @ H would miss the top block)
    c = np.ascontiguousarray
    return LowRank(c(Y[:n]), c(V.T @ Y), c(Z[:n]), c(V.T @ Z), maps.w is not None)


HOT_PATTERNS = 8
"""Sign patterns of a :class:`LowRank` block whose maps the generated kernel keeps as a
table (the ones random motions of the mechanism meet most): a trial with one of them is a
table product, any other pattern the k x k solve."""


def hot_patterns(counts: dict) -> list[int]:
    """Pattern 0 (every t positive: the search's first trial) and the most frequent other
    patterns of ``counts`` {pattern index: samples} (ties: the lower index first),
    :data:`HOT_PATTERNS` in all."""
    rest = [k for k in sorted(sorted(counts), key=lambda k: -counts[k]) if k != 0]
    return [0] + rest[:HOT_PATTERNS - 1]
