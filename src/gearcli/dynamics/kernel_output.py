"""Compiled writing of one sample's results (what :func:`.solve._result` does over arrays).

From the sample's solution row (every unknown, in
:func:`~gearcli.analysis.schedule.unknown_groups` order, joint reactions in the child's
basis): the joint reaction wrenches (N, J, 6) with the zero component of the joint's own
direction, the motor torques, the tooth forces t with their separating, radial and axial
components (the constants of :func:`.output_maps.output_constants`), the equivalent joint torques
tau = A motor and the motor speeds A^T qd.
"""
from __future__ import annotations

from numba import njit

from .kernel_links import INLINE, OPTS


@njit(**INLINE)
def _joints(n, xrow, jout, joint):
    """joint[n] (J*6): each joint's reaction, zero along (about) its own axis."""
    for j in range(jout.shape[0]):
        c0, d = jout[j, 0], 6 * j
        if jout[j, 1] == 1:            # prismatic: fx, fy, mx, my, mz
            joint[n, d], joint[n, d + 1], joint[n, d + 2] = xrow[c0], xrow[c0 + 1], 0.0
            joint[n, d + 3], joint[n, d + 4], joint[n, d + 5] = xrow[c0 + 2], xrow[c0 + 3], xrow[c0 + 4]
        else:                          # revolute: fx, fy, fz, mx, my
            for h in range(5):
                joint[n, d + h] = xrow[c0 + h]
            joint[n, d + 5] = 0.0


@njit(**INLINE)
def _meshes(n, xrow, gcol, mflt, gear_t, sep, rad, ax):
    """Tooth force t of every mesh and its separating, radial and axial components."""
    for c in range(gear_t.shape[1]):
        t = xrow[gcol[c]]
        gear_t[n, c] = t
        s = abs(t) * mflt[c, 1] if mflt[c, 0] == 1.0 else 0.0
        sep[n, c] = s
        rad[n, 2 * c] = t * mflt[c, 2] + s * mflt[c, 3]
        ax[n, 2 * c] = t * mflt[c, 4] + s * mflt[c, 5]
        rad[n, 2 * c + 1] = -(t * mflt[c, 6] + s * mflt[c, 7])
        ax[n, 2 * c + 1] = -(t * mflt[c, 8] + s * mflt[c, 9])


@njit(**INLINE)
def write_outputs(n, xrow, qdi, ints, flts, outs):
    """Every output array's row n from the solution row ``xrow``."""
    jout, mcol, gcol = ints[12], ints[13], ints[14]
    mflt = flts[8]
    motor, tau, joint, gear_t, sep, rad, ax, speed = outs[0], outs[1], outs[2], outs[3], outs[4], outs[5], \
        outs[6], outs[7]
    _joints(n, xrow, jout, joint)
    _meshes(n, xrow, gcol, mflt, gear_t, sep, rad, ax)
    for m in range(motor.shape[1]):
        motor[n, m] = xrow[mcol[m]]
    aptr, aidx, tptr, tidx = ints[17], ints[18], ints[19], ints[20]
    aval, tval = flts[11], flts[12]
    for d in range(aptr.shape[0] - 1):         # tau = A motor (A by rows of nonzeros)
        s = 0.0
        for e in range(aptr[d], aptr[d + 1]):
            s += aval[e] * motor[n, aidx[e]]
        tau[n, d] = s
    for m in range(tptr.shape[0] - 1):         # speed = A^T qd
        s = 0.0
        for e in range(tptr[m], tptr[m + 1]):
            s += qdi[n, tidx[e]] * tval[e]
        speed[n, m] = s
