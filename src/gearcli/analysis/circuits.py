"""Gear pairs: carriers, fundamental circuits (theta_j,c = e_kj theta_k,c) and mesh geometry."""
from __future__ import annotations

import numpy as np

from ..errors import Collector
from ..model.gears import GearGeometry, gear_geometry
from ..model.worms import worm_geometry
from ..model.belts import belt_geometry
from ..model.mechanism import Mechanism
from .context import Home
from .tree import Tree
from .types import Circuit, CoaxialGroup


def groups_of(groups: list[CoaxialGroup], x: int) -> list[CoaxialGroup]:
    """The coaxial groups that link ``x`` belongs to."""
    return [g for g in groups if x in g.members]


def relative_rotation(h: Home, canon: np.ndarray, x: int, c: int, g: CoaxialGroup):
    """Rotation of link ``x`` relative to link ``c`` about x's axis, both in coaxial group
    ``g``: its row (J,) over real joint angles (rad per rad), and that axis (3,) in the
    world frame at home (c's axis if x is the group's carrier)."""
    zw, jin = h.zw, h.jin
    ref = zw[jin[g.members[1]]]

    def phi(m):
        return np.zeros(h.J) if m == g.carrier else canon[m] * float(zw[jin[m]] @ ref)
    z = zw[jin[x]] if x != g.carrier else zw[jin[c]]
    return (phi(x) - phi(c)) * float(z @ ref), z


def circuits(h: Home, groups: list[CoaxialGroup], canon: np.ndarray, col: Collector) -> list[Circuit]:
    """Fundamental circuit of each gear pair and joint coupling, in ``mech.gears`` order
    (pairs with a problem are reported to ``col`` and left out)."""
    circuits: list[Circuit] = []
    for gi, gp in enumerate(h.mech.gears):
        j, k = h.idx[gp.j], h.idx[gp.k]
        if gp.joints is not None and gp.mesh_point is None:
            circ = joint_coupling(h.mech, h.tree, h.jidx, gi, gp, col)
        else:
            circ = gear_circuit(h, groups, canon, gi, gp, j, k, col)
        if circ is not None:
            circuits.append(circ)
    return circuits


def gear_circuit(h: Home, groups, canon, gi: int, gp, j: int, k: int, col: Collector) -> Circuit | None:
    """Circuit of gear pair ``gp`` between links j and k: theta_{j,c} - e theta_{k,c} = 0,
    with the ratio e given or derived from the mesh geometry."""
    if gp.reducer is not None:
        return reducer_circuit(h, groups, canon, gi, gp, j, k, col)
    if gp.screw is not None:
        return screw_circuit(h, groups, canon, gi, gp, j, k, col)
    if gp.worm is not None:
        return worm_circuit(h, groups, canon, gi, gp, j, k, col)
    if gp.belt is not None:
        return belt_circuit(h, groups, canon, gi, gp, j, k, col)
    found = gear_carrier(h, groups, gp, j, k, col)
    if found is None:
        return None
    c, gj, gk = found
    if not joint_types_fit(h, gp, c, gj, gk, col):
        return None
    row_j, zj_w = relative_rotation(h, canon, j, c, gj)
    row_k, zk_w = relative_rotation(h, canon, k, c, gk)
    Rc = h.kin.R[c]
    geom = None
    ratio = gp.ratio
    if gp.mesh_point is not None:
        geom = mesh_geometry(h, gp, j, k, c, gj, gk, zj_w, zk_w, col)
        if geom is None:
            return None
        ratio = geom.ratio
    if ratio is None:
        return None
    return Circuit(gi, j, k, c, float(ratio), row_j - ratio * row_k, Rc.T @ zj_w, Rc.T @ zk_w, geom,
                   row_j=np.rint(row_j))


