"""The solution schedule derived from a given maximum flow, in plain Python: how a cached
schedule (:mod:`.schedule_cache`) is proven to be the one :func:`.schedule.solution_schedule`
finds, without importing scipy.

A cache entry keeps the flow :class:`.schedule._Network` found (scalars of each unknown group
matched to each link's equations) beside the blocks.  :func:`proven_blocks` checks that the
flow is a maximum flow of *this* incidence (within the capacities: 6 per link, ``size`` per
group, only on the links a group acts on; every link's 6 equations matched), then derives
the blocks and their order from it as the scheduler does: the strong components of the
link dependency graph (link a after link b when a's equations contain an unknown matched
to b's), the under-determined links (those reaching a group with unmatched scalars by an
alternating path) one block per connected piece, ordered highest level first, a primary
link's block before the secondary ones, then by smallest link id.  Blocks and order do not
depend on which maximum flow is given (Dulmage-Mendelsohn), so a stored schedule equal to
the derived one is the scheduler's, whatever was written in the file; a forged or foreign
entry is either that schedule or refused.
"""
from __future__ import annotations

import heapq


def checked_flow(flow, moving, groups, cap) -> dict[tuple[int, int], int] | None:
    """``flow`` ([link, group index, scalars] triples) as {(link, group): scalars} when it is
    a maximum flow of the incidence of ``moving`` links and ``groups`` (capacities ``cap``,
    :func:`capacities`; see module docstring), else None."""
    out: dict[tuple[int, int], int] = {}
    link_sum = {int(x): 0 for x in moving}
    group_sum = [0] * len(groups)
    if not isinstance(flow, list):
        return None
    for item in flow:
        if not (isinstance(item, list) and len(item) == 3 and all(type(v) is int for v in item)):
            return None
        x, gi, a = item
        if (x, gi) not in cap or (x, gi) in out or not 0 < a <= cap[(x, gi)] or x not in link_sum:
            return None
        out[(x, gi)] = a
        link_sum[x] += a
        group_sum[gi] += a
    if any(s != 6 for s in link_sum.values()) or any(s > g.size for s, g in zip(group_sum, groups)):
        return None
    return out


def capacities(groups) -> dict[tuple[int, int], int]:
    """{(link, group index): scalars the group can carry to the link's equations}."""
    cap: dict[tuple[int, int], int] = {}
    for gi, g in enumerate(groups):
        for x in g.links:
            cap[(int(x), gi)] = cap.get((int(x), gi), 0) + int(g.size)
    return cap


def proven_blocks(flow, moving, groups, level, primary) -> tuple[tuple[int, ...], ...] | None:
    """The schedule (blocks of link ids in solution order) derived from ``flow``, or None
    when ``flow`` is not a maximum flow of this incidence."""
    cap = capacities(groups)
    f = checked_flow(flow, moving, groups, cap)
    if f is None:
        return None
    moving = [int(x) for x in moving]
    used: dict[int, list[int]] = {x: [] for x in moving}          # link -> groups matched to it
    for (x, gi) in f:
        used[x].append(gi)
    members = [sorted({int(x) for x in g.links}) for g in groups]
    dep = {a: set() for a in moving}                               # a -> b: a after b
    for b in moving:
        for gi in used[b]:
            for a in members[gi]:
                dep[a].add(b)
    comp = _strong_components(moving, dep)
    horizontal = _under_determined(moving, groups, members, f, used, cap)
    if horizontal:
        top = max(comp.values()) + 1
        for x, piece in _pieces(horizontal, members).items():
            comp[x] = top + piece
    blocks: dict[int, list[int]] = {}
    for x in moving:
        blocks.setdefault(comp[x], []).append(x)
    after: dict[int, set[int]] = {k: set() for k in blocks}
    for a in moving:
        for b in dep[a]:
            if comp[a] != comp[b]:
                after[comp[a]].add(comp[b])
    return ordered_blocks(blocks, after, level, primary)


def _strong_components(nodes, edges) -> dict[int, int]:
    """Strong component id of each node (iterative Tarjan)."""
    index: dict[int, int] = {}
    low: dict[int, int] = {}
    comp: dict[int, int] = {}
    stack: list[int] = []
    count = 0
    for root in nodes:
        if root in index:
            continue
        work = [(root, iter(sorted(edges[root])))]
        index[root] = low[root] = len(index)
        stack.append(root)
        while work:
            v, it = work[-1]
            for w in it:
                if w not in index:
                    index[w] = low[w] = len(index)
                    stack.append(w)
                    work.append((w, iter(sorted(edges[w]))))
                    break
                if w not in comp:
                    low[v] = min(low[v], index[w])
            else:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[v])
                if low[v] == index[v]:
                    while True:
                        w = stack.pop()
                        comp[w] = count
                        if w == v:
                            break
                    count += 1
    return comp


def _under_determined(moving, groups, members, f, used, cap) -> list[int]:
    """The links whose equations reach a group with unmatched scalars by an alternating
    path (residual network: link -> group while the pair's capacity is not used up, group ->
    link where scalars are matched)."""
    matched = [0] * len(groups)
    for (_, gi), a in f.items():
        matched[gi] += a
    seen_g = {gi for gi, g in enumerate(groups) if matched[gi] < g.size}
    seen_x: set[int] = set()
    todo = list(seen_g)
    while todo:
        gi = todo.pop()
        for x in members[gi]:
            if x not in seen_x and f.get((x, gi), 0) < cap[(x, gi)]:
                seen_x.add(x)
                for g2 in used[x]:
                    if g2 not in seen_g:
                        seen_g.add(g2)
                        todo.append(g2)
    return [x for x in moving if x in seen_x]


def _pieces(links, members) -> dict[int, int]:
    """Connected pieces of ``links`` (two links joined when a group acts on both)."""
    parent = {x: x for x in links}

    def find(x):
        while parent[x] != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x
    for m in members:
        inside = [x for x in m if x in parent]
        for x in inside[1:]:
            parent[find(x)] = find(inside[0])
    roots: dict[int, int] = {}
    return {x: roots.setdefault(find(x), len(roots)) for x in links}


def ordered_blocks(blocks: dict[int, list[int]], after: dict[int, set[int]], level,
                   primary) -> tuple[tuple[int, ...], ...]:
    """The blocks (links of each component ``k``) in the paper's order among those the
    dependencies allow (``after[k]``: the components k comes after): highest level first, a
    primary link before the secondary links of its level, then by link id."""
    prim = set(primary)

    def key(k):
        xs = blocks[k]
        return (-max(level[x] for x in xs), 0 if prim & set(xs) else 1, min(xs))
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
