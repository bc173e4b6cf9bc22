"""Numerical determinacy of the load equations (complements the structural schedule), and
:func:`analyse`: the graph analysis followed by that check (what every command needs)."""
from __future__ import annotations

from functools import lru_cache

import numpy as np
from threadpoolctl import threadpool_limits

from ..analysis.graph import Analysis
from ..analysis.graph import analyse as analyse_graph
from ..analysis.schedule import unknown_groups
from ..errors import Collector
from ..model.mechanism import Mechanism
from .kinematics import forward
from .equations import Columns
from .general import assemble
from .sharing import mesh_weights, null_directions_without_t, numerical_rank


def analyse(mech: Mechanism) -> Analysis:
    """Analyse ``mech`` and check that its loads are determined.

    The graph analysis (:func:`gearcli.analysis.graph.analyse`: canonical graph, levels,
    circuits, structure matrix, schedule) followed by the numerical determinacy check of the
    load equations (:func:`check_determinate`).  Raises
    :class:`~gearcli.errors.MechanismError` listing every problem.  (Also
    ``gearcli.analyse`` and ``gearcli.pipeline.analyse``; here, below the solver, so that
    ``gearcli check`` and ``graph`` do not import it.)
    """
    with threadpool_limits(limits=1, user_api="blas"):   # small matrices: threads only contend
        an = analyse_graph(mech)
        col = Collector(mech.source, mech.lines)
        check_determinate(an, col)
    col.raise_if_any()
    return an


def load_analysed(path) -> Analysis:
    """:func:`analyse` of the mechanism file ``path`` (:func:`gearcli.io.load_mechanism`),
    with every problem at once: where the reader built the mechanism despite a problem
    (:class:`~gearcli.errors.IncompleteMechanismError`, e.g. planets that do not fit), the
    analysis's problems are added to the reader's."""
    from ..errors import IncompleteMechanismError, MechanismError  # noqa: PLC0415
    from ..io import load_mechanism                                # noqa: PLC0415
    try:
        mech = load_mechanism(path)
    except IncompleteMechanismError as exc:
        try:
            analyse(exc.mechanism)
        except MechanismError as more:
            raise MechanismError(exc.issues + [i for i in more.issues if i not in exc.issues]) from None
        raise MechanismError(exc.issues) from None
    return analyse(mech)


def block_unknowns(an) -> list[list]:
    """Unknown groups owned by each block of ``an.schedule``: a group belongs to the first
    block (in solution order) that holds one of its links.  Per block, a list of
    :class:`~gearcli.analysis.schedule.UnknownGroup`."""
    block_of = {x: i for i, blk in enumerate(an.schedule) for x in blk}
    owned: list[list] = [[] for _ in an.schedule]
    for g in unknown_groups(an):
        owned[min(block_of[x] for x in g.links)].append(g)
    return owned


def _configurations(an):
    """The equation columns at the home configuration and at a random one (seed 0), in that
    order, each computed when first asked for (iterate ``map(cols, range(2))``): most
    mechanisms are checked at home alone (and then numpy.random is not even imported)."""
    @lru_cache(maxsize=None)
    def cols(i: int) -> Columns:
        q = np.zeros((1, an.dof)) if i == 0 else np.random.default_rng(0).uniform(-np.pi, np.pi, (1, an.dof))
        return Columns(an, forward(an.mech, an.tree, (q @ an.S.T).reshape(1, len(an.mech.joints))))
    return cols


def check_determinate(an, col: Collector) -> None:
    """Numerical check that the equations determine every load.

    The equations are block triangular in the schedule's order, so the full equation
    matrix (all links, all unknowns) is regular exactly when every block's own square
    matrix is.  Each block is checked at the home configuration or, failing that, at a
    random one (cost linear in the number of blocks).  The structural schedule cannot see
    a zero lever arm or a motor whose axis carries no load; this can.
    """
    owned = block_unknowns(an)
    cols = _configurations(an)
    rank, total = 0, 0
    for blk, groups in zip(an.schedule, owned):
        n = sum(g.size for g in groups)
        if n > 6 * len(blk):              # a redundant gear set: load sharing must be unique
            _check_sharing(an, cols, blk, groups, col)
            rank, total = rank + 6 * len(blk), total + 6 * len(blk)
            continue
        best = 0
        for c in map(cols, range(2)):
            A = assemble(c, groups, blk)[0]                 # (6B, n), world frame
            best = max(best, numerical_rank(np.linalg.svd(A, compute_uv=False)) if A.shape[0] == n else min(A.shape))
            if best == n == A.shape[0]:
                break
        rank, total = rank + best, total + n
    if rank < total or total != 6 * len(an.tree.moving):
        col.add("", f"the loads are statically indeterminate: the equations of the moving links are "
                f"singular (rank {rank} of {total}); check the gear geometry and the motors")


def _check_sharing(an, cols, blk: tuple, groups: list, col: Collector) -> None:
    """A redundant block: its equations must be independent (full row rank) and every
    redundancy must change some tooth force, else the mesh-stiffness model cannot share it."""
    w = mesh_weights(an, groups)
    names = ", ".join(f"'{an.tree.links[x]}'" for x in blk)
    found = [null_directions_without_t(assemble(c, groups, blk)[0], w) for c in map(cols, range(2))]
    if all(r < 6 * len(blk) for r, _ in found):
        col.add("", f"the loads are statically indeterminate: the equations of links {names} are "
                "singular; check the gear geometry and the motors")
    elif all(k > 0 for _, k in found):
        col.add("", f"the loads of links {names} are statically indeterminate beyond the mesh-stiffness "
                "model: a redundancy changes only bearing reactions or motor torques, no tooth force")
