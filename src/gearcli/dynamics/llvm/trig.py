"""cos and sin of a joint angle in the generated kernel, inline instead of a libm call.

Range reduction q = k pi/2 + r with |r| <= pi/4 (Cody-Waite with two parts of pi/2 and
fused multiply-adds: r is exact to an absolute ~1e-32 |k|), then the minimax polynomials
of fdlibm's ``__kernel_sin`` / ``__kernel_cos`` on r (< 1 ulp) and the quadrant k mod 4.
Angles beyond :data:`REDUCE_LIMIT` (and NaN, infinities) take libm's ``sin``/``cos``
(``llvm.sin.f64``, ``llvm.cos.f64``) on a rarely taken branch.  The results differ from
libm's by about an ulp, far below the 1e-12 to which the backends agree.
"""
from __future__ import annotations

import math

import llvmlite.ir as ir

from .types import D, I64

REDUCE_LIMIT = 1e5
PIO2_HI = 1.5707963267948966           # pi/2 rounded to a double
PIO2_LO = 6.123233995736766e-17        # pi/2 - PIO2_HI
INV_PIO2 = 0.6366197723675814          # 2/pi
SIN = (-1.66666666666666324348e-01, 8.33333333332248946124e-03, -1.98412698298579493134e-04,
       2.75573137070700676789e-06, -2.50507602534068634195e-08, 1.58969099521155010221e-10)
COS = (4.16666666666666019037e-02, -1.38888888888741095749e-03, 2.48015872894767294178e-05,
       -2.75573143513906633035e-07, 2.08757232129817482790e-09, -1.13596475577881948265e-11)


def _horner(e, z, coefs):      # e: the :class:`.build.Emitter`
    """coefs[0] + z (coefs[1] + z (...))."""
    acc = coefs[-1]
    for c in reversed(coefs[:-1]):
        acc = e.add(c, e.mul(z, acc))
    return acc


def _fma(e, a, b, c):
    return e.b.call(e.intrinsic("fma", 3), [e.const(a), e.const(b), e.const(c)])


def _reduced(e, q):
    """(cos, sin) of q by reduction to |r| <= pi/4 (|q| <= REDUCE_LIMIT)."""
    b = e.b
    k = b.call(e.intrinsic("rint"), [e.mul(q, INV_PIO2)])
    r = _fma(e, e.neg(k), PIO2_LO, _fma(e, e.neg(k), PIO2_HI, q))
    z = e.mul(r, r)
    s = e.add(r, e.mul(e.mul(z, r), e.add(SIN[0], e.mul(z, _horner(e, z, SIN[1:])))))
    hz = e.mul(0.5, z)
    w = e.sub(1.0, hz)
    c = e.add(w, e.add(e.sub(e.sub(1.0, w), hz), e.mul(e.mul(z, z), _horner(e, z, COS))))
    quad = b.and_(b.fptosi(k, I64), ir.Constant(I64, 3))
    odd = b.icmp_unsigned("!=", b.and_(quad, ir.Constant(I64, 1)), ir.Constant(I64, 0))
    sin_mag, cos_mag = b.select(odd, c, s), b.select(odd, s, c)
    sin_neg = b.icmp_unsigned("!=", b.and_(quad, ir.Constant(I64, 2)), ir.Constant(I64, 0))
    cos_neg = b.icmp_unsigned("!=", b.and_(b.add(quad, ir.Constant(I64, 1)), ir.Constant(I64, 2)),
                              ir.Constant(I64, 0))
    return (b.select(cos_neg, e.neg(cos_mag), cos_mag), b.select(sin_neg, e.neg(sin_mag), sin_mag))


def sincos(e, q):
    """(cos q, sin q) of an angle (a constant folds)."""
    if isinstance(q, float):
        return math.cos(q), math.sin(q)
    b = e.b
    far = b.fcmp_unordered(">", e.call("fabs", q), ir.Constant(D, REDUCE_LIMIT))
    with b.if_else(far, likely=False) as (libm, inline):
        with libm:
            slow, slow_end = (e.call("cos", q), e.call("sin", q)), b.block
        with inline:
            fast, fast_end = _reduced(e, q), b.block
    return tuple(e.phis([slow_end, fast_end], [slow, fast]))
