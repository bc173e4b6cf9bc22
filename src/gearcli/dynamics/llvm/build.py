"""Arithmetic for the generated kernel (:mod:`.kernel`): doubles that fold constants.

A value is either a Python ``float`` (a constant of the mechanism, known when the code is
generated) or an LLVM ``double`` (known per sample).  :class:`Emitter` emits an
instruction only when an operand is a per-sample value and skips what the constants make
trivial: a product with an exact 0.0 is 0.0, a product with 1.0 (-1.0) is the other
operand (negated), a sum with 0.0 is the other term.  Skipping ``0.0 * x`` drops a NaN or
an infinity that x might carry; the inputs are checked finite upstream
(:func:`..external.load_values`, the trajectory readers) and a sample whose own arithmetic
overflows still reaches the sign search through the products that remain.  Only the
``contract`` fast-math flag is set (fused multiply-adds): NaN must reach the sign search.

A 3-vector is a 3-tuple of values, a 3x3 matrix a row-major 9-tuple.
"""
from __future__ import annotations

import math
import struct

import llvmlite.ir as ir
import numpy as np

from ...algebra import Algebra
from . import trig
from .types import D, DP, FLAGS, I1, I64, I64P  # noqa: F401 (the types, for the generator's modules)


class ConstantPool:
    """The constants of one function's arithmetic in one constant array, each read at its
    use as base + offset.  As immediates of the JIT's large code model each use cost a
    10-byte ``movabs`` of its address besides the instruction: the code of a many-mesh lossy
    kernel then overflowed the instruction cache (planetary_5p with mesh friction: ~350 L1i
    misses a sample, valgrind).

    The base comes from an empty volatile asm at the top of each sample (``at``: the loop
    body's builder; the function's entry without): a register LLVM can neither fold into
    each read's offset nor see the pool through, and reads that depend on the sample, which
    LLVM folds into their arithmetic instead of hoisting them out of the loop and spilling
    them (servo_joint: 906 -> 872 stack spills; speed the same within the noise).

    The array's values are data, not IR: :meth:`finish` declares it as zeros and leaves the
    values in ``values``, which :class:`.driver.Jit` writes into the loaded code.  So the IR
    text, the compile and the disk cache's object code depend on where constants are used,
    not on their values: mechanisms that differ only in masses, a ratio, an efficiency, a
    friction coefficient, a point (a sweep's variants) share one compiled kernel, each with
    its own pool, as long as they fold the same products (a ratio of exactly -1 or 1, a zero
    coordinate folds).  Up to :data:`POOL_SLOTS` reads each has its own slot, so which values
    happen to be equal does not matter either; above, the reads of one value share a slot,
    which keeps a large kernel's pool small (planetary_3p_rated: 6,312 reads of 1,872
    values).  Per-read and shared slots ran at the same speed within the noise on the
    bundled kernels (2026-12-08, same process)."""

    def __init__(self, fn: ir.Function, at: ir.IRBuilder | None = None):
        self.fn, self.reads = fn, []
        self.ptr = ir.GlobalVariable(fn.module, DP, f"{fn.name}_pool_at")
        self.ptr.global_constant, self.ptr.linkage = True, "internal"
        if at is None:
            at = ir.IRBuilder(fn.entry_basic_block)
            at.position_at_start(fn.entry_basic_block)
        self.base = at.asm(ir.FunctionType(DP, [DP]), "", "=r,0", [at.load(self.ptr)], True)
        self.invariant = fn.module.add_metadata([])

    def load(self, b: ir.IRBuilder, a: float) -> ir.Value:
        """The constant ``a`` (a double), read from the pool at the builder's position (its
        slot numbered by :meth:`finish`)."""
        slot = ir.Constant(I64, 0)
        self.reads.append((struct.pack("<d", a), slot))
        v = b.load(b.gep(self.base, [slot]))
        v.set_metadata("invariant.load", self.invariant)
        return v

    def finish(self) -> None:
        """Number the slots, declare the pool (zeros, internal and read-only: the code
        LLVM makes of a constant array) and record its ``values`` in the module's
        ``pool_values`` ({symbol: values})."""
        index: dict = {}
        for k, (key, slot) in enumerate(self.reads):
            slot.constant = k if len(self.reads) <= POOL_SLOTS else index.setdefault(key, len(index))
        keys = [key for key, _ in self.reads] if len(self.reads) <= POOL_SLOTS else list(index)
        self.values = np.array([struct.unpack("<d", k)[0] for k in keys] or [0.0])
        g = ir.GlobalVariable(self.fn.module, ir.ArrayType(D, len(self.values)), pool_name(self.fn.name))
        g.global_constant, g.initializer = True, ir.Constant(g.value_type, None)
        self.ptr.initializer = g.bitcast(DP)
        pools = getattr(self.fn.module, "pool_values", {})
        pools[pool_name(self.fn.name)] = self.values
        self.fn.module.pool_values = pools