def reducer_circuit(h: Home, groups, canon, gi: int, gp, j: int, k: int, col: Collector) -> Circuit | None:
    """Circuit of a coaxial reducer (:mod:`gearcli.model.reducers`): input j, output k and
    housing c (``gp.carrier``) in one coaxial group, so that the joints on the paths from the
    housing to the input and to the output turn about one line; theta_{j,c} = e theta_{k,c}
    with e = i0 (z_j . z_k) about each member's own axis (i0 is about one common axis)."""
    c = h.idx[gp.carrier]
    shared = [g for g in groups_of(groups, j) if k in g.members and c in g.members]
    if not shared:
        col.add(f"{gp.path}.links", f"the {gp.kind} reducer's input '{gp.j}', output '{gp.k}' and housing "
                f"'{gp.carrier}' do not turn about one axis: the joints from the housing to the input and to "
                "the output must be colinear (within 1e-9 rad and 1e-9 m)")
        return None
    g = shared[0]
    for n, x in enumerate((j, k)):
        if h.mech.joints[h.jin[x if x != g.carrier else c]].type != "revolute":
            col.add(f"{gp.path}.links[{n}]", f"'{h.tree.links[x]}' slides on a prismatic joint: a reducer's members turn")
            return None
    if gp.ratio is None:
        return None
    row_j, zj_w = relative_rotation(h, canon, j, c, g)
    row_k, zk_w = relative_rotation(h, canon, k, c, g)
    ratio = gp.ratio * float(np.sign(zj_w @ zk_w))
    Rc = h.kin.R[c]
    return Circuit(gi, j, k, c, ratio, row_j - ratio * row_k, Rc.T @ zj_w, Rc.T @ zk_w, None,
                   row_j=np.rint(row_j))


def screw_circuit(h: Home, groups, canon, gi: int, gp, j: int, k: int, col: Collector) -> Circuit | None:
    """Circuit of a screw (:mod:`gearcli.model.screws`): the screw j turning and the nut k
    sliding relative to the carrier c on one line; theta_{j,c} = e x_{k,c}, e = (z_k . z_j) / h."""
    types = [h.mech.joints[h.jin[x]].type for x in (j, k)]
    for n, (name, got, need) in enumerate(zip((gp.j, gp.k), types, ("revolute", "prismatic"))):
        if got != need:
            col.add(f"{gp.path}.links[{n}]", f"'{name}' {'slides' if got == 'prismatic' else 'turns'} on its joint: "
                    f"a screw's {'screw must turn on a revolute' if n == 0 else 'nut must slide on a prismatic'}"
                    " joint (links: [screw, nut])")
            return None
    found = gear_carrier(h, groups, gp, j, k, col)
    if found is None:
        return None
    c, gj, gk = found
    if not h.collinear(h.jin[j], h.jin[k]):
        col.add(f"{gp.path}.links", f"the screw '{gp.j}' and the nut '{gp.k}' are not on one line: the nut must slide "
                "along the screw's axis (within 1e-9 rad and 1e-9 m)")
        return None
    row_j, zj_w = relative_rotation(h, canon, j, c, gj)
    row_k, zk_w = relative_rotation(h, canon, k, c, gk)
    ratio = float(zk_w @ zj_w) / gp.screw.h
    Rc, oc = h.kin.R[c], h.kin.o[c]
    return Circuit(gi, j, k, c, ratio, row_j - ratio * row_k, Rc.T @ zj_w, Rc.T @ zk_w, None,
                   row_j=np.rint(row_j), axis_point=Rc.T @ (h.ow[h.jin[j]] - oc))


def worm_circuit(h: Home, groups, canon, gi: int, gp, j: int, k: int, col: Collector) -> Circuit | None:
    """Circuit of a worm pair (:mod:`gearcli.model.worms`): worm j and wheel k turning about
    perpendicular axes fixed in the carrier; theta_{j,c} = e theta_{k,c} with e from the
    geometry (the hand and the axes' directions)."""
    found = gear_carrier(h, groups, gp, j, k, col)
    if found is None:
        return None
    c, gj, gk = found
    if not joint_types_fit(h, gp, c, gj, gk, col):
        return None
    row_j, zj_w = relative_rotation(h, canon, j, c, gj)
    row_k, zk_w = relative_rotation(h, canon, k, c, gk)
    Rc, oc = h.kin.R[c], h.kin.o[c]
    pj = h.ow[h.jin[j]] if j != gj.carrier else h.ow[h.jin[c]]
    pk = h.ow[h.jin[k]] if k != gk.carrier else h.ow[h.jin[c]]
    geo, problems = worm_geometry(gp.worm, Rc.T @ (pj - oc), Rc.T @ zj_w, Rc.T @ (pk - oc), Rc.T @ zk_w, (gp.j, gp.k))
    for fld, msg in problems:
        col.add(f"{gp.path}.{fld}", msg)
    if geo is None:
        return None
    return Circuit(gi, j, k, c, geo.ratio, row_j - geo.ratio * row_k, Rc.T @ zj_w, Rc.T @ zk_w, None,
                   row_j=np.rint(row_j), worm=geo)


