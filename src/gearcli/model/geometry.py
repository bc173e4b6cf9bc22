"""Joint geometry: the fixed transforms of a joint, from D-H parameters (paper Eqs. 1, 7)
or from a URDF-style origin and axis.

A joint is stored as four fixed parts (see :class:`~gearcli.model.mechanism.Joint`): the
joint frame in the parent frame (``R_pj``, ``p_pj``; z is the joint axis) and the child
frame in the joint frame (``R_jc``, ``p_jc``).  The motion Rz(q) (revolute) or Tz(q)
(prismatic) acts between the two, so the child frame in the parent frame is
``T_pc(q) = [R_pj, p_pj] * Rz(q) * [R_jc, p_jc]``.
"""
from __future__ import annotations

import numpy as np

from ..spatial import align_z, rot_x, rot_z, rpy_matrix


def dh_transform(theta: float, d: float, a: float, alpha: float):
    """Fixed parts of a Denavit-Hartenberg joint (paper Eq. 1 / Eq. 7, ERRATA 1).

    The homogeneous transform of the child frame in the parent frame is
    ``Rz(theta + q) Tz(d) Tx(a) Rx(alpha)``, whose rotation has third row
    ``[0, sin(alpha), cos(alpha)]``.

    Parameters
    ----------
    theta : joint angle offset, rad (the motion q is added to it).
    d : offset along the parent's z, m.
    a : link length along the child's x, m.
    alpha : twist about the child's x, rad.

    Returns
    -------
    R_pj (3, 3), p_pj (3,), R_jc (3, 3), p_jc (3,)
        The joint frame is Rz(theta) Tz(d) of the parent frame; the child frame is
        Tx(a) Rx(alpha) of the (turned) joint frame.
    """
    return rot_z(theta), np.array([0.0, 0.0, d]), rot_x(alpha), np.array([a, 0.0, 0.0])


def origin_axis_transform(xyz, rpy, axis):
    """Fixed parts of a URDF-style joint: origin ``xyz`` (m) and ``rpy`` (rad) in the parent
    frame, rotation axis ``axis`` (unit or not, non-zero) in that origin frame.

    The joint frame is the origin frame turned so that its z is the axis; the child frame
    is the origin frame itself.  Returns R_pj, p_pj, R_jc, p_jc as :func:`dh_transform`.
    """
    A = align_z(np.asarray(axis, float))
    return rpy_matrix(rpy) @ A, np.asarray(xyz, float), A.T, np.zeros(3)
