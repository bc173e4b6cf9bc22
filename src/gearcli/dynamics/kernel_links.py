"""Compiled per-sample kinematics and link loads (the first half of :mod:`.kernel`).

Scalar numba code for one sample at a time, the same formulas as the array versions:
:func:`.kinematics.forward` (Walker-Orin recursion, paper Eqs. 2-5, every joint with its
fixed transforms), :func:`.inertia.inertia_wrench` (Eqs. 17-18) and
:func:`.external.external_wrenches`.  Arrays of the program: :mod:`.kernel_program`.
"""
from __future__ import annotations

import math

from numba import njit

from .kernel_math import INLINE, OPTS, add, cx, load3, load9, mm, mtv, mv, row3, row9, scale, store3, store9, sub



@njit(**INLINE)
def cross(ax, ay, az, bx, by, bz):
    """a x b of two 3-vectors given by components."""
    return ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx


@njit(**INLINE)
def joint_space(sptr, sidx, sval, qi, qdi, qddi, n, q, qd, qdd):
    """Every real joint's q, qd, qdd (J,) of sample n from the independent ones (q = S q_ind,
    S by rows of nonzeros: kernel_program._csr)."""
    for j in range(sptr.shape[0] - 1):
        s0 = 0.0
        s1 = 0.0
        s2 = 0.0
        for e in range(sptr[j], sptr[j + 1]):
            d, s = sidx[e], sval[e]
            s0 += qi[n, d] * s
            s1 += qdi[n, d] * s
            s2 += qddi[n, d] * s
        q[j] = s0
        qd[j] = s1
        qdd[j] = s2


@njit(**INLINE)
def _joint_frame(k, f, flags, Rp, op, qk, prismatic):
    """Joint frame (R, o) of joint record k at qk (kinematics.forward), base axes.

    ``flags``: 1 parent is the base, 2 R_pj = I (skipped products)."""
    if flags & 1:
        R0, oj = row9(f, k, 0), row3(f, k, 9)
    else:
        R0 = Rp if flags & 2 else mm(Rp, row9(f, k, 0))
        oj = add(op, mv(Rp, row3(f, k, 9)))
    if prismatic:
        return R0, add(oj, scale((R0[2], R0[5], R0[8]), qk)), 1.0, 0.0
    cq, sq = math.cos(qk), math.sin(qk)
    return (cq * R0[0] + sq * R0[1], cq * R0[1] - sq * R0[0], R0[2],
            cq * R0[3] + sq * R0[4], cq * R0[4] - sq * R0[3], R0[5],
            cq * R0[6] + sq * R0[7], cq * R0[7] - sq * R0[6], R0[8]), oj, cq, sq


@njit(**INLINE)
def _joint(k, jrec, f, q, qd, qdd, R, o, w, dw, a, cs):
    """The child of joint record k: R, o, w, dw, a (kinematics.forward; flags 4 R_jc = I,
    8 p_jc = 0 skip products); cs[joint] = cos, sin of its angle (reused by the blocks)."""
    ji, p, c, pr, flags = jrec[k, 0], jrec[k, 1], jrec[k, 2], jrec[k, 3] == 1, jrec[k, 4]
    qdk, qddk = qd[ji], qdd[ji]
    op, wp, ap, dwp = load3(o, p), load3(w, p), load3(a, p), load3(dw, p)
    Rj, oj, cs[ji, 0], cs[ji, 1] = _joint_frame(k, f, flags, load9(R, p), op, q[ji], pr)
    z = (Rj[2], Rj[5], Rj[8])
    r = sub(oj, op)
    aj = add(ap, add(cx(dwp, r), cx(wp, cx(wp, r))))
    if pr:
        wc, dwc = wp, dwp
        aj = add(aj, add(scale(z, qddk), scale(cx(wp, scale(z, qdk)), 2.0)))
    else:
        wc = add(wp, scale(z, qdk))
        dwc = add(add(dwp, scale(z, qddk)), scale(cx(wp, z), qdk))
    store9(R, c, Rj if flags & 4 else mm(Rj, row9(f, k, 12)))
    if flags & 8:
        store3(o, c, oj)
        store3(a, c, aj)
    else:
        rc = mv(Rj, row3(f, k, 21))
        store3(o, c, add(oj, rc))
        store3(a, c, add(aj, add(cx(dwc, rc), cx(wc, cx(wc, rc)))))
    store3(w, c, wc)
    store3(dw, c, dwc)


@njit(**INLINE)
def kinematics(jrec, jflt, q, qd, qdd, R, o, w, dw, a, cs):
    """Every link's R, o, w, dw, a of one sample (base frame; the base row stays at rest)
    and every joint's cos, sin (J, 2)."""
    for k in range(jrec.shape[0]):
        _joint(k, jrec, jflt, q, qd, qdd, R, o, w, dw, a, cs)


@njit(**INLINE)
def rot(R, L, x, y, z):
    """R[L] v."""
    return (R[L, 0, 0] * x + R[L, 0, 1] * y + R[L, 0, 2] * z,
            R[L, 1, 0] * x + R[L, 1, 1] * y + R[L, 1, 2] * z,
            R[L, 2, 0] * x + R[L, 2, 1] * y + R[L, 2, 2] * z)


@njit(**INLINE)
def inertia(L, lflt, g, R, w, dw, a, rhs):
    """rhs[L] = d'Alembert wrench of link L about o_L, base frame (inertia.inertia_wrench)."""
    m = lflt[L, 0]
    I = row9(lflt, L, 1)
    RL, wL, dwL = load9(R, L), load3(w, L), load3(dw, L)
    wb = mtv(RL, wL)
    Nb = add(mv(I, mtv(RL, dwL)), cx(wb, mv(I, wb)))   # Eq. (18), link axes
    rc = mv(RL, row3(lflt, L, 10))
    ac = add(load3(a, L), add(cx(dwL, rc), cx(wL, cx(wL, rc))))
    F = scale(sub(ac, (g[0], g[1], g[2])), m)             # Eq. (17) with gravity
    M = add(mv(RL, Nb), cx(rc, F))
    rhs[L, 0], rhs[L, 1], rhs[L, 2] = F[0], F[1], F[2]
    rhs[L, 3], rhs[L, 4], rhs[L, 5] = M[0], M[1], M[2]


@njit(**INLINE)
def external(n, ldrec, ldflt, vals, R, rhs):
    """rhs[L] -= every external load on L (base frame, about o_L) at sample n."""
    for k in range(ldrec.shape[0]):
        L = ldrec[k, 0]
        row = ldrec[k, 2] + (n if ldrec[k, 3] == 1 else 0)
        f = (vals[row, 0], vals[row, 1], vals[row, 2])
        m = (vals[row, 3], vals[row, 4], vals[row, 5])
        if ldrec[k, 1] == 1:
            f = rot(R, L, f[0], f[1], f[2])
            m = rot(R, L, m[0], m[1], m[2])
        arm = rot(R, L, ldflt[k, 0], ldflt[k, 1], ldflt[k, 2])
        e = cross(arm[0], arm[1], arm[2], f[0], f[1], f[2])
        for i in range(3):
            rhs[L, i] -= f[i]
            rhs[L, 3 + i] -= m[i] + e[i]
