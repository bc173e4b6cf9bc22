"""Compiled per-sample kinematics and link loads (the first half of :mod:`.kernel`).

Scalar numba code for one sample at a time, the same formulas as the array versions:
:func:`.kinematics.forward` (Walker-Orin recursion, paper Eqs. 2-5, every joint with its
fixed transforms), :func:`.inertia.inertia_wrench` (Eqs. 17-18) and
:func:`.external.external_wrenches`.  Arrays of the program: :mod:`.kernel_program`.
"""
from __future__ import annotations

import math

from numba import njit

OPTS = dict(cache=True, nogil=True, fastmath=False, error_model="numpy", _nrt=False)
INLINE = OPTS


@njit(**INLINE)
def cross(ax, ay, az, bx, by, bz):
    """a x b of two 3-vectors given by components."""
    return ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx


@njit(**INLINE)
def joint_space(S, qi, qdi, qddi, n, q, qd, qdd):
    """Every real joint's q, qd, qdd (J,) of sample n from the independent ones (q = S q_ind)."""
    for j in range(S.shape[0]):
        s0 = 0.0
        s1 = 0.0
        s2 = 0.0
        for d in range(S.shape[1]):
            s = S[j, d]
            s0 += qi[n, d] * s
            s1 += qdi[n, d] * s
            s2 += qddi[n, d] * s
        q[j] = s0
        qd[j] = s1
        qdd[j] = s2


@njit(**INLINE)
def _place(k, f, flags, p, c, prismatic, qk, R, o, Rj, oj):
    """Joint frame (Rj, oj) of joint record k and its child's R[c], o[c] (kinematics.forward).

    ``flags``: 1 parent is the base, 2 R_pj = I, 4 R_jc = I, 8 p_jc = 0 (skipped products)."""
    if flags & 1:
        for i in range(3):
            oj[i] = f[k, 9 + i]
            for j in range(3):
                Rj[i, j] = f[k, 3 * i + j]
    elif flags & 2:
        for i in range(3):
            oj[i] = o[p, i] + R[p, i, 0] * f[k, 9] + R[p, i, 1] * f[k, 10] + R[p, i, 2] * f[k, 11]
            for j in range(3):
                Rj[i, j] = R[p, i, j]
    else:
        for i in range(3):
            oj[i] = o[p, i] + R[p, i, 0] * f[k, 9] + R[p, i, 1] * f[k, 10] + R[p, i, 2] * f[k, 11]
            for j in range(3):
                Rj[i, j] = R[p, i, 0] * f[k, j] + R[p, i, 1] * f[k, 3 + j] + R[p, i, 2] * f[k, 6 + j]
    if prismatic:
        for i in range(3):
            oj[i] += Rj[i, 2] * qk
    else:
        cq, sq = math.cos(qk), math.sin(qk)
        for i in range(3):
            x0, x1 = Rj[i, 0], Rj[i, 1]
            Rj[i, 0] = cq * x0 + sq * x1
            Rj[i, 1] = cq * x1 - sq * x0
    for i in range(3):
        if flags & 8:
            o[c, i] = oj[i]
        else:
            o[c, i] = oj[i] + Rj[i, 0] * f[k, 21] + Rj[i, 1] * f[k, 22] + Rj[i, 2] * f[k, 23]
        for j in range(3):
            if flags & 4:
                R[c, i, j] = Rj[i, j]
            else:
                R[c, i, j] = Rj[i, 0] * f[k, 12 + j] + Rj[i, 1] * f[k, 15 + j] + Rj[i, 2] * f[k, 18 + j]


@njit(**INLINE)
def _rates(k, f, p, c, prismatic, qdk, qddk, Rj, oj, o, w, dw, a):
    """w[c], dw[c], a[c] of the child of a joint (kinematics.forward)."""
    zx, zy, zz = Rj[0, 2], Rj[1, 2], Rj[2, 2]
    wx, wy, wz = w[p, 0], w[p, 1], w[p, 2]
    ax_, ay_, az_ = dw[p, 0], dw[p, 1], dw[p, 2]
    rx, ry, rz = oj[0] - o[p, 0], oj[1] - o[p, 1], oj[2] - o[p, 2]
    t = cross(ax_, ay_, az_, rx, ry, rz)
    u = cross(wx, wy, wz, rx, ry, rz)
    v = cross(wx, wy, wz, u[0], u[1], u[2])
    a0, a1, a2 = a[p, 0] + t[0] + v[0], a[p, 1] + t[1] + v[1], a[p, 2] + t[2] + v[2]
    if prismatic:
        w[c, 0], w[c, 1], w[c, 2] = wx, wy, wz
        dw[c, 0], dw[c, 1], dw[c, 2] = ax_, ay_, az_
        e = cross(wx, wy, wz, zx * qdk, zy * qdk, zz * qdk)
        a0 += zx * qddk + 2.0 * e[0]
        a1 += zy * qddk + 2.0 * e[1]
        a2 += zz * qddk + 2.0 * e[2]
    else:
        e = cross(wx, wy, wz, zx, zy, zz)
        w[c, 0], w[c, 1], w[c, 2] = wx + zx * qdk, wy + zy * qdk, wz + zz * qdk
        dw[c, 0] = ax_ + zx * qddk + e[0] * qdk
        dw[c, 1] = ay_ + zy * qddk + e[1] * qdk
        dw[c, 2] = az_ + zz * qddk + e[2] * qdk
    rx = Rj[0, 0] * f[k, 21] + Rj[0, 1] * f[k, 22] + Rj[0, 2] * f[k, 23]
    ry = Rj[1, 0] * f[k, 21] + Rj[1, 1] * f[k, 22] + Rj[1, 2] * f[k, 23]
    rz = Rj[2, 0] * f[k, 21] + Rj[2, 1] * f[k, 22] + Rj[2, 2] * f[k, 23]
    t = cross(dw[c, 0], dw[c, 1], dw[c, 2], rx, ry, rz)
    u = cross(w[c, 0], w[c, 1], w[c, 2], rx, ry, rz)
    v = cross(w[c, 0], w[c, 1], w[c, 2], u[0], u[1], u[2])
    a[c, 0] = a0 + t[0] + v[0]
    a[c, 1] = a1 + t[1] + v[1]
    a[c, 2] = a2 + t[2] + v[2]


