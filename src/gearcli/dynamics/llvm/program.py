"""The compiled kernel's "program": one analysed mechanism flattened into a few arrays.

The generated kernel (:mod:`.kernel`) is made from the arrays built here once per
analysis (from the
:class:`~gearcli.analysis.graph.Analysis` and the block plans of :func:`..blocks.make_plans`):

* ``jrec`` (J, 5) int: per real joint in tree order [joint index, parent link, child link,
  1 if prismatic, flags: 1 parent is the base, 2 R_pj = I, 4 R_jc = I, 8 p_jc = 0]; ``jflt`` (J, 24): R_pj (row-major), p_pj, R_jc, p_jc;
* ``lflt`` (L, 13): per link mass, inertia about the centre of mass (link axes, row-major),
  centre of mass (link frame); ``moving`` the moving link ids;
* ``ldrec`` (nloads, 4) int [link, 1 if in link axes, row offset in the values array,
  1 if one row per sample]; ``ldflt`` (nloads, 3) the load point (link frame);
* ``brec`` (B, 14) int per block (schedule order): [F, links offset, number of links,
  unknowns n, column offset, signed meshes m, t offset, Ainv offset, propagation offset,
  propagations, child-basis offset, child-basis count, term offset, term count]; ``blinks``
  the links; ``gcol`` each block column's position in the solution row; ``tcol`` the
  block columns of the signed t; ``scol`` their position in the signs row;
* ``ainv`` every pattern's (n, 6B) inverse (row-major, patterns in
  :func:`~..signs.sign_patterns` order: rectangular matrices are fine);
* ``prec`` (P, 7) int per propagated group [first column, size, 1 if signed, cmat offset,
  primary link, later-links offset, count]; ``cmat`` its C_plus (6, size) then C_sep;
  ``later`` the later links;
* ``cbrec`` (C, 3) int [first column, joint index or -1, offset in ``turns``]: joint
  reactions solved in another link's basis, turned to the child's by -q of the joint, or
  by -(q @ row) with the (J,) row at the offset in ``turns`` (a basis carried by a third
  coaxial link, :mod:`..coaxial_frames`); ``meta`` [base link id];
* the output maps of :func:`.output_maps.output_constants` and the structure matrix A;
* last, S (q = S q_ind), A (tau = A motor) and A^T (motor speed = A^T qd) by rows of
  nonzeros (:func:`_csr`): ``ints[15:21]`` their row pointers and column indices,
  ``flts[10:13]`` their values.

Blocks without a constant frame (F = -1 in ``brec``) are solved in world axes from the
column terms of :mod:`.terms`; one whose matrix is nevertheless constant in its one
link's axes gets F = that link and its inverse (:func:`_local_frame`), and keeps its terms
(term count > 0) for the propagation.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ...analysis.schedule import unknown_groups
from ..blocks import _primary_side, make_plans
from .output_maps import output_constants
from ..pattern_maps import hot_patterns, low_rank
from ..sharing import SharingError, mesh_weights
from ..signs import MAX_EXHAUSTIVE
from .terms import general_terms, local_inverse

I64 = np.int64


@dataclass(frozen=True, eq=False)
class Program:
    """A mechanism flattened for the kernel (see module docstring)."""

    ints: tuple          # int64 arrays, in the kernel's order
    flts: tuple          # float64 arrays, in the kernel's order
    ncols: int           # unknowns per sample (every group, in unknown_groups order)
    offsets: dict        # (kind, index) -> (first column, size)
    signed: list         # (kind, index) of each signs column
    names: list          # per block: names of its signed meshes (SignError)
    covered: bool        # False: a block the generated kernel cannot solve (use the numpy path)
    lowrank: dict = field(default_factory=dict)   # block -> pattern_maps.LowRank (too many patterns to store)
    hot: dict = field(default_factory=dict)       # block -> (hot pattern indices, their maps (k, n, 6B))
    weights: dict = field(default_factory=dict)   # redundant world-frame block -> sharing.mesh_weights
    free: dict = field(default_factory=dict)      # redundant world-frame block -> its free columns (_free_columns)


def _joints(an):
    mech, tree = an.mech, an.tree
    rec, flt = [], []
    for ji in tree.order:
        jt = mech.joints[ji]
        c = tree.index[jt.child]
        eye = np.eye(3)
        flags = (int(tree.parent[c] == tree.base) | 2 * int(np.array_equal(jt.R_pj, eye))
                 | 4 * int(np.array_equal(jt.R_jc, eye)) | 8 * int(not np.any(jt.p_jc)))
        rec.append([ji, tree.parent[c], c, int(jt.type == "prismatic"), flags])
        flt.append(np.concatenate([np.ravel(jt.R_pj), jt.p_pj, np.ravel(jt.R_jc), jt.p_jc]))
    return np.array(rec, I64).reshape(-1, 5), np.array(flt, float).reshape(-1, 24)


def _links(an):
    out = np.zeros((len(an.tree.links), 13))
    for L in an.tree.moving:
        link = an.mech.bodies[L]          # payloads merged
        out[L] = np.concatenate([[link.mass], np.ravel(link.inertia), link.com])
    return out


def _loads(an, values: dict, n: int):
    """Load records and the stacked values: one row (constant) or n rows per load."""
    rec, pts, rows = [], [], []
    off = 0
    for ld in an.mech.loads:
        w = values[ld.name]
        per = int(w.strides[0] != 0 and n > 1)
        w = np.ascontiguousarray(w if per else w[:1], float)
        rec.append([an.tree.index[ld.link], int(ld.frame == "link"), off, per])
        pts.append(np.asarray(ld.point, float))
        rows.append(w)
        off += w.shape[0]
    vals = (rows[0] if len(rows) == 1 else np.concatenate(rows)) if rows else np.zeros((1, 6))  # no copy of one
    return np.array(rec, I64).reshape(-1, 4), np.array(pts, float).reshape(-1, 3), vals


def load_arrays(an, values: dict, n: int):
    """(ldrec, ldflt, vals) of the loads of ``an`` for n samples (see module docstring)."""
    return _loads(an, values, n)


class _Builder:
    """Accumulates the per-block arrays."""

    def __init__(self):
        self.brec, self.blinks, self.gcol, self.tcol, self.scol = [], [], [], [], []
        self.ainv, self.prec, self.cmat, self.later, self.cbrec, self.turns = [], [], [], [], [], []
        self.ainv_len = self.cmat_len = 0

    def add_floats(self, attr: str, arr) -> int:
        arr = np.ascontiguousarray(arr, float).ravel()
        off = getattr(self, attr + "_len")
        getattr(self, attr).append(arr)
        setattr(self, attr + "_len", off + arr.size)
        return off

    def propagation(self, an, p, gi, g, later, first: int) -> bool:
        """Append group gi's propagation record (False: merged into the previous one)."""
        Cp, Cs = p.C[gi]
        if Cs is None and self._merge(int(p.offs[gi]), g.size, _primary_side(an, g), later, Cp, first):
            return False
        off = self.add_floats("cmat", Cp)
        if Cs is not None:
            self.add_floats("cmat", Cs)
        self.prec.append([int(p.offs[gi]), g.size, int(Cs is not None), off, _primary_side(an, g),
                          len(self.later), len(later)])
        self.later += later
        return True

    def _merge(self, c0, size, P, later, Cp, first) -> bool:
        """Unsigned groups in adjacent columns acting on the same later links (same primary
        link) share one record: their wrenches are summed in F before the one rotation
        (a serial chain's joint reaction and motor torque)."""
        if len(self.prec) <= first:
            return False
        last = self.prec[-1]
        if last[2] or last[0] + last[1] != c0 or last[4] != P or self.later[last[5]:last[5] + last[6]] != later:
            return False
        prev = self.cmat.pop().reshape(6, last[1])
        self.cmat_len -= prev.size
        last[3] = self.add_floats("cmat", np.hstack([prev, np.asarray(Cp, float).reshape(6, size)]))
        last[1] += size
        return True


