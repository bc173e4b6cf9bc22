"""The compiled kernel's "program": one analysed mechanism flattened into named arrays.

The generated kernel (:mod:`.kernel`) is made from the :class:`Program` built here once per
analysis (from the :class:`~gearcli.analysis.graph.Analysis` and the block plans of
:func:`..blocks.make_plans`): record arrays whose columns are named (:mod:`.records`: the
joints and their placements, the links' inertia, the blocks of the schedule, the
propagation, child-basis and column-term records, the output maps), the flat arrays those
records index (pattern maps ``ainv``, propagation columns ``cmat``, ``later`` links, the
blocks' links and columns, coaxial ``turns``), and S (q = S q_ind), A (tau = A motor),
gravity, the moving links and the base.

Blocks without a constant frame (``F`` = -1) are solved in world axes from the
column terms of :mod:`.terms`; one whose matrix is nevertheless constant in its one
link's axes gets F = that link and its inverse (:func:`_local_frame`), and keeps its terms
(``nterm`` > 0) for the propagation.
"""
from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field, fields, replace

import numpy as np

from ...analysis.schedule import unknown_groups
from ..blocks import primary_side
from ..kinematics import forward
from .basis import basis as _basis
from .lossy_maps import hot_lossy_maps
from .output_maps import output_constants
from ..pattern_maps import hot_patterns, low_rank
from ..sharing import SharingError, mesh_weights
from .records import BLOCK, BODY, CHILD_BASIS, JOINT, POSE, PROPAGATION, records
from .terms import general_terms, local_inverse
from .loss_program import build_loss_program

I64 = np.int64


def _arr():
    """An array field's default: empty (a program that is not ``covered``)."""
    return field(default_factory=lambda: np.zeros(0))


@dataclass(frozen=True, eq=False)
class Program:
    """A mechanism flattened for the kernel (see module docstring; record layouts in
    :mod:`.records`).  ``covered`` False: a block the generated kernel cannot solve (the
    numpy path then), and no arrays."""

    ncols: int           # unknowns per sample (every group, in unknown_groups order)
    offsets: dict        # (kind, index) -> (first column, size)
    signed: list         # (kind, index) of each signs column
    names: list          # per block: names of its signed meshes (SignError)
    covered: bool
    joints: np.ndarray = _arr()           # JOINT records, tree order
    poses: np.ndarray = _arr()            # POSE of each of those joints
    bodies: np.ndarray = _arr()           # BODY of each link (by link id)
    moving: np.ndarray = _arr()           # the moving link ids
    base: int = 0                         # the base link id
    gravity: np.ndarray = _arr()          # (3,) m/s^2, base axes
    S: np.ndarray = _arr()                # (J, dof): q = S q_ind
    A: np.ndarray = _arr()                # (dof, M): tau = A motor
    blocks: np.ndarray = _arr()           # BLOCK records, schedule order
    block_links: np.ndarray = _arr()      # the blocks' links
    group_col: np.ndarray = _arr()        # each block column's position in the solution row
    t_col: np.ndarray = _arr()            # the block columns of the signed t (in the order of ``signed``)
    ainv: np.ndarray = _arr()             # every pattern's (n, 6B) inverse, row-major, patterns in sign_patterns order
    props: np.ndarray = _arr()            # PROPAGATION records
    cmat: np.ndarray = _arr()             # their C_plus (6, size), then C_sep, row-major
    later: np.ndarray = _arr()            # their later links
    child_basis: np.ndarray = _arr()      # CHILD_BASIS records
    turns: np.ndarray = _arr()            # their (J,) rows
    terms: np.ndarray = _arr()            # TERM records of the world-frame blocks
    term_values: np.ndarray = _arr()      # TERM_VALUE of each
    joint_out: np.ndarray = _arr()        # JOINT_OUT of each joint (mechanism order)
    motor_col: np.ndarray = _arr()        # each motor's column
    gear_col: np.ndarray = _arr()         # each mesh's column
    gear_out: np.ndarray = _arr()         # GEAR_OUT of each mesh
    hashed: np.ndarray = _arr()           # what only the cache key needs: LowRank, hot and basis data, flat
    lowrank: dict = field(default_factory=dict)   # block -> pattern_maps.LowRank (too many patterns to store)
    hot: dict = field(default_factory=dict)       # block -> (hot pattern indices, their maps (k, n, 6B))
    weights: dict = field(default_factory=dict)   # redundant world-frame block -> sharing.mesh_weights
    free: dict = field(default_factory=dict)      # redundant world-frame block -> (free columns, row order, swaps) (basis.py)
    losses: object = None                         # loss_program.LossProgram of a lossy mechanism
    # belts' pretension (a known load, model.belts): per belt [pulley j, pulley k (-1: not
    # moving), carrier] and [T_i, the tangent points X (2 spans x 2 pulleys x 3), e_A, e_B]
    belt_int: np.ndarray = _arr()
    belt_flt: np.ndarray = _arr()
    # True: the kernel reads every link's mass, centre of mass and inertia at run time (its
    # ``bodies`` argument, :func:`body_rows`), not as constants: one compile for every
    # variant of those values (gearcli sweep); ``bodies`` is then NaN (the cache key's mark)
    data_bodies: bool = False

    def arrays(self) -> list:
        """(name, array) of every array field, in field order (the disk cache's fingerprint)."""
        return [(f.name, getattr(self, f.name)) for f in fields(self) if isinstance(getattr(self, f.name), np.ndarray)]


