"""The square basis of a redundant world-frame block (:class:`~.world.WorldBlock`): which
d columns the generated kernel leaves free, the row order it eliminates the rest in and the
row swaps that keep its static pivots sound (part of the kernel program, hashed with it).
"""
from __future__ import annotations

import numpy as np

MAX_BASIS_CONDITION = 1e8
"""Largest condition number of a redundant block's basis (its matrix without the free
columns) over the poses and sign patterns :func:`_free_columns` tries."""


def basis(an, p, w):
    """:func:`_free_columns`, None where its linear algebra fails (the KKT solve then)."""
    try:
        return _free_columns(an, p, w)
    except (np.linalg.LinAlgError, ValueError):
        return None


def _free_columns(an, p, w):
    """(free, row order, swaps): the d weighted columns of a redundant world-frame block (n unknowns, 6B equations,
    d = n - 6B) whose removal leaves a square basis A_B that is regular on 9 poses (home and
    8 random, every t positive and every t negative) with a condition number at most
    :data:`MAX_BASIS_CONDITION`: the generated kernel then solves A_B for the right-hand
    side and the free columns and minimises over the d free unknowns (a d x d system,
    :class:`~.world.WorldBlock`) instead of the (n + 6B)^2 KKT system.  Chosen by
    QR with column pivoting of the null space's weighted rows at home; the basis' row order
    of partial pivoting at home (:func:`_pivot_order`) and each column's alternative pivot
    row (:func:`_swaps`).  None: none found."""
    from scipy.linalg import qr                        # noqa: PLC0415

    from ..equations import Columns                     # noqa: PLC0415
    from ..general import assemble                      # noqa: PLC0415
    from ..kinematics import forward                    # noqa: PLC0415

    rng = np.random.default_rng(18)
    J = len(an.mech.joints)
    q = np.vstack([np.zeros((1, an.dof)), rng.uniform(-np.pi, np.pi, (8, an.dof))]) @ np.asarray(an.S, float).T
    cols = Columns(an, forward(an.mech, an.tree, q.reshape(-1, J)))
    A = assemble(cols, p.groups, list(p.links))                       # (9, 6B, n), every t positive
    nr, n = A.shape[1:]
    weighted = np.flatnonzero(w > 0)
    null = np.linalg.svd(A[0])[2][nr:].T                              # (n, d)
    if null.shape[1] != n - nr:
        return None
    piv = qr(null[weighted].T, pivoting=True)[2]
    free = sorted(int(weighted[i]) for i in piv[:n - nr])
    basis = [j for j in range(n) if j not in free]
    minus = A.copy()
    for gi in p.signed:                                               # every t negative
        c = int(p.offs[gi])
        for r, L in enumerate(p.links):
            if L in p.groups[gi].links:
                minus[:, 6 * r:6 * r + 6, c] = cols.group(p.groups[gi], L, -1.0)[:, :, 0]
    conds = np.linalg.cond(np.concatenate([A, minus])[:, :, basis])
    if not (np.all(np.isfinite(conds)) and conds.max() <= MAX_BASIS_CONDITION):
        return None
    order = _pivot_order(A[0][:, basis])
    q = rng.uniform(-np.pi, np.pi, (SWAP_POSES, an.dof)) @ np.asarray(an.S, float).T
    poses = assemble(Columns(an, forward(an.mech, an.tree, q.reshape(-1, J))), p.groups, list(p.links))
    return free, order, _swaps(poses[:, :, basis][:, order])


SWAP_POSES = 256
"""Random poses (a fixed seed) on which :func:`_swaps` chooses each column's alternative pivot row."""


def _swaps(M: np.ndarray) -> list:
    """Per column c of the matrices M (P, k, k) (rows in the static order): the row below
    c that the generated elimination swaps up where its |entry| is larger than the static
    pivot's (:func:`.world.lu_solve`; -1: none), the row that is largest most often among
    the poses whose static pivot is smaller than an entry below it by more than 10x
    (a pivot row that turns with a gear's angle: its twin row takes over), each pose
    eliminated with the swaps chosen so far."""
    M = np.array(M, float)
    k = M.shape[1]
    out = []
    for c in range(k - 1):
        col = np.abs(M[:, c + 1:, c])
        poor = col.max(axis=1) > 10.0 * np.abs(M[:, c, c])
        alt = -1
        if poor.any():
            rows, counts = np.unique(c + 1 + np.argmax(col[poor], axis=1), return_counts=True)
            alt = int(rows[np.argmax(counts)])
            swap = np.abs(M[:, alt, c]) > np.abs(M[:, c, c])
            M[swap, c], M[swap, alt] = M[swap, alt].copy(), M[swap, c].copy()
        out.append(alt)
        with np.errstate(all="ignore"):
            f = M[:, c + 1:, c] / M[:, c, c][:, None]
        M[:, c + 1:] -= f[:, :, None] * M[:, c, None, :]
    return out + [-1]


def _pivot_order(M: np.ndarray) -> list:
    """The row order partial pivoting takes on the square matrix M (the order the generated
    kernel eliminates in without pivoting, :func:`.world.lu_solve`)."""
    from scipy.linalg import lu_factor                # noqa: PLC0415

    order = list(range(M.shape[0]))
    for c, p in enumerate(lu_factor(M)[1]):
        order[c], order[p] = order[p], order[c]
    return order