def _block(bd: _Builder, an, bi, p, block_of, offsets, sigcol, terms):
    """Append block ``bi`` (plan ``p``) to the builder."""
    n = int(p.offs[-1])
    rec = [-1 if p.F is None else p.F, len(bd.blinks), len(p.links), n, len(bd.gcol), len(p.signed),
           len(bd.tcol), bd.ainv_len, len(bd.prec), 0, len(bd.cbrec), 0, *terms.get(bi, (0, 0))]
    bd.blinks += list(p.links)
    for g in p.groups:
        bd.gcol += range(offsets[(g.kind, g.index)][0], offsets[(g.kind, g.index)][0] + g.size)
    for gi in p.signed:
        bd.tcol.append(int(p.offs[gi]))
        bd.scol.append(sigcol[(p.groups[gi].kind, p.groups[gi].index)])
    if p.F is not None and (1 << len(p.signed)) > MAX_PATTERNS:
        rec[7] = -1                        # solved from its pattern_maps.LowRank (program.lowrank)
    else:
        for A in p.Ainv:
            bd.add_floats("ainv", A)
    for gi, g in enumerate(p.groups):
        later = [L for L in g.links if block_of[L] > bi]
        if later and p.F is not None and bd.propagation(an, p, gi, g, later, rec[8]):
            rec[9] += 1
        if p.parent_side.get(gi):
            if gi in p.turn:               # basis carried by a third coaxial link: q @ row
                bd.cbrec.append([int(p.offs[gi]), -1, len(bd.turns)])
                bd.turns += [float(v) for v in p.turn[gi]]
            else:
                bd.cbrec.append([int(p.offs[gi]), g.index, 0])
            rec[11] += 1
    bd.brec.append(rec)


