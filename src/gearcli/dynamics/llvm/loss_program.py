"""The losses of a mechanism flattened for the generated kernel (:mod:`.losses`).

A :class:`LossProgram` is attached to the kernel's :class:`~.program.Program` as one
field (None for a lossless mechanism).  It holds, with the model of :mod:`.losses`:

* ``rate_meshes``: the circuits with a loss factor; the kernel computes each one's rate
  theta'_{j,c} (rad/s), its s_v = sign(rate) and its mesh power loss c_p |t_p| |rate| r_j
  (``gear_loss``); ``rate_flt`` (R, dof) their rows of
  :attr:`~gearcli.analysis.types.Analysis.mesh_rate_rows` (the rate from the independent
  joint rates: exactly 0 for a gear at rest on its carrier), ``rate_int`` (R, 2) [gear j,
  carrier], ``loss_flt`` (R, 2) [c_p, r_j];
* ``couple``: circuit -> (3,) the friction couple on gear j per unit of sigma s_v t in
  carrier axes (:func:`..losses.mesh_friction_moment`; gear k receives the opposite);
* ``blocks``: block index -> :class:`BlockLosses`, the lossy signed meshes of that block;
* ``joints`` (Q, 5) int [joint index, child, parent (-1: not moving), 1 if prismatic, 0]
  and ``joint_flt`` (Q, 8): the joint's axis z and origin in its child's axes (from R_jc,
  p_jc), its F_c and F_v: the joints with friction (Coulomb, viscous or bearings), whose own
  friction -F_c sign(q'_J) - F_v q'_J the kernel computes from its joint rate
  (:func:`..losses.friction_force`'s law; the bearing friction: :mod:`.bearings`);
* ``bearing_flt``, ``bearing_single``: the bearings of the joints with bearing friction
  (:func:`..bearing_friction.bearing_layout`); ``bearing_blocks``: block index ->
  :class:`BearingBlock`, the bearing friction joints whose reaction the block solves, which
  the kernel converges there (:mod:`.bearings`); it writes their converged sum_b M_b and the
  most iterations over those blocks in its ``moments`` row (width :attr:`LossProgram.out_width`).

Frames and signs as in :mod:`..losses` and :mod:`..blocks`: a constant block's couples are
in its frame F (``fric`` rows, ``fric_C``), a world-frame block's in base axes per sample.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..bearing_friction import bearing_layout, friction_joints
from ..blocks import primary_side
from ..kinematics import forward
from ..losses import mesh_friction_moment, power_flow_sides
from ..pattern_maps import PatternMaps
from ...model.belts import belt_arms
from ...model.friction import JointFriction


@dataclass(frozen=True, eq=False)
class BlockLosses:
    """The lossy signed meshes of one block.

    ``positions``: their positions in the block's signed meshes (its t columns, sign
    columns); ``rates``: each one's index in :attr:`LossProgram.rate_meshes` (its s_v);
    ``circuits``: each one's circuit.  Constant frame: ``phi`` (ml, 6B) their friction
    couples on the block's rows in F per unit of sigma s_v t (:attr:`..blocks.BlockPlan.fric`),
    ``later`` per mesh [(link, +1 on j / -1 on k)] of the links of later blocks and
    ``couple_F`` (ml, 3) the couple on j in F; ``maps`` (a block with stored pattern maps
    and at most :data:`MAX_TABLE` of them): the changed matrix's map of every pair (s_v of
    its lossy meshes, sign pattern), index 2^m * sum_i (s_v,i + 1) 3^i + pattern, the maps
    of the numpy path (:func:`..blocks._constant_block`), else None.  World frame (``phi``
    None): ``rows`` per mesh [(block row of the link, sign)] and ``later`` as above; the
    couple is :attr:`LossProgram.couple` of the circuit turned by the carrier's R.  ``hot``
    (a constant frame without ``maps``): ((key, map), ...) the changed matrix's maps of the
    pairs random motions meet most (:func:`.lossy_maps.hot_lossy_maps`)."""

    positions: tuple
    rates: tuple
    circuits: tuple
    phi: np.ndarray | None
    couple_F: np.ndarray | None
    later: tuple
    rows: tuple = ()
    maps: tuple | None = None
    hot: tuple = ()
    # the block's signed power-flow elements (world frame): (position in its signed unknowns,
    # index in ReducerLosses, ((block row, coef), ...), ((later link, coef), ...))
    reducers: tuple = ()
    # the block's lossy worm pairs (world frame): (position, index in WormLosses, ((block row,
    # link, +1 wheel / -1 worm), ...), ((later link, sign), ...))
    worms: tuple = ()


@dataclass(frozen=True, eq=False)
class WormLosses:
    """The lossy worm pairs (:mod:`gearcli.model.worms`) for the kernel: per pair its
    ``circuits``, ``rate_flt`` (W, dof) the worm's rate row (s_v = its sign), ``carriers``,
    ``point`` (W, 3) the contact point P and ``h_hat`` (W, 3) the thread tangent in the
    carrier's axes, ``mu``.  Their friction adds sigma s_v mu h_hat, a force at P, to the flank
    load's column on the wheel (minus on the worm)."""

    circuits: tuple
    rate_flt: np.ndarray
    carriers: tuple
    point: np.ndarray
    h_hat: np.ndarray
    mu: tuple

    def parts(self) -> list:
        return [self.circuits, self.rate_flt.tobytes(), self.carriers, self.point.tobytes(), self.h_hat.tobytes(), self.mu]


