"""Degrees of freedom and independent coordinates: the map q = S q_ind from the independent
(equivalent open-loop chain) joint coordinates to every real joint coordinate.

The degrees of freedom are J minus the rank of the circuit rows: a kinematically consistent
redundant gear set (N planets between one sun and one ring, a duplicated pair) adds rows
that depend on the others and takes no freedom away.  Its loads are shared by the mesh
stiffness model of :mod:`gearcli.dynamics.general`; the sets are reported in
``Analysis.redundant``.  An inconsistent set (closure equations that contradict each other:
planets whose teeth or radii do not fit) locks the gear train and is refused, naming the
pairs.
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..errors import Collector, counted, plural
from .context import Home
from .types import Circuit

RTOL_RANK = 1e-6   # rows dependent within the ratio tolerance (as ratios are checked) are redundant


class Independent(NamedTuple):
    """Independent coordinates q_ind (dof of them) and q = S q_ind."""

    primary: list[int]     # primary links, base first (the EOLC, or the tree's free links)
    chain: list[int]       # moving primary links, one per independent coordinate
    open_loop: str         # "chain" or "tree"
    S: np.ndarray          # (J, dof): every real joint angle from the independent ones
    independent: tuple     # (dof,) joint id of each coordinate, -1 for a canonical angle
    independent_names: tuple
    redundant: tuple = ()  # circuit positions of each redundant (load-sharing) gear set


class CircuitRank(NamedTuple):
    """The circuit rows Gam (G, J), their numerical rank, a basis of independent rows
    (positions) and the singular values / left singular vectors of the scaled rows."""

    Gam: np.ndarray
    rank: int
    basis: list[int]
    sv: np.ndarray
    U: np.ndarray


def independent_coordinates(h: Home, cparent: list, canon: np.ndarray, primary: list[int],
                            circuits: list[Circuit], col: Collector) -> Independent:
    """Degrees of freedom (J - rank of the circuit rows), the independent coordinates and
    S (J, dof) solving the independent circuit rows Gam_b q = 0 together with q_ind = B q
    (canonical angles of the EOLC, or the free joints of a tree)."""
    J = h.J
    cr = circuit_rank(h, circuits)
    open_loop = "tree" if h.mech.open_loop == "tree" else "chain"
    if open_loop == "tree":
        dependent = {c.j for c in circuits}
        chain = [h.idx[jt.child] for jt in h.mech.joints if h.idx[jt.child] not in dependent]
        primary = [h.tree.base] + chain
    else:
        chain = primary[1:]
    dof = J - cr.rank
    if len(chain) > dof:
        _contradiction(h, circuits, cr, len(chain) - dof, col)
    elif len(chain) != dof:
        _dof_mismatch(h, primary, chain, dof, cr.rank, open_loop, col)
    if open_loop == "tree":
        B = np.zeros((dof, J))
        for r, c in enumerate(chain):
            B[r, h.jin[c]] = 1.0
    else:
        B = canon[chain]
    Mfull = np.vstack([cr.Gam[cr.basis], B])
    if np.linalg.matrix_rank(Mfull) < J:
        col.add("gears", "the gear trains lock the equivalent open-loop chain: its joint angles do not "
                "determine the motion of every link")
        col.raise_if_any()
    S = np.linalg.solve(Mfull, np.vstack([np.zeros((cr.rank, dof)), np.eye(dof)]))
    S[np.abs(S) < 1e-15] = 0.0
    # a coefficient one ulp or two from +-1 (the LU solve's rounding of a direct drive) is
    # +-1: exact, and the same IR for every ratio of a sweep (the kernel folds a unit product)
    unit = np.abs(np.abs(S) - 1.0) <= 4 * np.finfo(float).eps
    S[unit] = np.sign(S[unit])
    independent = []
    for c in chain:
        jt = h.jin[c]
        independent.append(jt if open_loop == "tree" or h.idx[h.mech.joints[jt].parent] == cparent[c] else -1)
    names = tuple(h.mech.joints[jt].name if jt >= 0 else f"{h.tree.links[cparent[c]]}-{h.tree.links[c]}"
                  for jt, c in zip(independent, chain))
    sets = redundant_sets(cr)
    _stiffness_given_for_all_or_none(h, circuits, sets, col)
    return Independent(primary, chain, open_loop, S, tuple(independent), names, sets)


def circuit_rank(h: Home, circuits: list[Circuit]) -> CircuitRank:
    """Rank of the circuit rows, judged on rows scaled to unit length with the ratio
    tolerance RTOL_RANK (rounded mesh points must not turn two redundant planets into
    "0 degrees of freedom"), and a basis of independent rows (every row when they are
    independent, else the pivots of a column-pivoted QR of the scaled rows' transpose).
    The left singular vectors are computed only when some rows depend on the others."""
    G = len(circuits)
    Gam = np.array([c.row for c in circuits]).reshape(G, h.J)
    if G == 0:
        return CircuitRank(Gam, 0, [], np.zeros(0), np.zeros((0, 0)))
    Gn = Gam / np.maximum(np.linalg.norm(Gam, axis=1, keepdims=True), 1e-300)
    sv = np.linalg.svd(Gn, compute_uv=False)
    rank = int(np.sum(sv > RTOL_RANK * sv[0]))
    if rank == G:
        return CircuitRank(Gam, rank, list(range(G)), sv, np.zeros((G, 0)))
    from scipy.linalg import qr  # noqa: PLC0415  (scipy.linalg: only when rows depend on others)

    U, sv, _ = np.linalg.svd(Gn)
    _, _, piv = qr(Gn.T, mode="economic", pivoting=True)
    return CircuitRank(Gam, rank, sorted(int(i) for i in piv[:rank]), sv, U)


def redundant_sets(cr: CircuitRank) -> tuple[tuple[int, ...], ...]:
    """Circuit positions of each redundant gear set: the supports of a sparse basis of the
    left null space of the rows (reduced row echelon form), merged where they overlap."""
    G = cr.Gam.shape[0]
    if cr.rank == G:
        return ()
    null = _rref(cr.U[:, cr.rank:].T)
    sets: list[set[int]] = []
    for v in null:
        s = set(np.flatnonzero(np.abs(v) > 1e-8 * np.abs(v).max()).tolist())
        for other in [o for o in sets if o & s]:
            s |= other
            sets.remove(other)
        sets.append(s)
    return tuple(tuple(sorted(s)) for s in sorted(sets, key=min))


def _stiffness_given_for_all_or_none(h: Home, circuits: list[Circuit], sets, col: Collector) -> None:
    """The load sharing of a redundant set weighs its pairs by stiffness: either every pair
    of the set gives ``stiffness`` or none does (equal sharing)."""
    gears = h.mech.gears
    for members in sets:
        missing = [gears[circuits[i].gear] for i in members if gears[circuits[i].gear].stiffness is None]
        if missing and len(missing) < len(members):
            col.add(f"{missing[0].path}", f"gear pair '{missing[0].name}' has no stiffness but other pairs of its "
                    f"redundant gear set have: give stiffness for every pair of the set "
                    f"({_pairs(h, circuits, members)}) or for none (equal sharing)")
    col.raise_if_any()


def _rref(M: np.ndarray) -> np.ndarray:
    """Reduced row echelon form of M (rows independent), partial pivoting."""
    M = M.copy()
    r = 0
    for c in range(M.shape[1]):
        if r == M.shape[0]:
            break
        p = r + int(np.argmax(np.abs(M[r:, c])))
        if abs(M[p, c]) < 1e-10:
            continue
        M[[r, p]] = M[[p, r]]
        M[r] /= M[r, c]
        f = M[:, c].copy()
        f[r] = 0.0
        M -= np.outer(f, M[r])            # eliminate column c from every other row
        r += 1
    return M


def _pairs(h: Home, circuits: list[Circuit], which) -> str:
    gears = h.mech.gears
    return ", ".join(f"'{gears[circuits[i].gear].name}' ({gears[circuits[i].gear].path})" for i in which)


def _contradiction(h: Home, circuits: list[Circuit], cr: CircuitRank, excess: int, col: Collector) -> None:
    """Refuse gear pairs whose closure equations contradict: the ``excess`` smallest nonzero
    singular directions of the rows name the pairs involved."""
    Uall = cr.U if cr.U.shape[1] else np.linalg.svd(cr.Gam / np.linalg.norm(cr.Gam, axis=1, keepdims=True))[0]
    U = Uall[:, cr.rank - excess:cr.rank]
    involved = sorted({i for v in U.T for i in np.flatnonzero(np.abs(v) > 1e-8)})
    misfit = cr.sv[cr.rank - 1] / cr.sv[0]
    col.add("gears", "gear pairs " + _pairs(h, circuits, involved) + " form a redundant set whose closure "
            f"equations contradict (teeth or mesh radii do not fit, relative misfit {misfit:.2g}): "
            "the gear trains lock")
    col.raise_if_any()


def _dof_mismatch(h: Home, primary, chain, dof: int, rank: int, open_loop: str, col: Collector) -> None:
    G = len(chain)
    if open_loop == "tree":
        col.add("gears", f"the mechanism has {counted(dof, 'degree')} of freedom ({counted(h.J, 'joint')} - {rank} "
                f"independent gear pairs and couplings) but {counted(G, 'joint')} {plural(G, 'is', 'are')} not made "
                "dependent by a pair")
    else:
        col.add("end_effector", f"the mechanism has {counted(dof, 'degree')} of freedom ({counted(h.J, 'joint')} - {rank} "
                f"independent gear pairs) but its equivalent open-loop chain "
                f"{' -> '.join(h.tree.links[i] for i in primary)} has {counted(G, 'joint')}")
    col.raise_if_any()
