"""The d'Alembert (inertia and gravity) load of every link: paper Eqs. (17)-(18).

F*_i = m_i a_ic (17) and N*_i = I_i dw_i + w_i x (I_i w_i) (18), the inertia tensor I_i
about the centre of mass in link axes; the equations of :mod:`gearcli.dynamics.equations`
balance these loads.
"""
from __future__ import annotations

import numpy as np

from ..spatial import cross, mtv, mv
from .kinematics import Kinematics


def inertia_load(an, kin: Kinematics) -> dict[int, np.ndarray]:
    """Right-hand side b_L (N, 6) of every moving link's balance: the d'Alembert wrench
    [F*_L - m g ; N*_L + r_c x (F*_L - m g)], base frame, about the link origin o_L, N and
    N*m (paper Eqs. 17-18 with gravity; centre of mass anywhere, full inertia tensor)."""
    mech, tree = an.mech, an.tree
    g = mech.gravity
    out = {}
    for L in tree.moving:
        link = mech.links[L]
        R = kin.R[L]
        w, dw = kin.w[L], kin.dw[L]
        wb = mtv(R, w)                                         # R^T w
        dwb = mtv(R, dw)
        Nb = dwb @ link.inertia.T + cross(wb, wb @ link.inertia.T)
        if np.any(link.com):
            rc = mv(R, link.com)                               # (N,3) o_L -> centre of mass
            a_c = kin.a[L] + cross(dw, rc) + cross(w, cross(w, rc))
            F = link.mass * (a_c - g)
            out[L] = np.concatenate([F, mv(R, Nb) + cross(rc, F)], axis=1)
        else:                                                  # centre of mass at the origin
            out[L] = np.concatenate([link.mass * (kin.a[L] - g), mv(R, Nb)], axis=1)
    return out
