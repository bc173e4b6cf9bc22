"""Left-hand sides of the Newton-Euler balance equations: the wrench columns of the unknowns.

The balance of a primary link i (paper Eqs. 15-16) and of a secondary link j (Eqs. 19-20)
are one equation written for every moving link L, in the base frame about the link origin
o_L (the paper writes the moments about the centre of mass; the two forms are equivalent)::

    sum over unknowns u acting on L of  C_u,L x_u  =  b_L

with the d'Alembert load b_L of :mod:`gearcli.dynamics.inertia` (Eqs. 17-18) on the right.
The unknowns of link L are the reactions of its joints (f, n of Eqs. 15-16 and 19-20, on the
real joints, which is the documented equivalent of the canonical-to-real conversion of
Eqs. 23-24), the tangential tooth forces t of its gear meshes (Eq. 14) and the torques of
the motors acting on it.  :meth:`Columns.balance` assembles the columns of one link;
``C_u,L`` (N, 6, size) is the wrench on L per unit of unknown u:

* joint (revolute): forces along x, y, z and moments about x, y of the joint frame, at the
  joint origin, on the child (+) by the parent; the parent receives the opposite wrench;
* joint (prismatic): forces along x, y, moments about x, y, z;
* motor: a moment about the input link's joint axis (a force along it, for a prismatic
  joint) on the input link, reversed on the stator;
* mesh (gear geometry): the tooth force on j, ``ut + sigma tan(phi) us`` per unit of t with
  sigma = sign(t) (paper Eq. 14), at the pitch point; gear k receives the opposite;
* mesh (ideal coupling): a moment about j's axis on j, -ratio times one about k's axis on k,
  the carrier taking the reaction;
* reducer (:mod:`gearcli.model.reducers`: j the input, k the output, the carrier the
  housing): as an ideal coupling, the moment on j times the power-flow factor c_r(sigma, a);
* screw (:mod:`gearcli.model.screws`: j the screw, k the nut): the axial force along the axis
  u through a point on it and the torque h c_r u, on the nut, reversed on the screw;
* belt (:mod:`gearcli.model.belts`: j the input pulley, k the other): the spans' forces per
  unit of the effective pull E at their tangent points, a lossy belt's loss couple on the
  driven pulley (the carrier taking the reaction);
* worm pair (:mod:`gearcli.model.worms`: j the worm, k the wheel): the flank load's force at
  the contact point, cos(a_n) e + sigma sin(a_n) n_c + sigma s_v mu h per unit N on the wheel,
  reversed on the worm (s_v the sign of the worm's rate);
* mesh (joint coupling q_B = ratio q_A, GearPair.joints): a unit generalised force of joint
  B and -ratio times one of joint A, each on the joint's child and reversed on its parent
  (a moment about the axis of a revolute joint, a force along that of a prismatic one);
* motor with a transmission (Motor.joints): c times a unit generalised force of each joint.
"""
from __future__ import annotations

import numpy as np

from ..model.gears import helical_terms
from ..model.belts import belt_arms
from ..spatial import cross, mv
from .kinematics import Kinematics
from ..algebra import ARRAYS
from . import loss_terms
from .losses import loss_couples, mesh_friction_moment, power_flow_terms, relative_rate
from .wrenches import joint_axis_wrench


def tooth_force_direction(ut: np.ndarray, us: np.ndarray, sigma, tan_phi: float,
                          axial: np.ndarray | None = None) -> np.ndarray:
    """Tooth force on gear j per unit of tangential force t (paper Eq. 14, ERRATA 7).

    g_jk = t ut + |t| tan(phi) us = t (ut + sigma tan(phi) us), sigma = sign(t); for a
    helical pair phi is the transverse pressure angle and the axial thrust t a is added,
    a = -+tan(beta) z_j for a right-/left-hand gear j
    (:func:`gearcli.model.gears.helical_terms`).

    Parameters
    ----------
    ut : (N, 3) unit tangential direction (turns j in j's positive sense), base frame.
    us : (N, 3) unit separating direction on j (away from the mesh partner, perpendicular to
        the pitch element), base frame.
    sigma : (N,) or scalar, sign of t.
    tan_phi : tangent of the (transverse) pressure angle.
    axial : (N, 3) axial thrust per unit of t, base frame (None: spur).
    """
    d = ut + (np.asarray(sigma, float).reshape(-1, 1) * tan_phi) * us
    return d if axial is None else d + axial


def _force_at(d: np.ndarray, point: np.ndarray, origin: np.ndarray) -> np.ndarray:
    """(N,6) wrench of unit force ``d`` (N,3) applied at ``point`` about ``origin``."""
    return np.concatenate([d, cross(point - origin, d)], axis=1)


def _moment(d: np.ndarray) -> np.ndarray:
    return np.concatenate([np.zeros_like(d), d], axis=1)


