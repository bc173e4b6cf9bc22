"""Graph analysis of a geared mechanism (paper: "Graph Representation" and "Kinematics").

Links are vertices, joints thin edges labelled by their axis line, gear pairs heavy edges.
:func:`analyse` derives, once per mechanism, everything the solver needs:

* the canonical graph (Tsai 1988): a link hanging from its parent through a joint collinear
  with the parent's own joint is re-attached to the grandparent, until every thin-edged path
  from the root has distinct axis labels; the canonical parent is the link's *carrier*;
* levels (thin-edge distance from the root), primary links (the equivalent open-loop
  chain, EOLC, base -> end-effector) and secondary links;
* coaxial groups (a carrier and the links turning about one line relative to it), the
  carrier and fundamental circuit of each gear pair, transmission lines;
* the linear map q = S q_ind from the independent (EOLC) joint angles to every real joint
  angle, and the structure matrix A (input rotations = A^T q_ind, paper Eq. 22);
* the solution schedule (:mod:`gearcli.schedule`).

Problems are reported with the file and YAML path of the offending element.
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import NamedTuple

import numpy as np

from ..errors import Collector
from ..model.gears import GearGeometry, gear_geometry
from .home import Placements, home_placements
from ..model.mechanism import Mechanism
from .schedule import solution_schedule
from .tree import Tree, build_tree

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
    canon_rows: np.ndarray     # (L, J): canonical angle of link i in real joint angles
    S: np.ndarray              # (J, dof): q = S q_ind
    motor_links: tuple[int, ...]
    motor_stators: tuple[int, ...]
    motor_rows: np.ndarray     # (M, J): motor input rotation in real joint angles
    A: np.ndarray              # (dof, M) structure matrix: motor angles = A^T q_ind
    transmission_lines: tuple[tuple[int, ...], ...]
    pseudo_triangular: bool
    schedule: tuple[tuple[int, ...], ...] = field(default=())
    # per motor: ((joint index, coefficient), ...) for a transmission motor (Motor.joints),
    # None for a motor acting between its link and stator; () when no motor has joints
    motor_joints: tuple = ()
    open_loop: str = "chain"   # "tree": primary links form a tree (Mechanism.open_loop)

    @property
    def dof(self) -> int:
        return self.S.shape[1]

    @property
    def names(self):
        return self.tree.links

    def name_of(self, ids) -> list[str]:
        return [self.tree.links[i] for i in ids]

    @property
    def secondary(self) -> list[int]:
        return [i for i in self.tree.moving if i not in self.primary]

    @property
    def carriers(self) -> dict[str, str]:
        return {self.names[i]: self.names[self.canonical_parent[i]] for i in self.secondary}


def _collinear(o1, z1, o2, z2, scale=1.0) -> bool:
    if np.linalg.norm(np.cross(z1, z2)) > TOL_LINE:
        return False
    d = o2 - o1
    return np.linalg.norm(d - (d @ z1) * z1) <= TOL_LINE * max(scale, 1.0)


def _first_collinear(O, Z, o, z, scale=1.0):
    """Index of the first line (origins O (k, 3), unit directions Z (k, 3)) that coincides
    with the line (o, z) as :func:`_collinear` decides, or None."""
    d = o - O
    hit = ((np.linalg.norm(np.cross(Z, z), axis=1) <= TOL_LINE)
           & (np.linalg.norm(d - np.sum(d * Z, axis=1)[:, None] * Z, axis=1) <= TOL_LINE * max(scale, 1.0)))
    k = np.flatnonzero(hit)
    return int(k[0]) if k.size else None


def analyse(mech: Mechanism) -> Analysis:
    """Canonical graph, levels, circuits, structure matrix and schedule of ``mech``.

    The steps follow the paper's graph analysis, one private function each; problems are
    collected in a :class:`~gearcli.errors.Collector` and raised after each step that
    later steps depend on.  Raises :class:`~gearcli.errors.MechanismError` listing every
    structural problem.
    """
    col = Collector(mech.source, mech.lines)
    tree = build_tree(mech, col)
    col.raise_if_any()
    h = _home_axes(mech, tree)
    cparent = _canonical_parents(h)
    primary = _eolc(h, cparent)
    label = _axis_labels(h, set(primary[1:]), col)
    level = _levels(h, cparent)
    canon = _canonical_angle_rows(h, cparent)
    groups = _coaxial_groups(h, cparent, label)
    if len(primary) < 2:
        col.add("end_effector", "the end-effector must be a moving link, not the base")
        col.raise_if_any()
    circuits = _circuits(h, groups, canon, col)
    col.raise_if_any()
    ind = _independent_coordinates(h, cparent, canon, primary, circuits, col)
    mot = _motors(h, cparent, groups, canon, ind.S.shape[1], col)
    A = _structure_matrix(mot.rows, ind.S, col)
    tlines, pseudo = _transmission_lines(h, circuits, ind.primary, ind.chain, mot.links)

    an = Analysis(mech, tree, tuple(cparent), tuple(label), tuple(level), tuple(ind.primary),
                  ind.independent, ind.independent_names, tuple(groups), tuple(circuits), canon,
                  ind.S, tuple(mot.links), tuple(mot.stators), mot.rows, A, tuple(tlines), pseudo,
                  motor_joints=tuple(mot.joints) if any(x is not None for x in mot.joints) else (),
                  open_loop=ind.open_loop)
    blocks = solution_schedule(an, col)
    col.raise_if_any()
    return replace(an, schedule=blocks)


# --- home geometry ------------------------------------------------------------------------

@dataclass(frozen=True, eq=False)
class _Home:
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
        return len(self.tree.links)

    @property
    def J(self) -> int:
        return len(self.mech.joints)

    def collinear(self, a: int, b: int) -> bool:
        """True if the axis lines of joints ``a`` and ``b`` coincide (home configuration)."""
        return _collinear(self.ow[a], self.zw[a], self.ow[b], self.zw[b], self.scale)


def _home_axes(mech: Mechanism, tree: Tree) -> _Home:
    """Joint axis lines (origin ``ow``, m; unit direction ``zw``) in the world frame at
    the home configuration, where every joint coordinate is zero."""
    J = len(mech.joints)
    home = home_placements(mech, tree)
    zw = [home.Rj[ji][:, 2] for ji in range(J)]
    ow = [home.oj[ji] for ji in range(J)]
    scale = max([1.0] + [float(np.linalg.norm(x)) for x in ow])
    jidx = {jt.name: ji for ji, jt in enumerate(mech.joints)}
    return _Home(mech, tree, tree.index, jidx, tree.parent_joint, home, ow, zw, scale)


# --- canonical graph ----------------------------------------------------------------------

def _canonical_parents(h: _Home) -> list:
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


def _eolc(h: _Home, cparent: list) -> list[int]:
    """Equivalent open-loop chain: link ids base -> end-effector along canonical parents
    (base first; only the base if the end-effector is the base)."""
    primary = [h.idx[h.mech.end_effector]]
    while primary[-1] != h.tree.base:
        primary.append(cparent[primary[-1]])
    return primary[::-1]


def _axis_labels(h: _Home, on_chain: set, col: Collector) -> list:
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
        k = _first_collinear(O[:len(lines)], Z[:len(lines)], h.ow[ji], h.zw[ji], h.scale)
        if k is None:
            O[len(lines)], Z[len(lines)] = h.ow[ji], h.zw[ji]
            lines.append((h.ow[ji], h.zw[ji], _auto_label(len(lines))))
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


def _levels(h: _Home, cparent: list) -> list[int]:
    """Level of each link: list (L,) of its thin-edge distance from the root in the
    canonical graph (base 0)."""
    level = [0] * h.L
    for ji in h.tree.order:
        c = h.idx[h.mech.joints[ji].child]
        level[c] = level[cparent[c]] + 1
    return level


def _canonical_angle_rows(h: _Home, cparent: list) -> np.ndarray:
    """(L, J) array: row i is the canonical angle of link i (its rotation relative to its
    canonical parent, about its own joint axis, rad) in real joint angles; entries are
    +-1 on the collinear joints between the link and its canonical parent, 0 elsewhere."""
    canon = np.zeros((h.L, h.J))
    for c in h.tree.moving:
        for ji in h.tree.path_up(c, cparent[c]):
            canon[c, ji] = float(np.sign(h.zw[ji] @ h.zw[h.jin[c]]))
    return canon


def _coaxial_groups(h: _Home, cparent: list, label: list) -> list[CoaxialGroup]:
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


def _groups_of(groups: list[CoaxialGroup], x: int) -> list[CoaxialGroup]:
    return [g for g in groups if x in g.members]


def _relative_rotation(h: _Home, canon: np.ndarray, x: int, c: int, g: CoaxialGroup):
    """Rotation of link ``x`` relative to link ``c`` about x's axis, both in coaxial group
    ``g``: its row (J,) over real joint angles (rad per rad), and that axis (3,) in the
    world frame at home (c's axis if x is the group's carrier)."""
    zw, jin = h.zw, h.jin
    ref = zw[jin[g.members[1]]]

    def phi(m):
        return np.zeros(h.J) if m == g.carrier else canon[m] * float(zw[jin[m]] @ ref)
    z = zw[jin[x]] if x != g.carrier else zw[jin[c]]
    return (phi(x) - phi(c)) * float(z @ ref), z


# --- gear pairs: carriers, fundamental circuits, geometry ----------------------------------

def _circuits(h: _Home, groups: list[CoaxialGroup], canon: np.ndarray, col: Collector) -> list[Circuit]:
    """Fundamental circuit of each gear pair and joint coupling, in ``mech.gears`` order
    (pairs with a problem are reported to ``col`` and left out)."""
    circuits: list[Circuit] = []
    for gi, gp in enumerate(h.mech.gears):
        j, k = h.idx[gp.j], h.idx[gp.k]
        if gp.joints is not None and gp.mesh_point is None:
            circ = _joint_coupling(h.mech, h.tree, h.jidx, gi, gp, col)
        else:
            circ = _gear_circuit(h, groups, canon, gi, gp, j, k, col)
        if circ is not None:
            circuits.append(circ)
    return circuits


def _gear_circuit(h: _Home, groups, canon, gi: int, gp, j: int, k: int, col: Collector) -> Circuit | None:
    """Circuit of gear pair ``gp`` between links j and k: theta_{j,c} - e theta_{k,c} = 0,
    with the ratio e given or derived from the mesh geometry."""
    found = _gear_carrier(h, groups, gp, j, k, col)
    if found is None:
        return None
    c, gj, gk = found
    row_j, zj_w = _relative_rotation(h, canon, j, c, gj)
    row_k, zk_w = _relative_rotation(h, canon, k, c, gk)
    Rc = h.kin.R[c]
    geom = None
    ratio = gp.ratio
    if gp.mesh_point is not None:
        geom = _mesh_geometry(h, gp, j, k, c, gj, gk, zj_w, zk_w, col)
        if geom is None:
            return None
        ratio = geom.ratio
    if ratio is None:
        return None
    return Circuit(gi, j, k, c, float(ratio), row_j - ratio * row_k, Rc.T @ zj_w, Rc.T @ zk_w, geom)


def _gear_carrier(h: _Home, groups, gp, j: int, k: int, col: Collector):
    """Carrier c of gear pair ``gp``: a link sharing a coaxial group with each gear (both
    gear axes fixed in it), given or unique.  Returns (c, group of j, group of k), or None
    with an issue."""
    cands = {}
    for gj in _groups_of(groups, j):
        for gk in _groups_of(groups, k):
            if gj is gk:
                continue
            for c in set(gj.members) & set(gk.members) - {j, k}:
                cands[c] = (gj, gk)
    names = h.tree.links
    if gp.carrier is not None:
        c = h.idx[gp.carrier]
        if c not in cands:
            col.add(f"{gp.path}.carrier", f"'{gp.carrier}' cannot carry gears '{gp.j}' and '{gp.k}': "
                    f"both gear axes must be fixed in the carrier"
                    + (f" (possible carrier: {', '.join(names[x] for x in sorted(cands))})" if cands else ""))
            return None
    elif len(cands) == 1:
        c = next(iter(cands))
    elif not cands:
        col.add(f"{gp.path}.links", f"gears '{gp.j}' and '{gp.k}' share no carrier: no link holds both "
                "gear axes fixed (each gear must turn about a line fixed in the carrier)")
        return None
    else:
        col.add(f"{gp.path}", f"gears '{gp.j}' and '{gp.k}' have several possible carriers "
                f"({', '.join(names[x] for x in sorted(cands))}): give carrier")
        return None
    return (c, *cands[c])


def _mesh_geometry(h: _Home, gp, j, k, c, gj, gk, zj_w, zk_w, col: Collector) -> GearGeometry | None:
    """Gear geometry of ``gp`` from its mesh point, with both gear axes (points, m, and
    directions) expressed in the carrier frame of c; None (with issues) if inconsistent."""
    Rc, oc = h.kin.R[c], h.kin.o[c]
    ow, jin = h.ow, h.jin
    pj = ow[jin[j]] if j != gj.carrier else ow[jin[c]]
    pk = ow[jin[k]] if k != gk.carrier else ow[jin[c]]
    geom, probs = gear_geometry(gp.kind, gp.mesh_point, Rc.T @ (pj - oc), Rc.T @ zj_w,
                                Rc.T @ (pk - oc), Rc.T @ zk_w, gp.teeth, gp.ratio,
                                gp.cone_angles, (gp.j, gp.k))
    for fld, msg in probs:
        col.add(f"{gp.path}.{fld}", msg)
    return geom


def _joint_coupling(mech: Mechanism, tree: Tree, jidx: dict, gi: int, gp, col: Collector) -> Circuit | None:
    """Circuit of an ideal coupling of two joint coordinates, q_B = ratio * q_A."""
    ok = True
    for name in gp.joints:
        if name not in jidx:
            col.add(f"{gp.path}.joints", f"coupling '{gp.name}' names unknown joint '{name}'")
            ok = False
    if not ok:
        return None
    b, a = (jidx[name] for name in gp.joints)
    if a == b:
        col.add(f"{gp.path}.joints", f"coupling '{gp.name}' couples joint '{gp.joints[0]}' to itself")
        return None
    if gp.ratio is None or gp.ratio == 0:
        col.add(f"{gp.path}.ratio", f"coupling '{gp.name}' needs a nonzero ratio")
        return None
    row = np.zeros(len(mech.joints))
    row[b] = 1.0
    row[a] -= gp.ratio
    jb, ja = mech.joints[b], mech.joints[a]
    return Circuit(gi, tree.index[jb.child], tree.index[ja.child], tree.index[jb.parent], float(gp.ratio),
                   row, jb.R_pj[:, 2].copy(), ja.R_pj[:, 2].copy(), None, joints=(b, a))


# --- degrees of freedom, independent coordinates -------------------------------------------

class _Independent(NamedTuple):
    """Independent coordinates q_ind (dof of them) and q = S q_ind."""

    primary: list[int]     # primary links, base first (the EOLC, or the tree's free links)
    chain: list[int]       # moving primary links, one per independent coordinate
    open_loop: str         # "chain" or "tree"
    S: np.ndarray          # (J, dof): every real joint angle from the independent ones
    independent: tuple     # (dof,) joint id of each coordinate, -1 for a canonical angle
    independent_names: tuple


def _independent_coordinates(h: _Home, cparent: list, canon: np.ndarray, primary: list[int],
                             circuits: list[Circuit], col: Collector) -> _Independent:
    """Degrees of freedom (J - G), the independent coordinates and S (J, dof) solving the
    circuit rows Gam q = 0 together with q_ind = B q (canonical angles of the EOLC, or the
    free joints of a tree)."""
    G, J = len(circuits), h.J
    Gam = _circuit_matrix(h, circuits, col)
    dof = J - G
    open_loop = "tree" if h.mech.open_loop == "tree" else "chain"
    if open_loop == "tree":
        primary, chain, B = _tree_coordinates(h, circuits, dof, col)
    else:
        chain = primary[1:]
        if len(chain) != dof:
            col.add("end_effector", f"the mechanism has {dof} degrees of freedom ({J} joints - {G} gear pairs) "
                    f"but its equivalent open-loop chain {' -> '.join(h.tree.links[i] for i in primary)} has "
                    f"{len(chain)} joints")
            col.raise_if_any()
        B = canon[chain]
    Mfull = np.vstack([Gam, B])
    if np.linalg.matrix_rank(Mfull) < J:
        col.add("gears", "the gear trains lock the equivalent open-loop chain: its joint angles do not "
                "determine the motion of every link")
        col.raise_if_any()
    S = np.linalg.solve(Mfull, np.vstack([np.zeros((G, dof)), np.eye(dof)]))
    S[np.abs(S) < 1e-15] = 0.0
    independent = []
    for c in chain:
        jt = h.jin[c]
        independent.append(jt if open_loop == "tree" or h.idx[h.mech.joints[jt].parent] == cparent[c] else -1)
    names = tuple(h.mech.joints[jt].name if jt >= 0 else f"{h.tree.links[cparent[c]]}-{h.tree.links[c]}"
                  for jt, c in zip(independent, chain))
    return _Independent(primary, chain, open_loop, S, tuple(independent), names)


def _circuit_matrix(h: _Home, circuits: list[Circuit], col: Collector) -> np.ndarray:
    """(G, J) matrix Gam of the circuit rows; raises if it is rank deficient (redundant
    gear pairs, whose loads would be statically indeterminate)."""
    G = len(circuits)
    Gam = np.array([c.row for c in circuits]).reshape(G, h.J)
    # rows scaled to unit length; a pair redundant within the ratio tolerance (1e-6, as
    # ratios are checked against the geometry) is redundant: rounded mesh points must not
    # turn two redundant planets into "0 degrees of freedom"
    Gn = Gam / np.maximum(np.linalg.norm(Gam, axis=1, keepdims=True), 1e-300)
    sv = np.linalg.svd(Gn, compute_uv=False) if G else np.zeros(0)
    rank = int(np.sum(sv > 1e-6 * sv[0])) if G else 0
    if rank < G:
        _, sv, Vt = np.linalg.svd(Gn.T)
        null = Vt[rank:]  # left null vectors of Gam
        involved = sorted({i for v in null for i in np.flatnonzero(np.abs(v) > 1e-8)})
        gears = h.mech.gears
        col.add("gears", "redundant gear pairs make the loads statically indeterminate: "
                + ", ".join(f"'{gears[circuits[i].gear].name}' ({gears[circuits[i].gear].path})"
                            for i in involved))
        col.raise_if_any()
    return Gam


def _tree_coordinates(h: _Home, circuits: list[Circuit], dof: int, col: Collector):
    """Open-loop tree (``open_loop: tree``): every link whose own joint is not made dependent
    by a pair (its first link j) is primary.  Returns (primary, chain, B (dof, J))."""
    dependent = {c.j for c in circuits}
    chain = [h.idx[jt.child] for jt in h.mech.joints if h.idx[jt.child] not in dependent]
    primary = [h.tree.base] + chain
    if len(chain) != dof:
        col.add("gears", f"the mechanism has {dof} degrees of freedom ({h.J} joints - {len(circuits)} gear pairs "
                f"and couplings) but {len(chain)} joints are not made dependent by a pair")
        col.raise_if_any()
    B = np.zeros((dof, h.J))
    for r, c in enumerate(chain):
        B[r, h.jin[c]] = 1.0
    return primary, chain, B


# --- motors and structure matrix -----------------------------------------------------------

class _Motors(NamedTuple):
    """Per motor (``mech.motors`` order): input link, stator link, input rotation row."""

    links: list[int]
    stators: list[int]
    rows: np.ndarray       # (M, J): motor input rotation in real joint angles
    joints: list           # ((joint id, coefficient), ...) of a transmission motor, else None


def _motors(h: _Home, cparent: list, groups: list[CoaxialGroup], canon: np.ndarray, dof: int,
            col: Collector) -> _Motors:
    """Input rotation of every motor as a row over real joint angles (one motor per dof)."""
    if len(h.mech.motors) != dof:
        col.add("motors", f"{len(h.mech.motors)} motor(s) for {dof} degree(s) of freedom: "
                "a mechanism needs one motor per degree of freedom")
    found = []
    for m in h.mech.motors:
        if m.joints:
            found.append(_transmission_motor(h, m, col))
        else:
            found.append(_link_motor(h, cparent, groups, canon, m, col))
    found = [f for f in found if f is not None]
    col.raise_if_any()
    rows = np.array([f[2] for f in found]).reshape(len(found), h.J)
    return _Motors([f[0] for f in found], [f[1] for f in found], rows, [f[3] for f in found])


def _transmission_motor(h: _Home, m, col: Collector):
    """Motor driving a combination of joint coordinates (``Motor.joints``): (link, stator,
    row (J,), ((joint id, coefficient), ...)); unknown joints are reported and skipped."""
    x = h.idx[m.link]
    row = np.zeros(h.J)
    pairs = []
    for name, coef in m.joints:
        if name not in h.jidx:
            col.add(f"{m.path}.joints", f"motor '{m.name}' drives unknown joint '{name}'")
            continue
        row[h.jidx[name]] += coef
        pairs.append((h.jidx[name], float(coef)))
    return x, _link_id(h, m.stator, h.tree.parent[x]), row, tuple(pairs)


def _link_motor(h: _Home, cparent: list, groups, canon: np.ndarray, m, col: Collector):
    """Motor turning its link relative to its stator (default: the link's carrier) about
    their common axis: (link, stator, row (J,), None), or None with an issue."""
    x = h.idx[m.link]
    if x == h.tree.base:
        col.add(f"{m.path}.link", "a motor cannot drive the base")
        return None
    s = _link_id(h, m.stator, cparent[x])
    g = next((g for g in _groups_of(groups, x) if s in g.members and x in g.members and s != x), None)
    if g is None:
        col.add(f"{m.path}.stator", f"stator link '{h.tree.links[s]}' does not share the axis of input link '{m.link}'")
        return None
    row, _ = _relative_rotation(h, canon, x, s, g)
    return x, s, row, None


def _link_id(h: _Home, name: str | None, default: int) -> int:
    """Id of link ``name``, or ``default`` if no name is given."""
    return h.idx[name] if name is not None else default


def _structure_matrix(mrows: np.ndarray, S: np.ndarray, col: Collector) -> np.ndarray:
    """Structure matrix A (dof, M): motor input rotations = A^T q_ind (paper Eq. 22);
    raises if singular (some dof driven by no motor)."""
    AT = mrows @ S
    AT[np.abs(AT) < 1e-15] = 0.0
    if np.linalg.matrix_rank(AT) < S.shape[1]:
        col.add("motors", "the motors do not drive every degree of freedom (structure matrix is singular)")
        col.raise_if_any()
    return AT.T.copy()


# --- transmission lines --------------------------------------------------------------------

def _transmission_lines(h: _Home, circuits: list[Circuit], primary: list[int], chain: list[int],
                        mlinks: list[int]):
    """Transmission lines: from each motor's input link along heavy edges (gear pairs) to the
    first primary link reached (a path of link ids per branch; a single link if the input
    link is primary).  Also whether the structure matrix is pseudo-triangular: every
    primary link ends exactly one line."""
    heavy: dict[int, list[int]] = {i: [] for i in range(h.L)}
    for c in circuits:
        heavy[c.j].append(c.k)
        heavy[c.k].append(c.j)
    pset = set(primary)
    tlines: list[tuple[int, ...]] = []
    for x in mlinks:
        if x in pset:
            tlines.append((x,))
        else:
            _extend_lines([x], heavy, pset, tlines)
    ends = [line[-1] for line in tlines]
    return tlines, all(ends.count(p) == 1 for p in chain)


def _extend_lines(path: list[int], heavy: dict, pset: set, out: list) -> None:
    """Depth-first extension of ``path`` along heavy edges, appending to ``out`` every
    extension that reaches a primary link (in ``pset``)."""
    for nb in heavy[path[-1]]:
        if nb in path:
            continue
        if nb in pset:
            out.append(tuple(path + [nb]))
        else:
            _extend_lines(path + [nb], heavy, pset, out)


def _auto_label(i: int) -> str:
    s = ""
    i += 1
    while i:
        i, r = divmod(i - 1, 26)
        s = chr(ord("a") + r) + s
    return s
