"""Constant output maps of the compiled kernels (the generated kernel's).

:func:`output_constants` says, from an analysed mechanism and the column offsets of its
unknowns, where each output of a sample comes from in the solution row and the
coefficients of the tooth force components (what :func:`..solve._result` computes over
arrays).
"""
from __future__ import annotations

import numpy as np

from ...model.gears import helical_terms


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
