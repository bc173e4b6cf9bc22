"""Bearing friction: a load-dependent moment, converged per sample by fixed-point iteration.

The simplified model of the bearing catalogues: bearing b of joint J resists the joint's
relative rotation with

    M_b = 1/2 mu_b d_b P_b,        on the child  -sign(q'_J) sum_b M_b  about the axis,

reversed on the parent, P_b the magnitude of the bearing's load vector (radial and axial
together), from gearcli's per-bearing split of the joint reaction: one bearing takes the
whole reaction force, P = |f|; two share the force and the tilting moment as a shaft on two
supports (:mod:`gearcli.model.shaft`, positions along the axis from
the joint origin), the locating one taking the axial force.  Revolute joints only.

The moments depend on the reactions they change, so the balance equations become
nonlinear.  :func:`solve_with_bearing_friction` iterates: solve with the moments of the
previous reactions (zero at first), recompute the moments from the new reactions, until
a sample's moments change by at most ``TOL`` relative (then kept; a contraction: one iteration
multiplies the error by about mu d / (2 lever), ~1e-3).  A sample that does not converge in
``MAX_ITERATIONS``, or whose moments grow past the largest float (friction that locks the
mechanism), is an error naming it, never a silent approximation or an infinite moment.
"""
from __future__ import annotations

import numpy as np

from ..algebra import ARRAYS
from ..model.shaft import split_components
from ..errors import GearcliError
from .wrenches import joint_axis_wrench

TOL = 1e-12
MAX_ITERATIONS = 500
"""The most iterations (numpy's fixed point) or Newton levels (the kernel, :mod:`.llvm.
bearing_newton`) a sample may take.  The fixed point contracts by Lambda an iteration (the
friction moment's rate per unit of itself through the loads it changes) and so needs ~log(1e-12)
/ log(Lambda) of them: 500 reach the tolerance up to Lambda ~0.945 (50 did up to 0.57, where
Newton's levels converge in two or three: both paths then gave different answers, one an
error); at Lambda >= 1 the friction locks the mechanism and no path converges."""


class BearingFrictionError(GearcliError):
    """The bearing friction moments of a sample did not converge."""

    def __init__(self, sample: int, joint: str):
        super().__init__()
        self.sample, self.joint = sample, joint

    def lines(self) -> list[str]:
        return [f"sample {self.sample}: the bearing friction moments of joint '{self.joint}' did not converge "
                f"(relative tolerance {TOL:g}, at most {MAX_ITERATIONS} iterations: they still changed, or grew "
                "past the largest float); the friction is too large for the loads it changes"]


def friction_joints(mech) -> list[int]:
    """Indices of the joints with bearing friction."""
    return [ji for ji, jt in enumerate(mech.joints) if any(b.friction_arm for b in jt.bearings or ())]


def bearing_loads(mech, joints: list[int], x_all: dict) -> tuple[np.ndarray, np.ndarray]:
    """(P_1, P_2) (K, N): the load magnitudes of the first and second bearing of each joint
    ``joints[k]`` (revolute) from its reaction x_all[("joint", ji)] (N, 5): [fx, fy, fz, mx,
    my] the parent exerts on the child, joint frame, about its origin.  One bearing takes the
    whole force, P_1 = |f| (P_2 = 0); two share it by the shaft statics of
    :mod:`gearcli.model.shaft` (:func:`~gearcli.model.shaft.split_components`),
    the locating one taking fz too: P = sqrt(R_x^2 + R_y^2 (+ fz^2)).  All joints at once,
    each component a contiguous (K, N) array."""
    z1, z2, loc, _, single = bearing_layout(mech, joints)
    fx, fy, fz, mx, my = (np.array([x_all[("joint", ji)][:, c] for ji in joints]) for c in range(5))
    R1x, R1y, R2x, R2y = split_components(fx, fy, mx, my, z1[:, None], z2[:, None])
    if single.any():
        R1x[single], R1y[single] = fx[single], fy[single]
    return load_magnitudes(ARRAYS, (R1x, R1y, R2x, R2y), fz, loc[:, :1], loc[:, 1:])


