"""Rolling bearings: loads on each bearing of a joint, ISO 281 rating life, ISO 76 static safety.

Every function works on arrays of samples (shape (N,)) and SI units: forces in N, moments
in N*m, positions in m, rates in rad/s, times in s.

Sources
-------
* ISO 281:2007, *Rolling bearings -- Dynamic load ratings and rating life*: basic rating
  life L10 = (C/P)^p million revolutions, p = 3 for ball and 10/3 for roller bearings
  (clause 7.2); the dynamic equivalent load P and its factors are in :mod:`.iso281`.
* Equivalent load of a varying duty (e.g. Harris & Kotzalas, *Essential Concepts of
  Bearing Technology*, 5th ed., ch. 11; SKF catalogue, "Fluctuating bearing load"): the
  load weighted by the revolutions n_k turned under it, P_eq = (sum n_k P_k^p / sum n_k)^(1/p)
  (:func:`life_sum`, :func:`equivalent_load`; with a life modification factor per sample,
  the Palmgren-Miner sum of ISO 281 section 9.3.3).
* ISO 76:2006, *Rolling bearings -- Static load ratings*: static equivalent load
  P0 = X0 Fr + Y0 Fa, not less than Fr (clause 6), static safety s0 = C0 / P0.
* The split of a joint reaction between two bearings (:mod:`gearcli.model.shaft`) is the
  statics of a shaft on two supports (any mechanics text, e.g. Shigley's *Mechanical Engineering Design*, 10th ed.,
  ch. 3, shaft reactions; Harris & Kotzalas ch. 3).
"""
from __future__ import annotations

import math

import numpy as np

from ..report.rms import trapezoid_weights
from . import magnitudes


def revolutions(rate, t, weights=None) -> np.ndarray:
    """Revolutions turned at each sample, |rate_k| w_k / 2 pi (w the trapezoid weights of
    :func:`gearcli.report.rms.trapezoid_weights`, or ``weights``, those of ``t`` already
    computed), shape (N,); rate in rad/s, t in s."""
    w = trapezoid_weights(t) if weights is None else weights
    n = magnitudes(rate, w)                   # (in place)
    n *= w
    n /= 2 * math.pi
    return n


def life_sum(P, revs, p: float, a=1.0) -> float:
    """Palmgren-Miner sum of a duty, sum_k n_k P_k^p / a_k (rev N^p): each revolution at P_k
    uses up (P_k/C)^p / a_k of a million-revolution life (a_k the life modification factor,
    1 for the basic rating life)."""
    P, revs = np.asarray(P, float), np.asarray(revs, float)
    w = np.empty(np.broadcast_shapes(P.shape, revs.shape))      # (in place)
    if p == 3.0:              # a ball bearing's cube: products, not pow
        np.multiply(P, P, out=w)
        w *= P
    else:
        np.power(P, p, out=w)
    w *= revs
    if not (np.ndim(a) == 0 and a == 1.0):      # / 1.0 changes nothing
        w /= a
    return float(np.sum(w))


def equivalent_load(total: float, revs: float, p: float) -> float:
    """Equivalent load of a varying duty, weighted by the revolutions turned under each load:
    P_eq = (life_sum / revolutions)^(1/p), N; 0 when the bearing never turns."""
    return (total / revs) ** (1.0 / p) if revs > 0 else 0.0


def rating_life_mrev(C: float, P_eq: float, p: float) -> float:
    """ISO 281 basic rating life L10 = (C / P_eq)^p in millions of revolutions (inf if P_eq = 0)."""
    if P_eq <= 0:
        return math.inf
    try:
        return (C / P_eq) ** p
    except OverflowError:     # float ** raises where * and / give inf: beyond 1.8e308, inf
        return math.inf


def rating_life_hours(L10_mrev: float, revolutions_per_hour: float) -> float:
    """L10h = L10 * 1e6 / (revolutions per hour), h (inf when the bearing does not turn)."""
    if revolutions_per_hour <= 0:
        return math.inf
    return L10_mrev * 1e6 / revolutions_per_hour


def required_equivalent_load(C: float, life_h: float, revolutions_per_hour: float, p: float) -> float:
    """The P_eq (N) that gives exactly ``life_h`` hours: C / (life_h * rev/h / 1e6)^(1/p);
    inf when the bearing turns too little for the product to be a positive float."""
    base = life_h * revolutions_per_hour / 1e6
    if not base > 0:
        return math.inf
    return C / base ** (1.0 / p)


def static_equivalent_load(Fr, Fa, X0: float, Y0: float) -> np.ndarray:
    """ISO 76 static equivalent radial load P0 = max(X0 Fr + Y0 Fa, Fr), N, per sample."""
    Fr, Fa = magnitudes(Fr, Fa), magnitudes(Fa, Fr)
    P = np.multiply(X0, Fr, out=np.empty_like(Fr))
    Fa *= Y0                  # (in place)
    P += Fa
    return np.maximum(P, Fr, out=P)


def static_safety(allowable: float, peak: float) -> float:
    """Safety factor s = allowable / peak (ISO 76 s0 = C0 / max P0; the same ratio for tooth
    stresses); inf when unloaded."""
    return math.inf if peak <= 0 else allowable / peak
