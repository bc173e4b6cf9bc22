"""Generated bearing friction fixed point (the model of :mod:`..bearing_friction`), per block
and per sample, for :mod:`.blocks`.

Joint J's bearing friction is a couple about its axis, -sign(q'_J) Mb_J on its child (reversed
on its parent), Mb_J = sum_b 1/2 mu_b d_b P_b from J's reaction [fx fy fz mx my], which the
first block of J's child and parent solves (:class:`~.loss_program.BearingBlock`): the couple
reaches no earlier block.  So in schedule order the fixed point is local to each block: only
its own joints' moments change its solution, and the converged couples on the links of later
blocks are loads there, as the joints' own friction (:func:`.friction_terms.joint_friction`).

Per block, from Mb = 0 (iteration 1; in a smooth stretch of the motion the extrapolated
moments of the two samples before, :func:`_warm`), as :func:`..bearing_friction.fixed_point`
with its ``TOL`` and ``MAX_ITERATIONS`` (:func:`_loop`): solve with r + sum_J s_J Mb_J w_J
(s_J = sign(q'_J), w_J the couple per unit in the block's coordinates), Mb_J' = sum_b 1/2
mu_b d_b P_b of the solved reactions (0 at rest), until every |Mb_J' - Mb_J| <= TOL |Mb_J'|;
the Mb that solved (not Mb') is kept.  A block solved in a constant frame or in world
axes searches its sign pattern p once, at zero moments; with p fixed its solution is affine
in the moments, x = x0 + sum_J s_J Mb_J g_J, g_J = X_p w_J (w_J constant in F: constants
per pattern for stored maps, the corrected map of :class:`~.losses.LossyBlock` per sample;
in world axes w_J per sample, solved with r by each trial of the search, the block's matrix
factored once, :meth:`~.world.WorldBlock.solve`), so are its bearings' load vectors,
and the moments converge on them alone: by Newton's method in a block of up to
:data:`NEWTON_JOINTS` bearing joints (:mod:`.bearing_newton`: from g(0), the fixed point's
first iteration, one level where the fixed point takes five or six iterations,
:func:`_cold`; one from the warm start in a smooth stretch; each a square root per bearing
and one division, stopped by the fixed point's own test or by Newton's proven error
bound), by the fixed point in a larger one (the numpy path's iterations, each a square
root per bearing and K products, no Jacobian).  Where no bearing load of the block depends on the moments
(:func:`.bearing_newton.unaffected`: a link whose other unknown is its motor torque about
the same axis takes the couple there) Mb = g(0) exactly, one iteration and no level.  The
tooth forces must fit p (the tolerance of the shifted r; no tolerance needed where each is
strictly on p's side of zero) at the converged moments; where
they do not, and in a block solved in its link's axes (no constant couple), the block goes
on from those moments and that iteration by the numpy path's loop: the whole block solved,
its sign search included, each iteration.  Where p's affine model does not converge in
MAX_ITERATIONS (friction so large that it changes the tooth force signs, which the numpy
path's search follows) a signed block starts that loop from zero moments, as the numpy path;
only a block without signs fails there.

Written per sample in the ``moments`` row: each joint's converged Mb_J, then the most
iterations over the sample's blocks; -s_J Mb_J joins J's friction output.  A block that does
not converge records ``fail`` = (number of blocks) + k, k the bearing joint of largest
relative change (the driver's :class:`..bearing_friction.BearingFrictionError`).
"""
from __future__ import annotations

import llvmlite.ir as ir

from ...model.shaft import split_terms
from ..bearing_friction import MAX_ITERATIONS, TOL, friction_moment, load_magnitudes
from .bearing_newton import level, loads, newton, unaffected, within
from .build import D, I1, I64, Emitter
from .links import Sample, floats
from .signs import WARM, _consistent, _sign_bit, tolerance


