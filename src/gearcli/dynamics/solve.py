"""Inverse dynamics of a geared mechanism along a trajectory (paper, "Dynamic Analysis").

:func:`solve` takes the independent joint angles (the equivalent open-loop chain), their
rates and accelerations, arrays shaped (N, dof), and returns a :class:`Result` with the
motor torques, the reaction wrench of every real joint and the contact force of every gear
mesh at every sample.

Method ``"block"`` (default) solves the Newton-Euler equations block by block in the
schedule of :mod:`gearcli.schedule` (highest level first, one link or a few coupled levels
at a time).  Method ``"full"`` assembles all 6 x (moving links) equations and solves them
simultaneously; it exists to cross-check the schedule.  Both are exact: the |t| of the
separating tooth force (Eq. 14) makes the equations piecewise linear, and each sample is
solved with the sign pattern of the tangential forces that is consistent with its solution.
"""
from __future__ import annotations

import itertools
from dataclasses import dataclass, field

import numpy as np

from .kinematics import forward
from .blocks import solve_blocks
from .loads import Columns, inertia_load
from ..analysis.schedule import unknown_groups

DEFAULT_CHUNK = 20_000


@dataclass
class Result:
    """Loads along a trajectory; every array has the samples first.

    ``motor`` (N, M): torque (N*m; N for a prismatic input) each motor applies to its input
    link about that link's positive joint axis.
    ``tau`` (N, dof): equivalent torques on the independent joints (paper Eq. 25),
    tau = A @ motor with A the structure matrix.
    ``joint`` (N, J, 6): reaction wrench [fx, fy, fz, mx, my, mz] the parent exerts on the
    child, in the joint frame (z along the axis, x fixed in the child), about the joint
    frame origin; N and N*m.  mz of a revolute joint (fz of a prismatic one) is zero: the
    motor torque is reported in ``motor``.
    ``gear_t`` (N, G): tangential tooth force on gear j by gear k, N, positive when it turns
    j in j's positive sense (for an ideal coupling: the mesh torque on j, N*m).
    ``gear_sep`` (N, G): separating force magnitude |t| tan(phi), N.
    ``motor_speed`` (N, M): speed of each motor's input rotation, A^T qd (rad/s; m/s for a
    prismatic input).
    ``gear_radial``, ``gear_axial`` (N, G, 2): components of the tooth force on gear j and on
    gear k along each gear's own outward radial direction (towards the pitch point) and its
    positive axis, N.
    """

    motor: np.ndarray
    tau: np.ndarray
    joint: np.ndarray
    gear_t: np.ndarray
    gear_sep: np.ndarray
    gear_radial: np.ndarray
    gear_axial: np.ndarray
    residual: float | None = None
    meta: dict = field(default_factory=dict)
    motor_speed: np.ndarray | None = None   # (N, M) motor speeds A^T qd, rad/s (m/s linear)


def joint_space(an, q_ind, qd_ind=None, qdd_ind=None):
    """Every real joint's angle, rate, acceleration (N, J) from the independent ones."""
    S = an.S
    q = np.asarray(q_ind, float) @ S.T
    qd = None if qd_ind is None else np.asarray(qd_ind, float) @ S.T
    qdd = None if qdd_ind is None else np.asarray(qdd_ind, float) @ S.T
    return q, qd, qdd


def _check_shapes(an, *arrays):
    out = []
    for name, x in zip(("q", "qd", "qdd"), arrays):
        x = np.asarray(x, float)
        if x.ndim == 1:
            x = x[None, :]
        if x.ndim != 2 or x.shape[1] != an.dof:
            raise ValueError(f"expected {name} with shape (N, {an.dof}), got {np.shape(x)}")
        out.append(x)
    if len({x.shape[0] for x in out}) != 1:
        raise ValueError(f"q, qd, qdd must have the same number of samples, got {[x.shape[0] for x in out]}")
    return out


