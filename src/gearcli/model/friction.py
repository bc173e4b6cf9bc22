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
    ``static``: the largest friction that holds the joint at rest (``gearcli simulate``'s
    stick-slip, Karnopp's model), N*m or N, >= coulomb; None: equal to ``coulomb``.
    """

    coulomb: float = 0.0
    viscous: float = 0.0
    static: float | None = None

    @property
    def holding(self) -> float:
        """The static friction F_s: ``static``, or ``coulomb`` when not given."""
        return self.coulomb if self.static is None else self.static

    @property
    def active(self) -> bool:
        """True when the joint has any friction."""
        return self.coulomb != 0.0 or self.viscous != 0.0
