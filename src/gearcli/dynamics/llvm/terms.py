"""Column terms of the kernel's world-frame blocks (blocks without a constant frame).

A block whose unknowns share no link in which they are all fixed (a motor spread over
several joints by a transmission, an ideal coupling) is solved per sample in world axes,
like :func:`~..general.solve_general`.  The kernel assembles its matrix from the column
terms of :mod:`..column_terms` (the numpy path's columns are the same terms), as
:data:`.records.TERM` records (target link, row, column, force or moment, frame link X,
signed-mesh position) with their :data:`.records.TERM_VALUE` (coef, d_X, p_X).
"""
from __future__ import annotations

import numpy as np

from ..column_terms import group_terms
from ..general import is_geared
from .records import TERM, TERM_VALUE, records


def general_terms(an, plans):
    """(terms, their values, {block: (offset, count)}) of the blocks without a constant
    frame (:data:`.records.TERM`, :data:`.records.TERM_VALUE` records); a block's groups act
    on its own links and on later blocks' (:attr:`..blocks.BlockPlan.later`), never earlier."""
    rec, flt, where = [], [], {}
    for bi, p in enumerate(plans):
        if p.F is not None:
            continue
        start = len(rec)
        for gi, g in enumerate(p.groups):
            t_pos = p.signed.index(gi) if is_geared(an, g) else -1
            for L in g.links:
                row = p.links.index(L) if L in p.links else -1
                for j, terms in enumerate(group_terms(an, g, L, t_pos)):
                    for kind, X, sgn, coef, d, pt in terms:
                        rec.append((L, row, int(p.offs[gi]) + j, kind, X, sgn))
                        flt.append((coef, d, pt))
        where[bi] = (start, len(rec) - start)
    return records(rec, TERM), records(flt, TERM_VALUE), where


MAX_LOCAL_CONDITION = 1e8
"""Largest condition number of a world-frame block's matrix that :func:`local_inverse`
inverts once instead of eliminating per sample."""


def local_inverse(terms, values, k0: int, nt: int, link: int, n: int):
    """The inverse (n, n) of a world-frame block's matrix in ``link``'s axes about its
    origin, when that matrix is constant: the block is the one link ``link``, it has no
    signed mesh (the caller checks both) and every term on it has ``link`` as its frame
    link X (a term then reads, in link axes, coef [d_X ; p_X x d_X] or coef [0 ; d_X]:
    no pose enters).  None otherwise, or when the matrix is singular or worse conditioned
    than :data:`MAX_LOCAL_CONDITION`.  The kernel then solves the block like a
    constant-frame block (rotating its right-hand side into link axes) and still
    propagates its wrenches from the terms."""
    A = np.zeros((n, n))
    for t, v in zip(terms[k0:k0 + nt], values[k0:k0 + nt]):
        if t.row < 0:
            continue
        if t.row != 0 or t.frame != link or t.sign >= 0:
            return None
        d = v.d
        A[:, t.col] += v.coef * (np.concatenate([np.zeros(3), d]) if t.moment == 1 else np.concatenate([d, np.cross(v.p, d)]))
    if n != 6 or not np.isfinite(cond := np.linalg.cond(A)) or cond > MAX_LOCAL_CONDITION:
        return None
    return np.linalg.inv(A)