def belt_circuit(h: Home, groups, canon, gi: int, gp, j: int, k: int, col: Collector) -> Circuit | None:
    """Circuit of a timing belt (:mod:`gearcli.model.belts`): pulleys j and k turning about
    parallel axes fixed in the carrier; theta_{j,c} = e theta_{k,c}, e = (r_k / r_j)(z_k . z_j)."""
    found = gear_carrier(h, groups, gp, j, k, col)
    if found is None:
        return None
    c, gj, gk = found
    if not joint_types_fit(h, gp, c, gj, gk, col):
        return None
    row_j, zj_w = relative_rotation(h, canon, j, c, gj)
    row_k, zk_w = relative_rotation(h, canon, k, c, gk)
    Rc, oc = h.kin.R[c], h.kin.o[c]
    pj = h.ow[h.jin[j]] if j != gj.carrier else h.ow[h.jin[c]]
    pk = h.ow[h.jin[k]] if k != gk.carrier else h.ow[h.jin[c]]
    geo, problems = belt_geometry(gp.belt, Rc.T @ (pj - oc), Rc.T @ zj_w, Rc.T @ (pk - oc), Rc.T @ zk_w, (gp.j, gp.k))
    for fld, msg in problems:
        col.add(f"{gp.path}.{fld}", msg)
    if geo is None:
        return None
    return Circuit(gi, j, k, c, geo.ratio, row_j - geo.ratio * row_k, Rc.T @ zj_w, Rc.T @ zk_w, None,
                   row_j=np.rint(row_j), belt=geo)


def joint_types_fit(h: Home, gp, c: int, gj: CoaxialGroup, gk: CoaxialGroup, col: Collector) -> bool:
    """True if gear j turns and gear k turns (slides, for a rack) relative to the carrier;
    otherwise an issue naming the pair's link."""
    types = [h.mech.joints[h.jin[g.members[1]]].type for g in (gj, gk)]
    want = ["revolute", "prismatic" if gp.kind == "rack" else "revolute"]
    ok = True
    for i, (name, got, need) in enumerate(zip((gp.j, gp.k), types, want)):
        if got == need:
            continue
        ok = False
        if gp.kind == "rack":
            what = ("the pinion of a rack pair must turn on a revolute joint" if i == 0
                    else "the rack of a rack pair must slide on a prismatic joint")
            col.add(f"{gp.path}.links[{i}]", f"'{name}' {'slides' if got == 'prismatic' else 'turns'} relative "
                    f"to the carrier '{h.tree.links[c]}': {what} (links: [pinion, rack])")
        else:
            col.add(f"{gp.path}.links[{i}]", f"'{name}' slides on a prismatic joint relative to the carrier: "
                    f"{'an' if gp.kind[:1] in 'aeiou' else 'a'} {gp.kind} gear must turn (for a rack and pinion use kind: rack, links: [pinion, rack])")
    return ok


def gear_carrier(h: Home, groups, gp, j: int, k: int, col: Collector):
    """Carrier c of gear pair ``gp``: a link sharing a coaxial group with each gear (both
    gear axes fixed in it), given or unique.  Returns (c, group of j, group of k), or None
    with an issue."""
    cands = {}
    for gj in groups_of(groups, j):
        for gk in groups_of(groups, k):
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


def mesh_geometry(h: Home, gp, j, k, c, gj, gk, zj_w, zk_w, col: Collector) -> GearGeometry | None:
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


def joint_coupling(mech: Mechanism, tree: Tree, jidx: dict, gi: int, gp, col: Collector) -> Circuit | None:
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
