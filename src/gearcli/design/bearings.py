"""Rolling bearings: loads on each bearing of a joint, ISO 281 rating life, ISO 76 static safety.

Every function works on arrays of samples (shape (N,)) and SI units: forces in N, moments
in N*m, positions in m, rates in rad/s, times in s.

Sources
-------
* ISO 281:2007, *Rolling bearings -- Dynamic load ratings and rating life*: dynamic
  equivalent radial load P = X Fr + Y Fa (with P = Fr when Fa/Fr <= e), basic rating life
  L10 = (C/P)^p million revolutions, p = 3 for ball and 10/3 for roller bearings (clauses
  6.2, 7.2).
* Equivalent load of a varying duty (e.g. Harris & Kotzalas, *Essential Concepts of
  Bearing Technology*, 5th ed., ch. 11; SKF catalogue, "Fluctuating bearing load"): the
  load weighted by the revolutions turned under it,
  P_eq = (sum |w_k| dt_k P_k^p / sum |w_k| dt_k)^(1/p).
* ISO 76:2006, *Rolling bearings -- Static load ratings*: static equivalent load
  P0 = X0 Fr + Y0 Fa, not less than Fr (clause 6), static safety s0 = C0 / P0.
* The split of a joint reaction between two bearings is the statics of a shaft on two
  supports (any mechanics text, e.g. Shigley's *Mechanical Engineering Design*, 10th ed.,
  ch. 3, shaft reactions; Harris & Kotzalas ch. 3).
"""
from __future__ import annotations

import math

import numpy as np

from ..model.ratings import BEARING_FACTOR_DEFAULTS

LIFE_EXPONENT = {"ball": 3.0, "roller": 10.0 / 3.0}
"""p of ISO 281: L10 = (C/P)^p."""

FACTOR_DEFAULTS = BEARING_FACTOR_DEFAULTS
"""Default X, Y, e, X0, Y0 by bearing type (see :mod:`gearcli.model.ratings`)."""


def equivalent_dynamic_load(Fr, Fa, X: float, Y: float, e: float) -> np.ndarray:
    """ISO 281 dynamic equivalent radial load of each sample.

    Parameters
    ----------
    Fr, Fa : array_like, shape (N,)
        Radial and axial load on the bearing, N (signs ignored).
    X, Y, e : float
        Radial and axial load factors and the limit e of Fa/Fr.

    Returns
    -------
    ndarray, shape (N,)
        P = Fr when Fa/Fr <= e, else X Fr + Y Fa (N).  With Fr = 0 and Fa > 0, Fa/Fr is
        infinite, so P = Y Fa.
    """
    Fr, Fa = np.abs(np.asarray(Fr, float)), np.abs(np.asarray(Fa, float))
    small = Fa <= e * Fr
    return np.where(small, Fr, X * Fr + Y * Fa)


def duty_equivalent_load(P, rate, dt, p: float) -> float:
    """Equivalent load of a duty cycle, weighted by the revolutions turned under each load.

    P_eq = (sum |rate_k| dt_k P_k^p / sum |rate_k| dt_k)^(1/p).

    Parameters
    ----------
    P : array_like, shape (N,)
        Dynamic equivalent load at each sample, N.
    rate : array_like, shape (N,)
        Relative rotation rate of the bearing rings (the joint rate), rad/s.
    dt : array_like, shape (N,)
        Time weight of each sample, s (see :func:`sample_weights`).
    p : float
        Life exponent (3 for ball, 10/3 for roller bearings).

    Returns
    -------
    float
        P_eq in N; 0 when the bearing never turns.
    """
    w = np.abs(np.asarray(rate, float)) * np.asarray(dt, float)
    total = float(np.sum(w))
    if total == 0.0:
        return 0.0
    return float((np.sum(w * np.asarray(P, float) ** p) / total) ** (1.0 / p))


def rating_life_mrev(C: float, P_eq: float, p: float) -> float:
    """ISO 281 basic rating life L10 = (C / P_eq)^p in millions of revolutions (inf if P_eq = 0)."""
    return math.inf if P_eq <= 0 else (C / P_eq) ** p


def rating_life_hours(L10_mrev: float, revolutions_per_hour: float) -> float:
    """L10h = L10 * 1e6 / (revolutions per hour), h (inf when the bearing does not turn)."""
    if revolutions_per_hour <= 0:
        return math.inf
    return L10_mrev * 1e6 / revolutions_per_hour


def required_equivalent_load(C: float, life_h: float, revolutions_per_hour: float, p: float) -> float:
    """The P_eq (N) that gives exactly ``life_h`` hours: C / (life_h * rev/h / 1e6)^(1/p)."""
    if revolutions_per_hour <= 0:
        return math.inf
    return C / (life_h * revolutions_per_hour / 1e6) ** (1.0 / p)


def static_equivalent_load(Fr, Fa, X0: float, Y0: float) -> np.ndarray:
    """ISO 76 static equivalent radial load P0 = max(X0 Fr + Y0 Fa, Fr), N, per sample."""
    Fr, Fa = np.abs(np.asarray(Fr, float)), np.abs(np.asarray(Fa, float))
    return np.maximum(X0 * Fr + Y0 * Fa, Fr)


def static_safety(C0: float, P0) -> float:
    """Static safety factor s0 = C0 / max_k P0_k (inf when unloaded)."""
    peak = float(np.max(P0)) if np.size(P0) else 0.0
    return math.inf if peak <= 0 else C0 / peak


def split_two_bearings(F, M, z1: float, z2: float) -> tuple[np.ndarray, np.ndarray]:
    """Radial force vectors on two bearings at z1 and z2 along the joint axis.

    The shaft is held by two supports on its axis (z of the joint frame).  The radial
    forces R1 (at z1 e_z) and R2 (at z2 e_z) must carry the joint reaction's force and
    tilting moment about the joint origin:

        R1 + R2 = F_xy,   z1 e_z x R1 + z2 e_z x R2 = M_xy,

    and e_z x R = (-R_y, R_x), so z1 R1 + z2 R2 = (M_y, -M_x) =: m.  Hence
    R2 = (m - z1 F_xy) / (z2 - z1) and R1 = F_xy - R2.

    Parameters
    ----------
    F, M : array_like, shape (N, 3)
        Reaction force (N) and moment about the joint origin (N*m), joint frame.
    z1, z2 : float
        Bearing positions along the joint axis from the joint origin, m (z1 != z2).

    Returns
    -------
    R1, R2 : ndarray, shape (N, 2)
        x, y components of the radial force on each bearing, N.
    """
    F, M = np.asarray(F, float), np.asarray(M, float)
    if z1 == z2:
        raise ValueError("two bearings need different positions")
    m = np.stack([M[:, 1], -M[:, 0]], axis=1)
    R2 = (m - z1 * F[:, :2]) / (z2 - z1)
    return F[:, :2] - R2, R2


def sample_weights(t) -> np.ndarray:
    """Time weight of each sample for sums over a trajectory (trapezoid rule), s.

    dt_k = (t_{k+1} - t_{k-1}) / 2 inside, half a step at the two ends; sums to t_N - t_1.
    A single sample gets weight 0.
    """
    t = np.asarray(t, float)
    if t.size < 2:
        return np.zeros_like(t)
    d = np.diff(t)
    w = np.empty_like(t)
    w[0], w[-1] = d[0] / 2, d[-1] / 2
    w[1:-1] = (d[:-1] + d[1:]) / 2
    return w