def solve(an, q, qd, qdd, method: str = "block", chunk: int = DEFAULT_CHUNK, verify: bool = False,
          progress=None) -> Result:
    """Inverse dynamics along a trajectory.

    Parameters
    ----------
    an : Analysis
        From :func:`gearcli.graph.analyse`.
    q, qd, qdd : array_like, shape (N, dof) or (dof,)
        Independent joint angles (rad), rates (rad/s) and accelerations (rad/s^2), in the
        order of ``an.independent_names``.
    method : {"block", "full"}
        Block schedule (default) or one simultaneous solve of all equations.
    chunk : int
        Samples processed at once (bounds memory).
    verify : bool
        Also compute the worst Newton-Euler residual of any link (``Result.residual``,
        relative to the largest load of the sample).
    progress : callable(int), optional
        Called with the number of samples done after each chunk.
    """
    q, qd, qdd = _check_shapes(an, q, qd, qdd)
    if method not in ("block", "full"):
        raise ValueError(f"unknown method '{method}' (expected 'block' or 'full')")
    parts = []
    worst = 0.0
    for s in range(0, q.shape[0], chunk):
        sl = slice(s, s + chunk)
        r = _solve_chunk(an, q[sl], qd[sl], qdd[sl], method, verify)
        parts.append(r)
        if verify:
            worst = max(worst, r.residual)
        if progress is not None:
            progress(min(chunk, q.shape[0] - s))
    if len(parts) == 1:
        res = parts[0]
    else:
        res = Result(*(np.concatenate([getattr(p, f) for p in parts]) for f in
                       ("motor", "tau", "joint", "gear_t", "gear_sep", "gear_radial", "gear_axial")))
    res.residual = worst if verify else None
    res.motor_speed = qd @ an.A
    return res


def _solve_chunk(an, q_ind, qd_ind, qdd_ind, method, verify) -> Result:
    q, qd, qdd = joint_space(an, q_ind, qd_ind, qdd_ind)
    kin = forward(an.mech, an.tree, q, qd, qdd)
    b = inertia_load(an, kin)
    cols = Columns(an, kin) if (method == "full" or verify) else _LazyColumns(an, kin)
    groups = unknown_groups(an)
    if method == "block":
        def general(gs, links, rhs):
            return _solve_signed(an, gs, cols, links, rhs)
        x, sig = solve_blocks(an, kin, b, q, general)
    else:
        x, sig = _full_solve(an, groups, cols, b)
    res = _result(an, groups, x)
    if verify:
        res.residual = residual(an, groups, cols, b, x, sig)
    return res


class _LazyColumns:
    """Columns built on first use (the fast block path rarely needs them)."""

    def __init__(self, an, kin):
        self.an, self.kin, self._c = an, kin, None

    def __getattr__(self, name):
        if self._c is None:
            self._c = Columns(self.an, self.kin)
        return getattr(self._c, name)


def _key(g):
    return (g.kind, g.index)


def _is_signed(an, g) -> bool:
    return g.kind == "mesh" and an.circuits[g.index].geometry is not None


def _assemble(an, groups, cols, links, sig):
    """Matrix (N, 6*len(links), n) of ``groups`` on ``links``; sig[key] gives mesh signs."""
    N = cols.kin.n
    pos = {L: i for i, L in enumerate(links)}
    n = sum(g.size for g in groups)
    A = np.zeros((N, 6 * len(links), n))
    c0 = 0
    for g in groups:
        for L in g.links:
            if L in pos:
                r0 = 6 * pos[L]
                A[:, r0:r0 + 6, c0:c0 + g.size] = cols.group(g, L, sig.get(_key(g), 1.0))
        c0 += g.size
    return A


def _solve_signed(an, groups, cols, links, rhs):
    """Solve A(sigma) x = rhs over ``links`` exactly: for each sample, a sign pattern of the
    tangential tooth forces that agrees with the solution.  Returns x (N, n) and signs."""
    N = rhs.shape[0]
    signed = [i for i, g in enumerate(groups) if _is_signed(an, g)]
    offs = np.cumsum([0] + [g.size for g in groups])
    n = offs[-1]
    x = np.zeros((N, n))
    sig = {_key(groups[i]): np.ones(N) for i in signed}
    todo = np.arange(N)
    patterns = list(itertools.product((1.0, -1.0), repeat=len(signed)))
    scale = 1.0 + np.max(np.abs(rhs), axis=1)
    best_err = np.full(N, np.inf)
    for pat in patterns:
        if todo.size == 0:
            break
        s = {_key(groups[i]): np.full(todo.size, p) for i, p in zip(signed, pat)}
        sub = _SubCols(cols, todo)
        A = _assemble(an, groups, sub, links, s)
        xs = np.linalg.solve(A, rhs[todo][:, :, None])[:, :, 0]
        viol = np.zeros(todo.size)
        for i, p in zip(signed, pat):
            viol = np.maximum(viol, -p * xs[:, offs[i]])
        better = viol < best_err[todo]
        idx = todo[better]
        x[idx] = xs[better]
        best_err[idx] = viol[better]
        for i, p in zip(signed, pat):
            sig[_key(groups[i])][idx] = p
        ok = viol <= 1e-12 * scale[todo]
        todo = todo[~ok]
    return x, sig


