"""Link and joint frames at the home configuration (every joint coordinate zero).

Pure geometry of the model: the analysis needs the joint axis lines at home to find
coaxial joints, carriers and mesh geometry, and nothing of the motion.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..model.mechanism import Mechanism
from .tree import Tree


@dataclass(frozen=True, eq=False)
class Placements:
    """Frames at q = 0, all in the base (world) frame.

    ``R[i]`` (3, 3) and ``o[i]`` (3,), m: orientation and origin of link i's frame;
    ``Rj[j]``, ``oj[j]``: the same for joint j's frame (z = joint axis).
    """

    R: list
    o: list
    Rj: list
    oj: list


def home_placements(mech: Mechanism, tree: Tree) -> Placements:
    """Compose every joint's fixed transforms from the base out: joint frame
    ``R_0j = R_0p R_pj``, ``o_0j = o_0p + R_0p p_pj``; child frame ``R_0c = R_0j R_jc``,
    ``o_0c = o_0j + R_0j p_jc`` (the joint's own motion is the identity at q = 0)."""
    L, J = len(tree.links), len(mech.joints)
    R, o = [None] * L, [None] * L
    Rj, oj = [None] * J, [None] * J
    R[tree.base], o[tree.base] = np.eye(3), np.zeros(3)
    for ji in tree.order:
        jt = mech.joints[ji]
        c = tree.index[jt.child]
        p = tree.parent[c]
        Rj[ji] = R[p] @ jt.R_pj
        oj[ji] = o[p] + R[p] @ jt.p_pj
        R[c] = Rj[ji] @ jt.R_jc
        o[c] = oj[ji] + Rj[ji] @ jt.p_jc
    return Placements(R, o, Rj, oj)
