"""The algebra every per-sample physics term is written against, and its numpy evaluation.

A physics term of the solver (the kinematics of Eqs. 2-5, the d'Alembert wrench of Eqs.
17-18, the friction laws, ...) is one Python function of an *algebra* ``al`` and values:

    def inertia_wrench(al, m, I_c, r_c, R, w, dw, a, g):
        wb = al.mtv(R, w)
        ...

and is evaluated in two ways, by the same source:

* :class:`Arrays` (here): a value is a Python ``float`` (a constant of the mechanism) or a
  numpy array over the samples, shape (N,); the numpy reference path calls the term once
  for all N samples;
* :class:`Floats` (here): one sample, every value a Python ``float`` (a call over one
  sample, an analysis pose or a ``simulate`` step, would otherwise pay numpy's cost per
  operation on (1,) arrays); the same operations, nothing folded;
* :class:`gearcli.dynamics.llvm.build.Emitter`: a value is a ``float`` or an LLVM
  ``double``; the generator calls the term once and gets the instructions of one sample
  (:mod:`gearcli.dynamics.llvm`).

Both fold the constants alike (:class:`Algebra`'s primitives): a product with an exact 0.0
is 0.0, with 1.0 (-1.0) the other operand (negated), a sum with 0.0 the other term.  So the
two paths perform the same operations in the same order (the kernel may fuse a multiply and
an add: ``contract``), and a term written wrongly is wrong on both paths: the tests that find
it are the by-hand and power-balance ones (pytest marker ``physics``, run first), not the
paths' comparison.

A 3-vector is a 3-tuple of values, a 3x3 matrix a row-major 9-tuple of values.  Control flow
(the sign search, block factorisations, fixed points, threads) stays each path's own.
"""
from __future__ import annotations

import math
import operator

import numpy as np


class Algebra:
    """The composite operations, written once over the primitives ``add``, ``sub``, ``mul``,
    ``neg`` of a subclass (each folding constants as the module docstring says)."""

    def dot(self, xs, ys):
        """sum_i xs[i] ys[i], left to right."""
        s = 0.0
        for x, y in zip(xs, ys):
            s = self.add(s, self.mul(x, y))
        return s

    def vadd(self, a, b):
        return tuple(self.add(x, y) for x, y in zip(a, b))

    def vsub(self, a, b):
        return tuple(self.sub(x, y) for x, y in zip(a, b))

    def scale(self, a, s):
        return tuple(self.mul(x, s) for x in a)

    def cx(self, a, b):
        """a x b."""
        return (self.sub(self.mul(a[1], b[2]), self.mul(a[2], b[1])),
                self.sub(self.mul(a[2], b[0]), self.mul(a[0], b[2])),
                self.sub(self.mul(a[0], b[1]), self.mul(a[1], b[0])))

    def mv(self, R, v):
        """R v."""
        return tuple(self.dot(R[3 * i:3 * i + 3], v) for i in range(3))

    def mtv(self, R, v):
        """R^T v."""
        return tuple(self.dot(R[i::3], v) for i in range(3))

    def mm(self, A, B):
        """A B."""
        return tuple(self.dot(A[3 * i:3 * i + 3], B[j::3]) for i in range(3) for j in range(3))

    def sign(self, v):
        """sign(v): -1, 0 or 1 (0 at an exact zero; a NaN gives 0)."""
        return self.signed(v, 1.0, -1.0)


class Arrays(Algebra):
    """The numpy evaluation: values are floats or (N,) arrays (every sample at once)."""

    def const(self, a):
        return a

    # The composites over per-sample values only (no constant to fold): the primitives'
    # operations in the same order, without a call per primitive (the one-sample path).

    def dot(self, xs, ys):
        if not xs or _any_float(xs) or _any_float(ys):
            return Algebra.dot(self, xs, ys)
        it = zip(xs, ys)
        x, y = next(it)
        s = x * y
        for x, y in it:
            s = s + x * y
        return s

    def vadd(self, a, b):
        if _any_float(a) or _any_float(b):
            return Algebra.vadd(self, a, b)
        return tuple(x + y for x, y in zip(a, b))

    def vsub(self, a, b):
        if _any_float(a) or _any_float(b):
            return Algebra.vsub(self, a, b)
        return tuple(x - y for x, y in zip(a, b))

    def cx(self, a, b):
        if _any_float(a) or _any_float(b):
            return Algebra.cx(self, a, b)
        return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])

    def add(self, a, b):
        fa, fb = isinstance(a, float), isinstance(b, float)
        if fa and fb:
            return a + b
        if fa and a == 0.0:
            return b
        if fb and b == 0.0:
            return a
        return a + b

    def neg(self, a):
        return -a

    def sub(self, a, b):
        fa, fb = isinstance(a, float), isinstance(b, float)
        if fa and fb:
            return a - b
        if fb and b == 0.0:
            return a
        if fa and a == 0.0:
            return -b
        return a - b

    def mul(self, a, b):
        fa = isinstance(a, float)
        if fa == isinstance(b, float):      # two constants, or two per-sample values
            return a * b
        c, v = (a, b) if fa else (b, a)
        if c == 0.0:
            return 0.0
        if c == 1.0:
            return v
        if c == -1.0:
            return -v
        return a * b

    def div(self, a, b):
        if isinstance(b, float) and b == 1.0:
            return a
        return a / b

    def plus_zero(self, a):
        """a + 0.0, not folded: -0.0 becomes +0.0 (a loss at rest reads 0, not -0)."""
        return a + 0.0

    def call(self, name: str, a):
        """fabs, sqrt, sin, cos of a (folded for a constant)."""
        if isinstance(a, float):
            return abs(a) if name == "fabs" else getattr(math, name)(a)
        return np.abs(a) if name == "fabs" else getattr(np, name)(a)

    def sincos(self, q):
        """(cos q, sin q)."""
        if isinstance(q, float):
            return math.cos(q), math.sin(q)
        return np.cos(q), np.sin(q)

    def signed(self, v, pos: float, neg: float):
        """pos where v > 0, neg where v < 0, else 0.0 (a NaN gives 0.0)."""
        if isinstance(v, float):
            return pos if v > 0.0 else neg if v < 0.0 else 0.0
        return np.where(v > 0.0, pos, np.where(v < 0.0, neg, 0.0))

    def interp(self, x, table):
        """np.interp(x, speeds, values) of a table (speeds, values) at x >= 0: linear between
        rows, held beyond the ends."""
        xs, ys = (np.asarray(col, float) for col in table)
        if len(xs) == 1:
            return float(ys[0])
        return np.interp(x, xs, ys)


