"""External loads: constant wrenches the environment applies to a link (a tool force, a
payload).  Frozen like the rest of the model; per-sample values come from the trajectory
(``load:<name>:fx`` ... columns) or from ``solve(..., loads=...)``."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

LOAD_FRAMES = ("base", "link")
LOAD_COMPONENTS = ("fx", "fy", "fz", "mx", "my", "mz")


@dataclass(frozen=True, eq=False)
class Load:
    """A wrench applied by the environment ON link ``link`` at ``point``.

    ``point`` (3,) is in the link frame, m.  ``force`` (3,) N and ``moment`` (3,) N*m (about
    ``point``) are in the base frame (``frame="base"``) or in the link frame (``"link"``,
    turning with the link).

    A payload also has ``mass`` (kg, its centre of mass at ``point``) and ``inertia`` (3, 3)
    (kg*m^2, about ``point``, link-frame axes): it is rigidly attached to the link and moves
    with it, so it enters the link's inertia (:func:`with_payloads`): its weight, its
    d'Alembert loads and the mass matrix.  Zero by default (a pure wrench).
    """

    name: str
    link: str
    frame: str = "base"
    point: np.ndarray = field(default_factory=lambda: np.zeros(3))
    force: np.ndarray = field(default_factory=lambda: np.zeros(3))
    moment: np.ndarray = field(default_factory=lambda: np.zeros(3))
    path: str = ""
    mass: float = 0.0
    inertia: np.ndarray = field(default_factory=lambda: np.zeros((3, 3)))

    @property
    def wrench(self) -> np.ndarray:
        """(6,) [fx, fy, fz, mx, my, mz] in the load's frame, about the load point."""
        return np.concatenate([np.asarray(self.force, float), np.asarray(self.moment, float)])


def with_payloads(links: tuple, loads: tuple[Load, ...]) -> tuple:
    """``links`` (:class:`~gearcli.model.mechanism.Link`) with the mass of every payload
    merged into the link it rides on: total mass, centre of mass, and inertia about the
    combined centre of mass (parallel-axis theorem), link-frame axes.  A link without a
    payload is returned as is (the same object)."""
    from dataclasses import replace  # noqa: PLC0415

    out = list(links)
    index = {lk.name: i for i, lk in enumerate(links)}
    for ld in loads:
        if ld.mass == 0 and not np.any(ld.inertia):
            continue
        i = index[ld.link]
        lk = out[i]
        parts = [(lk.mass, np.asarray(lk.com, float), np.asarray(lk.inertia, float)),
                 (ld.mass, np.asarray(ld.point, float), np.asarray(ld.inertia, float))]
        m = sum(p[0] for p in parts)
        c = sum(p[0] * p[1] for p in parts) / m if m > 0 else parts[0][1]
        I = sum(p[2] + p[0] * (np.dot(p[1] - c, p[1] - c) * np.eye(3) - np.outer(p[1] - c, p[1] - c)) for p in parts)
        out[i] = replace(lk, mass=m, com=c, inertia=I)
    return tuple(out)
