"""Catalogue power-flow efficiency, shared by the drive elements (reducers, screws;
``../shared/drive-elements.md``, "Power-flow efficiency"; docs/concepts/drive-elements.md).

Catalogues give efficiency as a power ratio in a flow direction: eta_f = P_out / P_in when the
input member drives, eta_b when the output member drives (eta_b <= 0: self-locking).  An
element whose lossless interaction is u (its unknown) puts its power-flow change on its input
as a factor c_r of one of its torques; with w the element's *drive rate* (the rate whose
product with u is the power that torque's lossless value delivers to the input, a linear
function of the joint rates), power flows input -> output where u w < 0 (the element takes
power from the input): c_r = 1/eta_f; output -> input where u w > 0: c_r = eta_b; u w = 0: 1.
The loss is -(c_r - 1) u w >= 0.  The efficiencies may depend on the input's speed only
(:class:`SpeedTable`), never on u.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class SpeedTable:
    """A value that depends on |w_in| only: rows (w_in rad/s increasing from >= 0, value),
    linear between rows, held beyond the ends; one row: a constant."""

    speeds: tuple[float, ...]
    values: tuple[float, ...]

    @classmethod
    def constant(cls, value: float) -> "SpeedTable":
        """The table of one constant ``value``."""
        return cls((0.0,), (float(value),))

    def at(self, a) -> np.ndarray:
        """The value at the input rates ``a`` (N,) (indexed by |a|)."""
        return np.interp(np.abs(np.asarray(a, float)), self.speeds, self.values)

    @property
    def is_constant(self) -> bool:
        """True for one row (the value does not depend on the speed)."""
        return len(self.values) == 1
