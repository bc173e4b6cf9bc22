"""Generalised joint efforts from a solved :class:`~gearcli.dynamics.solve.Result`."""
from __future__ import annotations

import numpy as np


def joint_efforts(an, res) -> np.ndarray:
    """(N, J) generalised force on every real joint about (along) its axis, on the child:
    the sum of the motors acting on it and the ideal couplings of its coordinate (N*m, N).

    Valid when every motor acts on real joints (a transmission motor, or a motor whose stator
    is its link's joint parent) and every ideal pair is a joint coupling (``GearPair.joints``):
    true for every URDF import.  Together with ``Result.joint`` it gives the whole wrench each
    joint transmits (what Pinocchio calls ``data.f``).
    """
    mech, tree = an.mech, an.tree
    N = res.motor.shape[0]
    out = np.zeros((N, len(mech.joints)))
    for mi in range(len(an.motor_links)):
        mj = an.motor_joints[mi] if an.motor_joints else None
        if mj is None:
            ji = tree.parent_joint[an.motor_links[mi]]
            if tree.parent[an.motor_links[mi]] != an.motor_stators[mi]:
                raise ValueError(f"motor '{mech.motors[mi].name}' does not act on one real joint")
            mj = ((ji, 1.0),)
        for ji, c in mj:
            out[:, ji] += c * res.motor[:, mi]
    for ci, c in enumerate(an.circuits):
        if c.joints is None:
            if c.geometry is None:
                raise ValueError(f"ideal pair '{mech.gears[c.gear].name}' is not a joint coupling")
            continue
        b, a = c.joints
        out[:, b] += res.gear_t[:, ci]
        out[:, a] -= c.ratio * res.gear_t[:, ci]
    return out
