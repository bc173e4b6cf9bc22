"""External loads on the links (``Mechanism.loads``): moved to the right-hand side.

The balance of link L reads sum_u C_u,L x_u = b_L with the d'Alembert load b_L of
:mod:`.inertia`; a wrench W applied by the environment on L joins gravity on the other
side: sum_u C_u,L x_u = b_L - W, with W in the base frame about the link origin o_L.
"""
from __future__ import annotations

import numpy as np

from ..algebra import ARRAYS, stack_vectors, vectors
from ..spatial import mv
from .wrenches import load_wrench
from .kinematics import Kinematics


def load_values(mech, n: int, loads: dict | None = None) -> dict[str, np.ndarray]:
    """Per-sample wrench (n, 6) of every load of ``mech``, in its own frame about its point.

    ``loads`` maps load names to arrays (n, 6) or (6,) overriding the constant of the
    mechanism file.  Raises ValueError for an unknown name, a bad shape or a value that is
    not finite.
    """
    known = {ld.name: ld for ld in mech.loads}
    loads = loads or {}
    for name in loads:
        if name not in known:
            raise ValueError(f"unknown load '{name}' (mechanism loads: {', '.join(known) or 'none'})")
    out = {}
    for name, ld in known.items():
        w = np.asarray(loads.get(name, ld.wrench), float)
        if w.ndim == 1:
            w = w[None, :]
        if w.shape[1:] != (6,) or w.shape[0] not in (1, n):
            raise ValueError(f"load '{name}': expected shape ({n}, 6) or (6,), got {np.shape(loads[name])}")
        if not np.all(np.isfinite(w)):
            raise ValueError(f"load '{name}' has a value that is not finite")
        out[name] = np.broadcast_to(w, (n, 6))
    return out


def external_wrenches(an, kin: Kinematics, values: dict[str, np.ndarray]) -> dict[int, np.ndarray]:
    """Sum of the external wrenches on each loaded link, (N, 6), base frame, about o_L.

    ``values`` from :func:`load_values` (each (N, 6): force N and moment N*m about the load
    point, in the base or link frame as the load says).
    """
    out: dict[int, np.ndarray] = {}
    for ld in an.mech.loads:
        L = an.tree.index[ld.link]
        w = values[ld.name]
        R = kin.R[L]
        f, m = w[:, :3], w[:, 3:]
        if ld.frame == "link":
            f, m = mv(R, f), mv(R, m)
        arm = mv(R, np.asarray(ld.point, float))          # o_L -> point, base axes
        W = stack_vectors(load_wrench(ARRAYS, vectors(f), vectors(m), vectors(arm)), f.shape[0])
        out[L] = out[L] + W if L in out else W
    return out


def subtract_external(b: dict[int, np.ndarray], ext: dict[int, np.ndarray]) -> None:
    """b_L -= W_L in place for every loaded link (the right-hand side of its balance)."""
    for L, W in ext.items():
        b[L] = b[L] - W