def load_magnitudes(al, R, fz, loc1, loc2) -> tuple:
    """(P_1, P_2): each bearing's load magnitude sqrt(R_x^2 + R_y^2 (+ fz^2 on the locating
    one)) from the split R = (R1x, R1y, R2x, R2y) (:func:`gearcli.model.shaft.split_terms`)
    and the axial force fz; ``loc1``, ``loc2`` 1.0 for the locating bearing, else 0.0.  Over
    the algebra ``al`` (:mod:`gearcli.algebra`): both paths."""
    R1x, R1y, R2x, R2y = R
    fz2 = al.mul(fz, fz)
    return (al.call("sqrt", al.add(al.add(al.mul(R1x, R1x), al.mul(R1y, R1y)), al.mul(loc1, fz2))),
            al.call("sqrt", al.add(al.add(al.mul(R2x, R2x), al.mul(R2y, R2y)), al.mul(loc2, fz2))))


def friction_moment(al, P1, P2, arm1, arm2):
    """sum_b M_b = 1/2 mu_1 d_1 P_1 + 1/2 mu_2 d_2 P_2 (N*m, >= 0), ``arm`` = 1/2 mu_b d_b."""
    return al.add(al.mul(arm1, P1), al.mul(arm2, P2))


def bearing_layout(mech, joints: list[int]):
    """Per joint of ``joints`` (K): bearing positions z1, z2 (K,) (0, 1 for a single
    bearing), locating flags (K, 2) (1.0/0.0; a single bearing: 1, 0), friction arms
    1/2 mu_b d_b (K, 2) (0 for a missing second bearing), single-bearing mask (K,).  The
    constants of :func:`friction_moments` and of its generated twin
    (:func:`gearcli.dynamics.llvm.bearings.moment`)."""
    K = len(joints)
    z1, z2, loc, arm, single = np.zeros(K), np.ones(K), np.zeros((K, 2)), np.zeros((K, 2)), np.zeros(K, bool)
    for k, ji in enumerate(joints):
        bs = mech.joints[ji].bearings
        if len(bs) == 1:
            single[k], loc[k, 0], arm[k, 0] = True, 1.0, bs[0].friction_arm
        else:
            z1[k], z2[k] = bs[0].position, bs[1].position
            loc[k] = [float(bool(b.locating)) for b in bs]
            arm[k] = [b.friction_arm for b in bs]
    return z1, z2, loc, arm, single


def friction_moments(mech, joints: list[int], x_all: dict) -> np.ndarray:
    """sum_b M_b = sum_b 1/2 mu_b d_b P_b (N, len(joints)) of each joint with bearing
    friction, N*m (>= 0), from the joint reactions x_all[("joint", ji)] (N, 5)."""
    arm = bearing_layout(mech, joints)[3]
    N = x_all[("joint", joints[0])].shape[0]
    out = np.empty((len(joints), N))
    for s in range(0, N, BLOCK):
        P1, P2 = bearing_loads(mech, joints, {("joint", ji): x_all[("joint", ji)][s:s + BLOCK] for ji in joints})
        out[:, s:s + BLOCK] = friction_moment(ARRAYS, P1, P2, arm[:, :1], arm[:, 1:])
    return out.T


BLOCK = 2048
"""Samples :func:`friction_moments` takes at a time: its dozen (K, BLOCK) temporaries stay in
the cache and in the heap's free lists (over all samples at once, 20,000 for 8 joints, they
were fresh pages every time: 11 ms a call instead of 3)."""