@dataclass(frozen=True, eq=False)
class ReducerLosses:
    """The lossy power-flow elements for the kernel: coaxial reducers
    (:mod:`gearcli.model.reducers`) and screws (:mod:`gearcli.model.screws`).

    Per element: ``circuits`` its circuit; ``rate_flt`` (R, dof) the row of its drive rate w
    over the independent rates (:mod:`gearcli.model.power_flow`: a reducer's a, the input's rate
    relative to the housing; a screw's -h a); ``scale`` (R,) |a| / |w| (1; 1/|h|), the speed its
    tables are read at; ``sides`` per element ((link or -1 where not moving, coef), ...) the
    moments coef delta u z its power-flow change puts on its links (a reducer: +1 input, -1
    housing; a screw: -h screw, +h nut); ``carriers`` (R,) the link whose axes ``axis`` (R, 3)
    is given in (the housing, the carrier); ``tables``: (eta_f, eta_b, T0 or None) each as
    (speeds, values) over |a|; ``signed``: 1 when its efficiency is below 1; ``reducer``: 1 for a
    reducer (its input torque is an output).  The kernel adds delta = A s_w^2 + B sigma s_w to
    c_r = 1 + delta, A = (1/eta_f + eta_b)/2 - 1, B = (eta_b - 1/eta_f)/2: 1/eta_f where sigma
    s_w = -1, eta_b where +1, 1 at rest; a reducer's no-load torque -T0 s_w coef z on its sides is
    a known load."""

    circuits: tuple
    rate_flt: np.ndarray
    scale: tuple
    sides: tuple
    carriers: tuple
    axis: np.ndarray
    tables: tuple
    signed: tuple
    reducer: tuple
    # per element how A, B follow from the efficiencies: 0 a reducer's or screw's factor c_r on
    # its torque; 1 a belt's loss couple on the driven pulley k where power flows j -> k,
    # A = -B = (1 - eta_f)/2; 2 the same on j where it flows k -> j, A = B = -(1 - eta_b)/2
    # (losses.loss_couples; a belt is two elements of one circuit)
    mode: tuple = ()

    def parts(self) -> list:
        return [self.circuits, self.rate_flt.tobytes(), self.scale, self.sides, self.carriers, self.axis.tobytes(),
                self.signed, self.reducer, self.mode, repr(self.tables).encode()]


@dataclass(frozen=True, eq=False)
class BearingBlock:
    """The bearing friction joints whose reaction one block solves (its child's or its
    parent's block, whichever comes first; their friction couple acts on no earlier block).

    ``joints``: each one's index in :attr:`LossProgram.bearing_joints`; ``cols``: the block
    column of its reaction [fx, fy, fz, mx, my] (the parent's or a coaxial link's basis: a
    turn about the axis, which leaves the bearing loads' magnitudes as they are); ``wF``
    (K, 6B): a constant-frame block's unit couple of each, +z on the child and -z on the
    parent where they are block links, in F's axes (constant: F carries the joint's axis),
    None for a block solved in world axes."""

    joints: tuple
    cols: tuple
    wF: np.ndarray | None


