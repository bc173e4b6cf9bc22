"""Loss parameters of a drive: joint friction (the robotics convention).

Mesh losses are a per-pair number, :attr:`gearcli.model.mechanism.GearPair.loss_factor`
(c = 1 - efficiency); the physics of both lives in :mod:`gearcli.dynamics.losses`.
"""
from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class JointFriction:
    """Load-independent friction of one joint, ``joints[].friction``.

    On the joint's child, a generalised force -coulomb * sign(qd) - viscous * qd about (a
    revolute joint) or along (a prismatic one) the joint axis, reversed on the parent; qd is
    the joint's own rate (so dependent joints, gear shafts, count too); sign(0) = 0.

    ``coulomb``: N*m (revolute) or N (prismatic), >= 0.
    ``viscous``: N*m*s/rad (revolute) or N*s/m (prismatic), >= 0.
    """

    coulomb: float = 0.0
    viscous: float = 0.0

    @property
    def active(self) -> bool:
        """True when the joint has any friction."""
        return self.coulomb != 0.0 or self.viscous != 0.0
