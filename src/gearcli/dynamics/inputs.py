"""The sample arrays given to :func:`gearcli.solve` and to forward dynamics: shapes, and
values that are finite.

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
    joints = joint_names(an)
    return sample_arrays({"q": (q, an.dof, joints), "qd": (qd, an.dof, joints), "qdd": (qdd, an.dof, joints)},
                         check_finite, " (check_finite=False lets it through)")


def joint_names(an) -> list[str]:
    """The independent joints as errors name them (``joint 'J1'``)."""
    return [f"joint '{n}'" for n in an.independent_names]


def sample_arrays(named: dict, check_finite: bool = True, hint: str = "") -> list[np.ndarray]:
    """The arrays of ``named`` {name: (array, width, column names)} as float (N, width) (a
    1-D array is one sample); ValueError for a bad shape, then different sample counts,
    then (``check_finite``) a value that is not finite (the first, by array, sample and
    column name; ``hint`` ends that message)."""
    out = []
    for name, (given, width, _) in named.items():
        x = np.asarray(given, float)
        if x.ndim == 1:
            x = x[None, :]
        if x.ndim != 2 or x.shape[1] != width:
            raise ValueError(f"expected {name} with shape (N, {width}) or ({width},), got {np.shape(given)}")
        out.append(x)
    if len({x.shape[0] for x in out}) != 1:
        raise ValueError(f"{', '.join(named)} must have the same number of samples, got {[x.shape[0] for x in out]}")
    for (name, (_, _, cols)), x in zip(named.items(), out if check_finite else ()):
        if not np.isfinite(x).all():
            i, j = np.argwhere(~np.isfinite(x))[0]
            raise ValueError(f"{name} is not finite at sample {i}, {cols[j]}: {x[i, j]}{hint}")
    return out
