"""Statics of a shaft on two supports: the split of a joint reaction between its two bearings.

The shaft is held by two supports on its axis (z of the joint frame), at z1 and z2 from the
joint origin (m, z1 != z2).  The radial forces R1 (at z1 e_z) and R2 (at z2 e_z) must carry
the joint reaction's force F and tilting moment M about the joint origin (joint frame):

    R1 + R2 = F_xy,   z1 e_z x R1 + z2 e_z x R2 = M_xy,

and e_z x R = (-R_y, R_x), so z1 R1 + z2 R2 = (M_y, -M_x) =: m.  Hence
R2 = (m - z1 F_xy) / (z2 - z1) and R1 = F_xy - R2 (N).

Used by the solve (bearing friction, :mod:`gearcli.dynamics.bearing_friction`, both paths)
and by the design checks (bearing loads, :func:`gearcli.design.evaluate.bearing_loads`).
"""
from __future__ import annotations

import numpy as np

from ..algebra import ARRAYS


def split_components(fx, fy, mx, my, z1, z2):
    """The split (module docstring), component by component: (R1x, R1y, R2x, R2y) from the
    force's and moment's x, y components (arrays of any one shape, e.g. (K, N): K shafts at
    once, with z1, z2 floats or (K, 1) arrays): :func:`split_terms` over numpy."""
    if np.any(np.asarray(z1) == np.asarray(z2)):
        raise ValueError("two bearings need different positions")
    return split_terms(ARRAYS, fx, fy, mx, my, z1, z2)


def split_terms(al, fx, fy, mx, my, z1, z2) -> tuple:
    """(R1x, R1y, R2x, R2y) of the module's shaft statics over the algebra ``al``
    (:mod:`gearcli.algebra`; the numpy path, and the kernel's bearing friction,
    :func:`gearcli.dynamics.llvm.bearings.split`): R2 = (m - z1 F_xy) / (z2 - z1) with
    m = (M_y, -M_x), R1 = F_xy - R2."""
    inv = al.div(1.0, al.sub(z2, z1))
    R2x = al.mul(al.sub(my, al.mul(z1, fx)), inv)
    R2y = al.mul(al.sub(al.neg(mx), al.mul(z1, fy)), inv)
    return al.sub(fx, R2x), al.sub(fy, R2y), R2x, R2y