class Floats(Algebra):
    """The numpy path at one sample: every value a Python float, plain IEEE arithmetic.

    A call over one sample (an analysis pose, a ``simulate`` step) spends its time in the
    per-operation cost of numpy on (1,) arrays; here an operation is the float's own.  Nothing
    is folded (a constant and a per-sample value are both floats), so a result equals
    :class:`Arrays`' at that sample but for the sign of a zero (0.0 * x reads -0.0 for x < 0
    where the folded product reads 0.0): the operations and their order are the primitives'.
    sqrt, sin, cos are numpy's (the (N,) path's functions), a division by zero gives inf or
    nan as numpy's does.
    """

    add = staticmethod(operator.add)
    sub = staticmethod(operator.sub)
    mul = staticmethod(operator.mul)
    neg = staticmethod(operator.neg)

    def const(self, a):
        return a

    def div(self, a, b):
        return a / b if b != 0.0 else float(np.divide(a, b))

    def plus_zero(self, a):
        return a + 0.0

    def call(self, name: str, a):
        return abs(a) if name == "fabs" else float(getattr(np, name)(a))

    def sincos(self, q):
        return float(np.cos(q)), float(np.sin(q))

    def signed(self, v, pos: float, neg: float):
        return pos if v > 0.0 else neg if v < 0.0 else 0.0

    def interp(self, x, table):
        return float(Arrays.interp(self, x, table))

    def dot(self, xs, ys):
        s = 0.0
        for x, y in zip(xs, ys):
            s = s + x * y
        return s

    def vadd(self, a, b):
        return (a[0] + b[0], a[1] + b[1], a[2] + b[2]) if len(a) == 3 else tuple(map(operator.add, a, b))

    def vsub(self, a, b):
        return (a[0] - b[0], a[1] - b[1], a[2] - b[2]) if len(a) == 3 else tuple(map(operator.sub, a, b))

    def scale(self, a, s):
        return tuple(x * s for x in a)

    def cx(self, a, b):
        return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])

    def mv(self, R, v):
        x, y, z = v
        return (R[0] * x + R[1] * y + R[2] * z, R[3] * x + R[4] * y + R[5] * z,
                R[6] * x + R[7] * y + R[8] * z)

    def mtv(self, R, v):
        x, y, z = v
        return (R[0] * x + R[3] * y + R[6] * z, R[1] * x + R[4] * y + R[7] * z,
                R[2] * x + R[5] * y + R[8] * z)

    def mm(self, A, B):
        return tuple(A[i] * B[j] + A[i + 1] * B[j + 3] + A[i + 2] * B[j + 6]
                     for i in (0, 3, 6) for j in (0, 1, 2))


def algebra_for(n: int):
    """The algebra of the numpy path for n samples: :data:`FLOATS` at one, else :data:`ARRAYS`."""
    return FLOATS if n == 1 else ARRAYS


def _any_float(vs) -> bool:
    """Whether a tuple of values holds a constant (a Python float)."""
    for v in vs:
        if isinstance(v, float):
            return True
    return False


ARRAYS = Arrays()
"""The numpy algebra (stateless: one for every caller)."""
FLOATS = Floats()
"""The one-sample numpy algebra (stateless)."""


def as_array(v, n: int) -> np.ndarray:
    """A value of :class:`Arrays` as an (N,) array (a constant broadcast, read-only)."""
    return np.broadcast_to(np.float64(v), (n,)) if isinstance(v, float) else v


def stack_vectors(vs, n: int) -> np.ndarray:
    """A k-tuple of :class:`Arrays` values (a 3-vector, a 6-vector wrench) as an (N, k) array."""
    out = np.empty((n, len(vs)))
    for i, x in enumerate(vs):
        out[:, i] = x
    return out


def stack_matrices(Ms, n: int) -> np.ndarray:
    """A row-major 9-tuple of :class:`Arrays` values as an (N, 3, 3) array."""
    return stack_vectors(Ms, n).reshape(n, 3, 3)


def vectors(a: np.ndarray) -> tuple:
    """An (N, 3) array as a 3-vector of (N,) arrays (contiguous copies), or a (3,) constant as
    a 3-tuple of floats."""
    a = np.asarray(a, float)
    if a.ndim == 1:
        return tuple(float(x) for x in a)
    return tuple(np.ascontiguousarray(a[:, i]) for i in range(3))


def matrices(R: np.ndarray) -> tuple:
    """An (N, 3, 3) array as a row-major 9-tuple of (N,) arrays, or a (3, 3) constant as floats."""
    R = np.asarray(R, float)
    if R.ndim == 2:
        return tuple(float(x) for x in R.reshape(9))
    return tuple(np.ascontiguousarray(R[:, i, j]) for i in range(3) for j in range(3))
