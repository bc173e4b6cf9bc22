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

import itertools
from dataclasses import dataclass

import numpy as np

from .kinematics import forward
from .loads import Columns
from ..analysis.schedule import unknown_groups
from ..spatial import cross


@dataclass
class BlockPlan:
    links: tuple[int, ...]
    groups: list            # UnknownGroup owned by the block
    F: int | None           # frame link, None -> general solve
    signed: list[int]       # positions in groups of signed mesh unknowns
    offs: np.ndarray        # column offsets of the groups
    patterns: list          # sign patterns
    Ainv: list              # inverse matrix per pattern, (n, 6*len(links))
    C: dict                 # group position -> (C_plus (6,size), C_sep (6,size)) in F about o_F, primary side
    parent_side: dict       # group position -> True when a joint basis is its parent's (rotate by -q)


def _spread(an, g) -> bool:
    """True when g's wrench is not one wrench applied +/- to two links: a motor acting on
    several joints (a transmission) or an ideal coupling (torques on several links)."""
    if g.kind == "motor":
        mj = an.motor_joints[g.index] if an.motor_joints else None
        return mj is not None and len(mj) > 1
    if g.kind == "mesh":
        return an.circuits[g.index].geometry is None
    return False


def _fixed_in(an, g) -> set[int]:
    """Links in which the wrench basis of unknown g is fixed (empty: none, general solve)."""
    mech, tree = an.mech, an.tree
    if _spread(an, g):
        return set()
    if g.kind == "joint":
        jt = mech.joints[g.index]
        c = tree.index[jt.child]
        return {c} if jt.type == "prismatic" else {tree.index[jt.parent], c}
    if g.kind == "motor":
        x, s = an.motor_links[g.index], an.motor_stators[g.index]
        if mech.joints[tree.parent_joint[x]].type == "prismatic":
            return {x}
        for grp in an.groups:
            if x in grp.members and s in grp.members:
                return set(grp.members)
        return {x, s}
    return {an.circuits[g.index].carrier}


def _primary_side(an, g) -> int:
    """The link that receives +column of group g."""
    if g.kind == "joint":
        return an.tree.index[an.mech.joints[g.index].child]
    if g.kind == "motor":
        return an.motor_links[g.index]
    return an.circuits[g.index].j


def make_plans(an) -> list[BlockPlan]:
    """Block plans of ``an.schedule`` (computed once per analysis)."""
    tree = an.tree
    groups = unknown_groups(an)
    blocks = an.schedule
    block_of = {L: i for i, blk in enumerate(blocks) for L in blk}
    owned: dict[int, list] = {i: [] for i in range(len(blocks))}
    for g in groups:
        owned[min(block_of[L] for L in g.links)].append(g)
    home = forward(an.mech, tree, np.zeros((1, len(an.mech.joints))))
    cols = Columns(an, home)
    plans = []
    for bi, blk in enumerate(blocks):
        gs = owned[bi]
        offs = np.cumsum([0] + [g.size for g in gs])
        signed = [i for i, g in enumerate(gs) if g.kind == "mesh" and an.circuits[g.index].geometry is not None]
        common = set.intersection(*[_fixed_in(an, g) for g in gs]) if gs else set()
        if not common or offs[-1] != 6 * len(blk):
            plans.append(BlockPlan(tuple(blk), gs, None, signed, offs, [], [], {}, {}))
            continue
        F = min(common, key=lambda x: (x != tree.base, x))  # prefer the base: no rotation
        RF, oF = home.R[F][0], home.o[F][0]

        def to_F(col, L):
            """world column(s) about o_L at home -> F axes about o_F."""
            col = col[0]
            f, m = col[:3], col[3:] + np.cross(home.o[L][0] - oF, col[:3], axis=0)
            return np.vstack([RF.T @ f, RF.T @ m])

        patterns = list(itertools.product((1.0, -1.0), repeat=len(signed)))
        Ainv = []
        for pat in patterns:
            sig = dict(zip(signed, pat))
            A = np.zeros((6 * len(blk), offs[-1]))
            for gi, g in enumerate(gs):
                for L in g.links:
                    if L in blk:
                        r0 = 6 * blk.index(L)
                        A[r0:r0 + 6, offs[gi]:offs[gi + 1]] = to_F(cols.group(g, L, sig.get(gi, 1.0)), L)
            Ainv.append(np.linalg.inv(A))
        C, parent_side = {}, {}
        for gi, g in enumerate(gs):
            P = _primary_side(an, g)
            if g.kind == "mesh" and gi in signed:
                cp = to_F(cols.group(g, P, 1.0), P)
                cm = to_F(cols.group(g, P, -1.0), P)
                C[gi] = ((cp + cm) / 2, (cp - cm) / 2)   # ut part, us part
            else:
                C[gi] = (to_F(cols.group(g, P, 1.0), P), None)
            if g.kind == "joint":
                jt = an.mech.joints[g.index]
                parent_side[gi] = jt.type != "prismatic" and F != tree.index[jt.child]
        plans.append(BlockPlan(tuple(blk), gs, F, signed, offs, patterns, Ainv, C, parent_side))
    return plans


