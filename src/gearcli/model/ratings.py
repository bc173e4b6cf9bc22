"""Component ratings (what a motor, bearing or gear can take): frozen dataclasses.

SI units: N, N*m, m, rad/s, W, Pa.  They are attached to the model through optional fields
(``Motor.rating``, ``Joint.bearings``, ``Joint.limit``, ``GearPair.rating``) that default
to None; the checks live in :mod:`gearcli.design`.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

STEEL_ELASTIC_COEFFICIENT = 189.8e3
"""Z_E of steel on steel (E = 206 GPa, nu = 0.3), sqrt(Pa) (ISO 6336-2): the default."""

_ALPHA = math.radians(15.0)
BEARING_FACTOR_DEFAULTS = {
    "ball": {"X": 0.56, "Y": 1.6, "e": 0.27, "X0": 0.6, "Y0": 0.5},
    "roller": {"X": 0.4, "Y": round(0.4 / math.tan(_ALPHA), 2), "e": round(1.5 * math.tan(_ALPHA), 2),
               "X0": 0.5, "Y0": round(0.22 / math.tan(_ALPHA), 2)},
}
"""Default ISO 281 (X, Y, e) and ISO 76 (X0, Y0) factors by bearing type (README,
"Bearings"): ISO 281 Table 3 for a radial deep-groove ball bearing at Fa/C0 ~ 0.07 (normal
clearance); for a roller bearing the factors of a single-row tapered roller bearing with a
contact angle of 15 deg (ISO 281 Table 4: e = 1.5 tan a, X = 0.4, Y = 0.4 cot a; ISO 76:
X0 = 0.5, Y0 = 0.22 cot a)."""


@dataclass(frozen=True)
class MotorRating:
    """``peak_torque`` and ``rms_torque`` (continuous) in N*m (N for a linear input),
    ``max_speed`` in rad/s (m/s), optional ``max_power`` in W."""

    peak_torque: float
    rms_torque: float
    max_speed: float
    max_power: float | None = None
    path: str = field(default="", compare=False)   # where it was read (for messages)


@dataclass(frozen=True)
class BearingRating:
    """A rolling bearing of a joint.

    ``position``: m along the joint axis from the joint origin; ``C``, ``C0``: dynamic and
    static load ratings, N; ``type``: ``"ball"`` or ``"roller"``; ISO 281 factors ``X``,
    ``Y``, ``e`` and ISO 76 factors ``X0``, ``Y0``; ``locating``: takes the axial load
    (one of two bearings); ``M``: tilting-moment rating, N*m (a single crossed-roller or
    four-point bearing), or None.
    """

    name: str
    position: float
    C: float
    C0: float
    type: str
    X: float
    Y: float
    e: float
    X0: float
    Y0: float
    locating: bool = True
    M: float | None = None
    path: str = field(default="", compare=False)   # where it was read (for messages)


@dataclass(frozen=True)
class JointLimit:
    """URDF ``<limit effort velocity>``: N*m (N) and rad/s (m/s); None when not given."""

    effort: float | None
    velocity: float | None
    path: str = field(default="", compare=False)   # where it was read (for messages)


@dataclass(frozen=True)
class GearRating:
    """Tooth rating of a gear pair (both gears of one material).

    ``module`` and ``face_width`` in m; ``bending_stress_limit`` and
    ``contact_stress_limit`` (allowable stresses) in Pa; ``elastic_coefficient`` Z_E in
    sqrt(Pa); ``application_factor`` K_A and ``load_sharing_factor`` multiply the
    tangential force.
    """

    module: float
    face_width: float
    bending_stress_limit: float
    contact_stress_limit: float
    elastic_coefficient: float
    application_factor: float = 1.0
    load_sharing_factor: float = 1.0
    path: str = field(default="", compare=False)   # where it was read (for messages)
