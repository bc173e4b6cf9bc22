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
_TAPERED = {"X": 0.4, "Y": round(0.4 / math.tan(_ALPHA), 2), "e": round(1.5 * math.tan(_ALPHA), 2),
            "X0": 0.5, "Y0": round(0.22 / math.tan(_ALPHA), 2)}
BEARING_FACTOR_DEFAULTS = {
    "ball": {"X": None, "Y": None, "e": None, "X0": 0.6, "Y0": 0.5},
    "cylindrical_roller": {"X": 1.0, "Y": 0.0, "e": 0.0, "X0": 1.0, "Y0": 0.0},
    "tapered_roller": _TAPERED,
    "roller": _TAPERED,
    # a single crossed-roller bearing: P_c (gearcli.design.iso281.crossed_roller_load) and the
    # catalogues' static P0 = F_r + 2 M/d_p + 0.44 F_a (THK, "Cross-Roller Ring", static
    # equivalent radial load); X, Y, e unused
    "crossed_roller": {"X": 1.0, "Y": 0.45, "e": 1.5, "X0": 1.0, "Y0": 0.44},
}
"""Default ISO 281 (X, Y, e) and ISO 76 (X0, Y0) factors by rolling-element type (docs/reference/mechanism-files.md,
"Bearings"); None: from ISO 281 Table 3 at each sample's f0 Fa/C0
(:func:`gearcli.design.iso281.ball_factors`).  Deep-groove ball: X = 0.56 with the table's
e and Y, ISO 76 X0 = 0.6, Y0 = 0.5.  Cylindrical roller (contact angle 0): no axial load
on the rollers, P = Fr and P0 = Fr.  Tapered roller (and ``roller``, its older name),
single row, contact angle 15 deg: ISO 281 Table 4 e = 1.5 tan a, X = 0.4, Y = 0.4 cot a;
ISO 76 X0 = 0.5, Y0 = 0.22 cot a."""

@dataclass(frozen=True)
class MotorRating:
    """``peak_torque`` and ``rms_torque`` (continuous) in N*m (N for a linear input),
    ``max_speed`` in rad/s (m/s), optional ``max_power`` in W, optional ``thermal_window``
    in s (the running RMS over that window is checked against ``rms_torque`` too).

    Servo sizing (optional, :mod:`gearcli.design.sizing`): ``rotor_inertia`` (kg*m^2) with
    ``max_inertia_ratio`` (load-to-rotor, dimensionless); ``torque_speed`` ((omega, T_max),
    ...) the torque-speed envelope (rad/s, N*m; omega increasing from 0); ``max_regen_energy``
    the regenerative energy one cycle may return (J)."""

    peak_torque: float
    rms_torque: float
    max_speed: float
    max_power: float | None = None
    path: str = field(default="", compare=False)   # where it was read (for messages)
    thermal_window: float | None = None
    rotor_inertia: float | None = None
    max_inertia_ratio: float | None = None
    torque_speed: tuple | None = None
    max_regen_energy: float | None = None


@dataclass(frozen=True)
class MotorModel:
    """A DC motor (``gearcli simulate`` with voltage columns): torque ``kt`` * i (N*m/A,
    also the back-EMF constant in V*s/rad), winding ``resistance`` (ohm) and
    ``inductance`` (H; None: the current follows the voltage at once,
    i = (V - kt*omega) / R), ``supply_voltage`` the largest |V| the drive applies (V)."""

    kt: float
    resistance: float
    supply_voltage: float
    inductance: float | None = None
    path: str = field(default="", compare=False)   # where it was read (for messages)

    def peak_torque(self, omega):
        """Largest torque at motor speed omega (rad/s) in the direction of motion:
        kt (V_supply - kt omega) / R (the torque-speed line)."""
        return self.kt * (self.supply_voltage - self.kt * omega) / self.resistance


@dataclass(frozen=True)
class BearingRating:
    """A rolling bearing of a joint.

    ``position``: m along the joint axis from the joint origin; ``C``, ``C0``: dynamic and
    static load ratings, N; ``type``: a key of :data:`BEARING_FACTOR_DEFAULTS`; ISO 281
    factors ``X``, ``Y``, ``e`` (None: ISO 281 Table 3 per sample) and ISO 76 factors
    ``X0``, ``Y0``; ``locating``: takes the axial load (one of two bearings); ``M``:
    tilting-moment rating, N*m (a single crossed-roller or four-point bearing), or None;
    ``f0``: the ball bearing's factor f0 for the table (None: the catalogue Fa/C0 column);
    ``a_ISO``: a given life modification factor, or ``kappa``, ``e_C`` and ``Cu`` (N) to
    compute it (:func:`gearcli.design.iso281.a_iso`); all None: basic rating life.
    A bearing with friction only (``friction_coefficient`` and ``bore``) has C, C0, type and
    the factors None: it enters the solve, not the design checks.
    """

    name: str
    position: float
    C: float | None
    C0: float | None
    type: str | None
    X: float | None
    Y: float | None
    e: float | None
    X0: float
    Y0: float
    locating: bool = True
    M: float | None = None
    path: str = field(default="", compare=False)   # where it was read (for messages)
    f0: float | None = None
    a_ISO: float | None = None
    kappa: float | None = None
    e_C: float | None = None
    Cu: float | None = None
    # Bearing friction (issue 19): M_b = friction_coefficient * bore / 2 * P_b about the axis,
    # P_b the magnitude of the bearing's load (dynamics.bearing_friction); bore in m.
    friction_coefficient: float | None = None
    bore: float | None = None
    pitch_diameter: float | None = None     # m: a crossed-roller bearing's d_p (its moment as 2 M/d_p)

    @property
    def rated(self) -> bool:
        """True when the bearing has load ratings (C, C0, type) for the design checks."""
        return self.C is not None

    @property
    def friction_arm(self) -> float:
        """mu_b d_b / 2 (m): the friction moment per N of bearing load; 0 without friction."""
        return 0.5 * self.friction_coefficient * self.bore if self.friction_coefficient else 0.0


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
    tangential force; ``quality_number`` Q_v and ``pitch_line_velocity`` (m/s) give the
    AGMA dynamic factor K_v (:func:`gearcli.design.fatigue.dynamic_factor`), which
    multiplies it too.
    """

    module: float
    face_width: float
    bending_stress_limit: float
    contact_stress_limit: float
    elastic_coefficient: float
    application_factor: float = 1.0
    load_sharing_factor: float = 1.0
    path: str = field(default="", compare=False)   # where it was read (for messages)
    quality_number: float | None = None       # AGMA Q_v: with pitch_line_velocity, the dynamic factor K_v
    pitch_line_velocity: float | None = None  # m/s, the highest of the duty (K_v is taken there)
