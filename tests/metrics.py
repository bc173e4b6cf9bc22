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


def sample_err(a, b, fields) -> float:
    """max over samples of max|a - b| / (1 + largest load of the sample), over the named
    fields of two solve results (``b`` the reference): the kernel-against-reference metric,
    judged per sample so that a quiet sample is not measured against a loud one."""
    n = b.motor.shape[0]
    fa = np.concatenate([getattr(a, f).reshape(n, -1) for f in fields], axis=1)
    fb = np.concatenate([getattr(b, f).reshape(n, -1) for f in fields], axis=1)
    return float(np.max(np.abs(fa - fb).max(axis=1) / (1.0 + np.abs(fb).max(axis=1))))


def per_sample_loads(an, n, seed=1):
    """Random per-sample values (N, 6) of the mechanism's first external load (the others
    keep their constants), or None when it has none."""
    if not an.mech.loads:
        return None
    rng = np.random.default_rng(seed)
    return {an.mech.loads[0].name: rng.normal(size=(n, 6)) * 5.0}


def nan_accelerations(qdd, count: int, seed: int = 9) -> int:
    """Put NaN into one acceleration of ``count`` random samples of ``qdd`` (N, dof), in
    place (no sign pattern fits such a sample: the SignError cases); returns the first
    such sample."""
    rng = np.random.default_rng(seed)
    for s in rng.choice(qdd.shape[0], count, replace=False):
        qdd[s, rng.integers(qdd.shape[1])] = np.nan
    return int(np.flatnonzero(np.isnan(qdd).any(axis=1))[0])
