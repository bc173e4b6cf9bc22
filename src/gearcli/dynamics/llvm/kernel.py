"""The per-mechanism kernel generated as LLVM IR (backend "llvm").

:func:`build_module` writes, from a :class:`~.program.Program`, one function

    run(qi, qdi, qddi, vals, ldpt, ldrow, ldgrp, motor, tau, joint, gear_t, gear_sep, gear_radial,
        gear_axial, motor_speed, signs, gear_loss, joint_friction, joint_loss, moments, fail, start, stop)

whose loop over the samples start..stop-1 does what the numpy path does for all of them,
with every structural integer and every constant of the program (fixed transforms,
masses, inertias, inverse block matrices, propagation columns, output coefficients) in
the code: joint space, kinematics, inertia and external loads (:mod:`.links`), the
blocks in schedule order (:mod:`.blocks`, :mod:`.signs`) and the outputs
(:mod:`.outputs`), straight-line except for the sign search; a lossy mechanism's losses
(:mod:`.losses`, :class:`~.loss_program.LossProgram`): the joints' own friction from their
rates, the mesh friction, the loss outputs ``gear_loss`` (N, G), ``joint_friction`` and
``joint_loss`` (N, J); with bearing friction, the converged bearing friction moments and
each block's iterations of :mod:`.bearings` in ``moments``).  Only the inputs (the
independent q, qd, qdd (N, dof), C-ordered), the external loads (their values, points
``ldpt``, records ``ldrow`` and per loaded link the range ``ldgrp``, :func:`.links.external`: one loop per loaded link,
whatever the number of loads) and the output arrays
(C-ordered rows of :func:`.outputs.widths`; ``fail`` (N,) int64, which ``run`` sets
to -1 or the sample's first failing block) are pointers.  ``run`` returns how many of its
samples failed (the caller checks a sum, not ``fail``).  Compiled by :mod:`.driver`.
"""
from __future__ import annotations

import llvmlite.ir as ir
import numpy as np

from . import friction_terms
from ..signs import MAX_EXHAUSTIVE
from .blocks import block
from .signs import WARM
from .build import DP, I64, I64P, ConstantPool, Emitter
from .links import at_rest, external, floats, inertia, joint, joint_space, load_groups
from .program import BODY_WIDTH
from .outputs import OUTPUTS, widths, write_outputs

LOSS_OUTPUTS = ("gear_loss", "joint_friction", "joint_loss")
ARGS = ("qi", "qdi", "qddi", "vals", "ldpt", "ldrow", "ldgrp", "bodies") + OUTPUTS + ("signs",) + LOSS_OUTPUTS + (
    "moments", "fail", "start", "stop")


def signature(mod: ir.Module, name: str, types: list, names: tuple) -> ir.Function:
    """Function ``name`` of ``mod`` returning i64, its arguments named (pointers noalias)."""
    fn = ir.Function(mod, ir.FunctionType(I64, types), name)
    for arg, arg_name in zip(fn.args, names):
        arg.name = arg_name
        if isinstance(arg.type, ir.PointerType):
            arg.add_attribute("noalias")
    return fn


def _carries(rec) -> bool:
    """A block whose search starts from the pattern of the sample before: it has signed
    meshes and searches every pattern after its own-sign trials (m <= MAX_EXHAUSTIVE), so it
    accepts a pattern exactly where the numpy path does, whatever it tries first."""
    return 0 < int(rec.m) <= MAX_EXHAUSTIVE


def _body(e: Emitter, bodies, L: int) -> tuple:
    """(mass, inertia (9,), com (3,)) of link L read from a data kernel's ``bodies`` argument
    (:func:`.program.body_rows`)."""
    v = [e.load(bodies, BODY_WIDTH * L + i) for i in range(BODY_WIDTH)]
    return v[0], tuple(v[1:10]), tuple(v[10:13])


def _sample(e: Emitter, fn, prog, loads, n, before: list) -> list:
    """The code of sample n (the loop body); returns the sign pattern each :func:`_carries`
    block settled on, which the next sample's search tries first (``before``: those of the sample
    before; :mod:`.signs`), but for the first sample of a run of WARM (the threads' ranges
    are cut at multiples of WARM: no result depends on the threads)."""
    a = dict(zip(ARGS, fn.args))
    S = prog.S
    dof = S.shape[1]
    e.b.store(ir.Constant(I64, -1), e.b.gep(a["fail"], [n]))
    ind = [[e.load(e.row(a[k], n, dof), d) for d in range(dof)] for k in ("qi", "qdi", "qddi")]
    s = joint_space(e, S, *ind)
    at_rest(s, prog.base)
    for rec, pose in zip(prog.joints, prog.poses):
        joint(e, s, rec, pose)
    for L in prog.moving:
        inertia(e, s, int(L), _body(e, a["bodies"], int(L)) if prog.data_bodies else prog.bodies[L], prog.gravity)
    external(e, s, fn, [L for L, _, _ in load_groups(loads)[1]], n, a["vals"], a["ldrow"], a["ldpt"], a["ldgrp"])
    belt_pretension(e, s, prog)
    lp, w = prog.losses, widths(prog)
    if lp is not None:
        rows = {k: e.row(a[k], n, max(w[k], 1)) for k in LOSS_OUTPUTS}
        rates, s.sv = friction_terms.mesh_rates(e, s, lp)
        if lp.reducers is not None:
            s.red = friction_terms.reducer_terms(e, s, lp.reducers)
        if lp.worms is not None:
            s.worm_sv = friction_terms.worm_signs(e, s, lp.worms)
        own = friction_terms.joint_friction(e, s, lp, rows)
    signs = e.row(a["signs"], n, max(w["signs"], 1))
    fresh = e.b.icmp_signed("==", e.b.srem(n, ir.Constant(I64, WARM)), ir.Constant(I64, 0))
    before, settled = iter(before), []
    for b in range(len(prog.blocks)):
        first = e.b.select(fresh, ir.Constant(I64, 0), next(before)) if _carries(prog.blocks[b]) else None
        p = block(e, fn, s, prog, b, n, a["fail"], signs, first=first)
        settled += [p] if first is not None else []
    inputs = {}
    if lp is not None:
        inputs = friction_terms.write_losses(e, s, lp, prog.gear_col, rates, own, rows)
    write_outputs(e, s, prog, ind[1], {k: e.row(a[k], n, max(w[k], 1)) for k in OUTPUTS}, inputs)
    return settled


