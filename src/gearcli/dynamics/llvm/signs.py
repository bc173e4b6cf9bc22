"""Generated sign resolution of one block (paper Eq. 14; :func:`..signs.resolve_signs`).

The sign search is the only control flow of the generated kernel: step 0 tries the pattern
the sample before settled on (:func:`.kernel._sample`; every t positive for the first sample
of a run of :data:`WARM` samples, so that no result depends on the threads,
and always with more than MAX_EXHAUSTIVE meshes), steps 1..m the signs of the previous
trial's own t, then every pattern in :func:`..signs.sign_patterns` order (m <=
MAX_EXHAUSTIVE), with the tolerance of the numpy path; a sample with no consistent pattern
records its first failing block.  The numpy path starts from every t positive: both fail
the same samples, and accept the same pattern but where a t lies within the zero tolerance
on its wrong side, whose loads then agree to that tolerance (exactly where t = 0).  A motion
that keeps its pattern takes one trial a sample: the servo joint's ring meshes pull against
its sun meshes, so every t positive never fits it and took two.  A trial of a
constant-frame block computes only the m signed t.  A trial and the
accepted pattern's full solution are a ``switch`` over the patterns into straight-line
code with the constant Ainv entries, or, when 2^m patterns make that code too large
(:data:`SWITCH_LIMIT`), row products reading a constant global array at the pattern's
offset.
"""
from __future__ import annotations

import llvmlite.ir as ir
import numpy as np

from .build import D, I1, I64, Emitter
from .links import floats
from ..signs import MAX_EXHAUSTIVE, TOL_SIGN

WARM = 256
"""Samples n = k WARM .. (k + 1) WARM - 1 of a call form a run: a sign search starts from the
pattern the sample before settled on (:func:`.kernel._sample`) and a bearing fixed point in a
smooth stretch from the moments of the two samples before (:func:`.bearings._warm`), both
within the run only; the driver's thread ranges start at multiples of WARM, so no result
depends on the threads."""

SWITCH_LIMIT = 8192
"""Constant products (2^m patterns x (n + m) rows x 6B) up to which a signed block's
patterns are a switch into straight-line code; more read a global constant array."""


def tolerance(e: Emitter, r: list):
    """TOL_SIGN (1 + max |r|): the zero tolerance of t (Eq. 14); NaN when an r is NaN
    (as the numpy path's scale), which no trial then passes."""
    big = max([0.0] + [abs(v) for v in r if isinstance(v, float)])
    nan = None
    for v in r:
        if isinstance(v, float):
            continue
        a = e.call("fabs", v)
        big = a if isinstance(big, float) and big == 0.0 else e.b.select(
            e.b.fcmp_ordered(">", a, e.const(big)), a, e.const(big))
        isnan = e.b.fcmp_unordered("uno", v, v)
        nan = isnan if nan is None else e.b.or_(nan, isnan)
    tol = e.mul(TOL_SIGN, e.add(1.0, big))
    return e.const(tol) if nan is None else e.b.select(nan, ir.Constant(D, float("nan")), e.const(tol))


def _sign_bit(e: Emitter, p, i: int, m: int):
    """True when pattern p (i64) makes t_i negative (bit m-1-i, signs.pattern_index)."""
    bit = e.b.and_(e.b.lshr(p, ir.Constant(I64, m - 1 - i)), ir.Constant(I64, 1))
    return e.b.icmp_unsigned("!=", bit, ir.Constant(I64, 0))


def _consistent(e: Emitter, t: list, negative: list, tol):
    """All -sig_i t_i <= tol (``negative``: per t an i1, true for sig_i = -1)."""
    ok = ir.Constant(I1, 1)
    for ti, neg in zip(t, negative):
        v = e.b.select(neg, e.const(ti), e.const(e.neg(ti)))
        ok = e.b.and_(ok, e.b.fcmp_ordered("<=", v, tol))
    return ok


def _rows_switch(e: Emitter, fn, p, maps: list, rows: list, r: list, tag: str):
    """Per pattern k a straight-line case computing rows ``rows`` of maps[k] r; returns the
    rows' values (phis).  The case of the pattern is the caller's ``p`` (i64)."""
    return e.switch(fn, p, [(k, lambda A=A: [e.dot(floats(A[i]), r) for i in rows]) for k, A in enumerate(maps)], tag)


def _rows_global(e: Emitter, table, p, n: int, nr: int, rows: list, r: list):
    """Rows ``rows`` of pattern p's (n, nr) map times r, the maps read from ``table``."""
    base = e.b.mul(p, ir.Constant(I64, n * nr))
    vals = []
    for i in rows:
        acc = 0.0
        for j, rj in enumerate(r):
            if isinstance(rj, float) and rj == 0.0:
                continue
            aij = e.load(table, e.b.add(base, ir.Constant(I64, i * nr + j)))
            acc = e.add(acc, e.mul(aij, rj))
        vals.append(e.const(acc))
    return vals


def _own_pattern(e: Emitter, t: list):
    """The pattern of the trial's own signs (t < 0 negative; NaN counts as positive)."""
    m = len(t)
    p = ir.Constant(I64, 0)
    for i, ti in enumerate(t):
        bit = e.b.zext(e.b.fcmp_ordered("<", ti, ir.Constant(D, 0.0)), I64)
        p = e.b.or_(p, e.b.shl(bit, ir.Constant(I64, m - 1 - i)))
    return p


