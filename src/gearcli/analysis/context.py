"""The shared, read-only context of the analysis steps: the joint tree and its joint axis
lines at the home configuration."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..model.mechanism import Mechanism
from .home import Placements, home_placements
from .tree import Tree
from .types import collinear


@dataclass(frozen=True, eq=False)
class Home:
    """The real joint tree and its joint axis lines at the home configuration (q = 0).

    Shared, read-only context of every analysis step.  Link ids index ``tree.links``
    (L of them), joint ids index ``mech.joints`` (J of them).
    """

    mech: Mechanism
    tree: Tree
    idx: dict           # link name -> link id
    jidx: dict          # joint name -> joint id
    jin: tuple          # (L,) joint into each link, None for the base: its axis is the link's axis
    kin: Placements     # link and joint frames at q = 0 (R[i] (3, 3), o[i] (3,), world frame)
    ow: list            # J arrays (3,): joint origins, world frame, m
    zw: list            # J arrays (3,): unit joint axes, world frame
    scale: float        # m: largest joint-origin distance (at least 1), scales TOL_LINE

    @property
    def L(self) -> int:
        """Number of links (base included)."""
        return len(self.tree.links)

    @property
    def J(self) -> int:
        """Number of real joints."""
        return len(self.mech.joints)

    def collinear(self, a: int, b: int) -> bool:
        """True if the axis lines of joints ``a`` and ``b`` coincide (home configuration)."""
        return collinear(self.ow[a], self.zw[a], self.ow[b], self.zw[b], self.scale)


def home_axes(mech: Mechanism, tree: Tree) -> Home:
    """Joint axis lines (origin ``ow``, m; unit direction ``zw``) in the world frame at
    the home configuration, where every joint coordinate is zero."""
    J = len(mech.joints)
    home = home_placements(mech, tree)
    zw = [home.Rj[ji][:, 2] for ji in range(J)]
    ow = [home.oj[ji] for ji in range(J)]
    scale = max([1.0] + [float(np.linalg.norm(x)) for x in ow])
    jidx = {jt.name: ji for ji, jt in enumerate(mech.joints)}
    return Home(mech, tree, tree.index, jidx, tree.parent_joint, home, ow, zw, scale)