class _SubCols:
    """Columns restricted to a subset of samples."""

    def __init__(self, cols: Columns, idx):
        self.cols, self.idx = cols, idx
        self.kin = _SubKin(cols.kin, idx)

    def group(self, g, L, sigma=1.0):
        if g.kind == "mesh":
            c = self.cols.an.circuits[g.index]
            if c.geometry is not None:
                full = np.ones(self.cols.kin.n)
                full[self.idx] = sigma
                return self.cols.mesh(g.index, L, full)[self.idx]
        return self.cols.group(g, L, sigma)[self.idx]


class _SubKin:
    def __init__(self, kin, idx):
        self.n = len(idx)


def _full_solve(an, groups, cols, b):
    links = list(an.tree.moving)
    R = np.concatenate([b[L] for L in links], axis=1)
    N = R.shape[0]
    offs = np.cumsum([0] + [g.size for g in groups])
    signed = [i for i, g in enumerate(groups) if _is_signed(an, g)]
    sig = {_key(groups[i]): np.ones(N) for i in signed}
    x = np.zeros((N, offs[-1]))
    todo = np.arange(N)
    for _ in range(len(signed) + 2):
        sub = _SubCols(cols, todo)
        A = _assemble(an, groups, sub, links, {k: v[todo] for k, v in sig.items()})
        x[todo] = np.linalg.solve(A, R[todo][:, :, None])[:, :, 0]
        changed = np.zeros(todo.size, bool)
        for i in signed:
            k = _key(groups[i])
            new = np.where(x[todo, offs[i]] < 0, -1.0, 1.0)
            changed |= new != sig[k][todo]
            sig[k][todo] = new
        todo = todo[changed]
        if todo.size == 0:
            break
    x_all = {_key(g): x[:, offs[i]:offs[i + 1]] for i, g in enumerate(groups)}
    return x_all, sig


def residual(an, groups, cols, b, x_all, sig) -> float:
    """Worst relative Newton-Euler residual over links and samples."""
    worst = 0.0
    for L in an.tree.moving:
        tot = -b[L]
        for g in groups:
            if L in g.links:
                C = cols.group(g, L, sig.get(_key(g), 1.0))
                tot = tot + np.einsum("nij,nj->ni", C, x_all[_key(g)])
        scale = 1.0 + np.max(np.abs(b[L]), axis=1)
        worst = max(worst, float(np.max(np.abs(tot).max(axis=1) / scale)))
    return worst


def _result(an, groups, x_all) -> Result:
    mech = an.mech
    N = next(iter(x_all.values())).shape[0]
    J, G, M = len(mech.joints), len(an.circuits), len(an.motor_links)
    joint = np.zeros((N, J, 6))
    for ji, jt in enumerate(mech.joints):
        xj = x_all[("joint", ji)]
        if jt.type == "prismatic":
            joint[:, ji, [0, 1, 3, 4, 5]] = xj
        else:
            joint[:, ji, :5] = xj
    motor = np.column_stack([x_all[("motor", i)][:, 0] for i in range(M)]) if M else np.zeros((N, 0))
    gt = np.zeros((N, G))
    sep = np.zeros((N, G))
    rad = np.zeros((N, G, 2))
    ax = np.zeros((N, G, 2))
    for ci, c in enumerate(an.circuits):
        t = x_all[("mesh", ci)][:, 0]
        gt[:, ci] = t
        if c.geometry is None:
            continue
        gm = c.geometry
        s = np.abs(t) * np.tan(mech.gears[c.gear].pressure_angle)
        sep[:, ci] = s
        # g = t ut + s us (on j); -g on k; ut is perpendicular to both radial directions
        rad[:, ci, 0] = s * (gm.us @ gm.rad_j)
        ax[:, ci, 0] = t * (gm.ut @ gm.zj) + s * (gm.us @ gm.zj)
        rad[:, ci, 1] = -(t * (gm.ut @ gm.rad_k) + s * (gm.us @ gm.rad_k))
        ax[:, ci, 1] = -(t * (gm.ut @ gm.zk) + s * (gm.us @ gm.zk))
    tau = motor @ an.A.T
    return Result(motor, tau, joint, gt, sep, rad, ax)
