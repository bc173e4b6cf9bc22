"""Coaxial reducers: strain-wave (harmonic) and cycloidal (RV) gears (``gears[].kind:
strain_wave | cycloidal``; ``../shared/drive-elements.md`` section A, docs/concepts/drive-elements.md "Reducers").

Members and ratio
-----------------
Input I (wave generator, eccentric crank), output O (flexspline, output flange) and housing H
(circular spline, case) turn about one axis u.  With a = (w_I - w_H).u and b = (w_O - w_H).u
the rates of the input and the output relative to the housing, the element imposes
``a = i0 b`` (i0 the signed basic ratio: ``ratio``, or for a strain-wave gear
``teeth: [Z_F, Z_C]``, i0 = -Z_F / (Z_C - Z_F): the flexspline turns backwards).

gearcli writes it as a fundamental circuit of the paper (Eq. 8) with the housing as the
carrier: theta_{I,H} = e theta_{O,H}, e = i0 (z_I . z_O) about each member's own joint axis.
Its unknown u is the torque on I about z_I of the lossless element; the element exerts pure
torques about the axis and no force:

* on O, about z_O: T = -e u (the output torque, ``gear:<p>:torque``);
* on I, about z_I: c_r u, c_r the power-flow factor below (``gear:<p>:input_torque``, with the
  no-load running torque);
* on H: minus the sum (lossless: -T (1 - 1/i0) about u).

Power-flow efficiency (catalogue semantics)
-------------------------------------------
Forward (the input drives, power flows I -> O: T b > 0, equivalently u a < 0) the torque on I is
the lossless one divided by eta_f; backward (the output drives: u a > 0) it is the lossless one
times eta_b (eta_b <= 0: self-locking); at a = 0 the element is lossless.  So c_r = 1/eta_f,
eta_b or 1 by sign(u) sign(a), a sign pattern like the separating force's sign(t) (Eq. 14):
the sign rule resolves it.  The regime is taken from the joint rates (a is formed from them),
never from world vectors.  The loss is P = -(c_r - 1) u a >= 0.

No-load running torque T0 (``no_load_torque``): -T0 sign(a) about z_I on I and the opposite
on H, a known load; it dissipates T0 |a|.
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from .power_flow import SpeedTable

REDUCER_KINDS = ("strain_wave", "cycloidal")

LIFE_BASES = ("L10", "L50")


@dataclass(frozen=True)
class ReducerRating:
    """Catalogue ratings of a reducer (``gears[].rating`` of a strain-wave or cycloidal gear).

    Torques in N*m, speeds in rad/s of the input relative to the housing, life in h.  The life
    law L = L_n (n_N / n_av) (T_N / T_av)^p (:func:`reducer_life`) needs ``rated_torque`` T_N,
    ``rated_input_speed`` n_N, ``rated_life`` L_n and its ``life_basis`` ("L50": strain-wave
    catalogues; "L10": cycloidal); ``life_exponent`` p (3 strain-wave, 10/3 cycloidal).  The
    limits are each checked when given."""

    rated_torque: float
    rated_input_speed: float
    rated_life: float
    life_basis: str
    life_exponent: float
    average_torque_limit: float | None = None
    repeated_peak_torque: float | None = None
    max_input_speed: float | None = None
    average_input_speed_limit: float | None = None
    path: str = field(default="", compare=False)


@dataclass(frozen=True)
class Reducer:
    """What a strain-wave or cycloidal gear adds to its :class:`~.mechanism.GearPair` (whose
    ``j`` is the input, ``k`` the output, ``carrier`` the housing, ``ratio`` i0).

    ``forward``, ``backward``: eta_f in (0, 1] and eta_b in (-1, 1] (tables over |a|);
    ``no_load_torque``: T0 >= 0, N*m (table over |a|), None: none; ``torsional_stiffness``:
    ((T1, T2), (K1, K2, K3)) N*m and N*m/rad, None: not given (no windup column)."""

    forward: SpeedTable = SpeedTable.constant(1.0)
    backward: SpeedTable = SpeedTable.constant(1.0)
    no_load_torque: SpeedTable | None = None
    torsional_stiffness: tuple | None = None
    rating: ReducerRating | None = None

    def lossless(self) -> "Reducer":
        """The same reducer without losses (efficiencies 1, no no-load torque)."""
        return replace(self, forward=SpeedTable.constant(1.0), backward=SpeedTable.constant(1.0), no_load_torque=None)

    @property
    def power_flow_lossy(self) -> bool:
        """True when an efficiency is below 1: the torque on the input then depends on the
        power-flow direction, sign(u) sign(a) (a signed unknown, like Eq. 14's t)."""
        return any(v != 1.0 for v in self.forward.values + self.backward.values)

    @property
    def lossy(self) -> bool:
        """True when the element dissipates power: an efficiency below 1 or a no-load torque."""
        return (self.power_flow_lossy
                or (self.no_load_torque is not None and any(self.no_load_torque.values)))


def strain_wave_ratio(z_f: int, z_c: int) -> float:
    """i0 = -Z_F / (Z_C - Z_F) of a strain-wave gear with the circular spline held (200/202 ->
    -100): the flexspline (Z_F teeth) turns backwards relative to the wave generator."""
    return -z_f / (z_c - z_f)


def windup(red: Reducer, T) -> np.ndarray | None:
    """The output's torsion angle phi(T) (rad, (N,)) from the three-segment stiffness: T/K1 up
    to T1, T1/K1 + (|T| - T1)/K2 up to T2, then + (|T| - T2)/K3; odd in T.  None without a
    stiffness.  Reported, not fed back into the kinematics."""
    if red.torsional_stiffness is None:
        return None
    (T1, T2), (K1, K2, K3) = red.torsional_stiffness
    m = np.abs(np.asarray(T, float))
    phi = (np.minimum(m, T1) / K1 + np.clip(m - T1, 0.0, T2 - T1) / K2 + np.maximum(m - T2, 0.0) / K3)
    return np.sign(T) * phi


def average_torque(T, a, dt, p: float) -> float:
    """T_av = (sum |a_k| |T_k|^p dt_k / sum |a_k| dt_k)^(1/p) (N*m): the speed-weighted mean of
    the catalogue life law; 0 when the input never turns."""
    w = np.abs(a) * dt
    den = float(np.sum(w))
    if den == 0.0:
        return 0.0
    return float((np.sum(w * np.abs(T) ** p) / den) ** (1.0 / p))


def reducer_life(rating: ReducerRating, T_av: float, n_av: float) -> float:
    """L = L_n (n_N / n_av) (T_N / T_av)^p, h (inf when the input does not turn or carries no
    torque on average)."""
    if n_av <= 0.0 or T_av <= 0.0:
        return float("inf")
    return rating.rated_life * (rating.rated_input_speed / n_av) * (rating.rated_torque / T_av) ** rating.life_exponent
