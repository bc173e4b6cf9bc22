"""Kinematics of every link along a trajectory, vectorised over samples.

All quantities are in the base frame ("world"), arrays shaped ``(N, 3)`` or ``(N, 3, 3)``:

* ``R[i]``  rotation of link i's frame,  ``o[i]`` its origin (m);
* ``w[i]``  angular velocity (rad/s),     ``dw[i]`` angular acceleration (rad/s^2);
* ``a[i]``  acceleration of the origin o_i (m/s^2);
* ``Rj[J]``, ``oj[J]`` the joint frame of joint J (fixed in the child; z = joint axis).

The recursion is Walker and Orin's (paper Eqs. 2-5), written for a general tree of joints
with arbitrary fixed transforms, so primary and secondary links (paper Eqs. 10-11) are
handled alike and no centre of mass needs to lie on an axis.  One joint's terms,
:func:`joint_frame` and :func:`child_motion`, are written once over the algebra of
:mod:`gearcli.algebra`: :func:`forward` evaluates them over all samples, the generated
kernel emits them per sample (:func:`gearcli.dynamics.llvm.links.joint`).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..model.mechanism import Mechanism
from ..algebra import algebra_for, matrices, stack_matrices, stack_vectors, vectors
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
    terms: dict | None = None          # per link (R, o, w, dw, a) as values of :class:`gearcli.algebra.Arrays`
    frames: dict | None = None         # per joint (R_j, o_j, cos, sin), the same

    def link_terms(self, L: int) -> tuple:
        """Link L's (R, o, w, dw, a) as values of :class:`gearcli.algebra.Arrays` (a 9-tuple and
        3-tuples: floats where constant, else (N,) arrays; at one sample every value a float,
        :class:`gearcli.algebra.Floats`), for the shared physics terms."""
        if self.terms is not None and L in self.terms:
            return self.terms[L]
        return (matrices(self.R[L]),) + tuple(vectors(x) for x in (self.o[L], self.w[L], self.dw[L], self.a[L]))

    def joint_axis(self, ji: int) -> tuple:
        """Joint ji's axis z and origin o_j (base frame) as 3-vectors of :class:`gearcli.algebra.Arrays`."""
        if self.frames is not None and ji in self.frames:
            Rj, oj = self.frames[ji][:2]
            return (Rj[2], Rj[5], Rj[8]), oj
        return vectors(self.Rj[ji][:, :, 2]), vectors(self.oj[ji])

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


EYE = (1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0)
ZERO3 = (0.0, 0.0, 0.0)
"""The base at rest: identity axes, zero origin, velocities and accelerations (constants)."""


def forward(mech: Mechanism, tree: Tree, q: np.ndarray, qd: np.ndarray | None = None,
            qdd: np.ndarray | None = None, qd_ind: np.ndarray | None = None) -> Kinematics:
    """Positions, velocities, accelerations of all links for joint values ``q`` (N, J).

    ``q``, ``qd``, ``qdd`` hold every real joint's coordinate (rad, rad/s, rad/s^2) in the
    order of ``mech.joints``; velocities and accelerations default to zero.  Each joint's
    terms are :func:`joint_frame` and :func:`child_motion` over all samples at once (the
    kernel emits the same functions per sample, :mod:`.llvm.links`).
    """
    q = np.atleast_2d(np.asarray(q, float))
    N = q.shape[0]
    qd = np.zeros_like(q) if qd is None else np.atleast_2d(qd)
    qdd = np.zeros_like(q) if qdd is None else np.atleast_2d(qdd)
    al = algebra_for(N)      # one sample: Python floats (the per-operation cost of numpy avoided)
    cols = [x[0].tolist() if N == 1 else np.ascontiguousarray(x.T) for x in (q, qd, qdd)]  # per joint its (N,) values
    links: dict = {tree.base: (EYE, ZERO3, ZERO3, ZERO3, ZERO3)}  # per link (R, o, w, dw, a)
    frames: dict = {}
    for ji in tree.order:
        jt = mech.joints[ji]
        p, c = tree.parent[tree.index[jt.child]], tree.index[jt.child]
        prismatic = jt.type == "prismatic"
        R_p, o_p, w_p, dw_p, a_p = links[p]
        Rj, oj, _, _ = frames[ji] = joint_frame(al, matrices(jt.R_pj), vectors(jt.p_pj), R_p, o_p, cols[0][ji],
                                                prismatic)
        links[c] = child_motion(al, Rj, oj, matrices(jt.R_jc), vectors(jt.p_jc), o_p, w_p, dw_p, a_p,
                                cols[1][ji], cols[2][ji], prismatic)
    L, J = len(tree.links), len(mech.joints)
    parts = [[stack_matrices(links[i][0], N) if i in links else None for i in range(L)]]
    parts += [[stack_vectors(links[i][k], N) if i in links else None for i in range(L)] for k in range(1, 5)]
    Rj = [stack_matrices(frames[j][0], N) if j in frames else None for j in range(J)]
    oj = [stack_vectors(frames[j][1], N) if j in frames else None for j in range(J)]
    return Kinematics(*parts, Rj, oj, qd, None if qd_ind is None else np.atleast_2d(np.asarray(qd_ind, float)),
                      terms=links, frames=frames)


