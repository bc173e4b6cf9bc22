"""The compiled per-sample kernel: a sample's whole chain in registers and small arrays.

For each sample: joint space, kinematics, inertia and external loads
(:mod:`.kernel_links`), then the blocks of the schedule in order, exactly as
:func:`.blocks.solve_blocks` does over arrays: a constant-frame block gathers its links'
right-hand sides in its frame F, x = Ainv[pattern] r with the sign resolution of
:func:`.signs.resolve_signs` (all t positive, then the solution's own signs m times, then
every pattern in order), passes its wrenches on to the later links and turns joint
reactions to their child's basis; a block without a constant frame is assembled in world
axes from column terms (:mod:`.kernel_terms`) and solved by Gaussian elimination.

Data-driven (:mod:`.kernel_program`): one compiled function serves every mechanism,
compiled once and cached on disk (numba ``cache=True``).  No allocation per sample:
:func:`run` allocates its scratch once per call (one call per thread).
"""
from __future__ import annotations

import numpy as np
from numba import njit

from .kernel_links import INLINE, OPTS, external, inertia, joint_space, kinematics
from .kernel_math import add, cx, load3, load9, mtv, mv, sub
from .kernel_output import write_outputs
from .kernel_world import world_gather, world_propagate, world_solve
from .signs import MAX_EXHAUSTIVE, TOL_SIGN

# numba re-validates a cached function against its own file only, and the helpers of the
# modules imported above (and the constants of signs.py) are compiled into :func:`run`: this
# digest of their sources
# (tests/test_kernel.py checks it) changes this file whenever they change, so that the
# disk cache of ``run`` is never stale
HELPERS_DIGEST = "cae330c1c4c7e310"
HELPER_FILES = ("kernel_links.py", "kernel_math.py", "kernel_output.py", "kernel_world.py", "signs.py")


@njit(**INLINE)
def _gather(F, base, lk0, B, blinks, R, o, rhs, r):
    """r (6B) = the block links' right-hand sides in F's axes about o_F."""
    at_rest = F == base      # the base: world axes about the origin already
    RF, oF = load9(R, F), load3(o, F)
    for i in range(B):
        L = blinks[lk0 + i]
        f = (rhs[L, 0], rhs[L, 1], rhs[L, 2])
        m = add((rhs[L, 3], rhs[L, 4], rhs[L, 5]), cx(sub(load3(o, L), oF), f))
        if not at_rest:
            f, m = mtv(RF, f), mtv(RF, m)
        r[6 * i], r[6 * i + 1], r[6 * i + 2] = f[0], f[1], f[2]
        r[6 * i + 3], r[6 * i + 4], r[6 * i + 5] = m[0], m[1], m[2]


@njit(**INLINE)
def _row(ainv, b, nr, r):
    """Row of Ainv at ``b`` (nr long) times r."""
    if nr == 6:
        return (ainv[b] * r[0] + ainv[b + 1] * r[1] + ainv[b + 2] * r[2]
                + ainv[b + 3] * r[3] + ainv[b + 4] * r[4] + ainv[b + 5] * r[5])
    s = 0.0
    for j in range(0, nr, 6):   # unrolled by six: independent products, short chains
        s += (ainv[b + j] * r[j] + ainv[b + j + 1] * r[j + 1] + ainv[b + j + 2] * r[j + 2]
              + ainv[b + j + 3] * r[j + 3] + ainv[b + j + 4] * r[j + 4] + ainv[b + j + 5] * r[j + 5])
    return s


@njit(**INLINE)
def _apply(ainv, off, n, nr, r, x):
    """x (n) = Ainv r, Ainv (n, nr) row-major at ``off``."""
    for i in range(n):
        x[i] = _row(ainv, off + i * nr, nr, r)


@njit(**INLINE)
def _apply_t(ainv, off, nr, r, x, tcol, t0, m):
    """Only the signed t of x = Ainv r (all a sign trial needs; the same row products)."""
    for i in range(m):
        c = tcol[t0 + i]
        x[c] = _row(ainv, off + c * nr, nr, r)


@njit(**INLINE)
def consistent(x, tcol, t0, m, sig, tol):
    """True when every t agrees with its sign (up to tol; signs.resolve_signs)."""
    for i in range(m):
        if not (-sig[i] * x[tcol[t0 + i]] <= tol):
            return False
    return True


@njit(**INLINE)
def own_signs(x, tcol, t0, m, sig):
    """sig = the signs of the solution's own t (zero counts as positive)."""
    for i in range(m):
        sig[i] = -1.0 if x[tcol[t0 + i]] < 0 else 1.0


@njit(**INLINE)
def pattern_signs(p, m, sig):
    """sig = pattern p of :func:`.signs.sign_patterns` (bit m-1-i set: t_i negative)."""
    for i in range(m):
        sig[i] = -1.0 if (p >> (m - 1 - i)) & 1 else 1.0