def split(e: Emitter, lp, k: int, x: list) -> list:
    """[R1x, R1y, R2x, R2y, fz] of bearing joint k from its reaction x = [fx, fy, fz, mx, my]
    (joint frame; any basis turned about the axis): the two-bearing split
    :func:`gearcli.model.shaft.split_terms` (one bearing: R1 = f), linear in x."""
    z1, z2 = (float(v) for v in lp.bearing_flt[k, :2])
    fx, fy, fz, mx, my = x
    if lp.bearing_single[k]:
        return [fx, fy, 0.0, 0.0, fz]
    return list(split_terms(e, fx, fy, mx, my, z1, z2)) + [fz]


def moment(e: Emitter, lp, k: int, R: list):
    """sum_b 1/2 mu_b d_b P_b of bearing joint k from its :func:`split` R
    (:func:`..bearing_friction.load_magnitudes`, :func:`..bearing_friction.friction_moment`;
    the constants of :func:`..bearing_friction.bearing_layout`)."""
    loc1, loc2, arm1, arm2 = (float(v) for v in lp.bearing_flt[k, 2:])
    P1, P2 = load_magnitudes(e, R[:4], R[4], loc1, loc2)
    return friction_moment(e, P1, P2, arm1, arm2)


class _Joints:
    """The bearing friction joints of one block for one sample: their records, axes z_J (base
    axes), s_J = sign(q'_J), moving flags and unit couples W (per joint, in the block's r)."""

    def __init__(self, e: Emitter, s: Sample, lp, bb, F: int, links: list, nr: int):
        jrow = [int(v) for v in lp.joints[:, 0]]
        self.rec = [lp.joints[jrow.index(lp.bearing_joints[k])] for k in bb.joints]
        self.zw = [e.mv(s.R[int(rc[1])], floats(lp.joint_flt[jrow.index(int(rc[0]))][:3])) for rc in self.rec]
        qd = [e.const(s.qd[int(rc[0])]) for rc in self.rec]
        self.sg = [e.sign(v) for v in qd]
        self.moving = [e.b.fcmp_unordered("une", v, ir.Constant(D, 0.0)) for v in qd]
        if bb.wF is not None:
            self.W = [floats(w) for w in bb.wF]
            return
        self.W = [[0.0] * nr for _ in self.rec]   # per sample: world axes, or F's of a block solved in its link
        for j, rc in enumerate(self.rec):
            z = self.zw[j] if F < 0 else e.mtv(s.R[F], self.zw[j])
            for L, sign in ((int(rc[1]), 1.0), (int(rc[2]), -1.0)):
                if L in links:
                    self.W[j][6 * links.index(L) + 3:6 * links.index(L) + 6] = [e.mul(sign, v) for v in z]

    def shifted(self, e: Emitter, r: list, Mb: list) -> list:
        """r - sum_J Q_J w_J, Q_J = -s_J Mb_J."""
        sm = [e.mul(sg, M) for sg, M in zip(self.sg, Mb)]
        return [e.add(r[i], e.dot([w[i] for w in self.W], sm)) for i in range(len(r))]

    def moments(self, e: Emitter, lp, bb, S: list) -> list:
        """Mb' of each joint from its :func:`split` S (0 at rest)."""
        return [e.b.select(mv, e.const(moment(e, lp, k, Sj)), ir.Constant(D, 0.0))
                for mv, k, Sj in zip(self.moving, bb.joints, S)]


