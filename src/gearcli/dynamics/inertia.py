"""The d'Alembert (inertia and gravity) load of every link: paper Eqs. (17)-(18).

F*_i = m_i a_ic (17) and N*_i = I_i dw_i + w_i x (I_i w_i) (18), the inertia tensor I_i
about the centre of mass in link axes; the equations of :mod:`gearcli.dynamics.equations`
balance these loads.
"""
from __future__ import annotations

import numpy as np

from ..algebra import algebra_for, matrices, stack_vectors, vectors
from .kinematics import Kinematics, arm_acceleration


def inertia_load(an, kin: Kinematics) -> dict[int, np.ndarray]:
    """Right-hand side b_L (N, 6) of every moving link's balance: the d'Alembert wrench
    [F*_L - m g ; N*_L + r_c x (F*_L - m g)], base frame, about the link origin o_L, N and
    N*m (paper Eqs. 17-18 with gravity; centre of mass anywhere, full inertia tensor):
    :func:`inertia_wrench` over all samples at once."""
    mech, tree = an.mech, an.tree
    g = vectors(mech.gravity)
    out, al = {}, algebra_for(kin.n)
    for L in tree.moving:
        link = mech.bodies[L]          # payloads merged (model.loads.with_payloads)
        R, _, w, dw, a = kin.link_terms(L)
        W = inertia_wrench(al, float(link.mass), matrices(link.inertia), vectors(link.com), R, w, dw, a, g)
        out[L] = stack_vectors(W, kin.n)
    return out


def inertia_wrench(al, m, I_c, r_c, R_0i, omega_i, alpha_i, a_i, g) -> tuple:
    """d'Alembert wrench of one link, base frame, about the link origin (Eqs. 17-18).

    F* = m a_c (17) and N* = I_c dw + w x (I_c w) (18), gravity moved to the left:
    returns [F* - m g ; R N*_body + r_c x (F* - m g)], N and N*m, a 6-tuple of values of the
    algebra ``al`` (:mod:`gearcli.algebra`: numpy over the samples, or the kernel's emitter).

    m : mass, kg.  I_c : inertia about the centre of mass, link axes, kg*m^2 (row-major 9).
    r_c : centre of mass in the link frame, m.  R_0i : link orientation (9).  omega_i,
    alpha_i : angular velocity and acceleration, rad/s, rad/s^2.  a_i : acceleration of the
    link origin, m/s^2.  All but I_c and r_c in the base frame.  g : gravity, m/s^2.
    """
    wb = al.mtv(R_0i, omega_i)                                          # R^T w (link axes)
    Nb = al.vadd(al.mv(I_c, al.mtv(R_0i, alpha_i)), al.cx(wb, al.mv(I_c, wb)))   # Eq. (18), link axes
    rc = al.mv(R_0i, r_c)                                               # o_i -> centre of mass, base axes
    F = al.scale(al.vsub(arm_acceleration(al, a_i, alpha_i, omega_i, rc), g), m)  # Eq. (17) with gravity
    return F + al.vadd(al.mv(R_0i, Nb), al.cx(rc, F))
