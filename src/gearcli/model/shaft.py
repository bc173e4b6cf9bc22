"""Statics of a shaft on two supports: the split of a joint reaction between its two bearings.

Used by the solve (bearing friction, :mod:`gearcli.dynamics.bearing_friction`) and by the
design checks (bearing loads, :mod:`gearcli.design.bearings`).
"""
from __future__ import annotations

import numpy as np


def split_two_bearings(F, M, z1: float, z2: float) -> tuple[np.ndarray, np.ndarray]:
    """Radial force vectors on two bearings at z1 and z2 along the joint axis.

    The shaft is held by two supports on its axis (z of the joint frame).  The radial
    forces R1 (at z1 e_z) and R2 (at z2 e_z) must carry the joint reaction's force and
    tilting moment about the joint origin:

        R1 + R2 = F_xy,   z1 e_z x R1 + z2 e_z x R2 = M_xy,

    and e_z x R = (-R_y, R_x), so z1 R1 + z2 R2 = (M_y, -M_x) =: m.  Hence
    R2 = (m - z1 F_xy) / (z2 - z1) and R1 = F_xy - R2.

    Parameters
    ----------
    F, M : array_like, shape (N, 3)
        Reaction force (N) and moment about the joint origin (N*m), joint frame.
    z1, z2 : float
        Bearing positions along the joint axis from the joint origin, m (z1 != z2).

    Returns
    -------
    R1, R2 : ndarray, shape (N, 2)
        x, y components of the radial force on each bearing, N.
    """
    F, M = np.asarray(F, float), np.asarray(M, float)
    R1x, R1y, R2x, R2y = split_components(F[:, 0], F[:, 1], M[:, 0], M[:, 1], z1, z2)
    return np.column_stack([R1x, R1y]), np.column_stack([R2x, R2y])


def split_components(fx, fy, mx, my, z1, z2):
    """:func:`split_two_bearings` component by component: (R1x, R1y, R2x, R2y) from the
    force's and moment's x, y components (arrays of any one shape, e.g. (K, N): K shafts at
    once, with z1, z2 floats or (K, 1) arrays), R2 = (m - z1 F_xy) / (z2 - z1), m = (M_y, -M_x),
    R1 = F_xy - R2."""
    if np.any(np.asarray(z1) == np.asarray(z2)):
        raise ValueError("two bearings need different positions")
    R2x = (my - z1 * fx) / (z2 - z1)
    R2y = (-mx - z1 * fy) / (z2 - z1)
    return fx - R2x, fy - R2y, R2x, R2y