def _local_frame(bd: _Builder, trec, tflt, p) -> None:
    """A world-frame block whose matrix is constant in its link's axes
    (:func:`.terms.local_inverse`) becomes a constant-frame block in that link
    (F = the link, its inverse in ``ainv``) that keeps its terms for the propagation."""
    rec = bd.brec[-1]
    Ainv = local_inverse(trec, tflt, rec[12], rec[13], p.links[0], rec[3])
    if Ainv is not None:
        rec[0], rec[7] = p.links[0], bd.add_floats("ainv", Ainv)


MAX_PATTERNS = 256
"""Sign patterns of one constant block up to which the program holds every pattern's map:
a block's maps are made on first use (:class:`..pattern_maps.PatternMaps`), and 2^m of them
for m signed meshes (2^16 for 8 planets) would take minutes to make; a block with more
is solved from one base matrix (:class:`..pattern_maps.LowRank`, ``Program.lowrank``: a
k x k solve a pattern, k = m or 2m)."""


def _csr(M: np.ndarray) -> tuple:
    """(row pointers (R+1,), column indices, values) of M's nonzero entries, row by row in
    column order: a product over them adds exactly what the dense product adds (+0 terms
    change no sum), in O(nonzeros) instead of O(R C) (S and A are one or two entries a row
    for a chain of geared links, dense (J, dof) and (dof, M) otherwise)."""
    rows, cols = np.nonzero(M)
    ptr = np.zeros(M.shape[0] + 1, I64)
    np.add.at(ptr, rows + 1, 1)
    idx = cols.astype(I64)
    return np.cumsum(ptr).astype(I64), (idx if idx.size else np.zeros(1, I64)), \
        (M[rows, cols] if rows.size else np.zeros(1))