def _joints(an):
    """(JOINT records, their POSE records) in tree order."""
    mech, tree = an.mech, an.tree
    rec, pose = [], []
    for ji in tree.order:
        jt = mech.joints[ji]
        c = tree.index[jt.child]
        rec.append((ji, tree.parent[c], c, int(jt.type == "prismatic")))
        pose.append((np.ravel(jt.R_pj), jt.p_pj, np.ravel(jt.R_jc), jt.p_jc))
    return records(rec, JOINT), records(pose, POSE)


def _bodies(an):
    """BODY records by link id (zeros for the base)."""
    out = np.zeros(len(an.tree.links), BODY).view(np.recarray)
    for L in an.tree.moving:
        link = an.mech.bodies[L]          # payloads merged
        out[L] = (link.mass, np.ravel(link.inertia), link.com)
    return out


BODY_WIDTH = 13
"""Doubles per link of a data kernel's ``bodies`` argument: mass, inertia (9, row-major, about
the centre of mass, link axes), centre of mass (3, link frame)."""


def body_rows(an) -> np.ndarray:
    """The ``bodies`` argument of a data kernel (:attr:`Program.data_bodies`) for the
    mechanism of ``an``: (links, :data:`BODY_WIDTH`) C-ordered, by link id."""
    b = _bodies(an)
    return np.ascontiguousarray(np.column_stack([b.mass, b.inertia, b.com]), float)


def load_arrays(an, values: dict, n: int, order: list) -> list:
    """The external loads' arguments of the kernel for n samples (vals, ldpt, ldrow),
    contiguous: the stacked values (one row (constant) or n rows per load) and, per load in
    ``order`` (:func:`.links.load_groups`), its point (link frame, m) and [its first row in
    the values, 1 if one row a sample, 1 if in link axes] (a row of zeros without loads)."""
    rows, rec, pts, off = [], [], [], 0
    for ld in an.mech.loads:
        w = values[ld.name]
        per = int(w.strides[0] != 0 and n > 1)
        rows.append(np.ascontiguousarray(w if per else w[:1], float))
        rec.append((off, per, int(ld.frame == "link")))
        pts.append(np.asarray(ld.point, float))
        off += rows[-1].shape[0]
    vals = (rows[0] if len(rows) == 1 else np.concatenate(rows)) if rows else np.zeros((1, 6))  # no copy of one
    return [vals, np.array([pts[k] for k in order] or [np.zeros(3)], float),
            np.array([rec[k] for k in order] or [(0, 0, 0)], np.int64)]


