"""The tree of real joints (thin edges): every moving link hangs from the base through
exactly one path of joints; only gear pairs may close loops."""
from __future__ import annotations

from collections import deque
from dataclasses import dataclass
from functools import cached_property

from ..errors import Collector
from ..model.mechanism import Mechanism


@dataclass(frozen=True)
class Tree:
    """Index maps of the real joint tree.

    ``links``: link names in file order (index = link id); ``base``: base id;
    ``parent_joint[i]``: index of the joint whose child is link i (None for the base);
    ``order``: joint indices from base to tips; ``parent[i]``: parent link id.
    """

    links: tuple[str, ...]
    index: dict
    base: int
    parent_joint: tuple
    parent: tuple
    order: tuple[int, ...]

    @cached_property
    def moving(self) -> tuple[int, ...]:
        """Ids of every link but the base, in link order (computed once: read in loops)."""
        return tuple(i for i in range(len(self.links)) if i != self.base)

    def path_up(self, i: int, stop: int) -> list[int]:
        """Joint indices from link ``i`` up to (not beyond) ancestor ``stop``."""
        out = []
        while i != stop:
            j = self.parent_joint[i]
            if j is None:
                raise ValueError("not an ancestor")
            out.append(j)
            i = self.parent[i]
        return out


def build_tree(mech: Mechanism, col: Collector) -> Tree | None:
    """Check the joints form a tree rooted at the base; None (with issues) if not."""
    names = tuple(mech.link_names)
    index = {n: i for i, n in enumerate(names)}
    base = index[mech.base]
    adj: dict[int, list[int]] = {i: [] for i in range(len(names))}
    for ji, jt in enumerate(mech.joints):
        adj[index[jt.parent]].append(ji)
        adj[index[jt.child]].append(ji)
    parent_joint: list = [None] * len(names)
    parent: list = [None] * len(names)
    seen = {base}
    used: set[int] = set()
    order: list[int] = []
    queue = deque([base])
    ok = True
    while queue:
        i = queue.popleft()
        for ji in adj[i]:
            if ji in used:
                continue
            used.add(ji)
            jt = mech.joints[ji]
            other = index[jt.child] if index[jt.parent] == i else index[jt.parent]
            if other in seen:
                col.add(jt.path, f"joint '{jt.name}' closes a loop of joints between links "
                        f"'{jt.parent}' and '{jt.child}' (only gear pairs may close loops)")
                ok = False
                continue
            if index[jt.child] != other:
                col.add(f"{jt.path}.parent", f"joint '{jt.name}' is written from child to parent: its "
                        f"parent '{jt.parent}' is farther from the base than its child '{jt.child}'")
                ok = False
            seen.add(other)
            parent_joint[other] = ji
            parent[other] = i
            order.append(ji)
            queue.append(other)
    for i, n in enumerate(names):
        if i not in seen:
            link = mech.links[i]
            col.add(link.path, f"link '{n}' is not connected to the base '{mech.base}' by joints")
            ok = False
    if not ok:
        return None
    return Tree(names, index, base, tuple(parent_joint), tuple(parent), tuple(order))
