"""The solution schedule: which links' Newton-Euler equations are solved together, in
which order (paper, "Dynamic Analysis").

Each moving link gives 6 equations.  Unknowns: 5 per joint (3 forces, 2 moments: a
revolute joint transmits no moment about its axis), 1 per gear mesh (the tangential tooth
force t), 1 per motor (its torque).  The equation/unknown incidence is block-
triangularised (Dulmage-Mendelsohn: a perfect matching, then the strongly connected
components of the dependency graph); the blocks are the irreducible sets of links whose
equations must be solved simultaneously.  Among the orders the dependencies allow, the
paper's is taken: highest level first, a primary link before the secondary links of its
level.
"""
from __future__ import annotations

import heapq
from dataclasses import dataclass

import numpy as np
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import connected_components, maximum_bipartite_matching

from ..errors import Collector


@dataclass(frozen=True)
class UnknownGroup:
    """A group of scalar unknowns: ``kind`` in {"joint", "mesh", "motor"}, ``index`` into
    mech.joints / analysis.circuits / mech.motors, ``size`` scalars, acting on ``links``."""

    kind: str
    index: int
    size: int
    links: tuple[int, ...]


def unknown_groups(an) -> list[UnknownGroup]:
    mech, tree = an.mech, an.tree
    b = tree.base
    out = []
    for ji, jt in enumerate(mech.joints):
        links = (tree.index[jt.parent], tree.index[jt.child])
        out.append(UnknownGroup("joint", ji, 5, tuple(x for x in links if x != b)))
    for ci, c in enumerate(an.circuits):
        if c.joints is not None:  # joint coupling: both joints' children and parents
            links = _joint_links(mech, tree, c.joints)
        else:
            links = (c.j, c.k) if c.geometry is not None else (c.j, c.k, c.carrier)
        out.append(UnknownGroup("mesh", ci, 1, tuple(x for x in links if x != b)))
    for mi, (x, s) in enumerate(zip(an.motor_links, an.motor_stators)):
        mj = an.motor_joints[mi] if an.motor_joints else None
        links = (x, s) if mj is None else _joint_links(mech, tree, [ji for ji, _ in mj])
        out.append(UnknownGroup("motor", mi, 1, tuple(y for y in links if y != b)))
    return out


def _joint_links(mech, tree, joints) -> tuple[int, ...]:
    """Children and parents of real joints ``joints``, each link once."""
    links: dict[int, None] = {}
    for ji in joints:
        jt = mech.joints[ji]
        links.setdefault(tree.index[jt.child])
        links.setdefault(tree.index[jt.parent])
    return tuple(links)


def solution_schedule(an, col: Collector | None = None) -> tuple[tuple[int, ...], ...]:
    """Blocks of link ids in solution order (see module docstring)."""
    tree = an.tree
    moving = tree.moving
    row_of_link = {x: i for i, x in enumerate(moving)}
    groups = unknown_groups(an)
    rows, cols = [], []
    ncol = 0
    for g in groups:
        for s in range(g.size):
            for x in g.links:
                r0 = 6 * row_of_link[x]
                rows.extend(range(r0, r0 + 6))
                cols.extend([ncol] * 6)
            ncol += 1
    nrow = 6 * len(moving)
    if ncol != nrow:
        if col is not None:
            col.add("", f"{nrow} equations for {ncol} unknowns: the loads are not statically determinate")
        return ()
    Inc = csr_matrix((np.ones(len(rows)), (rows, cols)), shape=(nrow, ncol))
    Inc.data[:] = 1.0
    match = maximum_bipartite_matching(Inc, perm_type="column")  # match[r] = column of row r
    if np.any(match < 0):
        bad = sorted({moving[r // 6] for r in np.flatnonzero(match < 0)})
        if col is not None:
            col.add("", "the loads are statically indeterminate: no unique solution for the equations of links "
                    + ", ".join(f"'{tree.links[x]}'" for x in bad))
        return ()
    row_of_col = np.empty(ncol, int)
    row_of_col[match] = np.arange(nrow)
    Inc = Inc.tocoo()
    dep = csr_matrix((np.ones(Inc.nnz), (Inc.row, row_of_col[Inc.col])), shape=(nrow, nrow))
    ncomp, comp = connected_components(dep, directed=True, connection="strong")
    link_comp = {x: comp[6 * row_of_link[x]] for x in moving}
    blocks: dict[int, list[int]] = {}
    for x in moving:
        blocks.setdefault(link_comp[x], []).append(x)
    # dependencies between blocks: block A after block B if A's rows use B's unknowns
    after: dict[int, set[int]] = {k: set() for k in blocks}
    for r, c in zip(Inc.row, Inc.col):
        a, b = comp[r], comp[row_of_col[c]]
        if a != b:
            after[a].add(b)
    prim = set(an.primary)

    def key(k):
        xs = blocks[k]
        return (-max(an.level[x] for x in xs), 0 if prim & set(xs) else 1, min(xs))
    indeg = {k: len(v) for k, v in after.items()}
    users: dict[int, list[int]] = {k: [] for k in blocks}
    for a, bs in after.items():
        for b in bs:
            users[b].append(a)
    heap = [(key(k), k) for k, d in indeg.items() if d == 0]
    heapq.heapify(heap)
    order = []
    while heap:
        _, k = heapq.heappop(heap)
        order.append(tuple(sorted(blocks[k])))
        for a in users[k]:
            indeg[a] -= 1
            if indeg[a] == 0:
                heapq.heappush(heap, (key(a), a))
    return tuple(order)
