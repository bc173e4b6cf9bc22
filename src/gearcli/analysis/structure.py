"""Motors, the structure matrix A of paper Eq. (22) (input rotations = A^T q_ind) and the
transmission lines."""
from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..errors import Collector, counted
from .circuits import groups_of, relative_rotation
from .context import Home
from .types import Circuit, CoaxialGroup


class Motors(NamedTuple):
    """Per motor (``mech.motors`` order): input link, stator link, input rotation row."""

    links: list[int]
    stators: list[int]
    rows: np.ndarray       # (M, J): motor input rotation in real joint angles
    joints: list           # ((joint id, coefficient), ...) of a transmission motor, else None


def motors(h: Home, cparent: list, groups: list[CoaxialGroup], canon: np.ndarray, dof: int,
            col: Collector) -> Motors:
    """Input rotation of every motor as a row over real joint angles (one motor per dof)."""
    if len(h.mech.motors) != dof:
        col.add("motors", f"{counted(len(h.mech.motors), 'motor')} for {counted(dof, 'degree')} of freedom: "
                "a mechanism needs one motor per degree of freedom")
    found = []
    for m in h.mech.motors:
        if m.joints:
            found.append(transmission_motor(h, m, col))
        else:
            found.append(link_motor(h, cparent, groups, canon, m, col))
    found = [f for f in found if f is not None]
    col.raise_if_any()
    rows = np.array([f[2] for f in found]).reshape(len(found), h.J)
    return Motors([f[0] for f in found], [f[1] for f in found], rows, [f[3] for f in found])


def transmission_motor(h: Home, m, col: Collector):
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
    return x, link_id(h, m.stator, h.tree.parent[x]), row, tuple(pairs)


def link_motor(h: Home, cparent: list, groups, canon: np.ndarray, m, col: Collector):
    """Motor turning its link relative to its stator (default: the link's carrier) about
    their common axis: (link, stator, row (J,), None), or None with an issue."""
    x = h.idx[m.link]
    if x == h.tree.base:
        col.add(f"{m.path}.link", "a motor cannot drive the base")
        return None
    s = link_id(h, m.stator, cparent[x])
    g = next((g for g in groups_of(groups, x) if s in g.members and x in g.members and s != x), None)
    if g is None:
        col.add(f"{m.path}.stator", f"stator link '{h.tree.links[s]}' does not share the axis of input link '{m.link}'")
        return None
    row, _ = relative_rotation(h, canon, x, s, g)
    return x, s, row, None


def link_id(h: Home, name: str | None, default: int) -> int:
    """Id of link ``name``, or ``default`` if no name is given."""
    return h.idx[name] if name is not None else default


def structure_matrix(mrows: np.ndarray, S: np.ndarray, col: Collector) -> np.ndarray:
    """Structure matrix A (dof, M): motor input rotations = A^T q_ind (paper Eq. 22);
    raises if singular (some dof driven by no motor)."""
    AT = mrows @ S
    AT[np.abs(AT) < 1e-15] = 0.0
    if np.linalg.matrix_rank(AT) < S.shape[1]:
        col.add("motors", "the motors do not drive every degree of freedom (structure matrix is singular)")
        col.raise_if_any()
    return AT.T.copy()


def transmission_lines(h: Home, circuits: list[Circuit], primary: list[int], chain: list[int],
                        mlinks: list[int]):
    """Transmission lines: from each motor's input link along heavy edges (gear pairs) to the
    first primary link reached (a path of link ids per branch; a single link if the input
    link is primary).  A gear meshing with a gear fixed to the base (a planet in its fixed
    ring) drives its carrier: the line goes on to the carrier instead of ending at the base,
    so a planetary's line ends at its output carrier and a two-stage planetary's runs
    through both stages.  Also whether the structure matrix is pseudo-triangular: every
    primary link ends exactly one line."""
    heavy: dict[int, list[tuple[int, int]]] = {i: [] for i in range(h.L)}
    for c in circuits:
        heavy[c.j].append((c.k, c.carrier))
        heavy[c.k].append((c.j, c.carrier))
    pset = set(primary)
    tlines: list[tuple[int, ...]] = []
    for x in mlinks:
        if x in pset:
            tlines.append((x,))
        else:
            extend_lines([x], heavy, pset, tlines, h.tree.base)
    ends = [line[-1] for line in tlines]
    return tlines, all(ends.count(p) == 1 for p in chain)


def extend_lines(path: list[int], heavy: dict, pset: set, out: list, base: int) -> None:
    """Depth-first extension of ``path`` along heavy edges, appending to ``out`` every
    extension that reaches a primary link (in ``pset``) other than the ``base``; a mesh with
    a gear on the base leads to the pair's carrier instead (when it moves)."""
    for nb, carrier in heavy[path[-1]]:
        if nb == base:
            nb = carrier
            if nb == base:
                continue
        if nb in path:
            continue
        if nb in pset:
            out.append(tuple(path + [nb]))
        else:
            extend_lines(path + [nb], heavy, pset, out, base)
