"""The general (world-frame) solve of a set of links' balance equations, exact in |t|.

Used by the block schedule for blocks without a constant frame and, over all moving links
at once, by the full simultaneous solve (``method="full"``), the cross-check of the
schedule.  The sign of t (paper Eq. 14) is resolved by :func:`~.signs.resolve_signs`.
"""
from __future__ import annotations

import numpy as np

from ..analysis.schedule import UnknownGroup, unknown_groups
from .equations import Columns
from .sharing import least_load_solve, mesh_weights
from .signs import resolve_signs


def is_geared(an, g: UnknownGroup) -> bool:
    """True for a signed unknown: the tangential force of a mesh with gear geometry (Eq. 14),
    or the torque of a reducer or the force of a screw whose efficiency depends on the
    power-flow direction (:mod:`gearcli.model.power_flow`)."""
    if g.kind != "mesh":
        return False
    c = an.circuits[g.index]
    if c.geometry is not None:
        return True
    gp = an.mech.gears[c.gear]
    if gp.worm is not None:          # its separating force |N| sin(a_n): always signed
        return True
    if gp.belt is not None:          # a lossy belt's loss couple follows sign(E)
        return gp.belt.lossy
    el = gp.reducer if gp.reducer is not None else gp.screw
    return el is not None and el.power_flow_lossy


def mesh_names(an, groups, signed) -> list[str]:
    """Names of the gear pairs of the signed unknowns ``signed`` (positions in groups)."""
    return [f"'{an.mech.gears[an.circuits[groups[i].index].gear].name}'" for i in signed]


def assemble(cols: Columns, groups, links) -> np.ndarray:
    """Matrix (N, 6 * len(links), n) of the balances of ``links`` (Eqs. 15-16, 19-20, one
    :meth:`~.equations.Columns.balance` per link, stacked), every t taken positive."""
    A = np.zeros((cols.kin.n, 6 * len(links), sum(g.size for g in groups)))
    for r, L in enumerate(links):
        cols.balance(groups, L, A[:, 6 * r:6 * r + 6, :])
    return A


def solve_general(an, cols: Columns, groups, links, rhs: np.ndarray):
    """Solve the balances of ``links`` for the unknowns ``groups``.

    Parameters
    ----------
    rhs : (N, 6 * len(links)) the d'Alembert loads minus the known wrenches, base frame,
        about each link's origin.

    Returns
    -------
    x : (N, n) unknowns in the order of ``groups``; signs : {(kind, index): (N,) sign of t}.

    With more unknowns than equations (a redundant gear set) x is the solution that
    minimises sum t^2 / k (:mod:`.sharing`).
    """
    N = rhs.shape[0]
    offs = np.cumsum([0] + [g.size for g in groups])
    signed = [i for i, g in enumerate(groups) if is_geared(an, g)]
    mid = assemble(cols, groups, links)
    shared = offs[-1] > 6 * len(links)
    w = mesh_weights(an, groups) if shared else None
    row = {L: 6 * r for r, L in enumerate(links)}
    half = {}
    for i in signed:                       # column = mid + sign(t) * half (Eq. 14)
        half[i] = np.zeros((N, 6 * len(links)))
        for L in groups[i].links:
            if L in row:
                rows = slice(row[L], row[L] + 6)
                plus, minus = mid[:, rows, offs[i]], cols.group(groups[i], L, -1.0)[:, :, 0]
                half[i][:, rows] = 0.5 * (plus - minus)
                mid[:, rows, offs[i]] = 0.5 * (plus + minus)
    def solve_pattern(pat, idx):
        every = idx.size == N
        A = mid.copy() if every else mid[idx]          # (fancy indexing copies too)
        for i, s in zip(signed, pat):
            A[:, :, offs[i]] += s * (half[i] if every else half[i][idx])
        r = rhs if every else rhs[idx]
        if shared:
            return least_load_solve(A, r, w)
        return np.linalg.solve(A, r[:, :, None])[:, :, 0]

    scale = 1.0 + np.max(np.abs(rhs), axis=1)
    x, signs = resolve_signs(solve_pattern, len(signed), [int(offs[i]) for i in signed], N, scale,
                             mesh_names(an, groups, signed))
    return x, {(groups[i].kind, groups[i].index): signs[:, n] for n, i in enumerate(signed)}


def solve_full(an, cols: Columns, b: dict):
    """All moving links' balances solved simultaneously (the schedule's cross-check).

    Returns ({(kind, index): (N, size)} unknowns, {(kind, index): (N,) sign of t}).
    """
    groups = unknown_groups(an)
    links = list(an.tree.moving)
    rhs = np.concatenate([b[L] for L in links], axis=1)
    x, signs = solve_general(an, cols, groups, links, rhs)
    offs = np.cumsum([0] + [g.size for g in groups])
    return {(g.kind, g.index): x[:, offs[i]:offs[i + 1]] for i, g in enumerate(groups)}, signs