@njit(**INLINE)
def _pattern(m, sig):
    """Position of the signs in :func:`.signs.sign_patterns` (signs.pattern_index)."""
    k = 0
    for i in range(m):
        if sig[i] < 0:
            k += 1 << (m - 1 - i)
    return k


@njit(**INLINE)
def _trial(ctx, world, a0, k0, nt, n, nr, r, x, tcol, t0, m, sig):
    """x = the block's solution for the signs ``sig`` (world axes), or only its signed t
    (constant frame: those rows of Ainv[pattern] r; :func:`_resolve` completes x)."""
    ainv, trec, tflt, R, o, A = ctx
    if world:
        world_solve(k0, nt, trec, tflt, sig, R, o, nr, r, x, A)
    else:
        _apply_t(ainv, a0 + _pattern(m, sig) * n * nr, nr, r, x, tcol, t0, m)


@njit(**INLINE)
def _resolve(ctx, world, a0, k0, nt, n, nr, r, x, tcol, t0, m, sig, tol):
    """Solve a block with a consistent sign pattern (signs.resolve_signs); False if none.

    Step 0: every t positive; steps 1..m: the signs of the previous solution's own t;
    then every pattern in :func:`.signs.sign_patterns` order (m <= MAX_EXHAUSTIVE).  One
    call site of the solve keeps the compiled code small.  A constant-frame block's trials
    compute its t only (m rows of Ainv r): the whole x is computed once, for the pattern
    accepted (bitwise what a full trial gives: the same row products)."""
    if not world:
        if m == 0:
            _apply(ctx[0], a0, n, nr, r, x)
            return True
    for i in range(m):
        sig[i] = 1.0
    steps = 1 + m + ((1 << m) if m <= MAX_EXHAUSTIVE else 0)
    for step in range(steps):
        if step > m:
            pattern_signs(step - m - 1, m, sig)
        elif step > 0:
            own_signs(x, tcol, t0, m, sig)
        _trial(ctx, world, a0, k0, nt, n, nr, r, x, tcol, t0, m, sig)
        if consistent(x, tcol, t0, m, sig, tol):
            if not world:
                _apply(ctx[0], a0 + _pattern(m, sig) * n * nr, n, nr, r, x)
            return True
    return False


@njit(**INLINE)
def _wrench_in_F(c0, size, signed, co, cmat, x):
    """C_plus x + C_sep |x| (6-tuple): a group's wrench on its primary link, F axes."""
    w0, w1, w2, w3, w4, w5 = 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    for j in range(size):
        xj = x[c0 + j]
        w0 += cmat[co + j] * xj
        w1 += cmat[co + size + j] * xj
        w2 += cmat[co + 2 * size + j] * xj
        w3 += cmat[co + 3 * size + j] * xj
        w4 += cmat[co + 4 * size + j] * xj
        w5 += cmat[co + 5 * size + j] * xj
        if signed == 1:
            ax = abs(xj)
            cs = co + 6 * size
            w0 += cmat[cs + j] * ax
            w1 += cmat[cs + size + j] * ax
            w2 += cmat[cs + 2 * size + j] * ax
            w3 += cmat[cs + 3 * size + j] * ax
            w4 += cmat[cs + 4 * size + j] * ax
            w5 += cmat[cs + 5 * size + j] * ax
    return (w0, w1, w2), (w3, w4, w5)


@njit(**INLINE)
def _propagate(F, base, p0, np_, prec, cmat, later, R, o, x, rhs):
    """rhs[L] -= the solved wrenches of the block's groups on their later links L."""
    RF, oF = load9(R, F), load3(o, F)
    for e in range(p0, p0 + np_):
        f, mo = _wrench_in_F(prec[e, 0], prec[e, 1], prec[e, 2], prec[e, 3], cmat, x)
        if F != base:
            f, mo = mv(RF, f), mv(RF, mo)                 # world axes, about o_F
        P, l0, nl = prec[e, 4], prec[e, 5], prec[e, 6]
        for i in range(nl):
            L = later[l0 + i]
            s = 1.0 if L == P else -1.0
            m = add(mo, cx(sub(oF, load3(o, L)), f))
            rhs[L, 0] -= s * f[0]
            rhs[L, 1] -= s * f[1]
            rhs[L, 2] -= s * f[2]
            rhs[L, 3] -= s * m[0]
            rhs[L, 4] -= s * m[1]
            rhs[L, 5] -= s * m[2]