class _Builder:
    """Accumulates the per-block arrays."""

    def __init__(self):
        self.brec, self.blinks, self.gcol, self.tcol = [], [], [], []
        self.ainv, self.prec, self.cmat, self.later, self.cbrec, self.turns = [], [], [], [], [], []
        self.poses = None       # the kinematics of the poses :func:`_term_props` checks, made once

    @staticmethod
    def add_floats(parts: list, arr) -> int:
        """Append ``arr`` (flat floats) to ``parts``; its offset in their concatenation."""
        parts.append(np.ascontiguousarray(arr, float).ravel())
        return sum(a.size for a in parts[:-1])

    def propagation(self, an, p, gi, g, later, first: int) -> bool:
        """Append group gi's propagation record (False: merged into the previous one)."""
        Cp, Cs = p.C[gi]
        if Cs is None and self._merge(int(p.offs[gi]), g.size, primary_side(an, g), later, Cp, first):
            return False
        off = self.add_floats(self.cmat, Cp)
        if Cs is not None:
            self.add_floats(self.cmat, Cs)
        self.prec.append(dict(col0=int(p.offs[gi]), ncols=g.size, signed=int(Cs is not None), cmat0=off,
                              primary=primary_side(an, g), later0=len(self.later), nlater=len(later)))
        self.later += later
        return True

    def _merge(self, c0, size, P, later, Cp, first) -> bool:
        """Unsigned groups in adjacent columns acting on the same later links (same primary
        link) share one record: their wrenches are summed in F before the one rotation
        (a serial chain's joint reaction and motor torque)."""
        if len(self.prec) <= first:
            return False
        last = self.prec[-1]
        if (last["signed"] or last["col0"] + last["ncols"] != c0 or last["primary"] != P
                or self.later[last["later0"]:last["later0"] + last["nlater"]] != later):
            return False
        prev = self.cmat.pop().reshape(6, last["ncols"])
        last["cmat0"] = self.add_floats(self.cmat, np.hstack([prev, np.asarray(Cp, float).reshape(6, size)]))
        last["ncols"] += size
        return True


def _block(bd: _Builder, an, bi, p, offsets, terms, lowrank):
    """Append block ``bi`` (plan ``p``) to the builder."""
    n = int(p.offs[-1])
    term0, nterm = terms.get(bi, (0, 0))
    rec = dict(F=-1 if p.F is None else p.F, link0=len(bd.blinks), nlinks=len(p.links), n=n, col0=len(bd.gcol),
               m=len(p.signed), t0=len(bd.tcol), ainv0=sum(a.size for a in bd.ainv), prop0=len(bd.prec), nprop=0,
               cb0=len(bd.cbrec), ncb=0, term0=term0, nterm=nterm, local=0)
    bd.blinks += list(p.links)
    for g in p.groups:
        bd.gcol += range(offsets[(g.kind, g.index)][0], offsets[(g.kind, g.index)][0] + g.size)
    bd.tcol += [int(p.offs[gi]) for gi in p.signed]
    if bi in lowrank:
        rec["ainv0"] = -1                  # solved from its pattern_maps.LowRank (program.lowrank)
    else:
        for A in p.Ainv:
            bd.add_floats(bd.ainv, A)
    for gi, g in enumerate(p.groups):
        later = p.later[gi]
        if later and p.F is not None and bd.propagation(an, p, gi, g, later, rec["prop0"]):
            rec["nprop"] += 1
        if p.parent_side.get(gi):
            if gi in p.turn:               # basis carried by a third coaxial link: q @ row
                bd.cbrec.append((int(p.offs[gi]), -1, len(bd.turns)))
                bd.turns += [float(v) for v in p.turn[gi]]
            else:
                bd.cbrec.append((int(p.offs[gi]), g.index, 0))
            rec["ncb"] += 1
    bd.brec.append(rec)


def _local_frame(bd: _Builder, an, terms, values, p) -> None:
    """A world-frame block whose matrix is constant in its link's axes
    (:func:`.terms.local_inverse`) becomes a constant-frame block in that link
    (F = the link, its inverse in ``ainv``, once per sign pattern of its signed reducers: the
    matrix does not depend on them, :func:`_sign_free`) that keeps its terms for the
    propagation."""
    rec = bd.brec[-1]
    Ainv = local_inverse(terms, values, rec["term0"], rec["nterm"], p.links[0], rec["n"])
    if Ainv is not None:
        rec["F"], rec["ainv0"], rec["local"] = p.links[0], bd.add_floats(bd.ainv, Ainv), 1
        for _ in range((1 << len(p.signed)) - 1):
            bd.add_floats(bd.ainv, Ainv)
        _term_props(bd, an, terms, values, rec)


