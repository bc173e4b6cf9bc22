"""Wrenches of unit generalised forces and of external loads: terms written once for both paths.

A wrench is [force ; moment], base frame, about the origin o_L of the link L it acts on (N,
N*m), a 6-tuple of values of the algebra ``al`` (:mod:`gearcli.algebra`); the numpy path
stacks it to (N, 6), the kernel emits it per sample.
"""
from __future__ import annotations

import numpy as np

from ..algebra import algebra_for, stack_vectors


def unit_joint_wrench(al, z, o_j, o_L, prismatic: bool) -> tuple:
    """The wrench on L of a unit generalised force of a joint: a unit force along its axis z
    through its origin o_j, [z ; (o_j - o_L) x z] (prismatic), or a unit moment about the
    axis, [0 ; z] (revolute; ``o_j`` unused)."""
    if prismatic:
        return z + al.cx(al.vsub(o_j, o_L), z)
    return (0.0, 0.0, 0.0) + tuple(z)


def term_direction(al, d_X, R_X) -> tuple:
    """A column term's direction d = R_X d_X in base axes (d_X given in link X's axes)."""
    return al.mv(R_X, d_X)


def term_point(al, p_X, R_X, o_X) -> tuple:
    """A column term's point P = o_X + R_X p_X in the base frame (p_X given in link X's frame,
    ``R_X``, ``o_X`` its orientation and origin)."""
    return al.vadd(o_X, al.mv(R_X, p_X))


def term_wrench(al, moment: bool, coef, d, P, o_L) -> tuple:
    """The wrench on L of one column term per unit of its unknown (:mod:`.column_terms`): a
    moment coef d, [0 ; coef d], or a force coef d through P, [coef d ; coef (P - o_L) x d]
    (d, P from :func:`term_direction`, :func:`term_point`; ``P`` unused for a moment)."""
    if moment:
        return (0.0, 0.0, 0.0) + al.scale(d, coef)
    arm = al.vsub(P, o_L)
    return al.scale(d, coef) + al.scale(al.cx(arm, d), coef)


def worm_friction(al, sigma, s_v, mu, R_c, o_c, h_hat, point) -> tuple:
    """(f, P): a worm pair's sliding friction on the wheel per unit of its flank load N, the
    force f = sigma s_v mu R_c h_hat (base axes; the worm takes -f) at the contact point
    P = o_c + R_c point (base frame): ``h_hat`` the unit sliding direction and ``point`` the
    contact, both in the carrier c's frame (``R_c``, ``o_c``), ``sigma`` the sign of N and
    ``s_v`` that of the worm's rate relative to the carrier (:mod:`gearcli.model.worms`)."""
    coef = al.mul(al.mul(sigma, s_v), mu)
    return al.scale(term_direction(al, h_hat, R_c), coef), term_point(al, point, R_c, o_c)


def mesh_friction_column(al, side, sigma, s_v, fr) -> tuple:
    """The column addition on a link of a geared mesh's friction couple per unit of its
    tooth force t (:mod:`.losses`): a moment side sigma s_v fr, ``fr`` R_c times the couple
    per unit of :func:`.losses.mesh_friction_moment` (base axes), ``side`` +1 on gear j, -1
    on gear k, ``sigma`` = sign(t) and ``s_v`` the sign of j's rate relative to the carrier."""
    return (0.0, 0.0, 0.0) + al.scale(fr, al.mul(al.mul(sigma, s_v), side))


def worm_friction_column(al, side, f, P, o_L) -> tuple:
    """The column addition on a link of a worm pair's sliding friction per unit of its flank
    load (:func:`worm_friction`'s f at P): side [f ; (P - o_L) x f], ``side`` +1 on the
    wheel, -1 on the worm."""
    return al.scale(f, side) + al.scale(al.cx(al.vsub(P, o_L), f), side)


def power_flow_column(al, coef, delta, z) -> tuple:
    """The column addition on a link of a power-flow element's change of its torque's factor
    per unit of its interaction u (:mod:`.loss_terms`): a moment (coef delta) z about the
    element's axis z (base axes), ``coef`` the link's side (+1 the input, -1 the housing, or
    the pulley's arm of a belt side)."""
    return (0.0, 0.0, 0.0) + al.scale(z, al.mul(coef, delta))


def load_wrench(al, f, m, arm) -> tuple:
    """The wrench about o_L of a force f and moment m applied at the point o_L + arm (base
    axes): [f ; m + arm x f]."""
    return tuple(f) + al.vadd(m, al.cx(arm, f))


def joint_axis_wrench(an, kin, ji: int, L: int, sign: float | None = None) -> np.ndarray:
    """(N, 6) :func:`unit_joint_wrench` of joint ``ji`` on link L over the samples of ``kin``:
    on its child, reversed on its parent, zero on other links (``sign``: +-1 on L instead, a
    motor's on its input link and its stator)."""
    jt = an.mech.joints[ji]
    if sign is None:
        sign = float(an.tree.index[jt.child] == L) - float(an.tree.index[jt.parent] == L)
    z, oj = kin.joint_axis(ji)
    W = unit_joint_wrench(algebra_for(kin.n), z, oj, kin.link_terms(L)[1], jt.type == "prismatic")
    return sign * stack_vectors(W, kin.n)
