"""Wrench columns of the unknown loads, and the inertia (d'Alembert) load of every link.

Newton-Euler equations of link L are written in the base frame about the link origin o_L:

    sum over unknowns u of  C_u,L x_u  =  b_L,      b_L = [F*_L - m g ; N*_L + r_c x (F*_L - m g)]

with F* = m a_c and N* = I dw + w x (I w) (paper Eqs. 17-18, centre of mass anywhere, full
inertia tensor).  ``C_u,L`` (N, 6, size) is the wrench on L per unit of unknown u:

* joint (revolute): forces along x, y, z and moments about x, y of the joint frame, at the
  joint origin, on the child (+) by the parent; the parent receives the opposite wrench;
* joint (prismatic): forces along x, y, moments about x, y, z;
* motor: a moment about the input link's joint axis (a force along it, for a prismatic
  joint) on the input link, reversed on the stator;
* mesh (gear geometry): the tooth force on j, ``ut + sigma tan(phi) us`` per unit of t with
  sigma = sign(t) (paper Eq. 14), at the pitch point; gear k receives the opposite;
* mesh (ideal coupling): a moment about j's axis on j, -ratio times one about k's axis on k,
  the carrier taking the reaction;
* mesh (joint coupling q_B = ratio q_A, GearPair.joints): a unit generalised force of joint
  B and -ratio times one of joint A, each on the joint's child and reversed on its parent
  (a moment about the axis of a revolute joint, a force along that of a prismatic one);
* motor with a transmission (Motor.joints): c times a unit generalised force of each joint.
"""
from __future__ import annotations

import numpy as np

from .kinematics import Kinematics
from ..spatial import cross, mtv, mv


def inertia_load(an, kin: Kinematics) -> dict[int, np.ndarray]:
    """b_L (N, 6) for every moving link (world frame, about the link origin)."""
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


def _force_at(d: np.ndarray, point: np.ndarray, origin: np.ndarray) -> np.ndarray:
    """(N,6) wrench of unit force ``d`` (N,3) applied at ``point`` about ``origin``."""
    return np.concatenate([d, cross(point - origin, d)], axis=1)


def _moment(d: np.ndarray) -> np.ndarray:
    return np.concatenate([np.zeros_like(d), d], axis=1)


class Columns:
    """World-frame directions of every unknown for one chunk of samples."""

    def __init__(self, an, kin: Kinematics):
        self.an, self.kin = an, kin
        self.tan_phi = {}
        self.world = {}
        for ci, c in enumerate(an.circuits):
            Rc, oc = kin.R[c.carrier], kin.o[c.carrier]
            if c.joints is not None:
                continue  # joint coupling: see axial()
            if c.geometry is not None:
                gm = c.geometry
                self.world[ci] = dict(P=oc + mv(Rc, gm.P), ut=mv(Rc, gm.ut), us=mv(Rc, gm.us))
                self.tan_phi[ci] = float(np.tan(an.mech.gears[c.gear].pressure_angle))
            else:
                self.world[ci] = dict(zj=mv(Rc, c.zj), zk=mv(Rc, c.zk))

    def joint(self, ji: int, L: int) -> np.ndarray:
        """(N, 6, 5) columns of joint ``ji``'s reaction on link L."""
        an, kin = self.an, self.kin
        jt = an.mech.joints[ji]
        sign = 1.0 if an.tree.index[jt.child] == L else -1.0
        E = kin.Rj[ji]
        o, oj = kin.o[L], kin.oj[ji]
        if jt.type == "prismatic":
            cols = [_force_at(E[:, :, 0], oj, o), _force_at(E[:, :, 1], oj, o),
                    _moment(E[:, :, 0]), _moment(E[:, :, 1]), _moment(E[:, :, 2])]
        else:
            cols = [_force_at(E[:, :, i], oj, o) for i in range(3)] + [_moment(E[:, :, 0]), _moment(E[:, :, 1])]
        return sign * np.stack(cols, axis=2)

    def axial(self, ji: int, L: int) -> np.ndarray:
        """(N, 6) wrench on link L of a unit generalised force of joint ``ji``: about its axis
        (revolute) or along it through the joint origin (prismatic), on the child, reversed
        on the parent; zero on any other link."""
        an, kin = self.an, self.kin
        jt = an.mech.joints[ji]
        sign = float(an.tree.index[jt.child] == L) - float(an.tree.index[jt.parent] == L)
        z = kin.Rj[ji][:, :, 2]
        if jt.type == "prismatic":
            return sign * _force_at(z, kin.oj[ji], kin.o[L])
        return sign * _moment(z)

    def motor(self, mi: int, L: int) -> np.ndarray:
        an, kin = self.an, self.kin
        if an.motor_joints and an.motor_joints[mi] is not None:
            return sum(coef * self.axial(ji, L) for ji, coef in an.motor_joints[mi])[:, :, None]
        x = an.motor_links[mi]
        ji = an.tree.parent_joint[x]
        z = kin.Rj[ji][:, :, 2]
        sign = 1.0 if L == x else -1.0
        if an.mech.joints[ji].type == "prismatic":
            col = _force_at(z, kin.oj[ji], kin.o[L])
        else:
            col = _moment(z)
        return sign * col[:, :, None]

    def mesh(self, ci: int, L: int, sigma) -> np.ndarray:
        """(N, 6, 1) column of mesh unknown ``ci`` on link L; ``sigma`` = sign(t), (N,) or scalar."""
        c = self.an.circuits[ci]
        if c.joints is not None:
            b, a = c.joints
            return (self.axial(b, L) - c.ratio * self.axial(a, L))[:, :, None]
        wv = self.world[ci]
        o = self.kin.o[L]
        if c.geometry is not None:
            sign = 1.0 if L == c.j else -1.0
            d = wv["ut"] + (np.asarray(sigma, float).reshape(-1, 1) * self.tan_phi[ci]) * wv["us"]
            return sign * _force_at(d, wv["P"], o)[:, :, None]
        col = 0.0
        if L == c.j:
            col = col + _moment(wv["zj"])
        if L == c.k:
            col = col - c.ratio * _moment(wv["zk"])
        if L == c.carrier:
            col = col - _moment(wv["zj"]) + c.ratio * _moment(wv["zk"])
        return col[:, :, None]

    def group(self, g, L: int, sigma=1.0) -> np.ndarray:
        if g.kind == "joint":
            return self.joint(g.index, L)
        if g.kind == "motor":
            return self.motor(g.index, L)
        return self.mesh(g.index, L, sigma)
