"""Ball and lead screws (``gears[].kind: screw``; ``../shared/drive-elements.md`` B, docs/concepts/drive-elements.md
"Screws").

Members and constraint
----------------------
The screw S turns about the axis u relative to the carrier c (a revolute joint), the nut N
slides along it (a prismatic joint on the same line).  Lead l > 0 (m/rev) and ``hand``:
h = +l/(2 pi) (right) or -l/(2 pi) (left), m/rad, with u = z_S, the screw's own joint axis: a
right-hand screw advances its nut along +u when the screw turns positively about u.  The
element imposes v_N . u = h (w_S - w_c) . u, i.e. x_N = h theta_S relative to c; in the
paper's circuit form theta_{S,c} = e x_{N,c} with e = (z_N . z_S) / h (rad/m, x_N along the
nut's joint axis z_N).

Interaction
-----------
The unknown F (N) is the axial force on the nut along u.  On N: the force F u through the
axis line and the torque h c_r F u (taken by the nut's guide); on S: -F u and -h c_r F u.  The
force does not depend on the efficiency; the torque does (catalogue power-flow efficiency,
:mod:`.power_flow`): the screw drives where F v > 0 (v = h a the nut's speed relative to c, a
the screw's rate relative to c), c_r = 1/eta_f; the load drives the screw back where F v < 0,
c_r = eta_b (eta_b <= 0: a self-locking lead screw needs the motor to lower its load).  With
the drive rate w = -h a (the power of the lossless torque on S per unit F), the loss is
-(c_r - 1) F w >= 0.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from .power_flow import SpeedTable


@dataclass(frozen=True)
class ScrewRating:
    """ISO 3408-5 ratings: ``C_a`` the basic dynamic axial load rating and ``C_0a`` the basic
    static one (N); ``max_speed`` the screw's highest rate (rad/s), None: not checked."""

    C_a: float
    C_0a: float
    max_speed: float | None = None
    path: str = field(default="", compare=False)


@dataclass(frozen=True)
class Screw:
    """What a screw adds to its :class:`~.mechanism.GearPair` (``j`` the screw, ``k`` the nut,
    ``ratio`` e): its ``lead`` (m/rev), ``hand``, efficiencies (tables over the screw's speed
    |a|, rad/s) and rating."""

    lead: float
    hand: str = "right"
    forward: SpeedTable = SpeedTable.constant(1.0)
    backward: SpeedTable = SpeedTable.constant(1.0)
    rating: ScrewRating | None = None

    @property
    def h(self) -> float:
        """The signed lead per radian, m/rad: +l/(2 pi) right hand, -l/(2 pi) left hand."""
        return (1.0 if self.hand == "right" else -1.0) * self.lead / (2.0 * math.pi)

    @property
    def power_flow_lossy(self) -> bool:
        """True when an efficiency is below 1 (the torque then depends on sign(F) sign(w))."""
        return any(v != 1.0 for v in self.forward.values + self.backward.values)

    lossy = power_flow_lossy

    def lossless(self) -> "Screw":
        """The same screw without losses."""
        return replace(self, forward=SpeedTable.constant(1.0), backward=SpeedTable.constant(1.0))


def friction_efficiencies(lead: float, diameter: float, mu: float) -> tuple[float, float]:
    """(eta_f, eta_b) of a screw from its friction: beta = atan(l / (pi d0)) the lead angle at
    the diameter d0, phi = atan(mu): eta_f = tan(beta) / tan(beta + phi), eta_b = tan(beta -
    phi) / tan(beta) (<= 0 where beta <= phi: self-locking)."""
    beta, phi = math.atan(lead / (math.pi * diameter)), math.atan(mu)
    return math.tan(beta) / math.tan(beta + phi), math.tan(beta - phi) / math.tan(beta)


def mean_axial_load(F, n, dt) -> float:
    """F_m = (sum |F_k|^3 |n_k| dt_k / sum |n_k| dt_k)^(1/3), N (ISO 3408-5); 0 without turning."""
    w = np.abs(n) * dt
    den = float(np.sum(w))
    return float((np.sum(w * np.abs(F) ** 3) / den) ** (1.0 / 3.0)) if den > 0 else 0.0


def screw_life_hours(C_a: float, F_m: float, n_m_rpm: float) -> float:
    """L_h = (C_a / F_m)^3 10^6 / (60 n_m) hours (ISO 3408-5), n_m the mean speed in rev/min;
    inf without load or turning."""
    if F_m <= 0.0 or n_m_rpm <= 0.0:
        return math.inf
    return (C_a / F_m) ** 3 * 1e6 / (60.0 * n_m_rpm)
