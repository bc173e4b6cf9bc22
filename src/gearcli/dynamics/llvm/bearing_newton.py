"""Newton's method for the bearing friction moments of a constant-frame block (:mod:`.bearings`).

With the block's sign pattern fixed its solution is affine in its joints' moments Mb (K),
so is each bearing's load vector

    u_b(Mb) = u0_b + sum_i Mb_i ug_bi,        P_b = |u_b|                     (:func:`loads`)

(joint k's split, :func:`.bearings.split`: (R_x, R_y, fz) of a locating bearing, (R_x, R_y,
0) of another).  The fixed point Mb = g(Mb), g_k = sum_{b of k} h_b P_b (h_b = 1/2 mu_b
d_b; 0 for a joint at rest), has the Jacobian J_ki = sum_b h_b (u_b . ug_bi) / P_b, and one
Newton step solves (1 - J) Delta = r, r = g(Mb) - Mb (:func:`level`, :func:`step`: one
square root per bearing, J as N_ki / D_k with D_k the product of joint k's loads, the rows
scaled by D_k, so one division per block of one or two joints).

A level stops the iteration (:func:`newton`) where either

* the fixed point's own test holds at Mb, |r_k| <= TOL |g_k| for every joint (Mb is kept,
  as :func:`..bearing_friction.fixed_point` keeps it), or
* Newton's error after the step is proven within TOL / (1 + Lambda) (Mb + Delta is kept,
  :func:`proven`), so that its residual |g - Mb| is within TOL too, as the fixed point's
  test would have it: with sigma_b = sum_i |ug_bi|_1 (>= the rate of P_b per unit Mb in
  the max norm) and Lambda = max_k sum_b h_b sigma_b (g's Lipschitz constant, max norm,
  < 1), e = ||r|| / (1 - Lambda) bounds ||Mb* - Mb||; along the segment to Mb* P_b >= Pmin_b
  = P_b - sigma_b e and g's second derivative is at most H = max_k sum_b h_b sigma_b^2 /
  min_b Pmin_b (b with sigma_b > 0: a load the moments do not move bends nothing, even at
  0), so ||Mb* - (Mb + Delta)|| <= 1/2 H e^2 / (1 - Lambda) (Taylor's remainder, ||(1 -
  J)^-1|| <= 1 / (1 - Lambda)), which must be <= TOL |Mb_k + Delta_k| / (1 + Lambda) for
  every moving joint (any Pmin_b <= 0 or Lambda >= 1: no proof, the next level).

A level from Mb lands within ~1/2 Lambda^2 (|Mb* - Mb| / |Mb*|)^2 of Mb*: from zero moments
~Lambda^2 / 2 (relative), so a second level; from g(0), the fixed point's first iteration
(within ~Lambda, :func:`.bearings._cold`), ~Lambda^4 / 2, proven at the first level where
Lambda ~ 1e-3 (random states: g(0) and one level, where the fixed point takes five or six
iterations); from the warm start in a smooth stretch one level.  The numpy path keeps the
fixed point (:func:`..bearing_friction.fixed_point`): both stop within TOL of the same Mb*.
"""
from __future__ import annotations

import llvmlite.ir as ir

from ..bearing_friction import MAX_ITERATIONS, TOL
from .build import D as D_, I1, I64, Emitter
from .world import lu_solve


def _vectors(lp, k: int, R: list) -> list:
    """(h_b, u_b) per bearing of joint k with friction, from its split R = [R1x, R1y, R2x, R2y, fz]."""
    loc1, loc2, arm1, arm2 = (float(v) for v in lp.bearing_flt[k, 2:])
    out = []
    for h, loc, (x, y) in ((arm1, loc1, R[0:2]), (arm2, loc2, R[2:4])):
        if h != 0.0:
            out.append((h, [x, y, R[4] if loc else 0.0]))
    return out


def loads(e: Emitter, lp, k: int, S0: list, SG: list) -> list:
    """Per bearing of joint k: (h, u0, ug (K), sigma) of its load vector u(Mb) = u0 + sum_i
    Mb_i ug_i (module docstring), from the split S0 of the solution at zero moments and
    SG[i], that of the solution's change per unit Mb_i; sigma = sum_i |ug_i|_1 (>= the 2-norms:
    no square root)."""
    out = []
    for (h, u0), *ugs in zip(_vectors(lp, k, S0), *(_vectors(lp, k, S) for S in SG)):
        ug = [u for _, u in ugs]
        sigma = 0.0
        for u in ug:
            for c in u:
                sigma = e.add(sigma, e.call("fabs", c))
        out.append((h, u0, ug, sigma))
    return out


def _constant(sigma) -> bool:
    """sigma_b is the constant 0: bearing b's load does not depend on the moments (ug_b = 0)."""
    return isinstance(sigma, float) and sigma == 0.0