def joint_frame(al, R_pj, p_pj, R_p, o_p, q, prismatic: bool):
    """(R_j, o_j, cos q, sin q): joint j's frame at its coordinate q, base axes (Eq. 2).

    The frame at q = 0 is fixed in the parent p (``R_pj``, ``p_pj`` in p's frame; ``R_p``,
    ``o_p`` the parent's orientation and origin); a revolute joint turns it about its z by q,
    R_j = R_p R_pj Rz(q) (by columns: c x0 + s y0, c y0 - s x0, z0), a prismatic joint moves
    its origin along z by q.  ``al``: the algebra (:mod:`gearcli.algebra`)."""
    R0 = al.mm(R_p, R_pj)
    oj = al.vadd(o_p, al.mv(R_p, p_pj))
    if prismatic:
        return R0, al.vadd(oj, al.scale((R0[2], R0[5], R0[8]), q)), 1.0, 0.0
    cq, sq = al.sincos(q)
    Rj = []
    for i in range(3):
        r0, r1 = R0[3 * i], R0[3 * i + 1]
        Rj += [al.add(al.mul(cq, r0), al.mul(sq, r1)), al.sub(al.mul(cq, r1), al.mul(sq, r0)), R0[3 * i + 2]]
    return tuple(Rj), oj, cq, sq


def arm_acceleration(al, a, dw, w, r):
    """a + dw x r + w x (w x r): the acceleration of a point at r from a point of acceleration
    a on a body turning at w, dw (base axes)."""
    return al.vadd(a, al.vadd(al.cx(dw, r), al.cx(w, al.cx(w, r))))


def child_motion(al, R_j, o_j, R_jc, p_jc, o_p, w_p, dw_p, a_p, qd, qdd, prismatic: bool):
    """(R_c, o_c, w_c, dw_c, a_c) of a joint's child link, base axes (paper Eqs. 3-5).

    From the joint frame (R_j, o_j) of :func:`joint_frame` (z = the axis), the child's fixed
    place in it (``R_jc``, ``p_jc``), the parent's origin, angular velocity and acceleration
    and its origin's acceleration, and the joint rate and acceleration q', q'':
    revolute w_c = w_p + z q', dw_c = dw_p + z q'' + (w_p x z) q'; prismatic w_c = w_p,
    dw_c = dw_p and the joint origin gains z q'' + 2 w_p x (z q') (Coriolis).  The
    accelerations of the joint origin and of the child's origin follow the arms
    (:func:`arm_acceleration`)."""
    z = (R_j[2], R_j[5], R_j[8])
    aj = arm_acceleration(al, a_p, dw_p, w_p, al.vsub(o_j, o_p))
    if prismatic:
        wc, dwc = w_p, dw_p
        aj = al.vadd(aj, al.vadd(al.scale(z, qdd), al.scale(al.cx(w_p, al.scale(z, qd)), 2.0)))
    else:
        wc = al.vadd(w_p, al.scale(z, qd))
        dwc = al.vadd(al.vadd(dw_p, al.scale(z, qdd)), al.scale(al.cx(w_p, z), qd))
    rc = al.mv(R_j, p_jc)
    return al.mm(R_j, R_jc), al.vadd(o_j, rc), wc, dwc, arm_acceleration(al, aj, dwc, wc, rc)
