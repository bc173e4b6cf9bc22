"""Numerical determinacy of the load equations (complements the structural schedule)."""
from __future__ import annotations

import numpy as np

from ..analysis.schedule import unknown_groups
from ..errors import Collector
from .kinematics import forward
from .loads import Columns


def check_determinate(an, col: Collector) -> None:
    """Numerical check that the equations determine every load: the full equation matrix
    (all links, all unknowns) must be regular at the home configuration or, failing that,
    at a random one.  The structural schedule cannot see a zero lever arm or a motor whose
    axis carries no load; this can."""
    groups = unknown_groups(an)
    moving = an.tree.moving
    pos = {L: i for i, L in enumerate(moving)}
    J = len(an.mech.joints)
    rng = np.random.default_rng(0)
    for q_ind in (np.zeros((1, an.dof)), rng.uniform(-np.pi, np.pi, (1, an.dof))):
        cols = Columns(an, forward(an.mech, an.tree, (q_ind @ an.S.T).reshape(1, J)))
        A = np.zeros((6 * len(moving), sum(g.size for g in groups)))
        c0 = 0
        for g in groups:
            for L in g.links:
                A[6 * pos[L]:6 * pos[L] + 6, c0:c0 + g.size] = cols.group(g, L, 1.0)[0]
            c0 += g.size
        sv = np.linalg.svd(A, compute_uv=False)
        if sv[-1] > 1e-10 * sv[0]:
            return
    col.add("", f"the loads are statically indeterminate: the equations of the moving links are "
            f"singular (rank {int(np.sum(sv > 1e-10 * sv[0]))} of {A.shape[1]}); check the gear "
            "geometry and the motors")