@njit(**INLINE)
def kinematics(jrec, jflt, q, qd, qdd, R, o, w, dw, a, Rj, oj):
    """Every link's R, o, w, dw, a of one sample (base frame; the base row stays at rest)."""
    for k in range(jrec.shape[0]):
        ji, p, c, pr = jrec[k, 0], jrec[k, 1], jrec[k, 2], jrec[k, 3] == 1
        _place(k, jflt, jrec[k, 4], p, c, pr, q[ji], R, o, Rj, oj)
        _rates(k, jflt, p, c, pr, qd[ji], qdd[ji], Rj, oj, o, w, dw, a)


@njit(**INLINE)
def _rot_t(R, L, x, y, z):
    """R[L]^T v."""
    return (R[L, 0, 0] * x + R[L, 1, 0] * y + R[L, 2, 0] * z,
            R[L, 0, 1] * x + R[L, 1, 1] * y + R[L, 2, 1] * z,
            R[L, 0, 2] * x + R[L, 1, 2] * y + R[L, 2, 2] * z)


@njit(**INLINE)
def rot(R, L, x, y, z):
    """R[L] v."""
    return (R[L, 0, 0] * x + R[L, 0, 1] * y + R[L, 0, 2] * z,
            R[L, 1, 0] * x + R[L, 1, 1] * y + R[L, 1, 2] * z,
            R[L, 2, 0] * x + R[L, 2, 1] * y + R[L, 2, 2] * z)


@njit(**INLINE)
def _inertia_times(lflt, L, v):
    """I_c v (link axes) of link L."""
    return (lflt[L, 1] * v[0] + lflt[L, 2] * v[1] + lflt[L, 3] * v[2],
            lflt[L, 4] * v[0] + lflt[L, 5] * v[1] + lflt[L, 6] * v[2],
            lflt[L, 7] * v[0] + lflt[L, 8] * v[1] + lflt[L, 9] * v[2])


@njit(**INLINE)
def inertia(L, lflt, g, R, w, dw, a, rhs):
    """rhs[L] = d'Alembert wrench of link L about o_L, base frame (inertia.inertia_wrench)."""
    m = lflt[L, 0]
    wb = _rot_t(R, L, w[L, 0], w[L, 1], w[L, 2])
    ab = _rot_t(R, L, dw[L, 0], dw[L, 1], dw[L, 2])
    Iw = _inertia_times(lflt, L, wb)
    Ia = _inertia_times(lflt, L, ab)
    e = cross(wb[0], wb[1], wb[2], Iw[0], Iw[1], Iw[2])
    Nw = rot(R, L, Ia[0] + e[0], Ia[1] + e[1], Ia[2] + e[2])
    rc = rot(R, L, lflt[L, 10], lflt[L, 11], lflt[L, 12])
    t = cross(dw[L, 0], dw[L, 1], dw[L, 2], rc[0], rc[1], rc[2])
    u = cross(w[L, 0], w[L, 1], w[L, 2], rc[0], rc[1], rc[2])
    v = cross(w[L, 0], w[L, 1], w[L, 2], u[0], u[1], u[2])
    F0 = m * (a[L, 0] + t[0] + v[0] - g[0])
    F1 = m * (a[L, 1] + t[1] + v[1] - g[1])
    F2 = m * (a[L, 2] + t[2] + v[2] - g[2])
    M = cross(rc[0], rc[1], rc[2], F0, F1, F2)
    rhs[L, 0], rhs[L, 1], rhs[L, 2] = F0, F1, F2
    rhs[L, 3], rhs[L, 4], rhs[L, 5] = Nw[0] + M[0], Nw[1] + M[1], Nw[2] + M[2]


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