@dataclass(frozen=True, eq=False)
class LossProgram:
    """See the module docstring."""

    rate_meshes: tuple
    rate_int: np.ndarray
    rate_flt: np.ndarray
    couple: dict
    blocks: dict
    joints: np.ndarray
    joint_flt: np.ndarray
    loss_flt: np.ndarray
    bearing_joints: tuple = field(default=())     # friction_joints(mech): the fixed point's joints
    bearing_flt: np.ndarray | None = None         # (K, 6) [z1, z2, locating 1, 2, arm 1, 2] (bearing_layout)
    bearing_single: tuple = field(default=())     # (K,) 1: the joint has one bearing
    bearing_blocks: dict = field(default_factory=dict)   # block -> BearingBlock
    reducers: ReducerLosses | None = None                # the lossy reducers and screws
    worms: WormLosses | None = None                      # the lossy worm pairs

    @property
    def out_width(self) -> int:
        """Width of the kernel's ``moments`` output row: each bearing friction joint's converged
        sum_b M_b, then the most iterations over the blocks of :attr:`bearing_blocks` (:mod:`.bearings`)."""
        return len(self.bearing_joints) + 1

    def parts(self) -> list:
        """What the kernel's code is generated from (hashed into the program fingerprint)."""
        out = [self.rate_meshes, self.rate_int.tobytes(), self.rate_flt.tobytes(), self.joints.tobytes(),
               self.joint_flt.tobytes(), self.loss_flt.tobytes(), self.bearing_joints, self.bearing_single,
               b"" if self.bearing_flt is None else self.bearing_flt.tobytes()]
        for ci in sorted(self.couple):
            out += [ci, self.couple[ci].tobytes()]
        for b in sorted(self.bearing_blocks):
            bb = self.bearing_blocks[b]
            out += [b, bb.joints, bb.cols, b"" if bb.wF is None else bb.wF.tobytes()]
        if self.reducers is not None:
            out += self.reducers.parts()
        if self.worms is not None:
            out += self.worms.parts()
        for b in sorted(self.blocks):
            bl = self.blocks[b]
            out += [b, bl.positions, bl.rates, bl.circuits, bl.later, bl.rows, bl.reducers, bl.worms]
            out += [a.tobytes() for a in (bl.phi, bl.couple_F) + (bl.maps or ()) if a is not None]
            out += [v for key, L in bl.hot for v in (key, L.tobytes())]
        return out


MAX_TABLE = 64
"""(s_v, sign pattern) pairs, 3^ml 2^m, up to which a constant block with stored pattern maps
stores the changed matrix's map of each (:attr:`BlockLosses.maps`: a trial then costs what a
lossless one does); more: the rank-ml correction of :class:`.losses.LossyBlock`."""