@njit(**INLINE)
def _store(n, b, brec, gcol, scol, cbrec, turns, q, cs, x, sig, X, SG):
    """Write block b's solution (joint reactions in the child's basis) into the solution
    row X and its signs into SG[n]."""
    nloc, g0, m, t0, cb0, ncb = brec[b, 3], brec[b, 4], brec[b, 5], brec[b, 6], brec[b, 10], brec[b, 11]
    for i in range(nloc):
        X[gcol[g0 + i]] = x[i]
    for e in range(cb0, cb0 + ncb):
        c0, j = cbrec[e, 0], cbrec[e, 1]
        if j >= 0:                                 # the joint's own angle
            cq, sq = cs[j, 0], cs[j, 1]
        else:
            angle = 0.0
            for k in range(q.shape[0]):
                angle += turns[cbrec[e, 2] + k] * q[k]
            cq, sq = np.cos(angle), np.sin(angle)
        for h in (0, 3):
            x0, x1 = x[c0 + h], x[c0 + h + 1]
            X[gcol[g0 + c0 + h]] = cq * x0 + sq * x1
            X[gcol[g0 + c0 + h + 1]] = -sq * x0 + cq * x1
    for i in range(m):
        SG[n, scol[t0 + i]] = sig[i]


@njit(**INLINE)
def _blocks(n, ints, flts, q, cs, R, o, rhs, r, x, sig, A, X, SG, fail):
    """Every block of the schedule in order, for sample n."""
    brec, blinks, gcol, tcol, scol, prec, later, cbrec, trec, meta = (ints[1], ints[2], ints[3], ints[4], ints[5],
                                                                      ints[6], ints[7], ints[8], ints[10], ints[11])
    ainv, cmat, tflt, turns = flts[4], flts[5], flts[6], flts[7]
    base = meta[0]
    ctx = (ainv, trec, tflt, R, o, A)
    for b in range(brec.shape[0]):
        F, lk0, B, nloc, m, t0, a0, k0, nt = (brec[b, 0], brec[b, 1], brec[b, 2], brec[b, 3], brec[b, 5],
                                              brec[b, 6], brec[b, 7], brec[b, 12], brec[b, 13])
        nr = 6 * B
        world = F < 0
        if world:
            world_gather(lk0, B, blinks, rhs, r)
        else:
            _gather(F, base, lk0, B, blinks, R, o, rhs, r)
        big = 0.0
        for i in range(nr if m > 0 else 0):       # the zero tolerance of t (Eq. 14)
            big = max(big, abs(r[i]))
        ok = _resolve(ctx, world, a0, k0, nt, nloc, nr, r, x, tcol, t0, m, sig, TOL_SIGN * (1.0 + big))
        if not ok and fail[n] < 0:
            fail[n] = b
        if nt > 0:                                # world axes, or its link's (kernel_terms.local_inverse)
            world_propagate(k0, nt, trec, tflt, sig, R, o, x, rhs)
        else:
            _propagate(F, base, brec[b, 8], brec[b, 9], prec, cmat, later, R, o, x, rhs)
        _store(n, b, brec, gcol, scol, cbrec, turns, q, cs, x, sig, X, SG)


@njit(**OPTS)
def run(ints, flts, ldrec, ldflt, vals, qi, qdi, qddi, start, stop, outs, scratch):
    """Solve samples start..stop-1 of qi, qdi, qddi (N, dof) into the output arrays ``outs``
    (motor (N, M), tau (N, dof), joint (N, J*6), gear_t, gear_sep (N, G), gear_radial,
    gear_axial (N, G*2), motor speed (N, M), the sign of each t used (N, signed meshes) and
    fail (N,): the first block with no consistent sign pattern, -1 if none); returns how
    many of these samples failed.  ``scratch`` from :func:`~.kernel_driver.scratch` (one per thread).
    Compiled without numba's reference counting (``_nrt=False``: ~10 ns an array passed
    otherwise): nothing here allocates."""
    jrec, moving = ints[0], ints[9]
    jflt, lflt, g = flts[0], flts[1], flts[3]
    sptr, sidx, sval = ints[15], ints[16], flts[10]
    R, o, w, dw, a, rhs, cs, q, qd, qdd, r, x, sig, A, xrow = scratch
    SG, fail = outs[8], outs[9]
    failed = 0
    for n in range(start, stop):
        fail[n] = -1
        joint_space(sptr, sidx, sval, qi, qdi, qddi, n, q, qd, qdd)
        kinematics(jrec, jflt, q, qd, qdd, R, o, w, dw, a, cs)
        for L in moving:
            inertia(L, lflt, g, R, w, dw, a, rhs)
        external(n, ldrec, ldflt, vals, R, rhs)
        _blocks(n, ints, flts, q, cs, R, o, rhs, r, x, sig, A, xrow, SG, fail)
        write_outputs(n, xrow, qdi, ints, flts, outs)
        if fail[n] >= 0:
            failed += 1
    return failed
