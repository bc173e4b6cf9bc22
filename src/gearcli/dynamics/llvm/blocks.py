"""Generated block solves (the second half of :mod:`.kernel`), one sample.

Per block of the schedule, as :func:`..blocks.solve_blocks` does: gather the block links'
right-hand sides in its frame F about o_F, solve x = Ainv[pattern] r (straight-line for a
block without signed meshes, else with the sign search of :mod:`.signs`), pass the
solved wrenches on to the later links (the propagation records and their C_plus, C_sep
columns, or the column terms of :mod:`.terms` for a block solved in its link's
axes) and write the solution into the sample's row (joint reactions turned to their
child's basis).  A block without a constant frame is solved in world axes by Gaussian
elimination per sample and per sign trial (:mod:`.world`).
"""
from __future__ import annotations

import llvmlite.ir as ir

from . import losses as llvm_losses
from .bearings import converge
from .hot_pairs import HotLossyBlock
from .build import I64, Emitter
from .links import Sample, floats
from .signs import SignedBlock, resolve, signs_of, tolerance
from .world import LowRankBlock, WorldBlock
from ..wrenches import term_direction, term_point, term_wrench as wrench_of_term


def gather(e: Emitter, s: Sample, F: int, links) -> list:
    """r (6B) = the block links' right-hand sides in F's axes about o_F (blocks' gather)."""
    RF, oF = s.R[F], s.o[F]
    r = []
    for L in links:
        f, m = s.rhs[L][:3], s.rhs[L][3:]
        m = e.vadd(m, e.cx(e.vsub(s.o[L], oF), f))
        r += list(e.mtv(RF, f)) + list(e.mtv(RF, m))
    return r


def _wrench_in_F(e: Emitter, rec, cmat, x: list, fixed: bool = False):
    """C_plus x + C_sep |x| of one :data:`.records.PROPAGATION` record: (f, m) on its primary link, F axes
    (``fixed``: C_sep x, the separating force of sign pattern 0 the block was solved with)."""
    c0, size, signed, co = int(rec.col0), int(rec.ncols), int(rec.signed), int(rec.cmat0)
    xs = x[c0:c0 + size]
    w = [e.dot(floats(cmat[co + h * size:co + (h + 1) * size]), xs) for h in range(6)]
    if signed:
        ax = xs if fixed else [e.call("fabs", v) for v in xs]
        cs = co + 6 * size
        w = [e.add(w[h], e.dot(floats(cmat[cs + h * size:cs + (h + 1) * size]), ax)) for h in range(6)]
    return tuple(w[:3]), tuple(w[3:])


def _subtract(e: Emitter, s: Sample, L: int, w, scale) -> None:
    """rhs[L] -= scale * w (w a 6-tuple)."""
    s.rhs[L] = tuple(e.sub(s.rhs[L][h], e.mul(scale, w[h])) for h in range(6))


def propagate(e: Emitter, s: Sample, F: int, recs, prog, x: list, fixed: bool = False, couples=None) -> None:
    """rhs[L] -= the solved wrenches of the block's groups on their later links (blocks' propagation;
    ``couples``: {first column of a record: a moment (F axes) added to its wrench})."""
    cmat, later = prog.cmat, prog.later
    RF, oF = s.R[F], s.o[F]
    for rec in recs:
        f, mo = _wrench_in_F(e, rec, cmat, x, fixed)
        if couples and int(rec.col0) in couples:
            mo = e.vadd(mo, couples[int(rec.col0)])
        f, mo = e.mv(RF, f), e.mv(RF, mo)                    # world axes, about o_F
        P, l0, nl = int(rec.primary), int(rec.later0), int(rec.nlater)
        for L in (int(v) for v in later[l0:l0 + nl]):
            m = e.vadd(mo, e.cx(e.vsub(oF, s.o[L]), f))
            _subtract(e, s, L, f + m, 1.0 if L == P else -1.0)