def _table(p, pos: list) -> tuple | None:
    """:attr:`BlockLosses.maps` of block plan ``p`` (lossy signed positions ``pos``), or None."""
    m, ml = len(p.signed), len(pos)
    if not isinstance(p.Ainv, PatternMaps) or 3 ** ml * (1 << m) > MAX_TABLE:
        return None
    maps = []
    for code in range(3 ** ml):
        key = np.zeros(m)
        key[pos] = [code // 3 ** i % 3 - 1 for i in range(ml)]
        pm = PatternMaps(p.Ainv.A_mid, p.Ainv.halves + key[:, None] * p.fric, p.Ainv.cols, p.Ainv.w)
        maps += [np.ascontiguousarray(X) for X in pm]
    return tuple(maps)


def friction_joint_list(mech) -> list:
    """Indices of the joints with a friction load in the kernel: own friction (Coulomb,
    viscous) or bearing friction, in joint order."""
    bearing = set(friction_joints(mech))
    return [ji for ji, jt in enumerate(mech.joints)
            if (jt.friction is not None and jt.friction.active) or ji in bearing]


def build_loss_program(an, plans) -> LossProgram | None:
    """The :class:`LossProgram` of ``an`` (block plans ``plans``), None without losses."""
    mech, tree = an.mech, an.tree
    if not mech.has_losses:
        return None
    rate_meshes = tuple(ci for ci, c in enumerate(an.circuits)
                        if mech.gears[c.gear].loss_factor and c.geometry is not None)
    couple = {ci: mesh_friction_moment(an, ci) for ci in rate_meshes}
    couple = {ci: np.asarray(v, float) for ci, v in couple.items() if v is not None}
    rate_int = np.array([[an.circuits[ci].j, an.circuits[ci].carrier] for ci in rate_meshes], np.int64).reshape(-1, 2)
    rate_flt = np.array(an.mesh_rate_rows[list(rate_meshes)], float).reshape(-1, an.dof)
    block_of = {L: i for i, p in enumerate(plans) for L in p.links}
    red, worms = _reducer_losses(an), _worm_losses(an)
    blocks = {}
    for bi, p in enumerate(plans):
        pos = [n for n, gi in enumerate(p.signed) if p.groups[gi].kind == "mesh" and p.groups[gi].index in couple]
        reds, wms = _block_reducers(an, p, bi, block_of, red), _block_worms(an, p, bi, block_of, worms)
        if reds or wms:
            assert p.F is None, "a reducer's, screw's or worm's lossy unknown is solved in world axes"
            if not pos:
                blocks[bi] = BlockLosses((), (), (), None, None, (), (), reducers=reds, worms=wms)
                continue
        if not pos:
            continue
        circ = tuple(p.groups[p.signed[n]].index for n in pos)
        later = tuple(tuple((L, 1 if L == an.circuits[ci].j else -1) for L in p.groups[p.signed[n]].links
                            if block_of[L] > bi) for n, ci in zip(pos, circ))
        rates = tuple(rate_meshes.index(ci) for ci in circ)
        if p.F is None:
            rows = tuple(tuple((p.links.index(L), 1 if L == an.circuits[ci].j else -1)
                               for L in p.groups[p.signed[n]].links if L in p.links) for n, ci in zip(pos, circ))
            blocks[bi] = BlockLosses(tuple(pos), rates, circ, None, None, later, rows, reducers=reds, worms=wms)
        else:
            assert p.fric is not None and all(p.signed[n] in p.fric_C for n in pos)
            assert all(primary_side(an, p.groups[p.signed[n]]) == an.circuits[ci].j for n, ci in zip(pos, circ))
            couple_F = np.array([p.fric_C[p.signed[n]][3:, 0] for n in pos], float)
            blocks[bi] = BlockLosses(tuple(pos), rates, circ, np.ascontiguousarray(p.fric[pos], float),
                                     couple_F, later, maps=_table(p, pos))
    bj = friction_joints(mech)
    jrec, jflt = [], []
    moving = set(tree.moving)
    for ji in friction_joint_list(mech):
        jt = mech.joints[ji]
        c, par = tree.index[jt.child], tree.index[jt.parent]
        R_jc = np.asarray(jt.R_jc, float)
        fr = jt.friction if jt.friction is not None else JointFriction()
        # child axes: the joint frame's z is R_jc^T e_z, its origin -R_jc^T p_jc (o_c = o_j + R_j p_jc)
        jrec.append([ji, c if c in moving else -1, par if par in moving else -1, int(jt.type == "prismatic"), 0])
        jflt.append(np.concatenate([R_jc[2, :], -R_jc.T @ np.asarray(jt.p_jc, float), [fr.coulomb, fr.viscous]]))
    loss_flt = np.array([[mech.gears[an.circuits[ci].gear].loss_factor, an.circuits[ci].geometry.r_j]
                         for ci in rate_meshes], float).reshape(-1, 2)
    z1, z2, loc, arm, single = bearing_layout(mech, bj)
    bflt = np.ascontiguousarray(np.column_stack([z1, z2, loc, arm]).reshape(-1, 6), float)
    return LossProgram(rate_meshes, rate_int, rate_flt, couple, blocks, np.array(jrec, np.int64).reshape(-1, 5),
                       np.array(jflt, float).reshape(-1, 8), loss_flt, tuple(bj), bflt, tuple(int(v) for v in single),
                       _bearing_blocks(an, plans, bj), red, worms)


def _worm_losses(an) -> WormLosses | None:
    """The :class:`WormLosses` of ``an``'s worm pairs with friction, None without one."""
    gears = an.mech.gears
    circ = tuple(ci for ci, c in enumerate(an.circuits) if gears[c.gear].worm is not None and gears[c.gear].worm.lossy)
    if not circ:
        return None
    cs = [an.circuits[ci] for ci in circ]
    return WormLosses(circ, np.array(an.mesh_rate_rows[list(circ)], float).reshape(-1, an.dof),
                      tuple(c.carrier for c in cs), np.array([c.worm.P for c in cs], float).reshape(-1, 3),
                      np.array([c.worm.h_hat for c in cs], float).reshape(-1, 3),
                      tuple(gears[c.gear].worm.mu for c in cs))


def _block_worms(an, p, bi: int, block_of: dict, worms: WormLosses | None) -> tuple:
    """:attr:`BlockLosses.worms` of block plan ``p`` (index ``bi``)."""
    if worms is None:
        return ()
    out = []
    for n, gi in enumerate(p.signed):
        g = p.groups[gi]
        if g.kind != "mesh" or g.index not in worms.circuits:
            continue
        c = an.circuits[g.index]
        sides = [(L, s) for L, s in ((c.k, 1.0), (c.j, -1.0)) if L in an.tree.moving]
        rows = tuple((p.links.index(L), L, s) for L, s in sides if L in p.links)
        later = tuple((L, s) for L, s in sides if L not in p.links and L in block_of and block_of[L] > bi)
        out.append((n, worms.circuits.index(g.index), rows, later))
    return tuple(out)


def _reducer_losses(an) -> ReducerLosses | None:
    """The :class:`ReducerLosses` of ``an``'s lossy reducers and screws, None without one."""
    gears, moving = an.mech.gears, set(an.tree.moving)
    circ0 = tuple(ci for ci, c in enumerate(an.circuits)
                  if (gears[c.gear].reducer is not None and gears[c.gear].reducer.lossy)
                  or (gears[c.gear].screw is not None and gears[c.gear].screw.lossy)
                  or (gears[c.gear].belt is not None and gears[c.gear].belt.lossy))
    if not circ0:
        return None
    circ, rows, scale, sides, tables, signed, reducer, mode = [], [], [], [], [], [], [], []
    for ci in circ0:
        c, gp = an.circuits[ci], gears[an.circuits[ci].gear]
        el = gp.reducer or gp.screw or gp.belt
        t0 = getattr(el, "no_load_torque", None)
        table = ((el.forward.speeds, el.forward.values), (el.backward.speeds, el.backward.values),
                 None if t0 is None else (t0.speeds, t0.values))
        if gp.belt is not None:         # w = -tk omega_k = tj omega_j: the power of E on k per unit E, negated
            arms = belt_arms(c.belt)
            k, parts = arms["tj"], (((c.k, -arms["tk"]), (c.carrier, arms["tk"])), ((c.j, arms["tj"]), (c.carrier, -arms["tj"])))
            modes = (1, 2)
        else:
            k = 1.0 if gp.reducer is not None else -gp.screw.h       # w = k a
            parts = (power_flow_sides(c, gp),)
            modes = (0,)
        for coefs, m in zip(parts, modes):
            circ.append(ci)
            rows.append(k * np.asarray(an.mesh_rate_rows[ci], float))
            scale.append(1.0 / abs(k))
            sides.append(tuple((L if L in moving else -1, coef) for L, coef in coefs))
            tables.append(table)
            signed.append(int(el.power_flow_lossy))
            reducer.append(int(gp.reducer is not None))
            mode.append(m)
    return ReducerLosses(tuple(circ), np.array(rows, float).reshape(-1, an.dof), tuple(scale), tuple(sides),
                         tuple(an.circuits[ci].carrier for ci in circ),
                         np.array([an.circuits[ci].zj for ci in circ], float).reshape(-1, 3), tuple(tables),
                         tuple(signed), tuple(reducer), tuple(mode))


def _block_reducers(an, p, bi: int, block_of: dict, red: ReducerLosses | None) -> tuple:
    """:attr:`BlockLosses.reducers` of block plan ``p`` (index ``bi``): per signed power-flow
    element (position, index in ``red``, ((block row, coef), ...), ((later link, coef), ...))."""
    if red is None:
        return ()
    out = []
    for n, gi in enumerate(p.signed):
        g = p.groups[gi]
        for r in (r for r, ci in enumerate(red.circuits) if g.kind == "mesh" and ci == g.index):
            sides = [(L, coef) for L, coef in red.sides[r] if L >= 0]
            rows = tuple((p.links.index(L), coef) for L, coef in sides if L in p.links)
            later = tuple((L, coef) for L, coef in sides if L not in p.links and L in block_of and block_of[L] > bi)
            out.append((n, r, rows, later))
    return tuple(out)


def _bearing_blocks(an, plans, bj: list) -> dict:
    """{block: :class:`BearingBlock`} of the bearing friction joints ``bj``."""
    out, home = {}, None
    for bi, p in enumerate(plans):
        gis = [gi for gi, g in enumerate(p.groups) if g.kind == "joint" and g.index in bj]
        if not gis:
            continue
        wF = None
        if p.F is not None:
            if home is None:
                home = forward(an.mech, an.tree, np.zeros((1, len(an.mech.joints))))
            wF = np.zeros((len(gis), 6 * len(p.links)))
            for k, gi in enumerate(gis):
                jt = an.mech.joints[p.groups[gi].index]
                c = an.tree.index[jt.child]
                z = home.R[p.F][0].T @ home.R[c][0] @ np.asarray(jt.R_jc, float)[2, :]
                for L, sign in ((c, 1.0), (an.tree.index[jt.parent], -1.0)):
                    if L in p.links:
                        wF[k, 6 * p.links.index(L) + 3:6 * p.links.index(L) + 6] = sign * z
        out[bi] = BearingBlock(tuple(bj.index(p.groups[gi].index) for gi in gis),
                               tuple(int(p.offs[gi]) for gi in gis), wF)
    return out
