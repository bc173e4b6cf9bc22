"""Fast block solves: each block's equations written in a frame where they are constant.

For a block of the schedule, pick a link F in which every unknown of the block is fixed: a
joint reaction is fixed in its parent and in its child (its force/moment basis may be taken
in either, since the 5-dimensional reaction space is invariant under rotation about the
axis), a motor torque in every link of its coaxial group, a tooth force in the carrier.
Writing the block's Newton-Euler equations about F's origin in F's axes makes the matrix
A_sigma constant along the motion, for each sign pattern sigma of the tangential tooth
forces; its inverse is computed once, and a block solve becomes a small matrix product per
sample.  Blocks with no such frame fall back to the general (world-frame) solve.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..spatial import cross
from .coaxial_frames import coaxial_links, turn_row
from .determinacy import block_unknowns
from .equations import Columns
from .general import is_geared, mesh_names, solve_general
from .kinematics import Kinematics, forward
from .losses import relative_rate
from .pattern_maps import PatternMaps
from .sharing import mesh_weights
from .signs import SignError, pattern_index, resolve_signs, rows_by_pattern


@dataclass(frozen=True, eq=False)
class BlockPlan:
    """Precomputed solve of one block of the schedule (built once per analysis)."""

    links: tuple[int, ...]
    groups: list            # UnknownGroup owned by the block
    F: int | None           # frame link, None -> general solve
    signed: list[int]       # positions in groups of signed mesh unknowns
    offs: np.ndarray        # column offsets of the groups
    Ainv: PatternMaps       # solution map per pattern (n, 6*len(links)), a sequence made on
                            # first use; rectangular (n > 6*len(links)) for a redundant gear
                            # set: the least-t^2/k map
    names: list             # gear pair names of the signed unknowns (messages)
    C: dict                 # group position -> (C_plus (6,size), C_sep (6,size)) in F about o_F, primary side
    parent_side: dict       # group position -> True when a joint basis is not its child's (rotate by -q)
    # group position -> (J,) row: a joint basis carried by a third coaxial link F
    # (:mod:`.coaxial_frames`), turned to the child's by -(q_all @ row) instead of -q
    turn: dict = field(default_factory=dict)
    # Mesh friction (:mod:`.losses`): (m, 6B) the friction couples of each signed mesh per
    # unit of sigma s_v t in F (zero rows for a lossless mesh), None when no mesh of the
    # block loses power; group position -> (6, 1) the couple on the primary side in F.
    fric: np.ndarray | None = None
    fric_C: dict = field(default_factory=dict)
    # s_v pattern (tuple of -1/0/1 per signed mesh) -> PatternMaps, made on first use
    fric_maps: dict = field(default_factory=dict)
    # group position -> the links of later blocks it acts on (its solved wrench is passed on)
    later: dict = field(default_factory=dict)


def _spread(an, g) -> bool:
    """True when g's wrench is not one wrench applied +/- to two links fixed in one frame: a
    motor acting on several joints (a transmission), an ideal coupling or a reducer (torques
    on several links), or a lossy screw (its torque's power-flow factor varies per sample)."""
    if g.kind == "motor":
        mj = an.motor_joints[g.index] if an.motor_joints else None
        return mj is not None and len(mj) > 1
    if g.kind == "mesh":
        c = an.circuits[g.index]
        sc = an.mech.gears[c.gear].screw
        if sc is not None:           # fixed in the carrier; lossy: its torque's factor per sample
            return sc.power_flow_lossy
        if an.mech.gears[c.gear].worm is not None or an.mech.gears[c.gear].belt is not None:
            return True               # per sample (a worm's friction; a belt's forces at four points)
        return c.geometry is None
    return False


def _fixed_in(an, g) -> set[int]:
    """Links in which the wrench basis of unknown g is fixed (empty: none, general solve)."""
    mech, tree = an.mech, an.tree
    if _spread(an, g):
        return set()
    if g.kind == "joint":
        jt = mech.joints[g.index]
        c = tree.index[jt.child]
        return {c} if jt.type == "prismatic" else {tree.index[jt.parent], c} | coaxial_links(an, g.index)
    if g.kind == "motor":
        x, s = an.motor_links[g.index], an.motor_stators[g.index]
        if mech.joints[tree.parent_joint[x]].type == "prismatic":
            return {x}
        for grp in an.groups:
            if x in grp.members and s in grp.members:
                return set(grp.members)
        return {x, s}
    return {an.circuits[g.index].carrier}


def primary_side(an, g) -> int:
    """The link that receives +column of group g."""
    if g.kind == "joint":
        return an.tree.index[an.mech.joints[g.index].child]
    if g.kind == "motor":
        return an.motor_links[g.index]
    return an.circuits[g.index].j


def _constant_matrices(an, blk, gs, offs, signed, to_F, cols) -> PatternMaps:
    """Solution map of the block in F about o_F for each sign pattern, made on first use
    (:class:`.pattern_maps.PatternMaps`): the inverse of the square block matrix, or for a
    redundant block (more unknowns than equations) the rectangular (n, 6B) map to the
    solution that minimises sum t^2 / k (:func:`.sharing.least_load_map`)."""
    w = mesh_weights(an, gs) if offs[-1] > 6 * len(blk) else None
    A = np.zeros((6 * len(blk), offs[-1]))
    halves = np.zeros((len(signed), 6 * len(blk)))
    for gi, g in enumerate(gs):
        for L in g.links:
            if L in blk:
                r0 = 6 * blk.index(L)
                A[r0:r0 + 6, offs[gi]:offs[gi + 1]] = to_F(cols.group(g, L, 1.0), L)
                if gi in signed:
                    minus = to_F(cols.group(g, L, -1.0), L)[:, 0]
                    halves[signed.index(gi), r0:r0 + 6] = 0.5 * (A[r0:r0 + 6, offs[gi]] - minus)
                    A[r0:r0 + 6, offs[gi]] = 0.5 * (A[r0:r0 + 6, offs[gi]] + minus)
    return PatternMaps(A, halves, [int(offs[gi]) for gi in signed], w)


def _propagation_columns(an, F, gs, signed, to_F, cols) -> tuple[dict, dict]:
    """Per group: its wrench on its primary-side link in F (ut part, us part) and whether a
    joint's basis is its parent's (the solution is then rotated by -q to the child's)."""
    C, parent_side = {}, {}
    for gi, g in enumerate(gs):
        P = primary_side(an, g)
        if gi in signed:
            cp, cm = to_F(cols.group(g, P, 1.0), P), to_F(cols.group(g, P, -1.0), P)
            C[gi] = ((cp + cm) / 2, (cp - cm) / 2)
        else:
            C[gi] = (to_F(cols.group(g, P, 1.0), P), None)
        if g.kind == "joint":
            jt = an.mech.joints[g.index]
            parent_side[gi] = jt.type != "prismatic" and F != an.tree.index[jt.child]
    return C, parent_side


def _friction_columns(an, blk, gs, signed, to_F, cols) -> tuple[np.ndarray | None, dict]:
    """Mesh friction of a constant block (:mod:`.losses`): the (m, 6B) couples of its signed
    meshes per unit of sigma s_v t in F (None if no mesh loses power) and, per lossy group,
    its (6, 1) couple on the primary side (j) in F."""
    fric = np.zeros((len(signed), 6 * len(blk)))
    fric_C = {}
    for n, gi in enumerate(signed):
        g, P = gs[gi], primary_side(an, gs[gi])
        couple = cols.mesh_friction(g.index, P)
        if couple is None:
            continue
        for L in g.links:
            if L in blk:
                r0 = 6 * blk.index(L)
                fric[n, r0:r0 + 6] = to_F(cols.mesh_friction(g.index, L), L)[:, 0]
        fric_C[gi] = to_F(couple, P)
    return (fric if fric_C else None), fric_C


def _frame(an, gs, common: set) -> tuple[int | None, dict]:
    """The frame link F of a block among the ``common`` candidates (the base first: no
    rotation; then links that carry every joint basis as its parent or child) and the turn
    rows of the joints whose basis F carries as a third coaxial link ({} if none)."""
    tree = an.tree

    def third(F):
        return [gi for gi, g in enumerate(gs) if g.kind == "joint" and F not in
                (tree.index[an.mech.joints[g.index].parent], tree.index[an.mech.joints[g.index].child])]
    for F in sorted(common, key=lambda x: (x != tree.base, len(third(x)), x)):
        turn = {gi: turn_row(an, gs[gi].index, F) for gi in third(F)}
        if all(row is not None for row in turn.values()):
            return F, turn
    return None, {}


SNAP = 8 * np.finfo(float).eps
"""A constant-frame block's home column entry at most this fraction of its column's largest is 0."""


def make_plans(an) -> tuple[BlockPlan, ...]:
    """Block plans of ``an.schedule`` (computed once per analysis, owned by the solver)."""
    tree = an.tree
    owned = block_unknowns(an)
    block_of = {L: i for i, blk in enumerate(an.schedule) for L in blk}
    home = forward(an.mech, tree, np.zeros((1, len(an.mech.joints))))
    cols = Columns(an, home)
    plans = []
    for bi, blk in enumerate(an.schedule):
        gs = owned[bi]
        offs = np.cumsum([0] + [g.size for g in gs])
        signed = [i for i, g in enumerate(gs) if is_geared(an, g)]
        names = mesh_names(an, gs, signed)
        later = {gi: [L for L in g.links if block_of[L] > bi] for gi, g in enumerate(gs)}
        common = set.intersection(*[_fixed_in(an, g) for g in gs]) if gs else set()
        F, turn = _frame(an, gs, common) if common and offs[-1] >= 6 * len(blk) else (None, {})
        if F is None:
            plans.append(BlockPlan(tuple(blk), gs, None, signed, offs, [], names, {}, {}, later=later))
            continue
        RF, oF = home.R[F][0], home.o[F][0]

        def to_F(col, L):
            """world column(s) about o_L at home -> F axes about o_F, each entry within a few
            ulps of its column's largest set to an exact 0: a structural zero that the axes'
            products left at 1e-17 (the column terms turn a joint's axes by R_c R_jc^T) would
            cost the kernel a multiply per sample where the constant 0 folds away."""
            col = col[0]
            f, m = col[:3], col[3:] + np.cross(home.o[L][0] - oF, col[:3], axis=0)
            out = np.vstack([RF.T @ f, RF.T @ m])
            out[np.abs(out) <= SNAP * np.abs(out).max(axis=0)] = 0.0
            return out

        Ainv = _constant_matrices(an, blk, gs, offs, signed, to_F, cols)
        C, parent_side = _propagation_columns(an, F, gs, signed, to_F, cols)
        fric, fric_C = _friction_columns(an, blk, gs, signed, to_F, cols)
        plans.append(BlockPlan(tuple(blk), gs, F, signed, offs, Ainv, names,
                               C, parent_side, turn, fric, fric_C, later=later))
    return tuple(plans)


def _rotate(R, w6, transpose=False):
    """Both halves of wrenches (N,6) rotated by R (N,3,3) (or by R^T)."""
    w = w6.reshape(-1, 2, 3)                      # rows: force, moment
    return np.matmul(w, R if transpose else R.transpose(0, 2, 1)).reshape(-1, 6)


def _shift(w6, o_from, o_to):
    """Wrench (N,6) about o_from -> about o_to."""
    out = w6.copy()
    out[:, 3:] += cross(o_from - o_to, w6[:, :3])
    return out


def _subtract(acc, sign, w6, o_from, o_to):
    """acc (N,6) about o_to -= sign * (wrench w6 about o_from), in place (sign +-1)."""
    acc -= sign * w6
    acc[:, 3:] -= sign * cross(o_from - o_to, w6[:, :3])


def _general_block(an, p: BlockPlan, cols: Columns, rhs: dict, x_all: dict, sig_all: dict):
    """Solve a block without a constant frame (world frame) and pass its loads on."""
    R = np.concatenate([rhs[L] for L in p.links], axis=1)
    x, sig = solve_general(an, cols, p.groups, list(p.links), R)
    sig_all.update(sig)
    for gi, g in enumerate(p.groups):
        xg = x[:, p.offs[gi]:p.offs[gi + 1]]
        x_all[(g.kind, g.index)] = xg
        for L in p.later[gi]:
            C = cols.group(g, L, sig.get((g.kind, g.index), 1.0))
            rhs[L] -= np.einsum("nij,nj->ni", C, xg)


def block_rhs(an, p: BlockPlan, kin: Kinematics, rhs: dict) -> np.ndarray:
    """r (N, 6B): the right-hand sides ``rhs`` of the block's links in its frame F's axes, about o_F."""
    at_rest = p.F == an.tree.base        # F = base: world axes about the origin already
    RF, oF = kin.R[p.F], kin.o[p.F]
    parts = []
    for L in p.links:
        w = _shift(rhs[L], kin.o[L], oF) if L != p.F else rhs[L]
        parts.append(w if at_rest else _rotate(RF, w, transpose=True))
    return np.concatenate(parts, axis=1) if len(parts) > 1 else parts[0]


def _constant_block(an, p: BlockPlan, kin: Kinematics, rhs: dict):
    """Solve a block in its constant frame F: x (N, n), signs (N, m), s_v (N, m) of its
    meshes (None when no mesh of the block loses power)."""
    r = block_rhs(an, p, kin, rhs)
    N = r.shape[0]
    if not p.signed:
        return r @ p.Ainv[0].T, np.zeros((N, 0)), None
    scale = 1.0 + np.abs(r).max(axis=1)
    t_cols = [int(p.offs[gi]) for gi in p.signed]
    sv, parts = None, [(None, p.Ainv)]       # (rows, their maps): every row, the lossless maps
    if p.fric is not None:       # lossy meshes: the block matrix depends on s_v too, maps per s_v pattern met
        sv = np.column_stack([np.sign(relative_rate(an, kin, p.groups[gi].index)) if gi in p.fric_C
                              else np.zeros(N) for gi in p.signed])
        parts = [(rows, _friction_maps(p, tuple(sv[rows[0]]))) for rows in rows_by_pattern(sv)]
    x, signs, first_bad = None, None, None
    for rows, maps in parts:
        rr, sc = (r, scale) if rows is None else (r[rows], scale[rows])

        def solve_pattern(sg, idx, rr=rr, maps=maps):
            return (rr if idx.size == rr.shape[0] else rr[idx]) @ maps[pattern_index(sg)].T
        try:
            xs, ss = resolve_signs(solve_pattern, len(p.signed), t_cols, rr.shape[0], sc, p.names)
        except SignError as exc:
            bad = exc.sample if rows is None else int(rows[exc.sample])
            first_bad = bad if first_bad is None else min(first_bad, bad)
            continue
        if rows is None:
            return xs, ss, None
        if x is None:
            x, signs = np.empty((N, xs.shape[1])), np.empty((N, len(p.signed)))
        x[rows], signs[rows] = xs, ss
    if first_bad is not None:
        raise SignError(first_bad, p.names)
    return x, signs, sv


def _friction_maps(p: BlockPlan, key: tuple) -> PatternMaps:
    """The block's maps for the s_v pattern ``key`` (made on first use): its signed columns
    gain s_v times their friction couple."""
    if key not in p.fric_maps:
        p.fric_maps[key] = PatternMaps(p.Ainv.A_mid, p.Ainv.halves + np.array(key)[:, None] * p.fric,
                                       p.Ainv.cols, p.Ainv.w) if any(key) else p.Ainv
    return p.fric_maps[key]


def _child_basis(x: np.ndarray, q: np.ndarray) -> np.ndarray:
    """A revolute joint's reaction (N, 5) from its parent's basis to its child's (turn by -q)."""
    c, s = np.cos(q), np.sin(q)
    out = x.copy()
    out[:, 0], out[:, 1] = c * x[:, 0] + s * x[:, 1], -s * x[:, 0] + c * x[:, 1]
    out[:, 3], out[:, 4] = c * x[:, 3] + s * x[:, 4], -s * x[:, 3] + c * x[:, 4]
    return out


def solve_blocks(an, plans, kin: Kinematics, b: dict, q_all: np.ndarray):
    """Block-by-block solve in schedule order (highest level first).

    ``b`` are the d'Alembert loads (:func:`~.inertia.inertia_load`), ``q_all`` (N, J) every
    real joint's coordinate.  Returns ({(kind, index): (N, size)} unknowns, joint reactions
    in their child's basis; {(kind, index): (N,) sign of t}).
    """
    rhs = {L: b[L].copy() for L in an.tree.moving}
    x_all, sig_all = {}, {}
    cols = None
    for p in plans:
        if p.F is None:
            cols = cols if cols is not None else Columns(an, kin)
            _general_block(an, p, cols, rhs, x_all, sig_all)
            continue
        x, signs, sv = _constant_block(an, p, kin, rhs)
        at_rest = p.F == an.tree.base
        for gi, g in enumerate(p.groups):
            xg = x[:, p.offs[gi]:p.offs[gi + 1]]
            if p.later[gi]:
                Cp, Cs = p.C[gi]
                wF = xg @ Cp.T if Cs is None else xg @ Cp.T + np.abs(xg) @ Cs.T
                if gi in p.fric_C:     # friction couple, sigma s_v t = s_v |t|
                    wF = wF + (np.abs(xg) * sv[:, p.signed.index(gi), None]) @ p.fric_C[gi].T
                w = wF if at_rest else _rotate(kin.R[p.F], wF)           # world axes, about o_F
                P = primary_side(an, g)
                for L in p.later[gi]:
                    _subtract(rhs[L], 1.0 if L == P else -1.0, w, kin.o[p.F], kin.o[L])
            if gi in p.signed:
                sig_all[(g.kind, g.index)] = signs[:, p.signed.index(gi)]
            if p.parent_side.get(gi):
                xg = _child_basis(xg, q_all @ p.turn[gi] if gi in p.turn else q_all[:, g.index])
            x_all[(g.kind, g.index)] = xg
    return x_all, sig_all