class SignedBlock:
    """The maps of one signed constant-frame block and how its code reads them: a switch
    into straight-line code per pattern, or, past :data:`SWITCH_LIMIT`, a constant table
    read with the ``hot`` patterns' (those random motions meet most,
    :func:`.program._hot_maps`) cases still straight-line."""

    def __init__(self, e: Emitter, maps: list, tcols: list, name: str, hot: list = ()):
        self.maps, self.tcols, self.hot = maps, tcols, list(hot)
        self.n, self.nr = maps[0].shape
        m = len(tcols)
        self.table = None
        if len(maps) * (self.n + m) * self.nr > SWITCH_LIMIT:
            flat = np.concatenate([np.ravel(A) for A in maps])
            ty = ir.ArrayType(D, flat.size)
            g = ir.GlobalVariable(e.module, ty, f"ainv_{name}")
            g.global_constant, g.linkage = True, "internal"
            g.initializer = ir.Constant(ty, [float(v) for v in flat])
            self.table = g.bitcast(D.as_pointer())

    def rows(self, e: Emitter, fn, p, rows: list, r: list, tag: str) -> list:
        """Rows ``rows`` of pattern p's map times r."""
        if self.table is None:
            return _rows_switch(e, fn, p, self.maps, rows, r, tag)
        if self.hot:             # the hot patterns straight-line, the others from the table
            return e.switch(fn, p, [(k, lambda A=self.maps[k]: [e.dot(floats(A[i]), r) for i in rows]) for k in self.hot],
                            tag, default=lambda: _rows_global(e, self.table, p, self.n, self.nr, rows, r))
        return _rows_global(e, self.table, p, self.n, self.nr, rows, r)


def resolve(e: Emitter, fn, blk: SignedBlock, r: list, tol, on_fail, tag: str, first=None):
    """(x (n values), p): the block's solution with the first consistent sign pattern p
    (i64) of the search order (module docstring; step 0 tries the pattern ``first`` (i64),
    every t positive where None); ``on_fail()`` emits what a sample with
    no consistent pattern does (its x is then that of the last pattern tried).  ``blk``:
    a :class:`SignedBlock`, or a :class:`~.world.WorldBlock` whose trials solve the
    whole block (kept for the pattern accepted), or a block with ``trial(e, fn, p, r, tol,
    tag) -> (t, kept)`` and ``full(e, fn, p, r, kept, tag)`` (:class:`~.losses.LossyBlock`: the
    accepted solution reuses its trial's kept values)."""
    m = len(blk.tcols)
    steps = 1 + m + ((1 << m) if m <= MAX_EXHAUSTIVE else 0)
    pre = e.b.block
    loop, nxt = fn.append_basic_block(f"{tag}_trial"), fn.append_basic_block(f"{tag}_next")
    fail, accept = fn.append_basic_block(f"{tag}_fail"), fn.append_basic_block(f"{tag}_accept")
    e.b.branch(loop)
    e.b.position_at_end(loop)
    step = e.b.phi(I64)
    prev = [e.b.phi(D) for _ in range(m)]
    own = _own_pattern(e, prev)
    late = e.b.sub(step, ir.Constant(I64, m + 1))
    p = e.b.select(e.b.icmp_signed("==", step, ir.Constant(I64, 0)), first if first is not None else ir.Constant(I64, 0),
                   e.b.select(e.b.icmp_signed("<=", step, ir.Constant(I64, m)), own, late))
    full = getattr(blk, "full_trial", False)     # a trial solves the whole block
    xs = blk.rows(e, fn, p, list(range(blk.n)), r, f"{tag}_x") if full else None
    kept = None                                  # what a block's trial passes to its full solution
    if hasattr(blk, "trial"):
        t, kept = blk.trial(e, fn, p, r, tol, f"{tag}_t")
    else:
        t = [xs[c] for c in blk.tcols] if full else blk.rows(e, fn, p, blk.tcols, r, f"{tag}_t")
    ok = _consistent(e, t, [_sign_bit(e, p, i, m) for i in range(m)], tol)
    e.b.cbranch(ok, accept, nxt)
    e.b.position_at_end(nxt)
    step1 = e.b.add(step, ir.Constant(I64, 1))
    e.b.cbranch(e.b.icmp_signed("<", step1, ir.Constant(I64, steps)), loop, fail)
    step.add_incoming(ir.Constant(I64, 0), pre)
    step.add_incoming(step1, nxt)
    for ph, ti in zip(prev, t):
        ph.add_incoming(ir.Constant(D, 1.0), pre)
        ph.add_incoming(ti, nxt)
    e.b.position_at_end(fail)
    on_fail()
    e.b.branch(accept)
    e.b.position_at_end(accept)
    if kept is not None:                         # (the loop body dominates accept: its last trial's values)
        return blk.full(e, fn, p, r, kept, f"{tag}_x"), p
    return (xs if full else blk.rows(e, fn, p, list(range(blk.n)), r, f"{tag}_x")), p


def signs_of(e: Emitter, p, m: int) -> list:
    """sig_i (+-1.0 doubles) of pattern p."""
    return [e.b.select(_sign_bit(e, p, i, m), ir.Constant(D, -1.0), ir.Constant(D, 1.0)) for i in range(m)]
