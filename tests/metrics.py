"""The one error metric of the numerical cross-checks.

``rel_err(a, b)`` is the largest absolute difference relative to the largest magnitude of
the reference ``b`` (``tiny`` guards an all-zero reference):

    rel_err(a, b) = max|a - b| / max(max|b|, tiny)

It is scale-free (a tolerance means the same for N, N*m or rad/s^2) and one number per
array, so a small component of a large vector is judged against the vector's size.
"""
from __future__ import annotations

import numpy as np

TINY = 1e-300


def rel_err(a, b, tiny: float = TINY) -> float:
    """max|a - b| / max(max|b|, tiny) over all elements (a, b broadcast)."""
    a, b = np.broadcast_arrays(np.asarray(a, float), np.asarray(b, float))
    if a.size == 0:
        return 0.0
    return float(np.max(np.abs(a - b)) / max(float(np.max(np.abs(b))), tiny))
