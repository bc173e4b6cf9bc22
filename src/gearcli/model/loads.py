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
    """

    name: str
    link: str
    frame: str = "base"
    point: np.ndarray = field(default_factory=lambda: np.zeros(3))
    force: np.ndarray = field(default_factory=lambda: np.zeros(3))
    moment: np.ndarray = field(default_factory=lambda: np.zeros(3))
    path: str = ""

    @property
    def wrench(self) -> np.ndarray:
        """(6,) [fx, fy, fz, mx, my, mz] in the load's frame, about the load point."""
        return np.concatenate([np.asarray(self.force, float), np.asarray(self.moment, float)])