def converge(e: Emitter, fn, s: Sample, prog, b: int, F: int, links: list, tcols: list, r: list, solve, rows,
             n, fail, world=None):
    """(x, p) of block b with the converged bearing friction of its joints (module
    docstring).  ``solve(r, tag)``: (x, p) of right-hand side r (the block's own sign search;
    p None without signed meshes); ``rows(p, idx, R, tag)``: rows idx of the solution with
    pattern p of each right-hand side of R (constant frame); ``world``: a world-frame block's
    :class:`~.world.WorldBlock` (None: a constant frame), whose solve at zero moments (each
    trial of its sign search) also solves the unit couples (its ``more``)."""
    lp = prog.losses
    bb = lp.bearing_blocks[b]
    K, m, tag = len(bb.joints), len(tcols), f"b{b}"
    jt = _Joints(e, s, lp, bb, F, links, len(r))
    warm = _warm(e, lp, bb, jt, n)
    done_bb = fn.append_basic_block(f"{tag}_bdone")
    ends = []                 # (block, Mb, it, x, p) of each way into done_bb
    start = (warm, ir.Constant(I64, 1))
    if bb.wF is not None or world is not None:     # affine in the moments, from the sign search at zero moments
        x0, p, G = _affine(e, jt, r, solve, rows, world, tag)
        S0 = [split(e, lp, k, _cols(x0, c0)) for k, c0 in zip(bb.joints, bb.cols)]
        SG = [[split(e, lp, k, _cols(G[i], c0)) for i in range(K)] for k, c0 in zip(bb.joints, bb.cols)]

        def at(Mb, rows=range(len(x0))):     # x[rows] at the moments Mb
            return [e.add(x0[i], e.dot([G[j][i] for j in range(K)], Mb)) for i in rows]

        again = fn.append_basic_block(f"{tag}_bagain") if m else None
        lv = [loads(e, lp, k, S0[j], SG[j]) for j, k in enumerate(bb.joints)]
        failed = (lambda g, change: None) if m else (lambda g, change: _failed(e, prog, bb, g, change, fail, n))
        Mb, it, failb, Mf = _iterate(e, fn, tag, lv, jt, start, failed)
        x, start = at(Mb), None
        if m:                  # converged: do the tooth forces fit p? else the whole block's loop from Mb
            fit_bb = fn.append_basic_block(f"{tag}_bfit")
            refit = _fits(e, fn, tag, jt, r, p, at(Mb, tcols), Mb, (fit_bb, again))
            start = (Mb, it)
            e.b.position_at_end(fit_bb)
        ends.append((e.b.block, Mb, it, x, p))
        e.b.branch(done_bb)
        if failb is not None:  # without signs a failure; with them p's model only: the whole block's loop from 0
            e.b.position_at_end(failb)
            if m:
                e.b.branch(again)
            else:
                ends.append((failb, Mf, it, at(Mf), p))
                e.b.branch(done_bb)
        if start is not None:
            e.b.position_at_end(again)
            if failb is not None:
                start = _restart(e, start, refit, failb)
    if start is not None:     # the whole block solved each iteration (a world-frame block, or a changed pattern)
        sol = {}

        def solved(Mb):
            sol["x"], sol["p"] = solve(jt.shifted(e, r, Mb), f"{tag}_s")
            return jt.moments(e, lp, bb, [split(e, lp, k, _cols(sol["x"], c0)) for k, c0 in zip(bb.joints, bb.cols)])
        Mb, it, failb = _loop(e, fn, f"{tag}_bs", start, solved, lambda g, change: _failed(e, prog, bb, g, change, fail, n))
        ends += [(e.b.block, Mb, it, sol["x"], sol["p"]), (failb, Mb, it, sol["x"], sol["p"])]
        e.b.branch(done_bb)
        e.b.position_at_end(failb)
        e.b.branch(done_bb)
    e.b.position_at_end(done_bb)
    Mb, it, x, p = (_phis(e, ends, k) for k in (1, 2, 3, 4))
    _outputs(e, s, lp, b, bb, jt, Mb, it[0], links, n)
    return x, (None if p is None else p[0])


def _iterate(e: Emitter, fn, tag: str, lv: list, jt: _Joints, start: tuple, failed) -> tuple:
    """(the converged Mb, its iteration, the block reached where it does not converge (None:
    it cannot fail), the Mb that reaches it) of a block affine in its moments (``lv``: per
    joint its bearings' :func:`.bearing_newton.loads`) from ``start``; ``failed(g, |g -
    Mb|)`` emits what a failure does."""
    if unaffected(lv):         # the loads do not see the moments: Mb* = g(0), one iteration
        return level(e, lv, jt.moving, [0.0] * len(lv))[0], ir.Constant(I64, 1), None, None
    if len(lv) > NEWTON_JOINTS:  # the fixed point on the loads: the numpy path's iterations, each cheap
        Mb, it, failb = _loop(e, fn, f"{tag}_bfp", start, lambda M: level(e, lv, jt.moving, M)[0], failed)
        return Mb, it, failb, Mb
    return newton(e, fn, f"{tag}_ba", _cold(e, fn, f"{tag}_bc", lv, jt, start), lv, jt.moving, failed)


