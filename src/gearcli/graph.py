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

from dataclasses import dataclass, field

import numpy as np

from .errors import Collector
from .gears import GearGeometry, gear_geometry
from .kinematics import forward
from .model import Mechanism
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

    def to_dict(self) -> dict:
        """Machine-readable summary (the ``gearcli graph --json`` output)."""
        mech, n = self.mech, self.names
        return {
            "mechanism": mech.name,
            "dof": self.dof,
            "levels": {n[i]: self.level[i] for i in range(len(n))},
            "primary": [n[i] for i in self.primary],
            "secondary": [n[i] for i in self.secondary],
            "carriers": self.carriers,
            "canonical_graph": {
                "thin_edges": [
                    {"parent": n[self.canonical_parent[i]], "child": n[i], "label": self.label[i]}
                    for i in self.tree.moving
                ],
                "heavy_edges": [
                    {"pair": mech.gears[c.gear].name, "links": [n[c.j], n[c.k]], "carrier": n[c.carrier]}
                    for c in self.circuits
                ],
            },
            "coaxial_groups": [
                {"carrier": n[g.carrier], "label": g.label, "links": [n[i] for i in g.members[1:]]}
                for g in self.groups if len(g.members) > 2
            ],
            "fundamental_circuits": [
                {"pair": mech.gears[c.gear].name, "j": n[c.j], "k": n[c.k], "carrier": n[c.carrier],
                 "ratio": c.ratio, "equation": _equation(mech, n, c)}
                for c in self.circuits
            ],
            "transmission_lines": [[n[i] for i in line] for line in self.transmission_lines],
            "independent_joints": list(self.independent_names),
            "motors": [m.name for m in mech.motors],
            "structure_matrix": self.A.tolist(),
            "pseudo_triangular": self.pseudo_triangular,
            "solve_order": [[n[i] for i in block] for block in self.schedule],
        } | ({"open_loop": "tree"} if self.open_loop == "tree" else {})


def _equation(mech: Mechanism, n, c: Circuit) -> str:
    if c.joints is not None:
        b, a = (mech.joints[x].name for x in c.joints)
        return f"q_{b} = {c.ratio:.6g} * q_{a}"
    return f"theta_{n[c.j]},{n[c.carrier]} = {c.ratio:.6g} * theta_{n[c.k]},{n[c.carrier]}"


def _collinear(o1, z1, o2, z2, scale=1.0) -> bool:
    if np.linalg.norm(np.cross(z1, z2)) > TOL_LINE:
        return False
    d = o2 - o1
    return np.linalg.norm(d - (d @ z1) * z1) <= TOL_LINE * max(scale, 1.0)


