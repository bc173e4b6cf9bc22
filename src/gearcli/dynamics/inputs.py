"""The motion arrays given to :func:`gearcli.solve`: shapes, and values that are finite.

The CLI reads and checks every value of a trajectory file (with its line and column) before
it solves; a library caller's arrays are checked here, so that a NaN or an infinity in
``q``, ``qd`` or ``qdd`` is a ``ValueError`` naming the array, the sample and the joint
instead of NaN loads (or a :class:`~.signs.SignError` at the first geared block).
``check_finite=False`` skips the value check (like scipy's ``check_finite``): for inputs
already checked, as the CLI's are.
"""
from __future__ import annotations

import numpy as np


def motion_arrays(an, q, qd, qdd, check_finite: bool = True) -> list[np.ndarray]:
    """q, qd, qdd as float arrays (N, dof) (a (dof,) array is one sample).

    Raises ValueError for a bad shape, different numbers of samples, or (``check_finite``)
    a NaN or infinite value: the first one, by array, sample index and joint name."""
    out = []
    for name, given in zip(("q", "qd", "qdd"), (q, qd, qdd)):
        x = np.asarray(given, float)
        if x.ndim == 1:
            x = x[None, :]
        if x.ndim != 2 or x.shape[1] != an.dof:
            raise ValueError(f"expected {name} with shape (N, {an.dof}) or ({an.dof},), got {np.shape(given)}")
        out.append(x)
    if len({x.shape[0] for x in out}) != 1:
        raise ValueError(f"q, qd, qdd must have the same number of samples, got {[x.shape[0] for x in out]}")
    if check_finite:
        for name, x in zip(("q", "qd", "qdd"), out):
            if not np.isfinite(x).all():
                i, j = np.argwhere(~np.isfinite(x))[0]
                raise ValueError(f"{name} is not finite at sample {i}, joint '{an.independent_names[j]}': "
                                 f"{x[i, j]} (check_finite=False lets it through)")
    return out
