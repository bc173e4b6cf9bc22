"""A lossy block's mesh-friction system 1 + M_l D, inverted once per kernel call and pattern.

:class:`~.losses.LossyBlock` solves, for the accepted sign pattern p of each sample,

    (1 + M_l D) t_l = t0_l,        M_l = (X_p Phi^T)[lossy tooth rows],  D = diag(sigma s_v),

a k x k system (k lossy meshes) that depends on the sample only through p and D's digits
(-1, 0, 1 each).  Forming M_l (a low-rank block: one inner solve per lossy mesh) and
factoring the matrix cost most of the mesh friction on a many-mesh block (planetary_5p:
~1,600 of its ~2,600 instructions a sample), while along a motion, and even over random
states, the same few (p, D) recur: every sample of 20,000 random states of the 5-planet
stage has one p, and D takes two values with the sign of its rate.

So each call of the kernel keeps the inverses of the last two matrices met, keyed by (p,
D), in stack arrays (:meth:`InverseCache.solve`): a sample whose key is there reads its
inverse back; another forms its matrix and inverts it (:func:`.world.lu_solve` of the
identity, ``dominant``: the matrix is strictly diagonally dominant for every pattern, so
elimination in row order without pivoting), stores the inverse over the older entry and
reads it back the same way.  The inverse is the same numbers either way (a deterministic
function of (p, D)), so no result depends on the cache, on the samples before or on the
threads.  The solution is then one k x k product, k independent dot products, where a
substitution was a chain of 2k steps (planetary_5p: 12.4 -> 11.2 ms a call of 20,000 samples
against the factors kept instead of the inverse).
"""
from __future__ import annotations

import llvmlite.ir as ir

from .build import D, DP, I64, Emitter
from .world import lu_solve


class InverseCache:
    """Two entries of (key, a k x k inverse, row-major) on the stack of the kernel function
    ``fn``, keys -1 (none) at its entry."""

    def __init__(self, e: Emitter, fn, k: int):
        self.k, size = k, k * k
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
        """A^-1 b for the matrix A = make() (k x k rows, built and inverted only where ``key``, a
        double naming A exactly, is not cached), A^-1 read from the cache entry of key."""
        b_ = e.b
        hit = [b_.fcmp_ordered("==", key, b_.load(b_.gep(self.keys, [ir.Constant(I64, s)]))) for s in (0, 1)]
        pre, miss, done = b_.block, fn.append_basic_block(f"{tag}_miss"), fn.append_basic_block(f"{tag}_cached")
        slot_hit = b_.select(hit[1], ir.Constant(I64, 1), ir.Constant(I64, 0))
        b_.cbranch(b_.or_(hit[0], hit[1]), done, miss)
        b_.position_at_end(miss)
        slot_new = b_.load(self.older)
        b_.store(b_.sub(ir.Constant(I64, 1), slot_new), self.older)
        b_.store(key, b_.gep(self.keys, [slot_new]))
        k = self.k
        inverse = lu_solve(e, make(), [[1.0 if i == j else 0.0 for j in range(k)] for i in range(k)], dominant=True)[0]
        base = b_.mul(slot_new, ir.Constant(I64, self.size))
        for i in range(k):
            for j in range(k):
                e.store(inverse[i][j], b_.gep(self.data, [base]), i * k + j)
        miss_end = b_.block
        b_.branch(done)
        b_.position_at_end(done)
        slot = b_.phi(I64)
        slot.add_incoming(slot_hit, pre)
        slot.add_incoming(slot_new, miss_end)
        row = b_.gep(self.data, [b_.mul(slot, ir.Constant(I64, self.size))])
        k = self.k
        return [e.dot([e.load(row, i * k + j) for j in range(k)], b) for i in range(k)]