def _restart(e: Emitter, start: tuple, refit, failb) -> tuple:
    """The whole block's loop's start (Mb, iteration) where the tooth forces no longer fit
    (``start``, from ``refit``) or p's affine model did not converge (zero moments, iteration
    1, from ``failb``: as the numpy path, whose sign search follows the moments)."""
    Mb, it = [e.b.phi(D) for _ in start[0]], e.b.phi(I64)
    _incoming(Mb + [it], [e.imm(v) for v in start[0]] + [start[1]], refit)
    _incoming(Mb + [it], [ir.Constant(D, 0.0)] * len(Mb) + [ir.Constant(I64, 1)], failb)
    return Mb, it


def _fits(e: Emitter, fn, tag: str, jt: _Joints, r: list, p, t: list, Mb: list, to: tuple):
    """Branch to to[0] where the tooth forces t at the converged moments Mb fit the pattern p
    (the tolerance of the shifted r), else to to[1]: first without the tolerance (every t_i
    strictly on p's side of zero, and Mb numbers: the common case), then with it.  Returns
    the block that branches to to[1]."""
    neg = [_sign_bit(e, p, i, len(t)) for i in range(len(t))]
    ok = _consistent(e, t, neg, ir.Constant(D, 0.0))
    for v in Mb:
        ok = e.b.and_(ok, e.b.fcmp_ordered("ord", v, v))
    exact = fn.append_basic_block(f"{tag}_bexact")
    e.b.cbranch(ok, to[0], exact)
    e.b.position_at_end(exact)
    e.b.cbranch(_consistent(e, t, neg, tolerance(e, jt.shifted(e, r, Mb))), *to)
    return e.b.block


def _cold(e: Emitter, fn, tag: str, lv: list, jt: _Joints, start: tuple) -> tuple:
    """``start`` (Mb, 1) with each moving joint not warm-started (Mb_J = 0) started from g_J(0)
    instead, the fixed point's first iteration (the count then 2 where one g_J(0) is nonzero):
    within ~Lambda of Mb*, so that the first Newton level's step lands within ~Lambda^4 / 2
    and is proven there (:func:`.bearing_newton.proven`), where from zero it lands ~Lambda^2
    / 2 off and takes a second level.  g(0) costs a square root per bearing, not a level,
    and nothing where every joint is warm-started (a smooth stretch)."""
    pre, cold_bb, join = e.b.block, fn.append_basic_block(f"{tag}_cold"), fn.append_basic_block(f"{tag}_join")
    zero, any_cold = ir.Constant(D, 0.0), ir.Constant(I1, 0)
    colds = [e.b.and_(mv, e.b.fcmp_ordered("==", e.const(w), zero)) for w, mv in zip(start[0], jt.moving)]
    for c in colds:
        any_cold = e.b.or_(any_cold, c)
    e.b.cbranch(any_cold, cold_bb, join)
    e.b.position_at_end(cold_bb)
    g0, first, Mc = level(e, lv, jt.moving, [0.0] * len(jt.moving))[0], ir.Constant(I1, 0), []
    for w, g, c in zip(start[0], g0, colds):
        Mc.append(e.b.select(c, e.const(g), e.const(w)))
        first = e.b.or_(first, e.b.and_(c, e.b.fcmp_ordered("!=", e.const(g), zero)))
    itc = e.b.add(ir.Constant(I64, 1), e.b.zext(first, I64))
    e.b.branch(join)
    e.b.position_at_end(join)
    Mb, it = [e.b.phi(D) for _ in Mc], e.b.phi(I64)
    _incoming(Mb + [it], [e.imm(w) for w in start[0]] + [start[1]], pre)
    _incoming(Mb + [it], Mc + [itc], cold_bb)
    return Mb, it