def unaffected(lv: list) -> bool:
    """True when no bearing load of the block depends on its joints' moments: every ug_bi is
    the constant 0 (known when the code is generated: the block's stored map sends the
    couples only to unknowns the splits do not read, e.g. a link whose other unknown is its
    motor torque about the same axis).  Then g is constant, Mb* = g(0) exactly, in one
    iteration and without a Newton level (the fixed point's second iteration only confirms it)."""
    return all(_constant(sigma) for bearings in lv for *_, sigma in bearings)


def level(e: Emitter, lv: list, moving: list, Mb: list):
    """(g, N, D, P) at the moments Mb (``lv``: per joint its bearings' :func:`loads`): g (K), the Jacobian J_ki = N_ki / D_k (K x K; D_k the
    product of joint k's nonzero bearing loads: a load P_b = 0 has u_b = 0, so its term of
    J is 0 (the subgradient 0 of |u| at 0: a gear in the plane of one bearing leaves the other
    unloaded); 1 for a joint at rest)
    and each joint's bearings' loads P (P_b = |u_b| from the vector, not from its square's
    expanded form, which cancels where a bearing's load nearly vanishes)."""
    K = len(Mb)
    g, N, D, P = [], [], [], []
    zero, one = ir.Constant(D_, 0.0), ir.Constant(D_, 1.0)
    for k, bearings in enumerate(lv):
        gk, Nk, Dk, Pk = 0.0, [0.0] * K, 1.0, []
        for h, u0, ug, sigma in bearings:
            u = [e.add(u0[c], e.dot([v[c] for v in ug], Mb)) for c in range(3)]
            p = e.call("sqrt", e.dot(u, u))
            gk = e.add(gk, e.mul(h, p))        # N/D + h d / p = (N p + h d D) / (D p)
            if not _constant(sigma):           # p = 0: u = 0, u . ug = 0, the term 0 with p read as 1
                q = e.b.select(e.b.fcmp_ordered(">", e.const(p), zero), e.const(p), one)
                Nk = [e.add(e.mul(Nk[i], q), e.mul(e.mul(h, Dk), e.dot(u, ug[i]))) for i in range(K)]
                Dk = e.mul(Dk, q)
            Pk.append(p)
        use = e.b.and_(moving[k], e.b.fcmp_ordered(">", e.const(Dk), zero))
        g.append(e.b.select(moving[k], e.const(gk), zero))
        N.append([e.b.select(use, e.const(v), zero) for v in Nk])
        D.append(e.b.select(use, e.const(Dk), one))
        P.append(Pk)
    return g, N, D, P


def step(e: Emitter, N: list, D: list, r: list) -> list:
    """Delta solving (1 - J) Delta = r, J_ki = N_ki / D_k: rows scaled by D_k, (D - N) Delta =
    D r; one division for one joint, Cramer's rule's one for two, else
    :func:`.world.lu_solve` in row order (1 - J is diagonally dominant, ||J|| <= Lambda < 1:
    no pivoting)."""
    K = len(r)
    A = [[e.sub(D[i] if i == j else 0.0, N[i][j]) for j in range(K)] for i in range(K)]
    b = [e.mul(D[i], r[i]) for i in range(K)]
    if K == 1:
        return [e.div(b[0], A[0][0])]
    if K == 2:
        inv = e.div(1.0, e.sub(e.mul(A[0][0], A[1][1]), e.mul(A[0][1], A[1][0])))
        return [e.mul(inv, e.sub(e.mul(b[0], A[1][1]), e.mul(A[0][1], b[1]))),
                e.mul(inv, e.sub(e.mul(A[0][0], b[1]), e.mul(A[1][0], b[0])))]
    X, _ = lu_solve(e, A, [[v] for v in b], list(range(K)), [-1] * K)
    return [row[0] for row in X]


