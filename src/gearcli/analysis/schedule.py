"""The solution schedule: which links' Newton-Euler equations are solved together, in
which order (paper, "Dynamic Analysis").

Each moving link gives 6 equations.  Unknowns: 5 per joint (3 forces, 2 moments: a
revolute joint transmits no moment about its axis), 1 per gear mesh (the tangential tooth
force t), 1 per motor (its torque).  The equation/unknown incidence is block-
triangularised (Dulmage-Mendelsohn: a perfect matching, found as a maximum flow, then
the strongly connected components of the dependency graph); the blocks are the
irreducible sets of links whose equations must be solved simultaneously.  Among the
orders the dependencies allow, the paper's is taken: highest level first, a primary link
before the secondary links of its level.

A schedule is kept on disk (:mod:`.schedule_cache`): a later process scheduling the same
incidence reads it and does not import scipy.sparse.csgraph (most of a ``gearcli check``).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import Collector, counted
from . import schedule_cache
from .schedule_proof import ordered_blocks


@dataclass(frozen=True)
class UnknownGroup:
    """A group of scalar unknowns: ``kind`` in {"joint", "mesh", "motor"}, ``index`` into
    mech.joints / analysis.circuits / mech.motors, ``size`` scalars, acting on ``links``."""

    kind: str
    index: int
    size: int
    links: tuple[int, ...]


def _loads_carrier(gp) -> bool:
    """True when a pair's unknown puts a wrench on its carrier: an ideal coupling's or a
    reducer's reaction torque, a lossy belt's loss couple; a screw's or a worm pair's forces,
    and a lossless belt's, act on its two members only."""
    if gp.screw is not None or gp.worm is not None:
        return False
    if gp.belt is not None:
        return gp.belt.lossy
    return True


def unknown_groups(an) -> list[UnknownGroup]:
    """The unknowns of the load equations, grouped: 5 per revolute joint reaction (3 forces,
    2 moments), 1 per gear mesh (the tangential force t), 1 per motor; each with the moving
    links whose balance it enters."""
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
            links = (c.j, c.k) if c.geometry is not None or not _loads_carrier(mech.gears[c.gear]) else (c.j, c.k, c.carrier)
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
    """Blocks of link ids in solution order (see module docstring).

    The perfect matching of equations to unknowns is found as a maximum flow (Dinic's
    algorithm, O(V^2 E), on the compressed network source -> link (6 equations) -> unknown
    group (``size`` scalars) -> sink), so the time stays polynomial (in practice linear) in
    the number of links.  The irreducible blocks and their partial order do not depend on
    which perfect matching is found (Dulmage-Mendelsohn), so neither does the schedule;
    it is read from the disk cache (:mod:`.schedule_cache`) when an earlier process found
    it, else found and stored (only schedules: a failure is found again each time).
    """
    tree = an.tree
    moving = tree.moving
    groups = unknown_groups(an)
    nrow = 6 * len(moving)
    ncol = sum(g.size for g in groups)
    if ncol < nrow or (ncol > nrow and not an.redundant):
        if col is not None:
            col.add("", f"{counted(nrow, 'equation')} for {counted(ncol, 'unknown')}: "
                    "the loads are not statically determinate")
        return ()
    key = schedule_cache.schedule_key(moving, groups, an.redundant, an.level, an.primary)
    cached = schedule_cache.load(key, moving, groups, an.level, an.primary)
    if cached is not None:
        return cached
    net = _Network(moving, groups)
    if net.value < nrow:
        if col is not None:
            bad = net.overdetermined_links()
            col.add("", "the loads are statically indeterminate: no unique solution for the equations of links "
                    + ", ".join(f"'{tree.links[x]}'" for x in bad))
        return ()
    comp, after = net.blocks()
    order = _ordered_blocks(an, moving, comp, after)
    schedule_cache.store(key, order, matched_flow(net, moving))
    return order


