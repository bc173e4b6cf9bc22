"""Generated per-sample kinematics and link loads (the first half of :mod:`.kernel`).

The terms of :func:`..kinematics.forward` and :func:`..inertia.inertia_load` (paper Eqs. 2-5 and
17-18: the same functions, :func:`..kinematics.joint_frame`, :func:`..kinematics.child_motion`,
:func:`..inertia.inertia_wrench`, over the emitter's algebra), and the external loads of
:func:`..external.external_wrenches`, emitted straight-line per joint and link with
every fixed transform, mass, inertia and load point of the :class:`~.program.Program`
as a constant (:class:`~.build.Emitter` folds the zeros and ones: a joint on the base,
an identity R_pj, a centre of mass on an axis cost nothing).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import llvmlite.ir as ir

from .build import D, I64, Emitter
from ..inertia import inertia_wrench
from ..kinematics import EYE, ZERO3, child_motion, joint_frame
from ..wrenches import load_wrench



@dataclass
class Sample:
    """One sample's values while its code is generated (every entry a float or an LLVM double).

    ``q, qd, qdd`` (J,) per real joint; ``R, o, w, dw, a`` per link (base frame; the base
    at rest: identity and zeros, constants); ``cs`` per joint (cos, sin of its angle);
    ``rhs`` per link the 6 right-hand-side entries (base frame, about o_L); ``sol`` per
    column of the solution row its value (joint reactions in the child's basis);
    ``frames`` per joint its (R, o, cos, sin) at q, emitted once and shared by the samples
    of the same pose (:mod:`.mass`).
    """

    q: list
    qd: list
    qdd: list
    R: dict = field(default_factory=dict)
    o: dict = field(default_factory=dict)
    w: dict = field(default_factory=dict)
    dw: dict = field(default_factory=dict)
    a: dict = field(default_factory=dict)
    cs: dict = field(default_factory=dict)
    rhs: dict = field(default_factory=dict)
    sol: dict = field(default_factory=dict)
    sv: list = field(default_factory=list)     # s_v of each lossy mesh (:mod:`.losses`)
    bearing: dict = field(default_factory=dict)   # joint: s_J Mb_J, its converged bearing friction (:mod:`.bearings`)
    frames: dict = field(default_factory=dict)
    qdi: list = field(default_factory=list)    # (dof,) the independent joint rates (mesh rates: :mod:`.friction_terms`)
    red: list = field(default_factory=list)    # per lossy reducer (s_a, A, B, z_I world) (:func:`.friction_terms.reducer_terms`)
    worm_sv: list = field(default_factory=list)   # per lossy worm pair, the sign of the worm's rate


def floats(row) -> tuple:
    """A row of program constants as Python floats (folded by :class:`~.build.Emitter`)."""
    return tuple(float(v) for v in row)


def joint_space(e: Emitter, S, qi: list, qdi: list, qddi: list) -> Sample:
    """The sample's q, qd, qdd of every real joint = S times the independent ones
    (``qi, qdi, qddi``: the loaded independent values)."""
    rows = [floats(S[j]) for j in range(S.shape[0])]
    return Sample([e.dot(qi, s) for s in rows], [e.dot(qdi, s) for s in rows], [e.dot(qddi, s) for s in rows],
                  qdi=list(qdi))


def at_rest(s: Sample, base: int) -> None:
    """The base link: identity axes, origin, velocities and accelerations zero (constants)."""
    s.R[base], s.o[base], s.w[base], s.dw[base], s.a[base] = EYE, ZERO3, ZERO3, ZERO3, ZERO3


def joint(e: Emitter, s: Sample, rec, pose) -> None:
    """The child link of one joint (``rec`` its :data:`.records.JOINT`, ``pose`` its
    :data:`.records.POSE`): its R, o, w, dw, a, and the joint's cos, sin (the terms of
    :func:`..kinematics.joint_frame` and :func:`..kinematics.child_motion`)."""
    ji, p, c, pr = int(rec.joint), int(rec.parent), int(rec.child), int(rec.prismatic) == 1
    if ji not in s.frames:
        s.frames[ji] = joint_frame(e, floats(pose.R_pj), floats(pose.p_pj), s.R[p], s.o[p], s.q[ji], pr)
    Rj, oj, cq, sq = s.frames[ji]
    s.cs[ji] = (cq, sq)
    s.R[c], s.o[c], s.w[c], s.dw[c], s.a[c] = child_motion(e, Rj, oj, floats(pose.R_jc), floats(pose.p_jc), s.o[p],
                                                           s.w[p], s.dw[p], s.a[p], s.qd[ji], s.qdd[ji], pr)


def inertia(e: Emitter, s: Sample, L: int, body, g) -> None:
    """rhs[L] = the d'Alembert wrench of link L (``body`` its :data:`.records.BODY`, or a
    (mass, inertia (9,), com (3,)) of values read at run time: a data kernel) about o_L, base
    frame (Eqs. 17-18, :func:`..inertia.inertia_wrench`)."""
    if isinstance(body, tuple):
        m, I, com = body
    else:
        m, I, com = float(body.mass), floats(body.inertia), floats(body.com)
    s.rhs[L] = inertia_wrench(e, m, I, com, s.R[L], s.w[L], s.dw[L], s.a[L], floats(g))


def load_groups(loads) -> tuple[list, list]:
    """(order, groups) of the external loads ``loads`` (per load its link first): ``order``
    the load indices grouped by link (first appearance), ``groups`` per loaded link
    (link, first, end) in that order.  The kernel's code holds one loop per loaded link;
    the loads themselves (points, frames, values) are run-time arrays, so the code does not
    grow with their number (1,000 constant loads compiled in minutes when they were
    straight-line constants; the loop bounds are run-time data too: one code, and one disk
    cache entry, for any number of loads on the same links)."""
    by_link: dict = {}
    for k, ld in enumerate(loads):
        by_link.setdefault(int(ld[0]), []).append(k)
    order, groups = [], []
    for L, ks in by_link.items():
        groups.append((L, len(order), len(order) + len(ks)))
        order += ks
    return order, groups


def external(e: Emitter, s: Sample, fn, links, n, vals, ldrow, ldpt, ldgrp) -> None:
    """rhs[L] -= the sum of the external loads on L at sample n (:func:`..external.external_wrenches`).

    ``links``: the loaded links in the order of :func:`load_groups`, ``ldgrp`` per loaded
    link [first, end] of its loads; per load k (in that order) ``ldrow`` [first row of its values in ``vals`` (rows of 6), 1 if one row a
    sample, 1 if in link axes] and ``ldpt`` its point (link frame): given at run time.
    Each load: W = [f ; m + (R_L p) x f] (f, m turned to base axes by R_L when in link
    axes), summed in load order, then subtracted, as the numpy path does."""
    one = ir.Constant(I64, 1)
    for g, L in enumerate(links):
        k0, k1 = e.load(ldgrp, 2 * g), e.load(ldgrp, 2 * g + 1)
        pre = e.b.block
        loop, done = fn.append_basic_block(f"load{L}"), fn.append_basic_block(f"load{L}_done")
        e.b.branch(loop)
        e.b.position_at_end(loop)
        k = e.b.phi(I64)
        acc = [e.b.phi(D) for _ in range(6)]
        rec = e.b.mul(k, ir.Constant(I64, 3))
        per = e.load(ldrow, e.b.add(rec, one))
        in_link = e.b.icmp_signed("!=", e.load(ldrow, e.b.add(rec, ir.Constant(I64, 2))), ir.Constant(I64, 0))
        row = e.b.add(e.load(ldrow, rec), e.b.mul(n, per))
        base = e.b.mul(row, ir.Constant(I64, 6))
        v = [e.load(vals, e.b.add(base, ir.Constant(I64, i))) for i in range(6)]
        f, m = tuple(v[:3]), tuple(v[3:])
        f = tuple(e.b.select(in_link, e.const(a), b) for a, b in zip(e.mv(s.R[L], f), f))
        m = tuple(e.b.select(in_link, e.const(a), b) for a, b in zip(e.mv(s.R[L], m), m))
        point = tuple(e.load(ldpt, e.b.add(rec, ir.Constant(I64, i))) for i in range(3))
        new = [e.const(e.add(a, w)) for a, w in zip(acc, load_wrench(e, f, m, e.mv(s.R[L], point)))]
        k_next = e.b.add(k, one)
        e.b.cbranch(e.b.icmp_signed("<", k_next, k1), loop, done)
        k.add_incoming(k0, pre)
        k.add_incoming(k_next, loop)
        for ph, nv in zip(acc, new):
            ph.add_incoming(ir.Constant(D, 0.0), pre)
            ph.add_incoming(nv, loop)
        e.b.position_at_end(done)
        s.rhs[L] = tuple(e.sub(s.rhs[L][i], new[i]) for i in range(6))