def solve_with_bearing_friction(an, kin, b: dict, qd_all: np.ndarray, solve_rhs):
    """Solve ``solve_rhs(rhs) -> (x_all, signs)`` with the bearing friction of the converged
    reactions on the right-hand side.

    Returns (x_all, signs, rhs used, moments (N, J): sum_b M_b of every joint, iterations
    (N,) int: the iteration at which each sample's moments met the tolerance; None for a
    mechanism without bearing friction, which is solved once)."""
    joints = friction_joints(an.mech)
    if not joints:
        x_all, sig = solve_rhs(b)
        return x_all, sig, b, None, None
    axis = {ji: {L: joint_axis_wrench(an, kin, ji, L) for L in _links(an, ji)} for ji in joints}
    used = {}

    def solve_moments(Mb, todo):              # every sample (the ones done again, unchanged)
        rhs = {L: v.copy() for L, v in b.items()}
        _subtract(rhs, axis, joints, qd_all, Mb)
        used["rhs"] = rhs
        x_all, used["sig"] = solve_rhs(rhs)
        return x_all
    x_all, moments, iterations = fixed_point(an, qd_all, solve_moments)
    return x_all, used["sig"], used["rhs"], moments, iterations


def _subtract(rhs: dict, axis: dict, joints: list, qd_all: np.ndarray, Mb: np.ndarray) -> None:
    """rhs[L] -= the bearing friction moments Mb (N, len(joints)) on L, -sign(q'_J) Mb about
    each joint's axis on its child (``axis``: per joint {L: unit wrench on L})."""
    for k, ji in enumerate(joints):
        Q = -np.sign(qd_all[:, ji]) * Mb[:, k]
        for L, w in axis[ji].items():
            rhs[L] -= Q[:, None] * w


def subtract_bearing_friction(an, kin, b: dict, qd_all: np.ndarray, moments: np.ndarray | None,
                              rows=slice(None)) -> None:
    """b[L] -= the converged bearing friction moments ``moments[rows]`` ((N, K) of the joints
    :func:`friction_joints`, the llvm kernel's; None: none) on L, in place (the right-hand
    side a solution balances)."""
    if moments is None:
        return
    joints = friction_joints(an.mech)
    axis = {ji: {L: joint_axis_wrench(an, kin, ji, L) for L in _links(an, ji)} for ji in joints}
    _subtract(b, axis, joints, qd_all, moments[rows])


def fixed_point(an, qd_all: np.ndarray, solve_moments):
    """The fixed point of the bearing friction moments of the numpy path (the llvm kernel
    converges them per block, :mod:`.llvm.bearings`, with this TOL and MAX_ITERATIONS, in a
    smooth stretch from the moments of the samples before).

    ``solve_moments(Mb, todo)`` solves the samples ``todo`` (indices) with the moments
    Mb[todo] (Mb (N, len(friction_joints)): sum_b M_b >= 0 of each joint with bearing
    friction, on the child -sign(q'_J) Mb about the axis, reversed on the parent) and
    returns the unknowns {(kind, index): (N, size)} of every sample (joint reactions in the
    child's basis; a path may solve the other samples again with their Mb, which no longer
    changes).  Iterates from zero moments, each sample until its moments change by at most
    ``TOL`` relative (its Mb is then kept: those of its solution).  Returns (x_all, moments
    (N, J) of every joint, iterations (N,) int: the iteration at which each sample met the
    tolerance).  Raises :class:`BearingFrictionError` naming the first sample that does not
    converge."""
    joints = friction_joints(an.mech)
    N, J = qd_all.shape
    s = qd_all[:, joints] != 0.0                    # at rest: no moment
    rest = not s.all()
    keys = [("joint", ji) for ji in joints]
    Mb = np.zeros((N, len(joints)))
    iterations = np.zeros(N, dtype=np.int64)
    todo = np.arange(N)
    grown = {}                      # sample -> the joint whose moment grew past the floats
    history: list = []              # the rescue's steps: (moments in, moments out) of the todo samples
    for it in range(1, MAX_ITERATIONS + RESCUE + 1):
        x_all = solve_moments(Mb, todo)
        every = todo.size == N
        given = Mb if every else Mb[todo]
        with np.errstate(over="ignore", invalid="ignore"):      # a moment grown past the floats
            new = friction_moments(an.mech, joints, x_all if every else {k: x_all[k][todo] for k in keys})
            if rest:
                new = np.where(s if every else s[todo], new, 0.0)
            change = np.abs(new - given)
        finite = np.isfinite(new)
        done = np.all(change <= TOL * np.abs(new) + 1e-300, axis=1) & finite.all(axis=1)
        for i in np.flatnonzero(~finite.all(axis=1)):      # never converges: out of the iteration
            grown[int(todo[i])] = joints[int(np.argmin(finite[i]))]
            Mb[todo[i]] = 0.0                                # (its solution no longer matters)
        out = done | ~finite.all(axis=1)
        if it > MAX_ITERATIONS - DEPTH:      # the last plain steps feed the rescue's first
            history = (history + [(given.copy(), new)])[-(DEPTH + 1):]
        step = (lambda h: anderson(h)) if it >= MAX_ITERATIONS else (lambda h: h[-1][1])
        if not out.any():                    # (early iterations: no gather, no scatter)
            Mb[todo if not every else slice(None)] = step(history) if history else new
            continue
        iterations[todo[done]] = it
        history = [(a[~out], b[~out]) for a, b in history]
        Mb[todo[~out]] = step(history) if history else new[~out]
        todo, change = todo[~out], change[~out]
        if todo.size == 0:
            break
    if todo.size or grown:
        _fail(an, joints, todo, change, Mb, grown)
    moments = np.zeros((N, J))
    moments[:, joints] = Mb
    return x_all, moments, iterations