class _Network:
    """Flow network of the equation/unknown incidence, compressed: node 0 the source,
    1..L the moving links (capacity 6 from the source), L+1..L+G the unknown groups
    (capacity ``size`` to the sink), L+G+1 the sink."""

    def __init__(self, moving: list[int], groups: list[UnknownGroup]):
        from scipy.sparse import csr_matrix  # noqa: PLC0415  (scipy.sparse: only without a cached schedule)
        from scipy.sparse.csgraph import maximum_flow  # noqa: PLC0415

        L, G = len(moving), len(groups)
        self.L, self.G = L, G
        node = {x: 1 + i for i, x in enumerate(moving)}
        sink = L + G + 1
        src, dst, cap = [], [], []
        for gi, g in enumerate(groups):
            for x in g.links:
                src.append(node[x])
                dst.append(L + 1 + gi)
                cap.append(g.size)
            src.append(L + 1 + gi)
            dst.append(sink)
            cap.append(g.size)
        src += [0] * L
        dst += list(range(1, L + 1))
        cap += [6] * L
        n = sink + 1
        self.cap = csr_matrix((np.asarray(cap, np.int32), (src, dst)), shape=(n, n))
        self.cap.sum_duplicates()
        res = maximum_flow(self.cap, 0, sink, method="dinic")
        self.value = res.flow_value
        self.flow = res.flow.tocsr()
        # link-group incidence (L, G) and the flow on it
        self.inc = self.cap[1:L + 1, L + 1:L + 1 + G].tocsr()
        self.inc.data[:] = 1
        used = self.flow[1:L + 1, L + 1:L + 1 + G].tocsr()
        used.data = (used.data > 0).astype(np.int32)
        used.eliminate_zeros()
        self.used = used

    def blocks(self):
        """Strong components of the link dependency graph (link a after link b when a's
        equations contain an unknown matched to b's) and, per component, the set of
        components it comes after.  The links of the under-determined part (more unknowns
        than equations: a redundant gear set) form one block per connected piece."""
        from scipy.sparse.csgraph import connected_components  # noqa: PLC0415

        dep = (self.inc @ self.used.T).tocoo()  # dep[a, b] > 0: a uses an unknown solved with b
        _, comp = connected_components(dep.tocsr(), directed=True, connection="strong")
        H = self.horizontal()
        if H.any():
            inc_h = self.inc[H]
            _, piece = connected_components((inc_h @ inc_h.T).tocsr(), directed=False)
            comp[H] = comp.max() + 1 + piece
        after: dict[int, set[int]] = {int(k): set() for k in comp}
        for a, b in zip(comp[dep.row], comp[dep.col]):
            if a != b:
                after[int(a)].add(int(b))
        return comp, after

    def horizontal(self) -> np.ndarray:
        """(L,) mask of the links in the under-determined (horizontal) part of the
        Dulmage-Mendelsohn decomposition: those whose equations reach an unmatched unknown
        by an alternating path, i.e. the links that reach the sink in the residual network.
        No other link's equations contain their unknowns, so their blocks come after the
        blocks they depend on."""
        from scipy.sparse.csgraph import breadth_first_order  # noqa: PLC0415

        residual = (self.cap - self.flow).tocsr()
        residual.data = (residual.data > 0).astype(np.int32)
        residual.eliminate_zeros()
        sink = self.L + self.G + 1
        order = breadth_first_order(residual.T.tocsr(), sink, directed=True, return_predecessors=False)
        mask = np.zeros(self.L, bool)
        mask[[int(v) - 1 for v in order if 1 <= v <= self.L]] = True
        return mask

    def overdetermined_links(self) -> list[int]:
        """Positions (in ``moving``) of the links whose equations cannot all be matched:
        the links reachable from the source in the residual network (the over-determined
        part of the Dulmage-Mendelsohn decomposition, the same for every maximum flow)."""
        from scipy.sparse.csgraph import breadth_first_order  # noqa: PLC0415

        residual = (self.cap - self.flow).tocsr()
        residual.data = (residual.data > 0).astype(np.int32)
        residual.eliminate_zeros()
        order = breadth_first_order(residual, 0, directed=True, return_predecessors=False)
        return sorted(int(v) - 1 for v in order if 1 <= v <= self.L)


def _ordered_blocks(an, moving: list[int], comp: np.ndarray, after: dict[int, set[int]]):
    """The blocks in the paper's order among those the dependencies allow
    (:func:`.schedule_proof.ordered_blocks`)."""
    blocks: dict[int, list[int]] = {}
    for i, x in enumerate(moving):
        blocks.setdefault(int(comp[i]), []).append(x)
    return ordered_blocks(blocks, after, an.level, an.primary)


def matched_flow(net: _Network, moving: list[int]) -> list[list[int]]:
    """[link, group index, scalars] of each pair the maximum flow of ``net`` matches (kept
    with a cached schedule: :func:`.schedule_proof.proven_blocks`)."""
    f = net.flow[1:net.L + 1, net.L + 1:net.L + 1 + net.G].tocoo()
    return sorted([int(moving[r]), int(c), int(a)] for r, c, a in zip(f.row, f.col, f.data) if a > 0)