def _affine(e: Emitter, jt: _Joints, r: list, solve, rows, world, tag: str):
    """(x0, p, G) of a block solved in a constant frame or world axes: its solution x0 and
    sign pattern p at zero moments, and G[J] = s_J X_p w_J, the solution's change per unit
    Mb_J (a world-frame block's unit couples solved by each trial with r, its ``more``)."""
    if world is not None:
        world.more = jt.W
    x0, p = solve(r, tag)
    if world is None:
        X = rows(p, list(range(len(x0))), jt.W, f"{tag}_g")
    else:
        X, world.more = world.more_x, ()
    return x0, p, [[e.mul(sg, v) for v in col] for sg, col in zip(jt.sg, X)]


def _loop(e: Emitter, fn, tag: str, start: tuple, step, failed):
    """Iterate Mb <- step(Mb) from ``start`` (Mb, its iteration number) until every
    |Mb' - Mb| <= TOL |Mb'| (:func:`.bearing_newton.within`): returns (the Mb that solved, its iteration, the
    block reached after MAX_ITERATIONS, where ``failed(Mb', |Mb' - Mb|)`` emitted what a
    failure does), the builder at the converged exit."""
    pre = e.b.block
    body, more, out, failb = (fn.append_basic_block(f"{tag}_{x}") for x in ("it", "more", "out", "fail"))
    e.b.branch(body)
    e.b.position_at_end(body)
    Mb, it = [e.b.phi(D) for _ in start[0]], e.b.phi(I64)
    new = step(Mb)
    change, ok, finite = within(e, new, Mb)
    e.b.cbranch(ok, out, more)
    e.b.position_at_end(more)
    it1 = e.b.add(it, ir.Constant(I64, 1))
    e.b.cbranch(e.b.and_(finite, e.b.icmp_signed("<=", it1, ir.Constant(I64, MAX_ITERATIONS))), body, failb)
    _incoming(Mb + [it], list(start[0]) + [start[1]], pre)
    _incoming(Mb + [it], new + [it1], more)
    e.b.position_at_end(failb)
    failed(new, change)
    e.b.position_at_end(out)
    return Mb, it, failb


def _phis(e: Emitter, ends: list, k: int):
    """Per position of item k of ``ends`` (block, Mb, it, x, p) a phi of its values (None: p without signs)."""
    if ends[0][k] is None:
        return None
    vals = [en[k] if isinstance(en[k], list) else [en[k]] for en in ends]
    phis = [e.b.phi(getattr(v, "type", D)) for v in vals[0]]
    for en, vs in zip(ends, vals):
        _incoming(phis, [e.imm(v) for v in vs], en[0])
    return phis


NEWTON_JOINTS = 2
"""The most bearing joints of a block whose moments converge by Newton's method; a block
with more iterates the fixed point on its affine loads (:func:`_loop` on
:func:`.bearing_newton.level`'s g): a level's K x K Jacobian (K products per bearing) and
its solve cost more than the fixed point's extra iterations, each a square root per bearing
(measured, 20,000 random states, thread CPU time: planetary_3p_rated's block of 5 joints
9.2 -> 7.9 ms, the servo joint's of 6 joints 21.4 -> 19.4 ms; the Bendix wrist's blocks of 1
or 2 joints 9.6 -> 11.6 ms the other way)."""

SMOOTH = 0.03125
"""A smooth stretch: each moment changed by at most SMOOTH of itself from sample n-2 to n-1
of a run (:data:`.signs.WARM`); there a sample's fixed point starts from their extrapolation."""


