"""Trajectory columns ``load:<name>:<component>`` that override an external load per sample.

``<component>`` is one of fx, fy, fz (N) and mx, my, mz (N*m, about the load point), in the
load's frame (``Load.frame``); any subset may be given, the others keep the mechanism
file's constant.
"""
from __future__ import annotations

import numpy as np

from ..errors import Issue, TrajectoryError
from ..model.loads import LOAD_COMPONENTS


def _show(text: str, limit: int = 40) -> str:
    text = text if text.isprintable() else text.encode("unicode_escape", "backslashreplace").decode("ascii")
    return text if len(text) <= limit else text[:limit - 1] + "…"


def load_columns(pos: dict[str, int], loads, file: str) -> dict[str, list[tuple[int, int]]]:
    """{load name: [(component 0..5, file column), ...]} for the ``load:`` columns of a
    header (``pos``: column name -> index); raises for an unknown load or component."""
    known = {ld.name for ld in loads}
    out: dict[str, list[tuple[int, int]]] = {}
    for h, c in pos.items():
        if not h.startswith("load:"):
            continue
        parts = h.split(":")
        place = f"column {c + 1} '{_show(h)}'"
        if len(parts) != 3 or parts[2] not in LOAD_COMPONENTS:
            raise TrajectoryError(Issue(file, place, 1, "a load column is load:<name>:<component> with "
                                        f"component {', '.join(LOAD_COMPONENTS)}"))
        if parts[1] not in known:
            raise TrajectoryError(Issue(file, place, 1, f"unknown load '{_show(parts[1])}' (mechanism loads: "
                                        f"{_show(', '.join(sorted(known)), 80) or 'none'})"))
        out.setdefault(parts[1], []).append((LOAD_COMPONENTS.index(parts[2]), c))
    return out


def load_samples(data: np.ndarray, cols: dict, loads) -> dict[str, np.ndarray]:
    """Per-sample wrenches (n, 6) of the loads that have columns: the constant of the
    mechanism file with the given components replaced by the columns of ``data`` (n, ncol)."""
    by_name = {ld.name: ld for ld in loads}
    out = {}
    for name, pairs in cols.items():
        w = np.tile(by_name[name].wrench, (data.shape[0], 1))
        for comp, c in pairs:
            w[:, comp] = data[:, c]
        out[name] = w
    return out
