"""Kinematics of every link along a trajectory, vectorised over samples.

All quantities are in the base frame ("world"), arrays shaped ``(N, 3)`` or ``(N, 3, 3)``:

* ``R[i]``  rotation of link i's frame,  ``o[i]`` its origin (m);
* ``w[i]``  angular velocity (rad/s),     ``dw[i]`` angular acceleration (rad/s^2);
* ``a[i]``  acceleration of the origin o_i (m/s^2);
* ``Rj[J]``, ``oj[J]`` the joint frame of joint J (fixed in the child; z = joint axis).

The recursion is Walker and Orin's (paper Eqs. 2-5), written for a general tree of joints
with arbitrary fixed transforms, so primary and secondary links (paper Eqs. 10-11) are
handled alike and no centre of mass needs to lie on an axis.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..model.mechanism import Mechanism
from ..spatial import cross, mm_const, mv
from ..analysis.tree import Tree


@dataclass
class Kinematics:
    """Kinematics of every link and joint along N samples, all in the base frame.

    Per link i (lists indexed by link id): ``R[i]`` (N, 3, 3) orientation R_0i of its frame;
    ``o[i]`` (N, 3) origin, m; ``w[i]`` (N, 3) angular velocity omega_i, rad/s; ``dw[i]``
    (N, 3) angular acceleration, rad/s^2; ``a[i]`` (N, 3) acceleration of the origin, m/s^2.
    Per real joint j (indexed as ``mech.joints``): ``Rj[j]`` (N, 3, 3) joint frame (z = axis)
    and ``oj[j]`` (N, 3) its origin, m.
    """

    R: list
    o: list
    w: list
    dw: list
    a: list
    Rj: list
    oj: list
    qd: np.ndarray | None = None       # (N, J) every real joint's rate, rad/s (m/s)
    qd_ind: np.ndarray | None = None   # (N, dof) the independent rates, when the caller had them

    def independent_rates(self, an) -> np.ndarray:
        """(N, dof) the independent joint rates q'_ind: as given to :func:`forward`, else
        read off the real joint rates when every independent coordinate is a real joint."""
        if self.qd_ind is not None:
            return self.qd_ind
        if self.qd is not None and all(j >= 0 for j in an.independent):
            return self.qd[:, list(an.independent)]
        if self.qd is not None and not self.qd.any():    # at rest: q' = S q'_ind = 0 gives q'_ind = 0
            return np.zeros((self.qd.shape[0], an.dof))
        raise ValueError("the kinematics were made without the independent joint rates "
                         "(forward(..., qd_ind=...)), which relative mesh rates need")

    @property
    def n(self) -> int:
        """Number of samples N."""
        return self.oj[0].shape[0]


def forward(mech: Mechanism, tree: Tree, q: np.ndarray, qd: np.ndarray | None = None,
            qdd: np.ndarray | None = None, qd_ind: np.ndarray | None = None) -> Kinematics:
    """Positions, velocities, accelerations of all links for joint values ``q`` (N, J).

    ``q``, ``qd``, ``qdd`` hold every real joint's coordinate (rad, rad/s, rad/s^2) in the
    order of ``mech.joints``; velocities and accelerations default to zero.
    """
    q = np.atleast_2d(np.asarray(q, float))
    N = q.shape[0]
    qd = np.zeros_like(q) if qd is None else np.atleast_2d(qd)
    qdd = np.zeros_like(q) if qdd is None else np.atleast_2d(qdd)
    L = len(tree.links)
    zero = np.zeros((N, 3))
    R = [None] * L
    o = [None] * L
    w = [None] * L
    dw = [None] * L
    a = [None] * L
    b = tree.base
    R[b] = np.broadcast_to(np.eye(3), (N, 3, 3))
    o[b], w[b], dw[b], a[b] = zero, zero, zero, zero
    Rj = [None] * len(mech.joints)
    oj = [None] * len(mech.joints)
    for ji in tree.order:
        jt = mech.joints[ji]
        p, c = tree.parent[tree.index[jt.child]], tree.index[jt.child]
        on_base = p == b                          # parent at rest: skip the zero terms
        if on_base:
            Rj0 = np.broadcast_to(jt.R_pj, (N, 3, 3))   # (N,3,3) joint frame at q = 0
            oj0 = np.broadcast_to(jt.p_pj, (N, 3))      # (N,3) joint origin
        else:
            Rj0 = mm_const(R[p], jt.R_pj)
            oj0 = o[p] + mv(R[p], jt.p_pj)
        z = np.ascontiguousarray(Rj0[:, :, 2])    # (N,3) joint axis
        qd_j, qdd_j = qd[:, ji:ji + 1], qdd[:, ji:ji + 1]
        if jt.type == "prismatic":
            Rj[ji] = Rj0
            oj[ji] = oj0 + z * q[:, ji:ji + 1]
            w[c], dw[c] = w[p], dw[p]
        else:
            Rj[ji] = _turn_z(Rj0, q[:, ji])
            oj[ji] = oj0
            if on_base:
                w[c], dw[c] = z * qd_j, z * qdd_j
            else:
                w[c] = w[p] + z * qd_j
                dw[c] = dw[p] + z * qdd_j + cross(w[p], z) * qd_j
        R[c] = Rj[ji] if np.array_equal(jt.R_jc, np.eye(3)) else mm_const(Rj[ji], jt.R_jc)
        if on_base:
            a_j = zero
        else:
            r = oj[ji] - o[p]
            a_j = a[p] + cross(dw[p], r) + cross(w[p], cross(w[p], r))
        if jt.type == "prismatic":
            a_j = a_j + z * qdd_j
            if not on_base:
                a_j = a_j + 2 * cross(w[p], z * qd_j)
        if not np.any(jt.p_jc):
            o[c], a[c] = oj[ji], a_j
        else:
            rc = mv(Rj[ji], jt.p_jc)
            o[c] = oj[ji] + rc
            a[c] = a_j + cross(dw[c], rc) + cross(w[c], cross(w[c], rc))
    return Kinematics(R, o, w, dw, a, Rj, oj, qd,
                      None if qd_ind is None else np.atleast_2d(np.asarray(qd_ind, float)))


def _turn_z(R0: np.ndarray, q: np.ndarray) -> np.ndarray:
    """R0 @ Rz(q) for R0 (N,3,3) and angles q (N,), by columns."""
    c, s = np.cos(q)[:, None], np.sin(q)[:, None]
    out = np.empty(R0.shape)
    out[:, :, 0] = c * R0[:, :, 0] + s * R0[:, :, 1]
    out[:, :, 1] = c * R0[:, :, 1] - s * R0[:, :, 0]
    out[:, :, 2] = R0[:, :, 2]
    return out