RESCUE = 100
"""Iterations of :func:`anderson` steps after MAX_ITERATIONS plain ones, for the samples the
fixed point has not converged (it contracts by ~Lambda an iteration: mu 0.9-0.99 on a bore
near the gear's diameter, Lambda ~ 0.96, where the kernel's Newton levels converge in 2-7;
issue 34, section 5).  A sample that converges plain keeps its moments and count."""

DEPTH = 4
"""The differences an :func:`anderson` step fits (its memory)."""


def anderson(history: list) -> np.ndarray:
    """The next moments (n, K) of the samples still iterating, by Anderson acceleration of
    M <- g(M) on the last steps ``history`` [(M_i, g(M_i))] ((n, K) each, oldest first):
    with the residuals f_i = g(M_i) - M_i, the step g_k - dG gamma where gamma minimises
    |f_k - dF gamma| per sample (dF, dG the differences of successive f and g).  Exact in
    one step for an affine g.  A sample whose step is not finite or gives a negative moment
    takes the plain step g_k."""
    if len(history) < 2:
        return history[-1][1]
    M = np.stack([h[0] for h in history], axis=2)          # (n, K, m + 1)
    G = np.stack([h[1] for h in history], axis=2)
    F = G - M
    dF, dG = np.diff(F, axis=2), np.diff(G, axis=2)        # (n, K, m)
    A = np.einsum("nkm,nkl->nml", dF, dF)
    b = np.einsum("nkm,nk->nm", dF, F[:, :, -1])
    m = A.shape[1]
    scale = np.trace(A, axis1=1, axis2=2)[:, None, None] / m + 1e-300
    with np.errstate(all="ignore"):
        gamma = np.linalg.solve(A + 1e-13 * scale * np.eye(m), b[:, :, None])[:, :, 0]
        step = G[:, :, -1] - np.einsum("nkm,nm->nk", dG, gamma)
    bad = ~np.all(np.isfinite(step) & (step >= 0.0), axis=1)
    step[bad] = G[bad, :, -1]
    return step


def _fail(an, joints: list, todo: np.ndarray, change: np.ndarray, Mb: np.ndarray, grown: dict):
    """Raise :class:`BearingFrictionError` for the first sample that did not converge: still
    changing after MAX_ITERATIONS (``todo``, ``change``), or grown to infinity (``grown``)."""
    first = min([*grown, *(int(v) for v in todo[:1])])
    if first in grown:
        raise BearingFrictionError(first, an.mech.joints[grown[first]].name)
    worst = joints[int(np.argmax(change[0] / (np.abs(Mb[first]) + 1e-300)))]
    raise BearingFrictionError(first, an.mech.joints[worst].name)


def _links(an, ji: int) -> list[int]:
    jt = an.mech.joints[ji]
    moving = set(an.tree.moving)
    return [L for L in (an.tree.index[jt.child], an.tree.index[jt.parent]) if L in moving]
