"""Degrees of freedom and independent coordinates: the map q = S q_ind from the independent
(equivalent open-loop chain) joint coordinates to every real joint coordinate."""
from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..errors import Collector
from .context import Home
from .types import Circuit


class Independent(NamedTuple):
    """Independent coordinates q_ind (dof of them) and q = S q_ind."""

    primary: list[int]     # primary links, base first (the EOLC, or the tree's free links)
    chain: list[int]       # moving primary links, one per independent coordinate
    open_loop: str         # "chain" or "tree"
    S: np.ndarray          # (J, dof): every real joint angle from the independent ones
    independent: tuple     # (dof,) joint id of each coordinate, -1 for a canonical angle
    independent_names: tuple


def independent_coordinates(h: Home, cparent: list, canon: np.ndarray, primary: list[int],
                             circuits: list[Circuit], col: Collector) -> Independent:
    """Degrees of freedom (J - G), the independent coordinates and S (J, dof) solving the
    circuit rows Gam q = 0 together with q_ind = B q (canonical angles of the EOLC, or the
    free joints of a tree)."""
    G, J = len(circuits), h.J
    Gam = circuit_matrix(h, circuits, col)
    dof = J - G
    open_loop = "tree" if h.mech.open_loop == "tree" else "chain"
    if open_loop == "tree":
        primary, chain, B = tree_coordinates(h, circuits, dof, col)
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
    return Independent(primary, chain, open_loop, S, tuple(independent), names)


def circuit_matrix(h: Home, circuits: list[Circuit], col: Collector) -> np.ndarray:
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


def tree_coordinates(h: Home, circuits: list[Circuit], dof: int, col: Collector):
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