def build_program(an, plans=None) -> Program:
    """The :class:`Program` of ``an`` (``plans`` from :func:`..blocks.make_plans`); not
    ``covered`` when a redundant block has no constant frame."""
    plans = make_plans(an) if plans is None else plans
    if any(len(p.signed) > MAX_EXHAUSTIVE for p in plans):   # a pattern is an i64 in the code; numpy's search
        return Program((), (), 0, {}, [], [], False)
    try:
        lowrank = {bi: low_rank(p.Ainv) for bi, p in enumerate(plans)
                   if p.F is not None and (1 << len(p.signed)) > MAX_PATTERNS}
    except (np.linalg.LinAlgError, SharingError):      # a singular base matrix: the numpy path
        return Program((), (), 0, {}, [], [], False)
    groups = unknown_groups(an)
    offsets, c = {}, 0
    for g in groups:
        offsets[(g.kind, g.index)] = (c, g.size)
        c += g.size
    signed = [(p.groups[gi].kind, p.groups[gi].index) for p in plans for gi in p.signed]
    sigcol = {k: i for i, k in enumerate(signed)}
    block_of = {L: i for i, p in enumerate(plans) for L in p.links}
    trec, tflt, terms = general_terms(an, plans, block_of)
    bd = _Builder()
    for bi, p in enumerate(plans):
        _block(bd, an, bi, p, block_of, offsets, sigcol, terms)
        if p.F is None and len(p.links) == 1 and not p.signed:
            _local_frame(bd, trec, tflt, p)
    jrec, jflt = _joints(an)
    cat = (lambda xs: np.concatenate(xs) if xs else np.zeros(1))
    jout, mcol, gcol, mflt = output_constants(an, offsets)
    ints = (jrec, np.array(bd.brec, I64).reshape(-1, 14), np.array(bd.blinks, I64),
            np.array(bd.gcol, I64), np.array(bd.tcol + [0], I64), np.array(bd.scol + [0], I64),
            np.array(bd.prec, I64).reshape(-1, 7), np.array(bd.later + [0], I64),
            np.array(bd.cbrec, I64).reshape(-1, 3), np.array(an.tree.moving, I64), trec,
            np.array([an.tree.base], I64), jout, mcol, gcol)
    S, A = np.asarray(an.S, float), np.asarray(an.A, float)
    sparse = (_csr(S), _csr(A), _csr(A.T))
    ints += tuple(a for ptr, idx, _ in sparse for a in (ptr, idx))
    flts = (jflt, _links(an), np.ascontiguousarray(S), np.asarray(an.mech.gravity, float),
            cat(bd.ainv), cat(bd.cmat), tflt, np.array(bd.turns + [0.0]), mflt,
            np.ascontiguousarray(A)) + tuple(val for *_, val in sparse)
    hot = _hot_maps(an, plans, lowrank)
    flts += (cat([np.ravel(a) for lr in lowrank.values() for a in (lr.Y, lr.G, lr.Z, lr.W)]
                 + [np.array(h, float) for h, _ in hot.values()] + [np.ravel(t) for _, t in hot.values()]),)
    weights = {bi: mesh_weights(an, p.groups) for bi, p in enumerate(plans)
               if p.F is None and int(p.offs[-1]) > 6 * len(p.links)}
    free = {bi: f for bi in weights if (f := _basis(an, plans[bi], weights[bi])) is not None}
    flts += (cat([w for w in weights.values()] + [np.array(f[0] + f[1], float) for f in free.values()]),)  # (hashed)
    return Program(ints, flts, c, offsets, signed, [p.names for p in plans], True, lowrank=lowrank, hot=hot,
                   weights=weights, free=free)


MAX_BASIS_CONDITION = 1e8
"""Largest condition number of a redundant block's basis (its matrix without the free
columns) over the poses and sign patterns :func:`_free_columns` tries."""


def _basis(an, p, w):
    """:func:`_free_columns`, None where its linear algebra fails (the KKT solve then)."""
    try:
        return _free_columns(an, p, w)
    except (np.linalg.LinAlgError, ValueError):
        return None


def _free_columns(an, p, w):
    """(free, row order): the d weighted columns of a redundant world-frame block (n unknowns, 6B equations,
    d = n - 6B) whose removal leaves a square basis A_B that is regular on 9 poses (home and
    8 random, every t positive and every t negative) with a condition number at most
    :data:`MAX_BASIS_CONDITION`: the generated kernel then solves A_B for the right-hand
    side and the free columns and minimises over the d free unknowns (a d x d system,
    :class:`~.world.WorldBlock`) instead of the (n + 6B)^2 KKT system.  Chosen by
    QR with column pivoting of the null space's weighted rows at home; the basis' row order
    of partial pivoting at home (:func:`_pivot_order`).  None: none found."""
    from scipy.linalg import qr                        # noqa: PLC0415

    from ..equations import Columns                     # noqa: PLC0415
    from ..general import assemble                      # noqa: PLC0415
    from ..kinematics import forward                    # noqa: PLC0415

    rng = np.random.default_rng(18)
    J = len(an.mech.joints)
    q = np.vstack([np.zeros((1, an.dof)), rng.uniform(-np.pi, np.pi, (8, an.dof))]) @ np.asarray(an.S, float).T
    cols = Columns(an, forward(an.mech, an.tree, q.reshape(-1, J)))
    A = assemble(cols, p.groups, list(p.links))                       # (9, 6B, n), every t positive
    nr, n = A.shape[1:]
    weighted = np.flatnonzero(w > 0)
    null = np.linalg.svd(A[0])[2][nr:].T                              # (n, d)
    if null.shape[1] != n - nr:
        return None
    piv = qr(null[weighted].T, pivoting=True)[2]
    free = sorted(int(weighted[i]) for i in piv[:n - nr])
    basis = [j for j in range(n) if j not in free]
    minus = A.copy()
    for gi in p.signed:                                               # every t negative
        c = int(p.offs[gi])
        for r, L in enumerate(p.links):
            if L in p.groups[gi].links:
                minus[:, 6 * r:6 * r + 6, c] = cols.group(p.groups[gi], L, -1.0)[:, :, 0]
    conds = np.linalg.cond(np.concatenate([A, minus])[:, :, basis])
    if not (np.all(np.isfinite(conds)) and conds.max() <= MAX_BASIS_CONDITION):
        return None
    return free, _pivot_order(A[0][:, basis])