def proven(e: Emitter, lv: list, moving: list, P: list, r: list, new: list):
    """i1: Newton's error bound after the step to ``new`` is within TOL / (1 + Lambda) of every
    moving joint's moment (module docstring), without a division: with room = 1 - Lambda, e =
    ||r|| / room, Pmin_b = slack_b / room, slack_b = P_b room - sigma_b ||r||, and S = max_k
    sum_b h_b sigma_b^2, the bound 1/2 S e^2 / (min_b Pmin_b room) <= TOL min_k |new_k| / (1 +
    Lambda) reads 1/2 (1 + Lambda) S ||r||^2 <= TOL min_k |new_k| min_b slack_b room^2 (with room > 0, every slack_b > 0 of a bearing with sigma_b > 0)."""
    def fmax(x, y):
        return e.b.select(e.b.fcmp_ordered(">", e.const(x), e.const(y)), e.const(x), e.const(y))

    def fmin(x, y):
        return e.b.select(e.b.fcmp_ordered("<", e.const(x), e.const(y)), e.const(x), e.const(y))
    zero, inf = ir.Constant(D_, 0.0), ir.Constant(D_, float("inf"))
    lam, S, rn, small = zero, zero, zero, inf
    for k, bearings in enumerate(lv):
        mv = moving[k]
        lam = fmax(lam, e.b.select(mv, e.const(e.dot([h for h, *_ in bearings], [s for *_, s in bearings])), zero))
        S = fmax(S, e.b.select(mv, e.const(e.dot([h for h, *_ in bearings], [e.mul(s, s) for *_, s in bearings])), zero))
        rn = fmax(rn, e.call("fabs", r[k]))
        small = fmin(small, e.b.select(mv, e.const(e.call("fabs", new[k])), inf))
    room = e.sub(1.0, lam)
    slack = inf
    for k, bearings in enumerate(lv):
        for (*_, sigma), p in zip(bearings, P[k]):
            if _constant(sigma):               # sigma_b = 0: no curvature, whatever P_b
                continue
            counts = e.b.and_(moving[k], e.b.fcmp_ordered(">", e.const(sigma), zero))
            slack = fmin(slack, e.b.select(counts, e.const(e.sub(e.mul(p, room), e.mul(sigma, rn))), inf))
    lhs = e.mul(e.mul(0.5, e.add(1.0, lam)), e.mul(S, e.mul(rn, rn)))
    rhs = e.mul(e.mul(TOL, small), e.mul(slack, e.mul(room, room)))
    ok = e.b.and_(e.b.fcmp_ordered(">", e.const(room), zero), e.b.fcmp_ordered(">", e.const(slack), zero))
    return e.b.and_(ok, e.b.fcmp_ordered("<=", e.const(lhs), e.const(rhs)))


def within(e: Emitter, new: list, old: list):
    """(|new - old| per joint, i1: each <= TOL |new| + 1e-300 and every |new| finite, i1: every
    |new| finite): the fixed point's test (:func:`..bearing_friction.fixed_point`), of a Newton
    level and of :func:`.bearings._loop`.  A moment grown past the floats (friction that locks
    the mechanism) never passes it (inf <= TOL inf would) and ends the iteration there, a
    failure, as on the numpy path."""
    change = [e.call("fabs", e.sub(v, o)) for v, o in zip(new, old)]
    ok, finite, inf = ir.Constant(I1, 1), ir.Constant(I1, 1), ir.Constant(D_, float("inf"))
    for v, c in zip(new, change):
        size = e.call("fabs", v)
        ok = e.b.and_(ok, e.b.fcmp_ordered("<=", c, e.const(e.add(e.mul(TOL, size), 1e-300))))
        finite = e.b.and_(finite, e.b.fcmp_ordered("<", e.const(size), inf))
    return change, e.b.and_(ok, finite), finite


def newton(e: Emitter, fn, tag: str, start: tuple, lv: list, moving: list, failed):
    """Levels from ``start`` (Mb, its iteration number) until the fixed point's test holds
    or Newton's step is proven (module docstring): returns (the Mb kept, its iteration, the
    block reached after MAX_ITERATIONS levels, where ``failed(g, |r|)`` records the
    failure, the loop's Mb (what reaches that block)), the builder at the converged exit."""
    pre = e.b.block
    body, tried, more, out, failb = (fn.append_basic_block(f"{tag}_{x}") for x in ("nt", "try", "more", "out", "fail"))
    e.b.branch(body)
    e.b.position_at_end(body)
    Mb, it = [e.b.phi(D_) for _ in start[0]], e.b.phi(I64)
    g, N, Dn, P = level(e, lv, moving, Mb)
    r = [e.sub(gk, m) for gk, m in zip(g, Mb)]
    change, ok, finite = within(e, g, Mb)
    here = e.b.block
    e.b.cbranch(ok, out, tried)
    e.b.position_at_end(tried)
    new = [e.add(m, d) for m, d in zip(Mb, step(e, N, Dn, r))]
    there = e.b.block
    e.b.cbranch(proven(e, lv, moving, P, r, new), out, more)
    e.b.position_at_end(more)
    it1 = e.b.add(it, ir.Constant(I64, 1))
    e.b.cbranch(e.b.and_(finite, e.b.icmp_signed("<=", it1, ir.Constant(I64, MAX_ITERATIONS))), body, failb)
    for phis, first, again in ((Mb, start[0], new), ([it], [start[1]], [it1])):
        for ph, v0, v1 in zip(phis, first, again):
            ph.add_incoming(e.imm(v0), pre)
            ph.add_incoming(v1, more)
    e.b.position_at_end(failb)
    failed(g, change)
    e.b.position_at_end(out)
    kept = [e.b.phi(D_) for _ in Mb]
    for ph, m, v in zip(kept, Mb, new):
        ph.add_incoming(m, here)
        ph.add_incoming(e.imm(v), there)
    return kept, it, failb, Mb