class Columns:
    """Wrench columns C_u,L of every unknown u on every link L, base frame, about o_L.

    Built for one chunk of samples from its :class:`~gearcli.dynamics.kinematics.Kinematics`.
    """

    def __init__(self, an, kin: Kinematics):
        self.an, self.kin = an, kin
        self.tan_phi = {}
        self.world = {}
        for ci, c in enumerate(an.circuits):
            Rc, oc = kin.R[c.carrier], kin.o[c.carrier]
            if c.joints is not None:
                continue  # joint coupling: see axial()
            bt = an.mech.gears[c.gear].belt
            if bt is not None:                   # a belt: the spans' tangent points and directions
                geo = c.belt
                self.world[ci] = dict(belt=bt, X=[[oc + mv(Rc, geo.X[s, p]) for p in (0, 1)] for s in (0, 1)],
                                      es=[mv(Rc, geo.e[s]) for s in (0, 1)], z=mv(Rc, geo.z))
                if bt.lossy:
                    self.world[ci].update(rate=relative_rate(an, kin, ci), **belt_arms(geo))
                continue
            wm = an.mech.gears[c.gear].worm
            if wm is not None:                   # a worm pair: the flank load's directions at P
                geo = c.worm
                self.world[ci] = dict(P=oc + mv(Rc, geo.P), e=mv(Rc, geo.e_hat), n=mv(Rc, geo.n_c),
                                      hh=mv(Rc, geo.h_hat), worm=wm,
                                      sv=np.sign(relative_rate(an, kin, ci)) if wm.mu else None)
                continue
            sc = an.mech.gears[c.gear].screw
            if sc is not None:                   # the axis u = z_S through a point P on it
                self.world[ci] = dict(u=mv(Rc, c.zj), P=oc + mv(Rc, c.axis_point), h=sc.h)
                if sc.power_flow_lossy:
                    self.world[ci].update(flow=power_flow_terms(an, ci, relative_rate(an, kin, ci)))
                continue
            if c.geometry is not None:
                gm, gp = c.geometry, an.mech.gears[c.gear]
                tan_t, a = helical_terms(gm, gp.pressure_angle, gp.helix_angle, gp.hand)
                self.world[ci] = dict(P=oc + mv(Rc, gm.P), ut=mv(Rc, gm.ut), us=mv(Rc, gm.us),
                                      ax=mv(Rc, a) if gp.helix_angle else None)
                self.tan_phi[ci] = tan_t
                fr = mesh_friction_moment(an, ci)
                if fr is not None:     # friction couple on j per unit sigma s_v t, and s_v
                    self.world[ci].update(fr=mv(Rc, fr), sv=np.sign(relative_rate(an, kin, ci)))
            else:
                self.world[ci] = dict(zj=mv(Rc, c.zj), zk=mv(Rc, c.zk))
                red = an.mech.gears[c.gear].reducer
                if red is not None and red.power_flow_lossy:   # the input's rate a, for c_r
                    self.world[ci].update(flow=power_flow_terms(an, ci, relative_rate(an, kin, ci)))

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

    def axial(self, ji: int, L: int, sign: float | None = None) -> np.ndarray:
        """(N, 6) wrench on link L of a unit generalised force of joint ``ji``: about its axis
        (revolute) or along it through the joint origin (prismatic), on the child, reversed
        on the parent, zero on any other link (``sign``: +-1 on L instead, a motor's)."""
        return joint_axis_wrench(self.an, self.kin, ji, L, sign)

    def motor(self, mi: int, L: int) -> np.ndarray:
        """(N, 6, 1) column of motor ``mi``'s torque on link L: about the input link's joint axis on the input link, reversed on the stator (a transmission motor: its joints' generalised forces)."""
        an = self.an
        if an.motor_joints and an.motor_joints[mi] is not None:
            return sum(coef * self.axial(ji, L) for ji, coef in an.motor_joints[mi])[:, :, None]
        x = an.motor_links[mi]
        return self.axial(an.tree.parent_joint[x], L, 1.0 if L == x else -1.0)[:, :, None]

    def mesh_friction(self, ci: int, L: int) -> np.ndarray | None:
        """(N, 6, 1) friction couple of geared mesh ``ci`` on link L per unit of sigma s_v t
        (:mod:`.losses`: on j, the opposite on k), None for a lossless mesh."""
        wv = self.world.get(ci, {})
        if "fr" not in wv:
            return None
        sign = 1.0 if L == self.an.circuits[ci].j else -1.0
        return sign * _moment(wv["fr"])[:, :, None]

    def mesh(self, ci: int, L: int, sigma) -> np.ndarray:
        """(N, 6, 1) column of mesh unknown ``ci`` on link L; ``sigma`` = sign(t), (N,) or
        scalar.  A lossy mesh adds its friction couple sigma s_v (:meth:`mesh_friction`)."""
        c = self.an.circuits[ci]
        if c.joints is not None:
            b, a = c.joints
            return (self.axial(b, L) - c.ratio * self.axial(a, L))[:, :, None]
        wv = self.world[ci]
        o = self.kin.o[L]
        if "belt" in wv:              # +E/2 on span A, -E/2 on span B: on j along e_S, on k against
            return self._belt(ci, wv, L, sigma)[:, :, None]
        if "worm" in wv:              # the force on the wheel per unit N, minus on the worm (model.worms)
            wm, sg = wv["worm"], np.asarray(sigma, float).reshape(-1, 1)
            d = np.cos(wm.pressure_angle) * wv["e"] + sg * (np.sin(wm.pressure_angle) * wv["n"])
            if wv["sv"] is not None:
                d = d + (sg * wv["sv"][:, None] * wm.mu) * wv["hh"]
            return ((float(L == c.k) - float(L == c.j)) * _force_at(d, wv["P"], o))[:, :, None]
        if "h" in wv:                 # a screw: F u through P and the torque h c_r F u on the nut, minus on the screw
            cr = 1.0 if "flow" not in wv else _power_flow_factor(wv["flow"], sigma)
            col = _force_at(wv["u"], wv["P"], o)
            col[:, 3:] += (wv["h"] * cr) * wv["u"]
            return ((float(L == c.k) - float(L == c.j)) * col)[:, :, None]
        if c.geometry is not None:
            sign = 1.0 if L == c.j else -1.0
            d = tooth_force_direction(wv["ut"], wv["us"], sigma, self.tan_phi[ci], wv["ax"])
            col = sign * _force_at(d, wv["P"], o)
            if "fr" in wv:
                sv = np.asarray(sigma, float).reshape(-1, 1) * wv["sv"][:, None]
                col[:, 3:] += sign * sv * wv["fr"]
            return col[:, :, None]
        cr = 1.0        # a lossy reducer's power-flow factor c_r (model.reducers), (N, 1)
        if "flow" in wv:
            cr = _power_flow_factor(wv["flow"], sigma)
        col = 0.0
        if L == c.j:
            col = col + cr * _moment(wv["zj"])
        if L == c.k:
            col = col - c.ratio * _moment(wv["zk"])
        if L == c.carrier:
            col = col - cr * _moment(wv["zj"]) + c.ratio * _moment(wv["zk"])
        return col[:, :, None]

    def _belt(self, ci: int, wv: dict, L: int, sigma) -> np.ndarray:
        """(N, 6) column of a belt's effective pull E on link L (:mod:`gearcli.model.belts`): on
        pulley j +1/2 e_A at X_jA and -1/2 e_B at X_jB, on k the opposites at X_kA, X_kB; a
        lossy belt adds its loss couple on the driven pulley, the carrier taking the reaction
        (:func:`.losses.loss_couples`)."""
        c, o = self.an.circuits[ci], self.kin.o[L]
        col = np.zeros((self.kin.n, 6))
        for side, link in ((0, c.j), (1, c.k)):
            if L == link:
                sign = 1.0 if side == 0 else -1.0
                col += sign * (0.5 * _force_at(wv["es"][0], wv["X"][0][side], o) - 0.5 * _force_at(wv["es"][1], wv["X"][1][side], o))
        if "rate" in wv:
            on_j, on_k = loss_couples(wv["belt"], wv["tj"], wv["tk"], wv["rk"], wv["rate"],
                                      np.broadcast_to(np.asarray(sigma, float), wv["rate"].shape))
            for link, cp in ((c.j, on_j), (c.k, on_k)):
                if L == link:
                    col[:, 3:] += cp[:, None] * wv["z"]
                if L == c.carrier:
                    col[:, 3:] -= cp[:, None] * wv["z"]
        return col

    def group(self, g, L: int, sigma=1.0) -> np.ndarray:
        """(N, 6, g.size) columns of unknown group ``g`` on link L (sigma: sign of t)."""
        if g.kind == "joint":
            return self.joint(g.index, L)
        if g.kind == "motor":
            return self.motor(g.index, L)
        return self.mesh(g.index, L, sigma)

    def balance(self, groups, L: int, out: np.ndarray) -> None:
        """Left-hand side of link L's balance (Eqs. 15-16 primary, 19-20 secondary), every t
        taken positive: into ``out``, a zeroed (N, 6, n) array (or view), the wrenches on L
        of the unknowns of ``groups`` (n scalars in their order; zero for a group not acting on L)."""
        c0 = 0
        for g in groups:
            if L in g.links:
                out[:, :, c0:c0 + g.size] = self.group(g, L, 1.0)
            c0 += g.size


def _power_flow_factor(f, sigma) -> np.ndarray:
    """(N, 1) c_r = 1 + delta of a power-flow element's terms ``f``
    (:func:`.losses.power_flow_terms`) for the sign pattern sigma (a float or (N,))."""
    delta = loss_terms.power_flow_delta(ARRAYS, f.A, f.B, sigma, f.s_w)
    return (1.0 + np.broadcast_to(delta, f.s_w.shape))[:, None]