def _warm(e: Emitter, lp, bb, jt: _Joints, n) -> list:
    """Per joint of the block the moments its fixed point starts from: where it moves and
    samples n-1 and n-2 are in the run with 0 < Mb(n-2) and |Mb(n-1) - Mb(n-2)| <= SMOOTH
    Mb(n-1), their extrapolation 2 Mb(n-1) - Mb(n-2); else 0, the fixed point's own start
    (:func:`..bearing_friction.fixed_point`: so a random motion's samples iterate as there)."""
    mom, start = (next(a for a in e.b.function.args if a.name == k) for k in ("moments", "start"))
    ok = e.b.and_(e.b.icmp_signed(">=", e.b.srem(n, ir.Constant(I64, WARM)), ir.Constant(I64, 2)),
                  e.b.icmp_signed(">=", e.b.sub(n, ir.Constant(I64, 2)), start))
    rows = [e.row(mom, e.b.select(ok, e.b.sub(n, ir.Constant(I64, h)), n), lp.out_width) for h in (1, 2)]
    out, zero = [], ir.Constant(D, 0.0)
    for mv, k in zip(jt.moving, bb.joints):     # (row n when not ok: loaded, never used)
        M1, M2 = (e.load(row, k) for row in rows)
        smooth = e.b.fcmp_ordered("<=", e.call("fabs", e.sub(M1, M2)), e.mul(SMOOTH, M1))
        use = e.b.and_(e.b.and_(ok, mv), e.b.and_(e.b.fcmp_ordered(">", M2, zero), smooth))
        out.append(e.b.select(use, e.sub(e.mul(2.0, M1), M2), zero))
    return out


def _cols(x: list, c0: int) -> list:
    return [x[c] for c in range(c0, c0 + 5)]


def _incoming(phis: list, values: list, block) -> None:
    for ph, v in zip(phis, values):
        ph.add_incoming(v, block)


def _failed(e: Emitter, prog, bb, new: list, change: list, fail, n) -> None:
    """``fail`` of sample n (if none before) = number of blocks + the bearing joint of largest
    relative change (as bearing_friction names it)."""
    code, best = ir.Constant(I64, len(prog.blocks) + bb.joints[0]), None
    for j, (v, c) in enumerate(zip(new, change)):
        rel = e.div(c, e.add(e.call("fabs", v), 1e-300))
        if best is None:
            best = rel
            continue
        gt = e.b.fcmp_ordered(">", rel, best)
        best, code = e.b.select(gt, rel, best), e.b.select(gt, ir.Constant(I64, len(prog.blocks) + bb.joints[j]), code)
    old = e.load(fail, n)
    e.b.store(e.b.select(e.b.icmp_signed("<", old, ir.Constant(I64, 0)), code, old), e.b.gep(fail, [n]))


def _outputs(e: Emitter, s: Sample, lp, b: int, bb, jt: _Joints, Mb, it, links, n) -> None:
    """The converged Mb and the most iterations so far over the sample's blocks into its
    ``moments`` row, s_J Mb_J into ``s.bearing`` (the joint friction outputs,
    :func:`.friction_terms.write_losses`); the couples -s_J Mb_J z_J on the joints' links of later
    blocks (rhs[L] -= Q w, reversed on the parent)."""
    fn = e.b.function
    row = e.row(next(a for a in fn.args if a.name == "moments"), n, lp.out_width)
    K = len(lp.bearing_joints)
    for j, k in enumerate(bb.joints):
        e.store(Mb[j], row, k)
    it = e.b.sitofp(it, D)
    if b != min(lp.bearing_blocks):
        before = e.load(row, K)
        it = e.b.select(e.b.fcmp_ordered(">", it, before), it, before)
    e.store(it, row, K)
    for j, rc in enumerate(jt.rec):
        amount = s.bearing[int(rc[0])] = e.mul(jt.sg[j], Mb[j])
        for L, sign in ((int(rc[1]), 1.0), (int(rc[2]), -1.0)):
            if L >= 0 and L not in links:
                s.rhs[L] = s.rhs[L][:3] + tuple(e.add(s.rhs[L][3 + h], e.mul(sign, e.mul(amount, jt.zw[j][h])))
                                                for h in range(3))
