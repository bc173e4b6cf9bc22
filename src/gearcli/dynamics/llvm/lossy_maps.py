"""The changed matrix's maps of the (sign pattern, s_v) pairs a many-mesh lossy block meets
most, made with the kernel's program for :class:`.hot_pairs.HotLossyBlock` (numpy only).

A constant-frame block with lossy meshes and too many (s_v, sigma) pairs to store every map
(:data:`.loss_program.MAX_TABLE`) solves each sample by the rank-ml correction of
:class:`~.losses.LossyBlock` around its lossless map X_sigma.  With the pair fixed, that
solution is one linear map of the block's right-hand side r,

    L = X - (X Phi^T) D (1 + M_l D)^-1 X[lt],    M_l = (X Phi^T)[lt],  D = diag(sigma s_v),

(lt the lossy meshes' t rows; :func:`lossy_map`, the twin of ``LossyBlock._exact`` and
``full``), whose entries are 0 wherever X's are on the bundled planetaries (Phi's few
nonzero entries sit on coaxial moment rows): a product with L costs what a lossless hot
pattern's does (:class:`~.world.LowRankBlock`).  Random motions of a planetary meet few
pairs (planetary_5p: its 3 hot patterns, each with the 2 s_v codes of the sign of its
rate), so the kernel keeps the maps of :data:`HOT` pairs of the mechanism's own random
motions (:func:`hot_lossy_maps`: pattern 0, every search's first trial, with each s_v code
met, then the pairs met most; a hint for speed, not a result: every other pair takes the
correction as before).  planetary_5p with mesh and joint friction, 20,000 random states:
+31 % -> +16 % over the lossless kernel (same run).
"""
from __future__ import annotations

from collections import Counter

import numpy as np

from ..losses import relative_rate

HOT = 8
"""(sign pattern, s_v code) pairs of one block whose changed map the kernel stores."""


def pair_key(pattern: int, code: int, ml: int) -> int:
    """The kernel's key of a (sign pattern, s_v code) pair: pattern 3^ml + code, code =
    sum_i (s_v,i + 1) 3^i over the block's lossy meshes (:attr:`.loss_program.BlockLosses.rates` order)."""
    return pattern * 3 ** ml + code


def lossy_map(X: np.ndarray, phi: np.ndarray, lt: list, d: np.ndarray) -> np.ndarray | None:
    """L (module docstring) of the lossless map X (n, nr), couples ``phi`` (ml, nr), lossy
    t rows ``lt`` and D's diagonal ``d`` (ml,); None where 1 + M_l D is singular."""
    XF = X @ phi.T
    try:
        return X - (XF * d) @ np.linalg.solve(np.eye(len(lt)) + XF[lt] * d, X[lt])
    except np.linalg.LinAlgError:
        return None


def hot_lossy_maps(an, kin, bl, X_of, tcols: list, settled: np.ndarray, patterns: np.ndarray) -> tuple:
    """((key, L), ...) of block losses ``bl``: the :data:`HOT` pairs met most by the random
    motions ``kin`` (their samples ``settled`` by the lossless search, with sign pattern
    ``patterns``), ties to the lower key; ``X_of(pattern)``: the lossless map."""
    ml, m = len(bl.positions), len(tcols)
    code = np.zeros(len(settled), np.int64)
    for i, ci in enumerate(bl.circuits):
        code += (np.sign(relative_rate(an, kin, ci)[settled]).astype(np.int64) + 1) * 3 ** i
    counts = Counter(pair_key(int(p), int(c), ml) for p, c in zip(patterns, code))
    lt = [tcols[i] for i in bl.positions]
    out = []
    codes = Counter(int(c) for c in code)          # pattern 0 of each code first: every search's first trial
    first = [pair_key(0, c, ml) for c in sorted(sorted(codes), key=lambda c: -codes[c])]
    rest = [k for k in sorted(sorted(counts), key=lambda k: -counts[k]) if k not in first]
    for key in (first + rest)[:HOT]:
        p, c = divmod(key, 3 ** ml)
        sv = np.array([c // 3 ** i % 3 - 1 for i in range(ml)], float)
        L = lossy_map(X_of(p), bl.phi, lt, np.array([-1.0 if p >> (m - 1 - i) & 1 else 1.0 for i in bl.positions]) * sv)
        if L is not None and np.isfinite(L).all():
            out.append((key, np.ascontiguousarray(L)))
    return tuple(out)
