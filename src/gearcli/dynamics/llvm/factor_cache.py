"""A lossy block's mesh-friction system 1 + M_l D, factored once per kernel call and pattern.

:class:`~.losses.LossyBlock` solves, for the accepted sign pattern p of each sample,

    (1 + M_l D) t_l = t0_l,        M_l = (X_p Phi^T)[lossy tooth rows],  D = diag(sigma s_v),

a k x k system (k lossy meshes) that depends on the sample only through p and D's digits
(-1, 0, 1 each).  Forming M_l (a low-rank block: one inner solve per lossy mesh) and
factoring the matrix cost most of the mesh friction on a many-mesh block (planetary_5p:
~1,600 of its ~2,600 instructions a sample), while along a motion, and even over random
states, the same few (p, D) recur: every sample of 20,000 random states of the 5-planet
stage has one p, and D takes two values with the sign of its rate.

So each call of the kernel keeps the factors of the last two (p, D) met, in stack arrays
(:func:`FactorCache.solve`): a sample whose key is there reads its factors back, another
forms and factors its matrix, stores the factors over the older entry and reads them back
the same way.  The factors are the same numbers either way (a deterministic function of
(p, D); elimination in row order, the matrix strictly diagonally dominant for every
pattern: no pivoting, :func:`.world.lu_solve`'s ``dominant``), so no result depends on the
cache, on the samples before or on the threads.  The forward and back substitution are
:func:`.world.lu_solve`'s, operation for operation.
"""
from __future__ import annotations

import llvmlite.ir as ir

from .build import D, DP, I64, Emitter


def factor(e: Emitter, A: list) -> tuple:
    """(LU, inv) of A (k x k rows of values, strictly diagonally dominant): LU[i][c] the
    multiplier of row c for row i (i > c), LU[c][j] U's entry (j > c), inv[c] = 1 / U[c][c];
    the elimination of :func:`.world.lu_solve` in row order."""
    k = len(A)
    A = [list(row) for row in A]
    inv = [1.0] * k
    for c in range(k):
        inv[c] = e.div(1.0, A[c][c])
        for i in range(c + 1, k):
            f = A[i][c] = e.mul(A[i][c], inv[c])
            for j in range(c + 1, k):
                A[i][j] = e.sub(A[i][j], e.mul(f, A[c][j]))
    return A, inv


def apply(e: Emitter, LU: list, inv: list, b: list) -> list:
    """A^-1 b from :func:`factor`'s (LU, inv): forward then back substitution, in the order
    of :func:`.world.lu_solve` (so the same values)."""
    k = len(b)
    x = list(b)
    for c in range(k):
        for i in range(c + 1, k):
            x[i] = e.sub(x[i], e.mul(LU[i][c], x[c]))
    for c in range(k - 1, -1, -1):
        v = x[c]
        for j in range(c + 1, k):
            v = e.sub(v, e.mul(LU[c][j], x[j]))
        x[c] = e.mul(v, inv[c])
    return x


class FactorCache:
    """Two entries of (key, the k x k factors and k inverse pivots) on the stack of the
    kernel function ``fn``, keys -1 (none) at its entry."""

    def __init__(self, e: Emitter, fn, k: int):
        self.k, size = k, k * k + k
        ib = ir.IRBuilder(fn.entry_basic_block)
        ib.position_at_start(fn.entry_basic_block)
        self.keys = ib.bitcast(ib.alloca(ir.ArrayType(D, 2)), DP)
        self.older = ib.alloca(I64)
        self.data = ib.bitcast(ib.alloca(ir.ArrayType(D, 2 * size)), DP)
        for slot in (0, 1):
            ib.store(ir.Constant(D, -1.0), ib.gep(self.keys, [ir.Constant(I64, slot)]))
        ib.store(ir.Constant(I64, 0), self.older)
        self.size = size

    def solve(self, e: Emitter, fn, key, make, b: list, tag: str) -> list:
        """A^-1 b for the matrix A = make() (k x k rows, built only where ``key``, a double
        naming A exactly, is not cached), its factors read from the cache entry of key."""
        b_ = e.b
        hit = [b_.fcmp_ordered("==", key, b_.load(b_.gep(self.keys, [ir.Constant(I64, s)]))) for s in (0, 1)]
        pre, miss, done = b_.block, fn.append_basic_block(f"{tag}_miss"), fn.append_basic_block(f"{tag}_cached")
        slot_hit = b_.select(hit[1], ir.Constant(I64, 1), ir.Constant(I64, 0))
        b_.cbranch(b_.or_(hit[0], hit[1]), done, miss)
        b_.position_at_end(miss)
        slot_new = b_.load(self.older)
        b_.store(b_.sub(ir.Constant(I64, 1), slot_new), self.older)
        b_.store(key, b_.gep(self.keys, [slot_new]))
        LU, inv = factor(e, make())
        base = b_.mul(slot_new, ir.Constant(I64, self.size))
        for i, v in enumerate([v for row in LU for v in row] + inv):
            e.store(v, b_.gep(self.data, [base]), i)
        miss_end = b_.block
        b_.branch(done)
        b_.position_at_end(done)
        slot = b_.phi(I64)
        slot.add_incoming(slot_hit, pre)
        slot.add_incoming(slot_new, miss_end)
        row = b_.gep(self.data, [b_.mul(slot, ir.Constant(I64, self.size))])
        k = self.k
        vals = [e.load(row, i) for i in range(self.size)]
        LU = [vals[i * k:(i + 1) * k] for i in range(k)]
        return apply(e, LU, vals[k * k:], b)
