"""Compiled writing of one sample's results (what :func:`.solve._result` does over arrays).

From the sample's solution row (every unknown, in
:func:`~gearcli.analysis.schedule.unknown_groups` order, joint reactions in the child's
basis): the joint reaction wrenches (N, J, 6) with the zero component of the joint's own
direction, the motor torques, the tooth forces t with their separating, radial and axial
components (the constants of :func:`output_constants`), the equivalent joint torques
tau = A motor and the motor speeds A^T qd.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from ..model.gears import helical_terms
from .kernel_links import INLINE, OPTS


def output_constants(an, offsets: dict):
    """(jout (J, 2) int [first column, 1 if prismatic], mcol (M,) and gcol (G,) columns,
    mflt (G, 10) [1 if gear geometry, tan(phi_t), t and |t| tan(phi_t) coefficients of the
    radial and axial components on j and on k])."""
    mech = an.mech
    jout = np.array([[offsets[("joint", ji)][0], int(jt.type == "prismatic")] for ji, jt in enumerate(mech.joints)],
                    np.int64).reshape(-1, 2)
    mcol = np.array([offsets[("motor", i)][0] for i in range(len(an.motor_links))] + [0], np.int64)
    gcol = np.array([offsets[("mesh", ci)][0] for ci in range(len(an.circuits))] + [0], np.int64)
    mflt = np.zeros((len(an.circuits) + 1, 10))
    for ci, c in enumerate(an.circuits):
        if c.geometry is None:
            continue
        gm, gp = c.geometry, mech.gears[c.gear]
        tan_t, a = helical_terms(gm, gp.pressure_angle, gp.helix_angle, gp.hand)
        ua = gm.ut + a
        mflt[ci] = [1.0, tan_t, ua @ gm.rad_j, gm.us @ gm.rad_j, ua @ gm.zj, gm.us @ gm.zj,
                    ua @ gm.rad_k, gm.us @ gm.rad_k, ua @ gm.zk, gm.us @ gm.zk]
    return jout, mcol, gcol, mflt


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
    mflt, A = flts[8], flts[9]
    motor, tau, joint, gear_t, sep, rad, ax, speed = outs[0], outs[1], outs[2], outs[3], outs[4], outs[5], \
        outs[6], outs[7]
    _joints(n, xrow, jout, joint)
    _meshes(n, xrow, gcol, mflt, gear_t, sep, rad, ax)
    M = motor.shape[1]
    for m in range(M):
        motor[n, m] = xrow[mcol[m]]
    for d in range(A.shape[0]):
        s = 0.0
        for m in range(M):
            s += A[d, m] * motor[n, m]
        tau[n, d] = s
    for m in range(M):
        s = 0.0
        for d in range(A.shape[0]):
            s += qdi[n, d] * A[d, m]
        speed[n, m] = s