def _term_props(bd: _Builder, an, terms, values, rec) -> None:
    """A local-frame block's propagation as :data:`.records.PROPAGATION` records, one per later
    link (its wrench summed in F's axes, one rotation a sample) instead of a rotation per term,
    when every later term's wrench is constant in F's axes about o_F: a force or moment in F
    itself, or a moment along the axis about which its frame link turns relative to F (a
    reducer's torques on its input and housing); checked at home and two other poses.  Else
    the terms stay."""
    F, k0, nt = int(rec["F"]), int(rec["term0"]), int(rec["nterm"])
    later = [(t, v) for t, v in zip(terms[k0:k0 + nt], values[k0:k0 + nt]) if t.row < 0]
    if bd.poses is None:              # home and two other poses, one kinematics for every block
        rng = np.random.default_rng(0)
        q = np.vstack([np.zeros(len(an.mech.joints))] + [rng.uniform(-3, 3, len(an.mech.joints)) for _ in range(2)])
        bd.poses = forward(an.mech, an.tree, q)
    kin = bd.poses
    by_link: dict = {}
    for t, v in later:
        ws = []
        for n in range(3):
            RF, RX = kin.R[F][n], kin.R[int(t.frame)][n]
            d = RF.T @ RX @ np.asarray(v.d, float)
            if t.moment == 1:
                ws.append(np.concatenate([np.zeros(3), v.coef * d]))
            else:
                P = RF.T @ (RX @ np.asarray(v.p, float) + kin.o[int(t.frame)][n] - kin.o[F][n])
                ws.append(np.concatenate([v.coef * d, v.coef * np.cross(P, d)]))
        if any(not np.allclose(w, ws[0], rtol=1e-12, atol=1e-12 * (1 + np.abs(ws[0]).max())) for w in ws[1:]):
            return
        by_link.setdefault(int(t.link), []).append((int(t.col), ws[0]))
    rec["prop0"], rec["nprop"] = len(bd.prec), 0
    for L, cols in by_link.items():
        c0, c1 = min(c for c, _ in cols), max(c for c, _ in cols) + 1
        C = np.zeros((6, c1 - c0))
        for c, w in cols:
            C[:, c - c0] += w
        bd.prec.append(dict(col0=c0, ncols=c1 - c0, signed=0, cmat0=bd.add_floats(bd.cmat, C), primary=L,
                            later0=len(bd.later), nlater=1))
        bd.later.append(L)
        rec["nprop"] += 1
    rec["nterm"] = 0


def _belts(an) -> dict:
    """``belt_int`` and ``belt_flt`` of the belts with a pretension (:class:`Program`)."""
    moving, ints, flts = set(an.tree.moving), [], []
    for c in an.circuits:
        bt = an.mech.gears[c.gear].belt
        if bt is None or not bt.pretension:
            continue
        ints.append([c.j if c.j in moving else -1, c.k if c.k in moving else -1, c.carrier])
        flts.append(np.concatenate([[bt.pretension], np.ravel(c.belt.X), np.ravel(c.belt.e)]))
    return {"belt_int": np.array(ints, I64).reshape(-1, 3), "belt_flt": np.array(flts, float).reshape(-1, 19)}


def _live_terms(bd: _Builder, trec, tflt):
    """The term records the kernel reads (those of the blocks that still propagate or solve by
    terms: a local-frame block whose propagation became records drops its own), the blocks'
    ``term0`` renumbered."""
    live = np.zeros(len(trec), bool)
    for rec in bd.brec:
        live[rec["term0"]:rec["term0"] + rec["nterm"]] = True
    first = np.cumsum(live) - live
    for rec in bd.brec:
        rec["term0"] = int(first[rec["term0"]]) if rec["nterm"] else 0
    return trec[live], tflt[live]


def _sign_free(an, p) -> bool:
    """True when block plan ``p``'s matrix does not depend on the signs of its signed
    unknowns: each is a reducer's (:mod:`gearcli.model.reducers`) whose input and housing,
    the links its power-flow factor acts on, are not block links (the block holds its output)."""
    for gi in p.signed:
        g = p.groups[gi]
        c = an.circuits[g.index] if g.kind == "mesh" else None
        if c is None or an.mech.gears[c.gear].reducer is None or {c.j, c.carrier} & set(p.links):
            return False
    return True


