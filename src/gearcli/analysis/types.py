"""The results of the graph analysis: coaxial groups, fundamental circuits, the Analysis."""
from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from ..model.gears import GearGeometry
from ..model.mechanism import Mechanism
from .tree import Tree


TOL_LINE = 1e-9


@dataclass(frozen=True)
class CoaxialGroup:
    """Links turning about one line relative to ``carrier`` (carrier included first)."""

    carrier: int
    label: str
    members: tuple[int, ...]
    direction: np.ndarray  # reference direction of the line, in the carrier frame


@dataclass(frozen=True, eq=False)
class Circuit:
    """Fundamental circuit of gear pair ``gear`` (index into mech.gears): links j, k, carrier c.

    ``row`` is the constraint theta_{j,c} - e theta_{k,c} = 0 as a row over real joints;
    ``geometry`` is None for an ideal coupling without mesh point.
    """

    gear: int
    j: int
    k: int
    carrier: int
    ratio: float
    row: np.ndarray
    zj: np.ndarray  # axis of j relative to c, carrier frame
    zk: np.ndarray
    geometry: GearGeometry | None
    # (B, A) real joint indices of a joint coupling q_B = ratio * q_A (GearPair.joints):
    # row = e_B - ratio e_A; the ideal mesh torque acts on both joints, each joint's parent
    # taking the reaction (``carrier`` is then B's parent, for display).
    joints: tuple[int, int] | None = None
    # theta_{j,c} as a row (J,) over real joint angles (rad per rad): gear j's rotation
    # relative to its carrier about z_j, the sum of the coaxial joints between them (each
    # coefficient an integer); None for a joint coupling
    row_j: np.ndarray | None = None
    # a screw's (GearPair.screw) axis line: a point on it in the carrier frame (m); None otherwise
    axis_point: np.ndarray | None = None
    # a worm pair's (GearPair.worm) geometry in the carrier frame (model.worms.WormGeometry)
    worm: object = None
    # a belt's (GearPair.belt) geometry in the carrier frame (model.belts.BeltGeometry)
    belt: object = None


@dataclass(frozen=True, eq=False)
class Analysis:
    """Derived topology of a mechanism; computed once, never mutated."""

    mech: Mechanism
    tree: Tree
    canonical_parent: tuple
    label: tuple             # axis label of each link's canonical edge (None for base)
    level: tuple
    primary: tuple[int, ...]   # EOLC, base first
    independent: tuple[int, ...]  # joint index (or -1) of each independent coordinate
    independent_names: tuple[str, ...]
    groups: tuple[CoaxialGroup, ...]
    circuits: tuple[Circuit, ...]
    S: np.ndarray              # (J, dof): q = S q_ind
    motor_links: tuple[int, ...]
    motor_stators: tuple[int, ...]
    A: np.ndarray              # (dof, M) structure matrix: motor angles = A^T q_ind
    transmission_lines: tuple[tuple[int, ...], ...]
    pseudo_triangular: bool
    schedule: tuple[tuple[int, ...], ...] = field(default=())
    # per motor: ((joint index, coefficient), ...) for a transmission motor (Motor.joints),
    # None for a motor acting between its link and stator; () when no motor has joints
    motor_joints: tuple = ()
    open_loop: str = "chain"   # "tree": primary links form a tree (Mechanism.open_loop)
    # positions in ``circuits`` of each redundant gear set (kinematically consistent pairs
    # beyond the rank of the circuit rows): loads shared by mesh stiffness, min sum t^2/k
    redundant: tuple[tuple[int, ...], ...] = ()

    @cached_property
    def mesh_rate_rows(self) -> np.ndarray:
        """(G, dof): theta'_{j,c} = mesh_rate_rows[ci] . q'_ind, each circuit's rate of gear
        j relative to its carrier (rad/s), from the independent joint rates alone (zeros for
        a joint coupling).  Coefficients within 1e-12 of the row's largest are exactly 0, so
        a gear that holds still on its carrier has an exactly zero rate in any frames: the
        sign that turns a mesh friction couple on comes from joint rates, never from world
        angular velocities (whose difference leaves ~1e-17 of rounding in turned frames)."""
        rows = np.zeros((len(self.circuits), self.dof))
        for ci, c in enumerate(self.circuits):
            if c.row_j is not None:
                r = c.row_j @ self.S
                r[np.abs(r) <= 1e-12 * max(np.abs(r).max(initial=0.0), 1.0)] = 0.0
                rows[ci] = r
        rows.setflags(write=False)
        return rows

    @property
    def prismatic_independent(self) -> list[str]:
        """Names of the independent coordinates that are prismatic joints (m, not rad)."""
        return [n for n, ji in zip(self.independent_names, self.independent)
                if ji >= 0 and self.mech.joints[ji].type == "prismatic"]

    @property
    def dof(self) -> int:
        """Degrees of freedom: the number of independent coordinates."""
        return self.S.shape[1]

    @property
    def names(self):
        """Link names, indexed by link id."""
        return self.tree.links

    def name_of(self, ids) -> list[str]:
        """Names of the links ``ids``."""
        return [self.tree.links[i] for i in ids]

    @property
    def secondary(self) -> list[int]:
        """Secondary links (gears and shafts carried by a primary link), ids."""
        return [i for i in self.tree.moving if i not in self.primary]

    @property
    def carriers(self) -> dict[str, str]:
        """Carrier (canonical parent) of every secondary link, by name."""
        return {self.names[i]: self.names[self.canonical_parent[i]] for i in self.secondary}


def collinear(o1, z1, o2, z2, scale=1.0) -> bool:
    """True if the lines (o1, z1) and (o2, z2) coincide (unit directions; tolerance TOL_LINE, lengths scaled by ``scale``, m)."""
    if np.linalg.norm(np.cross(z1, z2)) > TOL_LINE:
        return False
    d = o2 - o1
    return np.linalg.norm(d - (d @ z1) * z1) <= TOL_LINE * max(scale, 1.0)


def first_collinear(O, Z, o, z, scale=1.0):
    """Index of the first line (origins O (k, 3), unit directions Z (k, 3)) that coincides
    with the line (o, z) as :func:`collinear` decides, or None."""
    d = o - O
    hit = ((np.linalg.norm(np.cross(Z, z), axis=1) <= TOL_LINE)
           & (np.linalg.norm(d - np.sum(d * Z, axis=1)[:, None] * Z, axis=1) <= TOL_LINE * max(scale, 1.0)))
    k = np.flatnonzero(hit)
    return int(k[0]) if k.size else None