def analyse(mech: Mechanism) -> Analysis:
    """Canonical graph, levels, circuits, structure matrix and schedule of ``mech``.

    Raises :class:`~gearcli.errors.MechanismError` listing every structural problem.
    """
    col = Collector(mech.source, mech.lines)
    tree = build_tree(mech, col)
    col.raise_if_any()
    L, J = len(tree.links), len(mech.joints)
    idx = tree.index
    home = forward(mech, tree, np.zeros((1, J)))
    zw = [home.Rj[ji][0, :, 2] for ji in range(J)]   # joint axes, world, home
    ow = [home.oj[ji][0] for ji in range(J)]
    scale = max([1.0] + [float(np.linalg.norm(x)) for x in ow])

    # --- canonical graph -------------------------------------------------------------
    cparent = [None] * L
    for ji in tree.order:
        c = idx[mech.joints[ji].child]
        p = tree.parent[c]
        while p != tree.base:
            jp = tree.parent_joint[p]
            if not _collinear(ow[jp], zw[jp], ow[ji], zw[ji], scale):
                break
            if mech.joints[jp].type != "revolute" or mech.joints[ji].type != "revolute":
                break  # a slider on the line of a revolute joint is not coaxial with it
            p = tree.parent[p]
        cparent[c] = p
    jin = tree.parent_joint  # joint into each link; its axis is the link's canonical axis

    # labels: one per distinct line in space (explicit labels override the name); the
    # axes of the chain base -> end-effector are named first (a, b, c, ... as in the paper)
    on_chain = set()
    x = idx[mech.end_effector]
    while x != tree.base and x is not None:
        on_chain.add(x)
        x = cparent[x]
    lines: list[tuple[np.ndarray, np.ndarray, str]] = []
    label = [None] * L
    explicit: dict[str, int] = {}
    for ji in sorted(tree.order, key=lambda ji: idx[mech.joints[ji].child] not in on_chain):
        c = idx[mech.joints[ji].child]
        for k, (o, z, lab) in enumerate(lines):
            if _collinear(o, z, ow[ji], zw[ji], scale):
                break
        else:
            lines.append((ow[ji], zw[ji], _auto_label(len(lines))))
            k = len(lines) - 1
        given = mech.joints[ji].label
        if given is not None:
            if given in explicit and explicit[given] != k:
                col.add(f"{mech.joints[ji].path}.label", f"label '{given}' is given to joints whose axes are not collinear")
            explicit[given] = k
            o, z, _ = lines[k]
            lines[k] = (o, z, given)
        label[c] = k
    label = [None if k is None else lines[k][2] for k in label]

    level = [0] * L
    for ji in tree.order:
        c = idx[mech.joints[ji].child]
        level[c] = level[cparent[c]] + 1

    # canonical angle of each link (about its own joint axis) in real joint angles
    canon = np.zeros((L, J))
    for c in tree.moving:
        p = cparent[c]
        for ji in tree.path_up(c, p):
            canon[c, ji] = float(np.sign(zw[ji] @ zw[jin[c]]))

    # coaxial groups: carrier + children on one line
    groups: list[CoaxialGroup] = []
    for p in range(L):
        kids = [c for c in tree.moving if cparent[c] == p]
        done: set[int] = set()
        for c in kids:
            if c in done:
                continue
            same = [d for d in kids if d not in done and _collinear(ow[jin[c]], zw[jin[c]], ow[jin[d]], zw[jin[d]], scale)
                    and mech.joints[jin[d]].type == mech.joints[jin[c]].type]
            done.update(same)
            Rp = home.R[p][0]
            groups.append(CoaxialGroup(p, label[c], tuple([p] + same), Rp.T @ zw[jin[c]]))

    # --- primary chain -------------------------------------------------------------------
    ee = idx[mech.end_effector]
    primary = [ee]
    while primary[-1] != tree.base:
        primary.append(cparent[primary[-1]])
    primary = primary[::-1]
    if len(primary) < 2:
        col.add("end_effector", "the end-effector must be a moving link, not the base")
        col.raise_if_any()

    def relative(x: int, c: int, g: CoaxialGroup):
        """Row (over real joints) of the rotation of x relative to c about x's axis, and
        that axis in the world frame (home)."""
        ref = zw[jin[g.members[1]]]

        def phi(m):
            return np.zeros(J) if m == g.carrier else canon[m] * float(zw[jin[m]] @ ref)
        z = zw[jin[x]] if x != g.carrier else zw[jin[c]]
        return (phi(x) - phi(c)) * float(z @ ref), z

    def groups_of(x):
        return [g for g in groups if x in g.members]

    # --- gear pairs: carriers, circuits, geometry -----------------------------------------
    circuits: list[Circuit] = []
    jidx = {jt.name: ji for ji, jt in enumerate(mech.joints)}
    for gi, gp in enumerate(mech.gears):
        j, k = idx[gp.j], idx[gp.k]
        if gp.joints is not None and gp.mesh_point is None:
            circ = _joint_coupling(mech, tree, jidx, gi, gp, col)
            if circ is not None:
                circuits.append(circ)
            continue
        cands = {}
        for gj in groups_of(j):
            for gk in groups_of(k):
                if gj is gk:
                    continue
                for c in set(gj.members) & set(gk.members) - {j, k}:
                    cands[c] = (gj, gk)
        if gp.carrier is not None:
            c = idx[gp.carrier]
            if c not in cands:
                col.add(f"{gp.path}.carrier", f"'{gp.carrier}' cannot carry gears '{gp.j}' and '{gp.k}': "
                        f"both gear axes must be fixed in the carrier"
                        + (f" (possible carrier: {', '.join(tree.links[x] for x in sorted(cands))})" if cands else ""))
                continue
        elif len(cands) == 1:
            c = next(iter(cands))
        elif not cands:
            col.add(f"{gp.path}.links", f"gears '{gp.j}' and '{gp.k}' share no carrier: no link holds both "
                    "gear axes fixed (each gear must turn about a line fixed in the carrier)")
            continue
        else:
            col.add(f"{gp.path}", f"gears '{gp.j}' and '{gp.k}' have several possible carriers "
                    f"({', '.join(tree.links[x] for x in sorted(cands))}): give carrier")
            continue
        gj, gk = cands[c]
        row_j, zj_w = relative(j, c, gj)
        row_k, zk_w = relative(k, c, gk)
        Rc, oc = home.R[c][0], home.o[c][0]
        geom = None
        ratio = gp.ratio
        if gp.mesh_point is not None:
            pj = ow[jin[j]] if j != gj.carrier else ow[jin[c]]
            pk = ow[jin[k]] if k != gk.carrier else ow[jin[c]]
            geom, probs = gear_geometry(gp.kind, gp.mesh_point, Rc.T @ (pj - oc), Rc.T @ zj_w,
                                        Rc.T @ (pk - oc), Rc.T @ zk_w, gp.teeth, gp.ratio,
                                        gp.cone_angles, (gp.j, gp.k))
            for fld, msg in probs:
                col.add(f"{gp.path}.{fld}", msg)
            if geom is None:
                continue
            ratio = geom.ratio
        if ratio is None:
            continue
        circuits.append(Circuit(gi, j, k, c, float(ratio), row_j - ratio * row_k,
                                Rc.T @ zj_w, Rc.T @ zk_w, geom))
    col.raise_if_any()

    # --- degrees of freedom, independent coordinates ---------------------------------------
    G = len(circuits)
    Gam = np.array([c.row for c in circuits]).reshape(G, J)
    rank = np.linalg.matrix_rank(Gam) if G else 0
    if rank < G:
        _, sv, Vt = np.linalg.svd(Gam.T)
        null = Vt[rank:]  # left null vectors of Gam
        involved = sorted({i for v in null for i in np.flatnonzero(np.abs(v) > 1e-8)})
        col.add("gears", "redundant gear pairs make the loads statically indeterminate: "
                + ", ".join(f"'{mech.gears[circuits[i].gear].name}' ({mech.gears[circuits[i].gear].path})"
                            for i in involved))
        col.raise_if_any()
    dof = J - G
    chain = primary[1:]
    open_loop = "tree" if mech.open_loop == "tree" else "chain"
    if open_loop == "tree":
        # every link whose own joint is not made dependent by a pair (its first link j)
        dependent = {c.j for c in circuits}
        chain = [idx[jt.child] for jt in mech.joints if idx[jt.child] not in dependent]
        primary = [tree.base] + chain
        if len(chain) != dof:
            col.add("gears", f"the mechanism has {dof} degrees of freedom ({J} joints - {G} gear pairs "
                    f"and couplings) but {len(chain)} joints are not made dependent by a pair")
            col.raise_if_any()
        B = np.zeros((dof, J))
        for r, c in enumerate(chain):
            B[r, jin[c]] = 1.0
    elif len(chain) != dof:
        col.add("end_effector", f"the mechanism has {dof} degrees of freedom ({J} joints - {G} gear pairs) "
                f"but its equivalent open-loop chain {' -> '.join(tree.links[i] for i in primary)} has "
                f"{len(chain)} joints")
        col.raise_if_any()
    else:
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
        jt = jin[c]
        independent.append(jt if open_loop == "tree" or idx[mech.joints[jt].parent] == cparent[c] else -1)
    independent_names = tuple(mech.joints[jt].name if jt >= 0 else f"{tree.links[cparent[c]]}-{tree.links[c]}"
                              for jt, c in zip(independent, chain))

    # --- motors and structure matrix -------------------------------------------------------
    if len(mech.motors) != dof:
        col.add("motors", f"{len(mech.motors)} motor(s) for {dof} degree(s) of freedom: "
                "a mechanism needs one motor per degree of freedom")
    mlinks, mstators, mrows, mjoints = [], [], [], []
    for m in mech.motors:
        x = idx[m.link]
        if m.joints:
            row = np.zeros(J)
            pairs = []
            for name, coef in m.joints:
                if name not in jidx:
                    col.add(f"{m.path}.joints", f"motor '{m.name}' drives unknown joint '{name}'")
                    continue
                row[jidx[name]] += coef
                pairs.append((jidx[name], float(coef)))
            mlinks.append(x)
            mstators.append(idx[m.stator] if m.stator is not None else tree.parent[x])
            mrows.append(row)
            mjoints.append(tuple(pairs))
            continue
        if x == tree.base:
            col.add(f"{m.path}.link", "a motor cannot drive the base")
            continue
        s = idx[m.stator] if m.stator is not None else cparent[x]
        g = next((g for g in groups_of(x) if s in g.members and x in g.members and s != x), None)
        if g is None:
            col.add(f"{m.path}.stator", f"stator link '{tree.links[s]}' does not share the axis of input link '{m.link}'")
            continue
        row, _ = relative(x, s, g)
        mlinks.append(x)
        mstators.append(s)
        mrows.append(row)
        mjoints.append(None)
    col.raise_if_any()
    mrows = np.array(mrows).reshape(len(mrows), J)
    AT = mrows @ S
    AT[np.abs(AT) < 1e-15] = 0.0
    if np.linalg.matrix_rank(AT) < dof:
        col.add("motors", "the motors do not drive every degree of freedom (structure matrix is singular)")
        col.raise_if_any()

    # --- transmission lines ------------------------------------------------------------------
    heavy: dict[int, list[int]] = {i: [] for i in range(L)}
    for c in circuits:
        heavy[c.j].append(c.k)
        heavy[c.k].append(c.j)
    pset = set(primary)
    tlines: list[tuple[int, ...]] = []

    def extend(path):
        for nb in heavy[path[-1]]:
            if nb in path:
                continue
            if nb in pset:
                tlines.append(tuple(path + [nb]))
            else:
                extend(path + [nb])
    for x in mlinks:
        if x in pset:
            tlines.append((x,))
        else:
            extend([x])
    ends = [line[-1] for line in tlines]
    pseudo = all(ends.count(p) == 1 for p in chain)

    an = Analysis(mech, tree, tuple(cparent), tuple(label), tuple(level), tuple(primary),
                  tuple(independent), independent_names, tuple(groups), tuple(circuits), canon, S,
                  tuple(mlinks), tuple(mstators), mrows, AT.T.copy(), tuple(tlines), pseudo,
                  motor_joints=tuple(mjoints) if any(x is not None for x in mjoints) else (),
                  open_loop=open_loop)
    from .schedule import solution_schedule  # noqa: PLC0415

    blocks = solution_schedule(an, col)
    col.raise_if_any()
    object.__setattr__(an, "schedule", blocks)
    return an


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


def _auto_label(i: int) -> str:
    s = ""
    i += 1
    while i:
        i, r = divmod(i - 1, 26)
        s = chr(ord("a") + r) + s
    return s
