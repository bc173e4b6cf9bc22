"""The canonical graph (Tsai 1988): canonical parents (carriers), the equivalent open-loop
chain, axis labels, levels, canonical angles and coaxial groups."""
from __future__ import annotations

import numpy as np

from ..errors import Collector
from .context import Home
from .types import CoaxialGroup, first_collinear


def canonical_parents(h: Home) -> list:
    """Canonical parent (carrier) of every link, None for the base: list (L,) of link ids.

    Tsai's canonical graph: a link whose revolute joint is collinear with its parent's own
    revolute joint is re-attached to the grandparent, repeatedly, so that the thin-edged
    path from the root to any link has distinct axis labels.  (A slider on the line of a
    revolute joint is not coaxial with it.)
    """
    mech, tree = h.mech, h.tree
    cparent = [None] * h.L
    for ji in tree.order:
        c = h.idx[mech.joints[ji].child]
        p = tree.parent[c]
        while p != tree.base:
            jp = tree.parent_joint[p]
            if not h.collinear(jp, ji):
                break
            if mech.joints[jp].type != "revolute" or mech.joints[ji].type != "revolute":
                break
            p = tree.parent[p]
        cparent[c] = p
    return cparent


def eolc(h: Home, cparent: list) -> list[int]:
    """Equivalent open-loop chain: link ids base -> end-effector along canonical parents
    (base first; only the base if the end-effector is the base)."""
    primary = [h.idx[h.mech.end_effector]]
    while primary[-1] != h.tree.base:
        primary.append(cparent[primary[-1]])
    return primary[::-1]


def axis_labels(h: Home, on_chain: set, col: Collector) -> list:
    """Axis label of each link's canonical edge: list (L,) of str, None for the base.

    One label per distinct line in space.  The axes of the chain base -> end-effector
    (link ids ``on_chain``) are named first, a, b, c, ... as in the paper; a joint's
    explicit ``label`` overrides the name of its line (and must not name two lines).
    """
    mech = h.mech
    lines: list[tuple[np.ndarray, np.ndarray, str]] = []
    O, Z = np.zeros((h.J, 3)), np.zeros((h.J, 3))  # the lines so far, as arrays (vectorised test)
    label = [None] * h.L
    explicit: dict[str, int] = {}
    for ji in sorted(h.tree.order, key=lambda ji: h.idx[mech.joints[ji].child] not in on_chain):
        c = h.idx[mech.joints[ji].child]
        k = first_collinear(O[:len(lines)], Z[:len(lines)], h.ow[ji], h.zw[ji], h.scale)
        if k is None:
            O[len(lines)], Z[len(lines)] = h.ow[ji], h.zw[ji]
            lines.append((h.ow[ji], h.zw[ji], auto_label(len(lines))))
            k = len(lines) - 1
        given = mech.joints[ji].label
        if given is not None:
            if given in explicit and explicit[given] != k:
                col.add(f"{mech.joints[ji].path}.label", f"label '{given}' is given to joints whose axes are not collinear")
            explicit[given] = k
            o, z, _ = lines[k]
            lines[k] = (o, z, given)
        label[c] = k
    return [None if k is None else lines[k][2] for k in label]


def levels(h: Home, cparent: list) -> list[int]:
    """Level of each link: list (L,) of its thin-edge distance from the root in the
    canonical graph (base 0)."""
    level = [0] * h.L
    for ji in h.tree.order:
        c = h.idx[h.mech.joints[ji].child]
        level[c] = level[cparent[c]] + 1
    return level


def canonical_angle_rows(h: Home, cparent: list) -> np.ndarray:
    """(L, J) array: row i is the canonical angle of link i (its rotation relative to its
    canonical parent, about its own joint axis, rad) in real joint angles; entries are
    +-1 on the collinear joints between the link and its canonical parent, 0 elsewhere."""
    canon = np.zeros((h.L, h.J))
    for c in h.tree.moving:
        for ji in h.tree.path_up(c, cparent[c]):
            canon[c, ji] = float(np.sign(h.zw[ji] @ h.zw[h.jin[c]]))
    return canon


def coaxial_groups(h: Home, cparent: list, label: list) -> list[CoaxialGroup]:
    """Coaxial groups: each carrier with the canonical children that turn about one line
    (joints of one type), the line's reference direction given in the carrier frame."""
    jin, groups = h.jin, []
    for p in range(h.L):
        kids = [c for c in h.tree.moving if cparent[c] == p]
        done: set[int] = set()
        for c in kids:
            if c in done:
                continue
            same = [d for d in kids if d not in done and h.collinear(jin[c], jin[d])
                    and h.mech.joints[jin[d]].type == h.mech.joints[jin[c]].type]
            done.update(same)
            Rp = h.kin.R[p]
            groups.append(CoaxialGroup(p, label[c], tuple([p] + same), Rp.T @ h.zw[jin[c]]))
    return groups


def auto_label(i: int) -> str:
    """Axis label of the i-th distinct axis: a, b, ..., z, a1, b1, ..."""
    s = ""
    i += 1
    while i:
        i, r = divmod(i - 1, 26)
        s = chr(ord("a") + r) + s
    return s