def term_wrench(e: Emitter, s: Sample, term, value, L: int, sig: list):
    """Wrench (6-tuple, base axes, about o_L) of one column term (:data:`.records.TERM`,
    its :data:`.records.TERM_VALUE`) per unit of its unknown (the column of
    :meth:`..equations.Columns.group`)."""
    X = int(term.frame)
    coef = float(value.coef)
    if term.sign >= 0:
        coef = e.mul(coef, sig[int(term.sign)])
    d = term_direction(e, floats(value.d), s.R[X])
    P = None if term.moment == 1 else term_point(e, floats(value.p), s.R[X], s.o[X])
    return wrench_of_term(e, term.moment == 1, coef, d, P, s.o[L])


def propagate_terms(e: Emitter, s: Sample, k0: int, nt: int, prog, x: list, sig: list) -> None:
    """rhs[L] -= the solved wrenches on the later links from the terms with no block row
    (as :func:`..blocks.solve_blocks` propagates)."""
    for term, value in zip(prog.terms[k0:k0 + nt], prog.term_values[k0:k0 + nt]):
        if term.row >= 0:
            continue
        L = int(term.link)
        _subtract(e, s, L, term_wrench(e, s, term, value, L, sig), x[int(term.col)])


def store(e: Emitter, s: Sample, rec, prog, x: list) -> None:
    """The block's solution into the sample's row ``s.sol``: joint
    reactions solved in another basis turned to their child's by -q (or -(q @ row))."""
    gcol, turns = prog.group_col, prog.turns
    nloc, g0, cb0, ncb = int(rec.n), int(rec.col0), int(rec.cb0), int(rec.ncb)
    for i in range(nloc):
        s.sol[int(gcol[g0 + i])] = x[i]
    for c0, j, off in ((int(cb.col0), int(cb.joint), int(cb.turn0)) for cb in prog.child_basis[cb0:cb0 + ncb]):
        if j >= 0:
            cq, sq = s.cs[j]
        else:
            angle = e.dot(s.q, floats(turns[off:off + len(s.q)]))
            cq, sq = e.sincos(angle)
        for h in (0, 3):
            x0, x1 = x[c0 + h], x[c0 + h + 1]
            s.sol[int(gcol[g0 + c0 + h])] = e.add(e.mul(cq, x0), e.mul(sq, x1))
            s.sol[int(gcol[g0 + c0 + h + 1])] = e.sub(e.mul(cq, x1), e.mul(sq, x0))


def _sign_free(e: Emitter, x: list, tcols: list, tol):
    """(x, p) of a block whose matrix does not depend on its signs (a reducer's output block
    in its link's axes, :func:`.program._sign_free`): the pattern the numpy search accepts,
    every t positive but those below -tol (:func:`..signs.resolve_signs`: all positive is
    tried first, then the solution's own signs)."""
    p, m = ir.Constant(I64, 0), len(tcols)
    for i, c in enumerate(tcols):
        neg = e.b.zext(e.b.fcmp_ordered("<", e.const(x[c]), e.const(e.neg(tol))), I64)
        p = e.b.or_(p, e.b.shl(neg, ir.Constant(I64, m - 1 - i)))
    return x, p


def _on_fail(e: Emitter, fail, n, b: int):
    """The code that records block b as sample n's first failing block (if none before)."""
    def emit():
        old = e.load(fail, n)
        e.b.store(e.b.select(e.b.icmp_signed("<", old, ir.Constant(I64, 0)), ir.Constant(I64, b), old),
                  e.b.gep(fail, [n]))
    return emit