POOL_SLOTS = 1024
"""Reads of the pool of one function up to which each has its own slot (:class:`ConstantPool`)."""


def pool_name(fn_name: str) -> str:
    """The symbol of function ``fn_name``'s constant pool (:class:`ConstantPool`)."""
    return f"{fn_name}_pool"


class Emitter(Algebra):
    """Folding double arithmetic on an :class:`llvmlite.ir.IRBuilder` (see module docstring):
    the primitives of :class:`gearcli.algebra.Algebra`, whose composites (dot, cross,
    matrix-vector products) it inherits; with a :class:`ConstantPool` the constants of its
    arithmetic come from the pool."""

    def __init__(self, builder: ir.IRBuilder, module: ir.Module, pool: ConstantPool | None = None):
        self.b = builder
        self.module = module
        self.pool = pool

    def const(self, a) -> ir.Value:
        """``a`` as an LLVM value at the builder's position: a float is read from the pool
        (an immediate without one), so that the IR text holds no value of the mechanism's
        (:class:`ConstantPool`).  Not for a phi's incoming value (:meth:`imm`)."""
        if isinstance(a, float) and self.pool is not None:
            return self.pool.load(self.b, a)
        return self.imm(a)

    _operand = const

    @staticmethod
    def imm(a) -> ir.Value:
        """``a`` as an LLVM value, a float as an immediate double (a phi's incoming value,
        which a read at the builder's position could not be; a value that is the mechanism's
        then makes the IR text differ with it: another kernel, not a wrong one)."""
        return ir.Constant(D, a) if isinstance(a, float) else a

    def intrinsic(self, name: str, nargs: int = 1) -> ir.Function:
        """The declaration of ``llvm.<name>.f64`` (sin, cos, fabs, ...)."""
        full = f"llvm.{name}.f64"
        if full not in self.module.globals:
            ir.Function(self.module, ir.FunctionType(D, [D] * nargs), full)
        return self.module.globals[full]

    def add(self, a, b):
        if isinstance(a, float) and isinstance(b, float):
            return a + b
        if isinstance(a, float) and a == 0.0:
            return b
        if isinstance(b, float) and b == 0.0:
            return a
        return self.b.fadd(self._operand(a), self._operand(b), flags=FLAGS)

    def neg(self, a):
        return -a if isinstance(a, float) else self.b.fneg(a, flags=FLAGS)

    def sub(self, a, b):
        if isinstance(a, float) and isinstance(b, float):
            return a - b
        if isinstance(b, float) and b == 0.0:
            return a
        if isinstance(a, float) and a == 0.0:
            return self.neg(b)
        return self.b.fsub(self._operand(a), self._operand(b), flags=FLAGS)

    def mul(self, a, b):
        if isinstance(a, float) and isinstance(b, float):
            return a * b
        if isinstance(b, float):
            a, b = b, a
        if isinstance(a, float):
            if a == 0.0:
                return 0.0
            if a == 1.0:
                return b
            if a == -1.0:
                return self.neg(b)
        return self.b.fmul(self._operand(a), self._operand(b), flags=FLAGS)

    def div(self, a, b):
        if isinstance(a, float) and isinstance(b, float):
            return a / b
        if isinstance(b, float) and b == 1.0:
            return a
        return self.b.fdiv(self._operand(a), self._operand(b), flags=FLAGS)

    def call(self, name: str, a):
        """llvm.<name>.f64(a) (folded for a constant)."""
        if isinstance(a, float):
            return abs(a) if name == "fabs" else getattr(math, name)(a)
        return self.b.call(self.intrinsic(name), [a])

    def plus_zero(self, a):
        """a + 0.0, not folded: -0.0 becomes +0.0 (a loss at rest reads 0, not -0)."""
        if isinstance(a, float):
            return a + 0.0
        return self.b.fadd(a, ir.Constant(D, 0.0), flags=FLAGS)

    def signed(self, v, pos: float, neg: float):
        """pos where v > 0, neg where v < 0, else 0.0 (a NaN gives 0: no sign pattern accepts a
        NaN sample anyway)."""
        if isinstance(v, float):
            return pos if v > 0.0 else neg if v < 0.0 else 0.0
        zero = ir.Constant(D, 0.0)
        return self.b.select(self.b.fcmp_ordered(">", v, zero), self.imm(pos),
                             self.b.select(self.b.fcmp_ordered("<", v, zero), self.imm(neg), zero))

    def sincos(self, q):
        """(cos q, sin q) of an angle, inline (:mod:`.trig`; a constant folds)."""
        return trig.sincos(self, q)

    def interp(self, x, table):
        """np.interp(x, speeds, values) of a table (speeds, values) at x >= 0: linear between rows,
        held beyond the ends (a constant: folded)."""
        xs, ys = (tuple(float(v) for v in col) for col in table)
        y = ys[0]
        if len(xs) == 1:
            return y
        for i in range(len(xs) - 1):
            slope = (ys[i + 1] - ys[i]) / (xs[i + 1] - xs[i])
            seg = self.add(ys[i], self.mul(slope, self.sub(x, xs[i])))
            y = self.b.select(self.b.fcmp_ordered(">", x, self.const(xs[i])), self.const(seg), self.const(y))
        return self.b.select(self.b.fcmp_ordered(">=", x, self.const(xs[-1])), self.const(ys[-1]), y)

    # --- memory -------------------------------------------------------------------------
    def load(self, ptr, index):
        """ptr[index] (index an LLVM i64 or a Python int)."""
        idx = ir.Constant(I64, index) if isinstance(index, int) else index
        return self.b.load(self.b.gep(ptr, [idx]))

    def store(self, value, ptr, index):
        """ptr[index] = value (a constant as an immediate: read from the pool, LLVM hoists the
        invariant reads out of the sample loop, and servo_joint's spills went from 906 to 2,150)."""
        idx = ir.Constant(I64, index) if isinstance(index, int) else index
        self.b.store(self.imm(value), self.b.gep(ptr, [idx]))

    def row(self, ptr, n, width: int):
        """A pointer to row n of a (N, width) C-ordered array at ``ptr``."""
        return self.b.gep(ptr, [self.b.mul(n, ir.Constant(I64, width))])

    def stack(self, fn, sizes) -> tuple:
        """double* to new stack arrays of these sizes, allocated in ``fn``'s entry block
        (once per caller, not per sample)."""
        ib = ir.IRBuilder(fn.entry_basic_block)
        ib.position_at_start(fn.entry_basic_block)
        return tuple(ib.bitcast(ib.alloca(ir.ArrayType(D, k)), DP) for k in sizes)

    # --- control flow -------------------------------------------------------------------
    def phis(self, ends: list, values: list) -> list:
        """Where branches meet: per position of the value lists ``values`` a phi taking
        ``values[k]`` from the block ``ends[k]``."""
        out = []
        for i in range(len(values[0])):
            phi = self.b.phi(D)
            for end, vals in zip(ends, values):
                phi.add_incoming(self.imm(vals[i]), end)
            out.append(phi)
        return out

    def switch(self, fn, p, cases: list, tag: str, default=None) -> list:
        """The values of ``emit()`` of the case (key, emit) of ``cases`` whose key the i64 p
        equals, each case straight-line in its own block; ``default`` (an emit) where none
        does (None: the first case's block)."""
        merge = fn.append_basic_block(f"{tag}_merge")
        blocks = [fn.append_basic_block(f"{tag}_p{k}") for k, _ in cases]
        other = fn.append_basic_block(f"{tag}_other") if default is not None else blocks[0]
        sw = self.b.switch(p, other)
        ends, values = [], []
        for (k, emit), blk in zip(cases, blocks):
            sw.add_case(ir.Constant(I64, k), blk)
            self.b.position_at_end(blk)
            values.append(emit())
            ends.append(self.b.block)
            self.b.branch(merge)
        if default is not None:
            self.b.position_at_end(other)
            values.append(default())
            ends.append(self.b.block)
            self.b.branch(merge)
        self.b.position_at_end(merge)
        return self.phis(ends, values)
