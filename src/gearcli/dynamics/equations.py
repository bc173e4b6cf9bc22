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

The lossless columns are the terms of :mod:`.column_terms` (each term's wrench
:func:`~.wrenches.term_wrench`), the same the kernel sums; the losses' additions (a mesh's
friction couple, a reducer's or screw's delta u of c_r = 1 + delta, a worm's sliding friction,
a belt's loss couples) are added here, as the kernel's :mod:`.llvm.losses` adds them.
"""
from __future__ import annotations

import weakref

import numpy as np

from ..model.belts import belt_arms
from ..spatial import mv
from .kinematics import Kinematics
from ..algebra import ARRAYS, algebra_for, stack_vectors, vectors
from . import loss_terms
from .losses import loss_couples, mesh_friction_moment, power_flow_sides, power_flow_terms, relative_rate
from .column_terms import group_terms
from .wrenches import (mesh_friction_column, power_flow_column, term_direction, term_point, term_wrench,
                       worm_friction, worm_friction_column)


def _moment(d: np.ndarray) -> np.ndarray:
    return np.concatenate([np.zeros_like(d), d], axis=1)


class Columns:
    """Wrench columns C_u,L of every unknown u on every link L, base frame, about o_L.

    Built for one chunk of samples from its :class:`~gearcli.dynamics.kinematics.Kinematics`:
    the terms of :mod:`.column_terms` summed over the samples, and the losses' additions.
    """

    def __init__(self, an, kin: Kinematics):
        self.an, self.kin, self.al = an, kin, algebra_for(kin.n)
        self._axes = {}       # (X, d_X): a term direction d, (X, p_X, None): a term point P (base frame)
        self.world = {}       # per lossy circuit, what its loss additions read (base axes)
        for ci, c in enumerate(an.circuits):
            if c.joints is not None:
                continue
            Rc, gp = kin.R[c.carrier], an.mech.gears[c.gear]
            if gp.belt is not None and gp.belt.lossy:        # the loss couples about z
                self.world[ci] = dict(belt=gp.belt, z=mv(Rc, c.belt.z), rate=relative_rate(an, kin, ci),
                                      **belt_arms(c.belt))
            elif gp.worm is not None and gp.worm.mu:         # the sliding friction along h at P
                self.world[ci] = dict(mu=float(gp.worm.mu), sv=np.sign(relative_rate(an, kin, ci)),
                                      h_hat=tuple(map(float, c.worm.h_hat)), point=tuple(map(float, c.worm.P)))
            elif any(el is not None and el.power_flow_lossy for el in (gp.screw, gp.reducer)):
                self.world[ci] = dict(z=mv(Rc, c.zj), flow=power_flow_terms(an, ci, relative_rate(an, kin, ci)),
                                      sides=power_flow_sides(c, gp))
            elif c.geometry is not None and (fr := mesh_friction_moment(an, ci)) is not None:
                self.world[ci] = dict(fr=mv(Rc, fr), sv=np.sign(relative_rate(an, kin, ci)))

    def terms(self, g, L: int, sigma=1.0) -> np.ndarray:
        """(N, 6, g.size) the lossless columns of group ``g`` on link L: the sum of its
        :func:`~.column_terms.group_terms` (a signed term times ``sigma``, (N,) or a float)."""
        al, kin, n = self.al, self.kin, self.kin.n
        o_L = kin.link_terms(L)[1]
        sigma = sigma if isinstance(sigma, float) else np.broadcast_to(np.asarray(sigma, float), (n,))
        cols = _terms_of(self.an, g, L)
        out = np.empty((n, 6, len(cols)))
        axes = self._axes
        for j, terms in enumerate(cols):
            W = (0.0,) * 6
            for moment, X, signed, coef, d, p in terms:
                if (X, d) not in axes:          # (a joint's columns share its point, a mesh's too)
                    axes[X, d] = term_direction(al, d, kin.link_terms(X)[0])
                if not moment and (X, p, None) not in axes:
                    axes[X, p, None] = term_point(al, p, *kin.link_terms(X)[:2])
                W = al.vadd(W, term_wrench(al, moment, al.mul(coef, sigma) if signed else coef, axes[X, d],
                                           None if moment else axes[X, p, None], o_L))
            for h, v in enumerate(W):       # (a constant broadcast)
                out[:, h, j] = v
        return out

    def mesh_friction(self, ci: int, L: int) -> np.ndarray | None:
        """(N, 6, 1) friction couple of geared mesh ``ci`` on link L per unit of sigma s_v t
        (:mod:`.losses`: on j, the opposite on k), None for a lossless mesh."""
        wv = self.world.get(ci, {})
        if "fr" not in wv:
            return None
        side = 1.0 if L == self.an.circuits[ci].j else -1.0
        return stack_vectors(mesh_friction_column(self.al, side, 1.0, 1.0, vectors(wv["fr"])), self.kin.n)[:, :, None]

    def group(self, g, L: int, sigma=1.0) -> np.ndarray:
        """(N, 6, g.size) columns of unknown group ``g`` on link L (sigma: sign of t), the
        losses' additions included."""
        col = self.terms(g, L, sigma)
        wv = self.world.get(g.index) if g.kind == "mesh" else None
        if wv is not None:
            col[:, :, 0] += self._loss(self.an.circuits[g.index], wv, L, sigma)
        return col

    def _loss(self, c, wv: dict, L: int, sigma) -> np.ndarray | float:
        """(N, 6) the loss addition of lossy circuit c on link L per unit of its unknown
        (:mod:`.wrenches`' columns, the kernel's too)."""
        al, n = self.al, self.kin.n
        sg = sigma if isinstance(sigma, float) else np.asarray(sigma, float).reshape(-1)
        if "fr" in wv:                    # the friction couple sigma s_v fr on j, minus on k
            side = float(L == c.j) - float(L == c.k)
            return stack_vectors(mesh_friction_column(al, side, sg, wv["sv"], vectors(wv["fr"])), n)
        if "mu" in wv:                    # sigma s_v mu h at P on the wheel, minus on the worm
            (R_c, o_c), o_L = self.kin.link_terms(c.carrier)[:2], self.kin.link_terms(L)[1]
            f, P = worm_friction(al, sg, wv["sv"], wv["mu"], R_c, o_c, wv["h_hat"], wv["point"])
            return stack_vectors(worm_friction_column(al, float(L == c.k) - float(L == c.j), f, P, o_L), n)
        if "flow" in wv:                  # delta coef z on the element's sides (c_r = 1 + delta)
            coef = float(sum(k for link, k in wv["sides"] if link == L))
            f = wv["flow"]
            delta = loss_terms.power_flow_delta(ARRAYS, f.A, f.B, sg, f.s_w)
            return stack_vectors(power_flow_column(al, coef, delta, vectors(wv["z"])), n)
        on_j, on_k = loss_couples(wv["belt"], wv["tj"], wv["tk"], wv["rate"],
                                  np.broadcast_to(np.asarray(sigma, float), wv["rate"].shape))
        cp = (float(L == c.j) - float(L == c.carrier)) * on_j + (float(L == c.k) - float(L == c.carrier)) * on_k
        return _moment(cp[:, None] * wv["z"])

    def balance(self, groups, L: int, out: np.ndarray) -> None:
        """Left-hand side of link L's balance (Eqs. 15-16 primary, 19-20 secondary), every t
        taken positive: into ``out``, a zeroed (N, 6, n) array (or view), the wrenches on L
        of the unknowns of ``groups`` (n scalars in their order; zero for a group not acting on L)."""
        c0 = 0
        for g in groups:
            if L in g.links:
                out[:, :, c0:c0 + g.size] = self.group(g, L, 1.0)
            c0 += g.size


def _terms_of(an, g, L: int) -> list:
    """:func:`~.column_terms.group_terms` of unknown group ``g`` on link L, per column
    [(moment, X, signed, coef, d_X, p_X)] with floats and 3-tuples: made once per analysis
    (and again if its mechanism or circuits are replaced)."""
    made_of, cache = _TERMS.get(an, (None, None))
    if made_of != (id(an.mech), id(an.circuits)):       # (an analysis whose parts were replaced)
        cache = {}
        _TERMS[an] = ((id(an.mech), id(an.circuits)), cache)
    if (g.kind, g.index, L) not in cache:
        cache[g.kind, g.index, L] = [[(m == 1, X, s >= 0, float(c), vectors(d), vectors(p)) for m, X, s, c, d, p in terms]
                                 for terms in group_terms(an, g, L, 0)]
    return cache[g.kind, g.index, L]


_TERMS: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()
