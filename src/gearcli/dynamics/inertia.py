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
        link = mech.bodies[L]          # payloads merged (model.loads.with_payloads)
        out[L] = inertia_wrench(link.mass, link.inertia, link.com, kin.R[L], kin.w[L], kin.dw[L], kin.a[L], g)
    return out


def inertia_wrench(m: float, I_c: np.ndarray, r_c: np.ndarray, R_0i: np.ndarray, omega_i: np.ndarray,
                   alpha_i: np.ndarray, a_i: np.ndarray, g: np.ndarray) -> np.ndarray:
    """d'Alembert wrench of one link, base frame, about the link origin (Eqs. 17-18).

    F* = m a_c (17) and N* = I_c dw + w x (I_c w) (18), gravity moved to the left:
    returns [F* - m g ; R N*_body + r_c x (F* - m g)], N and N*m.

    Parameters
    ----------
    m : mass, kg.  I_c : (3, 3) inertia about the centre of mass, link axes, kg*m^2.
    r_c : (3,) centre of mass in the link frame, m.
    R_0i : (N, 3, 3) link orientation.  omega_i, alpha_i : (N, 3) angular velocity and
        acceleration, rad/s, rad/s^2.  a_i : (N, 3) acceleration of the link origin, m/s^2.
        All in the base frame.  g : (3,) gravity, m/s^2.
    """
    wb = mtv(R_0i, omega_i)                                   # R^T w (link axes)
    Nb = mtv(R_0i, alpha_i) @ I_c.T + cross(wb, wb @ I_c.T)   # Eq. (18), link axes
    if not np.any(r_c):                                       # centre of mass at the origin
        return np.concatenate([m * (a_i - g), mv(R_0i, Nb)], axis=1)
    rc = mv(R_0i, r_c)                                        # (N,3) o_i -> centre of mass
    a_c = a_i + cross(alpha_i, rc) + cross(omega_i, cross(omega_i, rc))
    F = m * (a_c - g)                                         # Eq. (17) with gravity
    return np.concatenate([F, mv(R_0i, Nb) + cross(rc, F)], axis=1)
