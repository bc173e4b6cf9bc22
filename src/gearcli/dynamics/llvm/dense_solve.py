"""A generated dense solve with loops (Gaussian elimination, partial pivoting), for the
k x k systems of :class:`~.world.LowRankBlock` that a sample meets rarely: one
function per module and size, its code independent of k's square (straight-line
elimination of a 20 x 20 system took most of a kernel's compile time).

``solve_k_m(A, X)``: A (k, k) and X (k, m) row-major in memory, overwritten: X = A^-1 X
(the first largest pivot, as :func:`.world.eliminate`); every X NaN when a pivot is
zero (a singular matrix, which no sign pattern accepts).
"""
from __future__ import annotations

import llvmlite.ir as ir

from .build import D, DP, I64, Emitter

FLAGS = ("contract",)


def _loop(b: ir.IRBuilder, fn, lo, hi, tag: str, body) -> None:
    """for (i = lo; i < hi; i++) body(i) (lo, hi i64 values; nothing when lo >= hi)."""
    pre = b.block
    head, loop, done = (fn.append_basic_block(f"{tag}_{s}") for s in ("head", "body", "done"))
    b.branch(head)
    b.position_at_end(head)
    i = b.phi(I64)
    i.add_incoming(lo, pre)
    b.cbranch(b.icmp_signed("<", i, hi), loop, done)
    b.position_at_end(loop)
    body(i)
    i.add_incoming(b.add(i, ir.Constant(I64, 1)), b.block)
    b.branch(head)
    b.position_at_end(done)


class _Matrix:
    """The builder state of one ``solve_<k>_<m>``: A (k, k) and X (k, m) row-major pointers."""

    def __init__(self, b: ir.IRBuilder, fn, k: int, m: int):
        self.b, self.fn, self.k, self.m = b, fn, k, m
        self.A, self.x = fn.args
        self.K, self.M = ir.Constant(I64, k), ir.Constant(I64, m)

    def at(self, i, j):
        return self.b.gep(self.A, [self.b.add(self.b.mul(i, self.K), j)])

    def xi(self, i, h):
        """X[i, h]."""
        return self.b.gep(self.x, [self.b.add(self.b.mul(i, self.M), h)])

    def each(self, tag: str, body) -> None:
        """body(h) for every column h of X."""
        _loop(self.b, self.fn, ir.Constant(I64, 0), self.M, tag, body)

    def fabs(self, v):
        return Emitter(self.b, self.fn.module).call("fabs", v)

    def exchange(self, a1, a2) -> None:
        """The values at the pointers a1 and a2 swapped."""
        v1, v2 = self.b.load(a1), self.b.load(a2)
        self.b.store(v2, a1)
        self.b.store(v1, a2)


def _column(s: _Matrix, c, singular, best) -> None:
    """Column c: the first largest pivot at or below row c swapped up, rows below reduced."""
    b, one = s.b, ir.Constant(I64, 1)
    b.store(c, best)

    def pick(i):
        better = b.fcmp_ordered(">", s.fabs(b.load(s.at(i, c))), s.fabs(b.load(s.at(b.load(best), c))))
        b.store(b.select(better, i, b.load(best)), best)
    _loop(b, s.fn, b.add(c, one), s.K, "piv", pick)
    p = b.load(best)
    _loop(b, s.fn, c, s.K, "swap", lambda j: s.exchange(s.at(c, j), s.at(p, j)))
    s.each("swapx", lambda h: s.exchange(s.xi(c, h), s.xi(p, h)))
    piv = b.load(s.at(c, c))
    b.store(b.or_(b.load(singular), b.fcmp_ordered("==", piv, ir.Constant(D, 0.0))), singular)

    def row(i):
        f = b.fdiv(b.load(s.at(i, c)), piv, flags=FLAGS)

        def entry(j):
            b.store(b.fsub(b.load(s.at(i, j)), b.fmul(f, b.load(s.at(c, j)), flags=FLAGS), flags=FLAGS), s.at(i, j))
        _loop(b, s.fn, b.add(c, one), s.K, "elim", entry)
        s.each("elimx", lambda h: b.store(b.fsub(b.load(s.xi(i, h)), b.fmul(f, b.load(s.xi(c, h)), flags=FLAGS),
                                                 flags=FLAGS), s.xi(i, h)))
    _loop(b, s.fn, b.add(c, one), s.K, "rows", row)


def _back_substitute(s: _Matrix, acc) -> None:
    """x = U^-1 x for the upper triangle U left by the elimination."""
    b, k = s.b, s.k

    def back(r):                         # c = k-1-r, down to 0
        c = b.sub(ir.Constant(I64, k - 1), r)

        def column(h):
            b.store(b.load(s.xi(c, h)), acc)

            def term(j):
                b.store(b.fsub(b.load(acc), b.fmul(b.load(s.at(c, j)), b.load(s.xi(j, h)), flags=FLAGS),
                               flags=FLAGS), acc)
            _loop(b, s.fn, b.add(c, ir.Constant(I64, 1)), s.K, "back", term)
            b.store(b.fdiv(b.load(acc), b.load(s.at(c, c)), flags=FLAGS), s.xi(c, h))
        s.each("backx", column)
    _loop(b, s.fn, ir.Constant(I64, 0), s.K, "subst", back)


def solve_function(module: ir.Module, k: int, m: int = 1) -> ir.Function:
    """The declaration (emitted once) of ``solve_<k>_<m>(double* A, double* X)``."""
    name = f"solve_{k}_{m}"
    if name in module.globals:
        return module.globals[name]
    fn = ir.Function(module, ir.FunctionType(ir.VoidType(), [DP, DP]), name)
    fn.linkage = "internal"
    b = ir.IRBuilder(fn.append_basic_block("entry"))
    s = _Matrix(b, fn, k, m)
    singular, best, acc = b.alloca(ir.IntType(1)), b.alloca(I64), b.alloca(D)   # in the entry: registers
    b.store(ir.Constant(ir.IntType(1), 0), singular)
    _loop(b, fn, ir.Constant(I64, 0), s.K, "col", lambda c: _column(s, c, singular, best))
    _back_substitute(s, acc)
    nan, ok = fn.append_basic_block("nan"), fn.append_basic_block("ok")
    b.cbranch(b.load(singular), nan, ok)
    b.position_at_end(nan)
    _loop(b, fn, ir.Constant(I64, 0), ir.Constant(I64, k * m), "fill",
          lambda i: b.store(ir.Constant(D, float("nan")), b.gep(s.x, [i])))
    b.ret_void()
    b.position_at_end(ok)
    b.ret_void()
    return fn


def loop_solve(e: Emitter, mem: tuple, A: list, B: list) -> list:
    """X = A^-1 B by ``solve_<k>_<m>``: A (k, k) and B (k, m), lists of rows of values, stored
    row-major into the stack arrays ``mem`` (k * k and k * m doubles); X as rows of values."""
    M, X = mem
    k, m = len(A), len(B[0])
    for i in range(k):
        for j in range(k):
            e.store(A[i][j], M, i * k + j)
        for h in range(m):
            e.store(B[i][h], X, i * m + h)
    e.b.call(solve_function(e.module, k, m), [M, X])
    return [[e.load(X, i * m + h) for h in range(m)] for i in range(k)]
