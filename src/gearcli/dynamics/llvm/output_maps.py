"""Constant output maps: where each output comes from and the coefficients of the tooth
force components.

:func:`output_constants` says, from an analysed mechanism and the column offsets of its
unknowns, where each output of a sample comes from in the generated kernel's solution row;
:func:`gear_outputs` holds the coefficients of the tooth force components, which the numpy
path (:func:`..solve._result`) applies to arrays and the kernel writes into its code.
"""
from __future__ import annotations

import numpy as np

from ...model.gears import helical_terms
from .records import GEAR_OUT, JOINT_OUT, records


def output_constants(an, offsets: dict):
    """(joint outputs (J,) :data:`.records.JOINT_OUT`, the motors' (M,) and the meshes' (G,)
    columns, the meshes' output coefficients (G,) :data:`.records.GEAR_OUT`)."""
    mech = an.mech
    jout = records([(offsets[("joint", ji)][0], int(jt.type == "prismatic")) for ji, jt in enumerate(mech.joints)],
                   JOINT_OUT)
    mcol = np.array([offsets[("motor", i)][0] for i in range(len(an.motor_links))], np.int64)
    gcol = np.array([offsets[("mesh", ci)][0] for ci in range(len(an.circuits))], np.int64)
    return jout, mcol, gcol, gear_outputs(an)


def gear_outputs(an) -> np.recarray:
    """(G,) :data:`.records.GEAR_OUT` of the meshes: the tooth force on gear j is
    g = t (ut + a) + s us with s = |t| tan(phi_t) (-g on k), so each radial or axial
    component is t times the t coefficient plus s times the sep one (ut is perpendicular to
    both radial directions; zeros without gear geometry)."""
    mflt = np.zeros((len(an.circuits), 11))
    for ci, c in enumerate(an.circuits):
        if c.geometry is None:
            mflt[ci, 10] = float(an.mech.gears[c.gear].reducer is not None)
            continue
        gm, gp = c.geometry, an.mech.gears[c.gear]
        tan_t, a = helical_terms(gm, gp.pressure_angle, gp.helix_angle, gp.hand)
        ua = gm.ut + a
        mflt[ci] = [1.0, tan_t, ua @ gm.rad_j, gm.us @ gm.rad_j, ua @ gm.zj, gm.us @ gm.zj,
                    ua @ gm.rad_k, gm.us @ gm.rad_k, ua @ gm.zk, gm.us @ gm.zk, 0.0]
    return records(map(tuple, mflt), GEAR_OUT)