MAX_PATTERNS = 256
"""Sign patterns of one constant block up to which the program holds every pattern's map:
a block's maps are made on first use (:class:`..pattern_maps.PatternMaps`), and 2^m of them
for m signed meshes (2^16 for 8 planets) would take minutes to make; a block with more
is solved from one base matrix (:class:`..pattern_maps.LowRank`, ``Program.lowrank``: a
k x k solve a pattern, k = m or 2m)."""


MAX_SIGNED = 32
"""Signed meshes of one block up to which the kernel solves it (above 16 its search is the
numpy path's: only the m + 1 own-sign trials).  A pattern is an i64 bit set in the code, so
63 would fit, but the cold compile grows steeply with the block: planetary_5p with 9, 15 and
30 planets (18, 30, 60 meshes) 4.5, 20 and 340 s (load 2), against 0.1 s of numpy."""


def build_program(an, plans, data_bodies: bool = False) -> Program:
    """The :class:`Program` of ``an`` and its block plans (:func:`..blocks.make_plans`); not
    ``covered`` when a block has more than :data:`MAX_SIGNED` signed meshes or a singular
    base matrix.  ``data_bodies``: the links' inertial values are run-time data
    (:attr:`Program.data_bodies`; nothing else of the program depends on them)."""
    if any(len(p.signed) > MAX_SIGNED for p in plans):
        return Program(0, {}, [], [], False)
    try:
        lowrank = {bi: low_rank(p.Ainv) for bi, p in enumerate(plans)
                   if p.F is not None and (1 << len(p.signed)) > MAX_PATTERNS}
    except (np.linalg.LinAlgError, SharingError):      # a singular base matrix: the numpy path
        return Program(0, {}, [], [], False)
    groups = unknown_groups(an)
    offsets, c = {}, 0
    for g in groups:
        offsets[(g.kind, g.index)] = (c, g.size)
        c += g.size
    signed = [(p.groups[gi].kind, p.groups[gi].index) for p in plans for gi in p.signed]
    trec, tflt, terms = general_terms(an, plans)
    bd = _Builder()
    for bi, p in enumerate(plans):
        _block(bd, an, bi, p, offsets, terms, lowrank)
        if p.F is None and len(p.links) == 1 and (not p.signed or _sign_free(an, p)):
            _local_frame(bd, an, trec, tflt, p)
    trec, tflt = _live_terms(bd, trec, tflt)
    joints, poses = _joints(an)
    cat = (lambda xs: np.concatenate(xs) if xs else np.zeros(0))
    jout, mcol, gcol, gout = output_constants(an, offsets)
    study = _Study(an, plans, lowrank)
    hot = _hot_maps(an, plans, lowrank, study)
    weights = {bi: mesh_weights(an, p.groups) for bi, p in enumerate(plans)
               if p.F is None and int(p.offs[-1]) > 6 * len(p.links)}
    free = {bi: f for bi in weights if (f := _basis(an, plans[bi], weights[bi])) is not None}
    hashed = cat([np.ravel(a) for lr in lowrank.values() for a in (lr.Y, lr.G, lr.Z, lr.W)]
                 + [np.array(h, float) for h, _ in hot.values()] + [np.ravel(t) for _, t in hot.values()]
                 + list(weights.values()) + [np.array(f[0] + f[1] + f[2], float) for f in free.values()])
    ints = (lambda xs: np.array(xs, I64))
    return Program(c, offsets, signed, [p.names for p in plans], True, joints=joints, poses=poses,
                   bodies=_bodies(an) if not data_bodies else np.full(len(an.tree.links), np.nan, BODY),
                   data_bodies=data_bodies, moving=ints(an.tree.moving), base=int(an.tree.base),
                   gravity=np.asarray(an.mech.gravity, float), S=np.ascontiguousarray(an.S, float),
                   A=np.ascontiguousarray(an.A, float), blocks=records(bd.brec, BLOCK), block_links=ints(bd.blinks),
                   group_col=ints(bd.gcol), t_col=ints(bd.tcol), ainv=cat(bd.ainv),
                   props=records(bd.prec, PROPAGATION), cmat=cat(bd.cmat), later=ints(bd.later),
                   child_basis=records(bd.cbrec, CHILD_BASIS), turns=np.array(bd.turns, float), terms=trec,
                   term_values=tflt, joint_out=jout, motor_col=mcol, gear_col=gcol, gear_out=gout, hashed=hashed,
                   lowrank=lowrank, hot=hot, weights=weights, free=free, **_belts(an),
                   losses=_hot_lossy(an, plans, build_loss_program(an, plans), study))