def belt_pretension(e: Emitter, s, prog) -> None:
    """rhs[L] -= each belt's pretension forces (:func:`..losses.subtract_belt_pretension`): on
    pulley j T_i e_S at X_jS, on k the opposites at X_kS, the points and directions in the
    carrier's axes."""
    for ints, f in zip(prog.belt_int, prog.belt_flt):
        j, k, c = (int(v) for v in ints)
        T, X, es = float(f[0]), np.asarray(f[1:13]).reshape(2, 2, 3), np.asarray(f[13:19]).reshape(2, 3)
        for side, L, sign in ((0, j, 1.0), (1, k, -1.0)):
            if L < 0:
                continue
            for sp in (0, 1):
                d = e.mv(s.R[c], floats(es[sp]))
                P = e.vadd(s.o[c], e.mv(s.R[c], floats(X[sp, side])))
                w = e.scale(d, sign * T) + e.scale(e.cx(e.vsub(P, s.o[L]), d), sign * T)
                s.rhs[L] = tuple(e.sub(s.rhs[L][h], w[h]) for h in range(6))


def build_module(prog, loads) -> ir.Module:
    """The IR module of ``prog``'s kernel (``loads``: per external load of the mechanism,
    its link id first (:func:`.driver.mech_loads`); only their links shape the code))."""
    mod = ir.Module(name="gearcli_kernel")
    types = [DP] * 5 + [I64P] * 2 + [DP] + [DP] * (len(OUTPUTS) + len(LOSS_OUTPUTS) + 2) + [I64P, I64, I64]
    fn = signature(mod, "run", types, ARGS)
    fail = fn.args[ARGS.index("fail")]

    def body(e: Emitter, n, before):
        settled = _sample(e, fn, prog, loads, n, before)
        return e.b.icmp_signed(">=", e.b.load(e.b.gep(fail, [n])), ir.Constant(I64, 0)), settled
    sample_loop(fn, body, carry=sum(1 for rec in prog.blocks if _carries(rec)))
    return mod


def sample_loop(fn: ir.Function, body, carry: int | None = None) -> None:
    """The body of ``fn``: a loop over the samples start..stop-1 (its last two arguments)
    emitting ``body(emitter, n)`` (which returns an i1: the sample failed); ``fn`` returns
    how many samples failed.  With ``carry`` (a count), ``body(emitter, n, before)`` returns
    (that i1, ``carry`` i64 values), which the next sample's body reads in ``before`` (0 for
    the first sample of the call)."""
    entry, loop, done = fn.append_basic_block("entry"), fn.append_basic_block("sample"), fn.append_basic_block("done")
    b = ir.IRBuilder(entry)
    start, stop = fn.args[-2], fn.args[-1]
    b.cbranch(b.icmp_signed("<", start, stop), loop, done)
    b.position_at_end(loop)
    n, bad = b.phi(I64, "n"), b.phi(I64, "bad")
    n.add_incoming(start, entry)
    bad.add_incoming(ir.Constant(I64, 0), entry)
    before = [b.phi(I64) for _ in range(carry or 0)]
    pool = ConstantPool(fn, b)
    e = Emitter(b, fn.module, pool)
    failed, after = body(e, n, before) if carry is not None else (body(e, n), ())
    pool.finish()
    n1, bad1 = b.add(n, ir.Constant(I64, 1)), b.add(bad, b.zext(failed, I64))
    latch = b.block
    n.add_incoming(n1, latch)
    bad.add_incoming(bad1, latch)
    for ph, v in zip(before, after):
        ph.add_incoming(ir.Constant(I64, 0), entry)
        ph.add_incoming(v, latch)
    b.cbranch(b.icmp_signed("<", n1, stop), loop, done)
    b.position_at_end(done)
    total = b.phi(I64, "failed")
    total.add_incoming(ir.Constant(I64, 0), entry)
    total.add_incoming(bad1, latch)
    b.ret(total)