def plans_of(an) -> list[BlockPlan]:
    plans = an.__dict__.get("_plans")
    if plans is None:
        plans = make_plans(an)
        object.__setattr__(an, "_plans", plans)
    return plans


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
    """acc (N,6) about o_to -= sign * (wrench w6 about o_from), in place."""
    if sign > 0:
        acc -= w6
        acc[:, 3:] -= cross(o_from - o_to, w6[:, :3])
    else:
        acc += w6
        acc[:, 3:] += cross(o_from - o_to, w6[:, :3])


def solve_blocks(an, kin, b, q_all, general):
    """Block-by-block solve.  ``general(groups, links, rhs)`` solves a block without a
    constant frame.  Returns x_all (post-rotation joint bases) and the mesh signs."""
    tree = an.tree
    plans = plans_of(an)
    block_of = {L: i for i, p in enumerate(plans) for L in p.links}
    rhs = {L: b[L].copy() for L in tree.moving}
    x_all, sig_all = {}, {}
    cols = None
    for bi, p in enumerate(plans):
        if p.F is None:
            if cols is None:
                cols = Columns(an, kin)
            R = np.concatenate([rhs[L] for L in p.links], axis=1)
            x, sig = general(p.groups, list(p.links), R)
            sig_all.update(sig)
            for gi, g in enumerate(p.groups):
                xg = x[:, p.offs[gi]:p.offs[gi + 1]]
                x_all[(g.kind, g.index)] = xg
                for L in g.links:
                    if block_of[L] > bi:
                        C = cols.group(g, L, sig.get((g.kind, g.index), 1.0))
                        rhs[L] -= np.einsum("nij,nj->ni", C, xg)
            continue
        at_rest = p.F == tree.base        # F = base: world axes about the origin already
        RF, oF = kin.R[p.F], kin.o[p.F]
        parts = []
        for L in p.links:
            w = _shift(rhs[L], kin.o[L], oF) if L != p.F else rhs[L]
            parts.append(w if at_rest else _rotate(RF, w, transpose=True))
        r = np.concatenate(parts, axis=1) if len(parts) > 1 else parts[0]   # (N, 6B) in F about o_F
        N = r.shape[0]
        if p.signed:
            # the first sign pattern consistent with its own solution (tolerance for t ~ 0),
            # else the least inconsistent one
            xs = [r @ Ai.T for Ai in p.Ainv]
            tol = 1e-12 * (1.0 + np.abs(r).max(axis=1))
            viol = np.stack([np.max([-s * xk[:, p.offs[gi]] for gi, s in zip(p.signed, pat)], axis=0)
                             for pat, xk in zip(p.patterns, xs)], axis=1)        # (N, patterns)
            ok = viol <= tol[:, None]
            pick = np.where(ok.any(axis=1), np.argmax(ok, axis=1), np.argmin(viol, axis=1))
            x = np.choose(pick[:, None], xs) if len(xs) < 32 else np.stack(xs)[pick, np.arange(N)]
            pat_arr = np.array(p.patterns)[pick]                       # (N, m)
        else:
            x = r @ p.Ainv[0].T
        # contributions of solved unknowns to later links, and results
        for gi, g in enumerate(p.groups):
            xg = x[:, p.offs[gi]:p.offs[gi + 1]]
            key = (g.kind, g.index)
            Cp, Cs = p.C[gi]
            later = [L for L in g.links if block_of[L] > bi]
            if later:
                wF = xg @ Cp.T
                if Cs is not None:
                    wF = wF + np.abs(xg) @ Cs.T
                w = wF if at_rest else _rotate(RF, wF)                  # world axes, about o_F
                P = _primary_side(an, g)
                for L in later:
                    _subtract(rhs[L], 1.0 if L == P else -1.0, w, oF, kin.o[L])
            if gi in p.signed:
                sig_all[key] = pat_arr[:, p.signed.index(gi)]
            if p.parent_side.get(gi):
                qj = q_all[:, g.index]
                c, s = np.cos(qj), np.sin(qj)
                xg = xg.copy()
                xg[:, 0], xg[:, 1] = c * x[:, p.offs[gi]] + s * x[:, p.offs[gi] + 1], -s * x[:, p.offs[gi]] + c * x[:, p.offs[gi] + 1]
                xg[:, 3], xg[:, 4] = c * x[:, p.offs[gi] + 3] + s * x[:, p.offs[gi] + 4], -s * x[:, p.offs[gi] + 3] + c * x[:, p.offs[gi] + 4]
            x_all[key] = xg
    return x_all, sig_all