def _pivot_order(M: np.ndarray) -> list:
    """The row order partial pivoting takes on the square matrix M (the order the generated
    kernel eliminates in without pivoting, :func:`.world.static_lu`)."""
    from scipy.linalg import lu_factor                # noqa: PLC0415

    order = list(range(M.shape[0]))
    for c, p in enumerate(lu_factor(M)[1]):
        order[c], order[p] = order[p], order[c]
    return order


def _hot_maps(an, plans, lowrank: dict) -> dict:
    """{block: (hot pattern indices, their maps)} of the :class:`~..pattern_maps.LowRank`
    blocks: the patterns the sign search settles on within its first m + 1 trials (every t
    positive, then the trial's own signs) for 256 random motions of the mechanism (a fixed
    seed; the block's own d'Alembert loads, without the wrenches of earlier blocks: a hint
    for speed, not a result; :func:`~..pattern_maps.hot_patterns`)."""
    if not lowrank:
        return {}
    from ..blocks import _rotate, _shift            # noqa: PLC0415
    from ..inertia import inertia_load             # noqa: PLC0415
    from ..kinematics import forward               # noqa: PLC0415

    rng = np.random.default_rng(18)
    n = 256
    qi = [rng.uniform(-np.pi, np.pi, (n, an.dof)), rng.normal(size=(n, an.dof)) * 3.0,
          rng.normal(size=(n, an.dof)) * 20.0]
    q, qd, qdd = (v @ np.asarray(an.S, float).T for v in qi)
    kin = forward(an.mech, an.tree, q, qd, qdd)
    b = inertia_load(an, kin)
    out = {}
    for bi, lr in lowrank.items():
        p = plans[bi]
        oF = kin.o[p.F]
        parts = [_shift(b[L], kin.o[L], oF) for L in p.links]
        r = np.concatenate([w if p.F == an.tree.base else _rotate(kin.R[p.F], w, transpose=True) for w in parts],
                           axis=1)
        counts = _settled(lr, r, [int(p.offs[gi]) for gi in p.signed])
        hot = hot_patterns(counts)
        try:
            out[bi] = (hot, np.array([p.Ainv[k] for k in hot]))
        except (np.linalg.LinAlgError, SharingError):
            continue
    return out


def _settled(lr, r: np.ndarray, tcols: list) -> dict:
    """{pattern index: samples} of the rows r (N, 6B) settled by the first m + 1 trials of
    the sign search (:func:`~..signs.resolve_signs`), solved by ``lr`` (LowRank.solve)."""
    from ..signs import TOL_SIGN, pattern_index    # noqa: PLC0415

    m = len(tcols)
    scale = 1.0 + np.abs(r).max(axis=1)
    todo, signs, counts = np.arange(r.shape[0]), np.ones((r.shape[0], m)), {}
    for _ in range(m + 1):
        left = []
        for k in np.unique([pattern_index(s) for s in signs[todo]]):
            idx = todo[[pattern_index(s) == k for s in signs[todo]]]
            sg = signs[idx[0]]
            with np.errstate(all="ignore"):
                t = lr.solve(sg, r[idx])[:, tcols]
            ok = np.all(-sg * t <= TOL_SIGN * scale[idx, None], axis=1)
            counts[int(k)] = counts.get(int(k), 0) + int(ok.sum())
            signs[idx[~ok]] = np.where(t[~ok] < 0, -1.0, 1.0)
            left.append(idx[~ok])
        todo = np.concatenate(left) if left else todo[:0]
        if todo.size == 0:
            break
    return {k: v for k, v in counts.items() if v}