def block(e: Emitter, fn, s: Sample, prog, b: int, n, fail, sg_row, search: bool = True, first=None):
    """Block b of the schedule for sample n; returns its sign pattern (i64; None without
    signed meshes or search).  ``fail`` (i64*) gets the first block with no consistent sign
    pattern (it comes filled with -1), ``sg_row`` (double*) the sign of each t used,
    ``first`` the pattern the search tries first (None: every t positive).  ``search``
    False: lossless, sign pattern 0 without the search (:mod:`.mass`: the torques do not
    depend on the pattern; ``n``, ``fail``, ``sg_row`` unused)."""
    rec = prog.blocks[b]
    F, lk0, B, nloc, m, t0, a0 = (int(v) for v in (rec.F, rec.link0, rec.nlinks, rec.n, rec.m, rec.t0, rec.ainv0))
    p0, np_, k0, nt, local = int(rec.prop0), int(rec.nprop), int(rec.term0), int(rec.nterm), int(rec.local)
    blinks, tcol, ainv = prog.block_links, prog.t_col, prog.ainv
    nr = 6 * B
    links = [int(v) for v in blinks[lk0:lk0 + B]]
    tcols = [int(c) for c in tcol[t0:t0 + m]]
    if F < 0:                       # world axes about each link's origin
        r = [v for L in links for v in s.rhs[L]]
        blk = WorldBlock(s, prog, k0, nt, nloc, tcols, term_wrench, fn, prog.weights.get(b), prog.free.get(b))
    elif b in prog.lowrank:          # too many patterns to store: one base matrix (pattern_maps.LowRank)
        r = gather(e, s, F, links)
        blk = LowRankBlock(prog.lowrank[b], tcols, prog.hot.get(b))
    else:
        r = gather(e, s, F, links)
        maps = [ainv[a0 + k * nloc * nr:a0 + (k + 1) * nloc * nr].reshape(nloc, nr) for k in range(1 << m)]
        blk = SignedBlock(e, maps, tcols, f"b{b}", prog.hot.get(b, ((),))[0]) if m and search and not local else None
    lossy = prog.losses.blocks.get(b) if prog.losses is not None and search else None
    if lossy is not None and F < 0:
        blk.extra = llvm_losses.world_columns(prog.losses, lossy, s)
    elif lossy is not None and local:     # solved in its link's axes: only reducers, none of whose
        assert not lossy.positions and not any(rows for _, _, rows, _ in lossy.reducers)   # factors act on it
    elif lossy is not None:
        blk = llvm_losses.lossy_block(e, blk, lossy, s.sv, f"b{b}")
        if lossy.hot:                # (a LossyBlock) its hot pairs from their stored maps
            blk = HotLossyBlock(e, blk, lossy, s.sv)

    def solve(r, tag):              # (x, p) of right-hand side r; p None: pattern 0 without a search
        if m and search and local:       # sign-free (program._sign_free): one map, the signs read off
            return _sign_free(e, [e.dot(floats(maps[0][i]), r) for i in range(nloc)], tcols, tolerance(e, r))
        if m and search:
            return resolve(e, fn, blk, r, tolerance(e, r), _on_fail(e, fail, n, b), tag, first)
        if F < 0:
            return blk.solve(e, [1.0] * m, r), None
        if b in prog.lowrank:
            return blk.rows(e, fn, ir.Constant(I64, 0), list(range(nloc)), r, f"{tag}_x"), None
        return [e.dot(floats(maps[0][i]), r) for i in range(nloc)], None

    def rows(p, idx, R, tag):       # rows idx of the solution with pattern p of each r of R (constant frame)
        if m == 0 or blk is None:                # (sign-free: every pattern's map is maps[0])
            return [[e.dot(floats(maps[0][i]), r) for i in idx] for r in R]
        X = blk.products(e, p, R) if hasattr(blk, "products") and all(isinstance(v, float) for r in R for v in r) else None
        if X is not None:
            return [[x[i] for i in idx] for x in X]
        return [blk.rows(e, fn, p, idx, r, f"{tag}{j}") for j, r in enumerate(R)]
    if search and prog.losses is not None and b in prog.losses.bearing_blocks:
        x, p = converge(e, fn, s, prog, b, F, links, tcols, r, solve, rows, n, fail, blk if F < 0 else None)
    else:
        x, p = solve(r, f"b{b}")
    sig = [1.0] * m if p is None else signs_of(e, p, m)
    for i in range(m if p is not None else 0):
        e.store(sig[i], sg_row, t0 + i)              # the signs row holds Program.signed in order
    if nt > 0:
        propagate_terms(e, s, k0, nt, prog, x, sig)
    else:
        couples = llvm_losses.couples_F(e, s, lossy, x, tcols) if lossy is not None and F >= 0 else {}
        propagate(e, s, F, prog.props[p0:p0 + np_], prog, x, not search, couples)
    if lossy is not None and (F < 0 or local):
        llvm_losses.propagate(e, s, prog.losses, lossy, x, tcols, sig)
    store(e, s, rec, prog, x)
    return p
