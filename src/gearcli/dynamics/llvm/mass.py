"""The mass-matrix kernel mode (backend "llvm"): M(q) and h(q, qd) of every sample.

:func:`build_module` writes, from the same :class:`~.program.Program` as :mod:`.kernel`,

    mass(qi, qdi, rhs, vals, ldpt, ldrow, ldgrp, M, h, qdd, start, stop)

whose loop does per sample what :mod:`..forward`'s stacked solve does with dof + 1
inverse-dynamics samples, writing only the torques tau = A motor: the h pass (q, qd loaded,
qdd = 0, gravity and the external loads: h = tau(q, qd, 0)), then per independent joint i
a column pass with qd = 0, qdd = e_i, no gravity and no loads: M e_i = tau(q, 0, e_i)
(tau is linear in qdd).  The passes share the pose: each joint's frame (its cos, sin,
rotation; :attr:`.links.Sample.frames`) is emitted once and LLVM's CSE merges the pose
arithmetic the passes repeat (the links' axes, origins and arms); the column passes'
constant zero rates and unit accelerations fold their velocity terms away.  No pass has a
sign search: every signed block takes sign pattern 0 (all t positive).  Lossless, the
separating forces |t| tan(phi) act at the pitch point, where the meshing teeth have no
relative velocity: they do no work and tau does not depend on the pattern they are solved
with (the numpy reference, which takes the consistent pattern, agrees to rounding).
No losses: M is the lossless inertia of paper Eq. 25.

M is written symmetric, M[d, i] = M[i, d] = column min(d, i)'s torque on joint max(d, i)
(LLVM then drops the work that only fed the other half, a column pass's blocks before its
own joint in a chain ordered root first: Panda 11,000 machine instructions instead of
13,400), (N, dof, dof), h (N, dof), and the accelerations
qdd = M^-1 (rhs - h) (N, dof) (``rhs`` (N, dof), forward dynamics' A T; Gaussian
elimination with partial pivoting, :func:`.world.eliminate`).  ``mass`` returns how many
samples have an output that is not finite (a singular matrix gives NaN).
"""
from __future__ import annotations

import hashlib

import llvmlite.ir as ir
import numpy as np

from .blocks import block
from .build import D, DP, I64, I64P, Emitter
from .driver import LlvmKernel, _program_ids, address
from .jobs import job_ranges, run_parts, threads_for
from .kernel import sample_loop, signature
from .links import Sample, at_rest, external, floats, inertia, joint, joint_space, load_groups
from .world import eliminate

ARGS = ("qi", "qdi", "rhs", "vals", "ldpt", "ldrow", "ldgrp", "M", "h", "qdd", "start", "stop")


def _tau(e: Emitter, fn, prog, s: Sample, gravity, loads=None) -> list:
    """tau = A motor (dof values) of one pass: kinematics, inertia (``loads(s)`` subtracts
    the external loads), the blocks with sign pattern 0."""
    at_rest(s, prog.base)
    for rec, pose in zip(prog.joints, prog.poses):
        joint(e, s, rec, pose)
    for L in prog.moving:
        inertia(e, s, int(L), prog.bodies[L], gravity)
    if loads is not None:
        loads(s)
    for b in range(len(prog.blocks)):
        block(e, fn, s, prog, b, None, None, None, search=False)
    motor = [s.sol[int(c)] for c in prog.motor_col]
    return [e.dot(floats(row), motor) for row in prog.A]


def _sample(e: Emitter, fn, prog, loads, n):
    """The code of sample n; returns an i1: an output is not finite."""
    a = dict(zip(ARGS, fn.args))
    S = prog.S
    J, dof = S.shape
    qi, qdi = ([e.load(e.row(a[k], n, dof), d) for d in range(dof)] for k in ("qi", "qdi"))
    s = joint_space(e, S, qi, qdi, [0.0] * dof)
    loaded = [L for L, _, _ in load_groups(loads)[1]]
    h = _tau(e, fn, prog, s, prog.gravity,
             lambda s: external(e, s, fn, loaded, n, a["vals"], a["ldrow"], a["ldpt"], a["ldgrp"]))
    cols = [_tau(e, fn, prog, Sample(s.q, [0.0] * J, list(floats(S[:, i])), frames=s.frames), (0.0, 0.0, 0.0))
            for i in range(dof)]
    M = [[cols[min(d, i)][max(d, i)] for i in range(dof)] for d in range(dof)]   # the later joint's torque
    rhs = e.row(a["rhs"], n, dof)
    qdd = eliminate(e, M, [e.sub(e.load(rhs, d), h[d]) for d in range(dof)])
    check = 0.0
    for name, values in (("h", h), ("qdd", qdd), ("M", [v for row in M for v in row])):
        row = e.row(a[name], n, len(values))
        for k, v in enumerate(values):
            e.store(v, row, k)
            check = e.add(check, v)
    return e.b.fcmp_unordered("uno", e.sub(check, check), ir.Constant(D, 0.0))   # NaN or an infinity


def build_module(prog, loads) -> ir.Module:
    """The IR module of ``prog``'s mass kernel (``loads`` as :func:`.kernel.build_module`'s)."""
    mod = ir.Module(name="gearcli_mass")
    fn = signature(mod, "mass", [DP] * 5 + [I64P] * 2 + [DP] * 3 + [I64] * 2, ARGS)
    sample_loop(fn, lambda e, n: _sample(e, fn, prog, loads, n))
    return mod


def _derived(key: str) -> str:
    return hashlib.sha256(f"mass|{key}".encode()).hexdigest()


class MassKernel(LlvmKernel):
    """The compiled mass kernel of one mechanism (compiled and cached on disk as the
    solve kernel is, :class:`.driver.LlvmKernel`; its own entries)."""

    ENTRY, POINTERS, INTS = "mass", 10, 2

    @staticmethod
    def build(prog, loads):
        if prog.data_bodies:        # its masses are constants: a data program's are NaN
            raise ValueError("the mass kernel is built from a program with constant bodies")
        return build_module(prog, loads)

    @staticmethod
    def ids(prog, an) -> tuple[str, str]:
        """(fingerprint, program key): the solve kernel's, derived (another function)."""
        return tuple(_derived(k) for k in _program_ids(prog, an))

    def run(self, an, q, qd, values: dict, rhs, jobs: int | None):
        """(M (N, dof, dof), h (N, dof), qdd (N, dof)) of the samples (q, qd, rhs (N, dof),
        ``values`` the external loads of :func:`..external.load_values`); None when a sample
        has an output that is not finite."""
        n, dof = q.shape
        out = M, h, qdd = np.empty((n, dof, dof)), np.empty((n, dof)), np.empty((n, dof))
        keep = [np.ascontiguousarray(v, float) for v in (q, qd, rhs)] + self.load_args(an, values, n) + list(out)
        ptrs = [address(v) for v in keep]
        bad = run_parts(lambda s, e: self._run(*ptrs, s, e), job_ranges(n, jobs), threads_for(n, jobs))
        return None if bad else out