STUDIED_PATTERNS = 16
"""Sign patterns from which a constant block's hot patterns are found (:func:`_hot_maps`;
:class:`.signs.SignedBlock` uses them where it reads its maps from a table)."""


def _hot_maps(an, plans, lowrank: dict, study) -> dict:
    """{block: (hot pattern indices, their maps)} of the :class:`~..pattern_maps.LowRank`
    blocks and of the others with :data:`STUDIED_PATTERNS` or more: the patterns the sign
    search settles on within its first m + 1 trials for the random motions of ``study``
    (:class:`_Study`; :func:`~..pattern_maps.hot_patterns`)."""
    out = {}
    many = [bi for bi, p in enumerate(plans)
            if bi not in lowrank and p.F is not None and 1 << len(p.signed) >= STUDIED_PATTERNS]
    for bi in list(lowrank) + many:
        try:
            hot = hot_patterns(Counter(int(k) for k in study.patterns(bi)[1]))
            out[bi] = (hot, np.array([plans[bi].Ainv[k] for k in hot]))
        except (np.linalg.LinAlgError, SharingError):
            continue
    return out


class _Study:
    """256 random motions of the mechanism (a fixed seed) and, per constant block, the sign
    patterns its search settles on within its first m + 1 trials (:class:`~..signs.OwnSigns`,
    ``LowRank.solve`` or the stored maps; the block's own d'Alembert loads, without the
    wrenches of earlier blocks): a hint for speed, not a result (hot patterns, hot lossy
    maps); made on first use."""

    def __init__(self, an, plans, lowrank: dict):
        self.an, self.plans, self.lowrank, self._kin, self._pat = an, plans, lowrank, None, {}

    @property
    def kin(self):
        if self._kin is None:
            from ..inertia import inertia_load             # noqa: PLC0415
            from ..kinematics import forward               # noqa: PLC0415
            rng, an, n = np.random.default_rng(18), self.an, 256
            qi = [rng.uniform(-np.pi, np.pi, (n, an.dof)), rng.normal(size=(n, an.dof)) * 3.0,
                  rng.normal(size=(n, an.dof)) * 20.0]
            q, qd, qdd = (v @ np.asarray(an.S, float).T for v in qi)
            kin = forward(an.mech, an.tree, q, qd, qdd, qd_ind=qi[1])
            self._kin = (kin, inertia_load(an, kin))
        return self._kin[0]

    def patterns(self, bi: int):
        """(settled samples, their pattern indices) of constant block ``bi``."""
        if bi not in self._pat:
            from ..blocks import block_rhs                 # noqa: PLC0415
            from ..signs import OwnSigns, pattern_index    # noqa: PLC0415
            p, kin = self.plans[bi], self.kin
            r = block_rhs(self.an, p, kin, self._kin[1])
            lr = self.lowrank.get(bi)
            solve = ((lambda sg, idx: lr.solve(sg, r[idx])) if lr is not None else
                     (lambda sg, idx: r[idx] @ p.Ainv[pattern_index(sg)].T))
            n = r.shape[0]
            search = OwnSigns(solve, len(p.signed), [int(p.offs[gi]) for gi in p.signed], n, 1.0 + np.abs(r).max(axis=1))
            with np.errstate(all="ignore"):
                settled = np.setdiff1d(np.arange(n), search.settle())
            self._pat[bi] = (settled, np.array([pattern_index(s) for s in search.used[settled]], np.int64))
        return self._pat[bi]


def _hot_lossy(an, plans, losses, study):
    """``losses`` with :attr:`~.loss_program.BlockLosses.hot` of each constant block without
    stored maps of every pair (:func:`.lossy_maps.hot_lossy_maps`)."""
    if losses is None:
        return None
    blocks = dict(losses.blocks)
    for bi, bl in losses.blocks.items():
        if bl.phi is None or bl.maps is not None:
            continue
        p = plans[bi]
        try:
            hot = hot_lossy_maps(an, study.kin, bl, lambda k: p.Ainv[k], [int(p.offs[gi]) for gi in p.signed],
                                 *study.patterns(bi))
        except (np.linalg.LinAlgError, SharingError):
            continue
        blocks[bi] = replace(bl, hot=hot)
    return replace(losses, blocks=blocks)
