"""The wrench columns of the unknowns, as terms: written once for both paths.

Every column C_u,L of an unknown u on link L (:class:`~.equations.Columns`, the paper's Eqs.
15-16 and 19-20) is a sum of wrenches

* ``coef * [d ; (P - o_L) x d]``: a force along d through P, or
* ``coef * [0 ; d]``: a moment along d,

with d = R_X d_X and P = o_X + R_X p_X for a link X (the joint child for a joint frame:
R_joint = R_child R_jc^T, o_joint = o_child - R_joint p_jc; the carrier for a mesh), and a
term of a geared mesh's separating force is multiplied by the sign of its t (Eq. 14).
:func:`group_terms` lists them from the model; :func:`gearcli.dynamics.wrenches.term_wrench`
is one term's wrench.  The numpy path sums them over the samples
(:meth:`~.equations.Columns.group`), the kernel per sample (its world-frame blocks,
:mod:`.llvm.terms`, and their propagation).  The losses' additions to the columns (a mesh's
friction couple, a power-flow element's delta u, a worm's sliding friction, a belt's loss
couples) are not terms: :mod:`.equations` and :mod:`.llvm.losses`.
"""
from __future__ import annotations

import weakref

import numpy as np

from ..model.gears import helical_terms


def _joint_frame(jt):
    """(E, p): the joint frame's axes (columns) and origin in its child's frame."""
    E = np.asarray(jt.R_jc, float).T
    return E, -E @ np.asarray(jt.p_jc, float)


def _axial(an, ji, L, coef, sign=None):
    """Terms of a unit generalised force of joint ji on link L (see Columns.axial)."""
    jt = an.mech.joints[ji]
    idx = an.tree.index
    if sign is None:
        sign = float(idx[jt.child] == L) - float(idx[jt.parent] == L)
    if not sign:
        return []
    E, p = _joint_frame(jt)
    kind = 0 if jt.type == "prismatic" else 1
    return [(kind, idx[jt.child], -1, coef * sign, E[:, 2], p)]


def _joint(an, ji, L):
    """Per column j of joint ji's reaction on L: its terms (see Columns.joint)."""
    jt = an.mech.joints[ji]
    c = an.tree.index[jt.child]
    s = 1.0 if c == L else -1.0
    E, p = _joint_frame(jt)
    if jt.type == "prismatic":
        spec = [(0, 0), (0, 1), (1, 0), (1, 1), (1, 2)]
    else:
        spec = [(0, 0), (0, 1), (0, 2), (1, 0), (1, 1)]
    return [[(kind, c, -1, s, E[:, i], p)] for kind, i in spec]


def _motor(an, mi, L):
    if an.motor_joints and an.motor_joints[mi] is not None:
        return [[t for ji, coef in an.motor_joints[mi] for t in _axial(an, ji, L, coef)]]
    x = an.motor_links[mi]
    return [_axial(an, an.tree.parent_joint[x], L, 1.0, 1.0 if L == x else -1.0)]


def _own_axis(an, x: int, c: int, z_c: np.ndarray) -> np.ndarray:
    """The axis ``z_c`` (carrier c's axes) of gear x turning about it relative to c, in x's own
    axes: constant, x's rotation relative to c being about that axis alone (its coaxial group),
    so R_x^T R_c z_c is taken at home.  A term on x in x's own axes lets a block of x alone be
    solved in x's frame (:func:`local_inverse`)."""
    home = _home(an)
    return home.R[x][0].T @ home.R[c][0] @ z_c


def _home(an):
    """The kinematics of ``an`` at home (every joint coordinate 0), made once per analysis."""
    from .kinematics import forward  # noqa: PLC0415
    if an not in _HOMES:
        _HOMES[an] = forward(an.mech, an.tree, np.zeros((1, len(an.mech.joints))))
    return _HOMES[an]


_HOMES: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()


def _mesh(an, ci, L, t_pos):
    c = an.circuits[ci]
    if c.joints is not None:
        b, a = c.joints
        return [_axial(an, b, L, 1.0) + _axial(an, a, L, -c.ratio)]
    zero = np.zeros(3)
    if an.mech.gears[c.gear].belt is not None:     # +-E/2 along the spans at their tangent points
        if L not in (c.j, c.k):
            return [[]]                            # (a lossy belt's couple on the carrier: .losses)
        geo, side = c.belt, (0 if L == c.j else 1)
        s = 1.0 if side == 0 else -1.0
        return [[(0, c.carrier, -1, 0.5 * s, geo.e[0], geo.X[0, side]),
                 (0, c.carrier, -1, -0.5 * s, geo.e[1], geo.X[1, side])]]
    wm = an.mech.gears[c.gear].worm
    if wm is not None:             # the flank load on the wheel at P: cos(a_n) e + sigma sin(a_n) n_c (friction: .losses)
        if L not in (c.j, c.k):
            return [[]]
        s, geo = (1.0 if L == c.k else -1.0), c.worm
        return [[(0, c.carrier, -1, s * np.cos(wm.pressure_angle), geo.e_hat, geo.P),
                 (0, c.carrier, t_pos, s * np.sin(wm.pressure_angle), geo.n_c, geo.P)]]
    sc = an.mech.gears[c.gear].screw
    if sc is not None:             # the axial force along z_S through the axis point, the torque h z_S
        if L not in (c.j, c.k):
            return [[]]
        s = 1.0 if L == c.k else -1.0
        return [[(0, c.carrier, -1, s, c.zj, c.axis_point), (1, c.carrier, -1, s * sc.h, c.zj, zero)]]
    if c.geometry is not None:
        gm, gp = c.geometry, an.mech.gears[c.gear]
        tan_t, ax = helical_terms(gm, gp.pressure_angle, gp.helix_angle, gp.hand)
        s = 1.0 if L == c.j else -1.0
        return [[(0, c.carrier, -1, s, gm.ut + ax, gm.P), (0, c.carrier, t_pos, s * tan_t, gm.us, gm.P)]]
    out = []
    if L == c.j:
        out.append((1, c.j, -1, 1.0, _own_axis(an, c.j, c.carrier, c.zj), zero))
    if L == c.k:
        out.append((1, c.k, -1, -c.ratio, _own_axis(an, c.k, c.carrier, c.zk), zero))
    if L == c.carrier:
        out += [(1, c.carrier, -1, -1.0, c.zj, zero), (1, c.carrier, -1, c.ratio, c.zk, zero)]
    return [out]


def group_terms(an, g, L, t_pos):
    """Per column of group g: the terms of its wrench on link L (t_pos: the block position
    of g's sign, for a geared mesh)."""
    if g.kind == "joint":
        return _joint(an, g.index, L)
    if g.kind == "motor":
        return _motor(an, g.index, L)
    return _mesh(an, g.index, L, t_pos)
