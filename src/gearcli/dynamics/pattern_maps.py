"""The constant map of a block's solution for each sign pattern of Eq. 14, made on first use.

A block written in a constant frame has the matrix A_sigma = A_mid + sum_i sigma_i H_i e_i^T
for the sign pattern sigma of its m tangential tooth forces (the separating force |t| tan phi
adds +-H_i to column i).  Its solution map X_sigma (n, 6B) is A_sigma^-1 for a square block
and the least-t^2/k map of :func:`.sharing.least_load_map` for a redundant one.  There are
2^m patterns (m = 2N for N planets) but a motion meets few of them, so each map is computed
when first asked for and kept: :class:`PatternMaps` is a read-only sequence indexed like
:func:`~.signs.sign_patterns` (:func:`~.signs.pattern_index`); iterating it computes all.
"""
from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .sharing import least_load_map


class PatternMaps(Sequence):
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

    def __getitem__(self, index):
        if isinstance(index, slice):
            return [self[i] for i in range(*index.indices(len(self)))]
        if index < 0:
            index += self.count
        if not 0 <= index < self.count:
            raise IndexError(index)
        X = self._maps.get(index)
        if X is None:
            A = self.matrix(index)
            X = self._maps[index] = np.linalg.inv(A) if self.w is None else least_load_map(A, self.w)
        return X

    def __iter__(self):
        return (self[i] for i in range(len(self)))
