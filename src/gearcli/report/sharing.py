"""Notes on the redundant gear sets of a mechanism (``check``, ``graph``, ``solve``): which
pairs share their load, and by which model."""
from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:   # no numpy or analysis import for `gearcli --help`
    from ..analysis.graph import Analysis

MODEL = "load shared by mesh stiffness, min sum t^2/k"


def sharing_sets(an: Analysis) -> list[dict]:
    """One dict per redundant gear set: ``pairs`` (names), ``model`` and ``stiffness``
    (N/m per pair, None where the default equal stiffness applies)."""
    out = []
    for members in an.redundant:
        gears = [an.mech.gears[an.circuits[i].gear] for i in members]
        out.append({"pairs": [g.name for g in gears], "model": MODEL,
                    "stiffness": [g.stiffness for g in gears]})
    return out


def sharing_notes(an: Analysis) -> list[str]:
    """One line per redundant gear set, e.g. ``note: redundant gear set 'S-P1', ...: load
    shared by mesh stiffness, min sum t^2/k (equal stiffness)``."""
    lines = []
    for s in sharing_sets(an):
        given = [k for k in s["stiffness"] if k is not None]
        how = "equal stiffness" if not given else "gears[].stiffness"
        lines.append(f"note: redundant gear set {', '.join(repr(p) for p in s['pairs'])}: "
                     f"{s['model']} ({how})")
    return lines
